"""NREL's solar position algorithm, split into a part shared by every site and a per-site part.

This module runs NREL's SPA [1]_ through the step functions of ``pvlib.spa``, split in two so that
many days and sites are one array program (:func:`foldopt.physics.solarposition.solar_position_grid`):
the geocentric part, which depends on time only, runs once per UTC hour that any day touches and
is interpolated, as SPA itself interpolates it for sunrise and sunset [1]_ (Appendix A.2); the
topocentric part runs per site every 10 minutes, the sun vector is interpolated between, and the
refraction is applied at every step: the sun's direction stays within 0.005 deg of
``pvlib.solarposition.spa_python`` (except at SPA's refraction cut-off, 0.83 deg below the horizon).

Why not ``pvlib.solarposition.get_solarposition``: ``bench/solarposition.py`` (2-core x86_64,
pvlib 0.16.1) times a year of steps per site, in seconds, ``*`` scaled per site from a measured run:

=====  ======  ========  =================  ==============================
step   sites   split     get_solarposition  get_solarposition every 10 min
                                            and foldopt's interpolation
=====  ======  ========  =================  ==============================
1 min  1       0.18      4.3                0.39
1 min  100     19.5      432 *              38.7 *
1 min  10 000  1 771 *   43 247 *           3 872 *
5 min  2 000   106 *     1 577 *            521 *
=====  ======  ========  =================  ==============================

(``spa_python(how='numba')`` on 2 threads: 1.8 s a site-year at 1 min.) The public call would
make the sun 11-24 times dearer; at the map's 5-minute steps it would add 0.74 s to a site's whole
0.26 s (``results/bench/map.md``). With the same subsampling it stays 2-5 times dearer. The
price of the split is a dependence on ``pvlib.spa``'s step functions, which are not pvlib's
public API: pyproject.toml pins pvlib to the releases in which they are unchanged (0.11 to 0.16,
by pvlib's source history; tested with 0.16.1), and tests/test_solarposition.py holds the split
to ``spa_python`` on random sites. A process that has called ``spa_python(how='numba')`` has
``pvlib.spa`` reloaded as scalar numba functions, and the split then raises ``TypeError``.

References
----------
.. [1] I. Reda, A. Andreas, "Solar position algorithm for solar radiation applications",
   Solar Energy 76(5), 577-589, 2004 (NREL/TP-560-34302), Sec. 3 and Appendix A.
"""

from __future__ import annotations

import numpy as np
import pvlib

NS_PER_HOUR = 3_600_000_000_000  # [ns]
SPA_SPACING_MIN = 10.0  # [min] between topocentric SPA evaluations on finely stepped series
SPA_DELTA_T = 67.0  # [s], TT - UT1, pvlib's default for spa_python
SPA_TEMPERATURE = 12.0  # [C], pvlib's default for the refraction correction
SPA_ATMOS_REFRACT = 0.5667  # [deg], SPA's refraction at sunrise and sunset


def spa_geocentric(unixtime, delta_t: float = SPA_DELTA_T) -> dict:
    """The time-only part of SPA [1]_ (Sec. 3.1-3.9, 3.12.1 and A.1) via ``pvlib.spa``.

    The steps of ``pvlib.spa.solar_position_numpy`` before its site enters.

    Parameters
    ----------
    unixtime : array_like
        UTC instants [s since 1970-01-01].
    delta_t : float, default :data:`SPA_DELTA_T`
        TT - UT1 [s].

    Returns
    -------
    dict of numpy.ndarray
        The geocentric right ascension ``alpha`` and declination ``delta`` [deg], the apparent
        sidereal time ``v`` [deg], the equatorial horizontal parallax ``xi`` [deg] and the equation
        of time ``eot`` [min].

    References
    ----------
    .. [1] I. Reda, A. Andreas, "Solar position algorithm for solar radiation applications",
       Solar Energy 76(5), 577-589, 2004.
    """
    spa = pvlib.spa
    unixtime = np.asarray(unixtime, dtype=float)
    jd = spa.julian_day(unixtime)
    jde = spa.julian_ephemeris_day(jd, delta_t)
    jc = spa.julian_century(jd)
    jce = spa.julian_ephemeris_century(jde)
    jme = spa.julian_ephemeris_millennium(jce)
    radius = spa.heliocentric_radius_vector(jme)
    theta = spa.geocentric_longitude(spa.heliocentric_longitude(jme))
    beta = spa.geocentric_latitude(spa.heliocentric_latitude(jme))
    args = (spa.mean_elongation(jce), spa.mean_anomaly_sun(jce), spa.mean_anomaly_moon(jce),
            spa.moon_argument_latitude(jce), spa.moon_ascending_longitude(jce))
    nutation = np.empty((2, unixtime.size))
    spa.longitude_obliquity_nutation(jce, *args, nutation)
    delta_psi, delta_epsilon = nutation
    epsilon = spa.true_ecliptic_obliquity(spa.mean_ecliptic_obliquity(jme), delta_epsilon)
    lamd = spa.apparent_sun_longitude(theta, delta_psi, spa.aberration_correction(radius))
    v = spa.apparent_sidereal_time(spa.mean_sidereal_time(jd, jc), delta_psi, epsilon)
    alpha = spa.geocentric_sun_right_ascension(lamd, epsilon, beta)
    delta = spa.geocentric_sun_declination(lamd, epsilon, beta)
    eot = spa.equation_of_time(spa.sun_mean_longitude(jme), alpha, delta_psi, epsilon)
    return {"alpha": alpha, "delta": delta, "v": v, "xi": spa.equatorial_horizontal_parallax(radius), "eot": eot}


_WRAPPED = ("alpha", "v")  # angles that wrap at 360 deg


#: The time-only terms at whole UTC hours this process has evaluated: (hours, terms), replaced
#: whole (one assignment, so a thread reads one state or the other). A map's sites of one year
#: share every hour; :data:`HOURS_KEPT` bounds it (about 80 MB).
_AT_HOURS: tuple = (np.zeros(0, dtype=np.int64), {})
HOURS_KEPT = 2_000_000


def _geocentric_at_hours(nodes: np.ndarray) -> dict:
    """:func:`spa_geocentric` at whole UTC hours (sorted, unique), each hour evaluated once per
    process. The terms are elementwise in time, so an hour's are the same bits whichever call
    first asked for it (tested)."""
    global _AT_HOURS
    hours, terms = _AT_HOURS
    missing = nodes[~np.isin(nodes, hours)]
    if missing.size:
        found = spa_geocentric(missing * 3600.0)
        if hours.size + missing.size > HOURS_KEPT:
            hours, terms = missing[:0], {name: values[:0] for name, values in found.items()}
        order = np.argsort(np.concatenate([hours, missing]), kind="stable")
        hours = np.concatenate([hours, missing])[order]
        terms = {name: np.concatenate([terms.get(name, values[:0]), values])[order] for name, values in found.items()}
        _AT_HOURS = (hours, terms)
    index = np.searchsorted(hours, nodes)
    return {name: values[index] for name, values in terms.items()}


def _geocentric_hourly(utc_ns: np.ndarray) -> dict:
    """:func:`spa_geocentric` at ``utc_ns`` (any shape), interpolated linearly between whole UTC
    hours, each hour evaluated once however many sites and days share it
    (:func:`_geocentric_at_hours`).

    Over an hour the geocentric terms are smooth to within 1e-5 deg of linear (tested)."""
    hours = np.floor_divide(utc_ns, NS_PER_HOUR)
    nodes = np.unique(np.concatenate([hours.ravel(), hours.ravel() + 1]))
    at_nodes = _geocentric_at_hours(nodes)
    index = np.searchsorted(nodes, hours)
    weight = (utc_ns - hours * NS_PER_HOUR) / NS_PER_HOUR
    out = {}
    for name, values in at_nodes.items():
        start, end = values[index], values[index + 1]
        change = end - start
        if name in _WRAPPED:
            change = (change + 180.0) % 360.0 - 180.0
        out[name] = start + weight * change
    return out


def _spa_topocentric(geo: dict, latitude, longitude, altitude):
    """Geometric (refraction-free) zenith and azimuth [deg] from geocentric terms, SPA Sec. 3.10-3.14
    via ``pvlib.spa``; site arguments broadcast against the terms."""
    spa = pvlib.spa
    hour_angle = spa.local_hour_angle(geo["v"], longitude, geo["alpha"])
    u = spa.uterm(latitude)
    x, y = spa.xterm(u, latitude, altitude), spa.yterm(u, latitude, altitude)
    delta_alpha = spa.parallax_sun_right_ascension(x, geo["xi"], hour_angle, geo["delta"])
    delta_prime = spa.topocentric_sun_declination(geo["delta"], x, y, geo["xi"], delta_alpha, hour_angle)
    hour_angle_prime = spa.topocentric_local_hour_angle(hour_angle, delta_alpha)
    elevation = spa.topocentric_elevation_angle_without_atmosphere(latitude, delta_prime, hour_angle_prime)
    gamma = spa.topocentric_astronomers_azimuth(hour_angle_prime, delta_prime, latitude)
    azimuth = spa.topocentric_azimuth_angle(gamma)
    return 90.0 - elevation, azimuth


def spa_solar_position(utc_ns, step_hours: float, latitude, longitude, altitude):
    """Apparent zenith, azimuth and equation of time by SPA [1]_ at every step of days of steps.

    On days stepped finer than :data:`SPA_SPACING_MIN`, the topocentric position is evaluated every
    10 minutes only (and on each day's last step); the geometric sun vector and the equation of time,
    which are smooth, are interpolated linearly between, and SPA's own refraction correction [1]_
    (Eq. 42, with pvlib's default pressure for the altitude and 12 C) is applied to every step, so
    that the correction's kink at the horizon stays exact. Measured at 1-minute steps against
    pvlib's full SPA: the sun's direction within 0.005 deg, the equation of time within 1e-6 min
    (tests/test_solarposition.py).

    Parameters
    ----------
    utc_ns : numpy.ndarray of int64
        (n_blocks, n_steps) UTC instants [ns since 1970-01-01], equally stepped along each row
        (:attr:`foldopt.physics.solarposition.ClockGrid.utc_ns`).
    step_hours : float
        Step length [h].
    latitude, longitude : float or array_like
        [deg north], [deg east]; one value, or one per block, shape (n_blocks, 1).
    altitude : float or array_like
        [m], as ``latitude``.

    Returns
    -------
    apparent_zenith, azimuth : numpy.ndarray
        [deg], azimuth clockwise from north, (n_blocks, n_steps).
    equation_of_time : numpy.ndarray
        [min], (n_blocks, n_steps).

    References
    ----------
    .. [1] I. Reda, A. Andreas, "Solar position algorithm for solar radiation applications",
       Solar Energy 76(5), 577-589, 2004, Sec. 3.10-3.14 and A.1.
    """
    n_steps = np.shape(utc_ns)[1]
    stride = int(SPA_SPACING_MIN // (step_hours * 60.0))
    if stride < 2 or n_steps < 4 * stride:
        picked = np.arange(n_steps)
    else:
        picked = np.unique(np.r_[np.arange(0, n_steps, stride), n_steps - 1])
    geo = _geocentric_hourly(np.asarray(utc_ns)[:, picked])
    zenith0, azimuth = (np.radians(a) for a in _spa_topocentric(geo, latitude, longitude, altitude))
    vector = np.stack([np.sin(zenith0) * np.sin(azimuth), np.sin(zenith0) * np.cos(azimuth), np.cos(zenith0)], -1)
    eot = geo["eot"]
    if picked.size < n_steps:
        # Every day has the same pattern of picks, so one set of weights serves all of them.
        position = np.arange(n_steps)
        right = np.clip(np.searchsorted(picked, position, side="right"), 1, picked.size - 1)
        weight = ((position - picked[right - 1]) / (picked[right] - picked[right - 1]))[None, :]
        vector = vector[:, right - 1] * (1.0 - weight[..., None]) + vector[:, right] * weight[..., None]
        eot = eot[:, right - 1] * (1.0 - weight) + eot[:, right] * weight
    east, north, up = np.moveaxis(vector, -1, 0)
    elevation0 = np.degrees(np.arctan2(up, np.hypot(east, north)))
    pressure = pvlib.atmosphere.alt2pres(np.asarray(altitude, dtype=float))
    refraction = pvlib.spa.atmospheric_refraction_correction(pressure / 100.0, SPA_TEMPERATURE, elevation0,
                                                             SPA_ATMOS_REFRACT)
    return 90.0 - (elevation0 + refraction), np.degrees(np.arctan2(east, north)) % 360.0, eot
