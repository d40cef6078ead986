"""Weather fetched from public services by name (:data:`SOURCES`), cached and replayed offline.

A source (:class:`WeatherSource`) asks a service for a site's weather with the request pvlib's
fetcher makes (``pvlib.iotools.get_pvgis_tmy``: the same route and parameters) and keeps the
service's answer as it came, byte for byte, in foldopt's cache folder (``weather/`` in
:func:`foldopt.cache.cache_dir`), so that the answer is then read as a weather file of the
source's format (:data:`foldopt.inputs.weather.FORMATS`: ``pvgis`` for ``pvgis-tmy``) by the
reader every file takes: same checks, same frame, same site, elevation and time zone. pvlib's
fetchers return the parsed frame, not the answer, so the request is made here with ``requests``
(pvlib's own dependency): the cached bytes are the service's, their SHA-256 names them, and the
faults a fetcher leaves to a traceback (a rate limit, a cut answer, no network) are each one line.

``pvgis-hourly`` asks PVGIS's hourly series (``seriescalc``, ``pvlib.iotools.get_pvgis_hourly``'s
request for a horizontal plane, with the beam and diffuse components) for the years given, and
its answer is read as a measured file (format ``pvgis-hourly``,
:mod:`foldopt.inputs.weather.stations`): real days at their hourly step, each day a block, the
direct and diffuse light PVGIS's where the answer holds them, else estimated from the global
light as for any measured file of ``ghi`` alone. Years outside those the service's version holds
are refused before anything is asked (:attr:`WeatherSource.years`).

A horizon source (:data:`HORIZON_SOURCES`: ``--horizon pvgis``, PVGIS's ``printhorizon`` with
``pvlib.iotools.get_pvgis_horizon``'s query) is fetched, checked and cached the same way
(:func:`fetch_horizon`) and its answer read as the horizon file it is
(:func:`foldopt.inputs.horizon.read_horizon`).

Each answer is stored once under a key of the source, the service's version (from its base
address, ``v5_3``), the site as the service rounds it and the request's options
(:func:`cache_path`), written atomically beside its provenance (:class:`WeatherProvenance`:
the request, the retrieval time, the answer's SHA-256); an answer that fails any check is not
stored. Offline (:func:`foldopt.cache.offline`: ``--offline``, ``FOLDOPT_OFFLINE=1``) only the
cache is read.

The base address of each service is its pinned versioned API address unless
``FOLDOPT_PVGIS_URL`` (or a study's ``weather.url``) names another, a mirror or a proxy.

The module may import :mod:`foldopt.cache`, :mod:`foldopt.errors`, :mod:`foldopt.inputs.reading`
and its package's readers; ``requests`` loads on the first fetch.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import email.utils
import errno
import hashlib
import json
import math
import os
import re
import threading
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from urllib.parse import urlencode

from foldopt.cache import cache_dir, offline, write_atomically
from foldopt.errors import WeatherError, printable
from foldopt.inputs.reading import MAX_WEATHER_BYTES

#: Seconds a request waits for the service to connect or to send more (``weather.timeout_s``).
DEFAULT_TIMEOUT_S = 30.0
#: Requests of one fetch, the first and its retries after a rate limit (HTTP 429).
MAX_ATTEMPTS = 3
#: Seconds foldopt waits at most for one retry a rate limit asks for; a longer wait is refused.
MAX_RETRY_WAIT_S = 60.0
#: Requests a second foldopt sends at most, the rate PVGIS's API documents for one address (30).
MAX_RATE = 30.0
_LAST_REQUEST = {"at": -math.inf}
_RATE_LOCK = threading.Lock()


@dataclass(frozen=True)
class WeatherSource:
    """One weather service's product of :data:`SOURCES`.

    Parameters
    ----------
    name : str
        As :data:`foldopt.names.WEATHER_SOURCES` lists it (``pvgis-tmy``).
    service : str
        What messages call the service (``PVGIS``).
    url : str
        The pinned versioned base address of its API, with its trailing slash.
    url_variable : str
        The environment variable that overrides ``url`` (``FOLDOPT_PVGIS_URL``).
    route : str
        The route after the base address (``tmy``).
    format : str
        The weather format its answer is read as (:data:`foldopt.inputs.weather.FORMATS`), or
        ``horizon`` for a horizon profile (:func:`foldopt.inputs.horizon.read_horizon`).
    decimals : int
        Decimals of latitude and longitude the service keeps: the site is rounded to them before
        it is asked for, so that sites the service does not tell apart share one answer.
    params : callable
        ``params(latitude, longitude, weather)``: the query's parameters, as pvlib's fetcher
        sends them, for the rounded site and a study's ``weather`` section (or its mapping).
    label : str
        What messages call its answer (``PVGIS TMY``).
    years : dict
        The years the service holds, by its version (``{'v5_3': (2005, 2023)}``): years asked
        for outside them are refused before any request; empty where the service says.
    """

    name: str
    service: str
    url: str
    url_variable: str
    route: str
    format: str
    decimals: int
    params: Callable
    label: str
    years: dict = field(default_factory=dict)


def _pvgis_tmy_params(latitude: float, longitude: float, weather) -> dict:
    """``pvlib.iotools.get_pvgis_tmy``'s query (JSON): the site, ``usehorizon=0`` where the
    horizon is left out, ``startyear`` and ``endyear`` where the years are given."""
    params = {"lat": latitude, "lon": longitude, "outputformat": "json"}
    if not _option(weather, "usehorizon", True):
        params["usehorizon"] = 0
    years = _option(weather, "years", None)
    if years is not None:
        params["startyear"], params["endyear"] = (int(year) for year in str(years).split(":"))
    return params


def _pvgis_hourly_params(latitude: float, longitude: float, weather) -> dict:
    """``pvlib.iotools.get_pvgis_hourly``'s query for a horizontal plane (JSON): the site,
    ``angle=0`` and ``components=1`` (the beam, diffuse and reflected light apart, so that the
    direct and diffuse light are PVGIS's own), ``usehorizon=0`` where the horizon is left out,
    ``raddatabase`` where one is named, ``startyear`` and ``endyear`` where the years are given
    (else PVGIS's whole record)."""
    params = {"lat": latitude, "lon": longitude, "outputformat": "json", "angle": 0}
    params["components"] = 1
    if not _option(weather, "usehorizon", True):
        params["usehorizon"] = 0
    database = _option(weather, "raddatabase", None)
    if database is not None:
        params["raddatabase"] = database
    years = _option(weather, "years", None)
    if years is not None:
        params["startyear"], params["endyear"] = (int(year) for year in str(years).split(":"))
    return params


def _pvgis_horizon_params(latitude: float, longitude: float, weather) -> dict:
    """``pvlib.iotools.get_pvgis_horizon``'s query: the site, JSON."""
    return {"lat": latitude, "lon": longitude, "outputformat": "json"}


#: PVGIS's versioned API address, as pvlib's docs advise: its unversioned /api/ follows whatever
#: version is current, and the answers with it.
PVGIS_URL = "https://re.jrc.ec.europa.eu/api/v5_3/"

#: The weather sources by name, in the order of :data:`foldopt.names.WEATHER_SOURCES`: a new
#: source is its entry here (and its name and description there).
SOURCES = {
    entry.name: entry
    for entry in (
        WeatherSource(
            name="pvgis-tmy",
            service="PVGIS",
            url=PVGIS_URL,
            url_variable="FOLDOPT_PVGIS_URL",
            route="tmy",
            format="pvgis",
            # PVGIS names its files and rows by the site to 3 decimals (tmy_45.000_8.000_...)
            decimals=3,
            params=_pvgis_tmy_params,
            label="PVGIS TMY",
        ),
        WeatherSource(
            name="pvgis-hourly",
            service="PVGIS",
            url=PVGIS_URL,
            url_variable="FOLDOPT_PVGIS_URL",
            route="seriescalc",
            # real hours of real years: read as a measured file, at its own step, day by day
            format="pvgis-hourly",
            decimals=3,
            params=_pvgis_hourly_params,
            label="PVGIS hourly series",
            # PVGIS 5.3's hourly series: PVGIS-SARAH3 and PVGIS-ERA5, 2005 to 2023
            years={"v5_3": (2005, 2023)},
        ),
    )
}

#: The horizon sources by the name ``--horizon`` / ``site.horizon`` gives them: the site's horizon
#: profile, read as the horizon file it is (:func:`foldopt.inputs.horizon.read_horizon`).
HORIZON_SOURCES = {
    "pvgis": WeatherSource(
        name="pvgis-horizon",
        service="PVGIS",
        url=PVGIS_URL,
        url_variable="FOLDOPT_PVGIS_URL",
        route="printhorizon",
        format="horizon",
        decimals=3,
        params=_pvgis_horizon_params,
        label="PVGIS horizon profile",
    ),
}


def _option(weather, key: str, default):
    value = weather.get(key) if isinstance(weather, dict) else getattr(weather, key, None)
    return default if value is None else value


@dataclass(frozen=True)
class WeatherProvenance:
    """Where a fetched weather file came from: ``run.json``'s ``weather_source``.

    Parameters
    ----------
    source : str
        The source's name (``pvgis-tmy``).
    url : str
        The request, the base address, route and query.
    params : dict
        The query's parameters.
    service_version : str
        The service's version its base address names (``v5_3``), or ``url-`` and a digest of an
        address that names none.
    retrieved : str
        When the answer came, ISO 8601 in UTC.
    sha256 : str
        The SHA-256 of the answer, the cached file's bytes.
    bytes : int
        Its size.
    file : str
        The cached file.
    """

    source: str
    url: str
    params: dict
    service_version: str
    retrieved: str
    sha256: str
    bytes: int
    file: str

    def to_dict(self) -> dict:
        """The record as JSON-ready data."""
        return asdict(self)


def weather_cache() -> Path:
    """The folder of fetched weather: ``weather/`` in :func:`foldopt.cache.cache_dir`."""
    return cache_dir() / "weather"


def base_url(source: WeatherSource, url: str | None = None) -> str:
    """The base address a source is asked at: ``url`` (a study's ``weather.url``), else the
    source's environment variable (``FOLDOPT_PVGIS_URL``), else its pinned address; with a
    trailing slash."""
    chosen = url or os.environ.get(source.url_variable) or source.url
    return chosen if chosen.endswith("/") else chosen + "/"


def service_version(base: str) -> str:
    """The service's version a base address names (``.../api/v5_3/`` -> ``v5_3``), or ``url-``
    and 8 hexadecimal digits of the address where it names none."""
    found = re.findall(r"/(v\d+(?:_\d+)*)(?=/)", base)
    return found[-1] if found else "url-" + hashlib.sha256(base.encode()).hexdigest()[:8]


@dataclass(frozen=True)
class _Request:
    source: WeatherSource
    base: str
    params: dict
    timeout_s: float

    @property
    def url(self) -> str:
        return f"{self.base}{self.source.route}?{urlencode(self.params)}"

    @property
    def version(self) -> str:
        return service_version(self.base)


def _request(source: WeatherSource, latitude: float, longitude: float, weather) -> _Request:
    site = (round(float(latitude), source.decimals), round(float(longitude), source.decimals))
    timeout_s = float(_option(weather, "timeout_s", DEFAULT_TIMEOUT_S))
    return _Request(
        source,
        base_url(source, _option(weather, "url", None)),
        source.params(*site, weather),
        timeout_s,
    )


def cache_path(request: _Request) -> Path:
    """The cached answer of a request: ``<source>_<version>_<lat>_<lon>_<digest>.json`` in
    :func:`weather_cache`, the digest of the source, version and query (every option)."""
    source, params = request.source, request.params
    key = json.dumps(
        {"source": source.name, "version": request.version, "params": params}, sort_keys=True
    )
    digest = hashlib.sha256(key.encode()).hexdigest()[:12]
    lat, lon = (f"{params['lat']:.{source.decimals}f}", f"{params['lon']:.{source.decimals}f}")
    return weather_cache() / f"{source.name}_{request.version}_{lat}_{lon}_{digest}.json"


def _provenance_path(path: Path) -> Path:
    return path.with_name(path.stem + ".provenance.json")


def cached(path) -> WeatherProvenance | None:
    """The provenance of a cached answer whose bytes are whole, or None.

    Parameters
    ----------
    path : str or pathlib.Path
        A cached answer (:func:`cache_path`).

    Returns
    -------
    WeatherProvenance or None
        None where the answer or its provenance is missing or unreadable, or where the answer's
        SHA-256 is not the one recorded (a damaged file: fetched again, or refused offline).
    """
    path = Path(path)
    try:
        record = json.loads(_provenance_path(path).read_text())
        provenance = WeatherProvenance(**{**record, "file": str(path)})
        payload = path.read_bytes()
    except (OSError, ValueError, TypeError):
        return None
    return provenance if hashlib.sha256(payload).hexdigest() == provenance.sha256 else None


def cached_entries() -> list[WeatherProvenance]:
    """Every whole answer in :func:`weather_cache`, by file name."""
    folder = weather_cache()
    if not folder.is_dir():
        return []
    found = (
        cached(path) for path in sorted(folder.glob("*.json")) if ".provenance" not in path.name
    )
    return [entry for entry in found if entry is not None]


def fetch(source: str, latitude: float, longitude: float, weather=None) -> WeatherProvenance:
    """A source's answer for a site, from the cache or else from the service (then cached).

    Parameters
    ----------
    source : str
        One of :data:`SOURCES`.
    latitude, longitude : float
        The site [deg], rounded as the service rounds it.
    weather : foldopt.inputs.weather_section.Weather or dict, optional
        The options: ``years`` (``START:END``), ``usehorizon``, ``raddatabase`` (``pvgis-hourly``),
        ``url``, ``timeout_s``.

    Returns
    -------
    WeatherProvenance
        Its ``file`` a weather file of the source's format.

    Raises
    ------
    foldopt.errors.WeatherError
        One line: years outside the service's, offline without a cached copy, no network, a
        timeout, the service's refusal (its own message), a rate limit beyond
        :data:`MAX_RETRY_WAIT_S`, a cut or malformed answer, a cache folder that cannot be
        written. Nothing is cached then.
    """
    return _fetch(SOURCES[source], latitude, longitude, weather, f"weather {source}")


def fetch_horizon(
    source: str, latitude: float, longitude: float, options=None
) -> WeatherProvenance:
    """A horizon source's answer for a site (:data:`HORIZON_SOURCES`), from the cache or else
    from the service (then cached), as :func:`fetch` has a weather source's.

    Parameters
    ----------
    source : str
        One of :data:`HORIZON_SOURCES` (``pvgis``).
    latitude, longitude : float
        The site [deg], rounded as the service rounds it.
    options : dict, optional
        ``url``, ``timeout_s``.

    Returns
    -------
    WeatherProvenance
        Its ``file`` a horizon file (:func:`foldopt.inputs.horizon.read_horizon`).

    Raises
    ------
    foldopt.errors.WeatherError
        As :func:`fetch`: one line, ``horizon pvgis: ...``, nothing cached.
    """
    return _fetch(HORIZON_SOURCES[source], latitude, longitude, options, f"horizon {source}")


def _fetch(source: WeatherSource, latitude, longitude, weather, label: str) -> WeatherProvenance:
    request = _request(source, latitude, longitude, weather)
    _check_years(request, label)
    path = cache_path(request)
    found = cached(path)
    if found is not None:
        return found
    if offline():
        params = request.params
        site = f"--lat {params['lat']:g} --lon {params['lon']:g}"
        if "startyear" in params:
            site += f" --years {params['startyear']}:{params['endyear']}"
        how = (
            f"foldopt weather fetch {source.name} {site}"
            if source.name in SOURCES
            else f"run once with --{label} {site}"
        )
        raise WeatherError(
            f"{label}: no cached copy for ({params['lat']:g}, {params['lon']:g}) with these "
            "options, and offline (--offline, FOLDOPT_OFFLINE=1) nothing is fetched; fetch it "
            f"first where there is a network: {how}"
        )
    payload = _download(request, label)
    retrieved = dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")
    return _store(request, payload, retrieved, label)


def _check_years(request: _Request, label: str) -> None:
    """Refuse years outside those the service's version holds (:attr:`WeatherSource.years`)
    before anything is asked: one line naming them."""
    held = request.source.years.get(request.version)
    params = request.params
    if held is None or "startyear" not in params:
        return
    first, last = held
    if params["startyear"] < first or params["endyear"] > last:
        version = request.version.removeprefix("v").replace("_", ".")
        raise WeatherError(
            f"{label}: years {params['startyear']}:{params['endyear']} are outside "
            f"{request.source.service} {version}'s record, {first} to {last}; give years within "
            "it (--years, weather.years)"
        )


def _download(request: _Request, label: str) -> bytes:
    """The answer's bytes, after at most :data:`MAX_ATTEMPTS` requests (a rate limit waits as
    the service asks, up to :data:`MAX_RETRY_WAIT_S`)."""
    import requests

    service, host = request.source.service, request.base
    for attempt in range(1, MAX_ATTEMPTS + 1):
        _pace()
        try:
            with requests.get(
                request.base + request.source.route,
                params=request.params,
                timeout=request.timeout_s,
                stream=True,
                headers={"User-Agent": "foldopt"},
            ) as response:
                payload = _body(response, label, service)
        except requests.exceptions.Timeout:
            raise WeatherError(
                f"{label}: {service} at {host} did not answer within {request.timeout_s:g} s "
                "(weather.timeout_s sets the wait); try again later"
            ) from None
        except requests.exceptions.RequestException as error:
            raise WeatherError(f"{label}: {_network_fault(error, service, host)}") from None
        if response.status_code == 429 and attempt < MAX_ATTEMPTS:
            wait = _retry_after(response.headers.get("Retry-After"))
            if wait > MAX_RETRY_WAIT_S:
                raise WeatherError(
                    f"{label}: {service} limits the rate of requests and asks to wait {wait:g} s, "
                    f"longer than foldopt waits ({MAX_RETRY_WAIT_S:g} s); try again later"
                )
            time.sleep(wait)
            continue
        if response.status_code != 200:
            raise WeatherError(f"{label}: {_refusal(response, payload, service, attempt)}")
        return payload
    raise AssertionError("unreachable: the last attempt returns or raises")


def _pace() -> None:
    """Wait, where needed, so that this process sends at most :data:`MAX_RATE` requests a second
    (a map's sites are fetched one after the other)."""
    with _RATE_LOCK:
        wait = _LAST_REQUEST["at"] + 1.0 / MAX_RATE - time.monotonic()
        if wait > 0:
            time.sleep(wait)
        _LAST_REQUEST["at"] = time.monotonic()


def _body(response, label: str, service: str) -> bytes:
    """The whole body, at most :data:`~foldopt.inputs.reading.MAX_WEATHER_BYTES`; a body shorter
    than its Content-Length is a cut answer."""
    import requests

    chunks, size = [], 0
    try:
        for chunk in response.iter_content(chunk_size=1 << 16):
            size += len(chunk)
            if size > MAX_WEATHER_BYTES:
                raise WeatherError(
                    f"{label}: {service}'s answer is larger than {MAX_WEATHER_BYTES:,} bytes "
                    "(MAX_WEATHER_BYTES)"
                )
            chunks.append(chunk)
    except (requests.exceptions.ChunkedEncodingError, requests.exceptions.ContentDecodingError):
        expected = response.headers.get("Content-Length")
        of = f" of {int(expected):,}" if expected and expected.isdigit() else ""
        raise WeatherError(
            f"{label}: {service}'s answer was cut off after {size:,}{of} bytes "
            "(the connection closed); nothing was cached, try again"
        ) from None
    return b"".join(chunks)


def _network_fault(error: Exception, service: str, host: str) -> str:
    text = str(error)
    if "RemoteDisconnected" in text or "Connection aborted" in text:
        return (
            f"{service} at {host} closed the connection without an answer; nothing was cached, "
            "try again"
        )
    reason = re.search(r"\[Errno -?\d+\] ([^'\")]+)|(Failed to resolve [^(]+)", text)
    why = (
        printable((reason.group(1) or reason.group(2)).strip(), 80)
        if reason
        else type(error).__name__
    )
    return (
        f"cannot reach {service} at {host} ({why}): no network? A site fetched before runs "
        "without one from the cache (--offline, FOLDOPT_OFFLINE=1)"
    )


def _retry_after(value: str | None) -> float:
    """Seconds a ``Retry-After`` header asks for (seconds or an HTTP date); 1 where it is absent
    or unreadable."""
    if value is None:
        return 1.0
    if value.strip().isdigit():
        return float(value.strip())
    try:
        when = email.utils.parsedate_to_datetime(value)
    except (TypeError, ValueError):
        return 1.0
    return max(0.0, (when - dt.datetime.now(dt.timezone.utc)).total_seconds())


def _refusal(response, payload: bytes, service: str, attempts: int) -> str:
    """A status other than 200: the service's own message where it gives one (PVGIS: JSON
    ``{"message": ...}`` with status 400), else the status."""
    status = f"{response.status_code} {response.reason or ''}".strip()
    try:
        message = json.loads(payload.decode("utf-8")).get("message")
    except (ValueError, AttributeError):
        message = None
    if message:
        return f"{service} refused the request ({status}): {printable(str(message), 200)}"
    if response.status_code == 429:
        return f"{service} still limits the rate of requests after {attempts} tries ({status}); try again later"
    later = "; try again later" if response.status_code >= 500 else ""
    return f"{service} answered {status}{later}"


def _store(request: _Request, payload: bytes, retrieved: str, label: str) -> WeatherProvenance:
    """Check the answer as the weather file it is, then cache it and its provenance atomically:
    an answer that fails a check is not stored."""
    path = cache_path(request)
    source = request.source
    try:
        text = payload.decode("utf-8")
        refusal = json.loads(text).get("message") if text.lstrip().startswith("{") else None
    except (UnicodeDecodeError, ValueError, AttributeError):
        refusal = None
    if refusal:  # a refusal with status 200
        raise WeatherError(
            f"{label}: {source.service} refused the request: {printable(str(refusal), 200)}"
        )
    digest = hashlib.sha256(payload).hexdigest()
    provenance = WeatherProvenance(
        source=source.name,
        url=request.url,
        params=request.params,
        service_version=request.version,
        retrieved=retrieved,
        sha256=digest,
        bytes=len(payload),
        file=str(path),
    )

    def check(temporary: Path) -> None:
        temporary.write_bytes(payload)
        reason = _unreadable(temporary, source.format)
        if reason is not None:
            raise WeatherError(
                f"{label}: {source.service}'s answer is not a readable {source.label} ({reason}); "
                "nothing was cached"
            )

    try:
        write_atomically(path, check)
        record = {k: v for k, v in provenance.to_dict().items() if k != "file"}
        write_atomically(
            _provenance_path(path),
            lambda temporary: temporary.write_text(json.dumps(record, indent=2) + "\n"),
        )
    except OSError as error:
        with contextlib.suppress(OSError):
            path.unlink(missing_ok=True)  # an answer without its provenance is no cached copy
        full = error.errno in (errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC))
        why = "the file system is full" if full else (error.strerror or str(error))
        raise WeatherError(
            f"{label}: cannot cache the answer in {weather_cache()} ({why}); FOLDOPT_CACHE_DIR "
            "names another cache folder"
        ) from None
    return provenance


def _unreadable(path: Path, fmt: str) -> str | None:
    """Why an answer is not a readable file of its format (every check a file of it gets), or
    None."""
    if fmt != "horizon":
        from foldopt.inputs import weather as files

        try:
            files.check_answer(path, fmt)
        except WeatherError as error:
            return error.errors[0].split(": ", 1)[-1]
        return None
    from foldopt.errors import ConfigError
    from foldopt.inputs.horizon import ACCEPTS, FIELD, read_horizon

    try:
        read_horizon(path)
    except ConfigError as error:
        reason = error.errors[0].removeprefix(f"{FIELD}: ").removesuffix(f"; {ACCEPTS}")
        for joint in (
            " is ",
            ": ",
            ", ",
            " ",
        ):  # the temporary file's name says nothing to the user
            reason = reason.replace(f"{path}{joint}", "")
        return reason
    return None
