"""Beam irradiance on a tilted surface.

References
----------
.. [1] D. Shin et al., "Reconfigurable three dimensional photovoltaic panel architecture for
   solar-powered time extension", Eq. 5.
.. [2] C. Honsberg, S. Bowden, PVCDROM / PVEducation, "Arbitrary Orientation and Tilt":
   S_module = S_incident [cos(a) sin(b) cos(psi - theta) + sin(a) cos(b)]; for a module facing the
   sun's azimuth this reduces to S_incident sin(a + b), which Shin et al. Eq. 5 multiplies by the
   cosine of the azimuth difference.
.. [3] pvlib.irradiance.aoi_projection (the exact cosine of the angle of incidence).
"""

from __future__ import annotations

import numpy as np
import pvlib

INCIDENCE_MODELS = ("paper", "exact")


def beam_incidence_factor(surface_tilt, surface_azimuth, solar_zenith, solar_azimuth, model="exact"):
    """Ratio of beam irradiance on the surface to direct normal irradiance, clipped at zero.

    Parameters
    ----------
    surface_tilt, surface_azimuth : array_like
        Surface orientation [deg]; broadcast against the sun's arrays.
    solar_zenith, solar_azimuth : array_like
        Sun position [deg].
    model : {'exact', 'paper'}
        ``exact``: cosine of the true angle of incidence [3]_.
        ``paper``: Shin et al. Eq. 5 [1]_, ``sin(elevation + tilt) * cos(surface_azimuth -
        solar_azimuth)``. It equals the exact factor when the surface faces the sun's azimuth and
        departs from it otherwise (at zero tilt it still depends on azimuth); each factor is
        clipped at zero so that two negative factors never make light from behind.

    Returns
    -------
    numpy.ndarray
        Incidence factor [-], in [0, 1].
    """
    if model == "exact":
        projection = pvlib.irradiance.aoi_projection(
            surface_tilt, surface_azimuth, solar_zenith, solar_azimuth
        )
        return np.clip(np.asarray(projection), 0.0, None)
    if model == "paper":
        elevation = 90.0 - np.asarray(solar_zenith)
        height = np.sin(np.radians(elevation + np.asarray(surface_tilt)))
        heading = np.cos(np.radians(np.asarray(surface_azimuth) - np.asarray(solar_azimuth)))
        return np.clip(height, 0.0, None) * np.clip(heading, 0.0, None)
    raise ValueError(f"model must be one of {', '.join(INCIDENCE_MODELS)}; got {model!r}")
