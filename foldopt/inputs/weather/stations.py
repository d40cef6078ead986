"""The readers of measured sub-hourly weather files, one per station network, and their registry.

:data:`STATION_FORMATS` names each format's :class:`StationFormat`: a pvlib.iotools reader [1]_
wrapped to return the columns foldopt uses (:class:`StationData`), with what the network's
timestamps mark. :func:`foldopt.inputs.weather.measured.read_measured` turns them into a
study's weather. What each reader takes from its file:

* ``surfrad``: NOAA SURFRAD daily files [2]_ through ``read_surfrad``: 1-min means (3-min before
  2009) of ``ghi``, ``dni``, ``dhi``, ``temp_air`` (10 m) and ``wind_speed``, stamped in UTC at the
  end of each minute, and the site in the header. A value whose QC flag is not 0 is dropped
  (SURFRAD flags 1 the physically impossible, 2 and up the improbable [2]_); -9999.9 is
  missing (pvlib). Older files write west longitudes positive (Alamosa, 105.92 in
  ``surfrad-slv16001.dat``): the sign that fits the file's own solar zenith column is taken.
* ``midc``: NREL MIDC daily or raw files [3]_ through ``read_midc``: columns as pvlib's
  ``MIDC_VARIABLE_MAP`` names them for the station whose names the file holds most of, else the
  first ``Global``, ``Direct`` and ``Diffuse`` [W/m^2], air temperature and mean wind speed
  columns; -7999 and below are missing. Stamps on the standard time the time column names. The
  file holds no site.
* ``srml``: University of Oregon SRML archival files [4]_ through ``read_srml``: the first
  instrument of elements 100 (``ghi``), 201 (``dni``), 300 (``dhi``), 930 (``temp_air``) and 921
  (``wind_speed``); flag 99 is missing (pvlib). Pacific standard time. No site in the file.
* ``bsrn``: BSRN station-to-archive files [5]_ through ``read_bsrn``: LR0100's 1-min means of
  ``ghi``, ``dni``, ``dhi`` and ``temp_air``, the site from LR0004; -999 and -99.9 are missing.
* ``solrad``: NOAA SOLRAD daily files [6]_ through ``read_solrad``: 1-min means (3-min before
  2015) of ``ghi``, ``dni``, ``dhi``, UTC at the end of each minute, values flagged by the
  network's QC dropped, the site and its standard time in the header.
* ``crn``: NOAA USCRN sub-hourly files [7]_ through ``read_crn``: 5-min means of ``ghi``
  (photodiode), ``temp_air`` and ``wind_speed`` (1.5 m), flagged values dropped, the site's
  coordinates in every row, its standard time from the local and UTC stamps, its altitude from
  pvlib ``location.lookup_altitude`` (the file has none).
* ``csv``: foldopt's generic CSV: a header row naming ``timestamp`` (ISO 8601, every stamp with a
  UTC offset or none, then on ``timezone``), ``ghi``, ``dni``, ``dhi`` (one or two may be
  absent), optionally ``temp_air`` and ``wind_speed``, in any order and case, other columns
  ignored; empty or ``NaN`` cells are missing; lines starting with ``#`` are comments. Stamps mark
  interval ends unless ``label`` says otherwise. No site in the file.
* ``pvgis-hourly``: PVGIS's hourly series (``seriescalc``, JSON) of a horizontal plane [8]_
  through ``read_pvgis_hourly``: real hours of real years, the site in ``inputs.location``, UTC
  stamps. An answer with the components (``components=1``): ``ghi`` their sum
  ``Gb(i) + Gd(i) + Gr(i)`` (``Gr(i)`` is 0 on a horizontal plane), ``dhi`` ``Gd(i)``, so that
  ``dni`` follows by closure from ``Gb(i)`` and the sun's elevation; an answer of ``G(i)``
  alone (asked without components, or an older service): ``ghi`` only, ``dni`` and ``dhi`` then
  by the decomposition a measured file of ``ghi`` alone gets (Erbs by default). ``T2m`` and
  ``WS10m`` (10 m). A tilted or tracking plane's series is refused: its ``G(i)`` is no ``ghi``.

What the stamps mark (``interval_label``): CRN, interval end (pvlib's ``read_crn``); BSRN, the
start ("All time labels in the station-to-archive files denote the start of a time interval",
GCOS-174, quoted by pvlib's ``read_bsrn``); SRML, the end ("the ending time of the measurement"
[4]_), which pvlib moves back one interval, so its stamps mark the start; SURFRAD and SOLRAD,
whose documents do not say, the end: their files' solar zenith column is pvlib's apparent zenith
30 s before each stamp, the middle of the minute that ends there (within 0.03 deg below 80 deg
on ``surfrad-slv16001.dat`` and ``abq19056.dat``, 0.1 deg off at the stamp itself); MIDC, the
end: its stations log on Campbell Scientific CR1000 loggers (``midc_raw_20181018.txt`` holds
their temperature and battery columns), which stamp a table's record at the end of its
interval; the generic CSV, the end, like most loggers; PVGIS's hourly series, the start of its
hour: its satellite values (PVGIS-SARAH) are instantaneous at their stamp (HH:10 over Europe), as
pvlib's ``get_pvgis_hourly`` notes (its ``H_sun`` is the sun's elevation then), and each stands
for the hour it falls in, HH:00 to HH:60, as in PVGIS's own hourly PV energy: the reader moves
the stamps to their hour's start (a study's steps are centred on the half hour), a note says so.
``label`` overrides.

References
----------
.. [1] pvlib.iotools.read_surfrad, read_midc, read_srml, read_bsrn, read_solrad, read_crn.
.. [2] NOAA GML, "Description of SURFRAD daily data files" (README_SURFRAD.txt).
.. [3] NREL Measurement and Instrumentation Data Center, https://midcdmz.nrel.gov/.
.. [4] UO SRML, "Archival (short interval) data files",
   http://solardat.uoregon.edu/ArchivalFiles.html.
.. [5] GCOS-174, "Update of the Technical Plan for BSRN Data Management", 2013.
.. [6] NOAA GML, "Description of SOLRAD daily data files" (README_SOLRAD.txt).
.. [7] H. J. Diamond et al., "U.S. Climate Reference Network after one decade of operations",
   Bull. Amer. Meteor. Soc. 94, 489-498, 2013.
.. [8] European Commission JRC, "PVGIS: hourly radiation" (``seriescalc``),
   https://joint-research-centre.ec.europa.eu/pvgis-online-tool/pvgis-tools/hourly-radiation_en.
"""

from __future__ import annotations

import datetime
import io
import re
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from foldopt.errors import printable
from foldopt.inputs.weather.formats import read_with_pvlib, reason
from foldopt.inputs.weather.pvgis import answer_records
from foldopt.inputs.weather.qc import COLUMNS

#: MIDC's missing-value marker: values at or below it are missing.
MIDC_MISSING = -7999.0


@dataclass(frozen=True)
class StationFormat:
    """One format of :data:`STATION_FORMATS`.

    Parameters
    ----------
    name : str
        As ``read_measured``'s ``fmt`` names it (``surfrad``).
    interval_label : {'start', 'end', 'centre'}
        Which edge of its interval a stamp marks, as the reader returns it (module docstring).
    reader : callable
        ``reader(path, fail, zone)``: the file as a :class:`StationData`; ``zone`` [h] is the UTC
        offset of stamps that carry none (the CSV's), ``fail(message)`` makes the error to raise.
    has_site : bool
        Whether the file holds its site's latitude and longitude.
    signature : str
        A regular expression its files' first lines match, to tell the format of a file read as
        another (:func:`foldopt.inputs.weather.reader.sniff_format`).
    """

    name: str
    interval_label: str
    reader: Callable
    has_site: bool
    signature: str


@dataclass(frozen=True)
class StationData:
    """What a reader takes from a file.

    Parameters
    ----------
    frame : pandas.DataFrame
        Some of :data:`COLUMNS` as floats (NaN where missing or dropped), indexed by the file's
        stamps, tz-aware, in file order.
    site : dict
        What the file says of its site: ``name``, ``latitude``, ``longitude`` [deg],
        ``altitude`` [m]; empty if nothing.
    zone : float or None
        The UTC offset [h] of the site's standard time, if the file tells it.
    dropped : int
        Values the network's own QC flags marked bad, made missing.
    notes : tuple of str
        One-line remarks for the study's notes.
    """

    frame: pd.DataFrame
    site: dict = field(default_factory=dict)
    zone: float | None = None
    dropped: int = 0
    notes: tuple = ()


def _columns(
    data: pd.DataFrame, names: dict, fail, flags: dict | None = None
) -> tuple[pd.DataFrame, int]:
    """``names`` (column -> pvlib's column) of ``data`` as floats, values whose ``flags``
    (column -> flag column) are not 0 made missing, and how many were; a cell that is no number
    (a word where a value or a flag belongs) is refused, as the generic CSV's reader refuses it."""
    frame, dropped = {}, 0
    for key, source in names.items():
        if source not in data.columns:
            continue
        values = _numbers(data, source, key, fail)
        flag = (flags or {}).get(key)
        if flag in data.columns:
            marks = _numbers(data, flag, flag, fail)
            bad = (np.nan_to_num(marks) != 0) & np.isfinite(values)
            dropped += int(bad.sum())
            values = np.where(bad, np.nan, values)
        frame[key] = values
    return pd.DataFrame(frame, index=pd.DatetimeIndex(data.index)), dropped


#: Cells a reader leaves as text that mean "no value".
_BLANK = ("", "nan", "na", "null")


def _numbers(data: pd.DataFrame, source: str, key: str, fail) -> np.ndarray:
    """Column ``source`` of ``data`` as floats (NaN where pvlib left none); a cell that is text but
    no number is refused, naming its row and stamp."""
    column = data[source]
    numbers = pd.to_numeric(column, errors="coerce")
    if not pd.api.types.is_numeric_dtype(column):
        text = column.astype(str).str.strip()
        bad = np.flatnonzero(
            numbers.isna().to_numpy()
            & column.notna().to_numpy()
            & ~text.str.lower().isin(_BLANK).to_numpy()
        )
        if bad.size:
            more = f"; and {bad.size - 1} more rows" if bad.size > 1 else ""
            stamp = pd.Timestamp(data.index[bad[0]]).isoformat(sep=" ")
            raise fail(
                f"row {bad[0] + 1} (stamped {stamp}): {key} = {text.iloc[bad[0]][:20]!r}: not a number{more}"
            )
    return numbers.to_numpy(dtype=float)


def _hours(stamp: pd.Timestamp) -> float:
    return stamp.utcoffset().total_seconds() / 3600.0


def read_surfrad(path: str, fail, zone=None) -> StationData:
    """A SURFRAD daily file (module docstring).

    Parameters
    ----------
    path : str
    fail : callable
        ``fail(message)``: the error to raise.
    zone : float, optional
        Unused: the stamps are UTC.

    Returns
    -------
    StationData
    """
    data, meta = read_with_pvlib(fail, "SURFRAD", "read_surfrad", path)
    names = {key: key for key in COLUMNS}
    frame, dropped = _columns(data, names, fail, {key: f"{key}_flag" for key in COLUMNS})
    latitude, longitude = float(meta["latitude"]), float(meta["longitude"])
    notes = ()
    if longitude > 0 and "solar_zenith" in data.columns:
        # The file's zenith is pvlib's apparent zenith at the middle of each minute: the sign of
        # the longitude that fits it is the file's.
        zenith = pd.to_numeric(data["solar_zenith"], errors="coerce").to_numpy(dtype=float)
        pick = np.flatnonzero(np.isfinite(zenith) & (zenith < 85.0))[::30]
        if pick.size:
            times = pd.DatetimeIndex(data.index[pick]) - pd.Timedelta(seconds=30)
            error = [
                np.nanmean(np.abs(_zenith(times, latitude, lon) - zenith[pick]))
                for lon in (longitude, -longitude)
            ]
            if error[1] < error[0]:
                notes = (
                    f"the file's longitude {longitude:g} is degrees west (its solar zenith column says so): "
                    f"read as {-longitude:g}",
                )
                longitude = -longitude
    site = {
        "name": str(meta.get("name") or "").strip() or None,
        "latitude": latitude,
        "longitude": longitude,
        "altitude": float(meta["elevation"]),
    }
    return StationData(frame, site, None, dropped, notes)


def _zenith(times, latitude, longitude) -> np.ndarray:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import pvlib

        position = pvlib.solarposition.get_solarposition(times, latitude, longitude)
    return position["apparent_zenith"].to_numpy(dtype=float)


#: MIDC columns by pattern, where pvlib's ``MIDC_VARIABLE_MAP`` names none: the first match wins.
MIDC_PATTERNS = {
    "ghi": r"^Global(?!.*(?:Accumulated|stdev|tracker)).*\[W/m\^2\]$",
    "dni": r"^Direct(?!.*(?:stdev|Accumulated)).*\[W/m\^2\]$",
    "dhi": r"^Diffuse(?!.*(?:stdev|Accumulated)).*\[W/m\^2\]$",
    "temp_air": r"^(?:Air Temperature|Tower Dry Bulb Temp|Dry Bulb Temp|Temperature @ ?[\d.]+ ?(?:m|ft))\b.*\[deg C\]$",
    "wind_speed": r"^Avg Wind Speed.*\[m/s\]$",
}


def read_midc(path: str, fail, zone=None) -> StationData:
    """An NREL MIDC daily or raw-data file (module docstring).

    Parameters
    ----------
    path : str
    fail : callable
        ``fail(message)``: the error to raise.
    zone : float, optional
        Unused: the time column names the zone.

    Returns
    -------
    StationData
    """
    try:
        header = pd.read_csv(path, nrows=0).columns
    except Exception as error:  # any failure of pandas is an unreadable file
        raise fail(f"not a readable MIDC file ({reason(error)})") from error
    raw = "DOY" in header and "Year" in header
    # A raw file's header may name fewer columns than its rows hold: read those it names.
    data = read_with_pvlib(
        fail, "MIDC", "read_midc", path, raw_data=raw, usecols=range(len(header)) if raw else None
    )
    columns = [str(name) for name in data.columns]
    import pvlib

    maps = pvlib.iotools.midc.MIDC_VARIABLE_MAP.values()
    best = max(maps, key=lambda names: sum(name in columns for name in names))
    names = {}
    for source, target in best.items():
        key = {"dni_chp1": "dni", "dni_nip": "dni"}.get(target, target)
        if source in columns and key in COLUMNS and key not in names:
            names[key] = source
    for key, pattern in MIDC_PATTERNS.items():
        if key not in names:
            names[key] = next((name for name in columns if re.search(pattern, name)), None)
    names = {key: source for key, source in names.items() if source is not None}
    frame, _ = _columns(data, names, fail)
    frame = frame.where(frame > MIDC_MISSING)
    used = ", ".join(f"{key} {source!r}" for key, source in names.items())
    return StationData(
        frame,
        {},
        _hours(frame.index[0]) if len(frame) else None,
        0,
        (f"MIDC columns read: {used or 'none of foldopt'}",),
    )


def read_srml(path: str, fail, zone=None) -> StationData:
    """A UO SRML archival file (module docstring).

    Parameters
    ----------
    path : str
    fail : callable
        ``fail(message)``: the error to raise.
    zone : float, optional
        Unused: the stamps are Pacific standard time.

    Returns
    -------
    StationData
    """
    data = read_with_pvlib(fail, "SRML", "read_srml", path)
    names = {}
    for key in COLUMNS:
        found = sorted(
            (column for column in map(str, data.columns) if re.fullmatch(rf"{key}_\d+", column)),
            key=lambda column: int(column.rsplit("_", 1)[1]),
        )
        if found:
            names[key] = found[0]
    frame, _ = _columns(data, names, fail)
    return StationData(
        frame,
        {},
        _hours(frame.index[0]) if len(frame) else None,
        0,
        (f"SRML columns read: {', '.join(f'{k} {v!r}' for k, v in names.items())}",),
    )


def read_bsrn(path: str, fail, zone=None) -> StationData:
    """A BSRN station-to-archive file's LR0100 (module docstring).

    Parameters
    ----------
    path : str
    fail : callable
        ``fail(message)``: the error to raise.
    zone : float, optional
        Unused: the stamps are UTC.

    Returns
    -------
    StationData
    """
    data, meta = read_with_pvlib(fail, "BSRN", "read_bsrn", path)
    if len(data) == 0 or "latitude" not in meta:
        raise fail(
            "no LR0100 record (basic measurements) and station LR0004: not a BSRN station-to-archive file"
        )
    frame, _ = _columns(data, {key: key for key in ("ghi", "dni", "dhi", "temp_air")}, fail)
    number = meta.get("station identification number")
    site = {
        "name": f"BSRN station {number}" if number is not None else None,
        "latitude": float(meta["latitude"]),
        "longitude": float(meta["longitude"]),
        "altitude": float(meta["altitude"]),
    }
    return StationData(frame, site)


def read_solrad(path: str, fail, zone=None) -> StationData:
    """A SOLRAD daily file (module docstring).

    Parameters
    ----------
    path : str
    fail : callable
        ``fail(message)``: the error to raise.
    zone : float, optional
        Unused: the stamps are UTC.

    Returns
    -------
    StationData
    """
    data, meta = read_with_pvlib(fail, "SOLRAD", "read_solrad", path)
    frame, dropped = _columns(
        data,
        {key: key for key in ("ghi", "dni", "dhi")},
        fail,
        {key: f"{key}_flag" for key in ("ghi", "dni", "dhi")},
    )
    site = {
        "name": str(meta.get("station_name") or "").strip() or None,
        "latitude": float(meta["latitude"]),
        "longitude": float(meta["longitude"]),
        "altitude": float(meta["altitude"]),
    }
    return StationData(frame, site, float(meta["TZ"]), dropped)


def read_crn(path: str, fail, zone=None) -> StationData:
    """A USCRN sub-hourly file (module docstring).

    Parameters
    ----------
    path : str
    fail : callable
        ``fail(message)``: the error to raise.
    zone : float, optional
        Unused: the stamps are UTC.

    Returns
    -------
    StationData
    """
    data = read_with_pvlib(fail, "CRN", "read_crn", path)
    if len(data) == 0:
        raise fail("no data rows")
    frame, dropped = _columns(
        data,
        {"ghi": "ghi", "temp_air": "temp_air", "wind_speed": "wind_speed"},
        fail,
        {"ghi": "ghi_flag", "wind_speed": "wind_speed_flag"},
    )
    first = data.iloc[0]
    latitude, longitude = float(first["latitude"]), float(first["longitude"])
    local = pd.to_datetime(
        f"{int(first['LST_DATE'])}{int(first['LST_TIME']):04d}", format="%Y%m%d%H%M"
    )
    utc = pd.Timestamp(data.index[0]).tz_localize(None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import pvlib

        altitude = float(pvlib.location.lookup_altitude(latitude, longitude))
    site = {
        "name": f"USCRN station {first['WBANNO']}",
        "latitude": latitude,
        "longitude": longitude,
        "altitude": altitude,
    }
    notes = (
        f"altitude {altitude:g} m from pvlib location.lookup_altitude (a CRN file holds none); "
        "wind speed measured 1.5 m above ground",
    )
    return StationData(frame, site, (local - utc).total_seconds() / 3600.0, dropped, notes)


_OFFSET = re.compile(r"(?:Z|[+-]\d{2}(?::?\d{2})?)$")
_TIME = re.compile(r"[T ]\d{1,2}:\d{2}")


def read_csv(path: str, fail, zone=None) -> StationData:
    """foldopt's generic measured CSV (module docstring).

    Parameters
    ----------
    path : str
    fail : callable
        ``fail(message)``: the error to raise.
    zone : float, optional
        The UTC offset [h] of stamps that carry none.

    Returns
    -------
    StationData
    """
    try:
        table = pd.read_csv(
            path, dtype=str, comment="#", skipinitialspace=True, keep_default_na=False
        )
    except Exception as error:  # any failure of pandas is an unreadable file
        raise fail(f"not a readable CSV file ({reason(error)})") from error
    named = {str(column).strip().lower(): column for column in table.columns}
    if "timestamp" not in named:
        held = printable(", ".join(str(column) for column in table.columns[:8]), 120)
        raise fail(
            f"no timestamp column: a measured CSV file's header names timestamp, ghi, dni, dhi and optionally "
            f"temp_air, wind_speed; this one names {held or 'nothing'}"
        )
    if len(table) == 0:
        raise fail("no data rows after the header")
    text = table[named["timestamp"]].str.strip()

    def refuse(bad, describe) -> None:
        bad = np.flatnonzero(np.asarray(bad))
        if bad.size:
            more = f"; and {bad.size - 1} more rows" if bad.size > 1 else ""
            raise fail(f"row {bad[0] + 1}: {describe(bad[0])}{more}")

    refuse(
        ~text.str.contains(_TIME),
        lambda i: f"timestamp = {text.iloc[i][:30]!r}: not an ISO 8601 date and time",
    )
    # The offset: of a stamp's time, after its clock time (a date's own dashes are no offset).
    offset = text.str.split(r"[T ]", n=1, regex=True).str[-1].str.contains(_OFFSET)
    aware = bool(offset.iloc[0])
    refuse(
        offset != aware,
        lambda i: (
            f"timestamp {text.iloc[i][:40]!r} {'has no' if aware else 'has a'} UTC offset, "
            f"unlike row 1's: give every stamp an offset or none"
        ),
    )
    stamps = pd.to_datetime(text, format="ISO8601", utc=aware, errors="coerce")
    refuse(
        stamps.isna(), lambda i: f"timestamp = {text.iloc[i][:30]!r}: not an ISO 8601 date and time"
    )
    if aware:
        file_zone = _hours(pd.Timestamp(text.iloc[0]))
        index = pd.DatetimeIndex(stamps).tz_convert(fixed_zone(file_zone))
    else:
        if zone is None:
            raise fail(
                "the timestamps carry no UTC offset: give timezone, a fixed offset like 'UTC-07:00'"
            )
        file_zone = zone
        index = pd.DatetimeIndex(stamps).tz_localize(fixed_zone(zone))
    values = {}
    for key in COLUMNS:
        if key not in named:
            continue
        cells = table[named[key]].str.strip()
        numbers = pd.to_numeric(cells, errors="coerce")
        blank = cells.str.lower().isin(("", "nan", "na", "null"))
        refuse(
            numbers.isna() & ~blank,
            lambda i, key=key, cells=cells: f"{key} = {cells.iloc[i][:20]!r}: not a number",
        )
        values[key] = numbers.to_numpy(dtype=float)
    return StationData(pd.DataFrame(values, index=index), {}, file_zone)


def read_pvgis_hourly(path: str, fail, zone=None) -> StationData:
    """A PVGIS hourly series of a horizontal plane, JSON (module docstring).

    Parameters
    ----------
    path : str
    fail : callable
        ``fail(message)``: the error to raise.
    zone : float, optional
        Unused: the stamps are UTC.

    Returns
    -------
    StationData
    """
    with open(path, encoding="utf-8", errors="replace") as handle:
        text = handle.read()
    source, hourly = answer_records(text, "hourly", "a PVGIS hourly series", fail)
    if not hourly:
        raise fail("not a PVGIS hourly series: no outputs.hourly list of hourly records")
    inputs = source.get("inputs") if isinstance(source.get("inputs"), dict) else {}
    mounting = inputs.get("mounting_system") or {}
    slope = (mounting.get("fixed") or {}).get("slope") if isinstance(mounting, dict) else None
    tilt = slope.get("value") if isinstance(slope, dict) else None
    if not isinstance(tilt, (int, float)) or tilt != 0:
        plane = f"a plane tilted {tilt} deg" if isinstance(tilt, (int, float)) else "no fixed plane"
        raise fail(
            f"inputs.mounting_system: {plane}; foldopt reads the horizontal plane's series "
            "(seriescalc with angle=0), whose G(i) is the global horizontal light"
        )
    data, _ = read_with_pvlib(
        fail,
        "PVGIS hourly series",
        "read_pvgis_hourly",
        io.StringIO(text),
        pvgis_format="json",
        map_variables=True,
    )
    parts = [key for key in ("poa_direct", "poa_sky_diffuse", "poa_ground_diffuse") if key in data]
    if {"poa_direct", "poa_sky_diffuse"} <= set(parts):
        columns = {"ghi": parts, "dhi": ["poa_sky_diffuse"]}
        note = (
            "PVGIS hourly series with its components: ghi = Gb(i) + Gd(i) + Gr(i), dhi = Gd(i), "
            "dni by closure from Gb(i) and the sun's elevation"
        )
    elif "poa_global" in data:
        columns = {"ghi": ["poa_global"]}
        note = (
            "PVGIS hourly series of G(i) alone (no beam and diffuse components in the answer): "
            "dni and dhi are estimated from ghi by a decomposition model, not PVGIS's own"
        )
    else:
        raise fail("outputs.hourly holds neither G(i) nor Gb(i) and Gd(i)")
    frame = {}
    for key, names in {**columns, "temp_air": ["temp_air"], "wind_speed": ["wind_speed"]}.items():
        if all(name in data for name in names):
            frame[key] = sum(_numbers(data, name, key, fail) for name in names)
    location = inputs.get("location") if isinstance(inputs.get("location"), dict) else {}
    missing = [key for key in ("latitude", "longitude", "elevation") if key not in location]
    if missing:
        raise fail(f"inputs.location has no {', '.join(missing)}")
    site = {
        "name": None,
        "latitude": location["latitude"],
        "longitude": location["longitude"],
        "altitude": location["elevation"],
    }
    meteo = inputs.get("meteo_data") if isinstance(inputs.get("meteo_data"), dict) else {}
    databases = ", ".join(
        str(meteo[key]) for key in ("radiation_db", "meteo_db") if meteo.get(key) is not None
    )
    notes = [note + (f" ({printable(databases, 60)})" if databases else "")]
    if "Int" in data and (data["Int"] != 0).any():
        notes.append(
            f"{int((data['Int'] != 0).sum())} hours of light PVGIS reconstructed (Int = 1)"
        )
    stamps = pd.DatetimeIndex(data.index)
    if (stamps != stamps.floor("h")).any():
        minute = int(stamps[0].minute)
        notes.append(
            f"PVGIS's stamps (:{minute:02d} past each hour, the satellite's instant) taken as the "
            "hour they fall in, as PVGIS's own hourly sums take them"
        )
    frame = pd.DataFrame(frame, index=stamps.floor("h"))
    return StationData(frame, site, notes=tuple(notes))


def fixed_zone(hours: float) -> datetime.timezone:
    """The fixed-offset time zone of a UTC offset.

    Parameters
    ----------
    hours : float
        The offset [h], to the minute.

    Returns
    -------
    datetime.timezone
    """
    return datetime.timezone(datetime.timedelta(minutes=round(hours * 60)))


#: The measured weather formats by name, in the order of :data:`foldopt.names.WEATHER_FORMATS`
#: (whose descriptions help and the docs print).
STATION_FORMATS = {
    entry.name: entry
    for entry in (
        # SURFRAD's and SOLRAD's second line: latitude, longitude, elevation (SURFRAD "m", SOLRAD its
        # UTC offset), "version"; MIDC's header, daily or raw; SRML's: station, year, elements, by tabs;
        # BSRN's first record; CRN's rows: WBAN, UTC date and time, local date and time.
        StationFormat(
            "surfrad",
            "end",
            read_surfrad,
            True,
            r"\A[^\n]*\n\s*-?[\d.]+\s+-?[\d.]+\s+\d+\s+m\s+version",
        ),
        StationFormat(
            "midc", "end", read_midc, False, r"\A(?:DATE \(MM/DD/YYYY\),|[^\n]*\bYear,DOY,)"
        ),
        StationFormat("srml", "start", read_srml, False, r"\A\d+\t\d{4}\t"),
        StationFormat("bsrn", "start", read_bsrn, True, r"\A\*[CU]0001"),
        StationFormat(
            "solrad",
            "end",
            read_solrad,
            True,
            r"\A[^\n]*\n\s*-?[\d.]+\s+-?[\d.]+\s+\d+\s+-?[\d.]+\s+version",
        ),
        StationFormat("crn", "end", read_crn, True, r"\A\d{5} \d{8} \d{4} \d{8} \d{4} "),
        StationFormat(
            "csv",
            "end",
            read_csv,
            False,
            r"(?i)\A(?:#[^\n]*\n|\s*\n)*(?:[^,\n]*,)*\s*timestamp\s*(?:,|\r?\n)",
        ),
        # PVGIS's hourly answer: its inputs, then outputs.hourly's records
        StationFormat(
            "pvgis-hourly",
            "start",
            read_pvgis_hourly,
            True,
            r'\A\s*\{\s*"inputs"[\s\S]*"mounting_system"[\s\S]*"outputs"\s*:\s*\{\s*"hourly"',
        ),
    )
}
