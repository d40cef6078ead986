"""Air mass and clear-sky beam irradiance.

References
----------
.. [1] F. Kasten, A. T. Young, "Revised optical air mass tables and approximation formula",
   Applied Optics 28(22), 4735-4738, 1989, Eq. 3 (Shin et al. Eq. 1).
.. [2] A. B. Meinel, M. P. Meinel, "Applied Solar Energy: An Introduction", Addison-Wesley,
   1976; as given by PVCDROM / PVEducation, "Air Mass" and "Solar radiation at the Earth's
   surface": I_D = 1.353 * 0.7 ** (AM ** 0.678) kW/m^2 (Shin et al. Eq. 2, whose OCR text reads
   the exponent 0.678 as "0.076").
.. [3] E. G. Laue, "The measurement of solar spectral irradiance at different terrestrial
   elevations", Solar Energy 13, 43-57, 1970; altitude term a*h with a = 0.14 /km, via PVEducation.
"""

from __future__ import annotations

import numpy as np
import pvlib

SKY_MODELS = ("meinel",)

SOLAR_CONSTANT_MEINEL = 1353.0  # [W/m^2], the constant of Meinel & Meinel [2]
LAUE_ALTITUDE_COEFFICIENT = 0.14  # [1/km], [3]


def relative_airmass(solar_zenith):
    """Relative optical air mass by Kasten & Young 1989 [1]_ (pvlib ``kastenyoung1989``).

    Parameters
    ----------
    solar_zenith : array_like
        Solar zenith [deg]; apparent zenith where refraction is modelled.

    Returns
    -------
    numpy.ndarray
        Air mass [-]; NaN with the sun below the horizon.
    """
    zenith = np.asarray(solar_zenith, dtype=float)
    return np.asarray(pvlib.atmosphere.get_relative_airmass(zenith, model="kastenyoung1989"))


def beam_meinel(airmass, altitude=0.0):
    """Direct normal irradiance of the Meinel & Meinel clear sky [2]_, with Laue's altitude term [3]_.

    ``I_D = 1353 * ((1 - a h) * 0.7 ** (AM ** 0.678) + a h)`` W/m^2, a = 0.14 /km, h [km].

    Parameters
    ----------
    airmass : array_like
        Relative air mass [-]; NaN (sun down) gives 0.
    altitude : float, default 0
        Site altitude [m]; 0 gives Shin et al. Eq. 2 exactly.

    Returns
    -------
    numpy.ndarray
        Direct normal irradiance [W/m^2].
    """
    airmass = np.asarray(airmass, dtype=float)
    altitude_term = LAUE_ALTITUDE_COEFFICIENT * altitude / 1000.0
    transmitted = (1.0 - altitude_term) * 0.7 ** (airmass**0.678) + altitude_term
    return np.where(np.isfinite(airmass), SOLAR_CONSTANT_MEINEL * transmitted, 0.0)


def clear_sky_dni(solar_zenith, altitude=0.0, model="meinel"):
    """Clear-sky direct normal irradiance [W/m^2], zero with the sun below the horizon.

    Parameters
    ----------
    solar_zenith : array_like
        [deg].
    altitude : float, default 0
        Site altitude [m].
    model : {'meinel'}
        Sky model.
    """
    if model == "meinel":
        return beam_meinel(relative_airmass(solar_zenith), altitude)
    raise ValueError(f"sky must be one of {', '.join(SKY_MODELS)}; got {model!r}")
