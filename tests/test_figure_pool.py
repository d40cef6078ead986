"""The command line's figure workers (:mod:`foldopt.output.drawing`, issue 49): the command line's
own process on more than one core has its figures drawn by worker processes beside it, and what
it writes and says is what it writes and says when it draws them itself (one core, or a caller in
its own process): the same bytes, the same error and exit code with nothing written, no worker
left once the command ends, however it ends.

Each command runs in a process of its own that runs the command line as the ``foldopt`` script
does (:data:`WATCH`, :data:`COMMAND`), on the cores it is given (``os.sched_setaffinity``): one
core draws in the command's process, two in the workers. The probe records the process that drew
each figure, and the collector's work (the command line's process freezes what it loads, issue
49). The processes are forked by one interpreter a module (:data:`SERVER`) that has imported what
a command loads before its figures, as a fresh one would (not matplotlib); a command that
completes is run once a module (:func:`commands`) for every check of its run. A caller in its own
process is tests/test_report_html.py's (each figure of its commands' folders drawn in the
caller's process).
"""

from __future__ import annotations

import contextlib
import json
import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import NamedTuple

import pytest

CORES = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
needs_two_cores = pytest.mark.skipif(
    sys.platform != "linux" or len(CORES) < 2, reason="the workers need Linux and two cores"
)

#: The probe's watch: as a command's process ends it prints its id, whether it imported
#: matplotlib, and the collector's passes that ran with objects frozen (and the most frozen then)
#: and what is frozen and not as it exits.
WATCH = r"""
import atexit, gc, json, os, sys

seen = {"passes": 0, "frozen": 0, "now": 0}


def counted(change):
    def changed():
        change()
        seen["now"] = gc.get_freeze_count()

    return changed


# The objects frozen as the last freeze left them: gc.get_freeze_count() walks them all, and read
# at each of a command's many passes it cost more than the command.
gc.freeze, gc.unfreeze = counted(gc.freeze), counted(gc.unfreeze)


def watch(phase, info):
    if phase == "start" and seen["now"]:
        seen["passes"] += 1
        seen["frozen"] = max(seen["frozen"], seen["now"])


def report():
    exit = [gc.get_freeze_count(), len(gc.get_objects())]
    state = {"passes": seen["passes"], "frozen": seen["frozen"], "exit": exit}
    print(json.dumps([os.getpid(), "matplotlib" in sys.modules, state]))


gc.callbacks.append(watch)
# Registered first, so run last: after the command and every exit handler of its libraries.
atexit.register(report)
"""

#: The probe's command, in a process that ran :data:`WATCH`: runs the command line as the script
#: does. Each figure drawn appends the drawing process's id to the file ``drawn`` (by the module's
#: one drawing function, wrapped), after ``slow`` seconds; with ``fail`` set, the figure of that
#: name raises.
COMMAND = r"""
import json, os, runpy, sys, time
import foldopt.output.figures as figures
from foldopt.output.figures.canvas import FigureFile

drawn, fail, slow, workers, args = json.loads(sys.argv[1])
if workers is not None:  # as many as the cores, however busy the machine is
    from foldopt.output import drawing

    drawing.workers = lambda: workers
draw = figures.figure_bytes


def recorded(file, args, kwargs):
    time.sleep(slow)
    with open(drawn, "a") as log:
        log.write(f"{os.getpid()}\n")
    return draw(file, args, kwargs)


def failing(*args, **kwargs):
    raise ValueError("a figure that cannot be drawn\nits second line")


# A worker finds the function by its name, as it finds the one it stands for.
recorded.__module__, recorded.__qualname__ = figures.__name__, "figure_bytes"
figures.figure_bytes = recorded
if fail:
    figures.FIGURES[fail] = FigureFile(failing, "fails")
sys.argv = ["foldopt", *args]
runpy.run_module("foldopt.cli.app", run_name="__main__", alter_sys=True)
"""

#: Forks each command (:func:`_start`): :data:`WATCH` (which sees no pass of the collector
#: before a command freezes), then the modules a command loads before its figures, which a
#: command's own interpreter spends 0.8-1.5 s CPU importing; not matplotlib (a command on two
#: cores never imports it), nor the command line's (run as ``__main__``, as the script runs it).
#: It reads a command a line (its folder, cores and probe's argument) and answers with its
#: process id, then its exit code (as ``Popen``'s).
SERVER = (
    WATCH
    + r"""
import multiprocessing, pvlib
import foldopt.api, foldopt.engine.kernel, foldopt.engine.storage_kernel, foldopt.output.folders
import foldopt.output.figures, foldopt.physics.spa_site, foldopt.studies.day
import foldopt.studies.request, foldopt.studies.result_answers
import foldopt.cli.map, foldopt.cli.optimize, foldopt.cli.run, foldopt.cli.size, foldopt.cli.sweep
import foldopt.cli.weather

assert "matplotlib" not in sys.modules and "foldopt.cli.app" not in sys.modules
for request in sys.stdin:
    folder, cores, argument = json.loads(request)
    pid = os.fork()
    if pid == 0:
        break
    print(pid, flush=True)
    print(os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1]), flush=True)
else:  # no command left: the server ends without the exit's walk of what it imported
    os._exit(0)
os.sched_setaffinity(0, cores)
os.chdir(folder)
for fd, name, flags in ((0, os.devnull, os.O_RDONLY), (1, folder + ".stdout", os.O_WRONLY),
                        (2, folder + ".stderr", os.O_WRONLY)):
    os.dup2(os.open(name, flags | (os.O_CREAT | os.O_TRUNC if fd else 0)), fd)
sys.argv = ["-c", argument]
"""
    + COMMAND
)


class Forked:
    """A command the server forked (:data:`SERVER`), as a ``subprocess.Popen`` of it: its id,
    exit code, and its end awaited or signalled."""

    def __init__(self, server: subprocess.Popen):
        self._answers = server.stdout  # unbuffered: a line read takes no more
        self.pid, self.returncode = int(self._answers.readline()), None

    def poll(self) -> int | None:
        return self.wait(timeout=0) if self.returncode is None else self.returncode

    def wait(self, timeout: float | None = None) -> int | None:
        if self.returncode is None:
            if not select.select([self._answers], [], [], timeout)[0]:
                if timeout == 0:
                    return None
                raise subprocess.TimeoutExpired(f"command {self.pid}", timeout)
            self.returncode = int(self._answers.readline())
        return self.returncode

    def send_signal(self, sig: int) -> None:
        os.kill(self.pid, sig)


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    """The interpreter that forks the module's commands (:data:`SERVER`), with Ctrl-C at its
    default (a pytest-xdist worker may hold it ignored, which a child keeps); its own errors in
    a file."""
    errors = tmp_path_factory.mktemp("server") / "stderr"
    with open(errors, "w") as stderr:
        forking = subprocess.Popen(
            [sys.executable, "-c", SERVER],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=stderr,
            bufsize=0,
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        )
    yield forking
    forking.stdin.close()
    assert forking.wait(timeout=60) == 0, errors.read_text()


def _start(server, args, folder: Path, cores: int, fail: str | None = None, slow: float = 0):
    """Start ``foldopt args`` in ``folder`` on the first ``cores`` cores (one: :func:`workers`
    says none; two: two workers, however busy the machine), forked by ``server``, its stdout
    and stderr to the files ``folder.stdout`` and ``folder.stderr`` beside it: files, not pipes,
    which a worker left behind would hold open."""
    folder.mkdir(parents=True, exist_ok=True)
    payload = [str(folder / "drawn"), fail, slow, None if cores == 1 else 2, args]
    request = [str(folder), CORES[:cores], json.dumps(payload)]
    server.stdin.write(f"{json.dumps(request)}\n".encode())
    return Forked(server)


class Ran(NamedTuple):
    """What a command did: its exit code, its stdout's lines but the probe's, its stderr, its
    process id, whether it imported matplotlib, the ids of the processes that drew its figures,
    the collector's work (:data:`WATCH`), its workers (two cores) and whether one outlived it."""

    code: int
    lines: list[str]
    stderr: str
    pid: int
    matplotlib: bool
    drawers: list[int]
    collector: dict
    workers: set[int]
    outlived: bool


def _run(server, args, folder: Path, cores: int, fail: str | None = None) -> Ran:
    """Run ``foldopt args`` in ``folder`` on ``cores`` cores (:func:`_start`) to its end, its
    workers seen while it runs where it has them."""
    process = _start(server, args, folder, cores, fail)
    workers = set()
    try:
        workers = _workers_of(process) if cores > 1 else set()
        process.wait(timeout=300)
        outlived = not _gone(workers)
    finally:
        _end(process, workers)
    lines = Path(f"{folder}.stdout").read_text().splitlines()
    pid, matplotlib, collector = json.loads(lines[-1])
    drawn = folder / "drawn"
    drawers = [int(line) for line in drawn.read_text().split()] if drawn.exists() else []
    drawn.unlink(missing_ok=True)
    stderr = Path(f"{folder}.stderr").read_text()
    return Ran(
        process.returncode,
        lines[:-1],
        stderr,
        pid,
        matplotlib,
        drawers,
        collector,
        workers,
        outlived,
    )


def _end(process: Forked, workers: set[int]) -> None:
    """Kill what is left of a command and its workers, and reap the command."""
    for pid in (process.pid, *workers):
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    process.wait()


def _files(folder: Path) -> dict[str, bytes]:
    return {path.name: path.read_bytes() for path in sorted(folder.iterdir())}


@pytest.fixture(scope="module")
def commands(server, tmp_path_factory):
    """``run(args, cores)``: ``foldopt args --out out`` run on ``cores`` cores (:func:`_run`), once
    a module for every check of its run, in a folder that has the repository's configs: (what it
    did, its results folder)."""
    repository = Path(__file__).resolve().parents[1]
    ran = {}

    def run(args, cores: int) -> tuple[Ran, Path]:
        if (tuple(args), cores) not in ran:
            folder = tmp_path_factory.mktemp("command")
            (folder / "configs").symlink_to(repository / "configs")
            ran[tuple(args), cores] = (
                _run(server, [*args, "--out", "out"], folder, cores),
                folder / "out",
            )
        return ran[tuple(args), cores]

    return run


@needs_two_cores
@pytest.mark.parametrize(
    "args",
    [
        ["run", "-q"],
        ["run", "configs/camera-buffer.yaml"],
        ["sweep", "angle", "--step-min", "10", "--format", "json"],
    ],
)
def test_the_workers_write_the_bytes_the_command_draws_itself(commands, args):
    """Every file (PNG, CSV, run.json, report.html) and what the command prints are the same
    whether the figures are drawn by the workers (two cores: drawn in other processes than the
    command's, which never imports matplotlib) or by the command itself (one core)."""
    seen = {}
    for cores in (1, 2):
        ran, out = commands(args, cores)
        assert ran.code == 0, ran.stderr
        assert ran.drawers and (set(ran.drawers) == {ran.pid}) is (cores == 1)
        assert ran.matplotlib is (cores == 1)
        seen[cores] = (ran.lines, ran.stderr, _files(out))
    assert any(name.endswith(".png") for name in seen[1][2])
    assert seen[1] == seen[2]


#: The shipped studies whose folder, as a user gets it, the module's commands write on one core
#: (every figure drawn whole in the command's process), checked here: tests/test_cli_studies.py
#: does not run them again (its RUN_ELSEWHERE). ``foldopt run`` runs configs/shin2015.yaml.
SHIPPED = {"shin2015": ["run", "-q"], "camera-buffer": ["run", "configs/camera-buffer.yaml"]}


@pytest.mark.skipif(sys.platform != "linux", reason="the probe sets a command's cores on Linux")
@pytest.mark.parametrize("config", SHIPPED)
def test_a_shipped_studys_folder_as_a_user_gets_it(commands, config):
    """The shipped study's folder, written by the command line's own process on one core, every
    figure drawn whole: as tests/test_cli_studies.py checks every other shipped study's."""
    from test_cli_studies import RUN_ELSEWHERE, assert_a_users_folder

    assert RUN_ELSEWHERE[config] == Path(__file__).name
    if config == "shin2015":  # the study of a bare `foldopt run`
        from foldopt.studies.request import make_request

        assert Path(make_request("run", None).source) == Path("configs/shin2015.yaml")
    ran, out = commands(SHIPPED[config], 1)
    assert ran.code == 0, ran.stderr
    assert_a_users_folder(out)


@needs_two_cores
def test_a_figure_that_fails_fails_the_command_as_it_does_without_workers(server, tmp_path):
    """A figure that raises in a worker ends the command with the one line and the exit code it
    ends with when the command draws it itself, and nothing is written: no folder, no staging
    folder, nothing beside."""
    said = {}
    for cores in (1, 2):
        folder = tmp_path / str(cores)
        ran = _run(server, ["run", "--out", "out"], folder, cores, fail="switching.png")
        assert sorted(path.name for path in folder.iterdir()) == []
        said[cores] = (ran.code, ran.stderr)
        assert ran.lines[0].startswith("shin2015: ")  # the answer, printed before the figures
    assert said[1] == said[2]
    code, stderr = said[2]
    assert code == 1 and stderr.splitlines() == [
        "error: internal error (ValueError: a figure that cannot be drawn); run again as "
        "foldopt --debug ... for the traceback, and please report it"
    ]


def _children(pid: int) -> set[int]:
    """The ids of the live processes whose parent is ``pid``: the kernel's list of each of its
    threads' children (a scan of every process's status, as often as the tests poll, cost more
    than the commands it watched)."""
    found = set()
    for children in Path(f"/proc/{pid}/task").glob("*/children"):
        with contextlib.suppress(OSError):  # a thread or process that has ended
            found.update(int(child) for child in children.read_text().split())
    return {child for child in found if _alive(child)}


def _alive(pid: int) -> bool:
    try:
        return (
            not (Path("/proc") / str(pid) / "status")
            .read_text()
            .split("State:\t")[1]
            .startswith("Z")
        )
    except (OSError, IndexError):
        return False


def _workers_of(process: Forked) -> set[int]:
    """The command's workers, once it has them all (within a minute): its child, and the one that
    child forks once it has imported matplotlib."""
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and process.poll() is None:
        for first in _children(process.pid):
            others = _children(first)
            if others:
                return {first, *others}
        time.sleep(0.01)
    raise AssertionError("the command forked no workers")


def _gone(workers: set[int], within: float = 10) -> bool:
    deadline = time.monotonic() + within
    while any(_alive(pid) for pid in workers):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.02)
    return True


@needs_two_cores
def test_no_worker_outlives_a_command_that_completes(commands):
    """A command that completes ends its workers as it ends (the quiet run of the bytes' test)."""
    ran, out = commands(["run", "-q"], 2)
    assert ran.workers and not ran.outlived, "a worker outlived the command"
    assert ran.code == 0 and (out / "report.html").is_file(), ran.stderr


@needs_two_cores
@pytest.mark.parametrize("ending", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL])
def test_no_worker_outlives_the_command(server, tmp_path, ending):
    """Whether the command is interrupted (Ctrl-C), terminated or killed while its workers draw,
    they end with it; an interrupted or terminated command says so as it does without workers
    and leaves no folder."""
    # A command still drawing when the signal comes: each figure takes a minute more.
    folder = tmp_path / "command"
    process = _start(server, ["run", "--out", "out"], folder, 2, slow=60)
    workers = set()
    try:
        workers = _workers_of(process)
        process.send_signal(ending)
        process.wait(timeout=300)
        assert _gone(workers), "a worker outlived the command"
    finally:
        _end(process, workers)
    stderr = Path(f"{folder}.stderr").read_text()
    if ending == signal.SIGINT:
        assert (process.returncode, stderr) == (130, "interrupted\n")
    else:
        assert process.returncode in (-ending, 128 + ending)
    assert not (folder / "out").exists()


@pytest.mark.skipif(sys.platform != "linux", reason="the probe sets a command's cores on Linux")
def test_the_command_lines_process_freezes_what_it_loads(commands):
    """In the command line's own process a command's modules are frozen once loaded (the
    collector's passes leave them out, issue 49) while the collector still collects the work's
    garbage, and the process exits with next to nothing left for the exit's passes to walk
    (the quiet run of the bytes' test, its figures drawn by two workers where two cores are)."""
    ran, _ = commands(["run", "-q"], min(len(CORES), 2))
    assert ran.code == 0, ran.stderr
    state = ran.collector
    # Passes ran during the work, with the 100,000-odd objects of typer, pydantic, numpy and
    # pandas (and matplotlib, where the command draws its figures itself) frozen.
    assert state["passes"] > 0 and state["frozen"] > 50_000
    # As it exits, all but what its last handlers made is frozen (none, today); the figure
    # workers' pool, ended as the command ends, has freed what it held, frozen with the rest.
    frozen_at_exit, unfrozen_at_exit = state["exit"]
    assert frozen_at_exit > 50_000 and unfrozen_at_exit < 1_000


@pytest.mark.parametrize(
    ("platform", "cores", "load", "expected"),
    [
        ("linux", {0}, 0.0, 0),
        ("linux", {0, 1}, 0.5, 2),
        ("linux", {0, 1}, 3.0, 2),
        ("linux", {0, 1}, 3.5, 0),
        ("linux", set(range(8)), 3.0, 2),
        ("darwin", {0, 1}, 0.0, 0),
    ],
)
def test_workers_where_a_core_is_to_spare(monkeypatch, platform, cores, load, expected):
    """Workers only on Linux, with more than one core to run on and a machine no busier than its
    cores and the command (the last minute's load), at most two."""
    from foldopt.output import drawing

    monkeypatch.setattr(drawing.sys, "platform", platform)
    monkeypatch.setattr(drawing.os, "sched_getaffinity", lambda pid: cores, raising=False)
    monkeypatch.setattr(drawing.os, "cpu_count", lambda: max(len(cores), 2))
    monkeypatch.setattr(drawing.os, "getloadavg", lambda: (load, load, load))
    assert drawing.workers() == expected


def test_no_workers_where_the_kernel_gives_no_process_file_descriptors(monkeypatch):
    """A kernel before Linux 5.3 has no pidfd_open, by which the command sees a worker end: the
    figures are drawn in the command's process, as on one core."""
    from foldopt.output import drawing

    def unsupported(pid, flags=0):
        raise OSError(38, "Function not implemented")

    monkeypatch.setattr(drawing.sys, "platform", "linux")
    monkeypatch.setattr(drawing.os, "sched_getaffinity", lambda pid: {0, 1}, raising=False)
    monkeypatch.setattr(drawing.os, "getloadavg", lambda: (0.0, 0.0, 0.0))
    monkeypatch.setattr(drawing.os, "pidfd_open", unsupported, raising=False)
    assert drawing.workers() == 0
