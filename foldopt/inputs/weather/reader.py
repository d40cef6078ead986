"""Reading a weather file: its format, its site, its hours and days, checked once per file.

Weather files are read through pvlib.iotools [1]_ once per study, with the site in their header
(:func:`weather_site`). Each format is one module and one entry of :data:`FORMATS`
(:class:`~foldopt.inputs.weather.formats.WeatherFormat`: its name, label, interval label,
extensions and reader): :mod:`~foldopt.inputs.weather.tmy3`, :mod:`~foldopt.inputs.weather.epw`
and :mod:`~foldopt.inputs.weather.pvgis`, whose names :data:`foldopt.names.WEATHER_FORMATS`
lists for validation and help. As pvlib returns them, timestamps mark the end of each interval
for TMY3 and its start for EPW (pvlib moves EPW's hour-ending rows back an hour) and for PVGIS
(hour-start stamps, in UTC, moved here to the site's standard time); foldopt moves them to the
interval centre, like its own clear-sky steps. ``label`` overrides the convention. Years are
coerced to one (a TMY mixes years), so a non-leap year matches the files' 365 days.

Every file is checked when it is read (:mod:`~foldopt.inputs.weather.qc`): any fault raises
:class:`~foldopt.errors.WeatherError`, one line naming the file, where and why. A study over a
period needs the file to hold every day of it, whole (:func:`weather_days`).

Measured files (SURFRAD, MIDC, SRML, BSRN, SOLRAD, CRN and a generic CSV,
:data:`MEASURED_FORMATS`) are read by :mod:`~foldopt.inputs.weather.measured` and evaluated at
their own step (:func:`measured_weather`, :func:`study_weather`); a study names their format.

References
----------
.. [1] pvlib.iotools.read_tmy3, read_epw, read_pvgis_tmy.
"""

from __future__ import annotations

import functools
import re
from pathlib import Path

import numpy as np
import pandas as pd

from foldopt.errors import WeatherError
from foldopt.inputs.weather import epw, pvgis, tmy3
from foldopt.inputs.weather.formats import HOUR, check_file
from foldopt.inputs.weather.measured import STATION_FORMATS, MeasuredWeather, read_measured
from foldopt.inputs.weather.qc import COLUMNS, check_rows

#: The hourly weather formats by name, in the order of :data:`foldopt.names.WEATHER_FORMATS`: a new
#: format is its module and its entry here (and its name and description there).
FORMATS = {entry.name: entry for entry in (tmy3.FORMAT, epw.FORMAT, pvgis.FORMAT)}
#: The measured formats (:mod:`~foldopt.inputs.weather.measured`), the rest of
#: :data:`foldopt.names.WEATHER_FORMATS`: evaluated at their own step. Their extensions are shared
#: (``.dat``, ``.txt``, ``.csv``), so a study names the format.
MEASURED_FORMATS = STATION_FORMATS


def weather_format(path: Path, fmt: str | None = None) -> str:
    """The format of a weather file.

    Parameters
    ----------
    path : str or pathlib.Path
    fmt : str, optional
        The format given, one of :data:`FORMATS`.

    Returns
    -------
    str
        ``fmt``, or the format its extension names (``.csv`` TMY3, ``.epw`` EPW, ``.json`` PVGIS:
        each hourly format's ``suffixes``); TMY3 for any other. A measured format is named, never
        guessed.

    Raises
    ------
    ValueError
        For a ``fmt`` that is no format.
    """
    if fmt is not None:
        if fmt not in FORMATS and fmt not in MEASURED_FORMATS:
            raise ValueError(
                f"weather format must be one of {', '.join([*FORMATS, *MEASURED_FORMATS])}; got {fmt!r}"
            )
        return fmt
    suffix = Path(path).suffix.lower()
    return next(
        (name for name, entry in FORMATS.items() if suffix in entry.suffixes), tmy3.FORMAT.name
    )


#: Bytes of a file's start that :func:`sniff_format` reads.
_HEAD_BYTES = 8192


def sniff_format(path) -> str | None:
    """The format a weather file's first lines look like (each format's ``signature``).

    Parameters
    ----------
    path : str or pathlib.Path
        A file :func:`~foldopt.inputs.weather.formats.check_file` accepts.

    Returns
    -------
    str or None
        One of :data:`FORMATS` or :data:`MEASURED_FORMATS`, or None where none matches or the
        file cannot be read.
    """
    if not Path(path).is_file():
        return None  # a FIFO or a device: nothing to read, nor to wait for
    try:
        with open(path, "rb") as handle:
            head = handle.read(_HEAD_BYTES).decode("utf-8", errors="replace").replace("\r\n", "\n")
    except OSError:
        return None
    entries = {**FORMATS, **MEASURED_FORMATS}
    return next((name for name, entry in entries.items() if re.search(entry.signature, head)), None)


def _read(path: str, fmt: str, year: int, mtime: float):
    """The checked columns of a file (:mod:`~foldopt.inputs.weather.qc`), indexed by pvlib's stamps
    with the year coerced (PVGIS: on the site's standard time), and pvlib's metadata; once per file
    and year."""
    result, message = _read_once(path, fmt, year, mtime)
    if message is not None:
        raise WeatherError(message)
    return result


#: The last answer :func:`check_answer` read before it was cached, by its :func:`_read_once` (or
#: :func:`_measured_once`) key as the cached file: the study that fetched it reads it next, and
#: takes it from here.
_checked: dict = {}


@functools.lru_cache(maxsize=8)
def _read_once(path: str, fmt: str, year: int, mtime: float):
    """:func:`_read`'s result, or its error message: a study validates its file once per value of
    every axis, and a bad file must not be read again each time."""
    checked = _checked.pop((path, fmt, year, mtime), None)
    if checked is not None:
        return checked, None
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
    entry = FORMATS[fmt]
    data, meta, index, where = entry.read(path, text, year, fail)
    site = entry.site(meta)
    frame = check_rows(data, entry, index, site, where, fail)
    if entry.to_local is not None:
        frame = entry.to_local(frame, site, year)
    return frame, meta


def check_answer(path, fmt: str, cached_as=None) -> None:
    """Check a service's answer as the weather file of format ``fmt`` it is, with every check a
    file of that format gets (:mod:`~foldopt.inputs.weather.sources`, before it is cached).

    Parameters
    ----------
    path : str or pathlib.Path
    fmt : str
        One of :data:`FORMATS` or :data:`MEASURED_FORMATS`.
    cached_as : str or pathlib.Path, optional
        Where ``path`` is renamed to once checked (its modification time kept): what is read here
        (a typical year's hours in 2025, a measured series with ``read_measured``'s options) is
        the next read of that file, not read again.

    Raises
    ------
    foldopt.errors.WeatherError
        Naming the file, where and why.
    """
    mtime = Path(path).stat().st_mtime
    if fmt in MEASURED_FORMATS:
        result = read_measured(path, fmt)
        if cached_as is None:
            return
        result.frame.attrs["weather"] = Path(cached_as).name  # as its read names it
        # read_measured's defaults: the options this answer was read with
        key = _measured_key(Path(cached_as), mtime, fmt, *read_measured.__defaults__)
    else:
        result = _read_checked(str(path), fmt, 2025)
        if cached_as is None:
            return
        key = (str(Path(cached_as).resolve()), fmt, 2025, mtime)
    _checked.clear()
    _checked[key] = result


def weather_site(path, fmt: str | None = None, site: dict | None = None, **measured) -> dict | None:
    """The site a weather file describes, from its header.

    Parameters
    ----------
    path : str or pathlib.Path
    fmt : str, optional
        One of :data:`FORMATS` or :data:`MEASURED_FORMATS`; default from the extension
        (:func:`weather_format`).
    site : dict, optional
        A measured file's site where the file holds none (:func:`measured_weather`).
    **measured
        :func:`measured_weather`'s options, for a measured file.

    Returns
    -------
    dict or None
        ``name``, ``latitude``, ``longitude`` [deg], ``altitude`` [m] and ``timezone`` (the fixed
        offset its timestamps keep); None for a measured file that holds no site when none is given.

    Raises
    ------
    foldopt.errors.WeatherError
        If the file fails any check (:mod:`~foldopt.inputs.weather.qc`,
        :mod:`~foldopt.inputs.weather.measured`).
    """
    path = Path(path)
    fmt = weather_format(path, fmt)
    if fmt in MEASURED_FORMATS:
        if site is None and not MEASURED_FORMATS[fmt].has_site:
            return None
        return measured_weather(path, fmt, site=site, **measured).site
    check_file(path)
    _, meta = _read(str(path.resolve()), fmt, 2025, path.stat().st_mtime)
    return FORMATS[fmt].site(meta)


def measured_weather(
    path,
    fmt: str,
    label: str | None = None,
    timezone: str | None = None,
    site: dict | None = None,
    decomposition: str = "erbs",
    max_gap_min: float = 60.0,
) -> MeasuredWeather:
    """A measured weather file (:func:`~foldopt.inputs.weather.measured.read_measured`), read once
    per file, its date and the options.

    Parameters
    ----------
    path : str or pathlib.Path
    fmt : str
        One of :data:`MEASURED_FORMATS`.
    label, timezone, decomposition, max_gap_min
        As :func:`~foldopt.inputs.weather.measured.read_measured`'s.
    site : dict, optional
        ``latitude``, ``longitude``, ``altitude`` (and ``name``) where the file holds no site.

    Returns
    -------
    MeasuredWeather

    Raises
    ------
    foldopt.errors.WeatherError
    """
    path = Path(path)
    check_file(path)
    key = _measured_key(
        path, path.stat().st_mtime, fmt, label, timezone, site, decomposition, max_gap_min
    )
    result, message = _measured_once(*key)
    if message is not None:
        raise WeatherError(message)
    return result


def _measured_key(path: Path, mtime, fmt, label, timezone, site, decomposition, max_gap_min):
    """:func:`_measured_once`'s arguments for a file and its options (the site hashable)."""
    where = (
        None
        if site is None
        else tuple(
            sorted(
                (key, site.get(key))
                for key in ("name", "latitude", "longitude", "altitude")
                if site.get(key) is not None
            )
        )
    )
    return (
        str(path.resolve()),
        mtime,
        fmt,
        label,
        timezone,
        where,
        decomposition,
        float(max_gap_min),
    )


@functools.lru_cache(maxsize=8)
def _measured_once(path, mtime, fmt, label, timezone, site, decomposition, max_gap_min):
    """:func:`measured_weather`'s result, or its error message (a bad file is read once)."""
    checked = _checked.pop(
        (path, mtime, fmt, label, timezone, site, decomposition, max_gap_min), None
    )
    if checked is not None:
        return checked, None
    try:
        return read_measured(
            path,
            fmt,
            label,
            timezone,
            None if site is None else dict(site),
            decomposition,
            max_gap_min,
        ), None
    except WeatherError as error:
        return None, error.errors[0]


def study_weather(weather, site) -> MeasuredWeather:
    """The measured weather of a study's ``weather`` section at its site.

    Parameters
    ----------
    weather : foldopt.inputs.weather_section.Weather
        ``path``, ``format`` (measured), ``label``, ``timezone``, ``decomposition``, ``max_gap_min``.
    site : foldopt.inputs.sections.Site or dict or None
        The study's site, for a file that holds none (a file's own site is its).

    Returns
    -------
    MeasuredWeather
    """
    entry = MEASURED_FORMATS[weather.format]
    given = None
    if not entry.has_site and site is not None:
        given = site if isinstance(site, dict) else site.model_dump()
    return measured_weather(
        weather.path,
        weather.format,
        weather.label,
        weather.timezone,
        given,
        weather.decomposition,
        weather.max_gap_min,
    )


def read_weather(
    path, fmt: str | None = None, year: int = 2025, label: str | None = None
) -> pd.DataFrame:
    """A weather file's hours.

    Parameters
    ----------
    path : str or pathlib.Path
    fmt : str, optional
        One of :data:`FORMATS`; default from the extension (:func:`weather_format`).
    year : int
        The year the file's days are coerced to.
    label : {'start', 'end', 'centre'}, optional
        What a timestamp of the file marks; default its format's ``interval_label``.

    Returns
    -------
    pandas.DataFrame
        ``ghi``, ``dni``, ``dhi`` [W/m^2], ``temp_air`` [C], ``wind_speed`` [m/s] and
        ``cloud_cover`` (the total sky cover [0-1], NaN where the file has none), indexed by
        tz-aware interval centres (the file's own time zone) in ``year``. A file without any air
        temperature or wind speed column gets :data:`~foldopt.inputs.weather.qc.DEFAULT_TEMP_AIR`
        and :data:`~foldopt.inputs.weather.qc.DEFAULT_WIND_SPEED`; nothing else is filled in.
        ``attrs["weather"]`` holds the file's name, for :func:`weather_days`' messages.

    Raises
    ------
    foldopt.errors.WeatherError
        If the file fails any check (:mod:`~foldopt.inputs.weather.qc`).
    """
    path = Path(path)
    fmt = weather_format(path, fmt)
    # A typical year has 365 days: it is read as a year without February 29, then its interval
    # centres move to ``year``, so that a leap year's February 29 is a day the file does not hold.
    typical = year - 1 if pd.Timestamp(year=year, month=1, day=1).is_leap_year else year
    check_file(path)
    data, _ = _read(str(path.resolve()), fmt, typical, path.stat().st_mtime)
    label = label or FORMATS[fmt].interval_label
    shift = {"end": -HOUR / 2, "start": HOUR / 2, "centre": HOUR * 0}[label]
    index = data.index + shift
    if typical != year:
        index = pd.DatetimeIndex(index.map(lambda t: t.replace(year=t.year + year - typical)))
    frame = pd.DataFrame(
        {key: data[key].to_numpy(copy=True) for key in (*COLUMNS, "cloud_cover")}, index=index
    )
    frame = frame.sort_index()
    frame.attrs["weather"] = path.name
    return frame


def weather_days(frame: pd.DataFrame, dates) -> np.ndarray:
    """The rows of a weather frame on each of some dates.

    Parameters
    ----------
    frame : pandas.DataFrame
        From :func:`read_weather`.
    dates : sequence of datetime.date
        Local to the file.

    Returns
    -------
    numpy.ndarray
        (n_dates, n_steps) row numbers of ``frame`` whose interval centres fall on each date.

    Raises
    ------
    foldopt.errors.WeatherError
        Naming the file of ``frame.attrs["weather"]``, unless the file holds every date, whole:
        the first missing dates and their count, or a date with fewer rows than a day has (a
        truncated day), and the span of dates the file holds.
    """
    source = frame.attrs.get("weather")
    prefix = f"weather {source}: " if source else "weather: "
    days = frame.index.tz_localize(None).to_numpy().astype("datetime64[D]")
    if days.size == 0:
        raise WeatherError(f"{prefix}no rows")
    held = f"the file holds {days[0]} to {days[-1]}"
    wanted = np.array(dates, dtype="datetime64[D]")
    start, stop = (
        np.searchsorted(days, wanted, side="left"),
        np.searchsorted(days, wanted, side="right"),
    )
    missing = [str(date) for date, a, b in zip(wanted, start, stop, strict=True) if a == b]
    if missing:
        leap = (
            " (a typical year has no February 29)"
            if any(d.endswith("-02-29") for d in missing)
            else ""
        )
        raise WeatherError(
            f"{prefix}no data for {', '.join(missing[:3])}"
            + (f" and {len(missing) - 3} more dates" if len(missing) > 3 else "")
            + f"; {held}{leap}"
        )
    step = pd.Series(frame.index).diff().median() if len(frame) > 1 else pd.NaT
    per_day = (
        round(pd.Timedelta(days=1) / step) if pd.notna(step) and step > pd.Timedelta(0) else None
    )
    counts = stop - start
    full = per_day if per_day else int(counts.max())
    short = [(str(date), int(n)) for date, n in zip(wanted, counts, strict=True) if n != full]
    if short:
        raise WeatherError(
            f"{prefix}{short[0][0]} holds {short[0][1]} rows, a whole day {full}"
            + (f"; and {len(short) - 1} more dates" if len(short) > 1 else "")
            + f"; {held}"
        )
    return start[:, None] + np.arange(full)


def weather_day(frame: pd.DataFrame, date) -> pd.DataFrame:
    """The rows of a weather frame on one date.

    Parameters
    ----------
    frame : pandas.DataFrame
        From :func:`read_weather`.
    date : datetime.date
        Local to the file.

    Returns
    -------
    pandas.DataFrame
        The intervals of ``frame`` whose centres fall on ``date``.

    Raises
    ------
    foldopt.errors.WeatherError
        Unless the file holds the whole day (:func:`weather_days`).
    """
    return frame.iloc[weather_days(frame, [date])[0]]
