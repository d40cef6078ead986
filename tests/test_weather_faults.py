"""Weather by name, its faults as classes (issue 47): a service that trickles its answer meets one
deadline for the whole fetch; a site out of range, an address that is not http(s) and a
FOLDOPT_OFFLINE that is no yes or no are refused before any request on every path that fetches;
a damaged cached copy is named (offline, ``weather path``) or fetched again, never read; an
address's user, password or key is never written; every ``weather`` subcommand takes --quiet and
--format json. Against the local server of tests/test_weather_fetch.py (127.0.0.1, recorded PVGIS
answers, stopped by its pid): each fault one line, exit 2, no traceback, the cache byte for byte
as it was, the server asked nothing where nothing should be asked. No test reaches the internet.
"""
# ruff: noqa: F811 - the server's fixtures are imported from test_weather_fetch and taken by name


import hashlib
import json
import math
import os
import time
from pathlib import Path

import pytest
import yaml

from foldopt.cli.app import app
from foldopt.errors import ConfigError
from foldopt.inputs.study_file import default_study_path
from test_weather_fetch import (  # noqa: F401 - cached, pvgis and server: fixtures
    RECORDED,
    SWEEP,
    cache_files,
    cached,
    pvgis,
    queries_made,
    requests_made,
    runner,
    server,
)

SITE = ["--lat", "45", "--lon", "8"]
FETCH = ["weather", "fetch", "pvgis-tmy", *SITE]


def one_error_line(result) -> str:
    """The one ``error:`` line of a refused command (exit 2, no traceback), without its prefix."""
    assert result.exit_code == 2, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    return lines[0].removeprefix("error: ")


def kept_entry(cached, tmp_path) -> dict:
    """A cached answer of other options (without the horizon) that a fault must leave as it is."""
    before = cached(tmp_path, *FETCH[2:], "--no-horizon")
    assert len(before) == 2
    return before


def study_file(tmp_path, name: str, site: dict, weather: dict | None = None) -> str:
    embedded = {k: v for k, v in yaml.safe_load(default_study_path().read_text()).items() if k != "sky"}
    study = {**embedded, "mode": "exact", "site": site, "date": "2025-06-21", "p_load": 4,
             "fold_angles": {"start": 30, "stop": 180, "step": 30}, "step_min": 10}
    if weather is not None:
        study["weather"] = weather
    (tmp_path / name).write_text(yaml.safe_dump(study))
    return name


# 1. One deadline for the whole fetch, connect and every read: a service that sends a byte every
#    0.05 s (its headers at once, or not even the status line whole) is given up on.

#: The whole fetch's deadline [s] against the trickle's byte every 0.05 s: each read comes in
#: time, only the whole fetch's deadline can end it. Short, as the wait is all wall time.
DEADLINE = "0.15"

@pytest.mark.parametrize("mode", ["trickle", "tricklehead"])
def test_a_trickling_service_is_given_up_on_at_the_deadline(pvgis, server, cached, tmp_path, mode):
    before = kept_entry(cached, tmp_path)
    route = pvgis(mode)
    started = time.monotonic()
    line = one_error_line(runner.invoke(app, [*FETCH, "--timeout", DEADLINE]))
    elapsed = time.monotonic() - started
    assert line.startswith("weather pvgis-tmy: PVGIS at http://127.0.0.1:")
    assert f"did not answer within {DEADLINE} s (weather.timeout_s sets the wait)" in line
    assert float(DEADLINE) <= elapsed < 4.0  # the deadline, not the 12 s the trickle lasts
    assert cache_files(tmp_path) == before and requests_made(server, route) == 1


def test_a_trickle_through_a_sweep_and_a_horizon_meets_the_studys_timeout(pvgis, server, tmp_path,
                                                                         folders_written_elsewhere):
    """weather.timeout_s (--set) bounds the weather's fetch and the horizon's alike."""
    route = pvgis("trickle")
    for options, label in [(["--weather", "pvgis-tmy"], "--weather pvgis-tmy"),
                           (["--weather", "pvgis-tmy", "--horizon", "pvgis"], "horizon pvgis")]:
        if label == "horizon pvgis":  # the weather cached, the horizon trickles
            pvgis("ok")
            with folders_written_elsewhere():  # test_weather_fetch's fetched year: this sweep
                assert runner.invoke(app, [*SWEEP, "--days", "2025-06-21", "--weather", "pvgis-tmy",
                                           "--out", "w"]).exit_code == 0
            route = pvgis("trickle")
        before, asked = cache_files(tmp_path), requests_made(server, route)
        started = time.monotonic()
        result = runner.invoke(app, [*SWEEP, "--days", "2025-06-21", *options,
                                     "--set", f"weather.timeout_s={DEADLINE}", "--out", "x"])
        line = one_error_line(result)
        assert line.startswith(f"{label}: ") and f"did not answer within {DEADLINE} s" in line
        assert time.monotonic() - started < 4.0
        assert cache_files(tmp_path) == before and not (tmp_path / "x").exists()
        assert requests_made(server, route) == asked + 1


def test_a_rate_limit_wait_past_the_deadline_is_refused_at_once(pvgis, server, tmp_path):
    """Retry-After: 1 s against a whole fetch of 0.8 s: no wait that cannot end in time."""
    route = pvgis("rate")
    started = time.monotonic()
    line = one_error_line(runner.invoke(app, [*FETCH, "--timeout", "0.8"]))
    assert "asks to wait 1 s, past the request's 0.8 s (weather.timeout_s)" in line
    assert time.monotonic() - started < 0.8 and requests_made(server, route) == 1
    assert cache_files(tmp_path) == {}


# 2, 8. A site out of range (or not finite) is refused before any request, on every path.

BAD_SITES = [("91", "8", "--lat"), ("-90.5", "8", "--lat"), ("45", "180.5", "--lon"),
             ("45", "-181", "--lon"), ("nan", "8", "--lat"), ("45", "inf", "--lon")]
PATHS = {
    "weather fetch": lambda lat, lon: ["weather", "fetch", "pvgis-tmy", "--lat", lat, "--lon", lon],
    "weather fetch hourly": lambda lat, lon: ["weather", "fetch", "pvgis-hourly", "--lat", lat,
                                              "--lon", lon, "--years", "2020:2021"],
    "weather path": lambda lat, lon: ["weather", "path", "--lat", lat, "--lon", lon],
    "sweep --weather": lambda lat, lon: [*SWEEP[:2], "--lat", lat, "--lon", lon, "--weather",
                                         "pvgis-tmy", "--out", "x"],
    "sweep --horizon": lambda lat, lon: [*SWEEP[:2], "--lat", lat, "--lon", lon, "--horizon",
                                         "pvgis", "--out", "x"],
}


@pytest.mark.parametrize(("lat", "lon", "option"), BAD_SITES, ids=[f"{a},{b}" for a, b, _ in BAD_SITES])
@pytest.mark.parametrize("path", list(PATHS))
def test_a_site_out_of_range_is_refused_before_any_request(pvgis, server, tmp_path, lat, lon,
                                                           option, path):
    route = pvgis("ok")
    line = one_error_line(runner.invoke(app, PATHS[path](lat, lon)))
    assert line.startswith(f"{option} = "), line
    assert "PVGIS" not in line  # nothing asked, nothing blamed on the service
    assert requests_made(server, route) == 0 and cache_files(tmp_path) == {}
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("site", [{"latitude": 91, "longitude": 8},
                                  {"latitude": 45, "longitude": -180.01},
                                  {"latitude": -91, "longitude": 8, "horizon": "pvgis"}])
def test_a_study_files_site_out_of_range_is_refused_before_any_request(pvgis, server, tmp_path, site):
    route = pvgis("ok")
    weather = None if "horizon" in site else {"source": "pvgis-tmy"}
    name = study_file(tmp_path, "site.yaml", site, weather)
    line = one_error_line(runner.invoke(app, ["run", name, "--out", "out"]))
    assert "latitude" in line or "longitude" in line or "--lat" in line or "--lon" in line, line
    assert "must be" in line and "PVGIS" not in line
    assert requests_made(server, route) == 0 and cache_files(tmp_path) == {}


def test_a_maps_site_out_of_range_is_refused_before_any_request(pvgis, server, tmp_path):
    route = pvgis("ok")
    (tmp_path / "sites.csv").write_text("name,latitude,longitude\nturin,45,8\npole,91,8\n")
    for options in (["--sites", "sites.csv"], ["--lat", "85:95:5", "--lon", "8"]):
        line = one_error_line(runner.invoke(app, ["map", *options, "--weather", "pvgis-tmy",
                                                  "--out", "map"]))
        assert "91" in line or "95" in line or "must be in [-90, 90]" in line, line
    assert requests_made(server, route) == 0 and cache_files(tmp_path) == {}


@pytest.mark.parametrize(("lat", "lon"), [(91.0, 8.0), (45.0, math.nan), (45.0, -math.inf), (True, 8.0)])
def test_the_library_refuses_a_site_out_of_range_before_any_request(pvgis, server, tmp_path, lat, lon):
    """Every path that fetches goes through sources.fetch: it checks the site itself."""
    from foldopt.inputs.weather.sources import fetch, fetch_horizon, site_problems

    route = pvgis("ok")
    for call in (lambda: fetch("pvgis-tmy", lat, lon), lambda: fetch_horizon("pvgis", lat, lon)):
        with pytest.raises(ConfigError) as raised:
            call()
        (line,) = raised.value.errors
        assert "site.l" in line and ("must be a finite number" in line or "a number of degrees" in line)
    assert requests_made(server, route) == 0 and cache_files(tmp_path) == {}
    # the bounds themselves are sites
    assert site_problems(90, 180) == site_problems(-90, -180) == []


def test_every_option_of_weather_fetch_is_checked_before_any_request(pvgis, server, tmp_path):
    route = pvgis("ok")
    result = runner.invoke(app, ["weather", "fetch", "pvgis-tmy", "--lat", "91", "--lon", "8",
                                 "--years", "2020", "--timeout", "0", "--format", "xml"])
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert [line.split(" = ")[0] for line in lines] == [
        "error: --format", "error: --lat", "error: --years", "error: --timeout"]
    assert requests_made(server, route) == 0 and cache_files(tmp_path) == {}


# 3. A damaged cached copy is named, with what is wrong and how to fetch it again; online it is
#    fetched again, never read as if whole.

def _flip(answer: Path) -> None:
    answer.write_bytes(answer.read_bytes().replace(b'"G(h)": 0.0', b'"G(h)": 9.0', 1))


def _cut(answer: Path) -> None:
    answer.write_bytes(answer.read_bytes()[:1000])


def _no_record(answer: Path) -> None:
    answer.with_name(answer.stem + ".provenance.json").unlink()


def _bad_record(answer: Path) -> None:
    answer.with_name(answer.stem + ".provenance.json").write_text("{not json")


def _no_answer(answer: Path) -> None:
    answer.unlink()


DAMAGES = {"a flipped value": (_flip, "its SHA-256 is not the one recorded"),
           "cut short": (_cut, "1,000 bytes where "),
           "no provenance record": (_no_record, "provenance record"),
           "an unreadable record": (_bad_record, "is not one foldopt wrote"),
           "no answer": (_no_answer, "its answer is missing")}


def damaged_cache(cached, tmp_path, damage) -> tuple[Path, dict]:
    cached(tmp_path, *FETCH[2:])
    answer = next(p for p in (tmp_path / "cache" / "weather").iterdir() if "provenance" not in p.name)
    damage(answer)
    return answer, cache_files(tmp_path)


@pytest.mark.parametrize("damage", list(DAMAGES))
def test_a_damaged_cached_copy_is_named_offline_and_by_weather_path(pvgis, server, cached, tmp_path,
                                                                     damage):
    answer, before = damaged_cache(cached, tmp_path, DAMAGES[damage][0])
    dead = pvgis("e500")
    for command in ([*SWEEP, "--days", "2025-06-21", "--weather", "pvgis-tmy", "--offline", "--out", "x"],
                    ["weather", "path", *SITE]):
        line = one_error_line(runner.invoke(app, command))
        assert f"the cached copy {answer} is damaged (" in line and DAMAGES[damage][1] in line, line
        assert "no cached copy" not in line
        assert line.endswith("which replaces it: foldopt weather fetch pvgis-tmy --lat 45 --lon 8")
    assert "--offline" not in line  # weather path: the user gave no --offline
    assert cache_files(tmp_path) == before and requests_made(server, dead) == 0


@pytest.mark.parametrize("damage", list(DAMAGES))
def test_a_damaged_cached_copy_is_fetched_again_online(pvgis, server, cached, tmp_path, damage,
                                                       figures_drawn_elsewhere):
    route = pvgis("ok")
    answer, _ = damaged_cache(cached, tmp_path, DAMAGES[damage][0])
    with figures_drawn_elsewhere():  # test_weather_fetch's fetched year: this sweep of this answer
        result = runner.invoke(app, [*SWEEP, "--days", "2025-06-21", "--weather", "pvgis-tmy",
                                     "--out", "x"])
    assert result.exit_code == 0, result.output
    (said,) = result.stderr.strip().splitlines()  # named, once
    assert said.startswith(f"foldopt: the cached copy {answer} was damaged (")
    assert said.endswith("); fetched it again") and DAMAGES[damage][1] in said
    assert answer.read_bytes() == RECORDED.read_bytes() and requests_made(server, route) == 1  # again
    meta = json.loads((tmp_path / "x" / "run.json").read_text())
    assert meta["weather_source"]["sha256"] == hashlib.sha256(RECORDED.read_bytes()).hexdigest()


def test_a_damaged_copy_whose_refetch_fails_is_left_as_it_was(pvgis, server, cached, tmp_path):
    _, before = damaged_cache(cached, tmp_path, _flip)
    route = pvgis("e500")
    line = one_error_line(runner.invoke(app, FETCH))
    assert line == "weather pvgis-tmy: PVGIS answered 500 Internal Server Error; try again later"
    assert cache_files(tmp_path) == before and requests_made(server, route) == 1


def test_weather_list_names_a_damaged_copy_and_lists_the_whole_ones(pvgis, server, cached, tmp_path):
    pvgis("ok")
    answer, _ = damaged_cache(cached, tmp_path, _flip)
    assert runner.invoke(app, [*FETCH, "--no-horizon"]).exit_code == 0
    listed = runner.invoke(app, ["weather", "list", "--format", "json"])
    assert listed.exit_code == 0
    assert [entry["params"].get("usehorizon") for entry in json.loads(listed.stdout)] == [0]
    assert listed.stderr.strip().splitlines() == [
        f"foldopt: the cached copy {answer} is damaged (its bytes changed since it was fetched: its "
        "SHA-256 is not the one recorded); foldopt weather fetch replaces it"]
    assert runner.invoke(app, ["weather", "list", "-q"]).stderr == ""  # --quiet: no notice


# 4. A mirror's user, password or key is used to ask, and written nowhere.

SECRETS = ("secret", "s3cret", "t0ken", "user:")


def with_credentials(route: str, monkeypatch) -> str:
    url = os.environ["FOLDOPT_PVGIS_URL"].replace("http://", "http://user:secret@")
    monkeypatch.setenv("FOLDOPT_PVGIS_URL", url + "?api_key=s3cret&access_token=t0ken&mirror=eu")
    return route


def written(tmp_path) -> str:
    """Every file the runs wrote, as text (the cache, the results folders)."""
    return "\n".join(p.read_bytes().decode("utf-8", "replace") for p in sorted(tmp_path.rglob("*"))
                     if p.is_file() and p.suffix in (".json", ".html", ".csv", ".txt", ".yaml")
                     and p.name != "site.yaml")


def test_a_mirrors_password_and_key_are_never_stored(pvgis, server, tmp_path, monkeypatch,
                                                     figures_drawn_elsewhere):
    route = with_credentials(pvgis("auth"), monkeypatch)
    # Its figures' kinds, a day of this answer and the horizon, are test_weather_fetch's (the
    # fetched year, the fetched horizon); here the files written are read for the secrets.
    with figures_drawn_elsewhere():
        result = runner.invoke(app, [*SWEEP, "--days", "2025-01-15", "--weather", "pvgis-tmy",
                                     "--horizon", "pvgis", "--out", "x"])
    assert result.exit_code == 0, result.output  # the password and the key were sent
    assert requests_made(server, route) == 2
    assert all("api_key=s3cret" in query and "mirror=eu" in query for _, query in queries_made(server, route))
    meta = json.loads((tmp_path / "x" / "run.json").read_text())
    for source in (meta["weather_source"], meta["horizon_source"]):
        assert source["url"].startswith(f"http://127.0.0.1:{server}/{route}/api/v5_3/")
        assert "mirror=eu" in source["url"]  # what is no secret stays
    fetched = runner.invoke(app, [*FETCH, "--format", "json"])
    listed = runner.invoke(app, ["weather", "list"])
    path = runner.invoke(app, ["weather", "path", *SITE, "--format", "json"])
    texts = [written(tmp_path), result.output, fetched.output, listed.output, path.output]
    assert not [secret for secret in SECRETS for text in texts if secret in text]


def test_a_study_files_address_with_a_password_is_not_written(pvgis, server, tmp_path, monkeypatch,
                                                              figures_drawn_elsewhere):
    route = pvgis("auth")
    url = os.environ.pop("FOLDOPT_PVGIS_URL").replace("http://", "http://user:secret@")
    monkeypatch.delenv("FOLDOPT_PVGIS_URL", raising=False)
    name = study_file(tmp_path, "site.yaml", {"latitude": 45.0, "longitude": 8.0},
                      {"source": "pvgis-tmy", "url": url + "?token=t0ken"})
    with figures_drawn_elsewhere():  # test_weather_fetch's study file of this source, and its sweep
        result = runner.invoke(app, ["run", name, "--out", "out", "--quiet", "--engine", "numpy"])
        assert result.exit_code == 0, result.output
        assert requests_made(server, route) == 1
        meta = json.loads((tmp_path / "out" / "run.json").read_text())
        assert meta["study"]["weather"]["url"] == url.replace("user:secret@", "")
        # the same address on the command line (run.json's command): asked as given, stored without
        typed = runner.invoke(app, [*SWEEP, "--days", "2025-06-21", "--weather", "pvgis-tmy", "--set",
                                    f"weather.url={url}?token=t0ken", "--out", "typed"])
    assert typed.exit_code == 0, typed.output
    command = json.loads((tmp_path / "typed" / "run.json").read_text())["command"]
    assert f"weather.url={url.replace('user:secret@', '')}" in command
    assert not [secret for secret in SECRETS if secret in written(tmp_path)]


@pytest.mark.parametrize("mode", ["e500", "close"])
def test_a_fault_at_a_mirror_with_a_password_does_not_show_it(pvgis, server, tmp_path, monkeypatch, mode):
    with_credentials(pvgis(mode), monkeypatch)
    line = one_error_line(runner.invoke(app, FETCH))
    assert f"PVGIS at http://127.0.0.1:{server}/" in line or "PVGIS answered 500" in line
    assert not [secret for secret in SECRETS if secret in line]


# 5. An address that is not http or https is refused by its scheme, before any attempt.

@pytest.mark.parametrize(("address", "said"), [
    ("file:///srv/pvgis/api/v5_3/", "the scheme file:// is not supported"),
    ("ftp://user:secret@mirror.example/api/v5_3/", "the scheme ftp:// is not supported"),
    ("FILE:///srv/pvgis/", "the scheme file:// is not supported"),
    ("127.0.0.1:8080/api/v5_3/", "is not supported"),
    ("mirror.example/api/v5_3/", "an address without a scheme is not supported"),
    ("http:///api/v5_3/", "names no host"),
    ("http://127.0.0.1:port/api/v5_3/", "not an address"),
])
def test_an_address_that_is_not_http_is_refused_by_its_scheme(pvgis, cached, tmp_path, monkeypatch, address,
                                                              said):
    before = kept_entry(cached, tmp_path)
    monkeypatch.setenv("FOLDOPT_PVGIS_URL", address)
    for command, label in [(FETCH, "weather pvgis-tmy: FOLDOPT_PVGIS_URL = "),
                           ([*SWEEP, "--weather", "pvgis-tmy", "--out", "x"],
                            "--weather pvgis-tmy: FOLDOPT_PVGIS_URL = "),
                           ([*SWEEP, "--horizon", "pvgis", "--out", "x"], "horizon pvgis: FOLDOPT_PVGIS_URL = ")]:
        line = one_error_line(runner.invoke(app, command))
        assert line.startswith(label) and said in line, line
        assert "give an http:// or https:// base address" in line
        assert "cannot reach" not in line and "secret" not in line
    monkeypatch.delenv("FOLDOPT_PVGIS_URL")
    line = one_error_line(runner.invoke(app, [*FETCH, "--url", address]))
    assert line.startswith("--url = ") and said in line and "secret" not in line
    assert cache_files(tmp_path) == before and not (tmp_path / "x").exists()


# 6. FOLDOPT_OFFLINE takes the usual spellings of a yes and a no, and refuses anything else.

@pytest.mark.parametrize("value", ["1", "true", "TRUE", "yes", "On", " on "])
def test_foldopt_offline_yes_is_offline(pvgis, server, tmp_path, monkeypatch, value):
    route = pvgis("ok")
    monkeypatch.setenv("FOLDOPT_OFFLINE", value)
    for command in (FETCH, [*SWEEP, "--weather", "pvgis-tmy", "--out", "x"]):
        line = one_error_line(runner.invoke(app, command))
        assert "no cached copy for (45, 8) with these options, and offline" in line
    assert requests_made(server, route) == 0 and cache_files(tmp_path) == {}


@pytest.mark.parametrize("value", ["0", "false", "No", "OFF", ""])
def test_foldopt_offline_no_is_online(pvgis, server, tmp_path, monkeypatch, value):
    route = pvgis("ok")
    monkeypatch.setenv("FOLDOPT_OFFLINE", value)
    assert runner.invoke(app, FETCH).exit_code == 0
    assert requests_made(server, route) == 1


@pytest.mark.parametrize("value", ["maybe", "2", "ja", "1.0", "true!"])
def test_foldopt_offline_that_is_no_yes_or_no_is_refused(pvgis, server, cached, tmp_path, monkeypatch, value):
    route = pvgis("ok")
    before = kept_entry(cached, tmp_path)
    monkeypatch.setenv("FOLDOPT_OFFLINE", value)
    for command in (FETCH, [*SWEEP, "--weather", "pvgis-tmy", "--out", "x"],
                    [*SWEEP, "--weather", "pvgis-tmy", "--offline", "--out", "x"], ["weather", "path", *SITE]):
        line = one_error_line(runner.invoke(app, command))
        assert line == (f"FOLDOPT_OFFLINE = {value!r}: a yes or a no, one of 1, true, yes, on or 0, "
                        "false, no, off (any case)")
    assert requests_made(server, route) == 0 and cache_files(tmp_path) == before  # nothing asked


def test_every_foldopt_yes_or_no_variable_has_one_parser(monkeypatch):
    """FOLDOPT_QUIET, the other yes-or-no variable, is read by the same parser."""
    from foldopt.cache import env_flag, notice

    for value, expected in [("YES", True), ("off", False), ("1", True), ("", False)]:
        monkeypatch.setenv("FOLDOPT_QUIET", value)
        assert env_flag("FOLDOPT_QUIET") is expected
    monkeypatch.setenv("FOLDOPT_QUIET", "loud")
    with pytest.raises(ConfigError, match=r"^FOLDOPT_QUIET = 'loud': a yes or a no"):
        notice("anything")


def test_foldopt_quiet_yes_silences_a_notice(pvgis, server, cached, tmp_path, monkeypatch):
    pvgis("ok")
    damaged_cache(cached, tmp_path, _flip)
    monkeypatch.setenv("FOLDOPT_QUIET", "true")
    result = runner.invoke(app, FETCH)
    assert result.exit_code == 0 and result.stderr == ""


# 7. Every weather subcommand takes --quiet and --format json: one JSON document on stdout.

def test_every_weather_subcommand_takes_quiet_and_json(pvgis, server, tmp_path):
    pvgis("ok")
    for command in (FETCH, ["weather", "list"], ["weather", "path", *SITE],
                    ["weather", "path", *SITE, "--out", "kept.json", "--overwrite"]):
        quiet = runner.invoke(app, [*command, "-q"])
        assert (quiet.exit_code, quiet.stdout, quiet.stderr) == (0, "", ""), (command, quiet.output)
        for fmt in ("json", "JSON"):
            document = runner.invoke(app, [*command, "--format", fmt, "--quiet"])
            assert document.exit_code == 0, document.output
            json.loads(document.stdout)  # one document, nothing else
        line = one_error_line(runner.invoke(app, [*command, "--format", "xml"]))
        assert line == "--format = 'xml': must be one of table, json"
    record = json.loads(runner.invoke(app, ["weather", "path", *SITE, "--format", "json"]).stdout)
    assert Path(record["file"]).read_bytes() == RECORDED.read_bytes()
    copied = json.loads(runner.invoke(app, ["weather", "path", *SITE, "--out", "copy.json",
                                            "--format", "json"]).stdout)
    assert copied["out"] == "copy.json" and copied["sha256"] == record["sha256"]
    assert (tmp_path / "copy.json").read_bytes() == RECORDED.read_bytes()
    listed = json.loads(runner.invoke(app, ["weather", "list", "--format", "json"]).stdout)
    assert [entry["sha256"] for entry in listed] == [record["sha256"]]


# 9. An uncached `weather path` says there is no cached copy and how to fetch it, not --offline.

@pytest.mark.parametrize(("options", "how"), [
    ([], "foldopt weather fetch pvgis-tmy --lat 45 --lon 8"),
    (["--no-horizon"], "foldopt weather fetch pvgis-tmy --lat 45 --lon 8 --no-horizon"),
    (["--years", "2005:2020"], "foldopt weather fetch pvgis-tmy --lat 45 --lon 8 --years 2005:2020"),
])
def test_an_uncached_weather_path_says_how_to_fetch_it(pvgis, server, tmp_path, options, how):
    route = pvgis("ok")
    line = one_error_line(runner.invoke(app, ["weather", "path", *SITE, *options]))
    assert line == (f"weather pvgis-tmy: no cached copy for (45, 8) with these options in "
                    f"{tmp_path / 'cache' / 'weather'}; fetch it first: {how}")
    assert "offline" not in line and requests_made(server, route) == 0
    assert runner.invoke(app, how.split()[1:]).exit_code == 0  # the command it gives fetches it
    assert runner.invoke(app, ["weather", "path", *SITE, *options]).exit_code == 0
    assert requests_made(server, route) == 1
