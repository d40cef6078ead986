"""Air mass and the Meinel beam against the papers' formulas, physical identities and pvlib."""

import numpy as np
import pvlib
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from foldopt.physics.atmosphere import (
    beam_meinel,
    clear_sky_dni,
    extraterrestrial_spencer,
    relative_airmass,
)


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


def test_meinel_sky_is_its_formula_at_every_step_with_the_sun_up_and_zero_else():
    """The Meinel sky (worked out only where the sun is up) is Eq. 1-2 with Laue's altitude term to
    the bit at every step up, 0 at every step down (the horizon and NaN included), per block's
    altitude."""
    zenith = np.random.default_rng(3).uniform(-5.0, 180.0, (40, 300))
    zenith[0, :4] = [90.0, np.nextafter(90.0, 100.0), np.nextafter(90.0, 0.0), np.nan]
    altitude = np.linspace(0.0, 3000.0, 40)[:, None]
    dni = clear_sky_dni(zenith, altitude, "meinel")
    up = zenith <= 90.0
    airmass = shin_eq1(zenith[up])
    term = 0.14 * np.broadcast_to(altitude, zenith.shape)[up] / 1000.0
    np.testing.assert_allclose(dni[up], 1353.0 * ((1.0 - term) * 0.7 ** (airmass**0.678) + term), rtol=1e-12)
    np.testing.assert_array_equal(dni[up], beam_meinel(relative_airmass(zenith), altitude)[up])
    np.testing.assert_array_equal(dni[~up], 0.0)


@pytest.mark.filterwarnings("ignore:DatetimeIndex.dayofyear is deprecated")  # in pvlib's lookup, not ours to fix
def test_linke_turbidity_is_pvlibs_lookup_to_the_bit():
    """foldopt reads pvlib's climatology once per site and interpolates once per UTC day
    (foldopt.inputs.turbidity); pvlib's own lookup, at every stamp, is the reference: random
    sites (the poles and the date line included) and instants over 40 years, leap years too."""
    import pandas as pd
    import pvlib

    from foldopt.inputs.turbidity import linke_turbidity

    rng = np.random.default_rng(3)
    places = [(90.0, -180.0), (-90.0, 180.0), *zip(rng.uniform(-90, 90, 30), rng.uniform(-180, 180, 30))]
    for latitude, longitude in places:
        stamps = np.sort(rng.integers(0, 40 * 365 * 86_400, 200)) * 10**9 + 10**18 // 2
        times = pd.DatetimeIndex(stamps).tz_localize("UTC")
        expected = pvlib.clearsky.lookup_linke_turbidity(times, latitude, longitude).to_numpy()
        np.testing.assert_array_equal(linke_turbidity(latitude, longitude, stamps), expected)
    assert linke_turbidity(0.0, 0.0, np.zeros((2, 0), dtype=np.int64)).shape == (2, 0)  # no step with the sun up


@pytest.mark.filterwarnings("ignore:DatetimeIndex.dayofyear is deprecated")  # in pvlib's lookup, not ours to fix
@settings(max_examples=40, deadline=None)
@given(
    places=st.lists(st.tuples(st.floats(-90.0, 90.0), st.floats(-180.0, 180.0)), min_size=1, max_size=4),
    data=st.data(),
)
def test_linke_turbidity_of_many_sites_is_pvlibs_lookup_to_the_bit(places, data):
    """A map's chunk asks for many sites at once, a site per row of steps (the engine's blocks):
    each row is pvlib's lookup at its own site, to the bit, whether the rows are a day's steps
    (across a UTC midnight or not) or instants spread over 40 years, and whichever sites share
    the call (repeated, interleaved)."""
    import pandas as pd

    from foldopt.inputs.turbidity import linke_turbidity

    which = data.draw(st.lists(st.integers(0, len(places) - 1), min_size=1, max_size=6))
    seconds = st.integers(0, 40 * 365 * 86_400)
    if data.draw(st.booleans(), label="a day's steps a row"):
        starts = data.draw(arrays(np.int64, len(which), elements=seconds), label="starts [s]")
        step = data.draw(st.sampled_from([60, 300, 1_800]), label="step [s]")
        stamps = (starts[:, None] + np.arange(48) * step) * 10**9 + 10**18 // 2
    else:
        stamps = data.draw(arrays(np.int64, (len(which), 30), elements=seconds)) * 10**9 + 10**18 // 2
    latitude = np.array([places[i][0] for i in which])
    longitude = np.array([places[i][1] for i in which])
    turbidity = linke_turbidity(latitude, longitude, stamps)
    for row, (lat, lon) in enumerate(zip(latitude, longitude, strict=True)):
        times = pd.DatetimeIndex(stamps[row]).tz_localize("UTC")
        expected = pvlib.clearsky.lookup_linke_turbidity(times, lat, lon).to_numpy()
        np.testing.assert_array_equal(turbidity[row], expected)


@settings(max_examples=50, deadline=None)
@given(zenith=arrays(np.float64, st.integers(1, 50), elements=st.floats(-10.0, 180.0)))
def test_airmass_is_pvlibs_kasten_young_to_the_bit(zenith):
    """pvlib's expression, operation for operation: the same bits, NaN below the horizon."""
    expected = pvlib.atmosphere.get_relative_airmass(zenith, model="kastenyoung1989")
    np.testing.assert_array_equal(relative_airmass(zenith), expected)


def test_spencer_extraterrestrial_irradiance_is_pvlibs_to_the_bit():
    """Every day of the year and a leap year's last: pvlib's get_extra_radiation (Spencer)."""
    days = np.arange(367)
    np.testing.assert_array_equal(
        extraterrestrial_spencer(days), np.asarray(pvlib.irradiance.get_extra_radiation(days))
    )
    np.testing.assert_array_equal(
        extraterrestrial_spencer(days, 1361.0),
        np.asarray(pvlib.irradiance.get_extra_radiation(days, solar_constant=1361.0)),
    )
    # The Earth is nearest the Sun in early January, farthest in early July (+-3.3 %).
    january, july = extraterrestrial_spencer([3, 185])
    assert january > 1366.1 * 1.03 > 1366.1 * 0.97 > july
