"""Years of measured weather: the planning and the whole run of a series against its length.

    python bench/weather_years.py                   # 1, 2, 10 and 19 years, 3 runs each
    python bench/weather_years.py --years 1,10 --runs 5

The series are PVGIS hourly answers (``seriescalc`` JSON, weather format ``pvgis-hourly``) made
from the one recorded answer, 45 N, 8 E, 2020-2021 (``tests/data/pvgis/``, its README): N years
from 2005, each year a copy of the recorded 2020 (a leap year) or 2021 (the others), restamped.
Real light, repeated: for timing only, not for any physical claim. 19 years, 2005-2023, are
PVGIS-SARAH3's record: 6,939 days.

Each figure is the minimum of the runs, each in a fresh process with this tree on
``PYTHONPATH``:

- *planning*: :func:`foldopt.studies.request.make_request` of ``sweep angle --weather FILE
  --weather-format pvgis-hourly`` (the file read, its days known, the plan of its days validated),
  timed after the imports;
- *whole run*: ``foldopt sweep angle --weather FILE --weather-format pvgis-hourly --out DIR`` as
  typed, its wall time and its CPU time (user and system, which the machine's other load moves
  less), after one run that fills numba's cache.

The targets (issue 49): planning linear in the days, 10 years at most 12x one year; PVGIS's
19 years at most 20 s the whole run.
"""

from __future__ import annotations

import argparse
import calendar
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RECORDED = ROOT / "tests" / "data" / "pvgis" / "seriescalc_45.000_8.000_2020_2021.json"
FIRST_YEAR = 2005
FORMAT = ["--weather-format", "pvgis-hourly"]
#: Ratio of 10 years' planning to one year's, and 19 years' whole run [s] (issue 49).
TARGETS = {"ratio": 12.0, "whole_19": 20.0}


def write_series(years: int, folder: Path) -> Path:
    """A PVGIS hourly answer of ``years`` years from :data:`FIRST_YEAR`, made of the recorded
    answer's years (module docstring)."""
    answer = json.loads(RECORDED.read_text())
    recorded = {
        year: [r for r in answer["outputs"]["hourly"] if r["time"].startswith(str(year))]
        for year in (2020, 2021)
    }
    hourly = [
        {**record, "time": f"{year}{record['time'][4:]}"}
        for year in range(FIRST_YEAR, FIRST_YEAR + years)
        for record in recorded[2020 if calendar.isleap(year) else 2021]
    ]
    meteo = {**answer["inputs"]["meteo_data"], "year_min": FIRST_YEAR,
             "year_max": FIRST_YEAR + years - 1}
    path = folder / f"pvgis_hourly_{years}y.json"
    path.write_text(json.dumps({**answer, "inputs": {**answer["inputs"], "meteo_data": meteo},
                                "outputs": {"hourly": hourly}}))
    return path


def plan_seconds(path: str) -> dict:
    """The planning of one series, in this process: its seconds and the days planned."""
    from foldopt.studies.request import make_request
    import foldopt.inputs.weather  # noqa: F401  (pvlib and pandas: imported outside the timing)

    start = time.perf_counter()
    request = make_request("sweep angle", options={"weather": path, "weather_format": "pvgis-hourly"})
    seconds = time.perf_counter() - start
    return {"seconds": seconds, "days": len(dict(request.plan.axes)["date"])}


def _environment() -> dict:
    return {**os.environ, "PYTHONPATH": str(ROOT)}


def _planning(path: Path) -> dict:
    done = subprocess.run([sys.executable, __file__, "--plan", str(path)], capture_output=True,
                          text=True, env=_environment(), check=False)
    if done.returncode:
        sys.exit(f"planning {path.name} failed:\n{done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def _whole_run(path: Path, out: Path) -> tuple[float, float]:
    """Wall and CPU seconds of the command line's whole run of one series."""
    command = [sys.executable, "-m", "foldopt.cli.app", "sweep", "angle", "--weather", str(path),
               *FORMAT, "--out", str(out), "--overwrite", "-q"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, env=_environment(), check=False)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode:
        sys.exit(f"foldopt sweep angle --weather {path.name} failed:\n{done.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def measure(years: list[int], runs: int) -> dict:
    """Planning and whole-run seconds of each length, the runs of all lengths in turn."""
    with tempfile.TemporaryDirectory() as temporary:
        folder = Path(temporary)
        paths = {n: write_series(n, folder) for n in years}
        _whole_run(paths[min(years)], folder / "warm")  # numba's cache filled before any timing
        found = {n: {"planning": [], "wall": [], "cpu": []} for n in years}
        for _ in range(runs):
            for n in years:
                planned = _planning(paths[n])
                found[n]["days"] = planned["days"]
                found[n]["planning"].append(planned["seconds"])
                wall, cpu = _whole_run(paths[n], folder / f"run{n}")
                found[n]["wall"].append(wall)
                found[n]["cpu"].append(cpu)
    return {n: {"days": f["days"], **{key: min(f[key]) for key in ("planning", "wall", "cpu")}}
            for n, f in found.items()}


def report(found: dict, runs: int) -> str:
    lines = [f"measured PVGIS hourly series, minimum of {runs} runs, {time.strftime('%Y-%m-%d %H:%M')}, "
             f"load {os.getloadavg()[0]:.1f}", "",
             "| years | days | planning | whole run (wall) | whole run (CPU) |", "|---|---|---|---|---|"]
    for n, f in found.items():
        lines.append(f"| {n} | {f['days']:,} | {f['planning']:.2f} s | {f['wall']:.2f} s | {f['cpu']:.2f} s |")
    if 1 in found and 10 in found:
        one, ten = found[1], found[10]
        lines += ["", f"10 years / 1 year: planning {ten['planning'] / one['planning']:.1f}x "
                  f"(target <= {TARGETS['ratio']:g}x), whole run {ten['wall'] / one['wall']:.1f}x wall, "
                  f"{ten['cpu'] / one['cpu']:.1f}x CPU"]
    if 19 in found:
        lines.append(f"19 years ({found[19]['days']:,} days), the whole run: {found[19]['wall']:.1f} s wall, "
                     f"{found[19]['cpu']:.1f} s CPU (target <= {TARGETS['whole_19']:g} s)")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description="planning and running years of measured weather")
    parser.add_argument("--years", default="1,2,10,19", help="series lengths, comma-separated")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--plan", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.plan:
        print(json.dumps(plan_seconds(args.plan)))
        return
    years = sorted({int(n) for n in args.years.split(",")})
    print(report(measure(years, args.runs), args.runs))


if __name__ == "__main__":
    main()
