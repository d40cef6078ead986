"""Irradiance on a tilted surface: the beam's incidence, and the diffuse light as terms.

Every transposition model that foldopt offers (pvlib's isotropic, Hay & Davies and Perez) gives
the sky diffuse light on a surface of tilt beta as
``max(iso * (1 + cos beta) / 2 + circ * max(cos AOI, 0) + hor * sin beta, 0)``, with terms that
depend on the sky and the sun only, and the ground-reflected light as
``ground * (1 - cos beta) / 2``. :func:`sky_diffuse_terms` computes the four terms once per time
step; then any number of orientations cost a few multiplications each
(:func:`plane_of_array`, and the compiled kernel), instead of one pvlib call per orientation.
Tests check the sum against ``pvlib.irradiance.get_total_irradiance``.

References
----------
.. [1] D. Shin et al., "Reconfigurable three dimensional photovoltaic panel architecture for
   solar-powered time extension", Eq. 5.
.. [2] C. Honsberg, S. Bowden, PVCDROM / PVEducation, "Arbitrary Orientation and Tilt":
   S_module = S_incident [cos(a) sin(b) cos(psi - theta) + sin(a) cos(b)]; for a module facing the
   sun's azimuth this reduces to S_incident sin(a + b), which Shin et al. Eq. 5 multiplies by the
   cosine of the azimuth difference.
.. [3] pvlib.irradiance.aoi_projection (the exact cosine of the angle of incidence).
.. [4] J. E. Hay, J. A. Davies, "Calculations of the solar radiation incident on an inclined
   surface", Proc. First Canadian Solar Radiation Data Workshop, 59-72, 1980 (pvlib
   ``irradiance.haydavies``).
.. [5] R. Perez, P. Ineichen, R. Seals, J. Michalsky, R. Stewart, "Modeling daylight availability
   and irradiance components from direct and global irradiance", Solar Energy 44(5), 271-289,
   1990, Eq. 9 and Table 6 (pvlib ``irradiance.perez``, its coefficient set
   ``allsitescomposite1990``).
"""

from __future__ import annotations

import numpy as np

from foldopt import names

INCIDENCE_MODELS = ("paper", "exact")
TRANSPOSITIONS = tuple(name for name in names.TRANSPOSITIONS if name != "none")
#: Lower edges of Perez et al.'s eight sky-clearness bins [5]_ Table 6, the first from 0 as pvlib
#: places it; a clearness below 0 (or NaN: no diffuse light) has no bin and no diffuse terms.
CLEARNESS_EDGES = (0.0, 1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2)
PEREZ_KAPPA = 1.041  # [rad^-3], Perez et al. [5]_ Eq. 1
#: The floors of cos(zenith) under the circumsolar term, as pvlib's ``haydavies`` and ``perez`` set them.
HAYDAVIES_COS_FLOOR, PEREZ_COS_FLOOR = 0.01745, float(np.cos(np.radians(85.0)))


def perez_coefficients() -> tuple[np.ndarray, np.ndarray]:
    """Perez et al.'s F1 and F2 coefficients [5]_ Table 6 per clearness bin, (8, 3) each, as pvlib's
    ``allsitescomposite1990`` set."""
    import pvlib

    f1, f2 = pvlib.irradiance._get_perez_coefficients("allsitescomposite1990")
    return np.ascontiguousarray(f1, dtype=float), np.ascontiguousarray(f2, dtype=float)


def beam_incidence_factor(
    surface_tilt, surface_azimuth, solar_zenith, solar_azimuth, model="exact"
):
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

    Raises
    ------
    ValueError
        If ``model`` is not one of :data:`INCIDENCE_MODELS`.

    Examples
    --------
    A south-facing panel tilted 30 deg, the sun 30 deg from the zenith in the south-east:

    >>> for model in ("exact", "paper"):
    ...     print(model, round(float(beam_incidence_factor(30.0, 180.0, 30.0, 135.0, model)), 4))
    exact 0.9268
    paper 0.7071
    """
    if model == "exact":
        import pvlib

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


def _perez_brightness(dhi, dni, dni_extra, solar_zenith, airmass):
    """Perez et al.'s circumsolar and horizon brightening coefficients F1, F2 [5]_ Eq. 9, with the
    sky clearness bins and coefficients of pvlib's ``irradiance.perez`` (``allsitescomposite1990``);
    NaN where there is no diffuse light."""
    z = np.radians(solar_zenith)
    delta = dhi * airmass / dni_extra
    # z cubed as products: np.power is much the slower over a map's steps (docs/performance.rst)
    kappa_z3 = PEREZ_KAPPA * (z * z * z)
    with np.errstate(invalid="ignore", divide="ignore"):
        eps = ((dhi + dni) / dhi + kappa_z3) / (1.0 + kappa_z3)
    # The bin is the count of its lower edges at or below eps, less one (np.digitize's), -1 for NaN
    # (no diffuse light), summed edge by edge: eight comparisons are a third of a binary search's cost.
    bins = np.full(np.shape(eps), -1, dtype=np.intp)
    for edge in CLEARNESS_EDGES:
        bins += eps >= edge
    f1c, f2c = (np.vstack((c, np.full(3, np.nan))) for c in perez_coefficients())
    f1 = np.maximum(f1c[bins, 0] + f1c[bins, 1] * delta + f1c[bins, 2] * z, 0.0)
    f2 = f2c[bins, 0] + f2c[bins, 1] * delta + f2c[bins, 2] * z
    return f1, f2


def sky_diffuse_terms(model, solar_zenith, dni, ghi, dhi, dni_extra, airmass, albedo):
    """Orientation-free terms of the diffuse light, per time step (see the module docstring).

    Parameters
    ----------
    model : {'isotropic', 'haydavies', 'perez'}
        Transposition model [4]_ [5]_, as pvlib implements it.
    solar_zenith, dni, ghi, dhi, dni_extra, airmass : array_like
        [deg], [W/m^2] x 4, relative air mass [-] (0 with the sun down); ``dhi >= 0``.
    albedo : float
        Ground reflectance [-].

    Returns
    -------
    numpy.ndarray
        (..., 4): ``iso``, ``circ``, ``hor``, ``ground`` [W/m^2].

    Raises
    ------
    ValueError
        If ``model`` is not one of :data:`TRANSPOSITIONS`.
    """
    dhi = np.asarray(dhi, dtype=float)
    zeros = np.zeros_like(dhi)
    if model == "isotropic":
        iso, circ, hor = dhi, zeros, zeros
    elif model == "haydavies":
        anisotropy = np.asarray(dni, dtype=float) / dni_extra
        iso = dhi * np.maximum(1.0 - anisotropy, 0.0)
        circ = dhi * anisotropy / np.maximum(np.cos(np.radians(solar_zenith)), HAYDAVIES_COS_FLOOR)
        hor = zeros
    elif model == "perez":
        f1, f2 = _perez_brightness(dhi, dni, dni_extra, solar_zenith, airmass)
        iso = dhi * (1.0 - f1)
        circ = dhi * f1 / np.maximum(np.cos(np.radians(solar_zenith)), PEREZ_COS_FLOOR)
        hor = dhi * f2
    else:
        raise ValueError(f"transposition must be one of {', '.join(TRANSPOSITIONS)}; got {model!r}")
    terms = np.stack(
        np.broadcast_arrays(iso, circ, hor, np.asarray(ghi, dtype=float) * albedo), axis=-1
    )
    terms[np.isnan(terms)] = 0.0  # no diffuse light: pvlib's NaN, foldopt's 0
    return terms


def plane_of_array(cos_aoi, cos_tilt, dni, terms=None, beam_factor=None, iam=1.0, views=None):
    """Irradiance on surfaces [W/m^2] from the sun's incidence and the diffuse terms.

    Parameters
    ----------
    cos_aoi : array_like
        Cosine of the angle of incidence [-] (any sign).
    cos_tilt : array_like
        Cosine of the surface tilt [-], broadcast against ``cos_aoi``.
    dni : array_like
        Direct normal irradiance [W/m^2].
    terms : array_like, optional
        (..., 4) from :func:`sky_diffuse_terms`; None for beam only.
    beam_factor : array_like, optional
        The beam's incidence factor, default ``max(cos_aoi, 0)`` (paper mode: Eq. 5).
    iam : array_like, default 1
        Incidence-angle modifier of the beam [-].
    views : tuple of array_like, optional
        The surfaces' factors of the isotropic and the horizon-band terms, in place of
        ``(1 + cos_tilt) / 2`` and ``sin(tilt)`` (a horizon hides part of the sky:
        :func:`foldopt.physics.horizon.sky_view_factors`).

    Returns
    -------
    numpy.ndarray
        Plane-of-array irradiance [W/m^2]: beam, sky diffuse and ground-reflected (the module
        docstring's sum), the broadcast shape.

    Examples
    --------
    Beam only, 800 W/m^2 normal to the sun at 60 deg incidence:

    >>> print(plane_of_array(0.5, 1.0, 800.0))
    400.0
    """
    cos_aoi = np.asarray(cos_aoi, dtype=float)
    factor = np.clip(cos_aoi, 0.0, None) if beam_factor is None else beam_factor
    poa = dni * factor * iam
    if terms is None:
        return poa
    iso, circ, hor, ground = np.moveaxis(np.asarray(terms), -1, 0)
    cos_tilt = np.asarray(cos_tilt, dtype=float)
    if views is None:
        sky_view, sin_tilt = (1.0 + cos_tilt) * 0.5, np.sqrt(np.clip(1.0 - cos_tilt**2, 0.0, None))
    else:
        sky_view, sin_tilt = views
    sky = np.maximum(iso * sky_view + circ * np.clip(cos_aoi, 0.0, None) + hor * sin_tilt, 0.0)
    return poa + sky + ground * (1.0 - cos_tilt) * 0.5
