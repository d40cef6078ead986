"""A buffer over 19 real years in sequence (issue 50): the whole run of a study like
``configs/camera-winter.yaml`` (a 2 W camera at 45 N 8 E, a LiFePO4 buffer in the cold sized
for 24 h on every day of every year, and the cheapest panel and buffer) over an hourly series of
2005-2023, and where its time goes.

    python bench/years.py                 # 19 years, 3 runs
    python bench/years.py --years 2,19 --runs 5

The series is ASSEMBLED, not measured: PVGIS's recorded 2020-2021 ``seriescalc`` answer at 45 N
8 E (``tests/data/pvgis/seriescalc_45.000_8.000_2020_2021.json``) repeated to 2005-2023, each year
a copy of the recorded 2020 (a leap year) or 2021 (the others), restamped
(``bench/weather_years.py``'s :func:`write_series`). Real light, repeated: for timing only, not for
any physical claim (every year of it is one of two real years).

Each figure is the minimum of the runs, each in a fresh process with this tree on ``PYTHONPATH``,
after one run that fills numba's cache:

- *whole run*: ``foldopt run STUDY --out DIR`` as typed, its wall time and its CPU time (user and
  system, which the machine's other load moves less);
- *phases*, in one process after the imports, wall and CPU (all threads): the request (the file
  read, the days planned), the run (the panels' curves, the buffer at every fold angle, the
  designs' buffers and their sizing, the tables by year and month) and the results folder
  (tables, figures, report).

On a shared machine the wall times drift with the others' load; the CPU times much less.

The target (issue 50): 19 years at most 20 s the whole run, on 2 cores.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from weather_years import write_series  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: The whole run of 19 years [s] (issue 50).
TARGET_S = 20.0
#: The study: configs/camera-winter.yaml (its cold and costs too), its weather the series.
STUDY = (
    (ROOT / "configs" / "camera-winter.yaml")
    .read_text()
    .replace("{", "{{")
    .replace("}", "}}")
    .replace(
        "weather: {{path: ../tests/data/pvgis/seriescalc_45.000_8.000_2020_2021.json, ",
        "weather: {{path: {path}, ",
    )
)


def _environment() -> dict:
    return {**os.environ, "PYTHONPATH": str(ROOT)}


def whole_run(study: Path, out: Path) -> tuple[float, float]:
    """Wall and CPU seconds of ``foldopt run STUDY`` in a fresh process."""
    command = [sys.executable, "-m", "foldopt.cli.app", "run", str(study), "--out", str(out),
               "--overwrite", "-q"]  # fmt: skip
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, env=_environment(), check=False)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode:
        sys.exit(f"foldopt run {study.name} failed:\n{done.stderr}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def phases(study: str, out: str) -> dict:
    """Seconds of the request, the run and the folder, in this process (after the imports)."""
    import foldopt.api as api
    import foldopt.inputs.weather  # noqa: F401  (pvlib and pandas: outside the timing)
    from foldopt.studies.request import make_request

    found, done = {}, {}

    def timed(name, work):
        wall, cpu = time.perf_counter(), time.process_time()
        done[name] = work()
        found[name] = time.perf_counter() - wall
        found[f"{name}_cpu"] = time.process_time() - cpu

    timed("request", lambda: make_request("run", study))
    timed("run", lambda: api.run(request=done["request"]))
    timed("folder", lambda: api.write(done["run"], out, overwrite=True))
    years = done["run"].extras["storage_years"]
    found["days"] = int(years.loc[years["design"] == "flat", "days_n"].sum())
    return found


def measure(years: list[int], runs: int) -> dict:
    with tempfile.TemporaryDirectory() as temporary:
        folder = Path(temporary)
        studies = {}
        for n in years:
            path = write_series(n, folder)
            studies[n] = folder / f"study_{n}y.yaml"
            studies[n].write_text(STUDY.format(path=path))
        whole_run(studies[min(years)], folder / "warm")
        phases = ("request", "run", "folder")
        found = {
            n: {key: [] for key in ("wall", "cpu", *phases, *(f"{p}_cpu" for p in phases))}
            for n in years
        }
        for _ in range(runs):
            for n in years:
                wall, cpu = whole_run(studies[n], folder / f"run{n}")
                found[n]["wall"].append(wall)
                found[n]["cpu"].append(cpu)
                done = subprocess.run(
                    [sys.executable, __file__, "--phases", str(studies[n]), str(folder / "p")],
                    capture_output=True, text=True, env=_environment(), check=True,
                )  # fmt: skip
                timed = json.loads(done.stdout.strip().splitlines()[-1])
                found[n]["days"] = timed.pop("days")
                for key, value in timed.items():
                    found[n][key].append(value)
    return {n: {key: min(v) if isinstance(v, list) else v for key, v in f.items()}
            for n, f in found.items()}  # fmt: skip


def report(found: dict, runs: int) -> str:
    lines = [
        "a buffer over years in sequence: an ASSEMBLED hourly series, PVGIS's recorded 2020-2021 "
        "seriescalc answer at 45 N 8 E repeated to 2005-2023 (timing only)",
        f"minimum of {runs} runs, {time.strftime('%Y-%m-%d %H:%M')}, load "
        f"{os.getloadavg()[0]:.1f}, {os.cpu_count()} cores",
        "",
        "| years | days | whole run (wall) | whole run (CPU) | request | run | folder |",
        "|---|---|---|---|---|---|---|",
    ]
    for n, f in found.items():
        phases = " | ".join(
            f"{f[p]:.2f} s ({f[f'{p}_cpu']:.2f} s CPU)" for p in ("request", "run", "folder")
        )
        lines.append(f"| {n} | {f['days']:,} | {f['wall']:.2f} s | {f['cpu']:.2f} s | {phases} |")
    if 19 in found:
        lines.append(
            f"19 years, the whole run: {found[19]['wall']:.1f} s wall, {found[19]['cpu']:.1f} s "
            f"CPU (target <= {TARGET_S:g} s)"
        )
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description="a buffer over 19 years in sequence")
    parser.add_argument("--years", default="19", help="series lengths, comma-separated")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--phases", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.phases:
        print(json.dumps(phases(*args.phases)))
        return
    years = sorted({int(n) for n in args.years.split(",")})
    print(report(measure(years, args.runs), args.runs))


if __name__ == "__main__":
    main()
