"""Maps on real Dask clusters: an embedded one, and a scheduler and workers started here on
127.0.0.1, bounded in time and stopped by process id; faults (a worker killed, the client killed)
must lose nothing and change nothing.

Every map of :data:`MAP` is held to the bit to its rows computed here without Dask
(:func:`direct`). The processes are what the tests are about and what they cost (each imports Dask
and foldopt, and a worker loads the compiled code: 2-3 s of CPU a process), so tests that check one
run share it: the killed map is finished by the run whose worker dies and whose terminal is checked
(:func:`resumed`), both runs' tasks say whether --quiet reached their workers, and the scheduler
lost is that of the cluster whose worker was killed (:func:`worker_killed`). The maps on that
cluster run their client in this process (:func:`_map_on`): what is killed there is a worker and
the scheduler, processes of their own. The other maps' command lines are processes of their own,
forked from one server that imported their modules (:func:`_faulty_run`)."""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import tempfile
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import pytest
from typer.testing import CliRunner

from foldopt.cli.app import app
from foldopt.errors import ConfigError
from foldopt.inputs.sites import grid_sites
from foldopt.studies.cluster import TASK_MODULES, run_map
from foldopt.studies.map_request import MapSpec
from foldopt.errors import OutputError
from foldopt.studies.worldmap import evaluate_sites

pytest.importorskip("distributed")

#: 8 sites, a chunk each, at 15-min steps: about 0.1 s of work per chunk, long enough to be killed mid-run
#: with chunks left (a worker's first chunk, its compiled code loaded, takes some 0.4 s more). Each run
#: computes every chunk it is given again: 16 sites were 2-3 s more of the workers' cores, and checked no
#: more.
MAP = ["--lat", "-60:60:40", "--lon", "-90,90", "--p-load", "1,2", "--area", "0.108", "--chunk-sites", "1",
       "--step-min", "15"]
#: MAP's grid.
LATITUDES, LONGITUDES = (-60.0, -20.0, 20.0, 60.0), (-90.0, 90.0)
#: The embedded cluster of one worker: one process to start, not two, on a machine whose two cores the
#: other tests share (the hand-started cluster below has two, so that one can be killed).
EMBEDDED = [*MAP, "--workers", "1"]
N_SITES, N_LOADS = 8, 2
SECONDS = 240  # any one run or cluster start


def _kill(process) -> None:
    """End a process of :func:`hand_started`'s (a :class:`multiprocessing.Process`)."""
    if process.is_alive():
        process.kill()
        process.join(timeout=30)


def _wait_for(condition, what: str, seconds: float = SECONDS) -> None:
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            raise TimeoutError(what)
        time.sleep(0.02)


def _parts(folder: Path) -> dict[str, tuple]:
    return {path.name: (path.stat().st_ino, path.stat().st_mtime_ns) for path in (folder / "parts").glob("part-*")}


def _every_site_once(table: pd.DataFrame) -> None:
    counts = table.groupby(["site_id", "p_load_w", "period"]).size()
    assert len(counts) == N_SITES * N_LOADS * 5 and (counts == 1).all()


@pytest.fixture(scope="session")
def direct() -> pd.DataFrame:
    """The reference: MAP's rows computed here without Dask, its sites in one batch (a site's rows
    are the same bits whatever batch it shares; the map's chunks hold one site each)."""
    from foldopt.inputs.study_file import default_study_path, read_study
    from foldopt.studies.map_request import map_study

    study = map_study(read_study(default_study_path())[0], step_min=15.0,
                      **{"panel.area": 0.108, "objective": {"statistic": "mean"}})
    sites = [{**site, "site_id": index} for index, site in enumerate(grid_sites(LATITUDES, LONGITUDES))]
    return evaluate_sites(study, sites, [1.0, 2.0])


# --- the embedded cluster: a run killed, a worker that dies, what a map prints ----------------------------


#: The command line, its map's task replaced by this script's (Dask pickles a function of __main__ by value,
#: so the embedded cluster's workers run it): foldopt's task but for the FAULT, raise (a RuntimeError, an
#: internal fault), bad-input (a ConfigError, as a weather file broken mid-run raises), die (the worker's
#: process ends), die-once (the first time only: it makes MARK), none. Where SEEN names a file, each task
#: adds a line to it, as it ends or before its process does: whether foldopt is quiet in its worker, whether
#: the worker came with every module a chunk needs imported, how many threads of its own its parent process
#: (the server it was forked from) holds, and what modules of foldopt's and its heavy dependencies' its
#: chunk imported ("-": none). The faults that end a task before its chunk start no server importing a
#: chunk's modules (numba, pvlib, SciPy: 1.5-2 s of CPU): their workers would not use them. The map's
#: figures are a PNG of one pixel, not drawn (matplotlib's import and five figures, some 2 s of the
#: client's core): they are tests/test_figures.py's; what is tested here is the cluster's processes, the
#: terminal and the table. The app is called as the foldopt script calls it (on the process's own
#: arguments): the command line's own process, whose exit walks no object (foldopt.cli.process).
FAULTY_TASK = """
import base64, os, sys
import foldopt.output.figures as figures
import foldopt.studies.cluster as cluster

figures.figure_bytes = lambda file, args, kwargs: base64.b64decode(
    "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mNkYPhfDwAChwGA60e6kgAAAABJRU5ErkJggg==")

FAULT, MARK, SEEN = os.environ["FAULT"], os.environ["MARK"], os.environ.get("SEEN")  # the task takes them along
evaluate_chunk = cluster.evaluate_chunk
HEAVY = ("foldopt", "pvlib", "scipy", "pandas", "distributed")
if FAULT in ("raise", "die"):  # tasks that end before their chunk: workers forked with Dask's modules only
    cluster.TASK_MODULES = cluster.WORKER_MODULES

def task(study, sites, loads, relative, year, engine):
    loaded = set(sys.modules)
    if FAULT == "raise":
        raise RuntimeError("a fault in the task")
    if FAULT == "bad-input":
        from foldopt.errors import ConfigError
        raise ConfigError(["weather: a file that broke mid-run"])
    dies = FAULT == "die" or FAULT == "die-once" and not os.path.exists(MARK)
    table = None if dies else evaluate_chunk(study, sites, loads, relative, year, engine)
    if SEEN:
        new = sorted(module for module in set(sys.modules) - loaded if module.split(".")[0] in HEAVY)
        from foldopt.cache import quiet
        from foldopt.studies.cluster import TASK_MODULES
        server = f"/proc/{os.getppid()}"
        name = open(f"{server}/comm").read()
        own = sum(open(f"{server}/task/{thread}/comm").read() == name for thread in os.listdir(f"{server}/task"))
        with open(SEEN, "a") as seen:
            print(quiet(), all(module in loaded for module in TASK_MODULES), own, ",".join(new) or "-", file=seen)
    if dies:
        open(MARK, "w").close()
        os._exit(1)
    return table

cluster.evaluate_chunk = task
from foldopt.cli.app import app
app(prog_name="foldopt")
"""
#: Two sites, a chunk each, at hourly steps and fold angles 90 and 180 deg.
SMALL = ["--lat", "0,30", "--lon", "0", "--p-load", "1", "--area", "0.108", "--step-min", "60", "--angle-step",
         "90", "--chunk-sites", "1"]
EMBEDDED_ONE = r"embedded LocalCluster, 1 worker process; dashboard: http://127\.0\.0\.1:\d+/status"


#: The modules a map's command line imports (its parsing, request and folder, its embedded
#: scheduler's dashboard, its terminal's rich, the parts' pyarrow), and the map's task's
#: (TASK_MODULES): imported once by the server this module's map processes are forked from
#: (:func:`_faulty_run`).
COMMAND_MODULES = (*TASK_MODULES, "foldopt.cli.app", "foldopt.studies.request", "foldopt.api",
                   "foldopt.output.figures", "foldopt.output.folders", "distributed.dashboard.scheduler",
                   "rich.console", "pyarrow.pandas_compat")
#: What a process of :func:`_faulty_run` runs (by :func:`exec`): ``python -c CODE *ARGS`` as a
#: fresh interpreter would, its imports done. Its own session where SESSION, stdout and stderr
#: to the files STDOUT and STDERR, the environment ENV (Dask's configuration read from it again,
#: as at Dask's import), no resource tracker of its parent's (the command starts its own), and the
#: exit's handlers run as the interpreter's exit runs them.
FORKED_COMMAND = """
import atexit, os, sys
from multiprocessing import resource_tracker
if SESSION:
    os.setsid()
for stream, path in ((1, STDOUT), (2, STDERR)):
    os.dup2(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC), stream)
os.environ.clear()
os.environ.update(ENV)
import dask
dask.config.refresh()
resource_tracker._resource_tracker._fd = None
sys.argv = ["-c", *ARGS]
try:
    exec(CODE, {"__name__": "__main__"})
finally:
    atexit._run_exitfuncs()
"""


class _Forked:
    """A process of :func:`_faulty_run`: what :class:`subprocess.Popen` gives the tests."""

    def __init__(self, process, stdout: Path, stderr: Path):
        self.process, self.pid, self.files = process, process.pid, (stdout, stderr)

    def poll(self) -> int | None:
        return None if self.process.is_alive() else self.process.exitcode

    @property
    def returncode(self) -> int | None:
        return self.poll()

    def communicate(self, timeout: float) -> tuple[str, str]:
        self.process.join(timeout)
        if self.process.is_alive():
            raise subprocess.TimeoutExpired("foldopt map", timeout)
        try:
            return tuple(path.read_text() for path in self.files)
        finally:
            shutil.rmtree(self.files[0].parent)


def _start_the_server() -> None:
    """Start this process's worker server (start_worker_server) with :data:`COMMAND_MODULES`,
    where it does not run yet; skip where the platform has none."""
    from foldopt.studies.dask_client import start_worker_server

    environment = dict(os.environ)
    if not start_worker_server(COMMAND_MODULES):
        pytest.skip("no forkserver on this platform")
    # The nanny's environment is the server's, not left in this process (an API caller's).
    assert dict(os.environ) == environment


def _faulty_run(fault: str, folder: Path, args: list[str], env=None, start_new_session=False) -> _Forked:
    """Start the map of ``args`` (its cluster's options too) with ``fault`` into ``folder / "map"``
    (:data:`FAULTY_TASK`); ``env``'s variables are added to this process's but for
    ``FOLDOPT_QUIET``: the map's own options say whether it is quiet. The process is a fork of
    the server the embedded cluster's workers are forked from (start_worker_server), which
    imported the command line's modules once (:data:`COMMAND_MODULES`): started by
    ``python -c``, each run imported them again, some 1.2 s of CPU (what a fresh command line
    imports is tests/test_imports.py's)."""
    import multiprocessing

    _start_the_server()
    environment = {**os.environ, "FAULT": fault, "MARK": str(folder / "died"), **(env or {})}
    environment.pop("FOLDOPT_QUIET", None)
    where = Path(tempfile.mkdtemp(prefix="foldopt-map-"))  # not in folder: the tests list what is there
    streams = (where / "stdout", where / "stderr")
    script = {"CODE": FAULTY_TASK, "ARGS": ["map", *args, "--out", str(folder / "map")], "ENV": environment,
              "SESSION": start_new_session, "STDOUT": str(streams[0]), "STDERR": str(streams[1])}
    process = multiprocessing.get_context("forkserver").Process(target=exec, args=(FORKED_COMMAND, script))
    process.start()
    return _Forked(process, *streams)


def _faulty_map(fault: str, folder: Path, args: list[str], **environment) -> tuple[int, list[str], str]:
    """Run :func:`_faulty_run` to its end: its exit code, the lines of its stderr and its stdout."""
    process = _faulty_run(fault, folder, args, env=environment)
    stdout, stderr = process.communicate(timeout=SECONDS)
    assert "distributed." not in stderr and "Traceback" not in stderr, stderr
    return process.returncode, stderr.splitlines(), stdout


@dataclass
class Resumed:
    """:func:`resumed`'s runs."""

    #: The map's folder.
    out: Path
    #: The parts the killed run left, and whether it left a table.
    before: dict[str, tuple]
    table_before: bool
    #: The same map without --resume (typer's result).
    refused: object
    #: The resuming run's exit code, stderr's lines and stdout; whether its worker died.
    code: int
    lines: list[str]
    stdout: str
    died: bool
    #: What each task said (FAULTY_TASK's SEEN): the killed run's (--quiet), the resuming run's (not).
    seen_killed: list[list[str]]
    seen_resuming: list[list[str]]


@pytest.fixture(scope="session")
def resumed(tmp_path_factory) -> Resumed:
    """A map on the embedded cluster killed with its client, the process group at once, once it has
    written three parts; the same map refused without --resume (run in this process: what is tested
    is the folder); then resumed with --format json by a process of its own on an embedded cluster,
    whose worker dies on the first chunk it is given (the nanny starts another, the scheduler
    reschedules the chunk). Both runs' tasks say whether foldopt is quiet in their workers."""
    folder = tmp_path_factory.mktemp("resumed")
    out, seen_killed, seen_resuming = folder / "map", folder / "quiet-killed", folder / "quiet-resuming"
    run = _faulty_run("none", folder, [*EMBEDDED, "-q"], env={"SEEN": str(seen_killed)}, start_new_session=True)
    try:
        # or its end: a run that failed is the tests' to show
        _wait_for(lambda: run.poll() is not None or out.exists() and len(_parts(out)) >= 3, "three parts")
    finally:
        os.killpg(run.pid, signal.SIGKILL)  # the client and its embedded cluster, at once
        run.communicate(timeout=30)
    before, table_before = _parts(out), (out / "map.parquet").exists()
    refused = CliRunner().invoke(app, ["map", *EMBEDDED, "--out", str(out)])
    code, lines, stdout = _faulty_map("die-once", folder, [*EMBEDDED, "--resume", "--format", "json"],
                                      SEEN=str(seen_resuming))
    return Resumed(out, before, table_before, refused, code, lines, stdout, (folder / "died").exists(),
                   *([line.split() for line in seen.read_text().splitlines()] for seen in (seen_killed, seen_resuming)))


def test_a_maps_terminal_holds_only_foldopts_lines(resumed):
    """Dask's records stay off the terminal: the worker that computes the first chunk dies (its
    nanny starts another, the scheduler reschedules), and the map is whole all the same. With
    --format json, stdout is the one document and stderr holds nothing (the cluster's line in
    table format: test_a_task_that_fails_is_one_line)."""
    assert resumed.code == 0 and resumed.died, resumed.lines
    assert resumed.lines == []
    assert json.loads(resumed.stdout)["command"] == "map"
    _every_site_once(pd.read_parquet(resumed.out / "map.parquet"))


def test_quiet_reaches_the_embedded_clusters_workers(resumed):
    """The embedded cluster's worker processes take --quiet as their environment (their notices
    of a cache built again reach the terminal), given to them explicitly: foldopt sets no
    environment variable of its own, and these runs do not inherit FOLDOPT_QUIET."""
    assert resumed.seen_killed and {quiet for quiet, *_ in resumed.seen_killed} == {"True"}
    assert resumed.seen_resuming and {quiet for quiet, *_ in resumed.seen_resuming} == {"False"}


def test_the_embedded_clusters_workers_are_forked_with_a_chunks_modules(resumed):
    """The embedded cluster's worker processes (the one the nanny started again too) are forks of
    a server that imported every module a chunk needs while the client went on
    (start_worker_server: a chunk imports none of foldopt's, pvlib's, SciPy's, pandas' or Dask's),
    and that holds a single thread of its own: no BLAS thread (the nanny's environment), nothing
    that a fork would copy half-way."""
    seen = resumed.seen_killed + resumed.seen_resuming
    assert {(preloaded, threads, new) for _, preloaded, threads, new in seen} == {("True", "1", "-")}, seen


def test_embedded_map_equals_the_computation_without_dask(resumed, direct):
    """The map of the embedded clusters: the killed run's parts and the resumed run's chunks."""
    table = pd.read_parquet(resumed.out / "map.parquet")
    pd.testing.assert_frame_equal(table, direct, check_exact=True)
    _every_site_once(table)


def test_a_killed_run_resumes_without_recomputing(resumed):
    before, out = resumed.before, resumed.out
    assert 3 <= len(before) < N_SITES and not resumed.table_before
    refused = resumed.refused
    assert refused.exit_code == 2 and "pass --resume to finish it" in refused.stderr, refused.output
    assert resumed.code == 0, resumed.lines
    answer = json.loads(resumed.stdout)  # one JSON document: the year's rows
    assert answer["command"] == "map" and answer["answer"]["result"]["sites"] == N_SITES
    assert len(answer["rows"]) == N_SITES * N_LOADS and answer["answer"]["result"]["chunks_from_disk"] == len(before)
    meta = json.loads((out / "run.json").read_text())
    finished = sorted(int(name[5:10]) for name in before)
    assert meta["chunks_from_disk"] == finished
    assert meta["chunks_computed"] == [index for index in range(N_SITES) if index not in finished]
    after = _parts(out)
    assert {name: after[name] for name in before} == before  # the same files, untouched
    assert not list(out.rglob(".*tmp*"))


@pytest.mark.parametrize("fault, code, line", [
    ("raise", 1, "error: internal error (RuntimeError: a fault in the task); run again as foldopt --debug ... "
                 "for the traceback, and please report it"),
    ("bad-input", 2, "error: "),
    ("die", 1, "error: internal error (RuntimeError: the map's worker processes died while computing it (chunk "),
], ids=["raise", "bad-input", "die"])
def test_a_task_that_fails_is_one_line(tmp_path, scheduler, fault, code, line):
    # The input's fault on a cluster of this process (the client's records are the point: its worker's
    # are this process's), the others on an embedded one; Dask gives up on a task at the first worker
    # that dies running it.
    cluster = ["--scheduler", scheduler] if fault == "bad-input" else ["--workers", "1"]
    returned, lines, _ = _faulty_map(fault, tmp_path, [*SMALL, *cluster],
                                     DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES="0")
    assert returned == code, lines
    announced = f"Dask scheduler {re.escape(scheduler)}; .*" if fault == "bad-input" else EMBEDDED_ONE
    assert len(lines) == 2 and re.fullmatch(announced, lines[0]) and lines[1].startswith(line), lines
    assert fault != "bad-input" or lines[1].endswith("weather: a file that broke mid-run")  # as the field is named
    assert sorted(path.name for path in tmp_path.iterdir()) == (["died"] if fault == "die" else [])


# --- a cluster started here: a worker killed, then its scheduler --------------------------------------------


#: Dask's command line ``MODULE ARGS`` (``python -m MODULE ARGS``) run by a process of
#: :func:`hand_started`, its output (Dask's records) to /dev/null; a script run by :func:`exec`, so
#: that the process imports nothing of this module's.
DASK_COMMAND = """
import importlib, os, sys
nowhere = os.open(os.devnull, os.O_WRONLY)
for stream in (1, 2):
    os.dup2(nowhere, stream)
sys.argv = [MODULE, *ARGS]
importlib.import_module(MODULE).main()
"""


@pytest.fixture(scope="module")
def hand_started(tmp_path_factory):
    """A scheduler and two single-threaded workers on 127.0.0.1 (without a nanny, so that killing
    one kills the worker): the scheduler file, the workers' processes and the scheduler's. Each
    process the module's own, killed at its end. The workers start with the scheduler: they wait
    for its file. Each is a fork of the server the embedded cluster's workers are forked from
    (start_worker_server), which imports Dask and the map's task once for the three (and the map
    processes of :func:`_faulty_run`): spawned, each imported them again (2-3 s of CPU a worker)."""
    import multiprocessing

    _start_the_server()
    scheduler_file = tmp_path_factory.mktemp("cluster") / "scheduler.json"
    # Without the dashboard (bokeh's import): nothing looks at it. Its HTTP server on a free port.
    commands = [("distributed.cli.dask_scheduler", ["--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                                    "--dashboard-address", "127.0.0.1:0", "--scheduler-file",
                                                    str(scheduler_file)])]
    commands += 2 * [("distributed.cli.dask_worker", ["--scheduler-file", str(scheduler_file), "--nthreads", "1",
                                                      "--no-nanny", "--host", "127.0.0.1"])]
    context, processes = multiprocessing.get_context("forkserver"), []
    try:
        for command in commands:
            script = {"MODULE": command[0], "ARGS": command[1]}
            processes.append(context.Process(target=exec, args=(DASK_COMMAND, script), daemon=True))
            processes[-1].start()
        _wait_for(lambda: _address_in(scheduler_file), "the scheduler's file", 60)
        yield scheduler_file, processes[1:], processes[0]
    finally:
        for process in processes:
            _kill(process)


def _address_in(scheduler_file: Path) -> bool:
    """Whether the scheduler has written its file whole: Dask creates it, then writes its JSON, and a
    map that read it between the two was refused (an empty file is not a scheduler file)."""
    try:
        return "address" in json.loads(scheduler_file.read_text())
    except (OSError, ValueError):
        return False


@contextmanager
def _once_written(out: Path, parts: int, act):
    """While the block runs, ``act()`` on a thread of this process once ``out`` holds ``parts``
    parts (:func:`_parts`), at most once; yields the list that gets ``act``'s result."""
    done, stop = [], threading.Event()

    def watch():
        while not stop.wait(0.02):
            if out.exists() and len(_parts(out)) >= parts:
                done.append(act())
                return

    watcher = threading.Thread(target=watch, daemon=True)
    watcher.start()
    try:
        yield done
    finally:
        stop.set()
        watcher.join(timeout=SECONDS)


def _map_on(scheduler_file: Path, out: Path):
    """``foldopt map MAP --scheduler scheduler_file --out out`` run in this process, the map's client
    (its cluster's processes are what these tests are about; a process of its own imported foldopt
    and drew the map's figures again)."""
    return CliRunner().invoke(app, ["map", *MAP, "--out", str(out), "--scheduler", str(scheduler_file)])


@pytest.fixture(scope="module")
def worker_killed(hand_started, tmp_path_factory, figures_drawn_elsewhere) -> tuple[Path, int, str]:
    """A map on :func:`hand_started`, one of whose two workers is killed once the first part is
    written: its folder, the parts there when the worker was killed, and the run's stderr. Its
    figures are not drawn (conftest.figures_drawn_elsewhere): what is tested is its table."""
    scheduler_file, workers, _ = hand_started
    out = tmp_path_factory.mktemp("worker-killed") / "map"

    def kill():
        alive = workers[0].is_alive()
        workers[0].kill()
        return alive, len(_parts(out))

    with figures_drawn_elsewhere(), _once_written(out, 1, kill) as killed:
        run = _map_on(scheduler_file, out)
    assert run.exit_code == 0, run.output
    [(alive, killed_at)] = killed
    assert alive
    return out, killed_at, run.stderr


def test_a_worker_killed_mid_run_loses_nothing(worker_killed, direct):
    """Every site once, the same bits as the computation without Dask."""
    out, killed_at, err = worker_killed
    assert killed_at < N_SITES  # the worker died with work left
    assert err.splitlines()[0].startswith("Dask scheduler tcp://127.0.0.1:") and len(err.splitlines()) == 1, err
    table = pd.read_parquet(out / "map.parquet")
    _every_site_once(table)
    pd.testing.assert_frame_equal(table, direct, check_exact=True)
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "complete" and meta["cluster"].startswith("Dask scheduler tcp://127.0.0.1:")


def _snapshot(folder: Path) -> dict[str, tuple]:
    return {str(path.relative_to(folder)): (path.read_bytes(), path.stat().st_mtime_ns)
            for path in sorted(folder.rglob("*")) if path.is_file()}


def test_a_scheduler_lost_mid_run_is_one_line_and_a_resume_that_cannot_connect_changes_nothing(
        hand_started, worker_killed, tmp_path):
    # The cluster whose worker was killed, once that map is whole (worker_killed): one worker left,
    # and what is lost is the scheduler.
    scheduler_file, _, scheduler = hand_started
    out = tmp_path / "map"
    address = json.loads(scheduler_file.read_text())["address"]
    with _once_written(out, 1, scheduler.kill):
        run = _map_on(scheduler_file, out)
    lines = run.stderr.splitlines()
    assert run.exit_code == 2 and len(lines) == 2, run.output
    assert lines[0].startswith("Dask scheduler tcp://127.0.0.1:")
    assert re.fullmatch(rf"error: --scheduler = '{re.escape(str(scheduler_file))}': the scheduler was lost mid-run "
                        rf"\((scheduler-connection-lost|CommClosedError)\); the \d+ of {N_SITES} chunks done are kept: "
                        r"start it again and finish the map with --resume", lines[1]), lines[1]
    before = _snapshot(out)
    assert json.loads((out / "run.json").read_text())["status"] == "running" and before
    refused = CliRunner().invoke(app, ["map", *MAP, "--out", str(out), "--resume", "--scheduler", address])
    assert refused.exit_code == 2, refused.output
    assert refused.stderr.startswith(f"error: --scheduler = '{address}': no Dask scheduler answers"), refused.stderr
    assert _snapshot(out) == before and not [path for path in tmp_path.iterdir() if path.name.startswith(".")]


# --- in this process --------------------------------------------------------------------------------------


def test_the_maps_digest_is_worked_out_once(monkeypatch):
    """Every part written and read carries the map's digest, and the spec holds every site: worked
    out per part, the 1-degree land grid's (0.3 s a time, 902 chunks, three times each) took a
    third of the client's core, which the two workers share."""
    calls = []
    as_dict = MapSpec.as_dict
    monkeypatch.setattr(MapSpec, "as_dict", lambda self: calls.append(1) or as_dict(self))
    spec = MapSpec({"name": "x", "panel": {"area": 0.1}}, tuple({"latitude": float(k), "longitude": 0.0}
                                                                for k in range(50)), (1.0,), sites_per_chunk=1)
    assert len({spec.key for _ in range(len(spec.chunks()))}) == 1 and len(calls) == 1


def test_resume_refuses_another_map(tmp_path, scheduler):
    out = tmp_path / "map"
    spec = MapSpec({"name": "x", "panel": {"area": 0.1}, "sky": "ineichen", "mode": "exact", "step_min": 60,
                    "fold_angles": {"start": 90, "stop": 180, "step": 90}}, ({"latitude": 0.0, "longitude": 0.0},),
                   (1.0,), sites_per_chunk=1)
    # What is tested is the folder, not the cluster: conftest's in-process one (an embedded cluster
    # started a worker process, 3-10 s).
    run_map(spec, out, scheduler=scheduler)
    other = MapSpec(spec.study.variant(panel={"area": 0.2}), spec.sites, spec.loads, sites_per_chunk=1)
    with pytest.raises(OutputError, match="holds another map \\(its study differ"):
        run_map(other, out, resume=True)
    finished = run_map(spec, out, resume=True)  # nothing left to compute
    assert finished.computed == () and finished.from_disk == (0,)


def test_no_scheduler_is_a_one_line_input_error(tmp_path):
    spec = MapSpec({"name": "x", "panel": {"area": 0.1}}, ({"latitude": 0.0, "longitude": 0.0},), (1.0,))
    with pytest.raises(ConfigError, match="no Dask scheduler answers there within 2 s"):
        run_map(spec, tmp_path / "map", scheduler="tcp://127.0.0.1:9", connect_timeout=2)
