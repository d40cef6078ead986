"""Shared fixtures: the paper's study as shipped, a small tmpfs for full disks, an in-process Dask
cluster and figures drawn without their pixels; the suite's order on its two workers, the
compiled code compiled once for both, and the command line's click tree built once a worker."""

import contextlib
import functools
import gc
import io
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

try:
    import fcntl
except ImportError:  # Windows: each worker compiles what it needs, as with -n 0
    fcntl = None

from foldopt.inputs.study_file import default_study_path
from foldopt.api import load_study


def _build_the_command_line_once() -> None:
    """typer's CliRunner builds the click command tree again at every invoke (it reads the
    signature and type hints of every command and option), which cost more than the refusal
    most command-line tests check. The tree is built once a process, as the ``foldopt`` script
    builds it once a run; what each invoke runs (click's parsing, the commands, their contexts)
    is made anew each time."""
    import typer.testing

    typer.testing._get_command = functools.cache(typer.testing._get_command)


_build_the_command_line_once()


@pytest.fixture(scope="session")
def shin_study():
    """configs/shin2015.yaml, resolved (paper mode, azimuth-split, 1-min steps)."""
    return load_study(default_study_path())


def _every_process_imports_this_foldopt() -> None:
    """Put the foldopt this suite imports (a checkout's, or an install's) first on the
    ``PYTHONPATH`` of every process a test starts (command lines, the warm-up, Sphinx, Dask's
    workers). A process started in another folder would otherwise import the installed copy, which
    on a fresh clone (``.ci/run`` installs with ``pip install .``) is another set of source files:
    numba's cache is kept per source file, and each such process compiled the kernel again for
    itself (some 30 s of CPU each), and tested other files than the suite's."""
    import foldopt

    here = str(Path(foldopt.__file__).resolve().parent.parent)
    paths = [path for path in os.environ.get("PYTHONPATH", "").split(os.pathsep) if path]
    if paths[:1] != [here]:
        os.environ["PYTHONPATH"] = os.pathsep.join([here, *paths])


def pytest_configure(config):
    # Electrical tables are cached on disk; tests keep theirs in pytest's own cache folder (kept
    # between runs, ignored by git) rather than in the user's ~/.cache.
    if getattr(config, "cache", None) is not None:  # None under -p no:cacheprovider
        os.environ.setdefault("FOLDOPT_CACHE_DIR", str(config.cache.mkdir("foldopt")))
    if sys.dont_write_bytecode or os.environ.get("PYTHONDONTWRITEBYTECODE"):
        # Where the environment asks Python not to write bytecode (this machine's does), each pytest
        # process would rewrite every test module for its assertions again (some 7 s), and each command
        # line a test starts would compile foldopt's modules again (some 0.5 s). The suite keeps the
        # bytecode of its own runs, in the __pycache__ folders git ignores, as Python does by default.
        sys.dont_write_bytecode = False
        os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
    _every_process_imports_this_foldopt()
    if hasattr(config, "workerinput") and "numba" not in sys.modules:
        # Each pytest-xdist worker has a core of its own: numba's threads (OpenMP, which spins while
        # it waits) and OpenBLAS's would fight the other worker for it. One thread each, here and in
        # the processes the tests start (the command line, Dask's workers): the suite's CPU time
        # fell from 460 s to 394 s, its wall time from 260 s to 224 s. Set before numba is imported,
        # which reads it once (changed later, it refuses to compile). The kernel's threads are
        # tested by tests/test_engine.py::test_the_kernel_on_two_threads.
        for name in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
            os.environ.setdefault(name, "1")
    if config.getoption("dist", "no") != "no" and not config.getoption("collectonly"):
        # The scopes in the order pytest_collection_modifyitems gives them, not pytest-xdist's
        # (the groups of most tests first, whatever they cost); the option is pytest-xdist 3.8's.
        config.option.loadscopereorder = False
        if not hasattr(config, "workerinput") and _whole_suite(config):
            _start_the_warm_up(config)


# --- the compiled code, compiled once ---------------------------------------------------------------

#: The environment variable that names the warm-up's folder to the workers.
WARM_UP = "SUITE_WARM_UP_FOLDER"
#: What each warm-up process runs (``python -c``): the numba functions the suite calls, in the
#: argument types it calls them with, compiled into numba's cache. On a fresh clone each worker
#: compiled them for itself, and again the Dask worker of the first map and the docs build, the
#: compile costing more than most modules' tests. Two parts run beside the workers, which start
#: with :data:`BEFORE_THE_WARM_UP`, on one cache, each about half the compile: the fold kernel's
#: rows (its general loop), and the rest (the sun and the sky, the common case's loop, the buffer,
#: the reduction of given curves); a third process would cost its imports and numba's start. Each
#: part is two steps, each marked done by a lock its process lets go of: ``first``, what the
#: modules of :data:`BEFORE_THE_WARM_UP` call and what the other part's loop calls, which they wait
#: for (``wait_for`` in a part), so that it is loaded from the cache, never compiled twice at once;
#: then the rest, which the other modules wait for. The rows' first step is the shorter: while its
#: process waits for the other's, the workers still collect the suite, and no core is idle.
WARM_UP_PARTS = {
    "rows": ("""
import numpy as np
import foldopt
from foldopt.engine import evaluation as engine
from foldopt.engine.curve_reduction import blocked_day
from foldopt.engine.kernel import _keep_curves
from foldopt.engine.sky import build_sky
from foldopt.inputs.study_file import default_study_path
from foldopt.studies.engine_options import engine_options

# What both kernel parts call, in the argument types they call it with: a day's walk by blocks, a
# row's curves kept.
one, two = np.zeros(1), np.zeros(2)
blocked_day(np.zeros(4), (0, 3), np.ones(1), 0.25, np.zeros(4), (one, one), (one, two), np.zeros(1))
_keep_curves(np.zeros((1, 4)), np.zeros((1, 4)), 0, 3)
""", """
# The fold kernel's rows: the ideal circuit's (the paper's study) and the circuit as built, on skies
# whose passes the other part compiles.
wait_for("common.first")
for name in ("shin2015", "site-as-built"):
    study = foldopt.load_study(default_study_path().parent / f"{name}.yaml")
    options = engine_options(study)
    orientation = engine.fold_orientations(study.geometry, [study.panel.tilt], [study.panel.azimuth], [90.0, 180.0])
    engine.row_metrics(build_sky(options.sky, [study.site], [study.date]), rows=engine.PanelRows(
        np.zeros(2, dtype=np.int64), orientation.reshape(-1, 4)), loads=[1.0], electrical=options.electrical,
        outputs=engine.OUTPUTS, contiguous=True, engine="numba")
"""),
    "common": ("""
import numpy as np
from foldopt.engine import evaluation as engine
from foldopt.engine.curve_reduction import period_means
from foldopt.engine.incidence import turning_poa
from foldopt.engine.sky import build_sky
from foldopt.engine.storage import Buffer, simulate
from foldopt.inputs.study import make_study
from foldopt.physics.trackers import TrackerDrive, moved_degrees
from foldopt.studies.engine_options import engine_options

# The sun and the sky's passes (SPA's, the clear sky's), of the fold kernel's common case (switching
# alone from one table set, exact incidence, constant loads).
study = make_study({"name": "common", "mode": "exact", "sky": "ineichen", "pv_model": "single-diode",
                    "connection": "switching", "site": {"latitude": 34.05, "longitude": -118.25},
                    "date": "2025-06-21", "panel": {"area": 0.108, "efficiency": 0.19}, "p_load": 1.0})
options = engine_options(study)
sky = build_sky(options.sky, [study.site], [study.date])
# The means over periods of days; a tracker's irradiance (its normal's components along the steps,
# as foldopt.studies.designs.sky_tracker_poa hands them) and moves.
period_means(np.zeros((1, 2)), np.ones((1, 1), dtype=bool))
turning_poa(np.zeros((2, 3, 2)), np.zeros((2, 3, 2)), np.zeros((2, 2)), np.zeros((2, 1, 2)),
            np.zeros((2, 2), dtype=np.int64), np.zeros((2, 2)))
TrackerDrive(standby_w=0.3).move_energy_wh(moved_degrees(np.eye(3)[None], "numba"), "numba")
""", """
# The buffer's simulation (one series or several, one buffer or one a series alike).
simulate(np.ones((1, 96)), 0.5, Buffer(1.0), 0.25, engine="numba")
# The common case's loop: every clear-sky study with I-V tables and a year of weather takes it, and
# until it is compiled `auto` sends such studies to the NumPy path (a year 41 s there against 2.5 s).
orientation = engine.fold_orientations(study.geometry, [study.panel.tilt], [study.panel.azimuth], [90.0, 180.0])
wait_for("rows.first")
engine.row_metrics(sky, rows=engine.PanelRows(np.zeros(2, dtype=np.int64), orientation.reshape(-1, 4)),
                   loads=[1.0], electrical=options.electrical, outputs=("switching",), engine="numba")
# The reduction of given curves (a tracker's, a design's: constant loads and a load profile's alike).
engine.curve_metrics(np.zeros((2, 96)), [1.0], 0.25, contiguous=True, engine="numba")
"""),
}
#: What each warm-up process runs before its part's steps: ``wait_for(step)`` returns once the
#: process of another part has let go of the step's lock (``<part>.first`` or ``<part>``), in the
#: warm-up's folder, its working folder.
_WARM_UP_PRELUDE = """
import fcntl
import os

def wait_for(step):
    with open(step + ".lock") as held:
        fcntl.flock(held, fcntl.LOCK_SH)
"""
#: The warm-up's processes (the controller's), to wait for or end at the session's end.
_warm_up_processes: dict[str, subprocess.Popen] = {}


def _whole_suite(config) -> bool:
    """Whether the run collects the whole suite (no narrower path given): what the warm-up is for."""
    here = Path(__file__).resolve().parent
    return all(here.is_relative_to(Path(arg.split("::")[0]).resolve()) for arg in config.args)


def _start_the_warm_up(config) -> None:
    """Start the warm-up's processes, each holding an exclusive lock on ``<part>.lock`` (and on
    ``<part>.first.lock`` while its first step runs) in a folder of its own until it ends (the locks
    are taken here and handed over, so that no worker can find one free before the process has
    it); the workers learn the folder from :data:`WARM_UP`."""
    if fcntl is None:
        return
    folder = Path(tempfile.mkdtemp(prefix="foldopt-warm-up-"))
    os.environ[WARM_UP] = str(folder)
    # The suite's foldopt is on PYTHONPATH (_every_process_imports_this_foldopt).
    env = {**os.environ, "NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    for part, (first, then) in WARM_UP_PARTS.items():
        with contextlib.ExitStack() as stack:
            log = stack.enter_context(open(folder / f"{part}.log", "w"))
            locks = [stack.enter_context(open(folder / f"{step}.lock", "w"))
                     for step in (part, *([f"{part}.first"] if first else []))]
            for lock in locks:
                fcntl.flock(lock, fcntl.LOCK_EX)
            # The first step's end closes the process's copy of its lock (this one closes here).
            code = _WARM_UP_PRELUDE + first + (f"os.close({locks[1].fileno()})\n" if first else "") + then
            _warm_up_processes[part] = subprocess.Popen(
                [sys.executable, "-c", code], cwd=folder, env=env, stdout=log, stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL, pass_fds=[lock.fileno() for lock in locks])
    config.add_cleanup(_end_the_warm_up)


def _end_the_warm_up() -> None:
    for process in _warm_up_processes.values():
        if process.poll() is None:
            process.kill()
        process.wait()
    shutil.rmtree(os.environ.pop(WARM_UP), ignore_errors=True)


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config):
    # Every object frozen as the process ends (a worker, the controller), as the command line's own
    # process does (foldopt.cli.process.ending): the exit's passes of the collector walked the
    # objects of half the suite, some 1-3 s a process, which the controller waited for.
    gc.freeze()


def pytest_terminal_summary(terminalreporter):
    failed = [(part, process) for part, process in _warm_up_processes.items() if process.poll() not in (0, None)]
    for part, process in failed:
        log = (Path(os.environ[WARM_UP]) / f"{part}.log").read_text(errors="replace").strip().splitlines()
        terminalreporter.write_line(f"the compiled code's warm-up ({part}) failed, exit {process.returncode}; each "
                                    f"worker compiled it for itself: {log[-1] if log else ''}", yellow=True)


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item):
    """In a worker, before the fixtures of a test, wait until the warm-up has compiled what the test
    calls: the first step of every part (``<part>.first.lock``) for the modules of
    :data:`BEFORE_THE_WARM_UP`, every part whole for the others (the first that evaluates a study,
    here, in a command line or in a Dask worker it starts). numba's cache then holds what they
    compiled, nothing is compiled twice, and ``auto`` finds the kernel compiled whole or not at all."""
    folder = os.environ.get(WARM_UP)
    steps = "*.first.lock" if item.path.name in BEFORE_THE_WARM_UP else "*.lock"
    if folder and fcntl is not None and steps not in _waited_for:
        for path in sorted(Path(folder).glob(steps)):
            with open(path) as held:
                fcntl.flock(held, fcntl.LOCK_SH)  # free once its process has let go of it
        _waited_for.add(steps)


#: The warm-up's steps this worker has waited for (a pattern of their locks' names).
_waited_for: set[str] = set()


# --- the order of the suite -------------------------------------------------------------------------

#: Modules that evaluate no study above ``auto``'s bound for a compiled kernel (physics against its
#: references, the code's layout, days on the NumPy path): what they compute does not hang on how far
#: the warm-up has got (``auto`` takes the kernel for a smaller request once it is compiled), so the
#: workers run them first, while the warm-up compiles. What they call compiled (the sun, the sky,
#: a tracker's irradiance and moves, the means over periods) is the warm-up parts' first steps,
#: which they wait for: with those in numba's cache they compile nothing the warm-up compiles.
BEFORE_THE_WARM_UP = ("test_weather_validation.py", "test_architecture.py", "test_aggregation.py",
                      "test_near_optimal.py", "test_storage_section.py", "test_atmosphere.py", "test_clearsky.py",
                      "test_converter.py", "test_electrical.py", "test_geometry.py", "test_horizon.py",
                      "test_invariants.py", "test_irradiance.py", "test_metrics.py", "test_plan.py", "test_pvmodel.py",
                      "test_pvsystem.py", "test_pvwatts.py", "test_registries.py", "test_reproduce.py",
                      "test_solarposition.py", "test_sweep.py", "test_tables.py", "test_tracker.py", "test_weather.py",
                      "test_weather_measured.py")
#: Then the longest units of work (an xdist group, a module, or a test), longest first: each worker
#: takes the next unit when it has two tests left, so that the long ones start early and the end is
#: made of short tests, and the two workers finish together.
LONG_FIRST = (*BEFORE_THE_WARM_UP, "test_docs.py", "test_report_html.py", "test_cluster.py", "test_cli_readme.py",
              "test_cli_studies.py", "test_weather_year.py", "test_weather_validation_minutes.py",
              "test_weather_fetch.py", "test_weather_faults.py", "test_camera_winter.py", "test_faults_cluster.py",
              "test_engine.py", "test_figures.py", "test_columns.py", "test_search.py", "test_faults_map_finish.py",
              "test_one_answer.py", "test_bad_input.py", "test_figure_pool.py")


#: conftest's module-scoped fixtures that cost a process's time to set up (a Dask cluster).
SHARED_HERE = ("scheduler",)


def _shares_a_fixture(item) -> bool:
    """Whether the test reads a module- or session-scoped fixture its own module defines (a study's
    run, a folder, a server), or one of :data:`SHARED_HERE`."""
    module, info = item.nodeid.split("::")[0], getattr(item, "_fixtureinfo", None)
    return info is not None and any(
        definition.scope in ("module", "session") and (definition.baseid == module or name in SHARED_HERE)
        for name, definitions in info.name2fixturedefs.items() for definition in definitions)


@pytest.hookimpl(tryfirst=True)  # before pytest-xdist names the groups in the node ids
def pytest_collection_modifyitems(items):
    rank = {name: index for index, name in enumerate(LONG_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))  # stable: each part's order is kept
    # pytest-xdist's --dist loadgroup gives a test outside a group to either worker: the tests of a
    # module that share a fixture built once a module (or a session) went to both, and each worker
    # built it (a year's study run twice). They are one group, the module's, run by one worker.
    for item in items:
        if not any(item.iter_markers("xdist_group")) and _shares_a_fixture(item):
            item.add_marker(pytest.mark.xdist_group(item.path.stem))


@functools.cache
def _one_pixel_png() -> bytes:
    from matplotlib.figure import Figure

    png = io.BytesIO()
    Figure(figsize=(0.01, 0.01)).savefig(png, dpi=100, format="png")
    return png.getvalue()


def _drawn_without_pixels(ax, file, margins=None, file_format=None):
    """foldopt's save_plot but for the pixels: every artist of the figure is drawn (matplotlib's
    ``draw_without_rendering``: a plot that fails on its data fails here), nothing is laid out
    (``margins`` unused) or rasterised, and the file (the figure's bytes) is a PNG of one pixel."""
    import numpy as np

    np.ravel(ax)[0].figure.draw_without_rendering()
    file.write(_one_pixel_png())
    return file


@contextlib.contextmanager
def _figures_without_pixels():
    """Within the block, a results folder's figures are drawn but not rasterised
    (:func:`_drawn_without_pixels`)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr("foldopt.output.figures.save_plot", _drawn_without_pixels)
        yield


@pytest.fixture(autouse=True)
def _no_pixels_unless_marked(request):
    """Every test's figures without pixels (:func:`_figures_without_pixels`), unless it is marked
    ``figure_pixels``: laying out and rasterising are most of writing a folder, in the tests that
    write folders for their tables, answers and refusals and never look at a figure. Those that
    look at them (the figures' own tests, the reports a browser opens, every shipped study's
    folder) are marked, and draw them whole."""
    with contextlib.nullcontext() if request.node.get_closest_marker("figure_pixels") else _figures_without_pixels():
        yield


@pytest.fixture(scope="session")
def without_pixels():
    """For module- and session-scoped fixtures that write folders (set up before a test's own
    fixtures): the context manager :func:`_no_pixels_unless_marked` enters."""
    return _figures_without_pixels


@pytest.fixture
def small_disk(tmp_path):
    """A 2 MB tmpfs at ``tmp_path / "disk"``, unmounted afterwards; skipped where it cannot be mounted."""
    disk = tmp_path / "disk"
    disk.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(disk)], capture_output=True,
                             text=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.strip() or mounted.returncode}")
    try:
        yield disk
    finally:
        subprocess.run(["umount", str(disk)], check=True)


@contextlib.contextmanager
def _in_process_cluster():
    """A Dask scheduler and one single-threaded worker in this process, on 127.0.0.1; yields its
    address. Skipped without distributed."""
    import logging

    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp://",
                                       host="127.0.0.1", dashboard_address=None, silence_logs=logging.ERROR)
    try:
        yield cluster.scheduler_address
    finally:
        cluster.close()


@pytest.fixture(scope="module")
def scheduler():
    """The address of a Dask cluster in this process (no process to start: a map's embedded
    cluster, ``--workers 1``, starts one that imports foldopt and loads its compiled code again,
    5-18 s on the 2-core machine). Tests whose point is the embedded cluster or a process of its
    own are tests/test_cluster.py's."""
    with _in_process_cluster() as address:
        yield address


@pytest.fixture(scope="session")
def in_process_scheduler():
    """For session-scoped fixtures that run a map: the context manager :func:`scheduler` enters,
    to enter for as long as the map runs."""
    return _in_process_cluster


@contextlib.contextmanager
def _figures_not_drawn():
    """Within the block, a results folder's figures are written as a PNG of one pixel without
    being drawn at all."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr("foldopt.output.figures.figure_bytes", lambda file, args, kwargs: _one_pixel_png())
        yield


@pytest.fixture(scope="session")
def figures_drawn_elsewhere():
    """For a run whose figures the test draws in another run from the same data (another view of
    one answer, one weather fetched and read from its file), whose folder is read for its tables
    and answers only: the context manager :func:`_figures_not_drawn`. Drawing a figure, even
    without its pixels, costs a few tenths of a second."""
    return _figures_not_drawn


@contextlib.contextmanager
def _folders_not_written():
    """Within the block, :func:`foldopt.api.write` (the command line's too) makes the results
    folder and writes nothing in it."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr("foldopt.api.write", lambda result, out, *args, **kwargs: Path(out).mkdir(
            parents=True, exist_ok=True))
        yield


@pytest.fixture(scope="session")
def folders_written_elsewhere():
    """For a command whose folder the test writes in another run of the same answer, or reads
    nothing of (its document, its terminal's lines): the context manager
    :func:`_folders_not_written`. Writing a folder (its tables, series, report and figures) costs
    most of a day's command."""
    return _folders_not_written


@contextlib.contextmanager
def _runs_shared():
    """Within the block, a request is evaluated once: :func:`foldopt.api.run` (``foldopt.run``,
    the command line's too) given a request equal to an earlier one's, with the same engine, is
    given the earlier result (one answer, decided once). A request that differs in anything
    (its plan, its source, its labels) runs anew."""
    import foldopt
    import foldopt.api
    from foldopt.names import DEFAULT_ENGINE
    from foldopt.studies.request import make_request

    real, done = foldopt.api.run, []

    def run(study=None, engine=DEFAULT_ENGINE, progress=None, request=None):
        if request is None:  # as foldopt.api.run makes it
            request = make_request("run", study)
        for asked, result in done:
            if asked == (request, engine):
                return result
        done.append(((request, engine), real(None, engine, progress, request)))
        return done[-1][1]

    with pytest.MonkeyPatch.context() as patch:
        # foldopt's package first: its ``run`` is looked up in foldopt.api when first asked for, and
        # once foldopt.api's is patched would be recorded, and put back, as the patch.
        patch.setattr(foldopt, "run", run)
        patch.setattr(foldopt.api, "run", run)
        yield


@pytest.fixture(scope="session")
def runs_shared():
    """For tests that ask one request by several routes (a command's ``--format json`` and its
    terminal, the command line and the API): the context manager :func:`_runs_shared`."""
    return _runs_shared
