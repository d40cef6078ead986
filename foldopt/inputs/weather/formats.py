"""The registry entry of a weather format (:class:`WeatherFormat`), and what its readers share.

Each format's module (:mod:`~foldopt.inputs.weather.tmy3`, :mod:`~foldopt.inputs.weather.epw`,
:mod:`~foldopt.inputs.weather.pvgis`) declares one :class:`WeatherFormat`: its name, what messages
call it, what its timestamps mark, the extensions it is detected by, where its columns come from
and its reader. :data:`foldopt.inputs.weather.reader.FORMATS` lists them.
"""

from __future__ import annotations

import json
import math
import threading
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from foldopt.errors import ConfigError, WeatherError, printable
from foldopt.inputs.reading import MAX_WEATHER_BYTES, check_input

HOUR = pd.Timedelta(hours=1)


@dataclass(frozen=True)
class WeatherFormat:
    """One weather format of :data:`foldopt.inputs.weather.reader.FORMATS`.

    Parameters
    ----------
    name : str
        As :data:`foldopt.names.WEATHER_FORMATS` lists it (``tmy3``).
    label : str
        What messages call it (``TMY3``).
    interval_label : {'start', 'end'}
        Which edge of its interval a timestamp marks, as pvlib.iotools returns it.
    suffixes : tuple of str
        File extensions (lower case) read as this format where no format is given.
    columns : dict
        Where each column (``ghi``, ``dni``, ``dhi``, ``temp_air``, ``wind_speed``) comes from in
        the file, for messages.
    columns_at : str
        Where the file names its columns, for a missing one.
    read : callable
        ``read(path, text, year, fail)``: the file through pvlib, checked as far as its own
        layout goes, as ``(data, meta, index, where)``: pvlib's frame and metadata, the rows'
        stamps with the year coerced to ``year``, and ``where(i)`` naming row ``i`` (``line 5``).
        ``fail(message)`` makes the error to raise.
    site : callable
        ``site(meta)``: the file's site from pvlib's metadata (``name``, ``latitude``,
        ``longitude`` [deg], ``altitude`` [m], ``timezone``).
    missing : dict
        The format's missing-value markers of the columns, named in messages.
    to_local : callable, optional
        ``to_local(frame, site, year)``: stamps in UTC moved to the site's standard time, once
        the rows are checked (the checks name UTC times).
    stamp_lag : float, default 0
        How many intervals pvlib's stamps lie before the file's own (EPW: 1, pvlib moves its
        hour-ending stamps back an hour). Air temperature and wind stand at the file's stamps.
    cover : tuple, optional
        ``(column, divisor)``: the file's total sky cover and what makes it a fraction of the sky
        (tenths: 10), for a cloud ensemble (:mod:`foldopt.inputs.weather.ensemble`).
    signature : str
        A regular expression its files' first lines match, to tell the format of a file read as
        another (:func:`foldopt.inputs.weather.reader.sniff_format`).
    """

    name: str
    label: str
    interval_label: str
    suffixes: tuple
    columns: dict
    columns_at: str
    read: Callable
    site: Callable
    missing: dict = field(default_factory=dict)
    to_local: Callable | None = None
    stamp_lag: float = 0.0
    cover: tuple | None = None
    signature: str = r"(?!)"


def check_file(path) -> None:
    """Refuse a weather file that is missing, no regular file (a folder, a device, a FIFO) or
    larger than :data:`~foldopt.inputs.reading.MAX_WEATHER_BYTES`, before anything reads it.

    Parameters
    ----------
    path : str or pathlib.Path

    Raises
    ------
    foldopt.errors.WeatherError
        One line naming the file and what it is.
    """
    try:
        check_input(
            path,
            f"weather {Path(path).name}",
            MAX_WEATHER_BYTES,
            "MAX_WEATHER_BYTES",
            "weather file",
        )
    except ConfigError as error:
        raise WeatherError(error.errors[0]) from None


def reason(error: Exception) -> str:
    """pvlib's or pandas' exception as a short reason.

    Parameters
    ----------
    error : Exception

    Returns
    -------
    str
        ``missing 'key'``, the JSON fault and its place, or the exception's type and first line.
    """
    if isinstance(error, KeyError):
        return f"missing {error}"
    if isinstance(error, json.JSONDecodeError):
        return f"not valid JSON: {error.msg} at line {error.lineno} column {error.colno}"
    if isinstance(error, UnicodeDecodeError):
        return f"not text: byte {error.start + 1:,} is 0x{error.object[error.start]:02x}, no UTF-8 (a binary file?)"
    text = str(error).strip().splitlines()
    # pandas' advice, on the next lines
    text = text[0].split(" You might want to try")[0] if text else ""
    return f"{type(error).__name__}: {printable(text, 200)}" if text else type(error).__name__


#: pvlib.iotools loads on first use (``foldopt/__init__.py``), and Python's lazy loading is not
#: thread-safe before 3.12: the first use is under this lock.
_IOTOOLS = threading.Lock()


def read_with_pvlib(fail, label: str, reader: str, *args, **kwargs):
    """A pvlib.iotools reader's result, any failure of it a file that is not readable.

    Parameters
    ----------
    fail : callable
        ``fail(message)``: the error to raise.
    label : str
        What messages call the format.
    reader : str
        The pvlib.iotools function's name (``read_tmy3``), called with ``args`` and ``kwargs``.

    Returns
    -------
    tuple
        ``(data, meta)`` as pvlib returns them.
    """
    with _IOTOOLS:
        import pvlib

        read = getattr(pvlib.iotools, reader)
    try:
        with warnings.catch_warnings():
            # pandas' warnings about pvlib's parsing: the checks follow
            warnings.simplefilter("ignore")
            return read(*args, **kwargs)
    except Exception as error:  # any failure of pvlib's reader is an unreadable file
        raise fail(f"not a readable {label} file ({reason(error)})") from error


def offset_zone(hours: float) -> str:
    """A fixed UTC offset as foldopt spells it.

    Parameters
    ----------
    hours : float
        The offset [h].

    Returns
    -------
    str
        ``UTC-05:00``.
    """
    minutes = round(hours * 60)
    sign = "+" if minutes >= 0 else "-"
    return f"UTC{sign}{abs(minutes) // 60:02d}:{abs(minutes) % 60:02d}"


def header_site(meta: dict, name: str) -> dict:
    """The site of a TMY3 or EPW file's header.

    Parameters
    ----------
    meta : dict
        pvlib's metadata.
    name : str
        The field of the site's name (``Name``, ``city``).

    Returns
    -------
    dict
        ``name``, ``latitude``, ``longitude`` [deg], ``altitude`` [m] and ``timezone``, the fixed
        offset its timestamps keep (:func:`offset_zone`).
    """
    label = meta.get(name)
    return {
        "name": str(label).strip('" ') if label else None,
        "latitude": float(meta["latitude"]),
        "longitude": float(meta["longitude"]),
        "altitude": float(meta["altitude"]),
        "timezone": offset_zone(float(meta["TZ"])),
    }


_SITE_BOUNDS = {
    "latitude": ("latitude", -90.0, 90.0, "deg"),
    "longitude": ("longitude", -180.0, 180.0, "deg"),
    "altitude": ("altitude", -math.inf, math.inf, "m"),
    "TZ": ("time zone TZ", -12.0, 14.0, "h"),
    "elevation": ("elevation", -math.inf, math.inf, "m"),
}


def site_value(fail, where: str, key: str, raw) -> float:
    """A header's site field as a number within its bounds.

    Parameters
    ----------
    fail : callable
        ``fail(message)``: the error to raise.
    where : str
        Where the field is (``line 1``).
    key : {'latitude', 'longitude', 'altitude', 'TZ', 'elevation'}
        The field, as pvlib names it: latitude and longitude [deg], altitude and elevation [m],
        the time zone offset TZ [h] in [-12, 14].
    raw : object
        Its value in the file.

    Returns
    -------
    float
    """
    label, lo, hi, unit = _SITE_BOUNDS[key]
    try:
        value = float(raw)
    except (TypeError, ValueError):
        raise fail(
            f"{where}: {label} = '{printable(str(raw).strip(), 40)}': not a number"
        ) from None
    if not math.isfinite(value):
        raise fail(f"{where}: {label} = {raw}: must be a finite number")
    if not lo <= value <= hi:
        raise fail(f"{where}: {label} = {value:g} {unit}: must be in [{lo:g}, {hi:g}] {unit}")
    return value


def header_fields(fail, label: str, names: tuple, first_line: str) -> list[str]:
    """The fields of a TMY3 or EPW file's first line, which must hold the site.

    Parameters
    ----------
    fail : callable
        ``fail(message)``: the error to raise.
    label : str
        What messages call the format.
    names : tuple of str
        The line's fields, as pvlib names them.
    first_line : str

    Returns
    -------
    list of str
        The fields, as many as the line holds: at least up to the site's.
    """
    fields = first_line.rstrip("\r\n").split(",")
    needed = ("TZ", "latitude", "longitude", "altitude")
    missing = [key for key in needed if names.index(key) >= len(fields)]
    if missing:
        raise fail(
            f"line 1: the {label} header has no {', '.join(missing)} ({len(fields)} fields; "
            f"it holds {len(names)}: {', '.join(names)})"
        )
    return fields


def check_site_fields(fail, names: tuple, fields: list[str]) -> None:
    """The site's fields of a TMY3 or EPW header, each a number within its bounds (:func:`site_value`).

    Parameters
    ----------
    fail : callable
        ``fail(message)``: the error to raise.
    names : tuple of str
        The header's fields, as pvlib names them.
    fields : list of str
        The header's values.
    """
    for key in ("latitude", "longitude", "altitude", "TZ"):
        site_value(fail, "line 1", key, fields[names.index(key)])


def table_rows(lines: list[str], header: int, label: str, fail) -> list[int]:
    """The file lines of a TMY3 or EPW table's rows, as pandas reads them (blank lines skipped).

    Parameters
    ----------
    lines : list of str
        The file's lines.
    header : int
        Lines before the first row.
    label : str
        What messages call the format.
    fail : callable
        ``fail(message)``: the error to raise.

    Returns
    -------
    list of int
        1-based line numbers.
    """
    # pandas skips blank lines (whitespace only included): the rows' own line numbers.
    line_of = [n for n in range(header + 1, len(lines) + 1) if lines[n - 1].strip()]
    if not line_of:
        held = max((n for n in range(1, len(lines) + 1) if lines[n - 1].strip()), default=0)
        raise fail(
            f"no data rows: a {label} file has {header} header lines, then one row per "
            f"hour; this one ends at line {held}"
        )
    return line_of


def refuse_february_29(fail, leap: list[int], why: str) -> None:
    """Refuse a typical year's February 29.

    Parameters
    ----------
    fail : callable
        ``fail(message)``: the error to raise.
    leap : list of int
        The file lines of February 29's rows.
    why : str
        Why the day cannot be read.
    """
    if leap:
        raise fail(
            f"line {leap[0]}: February 29 ({len(leap)} rows): {why}; a typical year has 365 days, "
            f"remove that day"
        )


def table_index(data: pd.DataFrame, header: int, fail) -> pd.DatetimeIndex:
    """The stamps of a TMY3 or EPW table's rows as pvlib read them.

    Parameters
    ----------
    data : pandas.DataFrame
        pvlib's frame.
    header : int
        Lines before the first row.
    fail : callable
        ``fail(message)``: the error to raise.

    Returns
    -------
    pandas.DatetimeIndex
    """
    if len(data) == 0:
        raise fail(f"no data rows after the {header} header lines")
    return pd.DatetimeIndex(data.index)


def line_locator(line_of: list[int], rows: int, header: int) -> Callable:
    """Where each row of a TMY3 or EPW table is in its file.

    Parameters
    ----------
    line_of : list of int
        The rows' lines (:func:`table_rows`).
    rows : int
        The rows pvlib read; where they differ from the lines counted, the rows are taken to
        follow the header line by line.
    header : int
        Lines before the first row.

    Returns
    -------
    callable
        ``where(i)``: ``line N`` of row ``i``.
    """
    if len(line_of) != rows:
        line_of = list(range(header + 1, header + 1 + rows))
    line_of = np.asarray(line_of)

    def where(i: int) -> str:
        return f"line {line_of[i]}"

    return where
