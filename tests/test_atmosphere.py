"""Air mass and the Meinel beam against the papers' formulas and physical identities."""

import numpy as np
import pytest

from foldopt.physics.atmosphere import beam_meinel, clear_sky_dni, relative_airmass


def shin_eq1(zenith):
    """Shin et al. Eq. 1 as printed (the OCR text of this equation is intact), Kasten & Young 1989."""
    return 1.0 / (np.cos(np.radians(zenith)) + 0.50572 * (96.07995 - zenith) ** -1.6364)


def test_airmass_is_kasten_young_eq1():
    zenith = np.linspace(0, 90, 91)
    np.testing.assert_allclose(relative_airmass(zenith), shin_eq1(zenith), rtol=1e-12)


def test_airmass_tends_to_secant_high_sun_and_is_nan_below_horizon():
    # Plane-parallel limit: within 0.3 % of sec(z) up to 60 deg (Kasten & Young 1989, Table).
    zenith = np.linspace(0, 60, 61)
    np.testing.assert_allclose(relative_airmass(zenith), 1 / np.cos(np.radians(zenith)), rtol=3e-3)
    assert np.isnan(relative_airmass(95.0))


def test_meinel_identities():
    # AM 0 is outside the atmosphere: the solar constant 1353 W/m^2 (Meinel & Meinel 1976);
    # AM 1 transmits 70 % ("0.7 arises from ... 70 % ... transmitted", PVEducation).
    assert beam_meinel(0.0) == pytest.approx(1353.0)
    assert beam_meinel(1.0) == pytest.approx(0.7 * 1353.0)
    # Laue's altitude term: at a*h = 1 (h = 1/0.14 km) the atmosphere would vanish.
    assert beam_meinel(5.0, altitude=1000 / 0.14) == pytest.approx(1353.0)
    # Higher sites see more beam at the same air mass.
    assert beam_meinel(2.0, altitude=2000) > beam_meinel(2.0)


def test_clear_sky_dni_zero_at_night_and_falls_with_zenith():
    dni = clear_sky_dni(np.array([0.0, 30.0, 60.0, 85.0, 90.5, 120.0]))
    assert np.all(np.diff(dni[:4]) < 0)
    np.testing.assert_array_equal(dni[4:], 0.0)
    with pytest.raises(ValueError, match="meinel"):
        clear_sky_dni(np.array([0.0]), model="ineichen")
