"""Weather fetched by name (issue 42): ``--weather pvgis-tmy`` against a real HTTP server on
127.0.0.1 that serves PVGIS's recorded answer (tests/data/pvgis/README.md), found through
``FOLDOPT_PVGIS_URL`` as a mirror would be. The fetched year is the recorded file to the bit,
a second run asks nothing, every fault of the service or the network is one line, exit 2, and
leaves the cache as it was; ``--offline`` runs from the cache alone. No test reaches the internet.
"""

import hashlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from foldopt.cli.app import app
from foldopt.inputs.study_file import default_study_path

runner = CliRunner()
RECORDED = Path(__file__).parent / "data" / "pvgis" / "tmy_45.000_8.000_2005_2023.json"
HORIZON = Path(__file__).parent / "data" / "pvgis" / "printhorizon_45.000_8.000.json"
HOURLY = Path(__file__).parent / "data" / "pvgis" / "seriescalc_45.000_8.000_2020_2021.json"
#: A few days of the year at a 5-degree fold-angle grid: enough to compare the two paths.
SWEEP = ["sweep", "angle", "--lat", "45", "--lon", "8", "--p-load", "4", "--engine", "numpy",
         "--angle-step", "5", "--step-min", "5", "--format", "json"]

#: The server: PVGIS's routes ``<mode>-<tag>/api/v5_3/tmy``, ``.../printhorizon`` and
#: ``.../seriescalc`` answered as ``mode`` says (``ok`` the route's recorded answer, the others a
#: fault), ``/_count`` the requests of each ``<mode>-<tag>``, ``/_queries`` their routes and
#: queries. It ends itself after its lifetime whatever happens to the test.
SERVER = r"""
import json, os, socket, sys, threading, time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from urllib.parse import urlsplit

BODIES = {"tmy": open(sys.argv[1], "rb").read(), "printhorizon": open(sys.argv[3], "rb").read(),
          "seriescalc": open(sys.argv[4], "rb").read()}
counts, queries, lock = {}, {}, threading.Lock()


class Handler(BaseHTTPRequestHandler):
    def log_message(self, *args):
        pass

    def do_GET(self):
        url = urlsplit(self.path)
        parts = url.path.strip("/").split("/")
        if parts == ["_count"]:
            return self.send(200, json.dumps(counts).encode())
        if parts == ["_queries"]:
            return self.send(200, json.dumps(queries).encode())
        with lock:
            counts[parts[0]] = n = counts.get(parts[0], 0) + 1
            queries.setdefault(parts[0], []).append([parts[-1], url.query])
        mode = parts[0].split("-")[0]
        if parts[1:3] != ["api", "v5_3"] or len(parts) != 4 or parts[3] not in BODIES:
            return self.send(404, b"")
        BODY = BODIES[parts[3]]
        if mode == "auth":  # a mirror behind a user and password: user:secret
            good = self.headers.get("Authorization") == "Basic dXNlcjpzZWNyZXQ="
            return self.send(200, BODY) if good else self.send(401, b"")
        if mode in ("trickle", "tricklehead"):  # a byte every 0.05 s, each read in time
            return self.trickle(BODY, mode == "trickle")
        if mode == "ok" or (mode == "rate" and n > 1) or (mode == "flaky" and n != 2):
            return self.send(200, BODY)
        if mode == "rate":
            return self.send(429, b"", {"Retry-After": "1"})
        if mode == "ratelong":
            return self.send(429, b"", {"Retry-After": "3600"})
        if mode in ("e500", "flaky"):
            return self.send(500, b"")
        if mode in ("refuse", "refuseescaped"):  # a refusal with status 200, its key as JSON allows
            key = b"message" if mode == "refuse" else b"\\u006dessage"
            return self.send(200, b'{"%s": "Location over the sea", "status": 400}' % key)
        if mode == "cut":  # the headers promise the whole answer, half of it comes
            self.send_response(200)
            self.send_header("Content-Length", str(len(BODY)))
            self.end_headers()
            self.wfile.write(BODY[: len(BODY) // 2])
            self.close_connection = True
            return
        if mode == "half":  # a whole answer of half the bytes
            return self.send(200, BODY[: len(BODY) // 2])
        if mode == "slow":
            time.sleep(3)
            return self.send(200, BODY)
        if mode == "close":
            self.close_connection = True
            self.connection.shutdown(socket.SHUT_RDWR)
            return
        return self.send(404, b"")

    def trickle(self, body, headers_first):
        if headers_first:  # the headers at once, promising the whole answer
            self.send_response(200)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.flush()
            slow = body
        else:  # not even the status line in one piece
            slow = b"HTTP/1.0 200 OK\r\nContent-Length: %d\r\n\r\n" % len(body) + body
        try:
            for byte in slow[:240]:  # 12 s at most, then the connection closes
                self.wfile.write(bytes([byte]))
                self.wfile.flush()
                time.sleep(0.05)
        except (BrokenPipeError, ConnectionResetError):
            pass  # the client gave up: what is tested
        self.close_connection = True

    def send(self, status, body, headers=()):
        self.send_response(status)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(body)))
        for item in dict(headers).items():
            self.send_header(*item)
        self.end_headers()
        try:
            self.wfile.write(body)
        except (BrokenPipeError, ConnectionResetError):
            pass  # a client that gave up waiting (the timeout's test)


server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
server.daemon_threads = True
print(server.server_address[1], flush=True)
threading.Timer(float(sys.argv[2]), lambda: os._exit(0)).start()
server.serve_forever()
"""


@pytest.fixture(scope="module")
def server(request):
    """The server's port, the server started on a free port and stopped by its pid."""
    process = subprocess.Popen([sys.executable, "-c", SERVER, str(RECORDED), "120", str(HORIZON),
                                str(HOURLY)], stdout=subprocess.PIPE, text=True)
    request.addfinalizer(lambda: (os.kill(process.pid, signal.SIGTERM), process.wait(timeout=10)))
    port = process.stdout.readline().strip()
    assert port.isdigit(), "the server did not start"
    return int(port)


def requests_made(port: int, route: str) -> int:
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/_count", timeout=5) as answer:
        return json.loads(answer.read()).get(route, 0)


@pytest.fixture
def pvgis(server, tmp_path, monkeypatch, request):
    """Point foldopt at ``<mode>-<this test>`` on the server, in a cache folder of its own:
    ``pvgis("ok")`` gives the route, whose requests :func:`requests_made` counts."""
    monkeypatch.setenv("FOLDOPT_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("FOLDOPT_OFFLINE", raising=False)
    monkeypatch.chdir(tmp_path)

    def route(mode: str) -> str:
        name = f"{mode}-" + re.sub(r"\W", "_", request.node.name)
        monkeypatch.setenv("FOLDOPT_PVGIS_URL", f"http://127.0.0.1:{server}/{name}/api/v5_3/")
        return name

    return route


@pytest.fixture(scope="module")
def cached(server, tmp_path_factory):
    """``cached(tmp_path, *options)``: the cache of ``weather fetch *options`` in the test's own
    cache folder, as the fetch leaves it (the answer and its provenance record), for tests that
    start from a cached answer (a fault must leave it as it was; a damaged copy). Each fetch is
    made once a module, from the server's recorded answers, and copied; returns the test's
    :func:`cache_files`."""
    made = {}

    def copy(tmp_path: Path, *options) -> dict:
        if options not in made:
            folder = tmp_path_factory.mktemp("cached")
            with pytest.MonkeyPatch.context() as patch:
                patch.setenv("FOLDOPT_CACHE_DIR", str(folder))
                patch.setenv("FOLDOPT_PVGIS_URL", f"http://127.0.0.1:{server}/ok-cached/api/v5_3/")
                patch.delenv("FOLDOPT_OFFLINE", raising=False)
                done = runner.invoke(app, ["weather", "fetch", *options])
            assert done.exit_code == 0, done.output
            made[options] = folder / "weather"
        shutil.copytree(made[options], tmp_path / "cache" / "weather", dirs_exist_ok=True)
        return cache_files(tmp_path)

    return copy


def cache_files(tmp_path: Path) -> dict:
    folder = tmp_path / "cache" / "weather"
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())} if folder.is_dir() else {}


def csv_files(folder: Path) -> dict:
    return {p.name: p.read_bytes() for p in sorted(folder.glob("*.csv"))}


@pytest.mark.parametrize("days", ["2025-06-21", "2025-01-15,2025-06-21,2025-09-30"],
                         ids=["a day, every angle", "three days, one angle"])
def test_the_fetched_year_is_the_recorded_file_to_the_bit(pvgis, server, tmp_path, figures_drawn_elsewhere,
                                                           days):
    route = pvgis("ok")
    fetched = runner.invoke(app, [*SWEEP, "--days", days, "--weather", "pvgis-tmy", "--out", "fetched"])
    assert fetched.exit_code == 0, fetched.output
    with figures_drawn_elsewhere():  # the fetched run's, of the same data
        read = runner.invoke(app, [*SWEEP, "--days", days, "--weather", str(RECORDED), "--out", "read"])
    assert read.exit_code == 0, read.output
    fetched, read = json.loads(fetched.stdout), json.loads(read.stdout)
    assert fetched["rows"] == read["rows"]  # every design's t_solar (at every angle of a day)
    assert fetched["answer"]["result"] == read["answer"]["result"]
    tables = csv_files(tmp_path / "fetched")
    assert tables == csv_files(tmp_path / "read") and tables  # sweep.csv, timeseries.csv ...
    assert requests_made(server, route) == 1
    # run.json says which data made it: the source, the request, the cached answer's hash
    meta = json.loads((tmp_path / "fetched" / "run.json").read_text())
    source = meta["weather_source"]
    assert source["sha256"] == hashlib.sha256(RECORDED.read_bytes()).hexdigest()
    assert source["url"].endswith("/api/v5_3/tmy?lat=45.0&lon=8.0&outputformat=json")
    assert source["source"] == "pvgis-tmy" and source["service_version"] == "v5_3"
    assert meta["study"]["weather"]["source"] == "pvgis-tmy"
    assert "weather_source" not in json.loads((tmp_path / "read" / "run.json").read_text())


def test_fetch_is_silent_quiet_and_one_json_document(pvgis, server, tmp_path):
    """``weather fetch -q`` prints nothing; ``--format json`` one document, the cached answer's
    provenance (its SHA-256 the recorded file's), the second time from the cache."""
    pvgis("ok")
    site = ["weather", "fetch", "pvgis-tmy", "--lat", "45", "--lon", "8"]
    quiet = runner.invoke(app, [*site, "-q"])
    assert quiet.exit_code == 0 and quiet.stdout == "", quiet.output
    document = runner.invoke(app, [*site, "--format", "json"])
    assert document.exit_code == 0, document.output
    record = json.loads(document.stdout)
    assert record["sha256"] == hashlib.sha256(RECORDED.read_bytes()).hexdigest()
    assert record["source"] == "pvgis-tmy"


def test_a_second_run_asks_nothing_and_offline_runs_from_the_cache(pvgis, server, tmp_path,
                                                                 folders_written_elsewhere):
    route = pvgis("ok")
    first = runner.invoke(app, ["weather", "fetch", "pvgis-tmy", "--lat", "45", "--lon", "8"])
    assert first.exit_code == 0, first.output
    # the site as PVGIS rounds it: 45.0001 is 45.000, the same answer
    again = runner.invoke(app, ["weather", "fetch", "pvgis-tmy", "--lat", "45.0001", "--lon", "8"])
    assert again.exit_code == 0, again.output
    assert requests_made(server, route) == 1
    assert cache_files(tmp_path)[next(iter(cache_files(tmp_path)))] == RECORDED.read_bytes()
    dead = pvgis("e500")  # a service that would fail: offline never asks it
    with folders_written_elsewhere():  # test_the_fetched_year's [a day, every angle]: this sweep
        offline = runner.invoke(app, [*SWEEP, "--days", "2025-06-21", "--weather", "pvgis-tmy",
                                      "--offline", "--out", "offline"])
    assert offline.exit_code == 0, offline.output
    assert requests_made(server, dead) == 0
    listed = runner.invoke(app, ["weather", "list", "--format", "json"])
    assert [entry["params"]["lat"] for entry in json.loads(listed.stdout)] == [45.0]
    kept = runner.invoke(app, ["weather", "path", "--lat", "45", "--lon", "8", "--out", "site.json"])
    assert kept.exit_code == 0, kept.output
    assert (tmp_path / "site.json").read_bytes() == RECORDED.read_bytes()


def test_a_fetched_year_is_read_once_and_as_its_file(pvgis, server, tmp_path, monkeypatch):
    """The answer's check before it is cached reads the year the study that fetched it reads next:
    that read takes the check's hours, the same bits as the cached file read afresh."""
    import pandas as pd

    from foldopt.inputs.weather import reader

    pvgis("ok")
    assert runner.invoke(app, ["weather", "fetch", "--lat", "45", "--lon", "8"]).exit_code == 0
    (answer,) = (p for p in (tmp_path / "cache" / "weather").iterdir() if "provenance" not in p.name)
    reads = []
    checked = reader._read_checked
    monkeypatch.setattr(reader, "_read_checked", lambda *args: reads.append(args) or checked(*args))
    fetched = reader.read_weather(answer)
    assert reads == []
    reader._read_once.cache_clear()
    pd.testing.assert_frame_equal(fetched, reader.read_weather(answer), check_exact=True)
    assert len(reads) == 1


def test_offline_without_a_cached_copy_is_one_line(pvgis, server, tmp_path):
    route = pvgis("ok")
    result = runner.invoke(app, [*SWEEP, "--weather", "pvgis-tmy", "--offline", "--out", "x"])
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == [
        "error: --weather pvgis-tmy: no cached copy for (45, 8) with these options, and offline "
        "(--offline, FOLDOPT_OFFLINE=1) nothing is fetched; fetch it first where there is a "
        "network: foldopt weather fetch pvgis-tmy --lat 45 --lon 8"]
    os.environ["FOLDOPT_OFFLINE"] = "1"  # the environment's word for it, restored by monkeypatch
    try:
        fetch = runner.invoke(app, ["weather", "fetch", "--lat", "45", "--lon", "8"])
    finally:
        del os.environ["FOLDOPT_OFFLINE"]
    assert fetch.exit_code == 2 and "no cached copy" in fetch.stderr
    assert requests_made(server, route) == 0 and cache_files(tmp_path) == {}
    assert not (tmp_path / "x").exists()


#: Each fault the service or the network can make, and what its one line says.
FAULTS = [
    ("e500", [], "PVGIS answered 500 Internal Server Error; try again later"),
    ("ratelong", [], "PVGIS limits the rate of requests and asks to wait 3600 s, longer than "
                     "foldopt waits (60 s); try again later"),
    ("cut", [], "PVGIS's answer was cut off after "),
    ("half", [], "PVGIS's answer is not a readable PVGIS TMY (not valid JSON: "),
    ("close", [], "closed the connection without an answer; nothing was cached, try again"),
    ("slow", ["--timeout", "0.2"], "did not answer within 0.2 s (weather.timeout_s sets the wait); its "
                                   "whole answer must come within it: nothing was cached"),
]


@pytest.mark.parametrize(("mode", "options", "said"), FAULTS, ids=[f[0] for f in FAULTS])
def test_a_fault_is_one_line_and_leaves_the_cache_as_it_was(pvgis, server, cached, tmp_path, mode,
                                                            options, said):
    before = cached(tmp_path, "--lat", "45", "--lon", "8", "--no-horizon")
    assert before
    route = pvgis(mode)
    started = time.monotonic()
    result = runner.invoke(app, ["weather", "fetch", "--lat", "45", "--lon", "8", *options])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: weather pvgis-tmy: ") and said in lines[0]
    assert cache_files(tmp_path) == before  # nothing new, nothing half-written, nothing lost
    assert requests_made(server, route) == 1
    assert time.monotonic() - started < 3  # bounded: the slow server sleeps 3 s


@pytest.mark.parametrize("mode", ["refuse", "refuseescaped"])
def test_a_refusal_with_status_200_is_one_line_and_caches_nothing(pvgis, server, tmp_path, mode):
    """PVGIS's ``{"message": ...}`` with status 200, its key spelled plainly or with a \\u escape."""
    route = pvgis(mode)
    result = runner.invoke(app, ["weather", "fetch", "--lat", "45", "--lon", "8"])
    assert (result.exit_code, result.stderr.strip().splitlines()) == (2, [
        "error: weather pvgis-tmy: PVGIS refused the request: Location over the sea"])
    assert cache_files(tmp_path) == {} and requests_made(server, route) == 1


def test_a_fault_through_a_sweep_is_the_same_line_and_exit_2(pvgis, tmp_path):
    pvgis("e500")
    result = runner.invoke(app, [*SWEEP, "--weather", "pvgis-tmy", "--out", "x"])
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == [
        "error: --weather pvgis-tmy: PVGIS answered 500 Internal Server Error; try again later"]
    assert not (tmp_path / "x").exists() and cache_files(tmp_path) == {}


def test_a_rate_limit_waits_as_the_service_asks(pvgis, server, tmp_path):
    route = pvgis("rate")
    started = time.monotonic()
    result = runner.invoke(app, ["weather", "fetch", "--lat", "45", "--lon", "8"])
    assert result.exit_code == 0, result.output
    assert time.monotonic() - started >= 1.0  # Retry-After: 1
    assert requests_made(server, route) == 2
    assert list(cache_files(tmp_path).values())[0] == RECORDED.read_bytes()


def test_a_cache_folder_that_cannot_be_written_is_one_line(pvgis, server, tmp_path, monkeypatch):
    route = pvgis("ok")
    (tmp_path / "file").write_text("not a folder")
    monkeypatch.setenv("FOLDOPT_CACHE_DIR", str(tmp_path / "file" / "cache"))
    result = runner.invoke(app, ["weather", "fetch", "--lat", "45", "--lon", "8"])
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert lines == [f"error: weather pvgis-tmy: cannot cache the answer in {tmp_path / 'file' / 'cache' / 'weather'} "
                     "(Not a directory); FOLDOPT_CACHE_DIR names another cache folder"]
    assert requests_made(server, route) == 1


def test_a_study_file_names_the_source_and_its_address(pvgis, server, tmp_path, monkeypatch):
    route = pvgis("ok")
    url = os.environ.pop("FOLDOPT_PVGIS_URL")  # the study's weather.url, not the environment's
    monkeypatch.delenv("FOLDOPT_PVGIS_URL", raising=False)
    embedded = {k: v for k, v in yaml.safe_load(default_study_path().read_text()).items() if k != "sky"}
    study = {**embedded, "mode": "exact",
             "site": {"latitude": 45.0, "longitude": 8.0}, "date": "2025-06-21", "p_load": 4,
             "fold_angles": {"start": 30, "stop": 180, "step": 30}, "step_min": 10,
             "weather": {"source": "pvgis-tmy", "url": url, "timeout_s": 10}}
    (tmp_path / "site.yaml").write_text(yaml.safe_dump(study))
    result = runner.invoke(app, ["run", "site.yaml", "--out", "out", "--quiet", "--engine", "numpy"])
    assert result.exit_code == 0, result.output
    assert requests_made(server, route) == 1
    meta = json.loads((tmp_path / "out" / "run.json").read_text())
    assert meta["weather_source"]["url"].startswith(url)
    bad = {**study, "weather": {"source": "pvgis-tmy", "years": "2020:2005"}}
    (tmp_path / "bad.yaml").write_text(yaml.safe_dump(bad))
    refused = runner.invoke(app, ["run", "bad.yaml", "--out", "bad"])
    assert refused.exit_code == 2
    assert "weather.years" in refused.stderr and "the first year comes after the last" in refused.stderr
    assert requests_made(server, route) == 1


def test_a_full_cache_folder_is_one_line_and_leaves_nothing(pvgis, server, small_disk, monkeypatch):
    route = pvgis("ok")
    monkeypatch.setenv("FOLDOPT_CACHE_DIR", str(small_disk / "cache"))
    (small_disk / "filler").write_bytes(b"\0" * 1_000_000)  # 2 MB disk: the 1.4 MB answer cannot fit
    result = runner.invoke(app, ["weather", "fetch", "--lat", "45", "--lon", "8"])
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == [
        f"error: weather pvgis-tmy: cannot cache the answer in {small_disk / 'cache' / 'weather'} (the file "
        "system is full); FOLDOPT_CACHE_DIR names another cache folder"]
    assert list((small_disk / "cache" / "weather").iterdir()) == []  # no partial file
    assert requests_made(server, route) == 1


def test_a_damaged_cached_answer_is_fetched_again(pvgis, server, tmp_path):
    route = pvgis("ok")
    assert runner.invoke(app, ["weather", "fetch", "--lat", "45", "--lon", "8"]).exit_code == 0
    answer = next(p for p in (tmp_path / "cache" / "weather").iterdir() if "provenance" not in p.name)
    answer.write_bytes(answer.read_bytes().replace(b'"G(h)": 0.0', b'"G(h)": 9.0', 1))  # one flipped value
    offline = runner.invoke(app, ["weather", "path", "--lat", "45", "--lon", "8"])
    assert offline.exit_code == 2 and "is damaged" in offline.stderr  # not read as if whole
    assert runner.invoke(app, ["weather", "fetch", "--lat", "45", "--lon", "8"]).exit_code == 0
    assert requests_made(server, route) == 2
    assert answer.read_bytes() == RECORDED.read_bytes()


def test_a_source_is_fetched_for_one_site(pvgis, server, tmp_path):
    route = pvgis("ok")
    result = runner.invoke(app, ["sweep", "latitude", "--lat", "40,45", "--lon", "8", "--days", "2025-06-21",
                                 "--weather", "pvgis-tmy", "--out", "x"])
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == [
        "error: --lat = [40.0, 45.0]: varies, but weather.source pvgis-tmy is fetched for one site; give one site "
        "(fetch several ahead with foldopt weather fetch, one site each)"]
    assert requests_made(server, route) == 0


def test_a_map_fetches_each_site_once_and_a_stopped_fetch_resumes(pvgis, server, tmp_path):
    """foldopt map --sites --weather pvgis-tmy: each site's answer is fetched before the map starts,
    one request a site (two names of one site as PVGIS rounds it: one), each cached as it comes,
    so that a fetch stopped by a fault resumes with the sites not yet fetched. (The server gives
    the recorded 45 N, 8 E answer to every site: what is tested is the requests.)"""
    from foldopt.studies.request import make_request

    (tmp_path / "sites.csv").write_text("name,latitude,longitude\nturin,45,8\nturin-b,45.0001,8\n"
                                        "asti,44.9,8.2\nalba,44.7,8.03\n")
    flaky = pvgis("flaky")  # the second request fails: asti's
    result = runner.invoke(app, ["map", "--sites", "sites.csv", "--weather", "pvgis-tmy", "--out", "map"])
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == [
        "error: site asti: weather pvgis-tmy: PVGIS answered 500 Internal Server Error; try again later"]
    assert requests_made(server, flaky) == 2 and not (tmp_path / "map").exists()
    assert len(cache_files(tmp_path)) == 2  # turin's answer and its provenance
    route = pvgis("ok")
    request = make_request("map", where={"sites": tmp_path / "sites.csv", "weather": {"source": "pvgis-tmy"}}).plan
    assert requests_made(server, route) == 2  # asti and alba: turin's came from the cache
    files = [Path(site["weather"]) for site in request.sites]
    assert [site["name"] for site in request.sites] == ["turin", "turin-b", "asti", "alba"]
    assert files[0] == files[1] and len(set(files)) == 3
    assert all(path.read_bytes() == RECORDED.read_bytes() for path in files)


def test_a_maps_weather_options_are_checked_before_anything_is_fetched(pvgis, server, tmp_path):
    route = pvgis("ok")
    (tmp_path / "sites.csv").write_text("name,latitude,longitude\nturin,45,8\n")
    for options, line in [
        (["--weather", "pvgis-tmx"], "error: --weather = 'pvgis-tmx': must be one of pvgis-tmy, "
                                     "pvgis-hourly; did you mean 'pvgis-tmy'?"),
        (["--years", "2005:2020"], "error: --years: the years of a weather source; give one with --weather"),
        (["--weather", "pvgis-tmy", "--years", "2005"], "error: --years = '2005': the first and last year as "
                                                        "START:END, e.g. 2005:2020"),
        (["--weather", "pvgis-tmy", "--offline"], "error: site turin: weather pvgis-tmy: no cached copy for (45, "
                                                  "8) with these options, and offline (--offline, "
                                                  "FOLDOPT_OFFLINE=1) nothing is fetched; fetch it first where "
                                                  "there is a network: foldopt weather fetch pvgis-tmy --lat 45 "
                                                  "--lon 8"),
    ]:
        result = runner.invoke(app, ["map", "--sites", "sites.csv", *options, "--out", "map"])
        assert (result.exit_code, result.stderr.strip().splitlines()) == (2, [line]), options
    assert requests_made(server, route) == 0 and cache_files(tmp_path) == {}


# --horizon pvgis: the site's horizon from PVGIS's printhorizon, recorded for 45 N, 8 E
# (tests/data/pvgis/README.md), read as the horizon file it is.
HORIZON_DAY = [*SWEEP, "--days", "2025-01-15"]  # a low winter sun, under the hills to the south


def test_the_fetched_horizon_is_the_recorded_file_to_the_bit(pvgis, server, tmp_path, figures_drawn_elsewhere,
                                                             folders_written_elsewhere):
    route = pvgis("ok")
    fetched = runner.invoke(app, [*HORIZON_DAY, "--horizon", "pvgis", "--out", "fetched"])
    assert fetched.exit_code == 0, fetched.output
    with figures_drawn_elsewhere():  # the fetched run's, of the same data
        read = runner.invoke(app, [*HORIZON_DAY, "--horizon", str(HORIZON), "--out", "read"])
    assert read.exit_code == 0, read.output
    with folders_written_elsewhere():  # the fetched run's sweep, the horizon left out: its rows alone
        flat = runner.invoke(app, [*HORIZON_DAY, "--out", "flat"])
    assert flat.exit_code == 0, flat.output
    fetched, read, flat = (json.loads(r.stdout) for r in (fetched, read, flat))
    assert fetched["rows"] == read["rows"]  # every angle's t_solar, to the bit
    assert fetched["answer"]["result"] == read["answer"]["result"]
    assert fetched["rows"] != flat["rows"]  # the horizon (up to 12.6 deg to the south) counts
    assert requests_made(server, route) == 1
    answer, = (p for p in (tmp_path / "cache" / "weather").iterdir() if "provenance" not in p.name)
    assert answer.name.startswith("pvgis-horizon_v5_3_45.000_8.000_")
    assert answer.read_bytes() == HORIZON.read_bytes()
    provenance = json.loads(answer.with_name(answer.stem + ".provenance.json").read_text())
    assert provenance["url"].endswith("/api/v5_3/printhorizon?lat=45.0&lon=8.0&outputformat=json")
    assert provenance["sha256"] == hashlib.sha256(HORIZON.read_bytes()).hexdigest()
    meta = json.loads((tmp_path / "fetched" / "run.json").read_text())
    assert meta["horizon_source"]["sha256"] == provenance["sha256"]
    assert "horizon_source" not in json.loads((tmp_path / "read" / "run.json").read_text())
    # a second run asks nothing; offline, a service that would fail is never asked
    with folders_written_elsewhere():  # the first run's, of the same data: their rows alone
        again = runner.invoke(app, [*HORIZON_DAY, "--horizon", "pvgis", "--out", "again"])
        assert again.exit_code == 0 and json.loads(again.stdout)["rows"] == read["rows"]
        assert requests_made(server, route) == 1
        dead = pvgis("e500")
        offline = runner.invoke(app, [*HORIZON_DAY, "--horizon", "pvgis", "--offline", "--out", "off"])
    assert offline.exit_code == 0, offline.output
    assert json.loads(offline.stdout)["rows"] == read["rows"]
    assert requests_made(server, dead) == 0


def test_a_study_files_horizon_names_pvgis(pvgis, server, tmp_path):
    route = pvgis("ok")
    embedded = {k: v for k, v in yaml.safe_load(default_study_path().read_text()).items() if k != "sky"}
    study = {**embedded, "mode": "exact", "date": "2025-06-21", "p_load": 4, "step_min": 10,
             "site": {"latitude": 45.0, "longitude": 8.0, "horizon": "pvgis"},
             "fold_angles": {"start": 30, "stop": 180, "step": 30}}
    (tmp_path / "site.yaml").write_text(yaml.safe_dump(study))
    result = runner.invoke(app, ["run", "site.yaml", "--out", "out", "--quiet", "--engine", "numpy"])
    assert result.exit_code == 0, result.output
    assert requests_made(server, route) == 1
    meta = json.loads((tmp_path / "out" / "run.json").read_text())
    assert Path(meta["study"]["site"]["horizon"]["file"]).read_bytes() == HORIZON.read_bytes()
    source = meta["horizon_source"]  # which data made it: the request and the answer's hash
    assert source["source"] == "pvgis-horizon" and source["service_version"] == "v5_3"
    assert source["sha256"] == hashlib.sha256(HORIZON.read_bytes()).hexdigest()


HORIZON_FAULTS = [
    ("e500", "PVGIS answered 500 Internal Server Error; try again later"),
    ("half", "PVGIS's answer is not a readable PVGIS horizon profile (not valid JSON: "),
]


@pytest.mark.parametrize(("mode", "said"), HORIZON_FAULTS, ids=[f[0] for f in HORIZON_FAULTS])
def test_a_horizon_fault_is_one_line_and_leaves_the_cache_as_it_was(pvgis, server, cached, tmp_path,
                                                                    mode, said):
    before = cached(tmp_path, "--lat", "45", "--lon", "8")
    assert before
    route = pvgis(mode)
    result = runner.invoke(app, [*HORIZON_DAY, "--horizon", "pvgis", "--out", "x"])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: horizon pvgis: ") and said in lines[0]
    assert cache_files(tmp_path) == before and not (tmp_path / "x").exists()
    assert requests_made(server, route) == 1


def test_offline_without_a_cached_horizon_is_one_line(pvgis, server, tmp_path):
    route = pvgis("ok")
    result = runner.invoke(app, [*HORIZON_DAY, "--horizon", "pvgis", "--offline", "--out", "x"])
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == [
        "error: horizon pvgis: no cached copy for (45, 8) with these options, and offline "
        "(--offline, FOLDOPT_OFFLINE=1) nothing is fetched; fetch it first where there is a "
        "network: run once with --horizon pvgis --lat 45 --lon 8"]
    assert requests_made(server, route) == 0 and cache_files(tmp_path) == {}


# --weather pvgis-hourly: PVGIS's hourly series (seriescalc) of a horizontal plane for real years,
# recorded for 45 N, 8 E, 2020-2021 without components (G(i) alone; tests/data/pvgis/README.md),
# read as a measured file of the pvgis-hourly format: each real day a block, at its hourly step.
HOURLY_SWEEP = ["sweep", "angle", "--lat", "45", "--lon", "8", "--p-load", "4",
                "--angle-step", "15", "--format", "json"]
YEARS = ["--years", "2020:2021"]


def queries_made(port: int, route: str) -> list:
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/_queries", timeout=5) as answer:
        return json.loads(answer.read()).get(route, [])


def read_as_a_users_file(*options) -> list:
    """The recorded answer read the way a user's file is: ``--weather FILE --weather-format
    pvgis-hourly``, the same sweep."""
    return [*HOURLY_SWEEP, "--weather", str(HOURLY), "--weather-format", "pvgis-hourly", *options]


def test_the_fetched_series_is_the_recorded_file_to_the_bit(pvgis, server, tmp_path, figures_drawn_elsewhere):
    """The whole span, 731 real days each a block: the fetched series gives every fold angle's
    mean t_solar to the bit as the recorded file read as a user's file; the request is
    get_pvgis_hourly's for a horizontal plane with the components."""
    route = pvgis("ok")
    fetched = runner.invoke(app, [*HOURLY_SWEEP, "--weather", "pvgis-hourly", *YEARS, "--out", "fetched"])
    assert fetched.exit_code == 0, fetched.output
    with figures_drawn_elsewhere():  # the fetched run's, of the same data
        read = runner.invoke(app, [*read_as_a_users_file(), "--out", "read"])
    assert read.exit_code == 0, read.output
    fetched, read = json.loads(fetched.stdout), json.loads(read.stdout)
    assert fetched["rows"] == read["rows"]  # each day's t_solar at the chosen angle, to the bit
    assert fetched["answer"]["result"] == read["answer"]["result"]
    tables = csv_files(tmp_path / "fetched")
    assert tables == csv_files(tmp_path / "read") and tables  # every angle's, every day's
    days = sorted({row["date"] for row in fetched["rows"]})
    assert (len(days), days[0], days[-1]) == (731, "2020-01-01", "2021-12-31")  # 2022-01-01: 1 h
    notes = " ".join(note["note"] for note in fetched["answer"]["notes"])
    assert "G(i) alone" in notes and "erbs decomposition" in notes  # PVGIS's DNI/DHI are not in it
    (made,) = queries_made(server, route)
    assert made[0] == "seriescalc"
    assert dict(pair.split("=") for pair in made[1].split("&")) == {
        "lat": "45.0", "lon": "8.0", "outputformat": "json", "angle": "0", "components": "1",
        "startyear": "2020", "endyear": "2021"}
    meta = json.loads((tmp_path / "fetched" / "run.json").read_text())
    assert meta["weather_source"]["source"] == "pvgis-hourly"
    assert meta["weather_source"]["sha256"] == hashlib.sha256(HOURLY.read_bytes()).hexdigest()


def test_a_second_hourly_run_asks_nothing_and_offline_runs_from_the_cache(pvgis, server, tmp_path, monkeypatch,
                                                                          folders_written_elsewhere):
    from foldopt.inputs.weather import reader

    route = pvgis("ok")
    for _ in range(2):
        result = runner.invoke(app, ["weather", "fetch", "pvgis-hourly", "--lat", "45", "--lon", "8", *YEARS])
        assert result.exit_code == 0, result.output
    assert requests_made(server, route) == 1
    (cached,) = (p for p in (tmp_path / "cache" / "weather").iterdir() if "provenance" not in p.name)
    assert cached.name.startswith("pvgis-hourly_v5_3_45.000_8.000_")
    assert cached.read_bytes() == HOURLY.read_bytes()
    days = ["--days", "2020-06-21,2021-01-15"]
    dead = pvgis("e500")  # a service that would fail: offline never asks it
    reads = []  # the files read: the answer was read by the fetch's check, before it was cached
    measured = reader.read_measured
    monkeypatch.setattr(reader, "read_measured", lambda path, *args: reads.append(path) or measured(path, *args))
    with folders_written_elsewhere():  # days of this series, their rows alone (test_the_fetched_series')
        offline = runner.invoke(app, [*HOURLY_SWEEP, "--weather", "pvgis-hourly", *YEARS, *days, "--offline",
                                      "--out", "offline"])
        assert offline.exit_code == 0, offline.output
        read = runner.invoke(app, [*read_as_a_users_file(*days), "--out", "read"])
    assert json.loads(offline.stdout)["rows"] == json.loads(read.stdout)["rows"]  # the same bits
    assert cached.name not in [Path(path).name for path in reads]
    assert requests_made(server, dead) == 0
    other = runner.invoke(app, [*HOURLY_SWEEP, "--weather", "pvgis-hourly", "--years", "2019:2020", *days,
                                "--offline", "--out", "x"])  # other years: no cached copy
    assert other.exit_code == 2
    assert other.stderr.strip().splitlines() == [
        "error: --weather pvgis-hourly: no cached copy for (45, 8) with these options, and offline "
        "(--offline, FOLDOPT_OFFLINE=1) nothing is fetched; fetch it first where there is a network: "
        "foldopt weather fetch pvgis-hourly --lat 45 --lon 8 --years 2019:2020"]
    assert requests_made(server, dead) == 0 and not (tmp_path / "x").exists()


HOURLY_FAULTS = [
    ("e500", "PVGIS answered 500 Internal Server Error; try again later"),
    ("cut", "PVGIS's answer was cut off after "),
    ("half", "PVGIS's answer is not a readable PVGIS hourly series (not valid JSON: "),
]


@pytest.mark.parametrize(("mode", "said"), HOURLY_FAULTS, ids=[f[0] for f in HOURLY_FAULTS])
def test_an_hourly_fault_is_one_line_and_leaves_the_cache_as_it_was(pvgis, server, cached, tmp_path, mode,
                                                                    said):
    before = cached(tmp_path, "pvgis-hourly", "--lat", "45", "--lon", "8", "--years", "2019:2020")
    assert before
    route = pvgis(mode)
    result = runner.invoke(app, [*HOURLY_SWEEP, "--weather", "pvgis-hourly", *YEARS, "--out", "x"])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: --weather pvgis-hourly: ") and said in lines[0]
    assert cache_files(tmp_path) == before and not (tmp_path / "x").exists()
    assert requests_made(server, route) == 1


def test_years_outside_pvgis_record_are_refused_before_any_request(pvgis, server, tmp_path):
    """PVGIS 5.3's hourly series holds 2005 to 2023 (no recorded refusal of PVGIS's own to quote):
    foldopt's own line, nothing asked."""
    route = pvgis("ok")
    result = runner.invoke(app, [*HOURLY_SWEEP, "--weather", "pvgis-hourly", "--years", "2023:2024",
                                 "--out", "x"])
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == [
        "error: --weather pvgis-hourly: years 2023:2024 are outside PVGIS 5.3's record, 2005 to 2023; "
        "give years within it (--years, weather.years)"]
    fetch = runner.invoke(app, ["weather", "fetch", "pvgis-hourly", "--lat", "45", "--lon", "8",
                                "--years", "2004:2010"])
    assert fetch.exit_code == 2 and "years 2004:2010 are outside" in fetch.stderr
    assert requests_made(server, route) == 0 and cache_files(tmp_path) == {}


def test_a_source_read_as_a_measured_file_is_named_so():
    """The sources read as measured files (real days at their own step) are those whose format
    is a measured one: names.MEASURED_WEATHER_SOURCES is what the study's policy reads."""
    from foldopt.inputs.weather.sources import SOURCES
    from foldopt.names import HOURLY_WEATHER_FORMATS, MEASURED_WEATHER_SOURCES

    assert {name for name, source in SOURCES.items() if source.format not in HOURLY_WEATHER_FORMATS} == set(
        MEASURED_WEATHER_SOURCES)


def test_a_study_file_names_the_hourly_source_its_years_and_database(pvgis, server, tmp_path,
                                                                     folders_written_elsewhere):
    route = pvgis("ok")
    embedded = {k: v for k, v in yaml.safe_load(default_study_path().read_text()).items()
                if k not in ("sky", "step_min")}
    study = {**embedded, "mode": "exact", "site": {"latitude": 45.0, "longitude": 8.0},
             "date": "2021-06-21", "p_load": 4, "fold_angles": {"start": 30, "stop": 180, "step": 30},
             "weather": {"source": "pvgis-hourly", "years": "2020:2021", "raddatabase": "PVGIS-SARAH3"}}
    (tmp_path / "site.yaml").write_text(yaml.safe_dump(study))
    with folders_written_elsewhere():  # its request is what is read here, nothing of its folder
        result = runner.invoke(app, ["run", "site.yaml", "--out", "out", "--quiet"])
    assert result.exit_code == 0, result.output
    ((where, query),) = queries_made(server, route)
    assert where == "seriescalc" and "raddatabase=PVGIS-SARAH3" in query.split("&")
    tmy = {**study, "weather": {"source": "pvgis-tmy", "raddatabase": "PVGIS-SARAH3"}}
    (tmp_path / "tmy.yaml").write_text(yaml.safe_dump(tmy))
    refused = runner.invoke(app, ["run", "tmy.yaml", "--out", "tmy"])
    assert refused.exit_code == 2
    assert "weather.raddatabase is only used by the pvgis-hourly source" in refused.stderr
    (tmp_path / "sites.csv").write_text("name,latitude,longitude\nturin,45,8\n")
    mapped = runner.invoke(app, ["map", "--sites", "sites.csv", "--weather", "pvgis-hourly", *YEARS,
                                 "--out", "map"])
    assert (mapped.exit_code, mapped.stderr.strip().splitlines()) == (2, [
        "error: --weather pvgis-hourly: a map runs a typical year at each site; a series of real years "
        "is studied one site at a time (foldopt sweep angle --weather pvgis-hourly --years START:END)"])
    assert requests_made(server, route) == 1 and not (tmp_path / "map").exists()


def test_a_kept_hourly_series_read_without_its_format_says_which(tmp_path, monkeypatch):
    """The recorded series read as a .json file (a PVGIS TMY by its extension): one line naming
    the format it looks like."""
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["sweep", "angle", "--weather", str(HOURLY), "--p-load", "4", "--out", "x"])
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == [
        f"error: --weather {HOURLY.name}: not a PVGIS TMY file: no outputs.tmy_hourly list of hourly records; "
        "read as pvgis (by its extension .json), it looks like a pvgis-hourly file: give --weather-format "
        "pvgis-hourly (weather.format: pvgis-hourly in a study)"]


def test_camera_winter_by_its_live_source_is_its_committed_answer(pvgis, server, tmp_path,
                                                                  figures_drawn_elsewhere):
    """configs/camera-winter.yaml as a user without the recorded file writes it (``weather:
    {source: pvgis-hourly, years: "2020:2021"}``): the fetched real years, their air temperature
    through the cold, give the committed example's buffer tables to the bit (per year, per month,
    the cold's columns and the least-cost search)."""
    route = pvgis("ok")
    config = Path(__file__).resolve().parents[1] / "configs" / "camera-winter.yaml"
    live = re.sub(r"(?m)^weather: .*$", 'weather: {source: pvgis-hourly, years: "2020:2021"}',
                  config.read_text())
    assert "source: pvgis-hourly" in live
    (tmp_path / "camera-winter.yaml").write_text(live)
    with figures_drawn_elsewhere():  # test_camera_winter's, whole, of these same tables
        done = runner.invoke(app, ["run", "camera-winter.yaml", "--out", "live", "--quiet"])
    assert done.exit_code == 0, done.output
    example = config.parents[1] / "results" / "examples" / "camera-winter"
    for name in ("storage_annual", "storage_years", "storage_monthly", "design_space"):
        assert (tmp_path / "live" / f"{name}.csv").read_bytes() == (example / f"{name}.csv").read_bytes()
    assert requests_made(server, route) == 1
