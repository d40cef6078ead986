"""Start-up time of the command line: what a user waits before anything is computed.

    python bench/startup.py             # 7 runs of each, the minimum and the median printed
    python bench/startup.py --runs 15

Each command runs in a fresh process (``python -m foldopt.cli.app ...``, and the installed ``foldopt``
script where there is one), so the figure includes the interpreter's own start. Measured side by side in one run:

- ``foldopt --help``;
- ``foldopt sweep angle --help`` (the sweep options, built from the name registry);
- a validation error (``foldopt sweep angle --lat 95``): the study is checked before pvlib,
  pandas or matplotlib are imported;
- the embedded study, warm (``foldopt run --out <tmp> --overwrite -q``, after one run that
  compiles the kernel and fills the caches): imports, the day, its five figures and report.html;
- a bare ``python -c pass`` for the interpreter alone.

The targets on the 2-core machine: 0.5 s for the help and the error (issue 13), 1.5 s for the
embedded run (issue 23).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

COMMANDS = {
    "python -c pass": [sys.executable, "-c", "pass"],
    "foldopt --help": [sys.executable, "-m", "foldopt.cli.app", "--help"],
    "foldopt sweep angle --help": [sys.executable, "-m", "foldopt.cli.app", "sweep", "angle", "--help"],
    "validation error (--lat 95)": [sys.executable, "-m", "foldopt.cli.app", "sweep", "angle", "--lat", "95"],
}
if shutil.which("foldopt"):  # the installed script, with its entry-point lookup
    COMMANDS["foldopt --help (the script)"] = [shutil.which("foldopt"), "--help"]
RUN = "foldopt run (embedded, warm)"
COMMANDS[RUN] = [sys.executable, "-m", "foldopt.cli.app", "run", "--out",
                 os.path.join(tempfile.mkdtemp(prefix="foldopt-startup-"), "run"), "--overwrite", "-q"]
TARGETS_S = {RUN: 1.5}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    runs = parser.parse_args().runs
    times: dict[str, list[float]] = {name: [] for name in COMMANDS}
    subprocess.run(COMMANDS[RUN], capture_output=True, check=True)  # compiles the kernel, fills the caches
    for _ in range(runs):  # interleaved: a noisy moment hits every command alike
        for name, command in COMMANDS.items():
            start = time.perf_counter()
            done = subprocess.run(command, capture_output=True, text=True, env={**os.environ, "COLUMNS": "100"})
            times[name].append(time.perf_counter() - start)
            if name.startswith("validation") and done.returncode != 2:
                sys.exit(f"{name}: exit code {done.returncode}, expected 2: {done.stderr.strip()}")
    print(f"foldopt start-up, {runs} runs each, {os.cpu_count()} cores, python {sys.version.split()[0]}")
    print(f"{'command':32s} {'min [s]':>8s} {'median [s]':>11s}  target")
    for name, values in times.items():
        limit = TARGETS_S.get(name, 0.5)
        target = "" if name.startswith("python") else (f"<= {limit} s " + ("ok" if min(values) <= limit else "MISSED"))
        print(f"{name:32s} {min(values):8.3f} {statistics.median(values):11.3f}  {target}")


if __name__ == "__main__":
    main()
