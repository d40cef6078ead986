"""The import graph of a command as it runs (issue 49): a refused request and ``foldopt --help``
load none of the heavy libraries (each of which alone costs the 0.3 s a refusal may take),
``foldopt run`` prints its answer before matplotlib loads for the figures, and the embedded
study's answer (the command's, the API's) loads none of numba, scipy, pvlib or pandas (its
tables are NumPy columns until the folder is written or a user asks for a DataFrame). An
in-process caller's collector is left as it was (the command line's own process freezes the
modules a command loads: tests/test_figure_pool.py).

Each command runs in a process of its own that runs the command line as the ``foldopt`` script
does and, as it ends, prints the heavy modules it imported; a meta-path hook writes a marker to
the process's stdout the moment a watched module is first imported, after flushing what the
command printed before, so the order of answer and import is the order of the lines read back.
The processes are forked, one a command, from one interpreter (:data:`PROBE`) that has imported
what the ``foldopt`` script imports before it runs a command, the request's front door and the
API (:data:`PRELOAD`): none of it heavy (:func:`test_import_stays_light`), so a command's child
imports each heavy library a fresh ``foldopt`` would, and an interpreter's start and the light
imports are paid once, not once a command. The API's run (as a notebook makes it) is one more
child of the same interpreter.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

#: Libraries a request's validation needs none of.
HEAVY = ("pvlib", "pandas", "matplotlib", "scipy", "numba", "numpy")
#: What the embedded study's answer imports none of: numba (the day runs on the NumPy path), scipy
#: (its two roots are :func:`foldopt.engine.roots.brentq`), pvlib (the formulas of it the day calls
#: are foldopt's, held to pvlib's bits), pandas (the day's tables are
#: :class:`foldopt.columnar.Columns` until written) and matplotlib (the figures come after the
#: answer).
NOT_FOR_THE_ANSWER = ("numba", "scipy", "pvlib", "pandas", "matplotlib")
#: The line the probe prints where a watched module is first imported.
MARKER = "<<imported {}>>"
#: What the ``foldopt`` script imports before it runs a command (its entry point), and the front
#: door every command's request goes through (:func:`foldopt.studies.request.make_request`, a
#: map's too): the modules the refusals' server imports once for all of them.
SCRIPT = ("foldopt.cli.app",)
FRONT_DOOR = (*SCRIPT, "foldopt.studies.request", "foldopt.studies.map_request")
#: What the probe's interpreter imports, in this order, before it forks the requests' children:
#: the package, the front door and the API (what a notebook imports first).
PRELOAD = ("foldopt", *FRONT_DOOR, "foldopt.api")
#: What a day's study (what ``foldopt run`` computes before it prints its answer) loads none of:
#: no cluster, no figures or report, no weather readers (pvlib.iotools: requests) and no
#: scipy.integrate (pvlib.spectrum); pvlib loads those two where first used (foldopt/__init__.py).
UNUSED = ("dask", "distributed", "xarray", "matplotlib", "jinja2", "requests", "scipy.integrate")
REPOSITORY = Path(__file__).resolve().parents[1]

#: Imports ``preload`` one module at a time, prints the heavy modules it holds after each, and runs
#: each request in a child forked from it (one at a time), as the ``foldopt`` script runs a command
#: (or, for a request whose arguments are a string, runs that Python code): the child's stdout and
#: stderr go to ``<folder>/<index>.out`` and ``.err``; it ends as the script does (the exit code,
#: the exit handlers), having printed the heavy modules it imported. The server prints the
#: children's exit codes.
PROBE = r"""
import json, os, sys

heavy, preload, requests, folder = json.loads(sys.argv[1])
held = []
for name in preload:
    __import__(name)
    held.append(sorted(m for m in heavy if m in sys.modules))
print(json.dumps(held))
codes = []
for index, (args, watched, imports, cwd, one_core) in enumerate(requests):
    sys.stdout.flush()
    sys.stderr.flush()
    child = os.fork()
    if child == 0:
        break
    codes.append(os.waitstatus_to_exitcode(os.waitpid(child, 0)[1]))
else:
    print(json.dumps(codes))
    sys.exit()

import atexit

for fd, name in ((0, os.devnull), (1, f"{folder}/{index}.out"), (2, f"{folder}/{index}.err")):
    os.dup2(os.open(name, os.O_RDWR | os.O_CREAT | os.O_TRUNC if fd else os.O_RDONLY), fd)
if cwd:
    os.chdir(cwd)
if one_core:
    os.sched_setaffinity(0, [min(os.sched_getaffinity(0))])
command = os.getpid()


class Watch:
    '''Marks the first import of each watched module on stdout, after what was printed before, in
    the command's process (not in the figure workers it forks).'''

    def find_spec(self, name, path=None, target=None):
        if name in watched and os.getpid() == command:
            watched.remove(name)
            sys.stdout.flush()
            sys.stdout.write("<<imported %s>>\n" % name)
            sys.stdout.flush()
        return None


sys.meta_path.insert(0, Watch())
for name in imports:
    __import__(name)
atexit.register(lambda: print(json.dumps(sorted(m for m in heavy if m in sys.modules))))
if isinstance(args, str):
    exec(args, {})
    sys.exit()
sys.argv = ["foldopt", *args]
from foldopt.cli.app import app

sys.exit(app())
"""


class Done:
    """What a command's child did: ``code`` (its exit code), ``lines`` (its stdout's lines before
    the last), ``imported`` (the heavy modules it held as it ended) and ``stderr``."""

    def __init__(self, code: int, stdout: str, stderr: str):
        lines = stdout.splitlines()
        assert lines, stderr
        self.code, self.lines, self.imported = code, lines[:-1], json.loads(lines[-1])
        self.stderr = stderr


def _probe(folder: Path, preload, requests) -> tuple[list[list[str]], list[Done]]:
    """Run ``requests`` (each ``(args, watched, imports, cwd, one_core)``: ``foldopt args``, or
    the Python code ``args`` is, in ``cwd``, ``watched`` modules marked, ``imports`` imported
    before it, on one core where ``one_core``, where the command draws its figures itself; on
    more, its workers do: tests/test_figure_pool.py) in the children of a server that has imported
    ``preload``: (the heavy modules the server held after each of ``preload``, what each child
    did)."""
    payload = [HEAVY, preload, requests, str(folder)]
    done = subprocess.run(
        [sys.executable, "-c", PROBE, json.dumps(payload)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    server, codes = map(json.loads, done.stdout.splitlines())
    children = [
        Done(code, (folder / f"{i}.out").read_text(), (folder / f"{i}.err").read_text())
        for i, code in enumerate(codes)
    ]
    return server, children


REFUSALS = [
    (["sweep", "angle", "--lat", "95"], "--lat = 95.0: must be in [-90, 90] deg"),
    (["run", "--set", "p_load=abc"], "p_load = 'abc': Input should be a valid number"),
    (["run", "configs/camera-buffer.yaml", "--set", "storage.capacity_wh=-1"], "capacity_wh"),
    (["sweep", "latitude", "--lat", "100:0:-5"], "--lat"),
    (["optimize", "--tilt-range", "0:200:5"], "--tilt-range"),
    (["sweep", "day", "--days", "1:60:7", "--set", "objective.months=[7]"], "objective.months"),
    (["weather", "fetch", "pvgis-tmy", "--lat", "95", "--lon", "0"], "--lat = 95.0"),
    # A map's request: its grid, loads, period, year, search and study, each checked before the
    # map's evaluation (numpy, pandas, the engine) loads.
    (["map", "--lat", "95", "--lon", "0"], "--lat: must be in [-90, 90] deg"),
    (["map", "--lon", "200"], "--lon: must be in [-180, 180] deg"),
    (["map", "--lat", "10:0:5"], "--lat = '10:0:5': empty range"),
    (["map", "--lat", "abc"], "--lat = 'abc'"),
    (["map", "--p-load", "2e7"], "--p-load = '2e7': loads must be in (0, 1e+06] W"),
    (["map", "--p-load-fraction", "3"], "--p-load-fraction = '3': fractions must be in (0, 2]"),
    (["map", "--show-period", "XYZ"], "--show-period = 'XYZ'"),
    (["map", "--objective", "foo"], "--objective = 'foo'"),
    (["map", "--year", "1000"], "--year = 1000"),
    (["map", "--optimize", "azimuth"], "a map searches the fold angle"),
    (["map", "--lat", "0", "--lon", "0", "--set", "panel.area=-1"], "panel.area = -1"),
    (["map", "--lat", "0", "--lon", "0", "--set", "step_min=7"], "step_min = 7"),
    (["map", "--sites", "no-such-sites.csv"], "--sites: file not found"),
    (["map", "--weather-dir", "no-such-folder"], "--weather-dir: not a folder"),
]


HELP = [["--help"], ["sweep", "angle", "--help"], ["run", "--help"]]
#: The checks' own check: a module imported before the command (as a command that imported it
#: would) is reported, and its marker comes before what the command prints.
SEEN = [
    (["sweep", "angle", "--lat", "95"], [], ["numpy"]),
    (["--version"], ["matplotlib"], ["matplotlib"]),
]


#: The API's run of the embedded study, as a notebook asks for it (Python code, a probe's child):
#: ``foldopt.run()``'s answer, the heavy modules held then; the :data:`UNUSED` modules held after
#: ``foldopt.run(foldopt.default_study())`` too (none after both: none after either); the result's
#: and the answer's tables' types and the series' time zone; then pvlib's two modules foldopt loads
#: where first used (foldopt/__init__.py), and whether the weather readers' ``requests`` came with
#: them.
API_RUN = (
    "import json, sys, foldopt; result = foldopt.run(); lines = result.answer.lines(); "
    f"before = sorted(m for m in {HEAVY!r} if m in sys.modules); "
    "foldopt.run(foldopt.default_study()); "
    f"unused = sorted(m for m in {UNUSED!r} if m in sys.modules); "
    "tables = [type(t).__name__ for t in (result.summary, result.sweep, result.timeseries, "
    "result.standby.table, result.answer.designs, result.answer.near_optimal, "
    "result.answer.schedule)]; "
    "import pvlib; lazy = [callable(pvlib.iotools.read_tmy3), 'requests' in sys.modules, "
    "callable(pvlib.spectrum.spectral_factor_sapm)]; "
    "print(json.dumps([bool(lines), before, unused, tables, str(result.timeseries.index.tz), "
    "lazy]))"
)


@pytest.fixture(scope="module")
def probed(tmp_path_factory) -> dict:
    """Every request, each in a child of one server that has imported :data:`PRELOAD` and none of
    the heavy libraries (else none of these would say what a fresh command imports): the
    refusals, the helps and the probe's own checks; ``foldopt run`` on one core, where it draws
    its figures itself, every heavy module the answer needs none of watched; the API's run
    (:data:`API_RUN`). What each did, by its arguments and the modules imported before it, with
    ``"server"`` (the heavy modules the server held after each of :data:`PRELOAD`) and
    ``"folder"`` (the run's results folder)."""
    folder = tmp_path_factory.mktemp("probe")
    requests = [
        *((args, [], [], str(REPOSITORY), False) for args, _ in REFUSALS),
        *((args, [], [], None, False) for args in HELP),
        *((args, watched, imports, None, False) for args, watched, imports in SEEN),
        (["run", "--out", str(folder / "out")], NOT_FOR_THE_ANSWER, [], str(REPOSITORY), True),
        (API_RUN, [], [], None, False),
    ]
    server, children = _probe(folder, PRELOAD, requests)
    done = {(tuple(r[0]) if isinstance(r[0], list) else r[0], tuple(r[2])): child
            for r, child in zip(requests, children, strict=True)}
    return {**done, "server": dict(zip(PRELOAD, server, strict=True)), "folder": folder / "out"}


@pytest.mark.parametrize("module", ["foldopt", "foldopt.cli.app", "foldopt.api, foldopt.studies.request"])
def test_import_stays_light(probed, module):
    """The command line's help and a bad value must not pay for pandas or pvlib (2 s of a 0.5 s budget):
    neither `import foldopt` nor the command line with every command loads them (a command module that
    imported a study's module at its top once made `foldopt --help` take 2.2 s), nor what checks a
    study (the API, a request): numpy only where a horizon is given (foldopt.inputs.horizon). The
    probe's server imports them in turn: what it holds after the last of ``module``'s (and the
    modules before them) is a bound on what ``module`` alone imports."""
    last = max(PRELOAD.index(name.strip()) for name in module.split(","))
    held = probed["server"][PRELOAD[last]]
    assert held == [], f"importing {PRELOAD[:last + 1]} imported {held}"


@pytest.mark.parametrize(("args", "says"), REFUSALS, ids=[" ".join(a) for a, _ in REFUSALS])
def test_a_refused_request_imports_no_heavy_library(probed, args, says):
    """Validating a request (the command line, the front door make_request, the study's models)
    is refused before pvlib, pandas, matplotlib, scipy, numba or numpy load."""
    done = probed[tuple(args), ()]
    assert done.code == 2 and says in done.stderr, done.stderr
    assert done.imported == [], f"foldopt {' '.join(args)} imported {done.imported}"


@pytest.mark.parametrize("args", HELP)
def test_help_imports_no_heavy_library(probed, args):
    done = probed[tuple(args), ()]
    assert done.code == 0 and any("Usage" in line for line in done.lines), done.stderr
    assert done.imported == []


def _answered(probed) -> tuple[Done, Path]:
    """``foldopt run``'s child (on one core, the answer's unneeded heavy modules watched) and its
    folder."""
    return probed[("run", "--out", str(probed["folder"])), ()], probed["folder"]


def test_the_answer_prints_before_matplotlib_loads(probed):
    """``foldopt run`` drawing its figures itself prints its answer, then loads matplotlib and
    draws them."""
    done, out = _answered(probed)
    assert done.code == 0, done.stderr
    assert MARKER.format("matplotlib") in done.lines and "matplotlib" in done.imported
    before = done.lines[: done.lines.index(MARKER.format("matplotlib"))]
    assert before and before[0].startswith("shin2015: ")
    assert any("best fold angle" in line for line in before)
    assert (out / "power_curves.png").is_file()


def test_the_embedded_studys_answer_imports_numpy_alone(probed):
    """``foldopt run`` computes and prints the embedded study's whole answer with numpy alone;
    writing its folder then adds pandas (its tables) and matplotlib (its figures, which it draws
    itself on one core), nothing else heavy."""
    done, out = _answered(probed)
    assert done.code == 0, done.stderr
    markers = [line for line in done.lines if line.startswith("<<imported")]
    assert sorted(markers) == [MARKER.format("matplotlib"), MARKER.format("pandas")]
    answer = done.lines[: done.lines.index(markers[0])]
    assert answer[0].startswith("shin2015: ") and "a flat panel would need" in answer[-1]
    assert done.imported == ["matplotlib", "numpy", "pandas"]
    assert (out / "summary.csv").is_file()


def test_the_apis_run_of_the_embedded_study_imports_numpy_alone_until_a_table_is_asked(probed):
    """``foldopt.run()`` and its answer, as a notebook asks for them: numpy alone; the result's
    and the answer's tables are DataFrames when asked for, and pandas loads then."""
    done = probed[API_RUN, ()]
    assert done.code == 0, done.stderr
    answered, imported, _, tables, zone, _ = json.loads(done.lines[-1])
    assert answered and imported == ["numpy"]
    assert tables == ["DataFrame"] * 7 and zone == "America/Los_Angeles"


def test_a_run_imports_only_what_it_uses(probed):
    """A day's study (what ``foldopt run`` computes before it prints its answer) loads none of
    :data:`UNUSED`; pvlib loads the weather readers and the spectral factors where first used
    (foldopt/__init__.py), the readers with ``requests``."""
    done = probed[API_RUN, ()]
    assert done.code == 0, done.stderr
    _, _, unused, _, _, lazy = json.loads(done.lines[-1])
    assert unused == [] and lazy == [True, True, True], done.stderr


def test_an_in_process_caller_keeps_its_collector():
    """A command run in the caller's process (a test's CliRunner, as a notebook would) freezes
    nothing and leaves the collector as it found it, on or off."""
    import gc

    from typer.testing import CliRunner

    from foldopt.cli.app import app

    before = gc.get_freeze_count()
    for enabled in (True, False):
        (gc.enable if enabled else gc.disable)()
        try:
            done = CliRunner().invoke(app, ["run", "--set", "p_load=abc"])
            assert done.exit_code == 2 and gc.isenabled() is enabled
        finally:
            gc.enable()
    assert gc.get_freeze_count() == before


def test_the_probe_sees_an_import(probed):
    """The checks can fail: a module imported before the command (as a command that imported it
    would) is reported, and its marker comes before the answer."""
    assert "numpy" in probed[("sweep", "angle", "--lat", "95"), ("numpy",)].imported
    done = probed[("--version",), ("matplotlib",)]
    assert done.code == 0 and done.lines[0] == MARKER.format("matplotlib")
    assert done.lines[1].startswith("foldopt ")
