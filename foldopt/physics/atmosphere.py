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
.. [4] H. C. Hottel, "A simple model for estimating the transmittance of direct solar radiation
   through clear atmospheres", Solar Energy 18, 129-134, 1976; as given by J. A. Duffie,
   W. A. Beckman, "Solar Engineering of Thermal Processes", Sec. 2.8, Eq. 2.8.1 and Table 2.8.1.
   Robles Algarin et al. Eq. 4-7 quote it with OCR damage: a1* has "+ 0.00595 (6.5 - A)^2" and k*
   "+ 0.01858 (2.5 - A)^2" (the seed text reads "- 0.005958 (6 - A)^2" and "- 0.01858").
.. [5] J. W. Spencer, "Fourier series representation of the position of the sun", Search 2(5),
   172, 1971; as given by M. Iqbal, "An Introduction to Solar Radiation", Academic Press, 1983,
   Eq. 1.2.1 (pvlib ``irradiance.get_extra_radiation``, method ``spencer``).
"""

from __future__ import annotations

import numpy as np

from foldopt.names import BEAM_SKIES

SKY_MODELS = BEAM_SKIES
#: Hottel's climate corrections (r0, r1, rk) of a0, a1 and k, Duffie & Beckman Table 2.8.1.
HOTTEL_CLIMATES = {
    "tropical": (0.95, 0.98, 1.02),
    "midlatitude-summer": (0.97, 0.99, 1.02),
    "subarctic-summer": (0.99, 0.99, 1.01),
    "midlatitude-winter": (1.03, 1.01, 1.00),
}
SOLAR_CONSTANT_HOTTEL = 1367.0  # [W/m^2], Duffie & Beckman

SOLAR_CONSTANT_MEINEL = 1353.0  # [W/m^2], the constant of Meinel & Meinel [2]
SOLAR_CONSTANT_PVLIB = 1366.1  # [W/m^2], pvlib's default for get_extra_radiation
LAUE_ALTITUDE_COEFFICIENT = 0.14  # [1/km], [3]


def relative_airmass(solar_zenith):
    """Relative optical air mass by Kasten & Young 1989 [1]_ (pvlib ``kastenyoung1989``).

    ``AM = 1 / (cos(z) + 0.50572 (96.07995 - z) ** -1.6364)``, z in degrees (Shin et al. Eq. 1).

    Parameters
    ----------
    solar_zenith : array_like
        Solar zenith [deg]; apparent zenith where refraction is modelled.

    Returns
    -------
    numpy.ndarray
        Air mass [-]; NaN with the sun below the horizon.

    References
    ----------
    .. [1] F. Kasten, A. T. Young, "Revised optical air mass tables and approximation formula",
       Applied Optics 28(22), 4735-4738, 1989, Eq. 3.

    Examples
    --------
    >>> print(relative_airmass([0.0, 60.0, 95.0]).round(4))
    [0.9997 1.9943    nan]
    """
    # pvlib's expression, operation for operation: the two agree to the bit
    # (tests/test_atmosphere.py), without importing pvlib (and the scipy it loads) for a formula.
    zenith = np.asarray(solar_zenith, dtype=float)
    zenith = np.where(zenith > 90, np.nan, zenith)
    return 1.0 / (np.cos(np.radians(zenith)) + 0.50572 * ((6.07995 + (90 - zenith)) ** -1.6364))


def beam_meinel(airmass, altitude=0.0):
    """Direct normal irradiance of the Meinel & Meinel clear sky [1]_, with Laue's altitude term [2]_.

    ``I_D = 1353 * ((1 - a h) * 0.7 ** (AM ** 0.678) + a h)`` W/m^2, a = 0.14 /km, h [km]; at
    h = 0 this is Shin et al. Eq. 2, whose OCR text reads the exponent 0.678 as "0.076".

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

    References
    ----------
    .. [1] A. B. Meinel, M. P. Meinel, "Applied Solar Energy: An Introduction", Addison-Wesley,
       1976, as given by PVCDROM / PVEducation, "Air Mass".
    .. [2] E. G. Laue, "The measurement of solar spectral irradiance at different terrestrial
       elevations", Solar Energy 13, 43-57, 1970, via PVEducation ("Air Mass").

    Examples
    --------
    >>> print(beam_meinel([1.0, 1.5, np.nan]).round(1))
    [947.1 846.    0. ]
    """
    airmass = np.asarray(airmass, dtype=float)
    altitude_term = LAUE_ALTITUDE_COEFFICIENT * altitude / 1000.0
    transmitted = (1.0 - altitude_term) * 0.7 ** (airmass**0.678) + altitude_term
    return np.where(np.isfinite(airmass), SOLAR_CONSTANT_MEINEL * transmitted, 0.0)


def hottel_transmittance(solar_zenith, altitude=0.0, climate="midlatitude-summer"):
    """Clear-sky beam transmittance of Hottel (1976) [1]_, 23 km visibility standard atmosphere.

    ``tau_b = a0 + a1 exp(-k / cos(zenith))`` with ``a0* = 0.4237 - 0.00821 (6 - A)^2``,
    ``a1* = 0.5055 + 0.00595 (6.5 - A)^2``, ``k* = 0.2711 + 0.01858 (2.5 - A)^2`` (A: altitude in
    km, below 2.5 km) times the climate corrections of :data:`HOTTEL_CLIMATES`.

    Parameters
    ----------
    solar_zenith : array_like
        Solar zenith [deg].
    altitude : float, default 0
        Site altitude [m], at most 2500.
    climate : str, default 'midlatitude-summer'
        One of :data:`HOTTEL_CLIMATES`.

    Returns
    -------
    numpy.ndarray
        Transmittance [-]; 0 with the sun below the horizon.

    Raises
    ------
    ValueError
        If ``climate`` is not one of :data:`HOTTEL_CLIMATES`.

    References
    ----------
    .. [1] H. C. Hottel, "A simple model for estimating the transmittance of direct solar radiation
       through clear atmospheres", Solar Energy 18, 129-134, 1976; as given by J. A. Duffie,
       W. A. Beckman, "Solar Engineering of Thermal Processes", Sec. 2.8, Eq. 2.8.1, 2.8.2 and
       Table 2.8.1 (Robles Algarin et al. Eq. 4-7, OCR-damaged, see the module docstring).

    Examples
    --------
    >>> print(hottel_transmittance([0.0, 60.0, 100.0]).round(4))
    [0.6291 0.4644 0.    ]
    """
    if climate not in HOTTEL_CLIMATES:
        raise ValueError(f"climate must be one of {', '.join(HOTTEL_CLIMATES)}; got {climate!r}")
    r0, r1, rk = HOTTEL_CLIMATES[climate]
    km = altitude / 1000.0
    a0 = r0 * (0.4237 - 0.00821 * (6.0 - km) ** 2)
    a1 = r1 * (0.5055 + 0.00595 * (6.5 - km) ** 2)
    k = rk * (0.2711 + 0.01858 * (2.5 - km) ** 2)
    cos_zenith = np.cos(np.radians(np.asarray(solar_zenith, dtype=float)))
    with np.errstate(divide="ignore", over="ignore"):
        tau = a0 + a1 * np.exp(-k / cos_zenith)
    return np.where(cos_zenith > 0, tau, 0.0)


def extraterrestrial_spencer(dayofyear, solar_constant: float = SOLAR_CONSTANT_PVLIB):
    """Extraterrestrial normal irradiance by Spencer's series for the Earth-Sun distance [5]_, as
    pvlib's ``irradiance.get_extra_radiation`` (its default ``spencer``) writes it, operation for
    operation: the two agree to the bit (tests/test_atmosphere.py).

    Parameters
    ----------
    dayofyear : array_like
        Day of year, 1 on January 1 [-].
    solar_constant : float, default :data:`SOLAR_CONSTANT_PVLIB`
        [W/m^2].

    Returns
    -------
    numpy.ndarray
        Irradiance on a surface normal to the sun above the atmosphere [W/m^2].

    Examples
    --------
    >>> extraterrestrial_spencer([1, 182]).round(1).tolist()
    [1414.0, 1320.5]
    """
    day_angle = (2.0 * np.pi / 365.0) * (np.asarray(dayofyear) - 1)
    distance = (
        1.00011
        + 0.034221 * np.cos(day_angle)
        + 0.00128 * np.sin(day_angle)
        + 0.000719 * np.cos(2 * day_angle)
        + 7.7e-05 * np.sin(2 * day_angle)
    )
    return np.asarray(solar_constant * distance, dtype=float)


def extraterrestrial_normal(dayofyear):
    """Extraterrestrial normal irradiance, Duffie & Beckman Eq. 1.4.1a [1]_ (pvlib ``asce``).

    Parameters
    ----------
    dayofyear : array_like
        Day of year, 1 on January 1 [-].

    Returns
    -------
    numpy.ndarray
        Irradiance on a surface normal to the sun above the atmosphere [W/m^2], with the
        solar constant :data:`SOLAR_CONSTANT_HOTTEL`.

    References
    ----------
    .. [1] J. A. Duffie, W. A. Beckman, "Solar Engineering of Thermal Processes", 4th ed., Wiley,
       2013, Eq. 1.4.1a.
    """
    import pvlib

    return np.asarray(
        pvlib.irradiance.get_extra_radiation(
            np.asarray(dayofyear), solar_constant=SOLAR_CONSTANT_HOTTEL, method="asce"
        ),
        dtype=float,
    )


def clear_sky_dni(
    solar_zenith, altitude=0.0, model="meinel", dayofyear=None, climate="midlatitude-summer"
):
    """Clear-sky direct normal irradiance by one of :data:`SKY_MODELS`.

    Parameters
    ----------
    solar_zenith : array_like
        Solar zenith [deg].
    altitude : float, default 0
        Site altitude [m].
    model : {'meinel', 'hottel'}
        Sky model: :func:`beam_meinel` of :func:`relative_airmass`, or :func:`hottel_transmittance`
        times :func:`extraterrestrial_normal`.
    dayofyear : array_like, optional
        Day of year, broadcast against ``solar_zenith``; needed by ``hottel``.
    climate : str, default 'midlatitude-summer'
        ``hottel``'s climate, one of :data:`HOTTEL_CLIMATES`.

    Returns
    -------
    numpy.ndarray
        Direct normal irradiance [W/m^2], zero with the sun below the horizon.

    Raises
    ------
    ValueError
        If ``model`` or ``climate`` is unknown.
    """
    if model == "meinel":
        zenith = np.asarray(solar_zenith, dtype=float)
        shape = np.broadcast_shapes(zenith.shape, np.shape(altitude))
        zenith = np.broadcast_to(zenith, shape)
        # The air mass and the beam at the steps with the sun up alone (the others have neither):
        # the same values, at half the cost over whole days.
        up = zenith <= 90.0
        dni = np.zeros(shape)
        dni[up] = beam_meinel(relative_airmass(zenith[up]), np.broadcast_to(altitude, shape)[up])
        return dni
    if model == "hottel":
        return extraterrestrial_normal(dayofyear) * hottel_transmittance(
            solar_zenith, altitude, climate
        )
    raise ValueError(f"sky must be one of {', '.join(SKY_MODELS)}; got {model!r}")
