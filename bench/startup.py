"""Start-up time of the command line: what a user waits before anything is computed, the first
time (an empty compile cache) and after (a warm one), and which compiled functions take the first
time's wait.

    python bench/startup.py                         # 7 warm runs and 2 cold runs of each
    python bench/startup.py --runs 3 --cold-runs 1
    python bench/startup.py --only "run (cold)"     # the rows whose name holds this; repeatable
    python bench/startup.py --before /tmp/before    # side by side with another tree
    python bench/startup.py --events run,optimize   # compile events of these commands [run]

Each command runs in a fresh process (``python -m foldopt.cli.app ...``, and the installed
``foldopt`` script where there is one), so a figure includes the interpreter's own start; the
minimum and the median of the runs are printed. The rows, measured side by side in one run:

- ``python -c pass``, the interpreter alone; ``foldopt --help``, ``foldopt sweep angle --help``
  (its options built from the name registry), three refusals (``sweep angle --lat 95``,
  ``run --set p_load=abc`` and ``map --lat 95 --lon 0``: refused before pvlib, pandas, scipy,
  numba, numpy or matplotlib are imported), each warm;
- ``foldopt run`` printing its answer (warm, not ``-q``): the seconds to its first answer line on
  stdout (printed before the figures are drawn) and to its end;
- ``import foldopt`` and the studies ``foldopt run`` (the embedded study: the day, its five
  figures, report.html), ``foldopt sweep angle``, ``foldopt sweep angle --weather`` (the TMY3
  file of configs/weather), ``foldopt optimize`` (fold angle, tilt and azimuth on coarse grids)
  and ``foldopt map`` (two sites, one Dask worker), each written to a temporary folder:

  - *warm*: numba's cache (``NUMBA_CACHE_DIR``) and foldopt's (``FOLDOPT_CACHE_DIR``: the
    electrical tables) filled by one run of each before the timed ones;
  - *cold*: both caches new, empty folders for each run, as on the first run after an install:
    every ``cache=True`` function is compiled (numba then reads and writes nothing next to the
    sources), and the files each run left in the caches are printed;

- *compile events* (``--events``): the command run once more with empty caches, in a process
  that listens to numba's ``numba:compile`` events: each compiled function (module.qualname),
  its type signature and its compile seconds, longest first, with the seconds of the compiles
  nested in it (callees typed while their caller compiles) also counted apart ("own"). ``map``
  compiles in its Dask worker, out of the listener's sight.

With ``--before PATH`` (another tree, e.g. ``git worktree add /tmp/before <rev>``), every row
runs for both trees in turn, the order alternating, and the figures stand in before / after
columns. Each tree's processes run in the tree with ``PYTHONPATH`` set to it (the foldopt each
imports is printed), and with caches of their own. This machine's environment sets
``PYTHONDONTWRITEBYTECODE``; it is dropped for the children, whose modules are then read
from their bytecode as after an install, rather than compiled by every process.

The targets on the 2-core machine: the first ``foldopt run`` after an install (an empty compile
cache) 10 s, a warm ``foldopt run`` 1.5 s, ``foldopt --help`` 0.3 s (issue 40); a warm
``foldopt run``'s first answer line 0.5 s and its whole command 1.5 s, a refusal 0.3 s (issue 49).
The other rows have none. The last table is issue 49's startup rows (the answer's first line, the
whole command, the refusals), the minimum of the runs against each target.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
WEATHER = ROOT / "configs" / "weather" / "723170TYA.CSV"
CLI = [sys.executable, "-m", "foldopt.cli.app"]

#: Compute commands, by key (--events): their row name and arguments, each run with --out.
STUDIES = {
    "run": ("foldopt run", ["run"]),
    "sweep": ("foldopt sweep angle", ["sweep", "angle"]),
    "sweep-weather": ("foldopt sweep angle --weather TMY3",
                      ["sweep", "angle", "--weather", str(WEATHER)]),
    "optimize": ("foldopt optimize (coarse grids)",
                 ["optimize", "--tilt-range", "0:90:5", "--azimuth-range", "-90:90:10"]),
    "map": ("foldopt map (2 sites, 1 worker)",
            ["map", "--lat", "35,40", "--lon", "-80", "--workers", "1"]),
}
#: The row of ``foldopt run`` printing its answer: its first line and its end are timed.
ANSWER = "foldopt run, answer printed (warm)"
#: The refusals' rows.
REFUSALS = {
    "refusal: sweep angle --lat 95": ["sweep", "angle", "--lat", "95"],
    "refusal: run --set p_load=abc": ["run", "--set", "p_load=abc"],
    "refusal: map --lat 95 --lon 0": ["map", "--lat", "95", "--lon", "0"],
}
#: Row name: (seconds, where the target is set).
TARGETS = {
    "foldopt run (cold)": (10.0, "issue 40"),
    "foldopt run (warm)": (1.5, "issue 40"),
    "foldopt --help": (0.3, "issue 40"),
    "foldopt --help (the script)": (0.3, "issue 40"),
    "foldopt sweep angle --help": (0.3, "issue 40"),
    ANSWER: (1.5, "issue 49"),
    f"{ANSWER}: first answer line": (0.5, "issue 49"),
    **{name: (0.3, "issue 49") for name in REFUSALS},
}
#: Issue 49's startup rows: (its words, the row name timed).
ISSUE_49 = (
    ("warm foldopt run: first answer line", f"{ANSWER}: first answer line"),
    ("warm foldopt run: whole command", ANSWER),
    *((f"a refusal ({name.split(': ')[1]})", name) for name in REFUSALS),
)

#: Run in the compile-events process: ``python -c EVENTS <json out> <foldopt arguments...>``.
EVENTS = r'''
import json, runpy, sys, time
from numba.core import event

class Compiles(event.Listener):
    """Each compile's seconds, and those of the compiles nested in it."""
    def __init__(self):
        self.open, self.done = [], []
    def on_start(self, ev):
        function = getattr(ev.data["dispatcher"], "py_func", None)
        self.open.append([time.perf_counter(), 0.0, getattr(function, "__qualname__", "?")])
    def on_end(self, ev):
        start, nested, _ = self.open.pop()
        seconds = time.perf_counter() - start
        if self.open:
            self.open[-1][1] += seconds
        dispatcher, args = ev.data["dispatcher"], tuple(ev.data["args"])
        function = getattr(dispatcher, "py_func", None)
        overload = dispatcher.overloads.get(args)
        self.done.append({
            "function": (f"{function.__module__}.{function.__qualname__}" if function
                         else repr(dispatcher)),
            "signature": "(" + ", ".join(map(str, overload.signature.args if overload else args))
                         + ") -> " + str(overload.signature.return_type if overload else "?"),
            "within": self.open[-1][2] if self.open else "",
            "seconds": seconds, "own": seconds - nested, "depth": len(self.open)})

compiles = Compiles()
event.register("numba:compile", compiles)
out, sys.argv = sys.argv[1], ["foldopt", *sys.argv[2:]]
start, code = time.perf_counter(), 0
try:
    runpy.run_module("foldopt.cli.app", run_name="__main__", alter_sys=True)
except SystemExit as exit:
    code = exit.code
with open(out, "w") as file:
    json.dump({"wall": time.perf_counter() - start, "code": code, "compiles": compiles.done}, file)
'''


@dataclass
class Row:
    """A measured command: its name, its command line (``{out}`` for the results folder), the
    caches it runs with (warm or cold) and its expected exit code."""

    name: str
    command: list[str]
    cache: str = "warm"
    expect: int = 0
    events: bool = False
    #: Also time its first line on stdout (the row :attr:`first_line_name`).
    first_line: bool = False

    @property
    def first_line_name(self) -> str:
        return f"{self.name}: first answer line"

    def names(self) -> list[str]:
        """The rows its runs time: its own, and its first line's."""
        return [self.name, *([self.first_line_name] * self.first_line)]


@dataclass
class Tree:
    """A source tree whose foldopt the rows run, with its own caches and results folders."""

    label: str
    path: Path
    work: Path
    times: dict = field(default_factory=dict)
    left: dict = field(default_factory=dict)  # row name: what the first cold run left in the caches
    first_line: float = 0.0  # seconds to the last run's first line on stdout
    compiles: dict = field(default_factory=dict)  # events row name: the child's JSON

    def environment(self, caches: Path) -> dict:
        env = {name: value for name, value in os.environ.items()
               if name != "PYTHONDONTWRITEBYTECODE"}
        env.update(PYTHONPATH=str(self.path), COLUMNS="100", NUMBA_CACHE_DIR=str(caches / "numba"),
                   FOLDOPT_CACHE_DIR=str(caches / "foldopt"))
        return env

    def run(self, row: Row, count: int) -> float:
        """Run ``row`` once in this tree; its seconds (or the compile events' file); those to its
        first line on stdout are kept in :attr:`first_line`."""
        cold = row.cache == "cold"
        caches = Path(tempfile.mkdtemp(dir=self.work, prefix="cold-")) if cold else self.work / "warm"
        for folder in ("numba", "foldopt"):
            (caches / folder).mkdir(parents=True, exist_ok=True)
        out = self.work / "out" / row.name.split(" (")[0].replace(" ", "-")
        command = [part.replace("{out}", str(out)) for part in row.command]
        if row.events:
            command = [sys.executable, "-c", EVENTS, str(caches / "events.json"), *command[3:]]
        start = time.perf_counter()
        with subprocess.Popen(command, cwd=self.path, env=self.environment(caches),
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as done:
            first = done.stdout.readline()
            first_seconds = time.perf_counter() - start
            _, stderr = done.communicate()
        seconds = time.perf_counter() - start
        if done.returncode != row.expect:
            sys.exit(f"{row.name} [{self.label}]: exit code {done.returncode}, expected "
                     f"{row.expect}:\n{stderr.strip()[-2000:]}")
        if row.first_line and not first:
            sys.exit(f"{row.name} [{self.label}]: printed nothing on stdout")
        self.first_line = first_seconds
        if row.events:
            self.compiles[row.name] = json.loads((caches / "events.json").read_text())
        if cold:
            if count == 0:
                self.left[row.name] = _contents(caches)
            shutil.rmtree(caches, ignore_errors=True)
        return seconds


def _contents(caches: Path) -> str:
    """What a cold run left in numba's and foldopt's cache folders."""
    numba = [path for path in (caches / "numba").rglob("*") if path.is_file()]
    size = sum(path.stat().st_size for path in numba) / 1e6
    index = sum(path.suffix == ".nbi" for path in numba)
    ours = [path for path in (caches / "foldopt").rglob("*") if path.is_file()]
    return (f"numba: {index} index files, {len(numba) - index} compiled ({size:.1f} MB); "
            f"foldopt: {len(ours)} files")


def rows(events: list[str], script: str | None) -> list[Row]:
    """Every row, in the order measured and printed."""
    found = [Row("python -c pass", [sys.executable, "-c", "pass"]),
             Row("foldopt --help", [*CLI, "--help"]),
             Row("foldopt sweep angle --help", [*CLI, "sweep", "angle", "--help"]),
             *(Row(name, [*CLI, *arguments], expect=2) for name, arguments in REFUSALS.items()),
             Row(ANSWER, [*CLI, "run", "--out", "{out}", "--overwrite"], first_line=True)]
    if script:  # the installed script, with its entry-point lookup
        found.append(Row("foldopt --help (the script)", [script, "--help"]))
    for cache in ("warm", "cold"):
        found.append(Row(f"import foldopt ({cache})", [sys.executable, "-c", "import foldopt"], cache))
        for name, arguments in STUDIES.values():
            found.append(Row(f"{name} ({cache})", [*CLI, *arguments, "--out", "{out}",
                                                   "--overwrite", "-q"], cache))
    for key in events:
        name, arguments = STUDIES[key]
        found.append(Row(f"compile events: {name}", [*CLI, *arguments, "--out", "{out}",
                                                     "--overwrite", "-q"], "cold", events=True))
    return found


def describe(tree: Tree) -> str:
    """The tree, its revision and the foldopt its processes import (checked to be its own)."""
    done = subprocess.run([sys.executable, "-c", "import foldopt; print(foldopt.__file__)"],
                          cwd=tree.path, env=tree.environment(tree.work / "warm"),
                          capture_output=True, text=True, check=True)
    imported = Path(done.stdout.strip())
    if not imported.is_relative_to(tree.path):
        sys.exit(f"{tree.label}: the children import {imported}, not the tree {tree.path}")
    git = ["git", "-C", str(tree.path)]
    revision = subprocess.run([*git, "log", "-1", "--format=%h %cI %s"], capture_output=True,
                              text=True).stdout.strip()[:90]
    changed = subprocess.run([*git, "status", "--porcelain", "--", "foldopt"], capture_output=True,
                             text=True).stdout.split("\n")
    changed = [line for line in changed if line.strip()]
    return (f"{tree.label}: {tree.path} at {revision or '(not git)'}"
            + (f", {len(changed)} files changed in foldopt/ (not committed)" if changed else "")
            + f"\n  imports {imported}")


def verdict(name: str, values: list[float]) -> str:
    if name not in TARGETS or not values:
        return ""
    limit, _ = TARGETS[name]
    return "ok" if min(values) <= limit else "MISSED"


def report(trees: list[Tree], measured: list[Row], runs: int, cold_runs: int, load: str) -> None:
    print(f"\nfoldopt start-up, {runs} warm / {cold_runs} cold runs each, {os.cpu_count()} cores, "
          f"python {sys.version.split()[0]}, numba {_numba()}, {time.strftime('%Y-%m-%d %H:%M %Z')}")
    print(f"load average (1, 5, 15 min): {load} at the start, "
          f"{', '.join(f'{value:.2f}' for value in os.getloadavg())} at the end")
    names = [name for row in measured if not row.events for name in row.names()]
    if names:
        heads = "".join(f" {tree.label + ' min':>12s} {'median':>7s}" for tree in trees)
        print(f"\n{'command [s]':52s}{heads}  target")
    for name in names:
        print(f"{name:52s}{_cells(trees, name)}  {_target(trees, name)}")
    issue = [(words, name) for words, name in ISSUE_49 if name in names]
    if issue:
        heads = "".join(f" {tree.label + ' min':>12s} {'':7s}" for tree in trees)
        print(f"\n{'issue 49, startup [s]':52s}{heads}  target")
        for words, name in issue:
            cells = "".join(f" {min(tree.times[name]):12.3f} {'':7s}" for tree in trees)
            print(f"{words:52s}{cells}  {_target(trees, name)}")
    for tree in trees:
        if tree.left:
            print(f"\nleft in the empty caches by a cold run [{tree.label}]:")
            for name, left in tree.left.items():
                print(f"  {name:40s} {left}")
    for row in (row for row in measured if row.events):
        for tree in trees:
            compiles(row.name, tree)


def _cells(trees: list[Tree], name: str) -> str:
    return "".join(f" {min(tree.times[name]):12.3f} {statistics.median(tree.times[name]):7.3f}"
                   for tree in trees)


def _target(trees: list[Tree], name: str) -> str:
    """``<= limit s (source) ok`` (each tree's verdict), or nothing for a row without a target."""
    if name not in TARGETS:
        return ""
    limit, source = TARGETS[name]
    verdicts = " -> ".join(verdict(name, tree.times[name]) for tree in trees)
    return f"<= {limit:g} s ({source}) {verdicts}"


def compiles(name: str, tree: Tree) -> None:
    """The compile events' table of one command in one tree: each function compiled outside
    numba's own library, longest first, and numba's library (the overloads of builtins and NumPy
    functions typed within them) summed in one line."""
    found = tree.compiles[name]
    events = found["compiles"]
    outermost = sum(event["seconds"] for event in events if event["depth"] == 0)
    library = [event for event in events if event["function"].startswith("numba.")]
    print(f"\n{name} [{tree.label}], empty caches: {len(events)} compiles, {outermost:.1f} s "
          f"of a {found['wall']:.1f} s run (in-process, from the imports on)")
    print(f"  {'seconds':>7s} {'own':>6s}  {'function':36s} {'within':12s} signature")
    for event in sorted((event for event in events if event not in library),
                        key=lambda event: -event["seconds"]):
        print(f"  {event['seconds']:7.2f} {event['own']:6.2f}  {event['function']:36s} "
              f"{event['within'] or '-':12s} {event['signature']}")
    if library:
        print(f"  {'':7s} {sum(event['own'] for event in library):6.2f}  numba's library: "
              f"{len(library)} compiles of {len({event['function'] for event in library})} overloads"
              " (str, repr, min, max, np.empty ...)")
    print(f"  {outermost:7.2f} {sum(event['own'] for event in events):6.2f}  total")


def _numba() -> str:
    try:
        from importlib.metadata import version

        return version("numba")
    except Exception:  # noqa: BLE001 - only a label
        return "?"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7, help="warm runs of each row [7]")
    parser.add_argument("--cold-runs", type=int, default=2,
                        help="cold runs of each row (each compiles for about a minute) [2]")
    parser.add_argument("--only", action="append", default=[], metavar="NAME",
                        help="only the rows whose name holds NAME (any case); repeatable")
    parser.add_argument("--before", type=Path, metavar="PATH",
                        help="another tree measured side by side (before / after columns)")
    parser.add_argument("--events", default="run", metavar="KEYS",
                        help=f"commands whose compile events are listed: any of {', '.join(STUDIES)}"
                             " joined by commas, or none [run]")
    options = parser.parse_args()
    events = [] if options.events in ("", "none") else options.events.split(",")
    if unknown := [key for key in events if key not in STUDIES]:
        parser.error(f"--events: unknown {', '.join(unknown)}; any of {', '.join(STUDIES)}")
    if options.before and not (options.before / "foldopt" / "__init__.py").is_file():
        parser.error(f"--before: {options.before} holds no foldopt package")
    measured = [row for row in rows(events, shutil.which("foldopt"))
                if not options.only or any(part.lower() in row.name.lower() for part in options.only)]
    if not measured:
        parser.error(f"--only: no row's name holds {' or '.join(options.only)}")
    load = ", ".join(f"{value:.2f}" for value in os.getloadavg())
    with tempfile.TemporaryDirectory(prefix="foldopt-startup-") as work:
        paths = [("before", options.before.resolve()), ("after", ROOT)] if options.before else \
            [("this tree", ROOT)]
        trees = [Tree(label, path, Path(work) / str(number)) for number, (label, path) in enumerate(paths)]
        for tree in trees:
            tree.work.mkdir()
            print(describe(tree))
            tree.times = {name: [] for row in measured for name in row.names()}
        warm = [row for row in measured if row.cache == "warm"]
        cold = [row for row in measured if row.cache == "cold" and not row.events]
        for tree in trees:  # fills the warm caches (compiles once) and the bytecode
            for row in warm:
                tree.run(row, 0)
        # interleaved: a noisy moment hits every row alike; the trees' order alternates
        for rounds, group in ((options.runs, warm), (options.cold_runs, cold)):
            for count in range(rounds):
                for row in group:
                    for tree in (trees if count % 2 == 0 else trees[::-1]):
                        tree.times[row.name].append(tree.run(row, count))
                        if row.first_line:
                            tree.times[row.first_line_name].append(tree.first_line)
                        if row.cache == "cold":
                            print(f"  {row.name} [{tree.label}]: {tree.times[row.name][-1]:.1f} s",
                                  file=sys.stderr)
        for row in (row for row in measured if row.events):
            for tree in trees:
                tree.run(row, 0)
        report(trees, measured, options.runs, options.cold_runs, load)


if __name__ == "__main__":
    main()
