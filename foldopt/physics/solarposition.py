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

The exact mode is NREL's SPA [3]_ as pvlib implements it, split by :mod:`foldopt.physics.spa` into
a time-only part shared by every site and a per-site part, so that many days and sites are one
array program (:class:`ClockGrid`, :func:`solar_position_grid`); that module says what the split
buys over ``pvlib.solarposition.get_solarposition`` and what it costs.

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
import functools
import zoneinfo
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from foldopt.names import MODES
from foldopt.physics.geometry import normal_vector
from foldopt.physics.spa import NS_PER_HOUR, SunTerms, spa_solar_position

if TYPE_CHECKING:
    import pandas as pd

_NS_PER_DAY = 24 * NS_PER_HOUR


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
        """``(n_blocks, n_steps)``."""
        return self.utc_ns.shape

    @property
    def local_ns(self) -> np.ndarray:
        """Local clock time of each step [ns since 1970-01-01 00:00 local]."""
        return self.utc_ns + self.utc_offset_ns

    @property
    def clock_hours(self) -> np.ndarray:
        """Local clock time of each step [h since local midnight]."""
        return (self.local_ns % _NS_PER_DAY) / NS_PER_HOUR

    @property
    def utc_offset_hours(self) -> np.ndarray:
        """Local clock minus UTC [h]."""
        return self.utc_offset_ns / NS_PER_HOUR

    @functools.cached_property
    def dayofyear(self) -> np.ndarray:
        """Local day of year of each step (1 on 1 January); worked out once a grid (a sky reads it
        for the sun and again for the light)."""
        local = self.local_ns
        # A block's steps lie in one local day but where a clock's change moves some: its first
        # and last step's day, not every step's.
        low, high = (
            np.floor_divide(extreme(local, axis=-1, keepdims=True), _NS_PER_DAY)
            for extreme in (np.min, np.max)
        )
        one_day = np.array_equal(low, high)
        days = low if one_day else np.floor_divide(local, _NS_PER_DAY)
        # Converted once per calendar day in the grid's range, then looked up.
        first = days.min()
        calendar = np.arange(first, high.max() + 1).astype("datetime64[D]")
        table = (calendar - calendar.astype("datetime64[Y]")).astype(np.int64) + 1
        dayofyear = table[days - first]
        if one_day:
            dayofyear = np.repeat(dayofyear, local.shape[-1], axis=-1)
        dayofyear.flags.writeable = False  # shared by every reader of the grid
        return dayofyear

    def times(self, block: int) -> pd.DatetimeIndex:
        """The tz-aware times of one block.

        Parameters
        ----------
        block : int
            Row of the grid.

        Returns
        -------
        pandas.DatetimeIndex
            The block's steps in its own time zone.
        """
        import pandas as pd

        utc = pd.DatetimeIndex(self.utc_ns[block].astype("datetime64[ns]"), tz="UTC")
        return utc.tz_convert(self.timezones[block])

    @classmethod
    def stack(cls, grids) -> ClockGrid:
        """Blocks of several grids of equal step, one after the other.

        Parameters
        ----------
        grids : iterable of ClockGrid
            Of equal steps per day and step length.

        Returns
        -------
        ClockGrid

        Raises
        ------
        ValueError
            If the grids' steps differ.
        """
        grids = list(grids)
        if len({g.shape[1] for g in grids}) != 1 or len({g.step_hours for g in grids}) != 1:
            raise ValueError("stacked grids need the same steps per day")
        if len(grids) == 1:
            return grids[0]
        return cls(
            np.concatenate([g.utc_ns for g in grids]),
            np.concatenate([g.utc_offset_ns for g in grids]),
            sum((g.timezones for g in grids), ()),
            grids[0].step_hours,
        )

    @classmethod
    def from_times(cls, days, timezone) -> ClockGrid:
        """A grid from tz-aware time indexes, one per block, of equal length and step.

        Parameters
        ----------
        days : sequence of pandas.DatetimeIndex
            One index per block.
        timezone : str or datetime.tzinfo
            The blocks' time zone.

        Returns
        -------
        ClockGrid
        """
        import pandas as pd

        utc = np.stack(
            [
                np.asarray(
                    pd.DatetimeIndex(t).tz_convert("UTC").tz_localize(None).as_unit("ns").asi8
                )
                for t in days
            ]
        )
        local = np.stack(
            [np.asarray(pd.DatetimeIndex(t).tz_localize(None).as_unit("ns").asi8) for t in days]
        )
        step = float(np.median(np.diff(utc, axis=1))) / NS_PER_HOUR if utc.shape[1] > 1 else 24.0
        return cls(utc, local - utc, (timezone,) * len(days), step)


def clock_grid(dates, timezone, step_min: float = 1.0) -> ClockGrid:
    """Interval-centred steps covering local clock days, all at once.

    Parameters
    ----------
    dates : sequence of datetime.date
        Local calendar days, one block each.
    timezone : str or datetime.tzinfo
        Time zone of the clock (IANA name or fixed offset).
    step_min : float, default 1
        Step length [min]; must divide the 24 h day.

    Returns
    -------
    ClockGrid
        ``(len(dates), 1440 / step_min)``; clock times that a DST change skips are shifted
        forward and repeated ones taken once, so every day keeps its number of steps.

    Raises
    ------
    ValueError
        If ``step_min`` does not divide 1440 min.
    """
    n_steps = 24 * 60 / step_min
    if abs(n_steps - round(n_steps)) > 1e-8 + 1e-5 * abs(round(n_steps)):  # as np.isclose tests
        raise ValueError(f"step_min must divide 1440 min exactly, got {step_min}")
    offsets = np.round((np.arange(round(n_steps)) + 0.5) * step_min * 60e9).astype(np.int64)
    # Days since 1970-01-01 from each date's ordinal: NumPy converts date objects one at a time,
    # and slowly.
    days = np.fromiter((date.toordinal() for date in dates), np.int64, len(dates))
    midnights = (days - _EPOCH.toordinal()) * _NS_PER_DAY
    naive = midnights[:, None] + offsets[None, :]
    if isinstance(timezone, dt.tzinfo) and not hasattr(timezone, "key"):
        # A fixed offset: no DST, so no localisation is needed.
        utc = naive - int(timezone.utcoffset(None).total_seconds() * 1e9)
    elif isinstance(timezone, zoneinfo.ZoneInfo):
        utc, naive = _localised(naive, timezone)
    else:
        # A zone by name or of another library: pandas localises it, the whole grid at once; a
        # DST jump makes some clock times ambiguous or absent: shift, never drop. The absent ones
        # come back NaT and are shifted forward alone, their clock times with them: pandas
        # localises each time on its own (given an array for ``ambiguous``), so these are the
        # bits of shifting the whole grid, and a grid with no absent time (most) needs no
        # conversion back to clock times.
        import pandas as pd

        index = pd.DatetimeIndex(naive.ravel().astype("datetime64[ns]"))
        ambiguous = np.ones(naive.size, dtype=bool)
        flat = index.tz_localize(timezone, ambiguous=ambiguous, nonexistent="NaT")
        utc = flat.as_unit("ns").asi8.reshape(naive.shape)  # UTC, NaT where absent
        absent = np.flatnonzero(flat.isna())
        if absent.size:
            shifted = index[absent].tz_localize(
                timezone, ambiguous=ambiguous[absent], nonexistent="shift_forward"
            )
            utc, naive = utc.copy(), naive.copy()
            utc.ravel()[absent] = shifted.as_unit("ns").asi8
            naive.ravel()[absent] = shifted.tz_localize(None).as_unit("ns").asi8
    return ClockGrid(utc, naive - utc, (timezone,) * len(dates), step_min / 60.0)


_EPOCH = dt.datetime(1970, 1, 1)


def _offset_ns(offset: dt.timedelta) -> int:
    """A UTC offset [ns], exactly."""
    return (offset.days * 86_400 + offset.seconds) * 1_000_000_000 + offset.microseconds * 1000


def _wall(local_ns: int, fold: int = 0) -> dt.datetime:
    """A local clock time [ns since 1970-01-01 00:00 local] as a naive datetime (to the
    microsecond below: a zone's transitions fall on whole seconds)."""
    return (_EPOCH + dt.timedelta(microseconds=local_ns // 1000)).replace(fold=fold)


def _localised(naive: np.ndarray, zone: zoneinfo.ZoneInfo) -> tuple[np.ndarray, np.ndarray]:
    """Local clock times of whole days in an IANA zone localised as pandas' ``tz_localize`` with
    ``ambiguous=True`` and ``nonexistent="shift_forward"`` does it, with the standard library: a
    repeated clock time is taken at its first instant (before the clocks go back), a skipped one
    moved forward (:func:`_localised_step`).

    Parameters
    ----------
    naive : numpy.ndarray of int64, (n_days, n_steps)
        Local clock times [ns since 1970-01-01 00:00 local], each row within one local day.
    zone : zoneinfo.ZoneInfo

    Returns
    -------
    utc, local : numpy.ndarray of int64
        Same shape: each step's instant [ns since the epoch, UTC] and its clock time as the zone
        reads it [ns since 1970-01-01 00:00 local] (a skipped clock time moved forward).
    """
    offsets = [
        _day_offset(first // _NS_PER_DAY * _NS_PER_DAY, zone) for first in naive[:, 0].tolist()
    ]
    # The days of one offset in one subtraction; the days on which the clocks change, step by step.
    utc = naive - np.array([offset or 0 for offset in offsets], dtype=np.int64)[:, None]
    local = naive.copy()
    for row in [row for row, offset in enumerate(offsets) if offset is None]:
        utc[row] = [_localised_step(int(t), zone) for t in naive[row]]
        local[row] = utc[row] + [
            _offset_s(zone, int(t) // 1_000_000_000) * 1_000_000_000 for t in utc[row]
        ]
    return utc, local


@functools.lru_cache(maxsize=65536)
def _day_offset(midnight: int, zone: zoneinfo.ZoneInfo) -> int | None:
    """The UTC offset [ns] of a local day [its midnight, ns since 1970-01-01 00:00 local] in which
    the zone's clocks do not change, None where they do; once a day and zone a process (a sweep
    repeats its dates at every site of a zone, a run's passes the same days: 26 readings of the
    zone a day).

    The offsets read at each whole hour of the day (zones change their clocks on whole hours or
    half hours, at most once in an hour) are one offset on a day with no transition: a repeated
    or skipped clock time reads the offset before the change (``fold=0``, PEP 495), the next
    whole hour the offset after it. Where the change comes after the day's last hour (a gap or a
    repetition that runs into the next day), the end of the day read after it (``fold=1``)
    differs; a repetition then is read at its first instant either way, as pandas reads it."""
    start, utcoffset = _wall(midnight), zone.utcoffset
    # The offsets as the zone gives them (timedeltas), converted once: a sweep's year reads 26 a day.
    hours = {utcoffset(start + hour) for hour in _DAY_HOURS}
    hours.add(utcoffset(_wall(midnight + 24 * NS_PER_HOUR, 1)))
    return _offset_ns(hours.pop()) if len(hours) == 1 else None


#: The whole hours of a local day, its end included (:func:`_day_offset`).
_DAY_HOURS = tuple(dt.timedelta(hours=hour) for hour in range(25))


def _localised_step(local_ns: int, zone: zoneinfo.ZoneInfo) -> int:
    """UTC [ns] of one local clock time (:func:`_localised`)."""
    before = _offset_ns(zone.utcoffset(_wall(local_ns, 0)))
    after = _offset_ns(zone.utcoffset(_wall(local_ns, 1)))
    if before >= after:  # an ordinary time, or a repeated one at its first instant
        return local_ns - before
    # Skipped by the clocks: pandas' rule, the clock's next whole hour read with the offset after
    # the jump (the first time after it where the jump is an hour or half an hour on a whole hour).
    return local_ns + NS_PER_HOUR - local_ns % NS_PER_HOUR - after


def _offset_s(zone: zoneinfo.ZoneInfo, utc_s: int) -> int:
    """A zone's UTC offset [s] at a UTC instant [s since the epoch]."""
    moment = dt.datetime.fromtimestamp(utc_s, dt.timezone.utc).astimezone(zone)
    return int(moment.utcoffset().total_seconds())


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
    """Equation of time of PVCDROM [2]_ ("Solar Time"), as pvlib's ``equation_of_time_pvcdrom``.

    ``EoT = 9.87 sin 2B - 7.53 cos B - 1.5 sin B`` with ``B = 360 / 365 (d - 81)`` deg.

    Parameters
    ----------
    dayofyear : array_like
        Day of year, 1 on January 1 [-].

    Returns
    -------
    numpy.ndarray
        Equation of time [min].
    """
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
    return _hour_angle_paper(grid.clock_hours, grid.utc_offset_hours, grid.dayofyear, longitude)[0]


def by_dayofyear(function, dayofyear):
    """``function`` of the day of year at every step, looked up in its table of days 0..366.

    Parameters
    ----------
    function : callable
        Of the day of year (array_like) alone, elementwise; a module's function (not a lambda
        made per call), whose table is worked out once a process.
    dayofyear : numpy.ndarray of int
        Day of year of each step, 1 on 1 January.

    Returns
    -------
    numpy.ndarray
        ``function(dayofyear)``'s values, shaped as ``dayofyear``.
    """
    return _day_table(function)[dayofyear]


@functools.lru_cache(maxsize=32)
def _day_table(function) -> np.ndarray:
    """``function`` at days 0..366, read-only (:func:`by_dayofyear`)."""
    table = np.asarray(function(np.arange(367)))
    table.flags.writeable = False  # shared by every call
    return table


def _declination_spencer(dayofyear):
    """pvlib's ``declination_spencer71`` [deg]."""
    import pvlib

    return np.degrees(pvlib.solarposition.declination_spencer71(dayofyear))


def _hour_angle_paper(clock_hours, utc_offset_hours, dayofyear, longitude):
    equation_of_time = by_dayofyear(equation_of_time_paper, dayofyear)
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


def solar_position_grid(
    grid: ClockGrid,
    latitude,
    longitude,
    altitude=0.0,
    model: str = "exact",
    sun_terms: SunTerms | None = None,
) -> dict:
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
    sun_terms : foldopt.physics.spa.SunTerms, optional
        ``exact``: SPA's time-only terms a run shares between its calls (its chunks, a map's
        sites); default: this call's own.

    Returns
    -------
    dict of numpy.ndarray
        ``solar_zenith``, ``solar_azimuth`` and the equatorial coordinates ``hour_angle`` and
        ``declination`` that trackers steer by [deg], each (n_blocks, n_steps), and ``sun_vector``,
        (n_blocks, n_steps, 3) the unit vector toward the sun (east, north, up). In exact mode the
        hour angle is pvlib's formula ``15 (UTC hours - 12) + longitude + EoT / 4`` with SPA's
        equation of time, worked out from UTC (so DST days need no care), and the declination
        pvlib's ``declination_spencer71``.
    """
    dayofyear = grid.dayofyear
    if model == "paper":
        declination = by_dayofyear(declination_paper, dayofyear)
        hour_angle = _hour_angle_paper(
            grid.clock_hours, grid.utc_offset_hours, dayofyear, longitude
        )
        solar_zenith, solar_azimuth = sun_from_angles(declination, hour_angle, latitude)
        vector = normal_vector(solar_zenith, solar_azimuth)
    elif model == "exact":
        solar_zenith, solar_azimuth, hour_angle, vector = spa_solar_position(
            grid.utc_ns, latitude, longitude, altitude, sun_terms
        )
        declination = by_dayofyear(_declination_spencer, dayofyear)
    else:
        raise ValueError(f"model must be one of {', '.join(MODES)}; got {model!r}")
    return {
        "solar_zenith": solar_zenith,
        "solar_azimuth": solar_azimuth,
        "hour_angle": hour_angle,
        "declination": np.broadcast_to(declination, np.shape(solar_zenith)),
        "sun_vector": vector,
    }


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
    import pandas as pd

    sun = solar_position_grid(
        ClockGrid.from_times([times], times.tz), latitude, longitude, altitude, model
    )
    return pd.DataFrame(
        {name: values[0] for name, values in sun.items() if name != "sun_vector"}, index=times
    )
