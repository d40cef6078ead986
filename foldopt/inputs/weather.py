"""Weather files and pvlib clear skies: global, direct and diffuse irradiance per time step.

Weather files are read through pvlib.iotools (TMY3, EPW, PVGIS TMY) once per study, with the site
in their header (:func:`weather_site`). As pvlib returns them, timestamps mark the end of each
interval for TMY3 and its start for EPW (pvlib moves EPW's hour-ending rows back an hour) and for
PVGIS (hour-start stamps, in UTC, moved here to the site's standard time); foldopt moves them to
the interval centre, like its own clear-sky steps. ``label`` overrides the convention. Years are
coerced to one (a TMY mixes years), so a non-leap year matches the files' 365 days.

A file's hourly means are evaluated on the study's own step (:func:`sub_hourly`): each hour's
clear-sky index, the ratio of its mean irradiance to the mean of the clear sky over the same hour
[3]_, is interpolated between hour centres and multiplied by the clear sky at every step, then
scaled so that each hour keeps its mean. Light then begins at sunrise and ends at sunset, as the
clear sky does, instead of being spread linearly from one hour's centre to the next.

Notes
-----
**Validation.** A file is checked once, when it is read, and any fault raises
:class:`WeatherError`: one line naming the file, where (``line N`` of a TMY3 or EPW file,
counting its 2 or 8 header lines; ``record N`` of a PVGIS file's ``outputs.tmy_hourly``; or the
header field or column) and why. When several rows fail the same check, the first is named and
the rest counted. Nothing is filled in silently, with one documented exception: a file without
any air temperature or wind speed column at all gets 20 C and 1 m/s (:data:`DEFAULT_TEMP_AIR`,
:data:`DEFAULT_WIND_SPEED`), as foldopt always did.

* The file: not empty, at least one row after its header, no February 29 (pvlib reads a TMY3
  file's as March 1, and an EPW file's cannot be coerced to a year without one), and readable by
  pvlib: any exception of pvlib's reader (pandas' ``EmptyDataError``, a ``KeyError`` for a
  missing date column, a ``UnicodeDecodeError``...) is reported as the file not being readable,
  with its reason; a PVGIS file that is not JSON is named with the line and column of the fault.
* The header: latitude in [-90, 90] deg, longitude in [-180, 180] deg, a finite altitude and a
  time zone offset in [-12, 14] h (UTC-12 to UTC+14, the offsets in use).
* The columns: ``ghi``, ``dni`` and ``dhi`` must exist; ``temp_air`` and ``wind_speed`` may be
  absent (see above) but, if present, are checked like the others.
* The rows: hourly and strictly increasing once the year is coerced (no duplicate hour); every
  value used a finite number; and within physical bounds, evaluated at the interval centre of the
  file's own convention (:data:`INTERVAL_LABELS`, whatever ``label`` a study gives):

  - ``0 <= ghi <= 1.5 E0`` and ``0 <= dni <= E0``, where ``E0`` is the extraterrestrial normal
    irradiance of the day (pvlib ``irradiance.get_extra_radiation``, 1320 to 1414 W/m^2);
    ``0 <= dhi``.
  - ``dhi <= 1.10 ghi + 10 W/m^2`` (:data:`DHI_TOLERANCE`): BSRN's comparison test bounds the
    diffuse ratio by 1.05 for solar zenith angles below 75 deg and 1.10 up to 93 deg when
    GHI > 50 W/m^2 [4]_; the 10 W/m^2 covers the dim hours the test leaves out and the rounding
    of files that store whole W/m^2.
  - ``dni max(cos(zenith), 0) <= ghi + 50 W/m^2`` (:data:`BEAM_TOLERANCE`), the solar zenith
    from pvlib ``solarposition.get_solarposition`` at the file's site and the interval centre:
    the beam cannot bring more light to the ground than the global light. A file whose clock, site
    or columns are wrong breaks this at low sun (a clock one hour off gives 90 to 94 W/m^2 on
    the Greensboro TMY3 sample).
  - ``temp_air`` in [-90, 65] C (world records -89.2 C at Vostok, 56.7 C at Death Valley [5]_),
    ``wind_speed`` in [0, 120] m/s (world record gust 113 m/s at Barrow Island [5]_). These and
    the irradiance bounds catch EPW's missing-value markers (9999 W/m^2, 99.9 C, 999 m/s [6]_).

  The tolerances sit above the worst residuals of real files, measured on pvlib's TMY3 samples
  (723170TYA.CSV, 703165TY.csv), an EPW written from the first (tests/test_weather_year.py), and
  the EPW and PVGIS files of pvlib's own tests (NLD_Amsterdam062400_IWEC.epw,
  tmy_45.000_8.000_2005_2023.epw and .json): ``dhi - ghi`` is at most 0.00 W/m^2 in all of them;
  ``dni cos(zenith) - ghi`` at most 0.00 W/m^2 but in PVGIS's EPW (25.6 W/m^2: its light comes
  about half an hour later than EPW's hour-ending stamps say); GHI reaches 0.77 E0 and DNI
  0.72 E0. Each of these files reads in 0.1 to 0.2 s, the checks included.

A study over a period needs the file to hold every day of it, whole (:func:`weather_days`).

References
----------
.. [1] pvlib.iotools.read_tmy3, read_epw, read_pvgis_tmy; pvlib.clearsky.ineichen,
   simplified_solis; pvlib.clearsky.lookup_linke_turbidity (bundled climatology).
.. [2] P. Ineichen, R. Perez, "A new airmass independent formulation for the Linke turbidity
   coefficient", Solar Energy 73(3), 151-157, 2002 (pvlib ``clearsky.ineichen``).
.. [3] The clear-sky index (pvlib ``irradiance.clearsky_index``, bounded by 2 for over-irradiance
   as pvlib bounds it); used to bring hourly irradiance to finer steps e.g. in A. P. Grantham,
   P. J. Pudney, J. W. Boland, M. Belusko, "Synthetically interpolated five-minute direct normal
   irradiance", MODSIM 2013, whose deterministic part (without the synthetic fluctuations) this is.
.. [4] C. N. Long, E. G. Dutton, "BSRN Global Network recommended QC tests, V2.0", BSRN
   Technical Report, 2002; C. N. Long, Y. Shi, "An automated quality assessment and control
   algorithm for surface radiation measurements", The Open Atmospheric Science Journal 2, 23-37,
   2008.
.. [5] World Meteorological Organization, World Weather and Climate Extremes Archive,
   https://wmo.asu.edu/.
.. [6] EnergyPlus, Auxiliary Programs, "Energyplus Weather File (EPW) Data Dictionary" (missing
   values of each field).
"""

from __future__ import annotations

import functools
import io
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pvlib

from foldopt.errors import WeatherError
from foldopt.names import CLEAR_SKIES, WEATHER_FORMATS

#: Which edge of its interval each format's timestamp marks, as pvlib.iotools returns it
#: (checked for TMY3 and EPW in tests/test_weather.py).
INTERVAL_LABELS = {"tmy3": "end", "epw": "start", "pvgis": "start"}
#: Bound of the clear-sky index at every step (pvlib's default: over-irradiance up to twice clear).
MAX_CLEARSKY_INDEX = 2.0

#: Air temperature [C] and wind speed [m/s] of a file without such a column at all.
DEFAULT_TEMP_AIR = 20.0
DEFAULT_WIND_SPEED = 1.0
#: Bounds of GHI and DNI as multiples of the extraterrestrial normal irradiance of the day.
MAX_GHI_PER_EXTRA = 1.5
MAX_DNI_PER_EXTRA = 1.0
#: ``dhi <= (1 + fraction) ghi + absolute`` [-, W/m^2]: BSRN's diffuse-ratio bound 1.10 [4]_,
#: plus 10 W/m^2 for dim hours and rounding. Worst on the real files (module docstring): 0.00 W/m^2.
DHI_TOLERANCE = (0.10, 10.0)
#: ``dni max(cos(zenith), 0) <= ghi + BEAM_TOLERANCE`` [W/m^2]. Worst on the real files: 0.00 W/m^2
#: (TMY3 samples, the EPW written from one, IWEC Amsterdam EPW, PVGIS JSON) and 25.6 W/m^2 (PVGIS EPW,
#: 2025-02-27 16:00-17:00: DNI 592, GHI 139 W/m^2, zenith 73.8 deg); a one-hour clock error on the
#: Greensboro TMY3 gives 90 to 94 W/m^2.
BEAM_TOLERANCE = 50.0
#: Air temperature [C] and wind speed [m/s] bounds (world records, module docstring [5]_).
TEMP_AIR_BOUNDS = (-90.0, 65.0)
WIND_SPEED_BOUNDS = (0.0, 120.0)

_FORMAT_NAMES = {"tmy3": "TMY3", "epw": "EPW", "pvgis": "PVGIS TMY"}
#: Lines before the first row of a TMY3 or EPW file.
HEADER_LINES = {"tmy3": 2, "epw": 8}
#: The first header line's fields, as pvlib names them.
_HEADER_FIELDS = {
    "tmy3": ("USAF", "Name", "State", "TZ", "latitude", "longitude", "altitude"),
    "epw": ("LOCATION", "city", "state-prov", "country", "data_type", "WMO_code", "latitude", "longitude", "TZ",
            "altitude"),
}
#: Where each column comes from in each format (EPW: the field number of a row).
_SOURCE_COLUMNS = {
    "tmy3": {"ghi": "GHI (W/m^2)", "dni": "DNI (W/m^2)", "dhi": "DHI (W/m^2)", "temp_air": "Dry-bulb (C)",
             "wind_speed": "Wspd (m/s)"},
    "epw": {"ghi": "field 14", "dni": "field 15", "dhi": "field 16", "temp_air": "field 7", "wind_speed": "field 22"},
    "pvgis": {"ghi": "G(h)", "dni": "Gb(n)", "dhi": "Gd(h)", "temp_air": "T2m", "wind_speed": "WS10m"},
}
#: EPW's missing-value markers of the columns used [6]_.
_EPW_MISSING = {"ghi": 9999.0, "dni": 9999.0, "dhi": 9999.0, "temp_air": 99.9, "wind_speed": 999.0}
_UNITS = {"ghi": "W/m^2", "dni": "W/m^2", "dhi": "W/m^2", "temp_air": "C", "wind_speed": "m/s"}
_COLUMNS = ("ghi", "dni", "dhi", "temp_air", "wind_speed")
_HOUR = pd.Timedelta(hours=1)


def weather_format(path: Path, fmt: str | None = None) -> str:
    """The file's format: given, or from its extension (``.epw``; ``.csv`` is TMY3; ``.json`` PVGIS)."""
    if fmt is not None:
        if fmt not in WEATHER_FORMATS:
            raise ValueError(f"weather format must be one of {', '.join(WEATHER_FORMATS)}; got {fmt!r}")
        return fmt
    suffix = Path(path).suffix.lower()
    return {".epw": "epw", ".csv": "tmy3", ".json": "pvgis"}.get(suffix, "tmy3")


def _offset_zone(hours: float) -> str:
    """A fixed UTC offset as foldopt spells it (``UTC-05:00``)."""
    minutes = round(hours * 60)
    sign = "+" if minutes >= 0 else "-"
    return f"UTC{sign}{abs(minutes) // 60:02d}:{abs(minutes) % 60:02d}"


def _site_of(fmt: str, meta: dict) -> dict:
    if fmt == "pvgis":
        inputs = meta["inputs"]
        location = inputs.get("location", inputs)
        latitude, longitude = float(location["latitude"]), float(location["longitude"])
        return {"name": None, "latitude": latitude, "longitude": longitude,
                "altitude": float(location["elevation"]), "timezone": _offset_zone(round(longitude / 15.0))}
    name = meta.get("Name") if fmt == "tmy3" else meta.get("city")
    return {"name": str(name).strip('" ') if name else None, "latitude": float(meta["latitude"]),
            "longitude": float(meta["longitude"]), "altitude": float(meta["altitude"]),
            "timezone": _offset_zone(float(meta["TZ"]))}


# --- Validation (module docstring, Notes) ------------------------------------------------------

def _reason(error: Exception) -> str:
    """pvlib's or pandas' exception as a short reason."""
    if isinstance(error, KeyError):
        return f"missing {error}"
    if isinstance(error, json.JSONDecodeError):
        return f"not valid JSON: {error.msg} at line {error.lineno} column {error.colno}"
    text = str(error).strip().splitlines()
    text = text[0].split(" You might want to try")[0] if text else ""  # pandas' advice, on the next lines
    return f"{type(error).__name__}: {text}" if text else type(error).__name__


_SITE_BOUNDS = {
    "latitude": ("latitude", -90.0, 90.0, "deg"),
    "longitude": ("longitude", -180.0, 180.0, "deg"),
    "altitude": ("altitude", -math.inf, math.inf, "m"),
    "TZ": ("time zone TZ", -12.0, 14.0, "h"),
    "elevation": ("elevation", -math.inf, math.inf, "m"),
}


def _site_value(fail, where: str, key: str, raw) -> float:
    """A header's site field as a number within its bounds."""
    label, lo, hi, unit = _SITE_BOUNDS[key]
    try:
        value = float(raw)
    except (TypeError, ValueError):
        raise fail(f"{where}: {label} = {str(raw).strip()!r}: not a number") from None
    if not math.isfinite(value):
        raise fail(f"{where}: {label} = {raw}: must be a finite number")
    if not lo <= value <= hi:
        raise fail(f"{where}: {label} = {value:g} {unit}: must be in [{lo:g}, {hi:g}] {unit}")
    return value


def _check_header(fail, fmt: str, first_line: str) -> None:
    """The first line of a TMY3 or EPW file: the site's fields, as pvlib reads them."""
    names = _HEADER_FIELDS[fmt]
    kind = _FORMAT_NAMES[fmt]
    fields = first_line.rstrip("\r\n").split(",")
    if fmt == "epw" and fields[0].strip() != "LOCATION":
        raise fail(f"line 1: not an EPW header: it starts {first_line[:20]!r}, not 'LOCATION,'")
    needed = ("TZ", "latitude", "longitude", "altitude")
    missing = [key for key in needed if names.index(key) >= len(fields)]
    if missing:
        raise fail(f"line 1: the {kind} header has no {', '.join(missing)} ({len(fields)} fields; "
                   f"it holds {len(names)}: {', '.join(names)})")
    if fmt == "tmy3":
        usaf = fields[0].strip()
        if not usaf.lstrip("+-").isdigit():
            raise fail(f"line 1: USAF = {usaf[:20]!r}: not a station number, so not a TMY3 header "
                       f"({', '.join(names)})")
    for key in ("latitude", "longitude", "altitude", "TZ"):
        _site_value(fail, "line 1", key, fields[names.index(key)])


def _read_table(path: str, text: str, fmt: str, year: int, fail):
    """A TMY3 or EPW file through pvlib, and the file line of each of its rows."""
    lines = [line.rstrip("\r") for line in text.split("\n")]
    header = HEADER_LINES[fmt]
    _check_header(fail, fmt, lines[0])
    # pandas skips blank lines (whitespace only included): the rows' own line numbers.
    line_of = [n for n in range(header + 1, len(lines) + 1) if lines[n - 1].strip()]
    if not line_of:
        held = max((n for n in range(1, len(lines) + 1) if lines[n - 1].strip()), default=0)
        raise fail(f"no data rows: a {_FORMAT_NAMES[fmt]} file has {header} header lines, then one row per "
                   f"hour; this one ends at line {held}")
    # February 29: pvlib reads a TMY3 file's as March 1 (so a leap year's hours would collide), and
    # cannot coerce an EPW file's to a year without one.
    if fmt == "tmy3":
        leap = [n for n in line_of if lines[n - 1].lstrip('"').startswith("02/29/")]
        why = "pvlib reads a TMY3 file's February 29 as March 1"
    else:
        leap = [n for n in line_of if [f.strip() for f in lines[n - 1].split(",", 3)[1:3]] == ["2", "29"]]
        why = f"{year} has none" if not pd.Timestamp(year=year, month=1, day=1).is_leap_year else ""
        leap = leap if why else []
    if leap:
        raise fail(f"line {leap[0]}: February 29 ({len(leap)} rows): {why}; a typical year has 365 days, "
                   f"remove that day")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # pandas' warnings about pvlib's parsing: the checks follow
            if fmt == "tmy3":
                data, meta = pvlib.iotools.read_tmy3(path, coerce_year=year, map_variables=True)
            else:
                data, meta = pvlib.iotools.read_epw(path, coerce_year=year)
    except Exception as error:  # any failure of pvlib's reader is an unreadable file
        raise fail(f"not a readable {_FORMAT_NAMES[fmt]} file ({_reason(error)})") from error
    if len(data) == 0:
        raise fail(f"no data rows after the {header} header lines")
    index = pd.DatetimeIndex(data.index)
    last = index[-1]
    if fmt == "tmy3" and last.year == year + 1 and (last.month, last.day, last.hour, last.minute) != (1, 1, 0, 0):
        # pvlib moves the last row to the next year, right for a year's closing 24:00 only: a file
        # that ends earlier keeps its last row in the year.
        index = index[:-1].append(pd.DatetimeIndex([last.replace(year=year)]))
    if len(line_of) != len(data):
        line_of = list(range(header + 1, header + 1 + len(data)))
    line_of = np.asarray(line_of)

    def where(i: int) -> str:
        return f"line {line_of[i]}"

    return data, meta, index, where


def _read_pvgis(text: str, year: int, fail):
    """A PVGIS TMY (JSON) file through pvlib, its stamps coerced to ``year`` (still UTC)."""
    try:
        source = json.loads(text)
    except json.JSONDecodeError as error:
        raise fail(f"not valid JSON: {error.msg} at line {error.lineno} column {error.colno}") from None
    outputs = source.get("outputs") if isinstance(source, dict) else None
    hourly = outputs.get("tmy_hourly") if isinstance(outputs, dict) else None
    if not isinstance(hourly, list):
        raise fail("not a PVGIS TMY file: no outputs.tmy_hourly list of hourly records")
    if not hourly:
        raise fail("no data rows: outputs.tmy_hourly is empty")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            data, meta = pvlib.iotools.read_pvgis_tmy(io.StringIO(text), pvgis_format="json", map_variables=True)
    except Exception as error:  # any failure of pvlib's reader is an unreadable file
        raise fail(f"not a readable PVGIS TMY file ({_reason(error)})") from error
    inputs = meta.get("inputs") or {}
    location = inputs.get("location", inputs)
    for key in ("latitude", "longitude", "elevation"):
        if key not in location:
            raise fail(f"inputs.location has no {key}")
        _site_value(fail, f"inputs.location.{key}", key, location[key])
    utc = pd.DatetimeIndex(data.index)
    leap = (utc.month == 2) & (utc.day == 29)
    if leap.any() and not pd.Timestamp(year=year, month=1, day=1).is_leap_year:
        first = int(np.flatnonzero(leap)[0])
        raise fail(f"record {first + 1} ({utc[first]:%Y-%m-%d %H:%M} UTC): February 29: {year} has none"
                   + (f"; and {leap.sum() - 1} more rows" if leap.sum() > 1 else ""))
    index = pd.DatetimeIndex(utc.map(lambda t: t.replace(year=year)))

    def where(i: int) -> str:
        return f"record {i + 1}"

    return data, meta, index, where


def _checked(data: pd.DataFrame, fmt: str, index: pd.DatetimeIndex, site: dict, where, fail) -> pd.DataFrame:
    """The rows' checks (module docstring): the columns used, as floats, in file order."""
    kind = _FORMAT_NAMES[fmt]
    label = INTERVAL_LABELS[fmt]
    utc = " UTC" if fmt == "pvgis" else ""

    def at(i: int) -> str:
        start = index[i] - _HOUR if label == "end" else index[i]
        return f"{where(i)} ({start:%Y-%m-%d %H:%M}-{start + _HOUR:%H:%M}{utc})"

    def refuse(bad, describe) -> None:
        bad = np.flatnonzero(bad)
        if bad.size:
            more = f"; and {bad.size - 1} more rows" if bad.size > 1 else ""
            raise fail(f"{at(bad[0])}: {describe(bad[0])}{more}")

    for key in ("ghi", "dni", "dhi"):
        if key not in data.columns:
            source = _SOURCE_COLUMNS[fmt][key]
            place = "line 2, the column names" if fmt == "tmy3" else "outputs.tmy_hourly"
            raise fail(f"column {key} missing: no {source!r} in {place} of this {kind} file")
    # Time: hourly and strictly increasing once the year is coerced.
    step = np.diff(index.as_unit("ns").asi8)
    hour = _HOUR.value
    refuse(index.duplicated(keep="first"), lambda i: f"the same hour as {where(int(np.argmax(index == index[i])))}")
    refuse(np.r_[False, step < 0], lambda i: f"before {at(i - 1)}: rows must run forward in time")
    refuse(np.r_[False, step > hour], lambda i: f"{step[i - 1] / hour:g} h after {at(i - 1)}: rows must be hourly")
    refuse(np.r_[False, (step > 0) & (step < hour)],
           lambda i: f"{step[i - 1] / 6e10:g} min after {at(i - 1)}: rows must be hourly")
    # Values: finite numbers; a column of air temperature or wind speed may be absent altogether.
    values = {}
    for key in _COLUMNS:
        if key not in data.columns:
            values[key] = np.full(len(data), DEFAULT_TEMP_AIR if key == "temp_air" else DEFAULT_WIND_SPEED)
            continue
        raw = data[key]
        values[key] = pd.to_numeric(raw, errors="coerce").to_numpy(dtype=float)

        def not_finite(i, key=key, raw=raw):
            text = raw.iloc[i]
            if text is None or (isinstance(text, float) and math.isnan(text)) or not str(text).strip():
                return f"{key} has no value (empty or NaN)"
            return f"{key} = {str(text).strip()[:20]}: not a finite number"

        refuse(~np.isfinite(values[key]), not_finite)
    ghi, dni, dhi = values["ghi"], values["dni"], values["dhi"]

    def value(key: str, i: int) -> str:
        text = f"{key} = {values[key][i]:g} {_UNITS[key]}"
        if fmt == "epw" and values[key][i] == _EPW_MISSING[key]:
            text += " (EPW's missing-value marker)"
        return text

    # Physical bounds, at the interval centres of the file's own convention.
    centres = index + (_HOUR / 2 if label == "start" else -_HOUR / 2)
    extra = np.asarray(pvlib.irradiance.get_extra_radiation(centres.day_of_year), dtype=float)
    for key in ("ghi", "dni", "dhi"):
        refuse(values[key] < 0, lambda i, key=key: f"{value(key, i)}: must be >= 0")
    refuse(ghi > MAX_GHI_PER_EXTRA * extra,
           lambda i: f"{value('ghi', i)}: must be <= {MAX_GHI_PER_EXTRA * extra[i]:.0f} W/m^2, "
                     f"{MAX_GHI_PER_EXTRA:g} times the extraterrestrial normal irradiance that day")
    refuse(dni > MAX_DNI_PER_EXTRA * extra,
           lambda i: f"{value('dni', i)}: must be <= {MAX_DNI_PER_EXTRA * extra[i]:.0f} W/m^2, "
                     f"the extraterrestrial normal irradiance that day")
    for key, (lo, hi) in (("temp_air", TEMP_AIR_BOUNDS), ("wind_speed", WIND_SPEED_BOUNDS)):
        refuse((values[key] < lo) | (values[key] > hi),
               lambda i, key=key, lo=lo, hi=hi: f"{value(key, i)}: must be in [{lo:g}, {hi:g}] {_UNITS[key]}")
    fraction, absolute = DHI_TOLERANCE
    refuse(dhi > (1.0 + fraction) * ghi + absolute,
           lambda i: f"{value('dhi', i)} exceeds {value('ghi', i)}: the diffuse light is part of the global "
                     f"(tolerance {fraction:.0%} + {absolute:g} W/m^2)")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pvlib reads DatetimeIndex.dayofyear, deprecated by pandas
        zenith = pvlib.solarposition.get_solarposition(
            centres, site["latitude"], site["longitude"], site["altitude"])["zenith"].to_numpy(dtype=float)
    beam = dni * np.maximum(np.cos(np.radians(zenith)), 0.0)
    refuse(beam > ghi + BEAM_TOLERANCE,
           lambda i: f"{value('dni', i)} at solar zenith {zenith[i]:.1f} deg brings {beam[i]:.0f} W/m^2 to "
                     f"the ground, more than {value('ghi', i)} (tolerance {BEAM_TOLERANCE:g} W/m^2): "
                     f"is the file's site, clock or a column wrong?")
    return pd.DataFrame(values, index=index.rename(None))


def _read(path: str, fmt: str, year: int, mtime: float):
    """The checked columns of a file (module docstring), indexed by pvlib's stamps with the year
    coerced (PVGIS: on the site's standard time), and pvlib's metadata; once per file and year."""
    result, message = _read_once(path, fmt, year, mtime)
    if message is not None:
        raise WeatherError(message)
    return result


@functools.lru_cache(maxsize=8)
def _read_once(path: str, fmt: str, year: int, mtime: float):
    """:func:`_read`'s result, or its error message: a study validates its file once per value of
    every axis, and a bad file must not be read again each time."""
    try:
        return _read_checked(path, fmt, year), None
    except WeatherError as error:
        return None, error.errors[0]


def _read_checked(path: str, fmt: str, year: int):
    def fail(message: str) -> WeatherError:
        return WeatherError(f"weather {Path(path).name}: {message}")

    try:
        text = Path(path).read_bytes().decode("utf-8", errors="replace")
    except OSError as error:
        raise fail(f"cannot be read ({error.strerror or error})") from None
    if not text.strip():
        raise fail("the file is empty")
    if fmt == "pvgis":
        data, meta, index, where = _read_pvgis(text, year, fail)
    else:
        data, meta, index, where = _read_table(path, text, fmt, year, fail)
    site = _site_of(fmt, meta)
    frame = _checked(data, fmt, index, site, where, fail)
    if fmt == "pvgis":
        # PVGIS stamps are UTC: on the site's standard time, with the year wrapped around (a TMY
        # is a cyclic year) so that every local day is whole.
        local = frame.index.tz_convert(site["timezone"])
        frame.index = pd.DatetimeIndex(local.map(lambda t: t.replace(year=year)))
        frame = frame.sort_index()
    return frame, meta


def weather_site(path, fmt: str | None = None) -> dict:
    """The site a weather file describes, from its header: ``name``, ``latitude``, ``longitude``
    [deg], ``altitude`` [m] and ``timezone`` (the fixed offset its timestamps keep).

    Raises :class:`WeatherError` if the file fails any check (module docstring)."""
    path = Path(path)
    fmt = weather_format(path, fmt)
    _, meta = _read(str(path.resolve()), fmt, 2025, path.stat().st_mtime)
    return _site_of(fmt, meta)


def read_weather(path, fmt: str | None = None, year: int = 2025, label: str | None = None) -> pd.DataFrame:
    """Weather as ``ghi``, ``dni``, ``dhi`` [W/m^2], ``temp_air`` [C], ``wind_speed`` [m/s].

    Indexed by tz-aware interval centres (the file's own time zone), years coerced to ``year``.
    ``label`` (``start``, ``end`` or ``centre``) overrides the format's timestamp convention. A file
    without any air temperature or wind speed column gets :data:`DEFAULT_TEMP_AIR` and
    :data:`DEFAULT_WIND_SPEED`; nothing else is filled in. The frame's ``attrs["weather"]`` holds the
    file's name, for :func:`weather_days`' messages.

    Raises :class:`WeatherError` if the file fails any check (module docstring).
    """
    path = Path(path)
    fmt = weather_format(path, fmt)
    # A typical year has 365 days: it is read as a year without February 29, then its interval
    # centres move to ``year``, so that a leap year's February 29 is a day the file does not hold.
    typical = year - 1 if pd.Timestamp(year=year, month=1, day=1).is_leap_year else year
    data, _ = _read(str(path.resolve()), fmt, typical, path.stat().st_mtime)
    label = label or INTERVAL_LABELS[fmt]
    shift = {"end": -_HOUR / 2, "start": _HOUR / 2, "centre": _HOUR * 0}[label]
    index = data.index + shift
    if typical != year:
        index = pd.DatetimeIndex(index.map(lambda t: t.replace(year=t.year + year - typical)))
    frame = pd.DataFrame({key: data[key].to_numpy(copy=True) for key in _COLUMNS}, index=index)
    frame = frame.sort_index()
    frame.attrs["weather"] = path.name
    return frame


def weather_days(frame: pd.DataFrame, dates) -> np.ndarray:
    """Row numbers of ``frame`` whose interval centres fall on each of ``dates`` (local to the
    file), (n_dates, n_steps).

    Raises :class:`WeatherError` (naming the file of ``frame.attrs["weather"]``) unless the file
    holds every date, whole: the first missing dates and their count, or a date with fewer rows
    than a day has (a truncated day), and the span of dates the file holds.
    """
    source = frame.attrs.get("weather")
    prefix = f"weather {source}: " if source else "weather: "
    days = frame.index.tz_localize(None).to_numpy().astype("datetime64[D]")
    if days.size == 0:
        raise WeatherError(f"{prefix}no rows")
    held = f"the file holds {days[0]} to {days[-1]}"
    wanted = np.array(dates, dtype="datetime64[D]")
    start, stop = np.searchsorted(days, wanted, side="left"), np.searchsorted(days, wanted, side="right")
    missing = [str(date) for date, a, b in zip(wanted, start, stop, strict=True) if a == b]
    if missing:
        leap = " (a typical year has no February 29)" if any(d.endswith("-02-29") for d in missing) else ""
        raise WeatherError(f"{prefix}no data for {', '.join(missing[:3])}"
                           + (f" and {len(missing) - 3} more dates" if len(missing) > 3 else "") + f"; {held}{leap}")
    step = pd.Series(frame.index).diff().median() if len(frame) > 1 else pd.NaT
    per_day = round(pd.Timedelta(days=1) / step) if pd.notna(step) and step > pd.Timedelta(0) else None
    counts = stop - start
    full = per_day if per_day else int(counts.max())
    short = [(str(date), int(n)) for date, n in zip(wanted, counts, strict=True) if n != full]
    if short:
        raise WeatherError(f"{prefix}{short[0][0]} holds {short[0][1]} rows, a whole day {full}"
                           + (f"; and {len(short) - 1} more dates" if len(short) > 1 else "") + f"; {held}")
    return start[:, None] + np.arange(full)


def weather_day(frame: pd.DataFrame, date) -> pd.DataFrame:
    """The intervals of ``frame`` whose centres fall on ``date`` (local to the file)."""
    return frame.iloc[weather_days(frame, [date])[0]]


def sub_hourly(means, clear, steps_per_interval: int, max_index: float = MAX_CLEARSKY_INDEX):
    """Irradiance at every step from interval means, by the clear-sky index (module docstring).

    Parameters
    ----------
    means : array_like
        (n_days, n_intervals) mean irradiance of each interval [W/m^2] (one component: GHI, DNI
        or DHI).
    clear : array_like
        (n_days, n_intervals * steps_per_interval) the clear sky's same component at the steps.
    steps_per_interval : int
        Steps in an interval; the steps fill the intervals in order.
    max_index : float, default 2
        Bound of the index at every step.

    Returns
    -------
    values : numpy.ndarray
        (n_days, n_steps) [W/m^2]: zero wherever the clear sky is, at most ``max_index`` times
        it, and with each interval's mean equal to the file's (to rounding), but where the clear
        sky is dark all interval long or the bound cuts in.
    placed : numpy.ndarray
        (n_days, n_intervals) the interval means the steps keep [W/m^2].
    """
    means = np.asarray(means, dtype=float)
    clear = np.asarray(clear, dtype=float)
    n_days, n_intervals = means.shape
    clear_mean = clear.reshape(n_days, n_intervals, steps_per_interval).mean(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        index = np.asarray(pvlib.irradiance.clearsky_index(means, clear_mean, max_index), dtype=float)
    # Dark intervals take the nearest lit interval's index, so the index does not ramp down toward
    # them inside a lit one; their own light is zero whatever the index.
    lit = clear_mean > 0
    positions = np.arange(n_intervals)
    before = np.maximum.accumulate(np.where(lit, positions, -1), axis=1)
    after = np.flip(np.minimum.accumulate(np.flip(np.where(lit, positions, n_intervals), axis=1), axis=1), axis=1)
    nearest = np.where(before >= 0, before, np.where(after < n_intervals, after, 0))
    index = np.where(lit, index, np.take_along_axis(index, nearest, axis=1) * lit.any(axis=1, keepdims=True))
    # Linear between interval centres, held beyond the first and the last.
    centres = (positions + 0.5) * steps_per_interval - 0.5
    steps = np.arange(n_intervals * steps_per_interval)
    right = np.clip(np.searchsorted(centres, steps, side="right"), 1, n_intervals - 1)
    weight = np.clip((steps - centres[right - 1]) / steps_per_interval, 0.0, 1.0)
    values = (index[:, right - 1] * (1.0 - weight) + index[:, right] * weight) * clear
    # Each interval keeps its mean, then the bound holds at every step.
    shaped = values.reshape(n_days, n_intervals, steps_per_interval)
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.where(shaped.mean(axis=-1) > 0, means / shaped.mean(axis=-1), 0.0)
    values = np.minimum(shaped * scale[..., None], max_index * clear.reshape(shaped.shape))
    return values.reshape(n_days, -1), values.mean(axis=-1)


def clear_sky(times, apparent_zenith, latitude, longitude, altitude, model="ineichen", linke_turbidity=None):
    """pvlib clear-sky ``ghi``, ``dni``, ``dhi`` [W/m^2] at ``times``.

    ``ineichen`` takes ``linke_turbidity``, or looks it up in pvlib's bundled climatology (offline);
    ``simplified-solis`` uses its defaults (aerosol optical depth 0.1, precipitable water 1 cm).
    """
    if model == "ineichen":
        turbidity = linke_turbidity
        if turbidity is None:
            with warnings.catch_warnings():
                # pvlib reads DatetimeIndex.dayofyear, which pandas 3 deprecates; not ours to fix.
                warnings.simplefilter("ignore", DeprecationWarning)
                warnings.simplefilter("ignore", FutureWarning)
                turbidity = pvlib.clearsky.lookup_linke_turbidity(times, latitude, longitude).to_numpy()
        airmass = pvlib.atmosphere.get_absolute_airmass(
            pvlib.atmosphere.get_relative_airmass(apparent_zenith), pvlib.atmosphere.alt2pres(altitude)
        )
        dni_extra = np.asarray(pvlib.irradiance.get_extra_radiation(times.day_of_year), dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):  # night: zero air mass terms
            sky = pvlib.clearsky.ineichen(apparent_zenith, airmass, turbidity, altitude, dni_extra)
    elif model == "simplified-solis":
        sky = pvlib.clearsky.simplified_solis(90.0 - np.asarray(apparent_zenith), pressure=pvlib.atmosphere.alt2pres(altitude))
    else:
        raise ValueError(f"clear sky must be one of {', '.join(CLEAR_SKIES)}; got {model!r}")
    return {key: np.nan_to_num(np.asarray(sky[key], dtype=float)) for key in ("ghi", "dni", "dhi")}
