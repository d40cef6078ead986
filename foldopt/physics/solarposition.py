"""Solar position over whole days, in the paper's approximation or exactly through pvlib.

The paper mode follows Shin et al. [1]_ Eq. 3-4 and 6, whose formulas are those of the
PVCDROM / PVEducation course [2]_. The OCR text of [1]_ is damaged; the repaired forms used
here, each checked against [2]_ and against pvlib's implementations of the same textbook
formulas (``equation_of_time_pvcdrom``, ``declination_cooper69``, ``solar_zenith_analytical``,
``solar_azimuth_analytical``), are:

- declination ``delta = asin(sin(23.45 deg) * sin(360/365 * (d - 81)))`` (OCR: "360 - 365");
- hour angle ``HRA = 15 deg * (LST - 12)`` (OCR drops the "- 12");
- elevation ``asin(sin(delta) sin(phi) + cos(delta) cos(phi) cos(HRA))``;
- azimuth ``acos((sin(delta) cos(phi) - cos(delta) sin(phi) cos(HRA)) / cos(elevation))``,
  mirrored to ``360 - azimuth`` after solar noon (OCR has theta_z where phi stands).

Clock time is converted to local solar time LST with the longitude correction and the
equation of time of [2]_: ``LST = LT + (4 (longitude - LSTM) + EoT) / 60``.

The exact mode is NREL's SPA [3]_ through ``pvlib.spa``. Many days and sites are evaluated as one
array program (:class:`ClockGrid`, :func:`solar_position_grid`): SPA's geocentric part, which
depends on time only, runs once per UTC hour that any day touches and is interpolated, as SPA
itself interpolates it for sunrise and sunset [3]_ (Appendix A.2); the topocentric part runs per
site.

References
----------
.. [1] D. Shin, N. Chang, Y. Wang, M. Pedram, "Reconfigurable three dimensional photovoltaic
   panel architecture for solar-powered time extension", Eq. 3, 4, 6.
.. [2] C. Honsberg, S. Bowden, "Photovoltaics Education Website" (PVCDROM), pages "Solar Time"
   and "Elevation Angle", "Azimuth Angle", "Declination Angle".
.. [3] I. Reda, A. Andreas, "Solar position algorithm for solar radiation applications",
   Solar Energy 76(5), 577-589, 2004 (NREL/TP-560-34302), Sec. 3 and Appendix A.2.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass

import numpy as np
import pandas as pd
import pvlib

from foldopt.names import MODES

_NS_PER_HOUR = 3_600_000_000_000
_NS_PER_DAY = 24 * _NS_PER_HOUR


def day_times(date: dt.date, timezone, step_min: float = 1.0) -> pd.DatetimeIndex:
    """Interval-centred time steps covering one local clock day.

    Parameters
    ----------
    date : datetime.date
        The local calendar day.
    timezone : str or datetime.tzinfo
        Time zone of the clock (IANA name or fixed offset).
    step_min : float, default 1
        Step length [min]; must divide the 24 h day.

    Returns
    -------
    pandas.DatetimeIndex
        Tz-aware times at the centre of each step, ``00:00 + step/2`` to ``24:00 - step/2``.
    """
    return clock_grid([date], timezone, step_min).times(0)


@dataclass(frozen=True)
class ClockGrid:
    """Time steps of whole local days, one row per day ("block"), all rows of equal length.

    A block is one day at one site; blocks of several sites (and time zones) can be stacked, so
    that a whole study is one array program.

    Attributes
    ----------
    utc_ns : numpy.ndarray of int64, (n_blocks, n_steps)
        UTC epoch of each step [ns].
    utc_offset_ns : numpy.ndarray of int64, (n_blocks, n_steps)
        Local clock minus UTC [ns] (DST included).
    timezones : tuple
        Each block's time zone (for :meth:`times`).
    step_hours : float
        Step length [h].
    """

    utc_ns: np.ndarray
    utc_offset_ns: np.ndarray
    timezones: tuple
    step_hours: float

    @property
    def shape(self) -> tuple[int, int]:
        return self.utc_ns.shape

    @property
    def local_ns(self) -> np.ndarray:
        return self.utc_ns + self.utc_offset_ns

    @property
    def clock_hours(self) -> np.ndarray:
        """Local clock time of each step [h since local midnight]."""
        return (self.local_ns % _NS_PER_DAY) / _NS_PER_HOUR

    @property
    def utc_offset_hours(self) -> np.ndarray:
        return self.utc_offset_ns / _NS_PER_HOUR

    @property
    def day_of_year(self) -> np.ndarray:
        """Local day of year of each step (1 on 1 January)."""
        days = np.floor_divide(self.local_ns, _NS_PER_DAY)
        # Converted once per calendar day in the grid's range, then looked up.
        first = days.min()
        calendar = np.arange(first, days.max() + 1).astype("datetime64[D]")
        table = (calendar - calendar.astype("datetime64[Y]")).astype(np.int64) + 1
        return table[days - first]

    def times(self, block: int) -> pd.DatetimeIndex:
        """The tz-aware times of one block."""
        utc = pd.DatetimeIndex(self.utc_ns[block].astype("datetime64[ns]"), tz="UTC")
        return utc.tz_convert(self.timezones[block])

    @classmethod
    def stack(cls, grids) -> ClockGrid:
        """Blocks of several grids of equal step, one after the other."""
        grids = list(grids)
        if len({g.shape[1] for g in grids}) != 1 or len({g.step_hours for g in grids}) != 1:
            raise ValueError("stacked grids need the same steps per day")
        return cls(np.concatenate([g.utc_ns for g in grids]), np.concatenate([g.utc_offset_ns for g in grids]),
                   sum((g.timezones for g in grids), ()), grids[0].step_hours)

    @classmethod
    def from_times(cls, days, timezone) -> ClockGrid:
        """A grid from tz-aware time indexes, one per block, of equal length and step."""
        utc = np.stack([np.asarray(pd.DatetimeIndex(t).tz_convert("UTC").tz_localize(None).as_unit("ns").asi8)
                        for t in days])
        local = np.stack([np.asarray(pd.DatetimeIndex(t).tz_localize(None).as_unit("ns").asi8) for t in days])
        step = float(np.median(np.diff(utc, axis=1))) / _NS_PER_HOUR if utc.shape[1] > 1 else 24.0
        return cls(utc, local - utc, (timezone,) * len(days), step)


def clock_grid(dates, timezone, step_min: float = 1.0) -> ClockGrid:
    """Interval-centred steps covering local clock days, all at once.

    Parameters
    ----------
    dates : sequence of datetime.date
    timezone : str or datetime.tzinfo
    step_min : float, default 1
        Step length [min]; must divide the 24 h day.
    """
    n_steps = 24 * 60 / step_min
    if not np.isclose(n_steps, round(n_steps)):
        raise ValueError(f"step_min must divide 1440 min exactly, got {step_min}")
    offsets = np.round((np.arange(round(n_steps)) + 0.5) * step_min * 60e9).astype(np.int64)
    midnights = np.array([np.datetime64(date, "ns") for date in dates]).astype(np.int64)
    naive = midnights[:, None] + offsets[None, :]
    if isinstance(timezone, dt.tzinfo) and not hasattr(timezone, "key"):
        # A fixed offset: no DST, so no localisation is needed.
        utc = naive - int(timezone.utcoffset(None).total_seconds() * 1e9)
    else:
        # One localisation for the whole grid; a DST jump makes some clock times ambiguous or
        # absent: shift, never drop.
        flat = pd.DatetimeIndex(naive.ravel().astype("datetime64[ns]")).tz_localize(
            timezone, ambiguous=np.ones(naive.size, dtype=bool), nonexistent="shift_forward"
        )
        utc = flat.tz_convert("UTC").tz_localize(None).as_unit("ns").asi8.reshape(naive.shape)
        naive = flat.tz_localize(None).as_unit("ns").asi8.reshape(naive.shape)
    return ClockGrid(utc, naive - utc, (timezone,) * len(dates), step_min / 60.0)


def declination_paper(dayofyear):
    """Solar declination by the sine-of-sines form of PVCDROM [2]_ (Shin et al. Eq. 4).

    Parameters
    ----------
    dayofyear : array_like
        Day of year, 1 on January 1 [-].

    Returns
    -------
    numpy.ndarray
        Declination [deg].
    """
    day_angle = np.radians(360.0 / 365.0 * (np.asarray(dayofyear, dtype=float) - 81.0))
    return np.degrees(np.arcsin(np.sin(np.radians(23.45)) * np.sin(day_angle)))


def equation_of_time_paper(dayofyear):
    """Equation of time of PVCDROM [2]_: 9.87 sin 2B - 7.53 cos B - 1.5 sin B [min]."""
    day_angle = np.radians(360.0 / 365.0 * (np.asarray(dayofyear, dtype=float) - 81.0))
    return 9.87 * np.sin(2 * day_angle) - 7.53 * np.cos(day_angle) - 1.5 * np.sin(day_angle)


def hour_angle_paper(times: pd.DatetimeIndex, longitude: float):
    """Hour angle from clock time via local solar time, PVCDROM [2]_ ("Solar Time").

    Parameters
    ----------
    times : pandas.DatetimeIndex
        Tz-aware clock times; the UTC offset in force (DST included) sets the local
        standard time meridian ``LSTM = 15 deg * offset``.
    longitude : float
        Site longitude [deg east].

    Returns
    -------
    numpy.ndarray
        Hour angle [deg] in [-180, 180), negative before solar noon.
    """
    grid = ClockGrid.from_times([times], times.tz)
    return _hour_angle_paper(grid.clock_hours, grid.utc_offset_hours, grid.day_of_year, longitude)[0]


def _by_day_of_year(function, dayofyear):
    """``function`` of the day of year at every step, evaluated once per day (1..366) and looked up."""
    return function(np.arange(367))[dayofyear]


def _hour_angle_paper(clock_hours, utc_offset_hours, dayofyear, longitude):
    equation_of_time = _by_day_of_year(equation_of_time_paper, dayofyear)
    time_correction_min = 4.0 * (longitude - 15.0 * utc_offset_hours) + equation_of_time
    local_solar_time = clock_hours + time_correction_min / 60.0
    return (15.0 * (local_solar_time - 12.0) + 180.0) % 360.0 - 180.0


def sun_from_angles(declination, hour_angle, latitude):
    """Solar zenith and azimuth from declination, hour angle and latitude.

    Shin et al. Eq. 3 and Eq. 6 as repaired (see module docstring), PVCDROM [2]_.

    Parameters
    ----------
    declination, hour_angle : array_like
        [deg]; hour angle negative in the morning.
    latitude : float
        [deg north].

    Returns
    -------
    solar_zenith, solar_azimuth : numpy.ndarray
        [deg]; azimuth clockwise from north.
    """
    dec, hra, lat = np.radians(declination), np.radians(hour_angle), np.radians(latitude)
    # Components of the sun vector: east, north (the numerator of Eq. 6) and up (Eq. 3).
    # atan2(east, north) is Eq. 6's acos(north / cos(elevation)), mirrored after noon, evaluated
    # without acos's loss of precision near due north or south.
    east = -np.cos(dec) * np.sin(hra)
    north = np.sin(dec) * np.cos(lat) - np.cos(dec) * np.sin(lat) * np.cos(hra)
    up = np.sin(dec) * np.sin(lat) + np.cos(dec) * np.cos(lat) * np.cos(hra)
    elevation = np.arcsin(np.clip(up, -1.0, 1.0))
    azimuth = np.degrees(np.arctan2(east, north)) % 360.0
    return 90.0 - np.degrees(elevation), azimuth


SPA_SPACING_MIN = 10.0  # [min] between topocentric SPA evaluations on finely stepped series
SPA_DELTA_T = 67.0  # [s], TT - UT1, pvlib's default for spa_python
SPA_TEMPERATURE = 12.0  # [C], pvlib's default for the refraction correction
SPA_ATMOS_REFRACT = 0.5667  # [deg], SPA's refraction at sunrise and sunset


def spa_geocentric(unixtime, delta_t: float = SPA_DELTA_T) -> dict:
    """The time-only part of SPA [3]_ (Sec. 3.1-3.9 and the equation of time) via ``pvlib.spa``.

    Returns the geocentric right ascension ``alpha`` and declination ``delta`` [deg], the apparent
    sidereal time ``v`` [deg], the equatorial horizontal parallax ``xi`` [deg] and the equation of
    time ``eot`` [min], the steps of ``pvlib.spa.solar_position_numpy`` before its site enters.
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


def _geocentric_hourly(utc_ns: np.ndarray) -> dict:
    """:func:`spa_geocentric` at ``utc_ns`` (any shape), interpolated linearly between whole UTC
    hours, each hour evaluated once however many sites and days share it.

    Over an hour the geocentric terms are smooth to within 1e-5 deg of linear (tested)."""
    hours = np.floor_divide(utc_ns, _NS_PER_HOUR)
    nodes = np.unique(np.concatenate([hours.ravel(), hours.ravel() + 1]))
    at_nodes = spa_geocentric(nodes * 3600.0)
    index = np.searchsorted(nodes, hours)
    weight = (utc_ns - hours * _NS_PER_HOUR) / _NS_PER_HOUR
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


def _spa_grid(grid: ClockGrid, latitude, longitude, altitude):
    """Apparent zenith, azimuth [deg] and equation of time [min] by SPA at every step of ``grid``.

    On a grid stepped finer than :data:`SPA_SPACING_MIN`, the topocentric position is evaluated every
    10 minutes only (and on each day's last step); the geometric sun vector and the equation of time,
    which are smooth, are interpolated linearly between, and SPA's own refraction correction (with
    pvlib's default pressure for the altitude and 12 C) is applied to every step, so that the
    correction's kink at the horizon stays exact. Measured at 1-minute steps against pvlib's full
    SPA: the sun's direction within 0.005 deg, the equation of time within 1e-6 min
    (tests/test_solarposition.py).
    """
    n_steps = grid.shape[1]
    stride = int(SPA_SPACING_MIN // (grid.step_hours * 60.0))
    if stride < 2 or n_steps < 4 * stride:
        picked = np.arange(n_steps)
    else:
        picked = np.unique(np.r_[np.arange(0, n_steps, stride), n_steps - 1])
    geo = _geocentric_hourly(grid.utc_ns[:, picked])
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


def solar_position_grid(grid: ClockGrid, latitude, longitude, altitude=0.0, model: str = "exact") -> dict:
    """Solar position at every step of a grid of days.

    Parameters
    ----------
    grid : ClockGrid
    latitude, longitude : float or array_like
        [deg north], [deg east]; one value, or one per block, shape (n_blocks, 1).
    altitude : float or array_like, default 0
        [m]; used by ``exact`` only.
    model : {'exact', 'paper'}
        ``paper``: Shin et al. Eq. 3, 4, 6 (repaired), geometric, no refraction.
        ``exact``: NREL SPA; the *apparent* (refracted) zenith is returned, as pvlib's
        ModelChain uses it for air mass and incidence.

    Returns
    -------
    dict of numpy.ndarray
        ``solar_zenith``, ``solar_azimuth`` and the equatorial coordinates ``hour_angle`` and
        ``declination`` that trackers steer by [deg], each (n_blocks, n_steps). In exact mode the
        hour angle is pvlib's formula ``15 (UTC hours - 12) + longitude + EoT / 4`` with SPA's
        equation of time, worked out from UTC (so DST days need no care), and the declination
        pvlib's ``declination_spencer71``.
    """
    doy = grid.day_of_year
    if model == "paper":
        declination = _by_day_of_year(declination_paper, doy)
        hour_angle = _hour_angle_paper(grid.clock_hours, grid.utc_offset_hours, doy, longitude)
        zenith, azimuth = sun_from_angles(declination, hour_angle, latitude)
    elif model == "exact":
        zenith, azimuth, equation_of_time = _spa_grid(grid, latitude, longitude, altitude)
        utc_hours = (grid.utc_ns % _NS_PER_DAY) / _NS_PER_HOUR
        hour_angle = (15.0 * (utc_hours - 12.0) + longitude + equation_of_time / 4.0 + 180.0) % 360.0 - 180.0
        declination = _by_day_of_year(lambda d: np.degrees(pvlib.solarposition.declination_spencer71(d)), doy)
    else:
        raise ValueError(f"model must be one of {', '.join(MODES)}; got {model!r}")
    return {"solar_zenith": zenith, "solar_azimuth": azimuth, "hour_angle": hour_angle,
            "declination": np.broadcast_to(declination, np.shape(zenith))}


def get_solar_position(
    times: pd.DatetimeIndex,
    latitude: float,
    longitude: float,
    altitude: float = 0.0,
    model: str = "exact",
) -> pd.DataFrame:
    """Solar zenith and azimuth at ``times`` (:func:`solar_position_grid` for one series of times).

    Parameters
    ----------
    times : pandas.DatetimeIndex
        Tz-aware, equally spaced times.
    latitude, longitude : float
        [deg north], [deg east].
    altitude : float, default 0
        Site altitude [m]; used by ``exact`` only.
    model : {'exact', 'paper'}

    Returns
    -------
    pandas.DataFrame
        Columns ``solar_zenith``, ``solar_azimuth``, ``hour_angle`` and ``declination`` [deg],
        indexed by ``times``.
    """
    sun = solar_position_grid(ClockGrid.from_times([times], times.tz), latitude, longitude, altitude, model)
    return pd.DataFrame({name: values[0] for name, values in sun.items()}, index=times)
