"""Measured sub-hourly weather files (1-min, 5-min...) as a study's weather.

:func:`read_measured` reads a station's file (:data:`STATION_FORMATS`, the readers in
:mod:`~foldopt.inputs.weather.stations`) into a :class:`MeasuredWeather`: light, air temperature
and wind at every step of every local day the file touches, on the site's standard time, with
what was derived, filled and left out. In this order, vectorised over the steps:

1. The network's missing-value markers and QC-flagged values become missing. Thermopiles read a
   few W/m^2 below zero at night (SURFRAD's README: "Small negative values of irradiance at
   night are not flagged"; down to -7.7 W/m^2 in ``midc_20181014.txt``): irradiance in
   [:data:`NEGATIVE_LIMIT`, 0) becomes 0; lower is a fault, missing. While pvlib's clear sky is
   dark (the sun below the horizon) the light is 0, whatever the night offsets.
2. The step is the modal spacing of the stamps; a duplicate stamp or one off that grid is
   refused. Each stamp moves to its interval's centre (``label``, else the format's convention),
   on the site's standard time; the steps of whole local days are laid out, and the file's values
   placed on them: steps the file lacks are missing. An edge day of which the file holds no
   daylight step is no day of the file (an end-labelled file beginning at 00:00 holds of the day
   before only the night period that ends at midnight): it is left out, and the minutes the file
   leaves of its first and last days are reported filled (``_file_days``).
3. Physical bounds, QCRad's "physically possible" limits [1]_ [2]_ with the extraterrestrial
   normal irradiance ``E0`` and the cosine of the solar zenith ``mu0`` at the interval centre:
   ``ghi <= 1.5 E0 mu0^1.2 + 100``, ``dni <= E0``, ``dhi <= 0.95 E0 mu0^1.2 + 50`` W/m^2; where two
   components are measured, ``dhi <= 1.10 ghi + 10`` and ``dni mu0 <= ghi + 50`` W/m^2 (the
   tolerances of :mod:`~foldopt.inputs.weather.qc`), else both are dropped; ``temp_air`` and
   ``wind_speed`` within world records. Measured data have spikes: values beyond become missing,
   gaps like the others, and are counted in the notes. (This runs before anything is derived, so
   that the values it drops are filled like missing ones.)
4. Missing components. ``ghi`` alone: ``dni`` and ``dhi`` by a pvlib decomposition
   (``decomposition``: ``erbs``, ``boland`` or ``dirint`` [3]_). ``ghi`` and one of ``dni``,
   ``dhi``: the other by closure ``ghi = dni cos(zenith) + dhi``, the true solar zenith at the
   interval centre; where ``cos(zenith) < 0.0175`` (zenith above about 89 deg) ``dni`` from closure
   is unbounded: ``dni`` 0 and ``dhi = ghi`` there; where the beam would exceed ``ghi``, ``dhi`` 0
   and ``dni = ghi / cos(zenith)`` (a derived ``dhi`` is never negative, closure always holds).
   ``dni`` and ``dhi`` without ``ghi``: ``ghi`` by closure. All three measured: kept as measured,
   the global light is their component sum ``dni cos(zenith) + dhi``, BSRN's best estimate of it
   [4]_, so that every study closes; the measured ``ghi``'s residual (99th percentile and
   maximum) is reported.
5. Gaps. A step is daylight where pvlib's Ineichen clear-sky ``ghi`` (``Location.get_clearsky``)
   is above 0. A run of daylight steps missing a component, up to ``max_gap_min`` long, is filled
   along the clear-sky index: ``ghi / ghi_clear`` and ``dhi / ghi_clear`` interpolated linearly
   from the steps on either side (one side's value where the run touches night or the file's
   end; the ratios capped at :data:`GAP_FILL_MAX_INDEX`), times ``ghi_clear``, the ``ghi`` and
   ``dhi`` measured in the run kept; ``dni`` by closure. Longer runs
   stay missing and their days are :attr:`MeasuredWeather.flagged_days`. Missing light at night is
   0. ``temp_air`` and ``wind_speed`` are interpolated linearly in time (nearest at the ends),
   but for daylight steps of runs longer than ``max_gap_min``, which stay missing and flag their
   days. A file without any air temperature or wind speed gets
   :data:`~foldopt.inputs.weather.qc.DEFAULT_TEMP_AIR` and ``DEFAULT_WIND_SPEED``.

The site's time zone: the ``timezone`` argument, else the site's, else the file's standard
time, else the standard time of the meridian nearest the site (the UTC offset nearest
``longitude / 15`` h). A ``site`` given overrides the file's; formats whose file holds none
(``midc``, ``srml``, ``csv``) need one.

The module may import numpy, pandas, pvlib, :mod:`foldopt.errors`, :mod:`foldopt.inputs.reading` (its
limits) and the weather package's :mod:`~foldopt.inputs.weather.formats`, :mod:`~foldopt.inputs.weather.qc`
(its bounds and defaults) and :mod:`~foldopt.inputs.weather.stations`.

References
----------
.. [1] C. N. Long, E. G. Dutton, "BSRN Global Network recommended QC tests, V2.0", BSRN
   Technical Report, 2002.
.. [2] C. N. Long, Y. Shi, "An automated quality assessment and control algorithm for surface
   radiation measurements", The Open Atmospheric Science Journal 2, 23-37, 2008 (QCRad).
.. [3] pvlib.irradiance.erbs, boland, dirint.
.. [4] L. J. B. McArthur, "Baseline Surface Radiation Network (BSRN) Operations Manual, Version
   2.1", WCRP-121, WMO/TD-No. 1274, 2005: the global irradiance as the sum of the direct on the
   horizontal and the diffuse, the more accurate where both are measured.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from foldopt.errors import WeatherError
from foldopt.names import DECOMPOSITIONS, INTERVAL_LABELS
from foldopt.inputs.reading import MAX_MEASURED_STEPS
from foldopt.inputs.weather.downscale import MIN_COS_ZENITH
from foldopt.inputs.weather.formats import check_file, offset_zone, site_value
from foldopt.inputs.weather.qc import (
    BEAM_TOLERANCE,
    COLUMNS,
    DEFAULT_TEMP_AIR,
    DEFAULT_WIND_SPEED,
    DHI_TOLERANCE,
    TEMP_AIR_BOUNDS,
    WIND_SPEED_BOUNDS,
)
from foldopt.inputs.weather.stations import STATION_FORMATS, StationFormat, fixed_zone

__all__ = [
    "STATION_FORMATS",
    "StationFormat",
    "MeasuredWeather",
    "read_measured",
    "DECOMPOSITIONS",
    "LABELS",
]

#: What a stamp may mark, and the decompositions of ``ghi`` alone into ``dni`` and ``dhi``
#: (pvlib.irradiance): the registries of :mod:`foldopt.names`.
LABELS = INTERVAL_LABELS
#: Irradiance [W/m^2] from here to 0 is a thermopile's night offset, made 0; below, a fault.
NEGATIVE_LIMIT = -20.0
#: The largest clear-sky index (``ghi / ghi_clear``, ``dhi / ghi_clear``) carried into a gap: at low
#: sun the clear sky is dim and the ratio of a few W/m^2 to it unbounded.
GAP_FILL_MAX_INDEX = 1.5
_DAY = pd.Timedelta(days=1)
_WORDS = {"temp_air": "air temperature", "wind_speed": "wind speed"}


def _count(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"


@dataclass(frozen=True)
class MeasuredWeather:
    """A measured weather file, ready for a study.

    Parameters
    ----------
    frame : pandas.DataFrame
        ``ghi``, ``dni``, ``dhi`` [W/m^2], ``temp_air`` [C], ``wind_speed`` [m/s] at every step of
        every local day the file covers, indexed by tz-aware interval centres on the site's
        standard time (a fixed offset), regular; NaN only in long daylight gaps
        (:attr:`flagged_days`). ``attrs["weather"]`` is the file's name.
    site : dict
        ``name``, ``latitude``, ``longitude`` [deg], ``altitude`` [m], ``timezone`` (``UTC-07:00``).
    step : pandas.Timedelta
        The file's own step.
    derived : dict
        Component -> how it was obtained (``{'dni': 'erbs', 'dhi': 'erbs'}``, ``{'dhi':
        'closure'}``); empty when all three are measured.
    gaps : tuple
        ``(start, stop, minutes)`` of each run of daylight steps missing a component (missing,
        flagged or out of bounds in the file), local time.
    filled_steps : int
        Steps filled along the clear-sky index (runs up to ``max_gap_min``).
    flagged_days : tuple of datetime.date
        Days holding a daylight gap longer than ``max_gap_min``: their steps in it stay NaN.
    notes : tuple of str
        What else reading did (columns read, values dropped, defaults, closure residual).
    """

    frame: pd.DataFrame
    site: dict
    step: pd.Timedelta
    derived: dict
    gaps: tuple
    filled_steps: int
    flagged_days: tuple
    notes: tuple = ()

    def report(self) -> list[str]:
        """One-line sentences for the study's notes.

        Returns
        -------
        list of str
            The file's step and days, the derived components and how, the gaps filled, the
            flagged days, then :attr:`notes`.
        """
        index = self.frame.index
        days = np.unique(index.tz_localize(None).to_numpy().astype("datetime64[D]"))
        site = self.site
        name = f"{site['name']} " if site.get("name") else ""
        lines = [
            f"measured weather {self.frame.attrs.get('weather', '')}: {_minutes(self.step)} steps, "
            f"{_count(days.size, 'day')} ({days[0]} to {days[-1]}) at interval centres on {site['timezone']}, "
            f"site {name}{site['latitude']:.4f}, {site['longitude']:.4f} deg, {site['altitude']:g} m"
        ]
        for how in dict.fromkeys(self.derived.values()):
            keys = " and ".join(key for key, value in self.derived.items() if value == how)
            if how == "closure":
                lines.append(
                    f"{keys} derived by closure ghi = dni cos(zenith) + dhi (where cos(zenith) < "
                    f"{MIN_COS_ZENITH:g}, dni 0 and dhi = ghi)"
                )
            else:
                lines.append(
                    f"{keys} derived from ghi by the {how} decomposition (pvlib.irradiance.{how})"
                )
        if self.gaps:
            minutes = [gap[2] for gap in self.gaps]
            lines.append(
                f"{_count(len(self.gaps), 'daylight gap')} ({sum(minutes):g} min, the longest "
                f"{max(minutes):g} min); {_count(self.filled_steps, 'step')} filled along the clear-sky index"
            )
        else:
            lines.append("no daylight gaps")
        if self.flagged_days:
            lines.append(
                f"{_count(len(self.flagged_days), 'day')} with a daylight gap too long to fill, left "
                "incomplete: " + ", ".join(str(day) for day in self.flagged_days)
            )
        return lines + list(self.notes)


def _minutes(step: pd.Timedelta) -> str:
    minutes = step / pd.Timedelta(minutes=1)
    return f"{minutes:g}-min" if minutes >= 1 else f"{step.total_seconds():g}-s"


def _zone_hours(text: str, fail) -> float:
    """The UTC offset [h] of ``UTC-07:00`` (or ``UTC``, ``UTC+5:30``)."""
    match = re.fullmatch(r"UTC(?:([+-])(\d{1,2})(?::?(\d{2}))?)?", str(text).strip())
    if not match:
        raise fail(f"timezone {text!r}: not a fixed UTC offset like 'UTC-07:00'")
    sign, hours, minutes = match.groups()
    value = (int(hours or 0) + int(minutes or 0) / 60.0) * (-1 if sign == "-" else 1)
    if not -12.0 <= value <= 14.0:
        raise fail(f"timezone {text!r}: must be within UTC-12:00 to UTC+14:00")
    return value


def _site(entry: StationFormat, found: dict, given: dict | None, fail) -> dict:
    """The site: ``given``'s fields over the file's, each checked."""
    site = {key: value for key, value in found.items() if value is not None}
    if given is not None:
        if not isinstance(given, dict):
            raise fail(
                f"site must be a mapping of latitude, longitude and altitude; got {type(given).__name__}"
            )
        site.update({key: value for key, value in given.items() if value is not None})
    missing = [key for key in ("latitude", "longitude", "altitude") if key not in site]
    if missing and not found and given is None:
        raise fail(
            f"the {entry.name} format holds no site; give site latitude, longitude and altitude"
        )
    if missing:
        raise fail(f"site has no {', '.join(missing)}: give site latitude, longitude and altitude")
    for key in ("latitude", "longitude", "altitude"):
        site[key] = site_value(fail, "site", key, site[key])
    site["name"] = str(site["name"]) if site.get("name") else None
    return site


def _grid(frame: pd.DataFrame, label: str, zone, fail):
    """The file's step, the whole local days' interval centres, the file's rows on them, and
    which steps the file has a row for."""
    frame = frame.iloc[np.argsort(frame.index.as_unit("ns").asi8, kind="stable")]
    stamps = frame.index.as_unit("ns")
    ns = stamps.asi8
    if ns.size < 2:
        raise fail("one row: a measured file needs two or more to tell its step")
    spacing = np.diff(ns)
    same = np.flatnonzero(spacing == 0) + 1
    if same.size:
        raise fail(
            f"{_count(same.size, 'duplicate stamp')}, the first {stamps[same[0]].isoformat(sep=' ')}"
        )
    values, counts = np.unique(spacing, return_counts=True)
    # a tie: the longest (a stray stamp makes two short ones)
    step = int(values[counts == counts.max()][-1])
    off = np.flatnonzero((ns - ns[0]) % step)
    step_td = pd.Timedelta(step, unit="ns")
    if off.size:
        raise fail(
            f"{_count(off.size, 'stamp')} off the {_minutes(step_td)} grid of the others, the first "
            f"{stamps[off[0]].isoformat(sep=' ')}"
        )
    if pd.Timedelta(hours=1).value % step:
        raise fail(f"step {_minutes(step_td)}: a measured file's step must divide an hour")
    shift = {"start": step_td / 2, "end": -step_td / 2, "centre": step_td * 0}[label]
    local = (stamps + shift).tz_convert(zone).tz_localize(None).asi8
    first = local[0] - local[0] % _DAY.value
    phase = (local[0] - first) % step
    days = (local[-1] - first) // _DAY.value + 1
    n = int(days * (_DAY.value // step))
    # beyond a limit, or a file 99 % gaps
    if n > MAX_MEASURED_STEPS or (days > 31 and n > 100 * ns.size):
        span = " to ".join(stamps[i].isoformat(sep=" ") for i in (0, -1))
        raise fail(
            f"the stamps span {span}, {_count(int(days), 'day')} at the file's {_minutes(step_td)} step: {n:,}"
            f" steps for {ns.size:,} rows; at most {MAX_MEASURED_STEPS:,} (FOLDOPT_MAX_MEASURED_STEPS) and 100 "
            "a row; check the stamps' years"
        )
    index = pd.DatetimeIndex(first + phase + step * np.arange(n, dtype=np.int64)).tz_localize(zone)
    rows = (local - first - phase) // step
    table = {key: np.full(n, np.nan) for key in frame.columns}
    for key in frame.columns:
        table[key][rows] = frame[key].to_numpy(dtype=float)
    held = np.zeros(n, dtype=bool)
    held[rows] = True
    return step_td, index, table, held


def _file_days(index: pd.DatetimeIndex, held: np.ndarray, day: np.ndarray, step: pd.Timedelta, air):
    """The steps of the days the file holds light of, and what its edges leave to fill.

    An edge day of which the file holds no daylight step is no day of the file: a file whose
    stamps end their periods and begins at 00:00 holds of the day before only its last period,
    at night; one whose stamps start their periods and ends at 00:00 holds the first period of
    the day after; a UTC day's file holds the evening of a western site's local day before.
    Such a day would be all gap. The file's first and last days are then laid out
    whole: the steps before its first period and after its last are filled as any other (light
    0 at night, along the clear-sky index in daylight, the air and wind from the nearest step),
    and said so.

    Parameters
    ----------
    index : pandas.DatetimeIndex
        Interval centres of whole local days, (n,).
    held : numpy.ndarray of bool
        (n,) the steps the file has a row for.
    day : numpy.ndarray of bool
        (n,) daylight steps (the clear sky's ``ghi`` above 0).
    step : pandas.Timedelta
    air : list of str
        The air's columns the file holds (``temp_air``, ``wind_speed``), taken from the nearest
        step where the edges leave them.

    Returns
    -------
    keep : slice
        The steps of the days kept, whole days.
    notes : list of str
        The days left out, and each edge's filled minutes and how.
    """
    per_day = int(pd.Timedelta(days=1) / step)
    days = held.size // per_day
    lit = (held & day).reshape(days, per_day).any(axis=1)
    first, last = (
        (int(np.argmax(lit)), days - 1 - int(np.argmax(lit[::-1]))) if lit.any() else (0, days - 1)
    )
    notes = []
    dates = index[::per_day].tz_localize(None).date
    for lo, hi in ((0, first), (last + 1, days)):
        if hi > lo:
            minutes = held.reshape(days, per_day)[lo:hi].sum() * step / pd.Timedelta(minutes=1)
            notes.append(
                f"{', '.join(str(d) for d in dates[lo:hi])} not counted: the file holds only "
                f"{minutes:g} min of it, all at night"
            )
    keep = slice(first * per_day, (last + 1) * per_day)
    inside = held[keep]
    at = np.flatnonzero(inside)
    lead, trail = at[0], inside.size - 1 - at[-1]
    step_min = step / pd.Timedelta(minutes=1)
    nearest = " and ".join(_WORDS[key] for key in air)
    nearest = f"; {nearest} the nearest step's" if nearest else ""
    for count, where, span in (
        (lead, "before the file's first period", (0, lead)),
        (trail, "after the file's last period", (inside.size - trail, inside.size)),
    ):
        if count:
            steps = slice(keep.start + span[0], keep.start + span[1])
            lit_steps = int(day[steps].sum())
            start, stop = index[steps][0] - step / 2, index[steps][-1] + step / 2
            how = (
                "night: light 0"
                if not lit_steps
                else f"{lit_steps * step_min:g} min of it in daylight, a daylight gap"
            )
            notes.append(
                f"{count * step_min:g} min {where} filled ({start:%Y-%m-%d %H:%M} to "
                f"{stop:%H:%M}; {how}{nearest})"
            )
    return keep, notes


def _closure_dni(ghi, dhi, cosz):
    """``dni`` and ``dhi`` from ``ghi`` and ``dhi`` by closure (module docstring)."""
    valid = np.isfinite(ghi) & np.isfinite(dhi)
    high = cosz >= MIN_COS_ZENITH
    dni = np.where(high, (ghi - dhi) / np.where(high, cosz, 1.0), 0.0)
    flat = ~high | (dni < 0)
    return np.where(valid, np.where(flat, 0.0, dni), np.nan), np.where(valid & flat, ghi, dhi)


def _closure_dhi(ghi, dni, cosz):
    """``dni`` and ``dhi`` from ``ghi`` and ``dni`` by closure; the steps where the beam exceeded
    ``ghi`` and ``dni`` was lowered to it."""
    beam = dni * np.maximum(cosz, 0.0)
    over = beam > ghi
    with np.errstate(divide="ignore", invalid="ignore"):
        lowered = np.where(over, ghi / cosz, dni)
    return lowered, np.where(over, 0.0, ghi - beam), over


def _components(table, present, decomposition, index, zenith, cosz, pressure, fail):
    """Derive the missing components in place (module docstring, step 4): what was derived, and at
    how many steps a measured ``dni`` was lowered to ``ghi``."""
    ghi, dni, dhi = (table.get(key) for key in ("ghi", "dni", "dhi"))
    lowered = 0
    if "ghi" in present and not {"dni", "dhi"} & present:
        if decomposition == "dirint":
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                import pvlib

                dni = np.asarray(
                    pvlib.irradiance.dirint(
                        pd.Series(ghi, index), pd.Series(zenith, index), index, pressure=pressure
                    ),
                    dtype=float,
                )
            dni, dhi, _ = _closure_dhi(
                ghi, np.where(np.isfinite(ghi), np.nan_to_num(dni), np.nan), cosz
            )
        else:
            with warnings.catch_warnings():
                # pvlib reads DatetimeIndex.dayofyear, deprecated by pandas
                warnings.simplefilter("ignore")
                import pvlib

                out = getattr(pvlib.irradiance, decomposition)(
                    pd.Series(ghi, index), pd.Series(zenith, index), index
                )
            dni, dhi = np.asarray(out["dni"], dtype=float), np.asarray(out["dhi"], dtype=float)
            flat = cosz < MIN_COS_ZENITH
            dni, dhi = np.where(flat & np.isfinite(ghi), 0.0, dni), np.where(flat, ghi, dhi)
        derived = {"dni": decomposition, "dhi": decomposition}
    elif present == {"ghi", "dni"}:
        dni, dhi, over = _closure_dhi(ghi, dni, cosz)
        lowered = int(over.sum())
        derived = {"dhi": "closure"}
    elif present == {"ghi", "dhi"}:
        dni, dhi = _closure_dni(ghi, dhi, cosz)
        derived = {"dni": "closure"}
    elif present == {"dni", "dhi"}:
        ghi = dni * np.maximum(cosz, 0.0) + dhi
        derived = {"ghi": "closure"}
    elif "ghi" not in present:
        raise fail(
            "no ghi column, nor dni and dhi to make it by closure ghi = dni cos(zenith) + dhi"
        )
    else:
        derived = {}
    table.update(ghi=ghi, dni=dni, dhi=dhi)
    return derived, lowered


def _bounds(table, present, extra, cosz, dropped) -> None:
    """Clip night offsets and drop values out of physical bounds, in place (module docstring)."""
    mu = np.maximum(cosz, 0.0)
    limits = {
        "ghi": 1.5 * extra * mu**1.2 + 100.0,
        "dni": extra,
        "dhi": 0.95 * extra * mu**1.2 + 50.0,
    }
    bad = {}
    for key in present & {"ghi", "dni", "dhi"}:
        values = table[key]
        bad[key] = (values < NEGATIVE_LIMIT) | (values > limits[key])
        table[key] = np.where(values < 0, 0.0, values)
    if {"ghi", "dhi"} <= present:
        fraction, absolute = DHI_TOLERANCE
        pair = table["dhi"] > (1.0 + fraction) * table["ghi"] + absolute
        bad["ghi"] |= pair
        bad["dhi"] |= pair
    if {"ghi", "dni"} <= present:
        pair = table["dni"] * mu > table["ghi"] + BEAM_TOLERANCE
        bad["ghi"] |= pair
        bad["dni"] |= pair
    for key, (lo, hi) in (("temp_air", TEMP_AIR_BOUNDS), ("wind_speed", WIND_SPEED_BOUNDS)):
        if key in table:
            bad[key] = (table[key] < lo) | (table[key] > hi)
    for key, mask in bad.items():
        if mask.any():
            dropped[key] = int(mask.sum())
            table[key] = np.where(mask, np.nan, table[key])


def _runs(mask: np.ndarray):
    """Starts and (exclusive) stops of the runs of True in ``mask``."""
    edges = np.diff(np.r_[0, mask.astype(np.int8), 0])
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)


def _fill(table, day, clear, cosz, step_min, max_gap_min, index):
    """Fill the gaps in place (module docstring, step 5): the gaps, steps filled, flagged days."""
    ghi, dni, dhi = table["ghi"], table["dni"], table["dhi"]
    missing = day & ~(np.isfinite(ghi) & np.isfinite(dni) & np.isfinite(dhi))
    starts, stops = _runs(missing)
    lengths = stops - starts
    n = ghi.size
    left, right = starts - 1, stops
    left_ok = (left >= 0) & day[np.clip(left, 0, n - 1)]
    right_ok = (right < n) & day[np.clip(right, 0, n - 1)]
    fillable = (lengths * step_min <= max_gap_min) & (left_ok | right_ok)
    run = np.repeat(np.arange(starts.size), lengths)
    at = np.flatnonzero(missing)
    fraction = (at - starts[run] + 1) / (lengths[run] + 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        for key in ("ghi", "dhi"):
            ratio = np.clip(table[key] / clear, 0.0, GAP_FILL_MAX_INDEX)
            lo, hi = ratio[np.clip(left, 0, n - 1)][run], ratio[np.clip(right, 0, n - 1)][run]
            both = left_ok[run] & right_ok[run]
            value = (
                np.where(both, lo + (hi - lo) * fraction, np.where(left_ok[run], lo, hi))
                * clear[at]
            )
            keep = np.isfinite(table[key][at])
            table[key][at] = np.where(fillable[run] & ~keep, value, table[key][at])
    filled = at[fillable[run]]
    new_dni, new_dhi = _closure_dni(table["ghi"][filled], table["dhi"][filled], cosz[filled])
    table["dni"][filled], table["dhi"][filled] = new_dni, new_dhi
    for key in ("ghi", "dni", "dhi"):
        table[key] = np.where(~day & ~np.isfinite(table[key]), 0.0, table[key])
    step = index[1] - index[0] if n > 1 else pd.Timedelta(0)
    gaps = tuple(
        (index[s] - step / 2, index[e - 1] + step / 2, float(length * step_min))
        for s, e, length in zip(starts, stops, lengths, strict=True)
    )
    long_steps = at[~fillable[run]]
    for key in ("temp_air", "wind_speed"):
        values = table[key]
        if np.isfinite(values).all():
            continue
        a, b = _runs(~np.isfinite(values))
        spans = np.repeat((b - a) * step_min > max_gap_min, b - a)
        holes = np.flatnonzero(~np.isfinite(values))
        table[key] = (
            pd.Series(values).interpolate(limit_area="inside").ffill().bfill().to_numpy(copy=True)
        )
        keep_missing = holes[spans & day[holes]]
        table[key][keep_missing] = np.nan
        long_steps = np.r_[long_steps, keep_missing]
    dates = index[long_steps].tz_localize(None).normalize().unique().sort_values()
    return gaps, int(filled.size), tuple(stamp.date() for stamp in dates)


def read_measured(
    path,
    fmt: str,
    label: str | None = None,
    timezone: str | None = None,
    site: dict | None = None,
    decomposition: str = "erbs",
    max_gap_min: float = 60.0,
) -> MeasuredWeather:
    """A measured sub-hourly weather file as a study's weather (module docstring).

    Parameters
    ----------
    path : str or pathlib.Path
    fmt : str
        One of :data:`STATION_FORMATS` (``surfrad``, ``midc``, ``srml``, ``bsrn``, ``solrad``,
        ``crn``, ``csv``).
    label : {'start', 'end', 'centre'}, optional
        What a stamp of the file marks; default its format's ``interval_label``
        (:mod:`~foldopt.inputs.weather.stations`; ``end`` for ``csv``).
    timezone : str, optional
        The site's standard time, a fixed offset (``UTC-07:00``); it also places a CSV file's
        stamps that carry no offset. Default the site's, the file's, or the offset nearest
        ``longitude / 15`` h.
    site : dict, optional
        ``latitude``, ``longitude`` [deg], ``altitude`` [m], optional ``name`` and ``timezone``:
        required where the file holds no site (``midc``, ``srml``, ``csv``), else overriding it.
    decomposition : {'erbs', 'boland', 'dirint'}
        How ``dni`` and ``dhi`` come from ``ghi`` alone.
    max_gap_min : float
        The longest daylight gap filled [min].

    Returns
    -------
    MeasuredWeather

    Raises
    ------
    ValueError
        For an unknown ``fmt``, ``label`` or ``decomposition``, or a negative ``max_gap_min``.
    foldopt.errors.WeatherError
        One line ``weather <file name>: ...`` for a file that cannot be used: unreadable, empty,
        without rows, ghi or site, with duplicate or off-grid stamps.
    """
    if fmt not in STATION_FORMATS:
        raise ValueError(
            f"measured weather format must be one of {', '.join(STATION_FORMATS)}; got {fmt!r}"
        )
    if label is not None and label not in LABELS:
        raise ValueError(f"label must be one of {', '.join(LABELS)}; got {label!r}")
    if decomposition not in DECOMPOSITIONS:
        raise ValueError(
            f"decomposition must be one of {', '.join(DECOMPOSITIONS)}; got {decomposition!r}"
        )
    if not float(max_gap_min) >= 0:
        raise ValueError(f"max_gap_min must be a number of minutes >= 0; got {max_gap_min!r}")
    entry, path = STATION_FORMATS[fmt], Path(path)

    def fail(message: str) -> WeatherError:
        return WeatherError(f"weather {path.name}: {message}")

    check_file(path)
    try:
        if not path.read_bytes().strip():
            raise fail("the file is empty")
    except OSError as error:
        raise fail(f"cannot be read ({error.strerror or error})") from None
    given = (
        timezone
        if timezone is not None
        else (site or {}).get("timezone")
        if isinstance(site, dict)
        else None
    )
    zone = None if given is None else _zone_hours(given, fail)
    raw = entry.reader(str(path), fail, zone)
    if len(raw.frame) == 0:
        raise fail("no data rows")
    where = _site(entry, raw.site, site, fail)
    hours = (
        zone
        if zone is not None
        else raw.zone
        if raw.zone is not None
        else round(where["longitude"] / 15.0)
    )
    where["timezone"] = offset_zone(hours)
    tz = fixed_zone(hours)
    step, index, table, held = _grid(raw.frame, label or entry.interval_label, tz, fail)
    present = {
        key for key in ("ghi", "dni", "dhi") if key in table and np.isfinite(table[key]).any()
    }
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pvlib reads DatetimeIndex.dayofyear, deprecated by pandas
        import pvlib

        sun = pvlib.solarposition.get_solarposition(
            index, where["latitude"], where["longitude"], where["altitude"]
        )
        clear = (
            pvlib.location.Location(
                where["latitude"], where["longitude"], altitude=where["altitude"]
            )
            .get_clearsky(index, model="ineichen", solar_position=sun)["ghi"]
            .to_numpy(dtype=float)
        )
        extra = np.asarray(pvlib.irradiance.get_extra_radiation(index), dtype=float)
    air = [key for key in _WORDS if key in table and np.isfinite(table[key]).any()]
    keep, edges = _file_days(index, held, clear > 0, step, air)
    index, clear, extra = index[keep], clear[keep], extra[keep]
    table = {key: values[keep] for key, values in table.items()}
    zenith = sun["zenith"].to_numpy(dtype=float)[keep]
    cosz = np.cos(np.radians(zenith))
    dropped: dict = {}
    _bounds(table, present, extra, cosz, dropped)
    notes = list(raw.notes) + edges
    derived, lowered = _components(
        table,
        present,
        decomposition,
        index,
        zenith,
        cosz,
        pvlib.atmosphere.alt2pres(where["altitude"]),
        fail,
    )
    if lowered:
        notes.append(
            f"measured dni lowered to ghi / cos(zenith) at {_count(lowered, 'step')} where its beam "
            f"exceeded ghi (within the {BEAM_TOLERANCE:g} W/m^2 tolerance)"
        )
    day = clear > 0
    if not derived:
        residual = np.abs(table["ghi"] - table["dni"] * np.maximum(cosz, 0.0) - table["dhi"])[day]
        residual = residual[np.isfinite(residual)]
        if residual.size:
            notes.append(
                f"ghi, dni and dhi all measured: ghi is their component sum dni cos(zenith) + dhi, the "
                f"best estimate of the global light (BSRN operations manual); the measured ghi differs by "
                f"{np.percentile(residual, 99):.1f} W/m^2 at the 99th percentile in daylight, "
                f"{residual.max():.1f} W/m^2 at most"
            )
        # One light a study's steps can close: the component sum, where both components exist.
        both = np.isfinite(table["dni"]) & np.isfinite(table["dhi"]) & day
        table["ghi"] = np.where(
            both, table["dni"] * np.maximum(cosz, 0.0) + table["dhi"], table["ghi"]
        )
    for key, default, unit in (
        ("temp_air", DEFAULT_TEMP_AIR, "C"),
        ("wind_speed", DEFAULT_WIND_SPEED, "m/s"),
    ):
        if key not in table or not np.isfinite(table[key]).any():
            table[key] = np.full(index.size, default)
            notes.append(f"no {_WORDS[key]} in the file: {default:g} {unit} throughout")
    gaps, filled, flagged = _fill(
        table, day, clear, cosz, step / pd.Timedelta(minutes=1), float(max_gap_min), index
    )
    if raw.dropped:
        notes.append(f"{raw.dropped} values flagged by the network's QC made missing")
    if dropped:
        notes.append(
            "values beyond physical bounds made missing: "
            + ", ".join(f"{key} {count}" for key, count in dropped.items())
        )
    # No light while the clear sky is dark (the sun below the horizon): a thermopile's night
    # offset would otherwise light a study's panels at night.
    for key in ("ghi", "dni", "dhi"):
        table[key] = np.where(day, table[key], 0.0)
    frame = pd.DataFrame({key: table[key] for key in COLUMNS}, index=index)
    frame.attrs["weather"] = path.name
    return MeasuredWeather(frame, where, step, derived, gaps, filled, flagged, tuple(notes))
