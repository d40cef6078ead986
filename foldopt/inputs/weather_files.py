"""What a study's weather file brings before the study is validated: its site and, for a measured
file, its step and its days (:func:`weather_read`), and the fields a study takes from it where it
leaves them out (:func:`weather_defaults`). The file is read through :mod:`foldopt.inputs.weather`,
imported only when a file is named (pandas and pvlib).

The module may import :mod:`foldopt.errors`, :mod:`foldopt.names`, :mod:`foldopt.inputs.reading` and
:mod:`foldopt.inputs.weather`.
"""

from __future__ import annotations

from pathlib import Path

from foldopt.errors import ConfigError, WeatherError, printable
from foldopt.inputs.reading import MAX_WEATHER_BYTES, check_input
from foldopt.names import (
    HOURLY_WEATHER_FORMATS,
    MEASURED_WEATHER_SOURCES,
    WEATHER_FORMATS,
    canonical,
)


def weather_read(weather, site=None) -> dict:
    """What a study's weather file brings to its validation (:class:`~foldopt.inputs.sections.FilesRead`'s
    weather fields).

    Parameters
    ----------
    weather : str or dict or None
        The study's ``weather`` (a path, or a mapping with ``path``, ``format`` and options).
    site : dict, optional
        The study's ``site``, for a measured file that holds none.

    Returns
    -------
    dict
        ``weather_site``, and for a measured file ``weather_step_min`` and ``weather_dates``; or
        ``weather_problem`` (one line naming the file) and ``weather_missing``; empty where no
        file is named (or its format is no format: the study names that fault).
    """
    spec = {"path": weather} if isinstance(weather, str) else weather
    path = spec.get("path") if isinstance(spec, dict) else None
    if not isinstance(path, str) or _options_problem(spec):
        return {}  # the study names the fault of an option that is not one value of its kind
    try:
        check_input(path, "weather", MAX_WEATHER_BYTES, "MAX_WEATHER_BYTES", "weather file")
    # missing, a folder, a device, a FIFO, too large: named before any read
    except ConfigError as error:
        return {"weather_missing": True, "weather_problem": error.errors[0]}
    try:
        fmt = canonical(spec.get("format"), WEATHER_FORMATS)
    except ValueError:
        return {}  # the study names the format's fault
    # pandas and pvlib: only when a file is named
    from foldopt.inputs.weather import reader as files

    try:
        if fmt in files.MEASURED_FORMATS:
            return _measured_read(files, path, fmt, spec, site)
        return {"weather_site": files.weather_site(path, fmt)}
    except ConfigError as error:  # foldopt.errors.WeatherError: the file, the line, the reason
        return {"weather_problem": str(error) + _format_hint(files, path, fmt, spec.get("format"))}
    except (ValueError, KeyError, OSError) as error:
        return {
            "weather_problem": f"weather: cannot read a site from {path} ({error.__class__.__name__})"
        }


def _format_hint(files, path: str, fmt: str | None, given) -> str:
    """Where a file that failed was read in the format its extension implies, the format its
    first lines look like, if another."""
    if given is not None:
        return ""
    used = files.weather_format(path)
    seen = files.sniff_format(path)
    if seen is None or seen == used:
        return ""
    suffix = Path(path).suffix.lower()
    why = (
        f"by its extension {suffix}"
        if suffix in files.FORMATS[used].suffixes
        else "no format given"
    )
    return (
        f"; read as {used} ({why}), it looks like a {seen} file: give --weather-format {seen} "
        f"(weather.format: {seen} in a study)"
    )


def _measured_read(files, path: str, fmt: str, spec: dict, site) -> dict:
    """A measured file's site, step and days, read with the study's weather options (the study's
    site for a file that holds none: without one, the file waits for the study to name it)."""
    entry = files.MEASURED_FORMATS[fmt]
    given = site if isinstance(site, dict) and not entry.has_site else None
    if not entry.has_site and not (
        given
        and all(
            isinstance(given.get(k), (int, float)) for k in ("latitude", "longitude", "altitude")
        )
    ):
        varied = _varied_site(site)
        if varied is not None:
            return {
                "weather_problem": f"{varied}: varies, but a {fmt} file holds no site and is read at the study's; "
                "a measured file's light is of one place: give one site"
            }
        # A file that cannot be parsed says so first: naming a site would not make it readable.
        entry.reader(
            path, lambda message: WeatherError(f"weather {Path(path).name}: {message}"), 0.0
        )
        return {
            "weather_problem": f"weather {Path(path).name}: the {fmt} format holds no site; give the site's "
            "latitude, longitude and altitude (--lat, --lon, --altitude)"
        }
    options = {
        key: spec[key]
        for key in ("label", "timezone", "decomposition", "max_gap_min")
        if spec.get(key) is not None
    }
    try:
        measured = files.measured_weather(path, fmt, site=given, **options)
    except ConfigError:
        raise  # foldopt.errors.WeatherError: what is wrong with the file
    except ValueError:
        return {}  # an option out of its range: the study's validation names it
    import numpy as np  # with pandas: only when a file is named

    days = measured.frame.index.tz_localize(None).normalize().unique()
    # vectorised: a study checks its file once per day, and a series of years has hundreds
    whole = days.to_numpy().astype("datetime64[D]")
    flagged = np.array(measured.flagged_days, dtype="datetime64[D]")
    dates = tuple(np.datetime_as_string(whole[~np.isin(whole, flagged)]).tolist())
    read = {
        "weather_site": measured.site,
        "weather_step_min": measured.step.total_seconds() / 60.0,
        "weather_dates": dates,
    }
    if not dates:
        given_gap = spec.get("max_gap_min")
        read["weather_problem"] = _every_day_left_out(
            measured, days, 60.0 if given_gap is None else float(given_gap)
        )
    return read


def _varied_site(site) -> str | None:
    """``site.latitude = '30:40:5'`` where the study's site is a sweep axis (a list or a range), or None."""
    if isinstance(site, list):
        return f"site = {len(site)} sites"
    for key in ("latitude", "longitude", "altitude"):
        value = site.get(key) if isinstance(site, dict) else None
        if isinstance(value, (list, str)):
            return f"site.{key} = {printable(repr(value), 40)}"
    return None


def _every_day_left_out(measured, days, max_gap_min: float) -> str:
    """Why a measured file has no day a study can use: each of its days has a daylight gap longer
    than ``max_gap_min``; the first's, and what reading made missing."""
    name = measured.frame.attrs.get("weather", "")
    first = days[0].date()
    gaps = [gap for gap in measured.gaps if gap[0].date() == first and gap[2] > max_gap_min]
    longest = max(gaps, key=lambda gap: gap[2]) if gaps else None
    which = (
        f"its only day, {first}, is left out: it"
        if len(days) == 1
        else f"all {len(days)} of its days are left out; the first, {first},"
    )
    why = (
        "has daylight steps missing"
        if longest is None
        else (
            f"has a daylight gap of {longest[2]:g} min ({longest[0]:%H:%M} to {longest[1]:%H:%M})"
        )
    )
    found = [
        note
        for note in measured.notes
        if note.startswith(("values beyond physical bounds", "values flagged"))
    ]
    return (
        f"weather {name}: {which} {why}, longer than weather.max_gap_min = {max_gap_min:g} min"
        + (f" ({'; '.join(found)})" if found else " (steps the file lacks)")
        + "; no day is left to study"
    )


#: A weather file's options that take one name, and those that take one number.
_NAMED_OPTIONS = ("format", "label", "timezone", "decomposition")
_NUMBER_OPTIONS = ("max_gap_min", "members", "seed")
#: The options a measured file is read with: its days and step follow from them.
_READ_OPTIONS = ("format", "label", "timezone", "decomposition", "max_gap_min")


def _options_problem(spec: dict, keys=(*_NAMED_OPTIONS, *_NUMBER_OPTIONS)) -> str | None:
    """Why ``spec``'s ``keys`` are not each one value of their kind (``weather.format = [...]:
    ...``), or None."""
    for key in keys:
        value = spec.get(key)
        kinds = str if key in _NAMED_OPTIONS else (int, float)
        if value is not None and (not isinstance(value, kinds) or isinstance(value, bool)):
            what = "one name" if key in _NAMED_OPTIONS else "one number"
            kind = type(value).__name__
            kind = f"{'an' if kind[0] in 'aeiou' else 'a'} {kind}"
            swept = (
                "; the file is read with it, so it is not swept"
                if isinstance(value, (list, tuple, dict))
                else ""
            )
            return f"weather.{key} = {printable(repr(value), 40)}: {what} is expected, not {kind}{swept}"
    return None


def with_fetched_weather(data):
    """A study's data whose ``weather`` names a source (:data:`foldopt.names.WEATHER_SOURCES`),
    with the source's answer for the study's site as its file: ``weather.path`` the cached
    answer (fetched where it is not cached, :func:`foldopt.inputs.weather.sources.fetch`) and
    ``weather.format`` the format it is read as; from there on it is a weather file like any.

    Parameters
    ----------
    data : dict
        A study's fields.

    Returns
    -------
    dict
        ``data`` itself where its weather names no source, or a source or option that is not
        valid (the study's validation names the fault).

    Raises
    ------
    foldopt.errors.ConfigError
        For a site that varies or is not given (a source is fetched for one site).
    foldopt.errors.WeatherError
        For an answer that cannot be had (:func:`~foldopt.inputs.weather.sources.fetch`).
    """
    weather = data.get("weather") if isinstance(data, dict) else None
    if not isinstance(weather, dict) or weather.get("source") is None:
        return data
    _file_or_source(weather)
    from pydantic import ValidationError

    from foldopt.inputs.weather_section import Weather

    try:
        spec = Weather.model_validate({**weather, "path": None})
    except ValidationError:
        return data  # the study names the fault
    what = f"weather.source {spec.source}"
    latitude, longitude = _site_to_fetch(
        data.get("site"),
        what,
        "weather",
        " (fetch several ahead with foldopt weather fetch, one site each)",
    )
    from foldopt.inputs.weather.sources import SOURCES, fetch  # requests: only to fetch

    answer = fetch(spec.source, latitude, longitude, spec)
    fetched = {**weather, "source": spec.source, "path": answer.file}
    return {**data, "weather": {**fetched, "format": SOURCES[spec.source].format}}


def _file_or_source(weather: dict) -> None:
    """Refuse a weather section that names both a file and a source: either would be the study's
    light, and running one would ignore the other. A path inside the weather cache is the
    source's own answer (a fetched study's data, :meth:`foldopt.Study.data`), not a second value."""
    path = weather.get("path")
    if path is None:
        return
    from foldopt.inputs.weather.sources import weather_cache

    if Path(str(path)).resolve().parent != weather_cache().resolve():
        raise ConfigError(
            [
                f"weather: names a file ({path}) and a source ({weather['source']}); give one: "
                "weather.path (--weather FILE) or weather.source (--weather NAME)"
            ]
        )


def with_fetched_horizon(data):
    """A study's data whose ``site.horizon`` names a horizon source
    (:data:`foldopt.inputs.weather.sources.HORIZON_SOURCES`: ``pvgis``) instead of a file, with
    the source's answer for the study's site as its file (fetched where it is not cached,
    :func:`foldopt.inputs.weather.sources.fetch_horizon`): from there on a horizon file like any.

    Parameters
    ----------
    data : dict
        A study's fields; a ``weather`` section's ``url`` and ``timeout_s`` are the horizon's too.

    Returns
    -------
    dict
        ``data`` itself where its horizon names no source.

    Raises
    ------
    foldopt.errors.ConfigError
        For a site that varies or is not given (a horizon is fetched for one site).
    foldopt.errors.WeatherError
        For an answer that cannot be had.
    """
    from foldopt.inputs.weather.sources import HORIZON_SOURCES, fetch_horizon

    site = data.get("site") if isinstance(data, dict) else None
    horizon = site.get("horizon") if isinstance(site, dict) else None
    name = horizon.get("file") if isinstance(horizon, dict) else horizon
    if not isinstance(name, str) or name not in HORIZON_SOURCES:
        return data
    latitude, longitude = _site_to_fetch(site, f"site.horizon {name}", "horizon")
    weather = data.get("weather")
    options = {
        key: weather[key]
        for key in ("url", "timeout_s")
        if isinstance(weather, dict) and weather.get(key) is not None
    }
    answer = fetch_horizon(name, latitude, longitude, options)
    fetched = {**horizon, "file": answer.file} if isinstance(horizon, dict) else answer.file
    return {**data, "site": {**site, "horizon": fetched}}


def _site_to_fetch(site, what: str, kind: str, more: str = "") -> tuple[float, float]:
    """The one site that ``what`` (``weather.source pvgis-tmy``) fetches the ``kind`` of
    (``weather``), checked before anything is asked: its latitude and longitude [deg].

    Raises
    ------
    foldopt.errors.ConfigError
        For a site that varies (``more`` ends the line), that is not given, or whose latitude or
        longitude is out of range or not finite
        (:func:`foldopt.inputs.weather.sources.site_problems`).
    """
    varied = _varied_site(site)
    if varied is not None:
        raise ConfigError(
            [f"{varied}: varies, but {what} is fetched for one site; give one site{more}"]
        )
    place = site if isinstance(site, dict) else {}
    if not all(
        isinstance(place.get(key), (int, float)) and not isinstance(place.get(key), bool)
        for key in ("latitude", "longitude")
    ):
        raise ConfigError(
            [
                f"{what}: fetches the {kind} of the study's site; give its latitude and longitude "
                "(--lat, --lon; site.latitude, site.longitude)"
            ]
        )
    from foldopt.inputs.weather.sources import site_problems

    problems = site_problems(place["latitude"], place["longitude"])
    if problems:
        raise ConfigError(problems)
    return place["latitude"], place["longitude"]


def with_fetched_sites(sites: list[dict], weather) -> list[dict]:
    """A map's sites, each with its weather from a source: ``weather`` the cached answer for the
    site (:func:`foldopt.inputs.weather.sources.fetch`), fetched one site after the other, each
    answer cached as it comes, so that a fetch that stops (killed, a fault) resumes from the cache.

    Parameters
    ----------
    sites : list of dict
        ``latitude``, ``longitude`` [deg] and any of ``name``, ``altitude``, ``timezone``.
    weather : dict
        A ``weather`` section naming a ``source`` and its options (no ``path``).

    Returns
    -------
    list of dict
        The sites, each with ``weather``: its file, whose site and light the map takes.

    Raises
    ------
    foldopt.errors.ConfigError
        For a section that is not a source's (one line per fault, ``weather.years = ...``).
    foldopt.errors.WeatherError
        For the first site whose answer cannot be had, named by the site.
    """
    from pydantic import ValidationError

    from foldopt.inputs.study import format_errors
    from foldopt.inputs.weather_section import Weather

    try:
        spec = Weather.model_validate({**weather, "path": None})
    except ValidationError as error:
        raise ConfigError([f"weather.{line}" for line in format_errors(error)]) from None
    if spec.source is None:
        raise ConfigError(["weather: a map's weather names a source (weather.source)"])
    if spec.source in MEASURED_WEATHER_SOURCES:
        raise ConfigError(
            [
                f"weather.source {spec.source}: a map runs a typical year at each site; a series "
                f"of real years is studied one site at a time (foldopt sweep angle --weather "
                f"{spec.source} --years START:END)"
            ]
        )
    from foldopt.inputs.weather.sources import fetch, site_problems  # requests: only to fetch

    problems = [
        f"site {_site_name(site)}: {line}"
        for site in sites
        for line in site_problems(site.get("latitude"), site.get("longitude"))
    ]
    if problems:  # every site checked before any is fetched
        raise ConfigError(problems)
    fetched = []
    for site in sites:
        try:
            answer = fetch(spec.source, site["latitude"], site["longitude"], spec)
        except WeatherError as error:
            raise WeatherError(f"site {_site_name(site)}: {error.errors[0]}") from None
        fetched.append({**site, "weather": answer.file})
    return fetched


def _site_name(site: dict) -> str:
    """A map's site as messages name it: its name, else its latitude and longitude."""
    where = [site.get(key) for key in ("latitude", "longitude")]
    numbers = all(isinstance(value, (int, float)) for value in where)
    return site.get("name") or ", ".join(f"{v:g}" if numbers else repr(v) for v in where)


def weather_defaults(data: dict) -> dict:
    """What a study's fields take from its weather file where it leaves them out: the dates (an
    hourly file's whole ``year``; a measured file's days) and, for a measured file, the step.

    Parameters
    ----------
    data : dict
        A study's fields.

    Returns
    -------
    dict
        ``date`` and, for a measured file that can be read, ``step_min`` (where it cannot,
        ``year``, and the study's validation names why).

    Raises
    ------
    foldopt.errors.ConfigError
        For a ``weather.format`` (or a measured file's reading option) that is not one value, such
        as a list: the file's days and step follow from it, so it is not swept. For a site that
        varies (a sweep axis) with a file of one site, unless ``force_site``; for a measured file
        whose days cannot be known (it cannot be read, or every day is left out).
    """
    weather = data.get("weather")
    spec = (
        {"path": weather}
        if isinstance(weather, str)
        else weather
        if isinstance(weather, dict)
        else {}
    )
    problem = _options_problem(spec, ("format",))
    if problem is not None:
        raise ConfigError([problem])
    varied = _varied_site(data.get("site"))
    if varied is not None and not data.get("force_site"):
        own = weather_read(weather).get("weather_site")  # None for a file that holds no site
        if own is not None:
            raise ConfigError(
                [
                    f"{varied}: varies, but a weather file is of one site, {own['name'] or 'its own'} "
                    f"({own['latitude']:g}, {own['longitude']:g}); leave the site to the file, or set "
                    "force_site (--force-site) to give each site the file's weather"
                ]
            )
    try:
        fmt = canonical(spec.get("format"), WEATHER_FORMATS)
    except ValueError:
        fmt = None
    if fmt is None or fmt in HOURLY_WEATHER_FORMATS:
        return {"date": "year"}
    problem = _options_problem(spec, _READ_OPTIONS)
    if problem is not None:
        raise ConfigError([problem])
    read = weather_read(weather, data.get("site"))
    if read.get("weather_problem") is not None and (
        not read.get("weather_dates") or _varied_site(data.get("site"))
    ):
        # its days and step cannot be known: none to default
        raise ConfigError([read["weather_problem"]])
    if read.get("weather_dates") is None:
        return {"date": "year"}  # the file cannot be read: the study's validation names why
    return {"date": list(read["weather_dates"]), "step_min": read["weather_step_min"]}
