"""foldopt benchmark suite: wall time and peak memory of the workloads of issue 7.

    python bench/run.py            # every workload, printed
    python bench/run.py --write    # ... and written to results/bench/
    python bench/run.py --only W1 --days 30

- W1: one site (Shin et al.'s), 365 days x 1-minute interval-centred steps, fold angles 1..180 deg
  at 1 deg, single-diode A-300 sub-panels with switching; t_solar and energy for every day x angle.
- W2: a design map, 90 latitudes x 24 days x 180 angles x 50 loads (same physics); t_solar for
  every case x angle.
- W3: the same physics as W1 through a straightforward pvlib-per-point pipeline (pvlib solar
  position, aoi, single-diode parameters and the parallel curve through i_from_v, step by step and
  angle by angle) on a slice of W1, scaled per point, so that the speed-up is a ratio measured in
  one run.

Each workload runs in its own process, so its peak memory (max RSS) is its own. W1 and W2 use
``--workers`` processes (default: every core), forked after the electrical tables are built so
that they share them; the wall time includes building the tables.
"""

from __future__ import annotations

import os

# One BLAS thread a process: the matrix products here are small, and BLAS threads in several
# worker processes would fight over the cores (measured: 2 workers slower than 1 without this).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import datetime as dt
import json  # noqa: E402
import platform
import resource  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
TARGETS = {"W1": "<= 2 s", "W2": "<= 10 s", "W3": "W1 >= 100x faster per point", "memory": "<= 2 GiB"}


def _study():
    sys.path.insert(0, str(ROOT))
    from foldopt.config import default_study_path, load_study

    return load_study(default_study_path()).variant(
        pv_model="single-diode", connection="switching", mode="exact", geometry="hinge"
    )


_SHARED: dict = {}  # inherited by forked workers: the study, the tables, the grids


def _w1_chunk(dates):
    from foldopt.metrics import energy, t_solar
    from foldopt.study import Day

    base, tables, angles = _SHARED["base"], _SHARED["tables"], _SHARED["angles"]
    hours, wh = [], []
    for date in dates:
        day = Day(base.variant(date=date), tables)
        power = day.combined_power(angles)
        hours.append(t_solar(power, base.p_load, day.step_hours))
        wh.append(energy(power, day.step_hours))
    return np.array(hours), np.array(wh)


def _w2_chunk(cases):
    from foldopt.metrics import t_solar_many_loads
    from foldopt.study import Day

    base, tables, angles, loads = _SHARED["base"], _SHARED["tables"], _SHARED["angles"], _SHARED["loads"]
    best = []
    for lat, date in cases:
        study = base.variant(date=date, site={"latitude": float(lat), "longitude": 0.0, "timezone": "UTC"})
        day = Day(study, tables)
        best.append(t_solar_many_loads(day.combined_power(angles), loads, day.step_hours).max(axis=0))
    return np.array(best)


def _parallel(function, items, workers):
    """Map ``function`` over ``workers`` contiguous chunks of ``items`` in forked processes."""
    import multiprocessing

    chunks = [list(chunk) for chunk in np.array_split(np.array(items, dtype=object), workers) if len(chunk)]
    if workers == 1:
        return [function(chunks[0])]
    with multiprocessing.get_context("fork").Pool(workers) as pool:
        return pool.map(function, chunks)


def _prepare(angles, loads=None):
    from foldopt.study import Day

    base = _study()
    tables: dict = {}
    Day(base, tables).combined_power(angles[:1])  # build the electrical tables once, before forking
    _SHARED.update(base=base, tables=tables, angles=angles, loads=loads)


def workload_w1(days: int, workers: int) -> dict:
    angles = np.arange(1.0, 181.0)
    dates = [dt.date(2014, 1, 1) + dt.timedelta(days=int(d)) for d in np.linspace(0, 364, days)]
    start = time.perf_counter()
    _prepare(angles)
    parts = _parallel(_w1_chunk, dates, workers)
    seconds = time.perf_counter() - start
    hours = np.concatenate([p[0] for p in parts])
    wh = np.concatenate([p[1] for p in parts])
    return {"seconds": seconds, "points": days * 1440 * angles.size, "days": days, "workers": workers,
            "mean_best_t_solar_h": float(hours.max(axis=1).mean()), "mean_energy_wh": float(wh.mean())}


def workload_w2(days_per_latitude: int, latitudes: int, workers: int) -> dict:
    angles = np.arange(1.0, 181.0)
    loads = np.linspace(0.2, 10.0, 50)
    lats = np.linspace(-89.0, 89.0, latitudes)
    dates = [dt.date(2014, m, d) for m in range(1, 13) for d in (1, 15)][:days_per_latitude]
    cases = [(lat, date) for lat in lats for date in dates]
    start = time.perf_counter()
    _prepare(angles, loads)
    best = np.concatenate(_parallel(_w2_chunk, cases, workers))
    seconds = time.perf_counter() - start
    return {"seconds": seconds, "points": len(cases) * angles.size * loads.size, "workers": workers,
            "cases": len(cases) * loads.size, "mean_best_t_solar_h": float(best.mean())}


def workload_w3(steps: int, angles_count: int) -> dict:
    """The straightforward pipeline: every step and fold angle through pvlib calls of its own."""
    import pandas as pd
    import pvlib

    sys.path.insert(0, str(ROOT))
    from foldopt.atmosphere import clear_sky_dni
    from foldopt.geometry import subpanel_orientation
    from foldopt.pvmodel import A300_CELL

    base = _study()
    site, panel = base.site, base.panel
    unit = A300_CELL
    cells = panel.area / 2 / unit.area
    times = pd.date_range("2014-06-21 06:00:30", periods=steps, freq="min", tz=site.timezone)
    angles = np.linspace(1.0, 180.0, angles_count)
    start = time.perf_counter()
    checksum = 0.0
    for when in times:
        sun = pvlib.solarposition.get_solarposition(pd.DatetimeIndex([when]), site.latitude, site.longitude)
        zenith, azimuth = float(sun["apparent_zenith"].iloc[0]), float(sun["azimuth"].iloc[0])
        dni = float(clear_sky_dni(np.array([zenith]))[0])
        for angle in angles:
            sides = subpanel_orientation(angle, panel.tilt or 34.05, panel.azimuth or 180.0, "hinge")
            params = []
            for side in ("east", "west"):
                aoi = pvlib.irradiance.aoi(float(sides[f"tilt_{side}"]), float(sides[f"azimuth_{side}"]), zenith, azimuth)
                poa = np.array([max(dni * np.cos(np.radians(aoi)), 0.0)])
                temp = pvlib.temperature.sapm_cell(poa, base.temp_air, base.wind_speed, -3.56, -0.075, 3)
                il, io, rs, rsh, nv = pvlib.pvsystem.calcparams_desoto(
                    poa, temp, unit.alpha_sc, unit.a_ref, unit.I_L_ref, unit.I_o_ref, unit.R_sh_ref, unit.R_s)
                params.append((il, io, rs * cells, rsh * cells, nv * cells))
                pvlib.pvsystem.singlediode(*params[-1])
            voltage = np.linspace(0, 1.2 * cells * 0.7, 200)
            current = sum(np.nan_to_num(np.clip(pvlib.pvsystem.i_from_v(voltage, *p), 0, None)) for p in params)
            checksum += float(np.nanmax(voltage * current))
    seconds = time.perf_counter() - start
    return {"seconds": seconds, "points": steps * angles_count, "checksum": checksum}


def run_one(name: str, args) -> dict:
    result = {"W1": lambda: workload_w1(args.days, args.workers),
              "W2": lambda: workload_w2(args.w2_days, args.w2_latitudes, args.workers),
              "W3": lambda: workload_w3(args.w3_steps, args.w3_angles)}[name]()
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    result["peak_mib"] = max(own, children) / 1024  # the largest single process
    return result


def main():
    parser = argparse.ArgumentParser(description="foldopt benchmarks")
    parser.add_argument("--only", default="W1,W2,W3")
    parser.add_argument("--days", type=int, default=365, help="W1 days")
    parser.add_argument("--w2-days", type=int, default=24)
    parser.add_argument("--w2-latitudes", type=int, default=90)
    parser.add_argument("--w3-steps", type=int, default=30)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1, help="processes for W1 and W2")
    parser.add_argument("--w3-angles", type=int, default=4)
    parser.add_argument("--write", action="store_true", help="write results/bench/bench.md and bench.json")
    parser.add_argument("--workload", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.workload:
        print(json.dumps(run_one(args.workload, args)))
        return
    results = {}
    for name in args.only.split(","):
        command = [sys.executable, __file__, "--workload", name] + sys.argv[1:]
        done = subprocess.run(command, capture_output=True, text=True, check=True)
        results[name] = json.loads(done.stdout.strip().splitlines()[-1])
    lines = [f"machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
             f"{dt.date.today().isoformat()}", "",
             "| workload | points | wall time | per point | peak memory | target |", "|---|---|---|---|---|---|"]
    for name, r in results.items():
        lines.append(f"| {name} | {r['points']:,} | {r['seconds']:.2f} s | {r['seconds'] / r['points'] * 1e9:.1f} ns "
                     f"| {r['peak_mib']:.0f} MiB | {TARGETS[name]} |")
    if "W1" in results and "W3" in results:
        ratio = (results["W3"]["seconds"] / results["W3"]["points"]) / (results["W1"]["seconds"] / results["W1"]["points"])
        lines += ["", f"W1 against W3 per point, measured in this run: {ratio:,.0f}x faster"]
        scaled = results["W3"]["seconds"] / results["W3"]["points"] * results["W1"]["points"]
        lines.append(f"W3 scaled to W1's {results['W1']['points']:,} points: {scaled / 3600:,.1f} h")
    text = "\n".join(lines)
    print(text)
    if args.write:
        folder = ROOT / "results" / "bench"
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "bench.md").write_text(text + "\n")
        (folder / "bench.json").write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
