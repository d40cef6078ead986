"""Benchmark: the electrical fast path (tables, in the compiled kernel) against the exact per-step
I-V solve.

Workload: the paper's site, single-diode A-300 sub-panels with switching, fold angles 1..180 deg
at 1 deg, 1-minute interval-centred steps over a year (or ``--days`` of it). The fast path runs
the whole workload; the exact solve runs a slice (``--exact-days`` days x ``--exact-angles``
angles) and is scaled per point, so the speed-up is a ratio measured in one run. Then the tables'
accuracy: on the paper's day, 180 angles and loads from 10 % to 90 % of the peak, paper and exact
modes, single-diode and b-model, every connection's largest t_solar and energy difference from the
exact solve.

    python bench/electrical.py [--days 365] [--exact-days 1] [--exact-angles 12] [--mode exact]
"""

from __future__ import annotations

import argparse
import datetime as dt
import platform
import resource
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from foldopt.engine import evaluation as engine  # noqa: E402
from foldopt.inputs.study_file import default_study_path
from foldopt.api import load_study  # noqa: E402
from foldopt.engine.sky import build_sky  # noqa: E402
from foldopt.studies.engine_options import engine_options  # noqa: E402


def _t_solar(study, dates, angles):
    """t_solar [h] of every date x angle, (n_dates, n_angles), and the seconds it took."""
    start = time.perf_counter()
    options = engine_options(study)
    sky = build_sky(options.sky, [study.site] * len(dates), dates)
    panel = study.panel
    orientation = engine.fold_orientations(study.geometry, [panel.tilt] * len(dates), [panel.azimuth] * len(dates),
                                           angles)
    rows = engine.PanelRows(np.repeat(np.arange(len(dates)), angles.size), orientation.reshape(-1, 4))
    hours = engine.row_metrics(sky, rows=rows, loads=[study.p_load], electrical=options.electrical).t_solar
    return hours.reshape(len(dates), angles.size), time.perf_counter() - start


def accuracy():
    """Largest t_solar [s] and energy [%] differences of the tables from the exact solve."""
    from foldopt.engine.metrics import energy, t_solar
    from foldopt.studies.day import Day

    base = load_study(default_study_path())
    angles = np.arange(1.0, 181.0)
    worst_hours = worst_energy = 0.0
    for pv_model in ("single-diode", "b-model"):
        for mode, geometry in (("paper", "azimuth-split"), ("exact", "hinge")):
            study = base.variant(pv_model=pv_model, mode=mode, geometry=geometry, switch_series=True)
            fast, _ = Day(study).connections(angles)
            exact, _ = Day(study.variant(exact_electrical=True)).connections(angles)
            loads = np.linspace(0.1, 0.9, 9)[:, None, None] * exact["switching"].max()
            step = study.step_min / 60
            for name in fast:
                hours = np.abs(t_solar(fast[name][None], loads, step) - t_solar(exact[name][None], loads, step))
                worst_hours = max(worst_hours, float(hours.max()) * 3600)
                ratio = energy(fast[name], step) / energy(exact[name], step)
                worst_energy = max(worst_energy, float(np.abs(ratio - 1).max()) * 100)
    return worst_hours, worst_energy


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--days", type=int, default=365)
    parser.add_argument("--exact-days", type=int, default=1)
    parser.add_argument("--exact-angles", type=int, default=12)
    parser.add_argument("--mode", default="exact", choices=["paper", "exact"])
    args = parser.parse_args()

    base = load_study(default_study_path()).variant(
        pv_model="single-diode", connection="switching", mode=args.mode,
        geometry="azimuth-split" if args.mode == "paper" else "hinge",
    )
    angles = np.arange(1.0, 181.0)
    dates = [dt.date(2014, 1, 1) + dt.timedelta(days=int(d)) for d in np.linspace(0, 364, args.days)]
    _t_solar(base, dates[:1], angles[:2])  # kernel and tables loaded from their disk caches
    _, fast_seconds = _t_solar(base, dates, angles)
    fast_points = len(dates) * angles.size * 1440

    slice_angles = np.linspace(1.0, 180.0, args.exact_angles)
    exact_hours, exact_seconds = _t_solar(base.variant(exact_electrical=True), dates[: args.exact_days], slice_angles)
    fast_hours, _ = _t_solar(base, dates[: args.exact_days], slice_angles)
    worst = float(np.abs(exact_hours - fast_hours).max()) * 3600
    exact_points = args.exact_days * slice_angles.size * 1440

    fast_per_point = fast_seconds / fast_points
    exact_per_point = exact_seconds / exact_points
    peak_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"machine: {platform.machine()}, {platform.processor() or 'cpu'}, python {platform.python_version()}")
    print(f"workload: {len(dates)} days x {angles.size} angles x 1440 steps, single-diode + switching, "
          f"{args.mode} mode")
    print(f"fast path (tables, compiled kernel): {fast_seconds:8.2f} s  {fast_per_point * 1e9:8.1f} ns/point")
    print(f"exact solve (slice {exact_points} points):  {exact_seconds:8.2f} s  {exact_per_point * 1e9:8.1f} ns/point")
    print(f"speed-up, measured in this run: {exact_per_point / fast_per_point:8.1f} x")
    print(f"exact solve scaled to the whole workload: {exact_per_point * fast_points:8.1f} s")
    print(f"largest t_solar difference on the slice: {worst:.1f} s")
    print(f"peak memory: {peak_mib:.0f} MiB")
    hours, percent = accuracy()
    print(f"tables against the exact solve on the paper's day (180 angles, loads 10-90 % of the peak, paper and "
          f"exact modes, single-diode and b-model, every connection): t_solar within {hours:.2f} s, "
          f"energy within {percent:.5f} %")


if __name__ == "__main__":
    main()
