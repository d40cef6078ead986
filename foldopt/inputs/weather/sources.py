"""Weather fetched from public services by name (:data:`SOURCES`), cached and replayed offline.

A source (:class:`WeatherSource`) asks a service for a site's weather with the request pvlib's
fetcher makes (``pvlib.iotools.get_pvgis_tmy``: the same route and parameters) and keeps the
service's answer as it came, byte for byte, in foldopt's cache folder (``weather/`` in
:func:`foldopt.cache.cache_dir`), so that the answer is then read as a weather file of the
source's format (:data:`foldopt.inputs.weather.reader.FORMATS`: ``pvgis`` for ``pvgis-tmy``) by the
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
stored; a damaged cached answer is fetched again, and offline it is named with what is wrong
with it. Offline (:func:`foldopt.cache.offline`: ``--offline``, ``FOLDOPT_OFFLINE=1``) only the
cache is read.

Before anything is asked, the site is checked (:func:`site_problems`) and the address: a scheme
other than http or https is refused. A fetch has one deadline, ``weather.timeout_s``, for the
whole answer (:class:`_Deadline`), not for each read. An address may carry a user and password
or a key in its query: it is asked as given, but every address foldopt writes (a message, the
provenance, ``run.json``) is :func:`foldopt.errors.redacted`.

The base address of each service is its pinned versioned API address unless
``FOLDOPT_PVGIS_URL`` (or a study's ``weather.url``) names another, a mirror or a proxy.

The module may import :mod:`foldopt.cache`, :mod:`foldopt.errors`, :mod:`foldopt.inputs.reading`,
:mod:`foldopt.inputs.weather_section` and its package's readers; ``requests`` loads on the first
fetch.
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
import socket
import threading
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from urllib.parse import parse_qsl, urlencode

from foldopt.cache import cache_dir, notice, offline, write_atomically
from foldopt.errors import ConfigError, WeatherError, printable, redacted
from foldopt.inputs.reading import MAX_WEATHER_BYTES
from foldopt.inputs.weather_section import address_problem

#: Seconds a fetch waits at most for the service's whole answer (``weather.timeout_s``):
#: connecting, every read and every retry; a service that trickles its answer is given up on.
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
        The weather format its answer is read as (:data:`foldopt.inputs.weather.reader.FORMATS`), or
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
    trailing slash (before its query, where it has one)."""
    chosen = url or os.environ.get(source.url_variable) or source.url
    address, question, query = chosen.partition("?")
    slash = "" if address.endswith("/") else "/"
    return f"{address}{slash}{question}{query}"


def service_version(base: str) -> str:
    """The service's version a base address names (``.../api/v5_3/`` -> ``v5_3``), or ``url-``
    and 8 hexadecimal digits of the address (:func:`foldopt.errors.redacted`) where it names
    none."""
    base = redacted(base)
    found = re.findall(r"/(v\d+(?:_\d+)*)(?=/)", base.partition("?")[0])
    return found[-1] if found else "url-" + hashlib.sha256(base.encode()).hexdigest()[:8]


#: A site's coordinates and their bounds [deg].
_BOUNDS = {"latitude": 90.0, "longitude": 180.0}


def site_problems(latitude, longitude) -> list[str]:
    """Why a site cannot be asked for: one ``site.latitude = 91.0: ...`` line per coordinate
    that is not a finite number within its bounds (latitude [-90, 90], longitude
    [-180, 180] deg). Every path that fetches checks it before anything is asked.

    Parameters
    ----------
    latitude, longitude : float
        [deg]

    Returns
    -------
    list of str
        Empty for a site that can be asked for.
    """
    problems = []
    for field_name, value in (("latitude", latitude), ("longitude", longitude)):
        bound = _BOUNDS[field_name]
        try:
            number = None if isinstance(value, bool) else float(value)
        except (TypeError, ValueError):
            number = None
        if number is None:
            shown = printable(repr(value), 40)
            problems.append(f"site.{field_name} = {shown}: a number of degrees is expected")
        elif not math.isfinite(number) or abs(number) > bound:
            problems.append(
                f"site.{field_name} = {number!r}: must be a finite number in "
                f"[-{bound:g}, {bound:g}] deg"
            )
    return problems


@dataclass(frozen=True)
class _Request:
    source: WeatherSource
    base: str  # without its query
    query: tuple  # the base address's own query parameters (a mirror's key), sent first
    params: dict
    timeout_s: float

    @property
    def url(self) -> str:
        """The request as foldopt shows and stores it (:func:`foldopt.errors.redacted`)."""
        query = urlencode([*self.query, *self.params.items()])
        return redacted(f"{self.base}{self.source.route}?{query}")

    @property
    def version(self) -> str:
        return service_version(self.base)


def _request(
    source: WeatherSource, latitude: float, longitude: float, weather, label: str
) -> _Request:
    """The request for a site, its site and base address checked before anything is asked."""
    problems = site_problems(latitude, longitude)
    if problems:
        raise ConfigError([f"{label}: {line}" for line in problems])
    given = _option(weather, "url", None)
    base = base_url(source, given)
    problem = address_problem(base)
    if problem is not None:
        where = "weather.url" if given else source.url_variable
        raise WeatherError(f"{label}: {where} = {printable(repr(redacted(base)), 120)}: {problem}")
    site = (round(float(latitude), source.decimals), round(float(longitude), source.decimals))
    address, _, query = base.partition("?")
    return _Request(
        source,
        address,
        tuple(parse_qsl(query, keep_blank_values=True)),
        source.params(*site, weather),
        float(_option(weather, "timeout_s", DEFAULT_TIMEOUT_S)),
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
        None where the answer is not cached or is damaged (:func:`damage`: fetched again, or
        named offline); its ``url`` redacted (:func:`foldopt.errors.redacted`), whatever an
        earlier foldopt stored.
    """
    return _examined(Path(path))[0]


def damage(path) -> str | None:
    """What is wrong with a cached answer that is there but cannot be used, or None (a whole
    answer, or none at all).

    Parameters
    ----------
    path : str or pathlib.Path
        A cached answer (:func:`cache_path`).

    Returns
    -------
    str or None
        One phrase: its provenance record missing or unreadable, its answer missing or
        unreadable, or its bytes not those fetched (their SHA-256 not the one recorded).
    """
    return _examined(Path(path))[1]


def _examined(path: Path) -> tuple[WeatherProvenance | None, str | None]:
    """A cached answer's provenance where it is whole, else None and what is wrong with it
    (None where neither the answer nor its record is there)."""
    record_path = _provenance_path(path)
    if not path.exists() and not record_path.exists():
        return None, None
    try:
        payload = path.read_bytes()
    except FileNotFoundError:
        return None, f"its answer is missing beside its provenance record {record_path.name}"
    except OSError as error:
        return None, f"it cannot be read ({error.strerror or error})"
    try:
        record = json.loads(record_path.read_text())
        provenance = WeatherProvenance(**{**record, "file": str(path)})
    except FileNotFoundError:
        return None, f"its provenance record {record_path.name} is missing"
    except OSError as error:
        return None, f"its provenance record cannot be read ({error.strerror or error})"
    except (ValueError, TypeError):
        return None, f"its provenance record {record_path.name} is not one foldopt wrote"
    if hashlib.sha256(payload).hexdigest() != provenance.sha256:
        size = (
            f"{len(payload):,} bytes where {provenance.bytes:,} were fetched"
            if len(payload) != provenance.bytes
            else "its bytes changed since it was fetched"
        )
        return None, f"{size}: its SHA-256 is not the one recorded"
    return replace(provenance, url=redacted(str(provenance.url))), None


def _answers() -> list[Path]:
    folder = weather_cache()
    if not folder.is_dir():
        return []
    return [path for path in sorted(folder.glob("*.json")) if ".provenance" not in path.name]


def cached_entries() -> list[WeatherProvenance]:
    """Every whole answer in :func:`weather_cache`, by file name."""
    found = (cached(path) for path in _answers())
    return [entry for entry in found if entry is not None]


def damaged_entries() -> list[tuple[Path, str]]:
    """Every damaged answer in :func:`weather_cache` (:func:`damage`), by file name: the file
    and what is wrong with it."""
    found = ((path, damage(path)) for path in _answers())
    return [(path, why) for path, why in found if why is not None]


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
        ``url``, ``timeout_s`` (the whole fetch's time: connecting, every read, every retry).

    Returns
    -------
    WeatherProvenance
        Its ``file`` a weather file of the source's format.

    Raises
    ------
    foldopt.errors.ConfigError
        Before anything is asked, for a site out of range or not finite (:func:`site_problems`)
        or a ``FOLDOPT_OFFLINE`` that is no yes or no.
    foldopt.errors.WeatherError
        One line: an address that is not http or https (before anything is asked), years
        outside the service's, offline without a cached copy or with a damaged one, no network,
        no whole answer within ``timeout_s``, the service's refusal (its own message), a rate
        limit beyond :data:`MAX_RETRY_WAIT_S`, a cut or malformed answer, a cache folder that
        cannot be written. Nothing is cached then. A damaged cached copy is fetched again
        online (a notice names it).
    """
    return _fetch(SOURCES[source], latitude, longitude, weather, f"weather {source}")


def lookup(source: str, latitude: float, longitude: float, weather=None) -> WeatherProvenance:
    """A source's cached answer for a site; nothing is fetched (``foldopt weather path``).

    Parameters
    ----------
    source, latitude, longitude, weather
        As :func:`fetch` takes them.

    Returns
    -------
    WeatherProvenance

    Raises
    ------
    foldopt.errors.ConfigError
        As :func:`fetch` before anything is asked.
    foldopt.errors.WeatherError
        One line: no cached copy, or a damaged one (named, with what is wrong), and the command
        that fetches it.
    """
    label = f"weather {source}"
    return _fetch(SOURCES[source], latitude, longitude, weather, label, fetching=False)


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
    foldopt.errors.ConfigError, foldopt.errors.WeatherError
        As :func:`fetch`: one line, ``horizon pvgis: ...``, nothing cached.
    """
    return _fetch(HORIZON_SOURCES[source], latitude, longitude, options, f"horizon {source}")


def _fetch(
    source: WeatherSource, latitude, longitude, weather, label: str, fetching: bool = True
) -> WeatherProvenance:
    request = _request(source, latitude, longitude, weather, label)
    _check_years(request, label)
    offline_now = offline()  # a FOLDOPT_OFFLINE that is no yes or no is refused on every path
    path = cache_path(request)
    found, wrong = _examined(path)
    if found is not None:
        return found
    how = _fetch_command(request, weather, label)
    if not fetching or offline_now:
        offline_said = (
            ", and offline (--offline, FOLDOPT_OFFLINE=1) nothing is fetched" if fetching else ""
        )
        where = " where there is a network" if fetching else ""
        if wrong is not None:
            raise WeatherError(
                f"{label}: the cached copy {path} is damaged ({wrong}){offline_said}; fetch it "
                f"again{where}, which replaces it: {how}"
            )
        params = request.params
        raise WeatherError(
            f"{label}: no cached copy for ({params['lat']:g}, {params['lon']:g}) with these "
            f"options{offline_said or ' in ' + str(weather_cache())}; fetch it first{where}: {how}"
        )
    payload = _download(request, label)
    retrieved = dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")
    stored = _store(request, payload, retrieved, label)
    if wrong is not None:
        notice(f"the cached copy {path} was damaged ({wrong}); fetched it again")
    return stored


def _fetch_command(request: _Request, weather, label: str) -> str:
    """The command that fetches a request's answer into the cache."""
    params = request.params
    options = f"--lat {params['lat']:g} --lon {params['lon']:g}"
    if "startyear" in params:
        options += f" --years {params['startyear']}:{params['endyear']}"
    if request.source.name not in SOURCES:
        return f"run once with --{label} {options}"
    if params.get("usehorizon") == 0:
        options += " --no-horizon"
    if "raddatabase" in params:
        options += f" --raddatabase {params['raddatabase']}"
    given = _option(weather, "url", None)
    if given is not None:
        options += f" --url {redacted(given)}"
    return f"foldopt weather fetch {request.source.name} {options}"


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


class _Deadline:
    """A fetch's whole time [s] (``weather.timeout_s``): connecting, every read, every retry.
    When it is spent the sockets the fetch opened are shut, so that a service that sends its
    answer a byte at a time, each read within any per-read timeout, is given up on all the same.

    Parameters
    ----------
    seconds : float
    """

    def __init__(self, seconds: float):
        self.end = time.monotonic() + seconds
        self.expired = False
        self._sockets: list = []
        self._lock = threading.Lock()
        self._timer = threading.Timer(seconds, self._expire)
        self._timer.daemon = True

    def __enter__(self):
        self._timer.start()
        return self

    def __exit__(self, *exc) -> None:
        self._timer.cancel()

    def left(self) -> float:
        """Seconds left [s], 0 once spent."""
        return max(self.end - time.monotonic(), 0.0)

    def watch(self, sock) -> None:
        """Shut ``sock`` at the deadline (at once where it is spent)."""
        with self._lock:
            self._sockets.append(sock)
            expired = self.expired
        if expired:
            _shut(sock)

    def _expire(self) -> None:
        with self._lock:
            self.expired = True
            sockets = list(self._sockets)
        for sock in sockets:
            _shut(sock)

    def session(self):
        """A ``requests`` session whose connections the deadline watches."""
        import requests
        from requests.adapters import HTTPAdapter

        deadline = self

        class Watched(HTTPAdapter):
            def get_connection_with_tls_context(self, *args, **kwargs):
                pool = super().get_connection_with_tls_context(*args, **kwargs)
                if getattr(pool.ConnectionCls, "deadline", None) is not deadline:
                    pool.ConnectionCls = _watched(pool.ConnectionCls, deadline)
                return pool

        session = requests.Session()
        for prefix in ("http://", "https://"):
            session.mount(prefix, Watched())
        return session


def _watched(connection_class, deadline: _Deadline):
    """``connection_class`` (urllib3's) whose sockets ``deadline`` shuts when it is spent."""

    class Watched(connection_class):
        def connect(self):
            super().connect()
            deadline.watch(self.sock)

    Watched.deadline = deadline
    return Watched


def _shut(sock) -> None:
    # the plain socket's shutdown: it wakes a read blocked in another thread (an SSL socket's own
    # would unwrap the socket under its reader)
    with contextlib.suppress(OSError):
        socket.socket.shutdown(sock, socket.SHUT_RDWR)


def _download(request: _Request, label: str) -> bytes:
    """The answer's bytes, after at most :data:`MAX_ATTEMPTS` requests (a rate limit waits as
    the service asks, up to :data:`MAX_RETRY_WAIT_S`), all within ``request.timeout_s``."""
    import requests

    service, host = request.source.service, request.base
    late = WeatherError(
        f"{label}: {service} at {host} did not answer within {request.timeout_s:g} s "
        "(weather.timeout_s sets the wait); its whole answer must come within it: nothing was "
        "cached, try again later"
    )
    with _Deadline(request.timeout_s) as deadline, deadline.session() as session:
        for attempt in range(1, MAX_ATTEMPTS + 1):
            _pace()
            if deadline.left() == 0:
                raise late
            try:
                with session.get(
                    request.base + request.source.route,
                    params=[*request.query, *request.params.items()],
                    timeout=deadline.left(),
                    stream=True,
                    headers={"User-Agent": "foldopt"},
                ) as response:
                    payload = _body(response, label, service)
            except Exception as error:
                # a read the deadline cut short fails as a cut answer or a closed connection
                if deadline.expired or isinstance(error, requests.exceptions.Timeout):
                    raise late from None
                if isinstance(error, requests.exceptions.RequestException):
                    raise WeatherError(f"{label}: {_network_fault(error, service, host)}") from None
                raise
            if deadline.expired:
                raise late
            if response.status_code == 429 and attempt < MAX_ATTEMPTS:
                wait = _retry_after(response.headers.get("Retry-After"))
                if wait > MAX_RETRY_WAIT_S or wait >= deadline.left():
                    limit = (
                        f"longer than foldopt waits ({MAX_RETRY_WAIT_S:g} s)"
                        if wait > MAX_RETRY_WAIT_S
                        else f"past the request's {request.timeout_s:g} s (weather.timeout_s)"
                    )
                    raise WeatherError(
                        f"{label}: {service} limits the rate of requests and asks to wait "
                        f"{wait:g} s, {limit}; try again later"
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
        # A key that reads "message" is spelled so in the text, or with a \u escape: an answer
        # with neither (a whole TMY or series, 1-3 MB) holds none, and is not decoded for it (some
        # 20 ms) before its check below decodes it.
        spelled = "message" in text or "\\u" in text
        refusal = (
            json.loads(text).get("message") if spelled and text.lstrip().startswith("{") else None
        )
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
        reason = _unreadable(temporary, source.format, path)
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


def _unreadable(path: Path, fmt: str, cached_as: Path) -> str | None:
    """Why an answer is not a readable file of its format (every check a file of it gets), or
    None; ``cached_as`` is the file it becomes
    (:func:`~foldopt.inputs.weather.reader.check_answer`)."""
    if fmt != "horizon":
        from foldopt.inputs.weather import reader as files

        try:
            files.check_answer(path, fmt, cached_as)
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
