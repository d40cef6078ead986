"""Inputs under faults (issue 21): files that never end or never start, values the calendar or a
float cannot hold, rows and times that would be lost unseen, a tracker that costs more than it
harvests, and the environment a command runs in (a C locale, an unusable HOME, Ctrl-C). Each bad
input is one line naming the field, exit code 2 and nothing written; the environment's cases run
as real processes with a changed environment, each bounded by a timeout."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from foldopt.cli.app import app
from foldopt.inputs.study_file import default_study_path
from foldopt.errors import ConfigError
from foldopt.inputs.policy import EXACT_NOTE

runner = CliRunner()
QUICK = ["--step-min", "60", "--angle-step", "30"]
#: The embedded study made cheap: hourly steps, a 30-degree fold-angle grid.
FAST = {**yaml.safe_load(default_study_path().read_text()), "step_min": 60,
        "fold_angles": {"start": 30, "stop": 180, "step": 30}}
PROFILE = "time,watts\n07:00,6\n19:00,1.5\n"
#: A subprocess's bound [s]: an import, a cheap study and its folder take a few seconds.
TIMEOUT = 120


@pytest.fixture
def here(tmp_path, monkeypatch):
    """A working folder; nothing an error leaves may appear in it."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


def one_line(result, *words):
    """The result of a refused input: exit code 2, one ``error:`` line holding ``words``."""
    assert result.exit_code == 2, (result.exit_code, result.output)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert "Traceback" not in result.output and result.stdout == ""
    for word in words:
        assert word in lines[0], (word, lines[0])
    return lines[0]


def refused(folder: Path, args, *words):
    """``args`` run in ``folder`` are refused in one line, and nothing is written there."""
    before = sorted(path.name for path in folder.iterdir())
    line = one_line(runner.invoke(app, [*args, "--out", "out"]), *words)
    assert sorted(path.name for path in folder.iterdir()) == before
    return line


# --- 1. Internal errors that are bad input ------------------------------------------------------


@pytest.mark.parametrize("args,field", [
    (["map", "--sites", "{file}"], "--sites"),
    (["sweep", "angle", "--load-profile", "{file}", *QUICK], "--load-profile"),
    (["run", "{file}"], "config"),
], ids=["sites", "load-profile", "study"])
@pytest.mark.parametrize("kind", ["character device", "FIFO"])
def test_a_device_or_a_fifo_as_an_input_file_is_refused_by_name(here, args, field, kind):
    # /dev/zero never ends (it was a MemoryError) and a FIFO without a writer never starts.
    if kind == "FIFO":
        os.mkfifo(here / "pipe")
    name = "/dev/zero" if kind == "character device" else "pipe"
    refused(here, [arg.format(file=name) for arg in args], field, name, f"is a {kind}, not a regular file")


@pytest.mark.parametrize("args,field", [
    (["map", "--sites", "big.csv"], "--sites"),
    (["sweep", "angle", "--load-profile", "big.csv", *QUICK], "--load-profile"),
], ids=["sites", "load-profile"])
def test_a_csv_over_the_limit_is_refused_unread(here, args, field):
    with open(here / "big.csv", "wb") as handle:
        handle.truncate(25_000_000)  # sparse: no time spent writing it
    refused(here, args, field, "big.csv", "25,000,000 bytes", "at most 20,000,000", "FOLDOPT_MAX_CSV_BYTES")


def test_a_maps_year_is_checked_by_the_library_too():
    from foldopt.studies.map_request import map_study, site_study

    study = map_study(FAST)
    with pytest.raises(ConfigError, match=r"year = 10000: must be a whole year in \[1901, 2099\]"):
        site_study(study, {"latitude": 10.0, "longitude": 0.0}, 10000)


# --- 2. Input that would be accepted and lose something -----------------------------------------


@pytest.mark.parametrize("text,words", [
    ("name,latitude,longitude\nLA,34,-118\nLA,35,-118\n", ["line 3", "name 'LA' is also on line 2"]),
    ("name,latitude,longitude\nLA,34,-118\nSF,37.8,-122.4,0\n", ["line 3", "4 fields; the header names 3"]),
    ("name,latitude,latitude\nLA,34,-118\n", ["latitude twice"]),
], ids=["duplicate-name", "extra-field", "duplicate-column"])
def test_a_sites_row_that_would_be_lost_is_refused(here, text, words):
    (here / "sites.csv").write_text(text)
    refused(here, ["map", "--sites", "sites.csv"], "--sites sites.csv", *words)


@pytest.mark.parametrize("text,words", [
    ("time,watts\n07:00,6\n12:00,2\n07:00,3\n", ["line 4", "time 07:00 is also on line 2"]),
    ("time,watts\n07:00,6\n7:00,3\n", ["'7:00' is the time '07:00' again"]),
], ids=["same-text", "same-time"])
def test_a_load_profile_time_given_twice_is_refused(here, text, words):
    (here / "profile.csv").write_text(text)
    refused(here, ["sweep", "angle", "--load-profile", "profile.csv", *QUICK], "--load-profile", "profile.csv",
            *words)


@pytest.mark.parametrize("axis", ["angle", "load"])
def test_a_profiles_scale_is_named_as_given(here, axis):
    (here / "p.csv").write_text(PROFILE)
    line = refused(here, ["sweep", axis, "--load-profile", "p.csv", "--p-load-scale", "0", *QUICK], "--p-load-scale")
    assert "--p-load " not in line and "--p-load =" not in line


def test_a_spreadsheets_utf8_csv_with_a_byte_order_mark_is_read(here):
    from foldopt.inputs.study_file import read_profile
    from foldopt.inputs.sites import read_sites

    (here / "sites.csv").write_bytes("\ufeffname,latitude,longitude\nSão Paulo,-23.55,-46.63\n".encode())
    (here / "p.csv").write_bytes(("\ufeff" + PROFILE).encode())
    assert read_sites("sites.csv") == [{"name": "São Paulo", "latitude": -23.55, "longitude": -46.63,
                                        "altitude": 0.0}]
    assert read_profile("p.csv") == {"07:00": 6.0, "19:00": 1.5}


# --- 3. Physics at the edges --------------------------------------------------------------------


def test_a_tracker_whose_drive_costs_more_than_it_harvests_says_so(here):
    # At the polar circle on the December solstice the single-axis tracker's motor spends more than
    # the tracker harvests: its net energy is below zero, and nothing is served or wasted.
    result = runner.invoke(app, ["sweep", "angle", "--lat", "66.56", "--date", "2025-12-21", "--tracker",
                                 "single-axis", *QUICK, "--out", "out", "--format", "json"])
    assert result.exit_code == 0, result.output
    document = json.loads(result.stdout)
    rows = {row["design"]: row for row in document["rows"]}
    net = rows["tracker-net"]
    assert net["energy_harvested_wh"] < 0
    assert net["energy_served_wh"] == 0 and net["energy_wasted_wh"] == 0
    assert "drive costs more than it harvests" in net["note"]
    for row in rows.values():
        assert row["energy_wasted_wh"] >= 0 and row["energy_served_wh"] <= max(row["energy_harvested_wh"], 0)
    assert {"note": "drive costs more than it harvests", "designs": ["tracker-net"]} in document["answer"]["notes"]
    assert "note: drive costs more than it harvests (tracker-net)" in document["answer"]["lines"]


def test_a_sweeps_rows_say_so_too(here):
    result = runner.invoke(app, ["sweep", "day", "--lat", "66.56", "--days", "2025-12-14:2025-12-28:7", "--tracker",
                                 "single-axis", *QUICK, "--out", "out", "--format", "json"])
    assert result.exit_code == 0, result.output
    document = json.loads(result.stdout)
    net = [row for row in document["rows"] if row["design"] == "tracker-net"]
    assert len(net) == 3 and all(row["energy_harvested_wh"] < 0 and row["energy_wasted_wh"] == 0
                                 and "drive costs more than it harvests" in row["note"] for row in net)
    assert all(row["energy_wasted_wh"] >= 0 for row in document["rows"])
    note = {"note": "drive costs more than it harvests", "designs": ["tracker-net"], "cases": 3, "of": 3}
    assert note in document["answer"]["notes"]


def test_served_energy_never_exceeds_a_negative_harvest():
    import numpy as np

    from foldopt.engine.metrics import metric_columns

    columns = metric_columns(np.array([2.0, 1.0, 0.0]), np.array([2.0, 1.0, 0.0]), np.array([10.0, -3.0, -1.0]),
                             np.array([5.0, 4.0, 0.0]), 2.0)
    assert columns["energy_served_wh"].tolist() == [4.0, 0.0, 0.0]
    assert columns["energy_wasted_wh"].tolist() == [6.0, 0.0, 0.0]
    assert columns["energy_harvested_wh"].tolist() == [10.0, -3.0, -1.0]  # the net harvest keeps its sign


def test_an_altitude_takes_the_paper_study_to_exact_mode_and_says_so(here, folders_written_elsewhere):
    # The paper's Eq. 5 has no altitude term: a paper-mode study at 8000 m runs in exact mode.
    with folders_written_elsewhere():  # its answer is what is read, nothing of its folder
        result = runner.invoke(app, ["sweep", "angle", "--altitude", "8000", *QUICK, "--out", "out", "--format",
                                     "json"])
    assert result.exit_code == 0, result.output
    answer = json.loads(result.stdout)["answer"]
    assert answer["question"]["models"].startswith("exact mode")
    assert EXACT_NOTE in answer["defaults"]["taken"]


# --- 4. The environment -------------------------------------------------------------------------


def foldopt_env(**changes) -> dict:
    """This process's environment with ``changes`` (None removes a variable)."""
    env = dict(os.environ)
    for name, value in changes.items():
        if value is None:
            env.pop(name, None)
        else:
            env[name] = value
    return env


def foldopt_process(args, cwd: Path, env: dict) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "foldopt.cli.app", *args], cwd=cwd, env=env, capture_output=True,
                          timeout=TIMEOUT)


#: A C locale without Python's UTF-8 mode: file names and files are bytes, stdout is ASCII.
C_LOCALE = {"LC_ALL": "C", "LANG": "C", "PYTHONUTF8": "0", "PYTHONIOENCODING": None}


@pytest.fixture(scope="module")
def c_locale_without_home(tmp_path_factory):
    """One process (each costs a second of imports) under a C locale with HOME unusable: it reads
    UTF-8 input files, then loads matplotlib for foldopt's figures. Returns its folder, its
    CompletedProcess and stdout's lines."""
    folder = tmp_path_factory.mktemp("c-locale")
    (folder / "sites.csv").write_bytes("name,latitude,longitude\nSão Paulo,-23.55,-46.63\n".encode())
    (folder / "p.csv").write_bytes("time,watts\n07:00,6\n".encode())
    (folder / "s.yaml").write_bytes(yaml.safe_dump({**FAST, "description": "Zürich"}, allow_unicode=True).encode())
    (folder / "a-file").write_text("")
    env = foldopt_env(**C_LOCALE, HOME=str(folder / "a-file" / "home"), XDG_CONFIG_HOME=None, XDG_CACHE_HOME=None,
                      MPLCONFIGDIR=None, FOLDOPT_CACHE_DIR=str(folder / "cache"))
    code = ("import os; before = dict(os.environ); "
            "from foldopt.inputs.study_file import read_profile, read_study; "
            "from foldopt.inputs.sites import read_sites; "
            "print(ascii([read_sites('sites.csv')[0]['name'], read_profile('p.csv'), "
            "read_study('s.yaml')[0]['description']])); "
            "from foldopt.output.figures import canvas; canvas.load_matplotlib(); import matplotlib; "
            "print(dict(os.environ) == before, matplotlib.get_configdir(), matplotlib.get_cachedir())")
    done = subprocess.run([sys.executable, "-c", code], cwd=folder, env=env, capture_output=True, timeout=TIMEOUT)
    return folder, done, done.stdout.decode().splitlines()


def test_utf8_input_files_under_the_c_locale(c_locale_without_home):
    _, done, lines = c_locale_without_home
    assert done.returncode == 0, done.stderr.decode(errors="replace")
    assert lines[0] == ascii(["São Paulo", {"07:00": 6.0}, "Zürich"])


def test_a_unicode_folder_under_the_c_locale_with_an_unusable_home(tmp_path):
    # One process for both (each costs seconds). The command line's text is kept as typed in
    # run.json, report.html and the JSON (it was a UnicodeEncodeError). HOME lies under a file:
    # nothing can be made there, not even by root, and matplotlib would warn on stderr that it made
    # a temporary cache: it gets foldopt's cache folder (kept between runs), and --quiet stays quiet.
    (tmp_path / "a-file").write_text("")
    cache = Path(os.environ.get("FOLDOPT_CACHE_DIR") or tmp_path / "cache")
    env = foldopt_env(**C_LOCALE, HOME=str(tmp_path / "a-file" / "home"), XDG_CONFIG_HOME=None, XDG_CACHE_HOME=None,
                      MPLCONFIGDIR=None, FOLDOPT_CACHE_DIR=str(cache))
    done = foldopt_process(["sweep", "angle", *QUICK, "--out", "résultats-é", "--format", "json", "--quiet"],
                           tmp_path, env)
    assert done.returncode == 0, done.stderr.decode(errors="replace")
    assert done.stderr == b"" and json.loads(done.stdout)["out"] == "résultats-é"
    folder = tmp_path / "résultats-é"
    assert "résultats-é" in json.loads((folder / "run.json").read_text(encoding="utf-8"))["command"]
    assert "--out résultats-é" in (folder / "report.html").read_text(encoding="utf-8")
    assert (cache / "matplotlib").is_dir()


def test_matplotlib_gets_a_folder_and_the_environment_is_as_it_was(c_locale_without_home):
    """With HOME unusable, loading matplotlib for foldopt's figures (as the first figure drawn
    does) gives it foldopt's cache folder for its configuration and fonts (it reads MPLCONFIGDIR
    once, as it is imported) and leaves the process's environment as it was: no MPLCONFIGDIR
    behind the caller's back."""
    folder, done, lines = c_locale_without_home
    assert (done.returncode, done.stderr) == (0, b"")
    cache = folder / "cache"
    assert lines[1].split() == ["True", str(cache / "matplotlib"), str(cache / "matplotlib")]


def _interrupt_while_writing(folder):
    """A sweep in ``folder``, sent SIGINT once its staging folder appears: its return code, stdout
    and stderr.

    The child starts with SIGINT at its default, as a process a terminal's Ctrl-C reaches: in some
    suite runs the pytest-xdist worker held SIGINT ignored (SIG_IGN), which a child keeps across
    exec, so that the run never saw the signal and finished (five times in five)."""
    process = subprocess.Popen([sys.executable, "-m", "foldopt.cli.app", "sweep", "angle", "--step-min", "5",
                                "--angle-step", "30", "--out", "out", "-q"], cwd=folder, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline, staged = time.monotonic() + TIMEOUT, []
        while time.monotonic() < deadline and process.poll() is None and not staged:
            staged = list(folder.glob(".out.tmp-*"))
            time.sleep(0.002)
        assert staged, "the run ended before it was seen writing"
        process.send_signal(signal.SIGINT)
        stdout, stderr = process.communicate(timeout=TIMEOUT)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    return process.returncode, stdout, stderr


def test_ctrl_c_says_interrupted_and_leaves_nothing(tmp_path):
    # SIGINT while the run writes its folder (its staging folder appears): one line, exit code 130.
    # The write lasts a fraction of a second: on a loaded machine the run can finish between the
    # staging folder being seen and the signal, and then it must have finished whole (tried again).
    for attempt in range(5):
        folder = tmp_path / str(attempt)
        folder.mkdir()
        returncode, stdout, stderr = _interrupt_while_writing(folder)
        if returncode != 0:
            break
        assert sorted(path.name for path in folder.iterdir()) == ["out"] and (folder / "out" / "run.json").is_file()
    assert returncode == 130, stderr
    assert stderr.decode().strip() == "interrupted" and stdout == b""
    assert list(folder.iterdir()) == []
