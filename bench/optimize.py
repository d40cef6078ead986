"""W6: the joint optimiser (``foldopt optimize``) against the brute-force grid it replaces, at the
paper's site and three others.

    python bench/optimize.py              # four sites, printed
    python bench/optimize.py --days 1:365:7

Per site: configs/optimize.yaml's study (exact mode, Ineichen clear sky, its PV model, the 4.398 W
camera, mean daily t_solar over the days) with the fold angle (10 to 180 by 2 deg), base tilt (0 to
90 by 2) and base azimuth (the equator-facing one +-60 by 4) varied together; the search
(:func:`foldopt.engine.search.grid_search`) and every point of the same grid, each timed in this
process. Printed: each best design and objective, their difference against the search's stated
tolerance, the share of the grid the search evaluated, and both times.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

SITES = {
    "Los Angeles (Shin et al.)": (34.05, -118.25, "America/Los_Angeles"),
    "Sydney": (-33.87, 151.21, "Australia/Sydney"),
    "Nairobi": (-1.29, 36.82, "Africa/Nairobi"),
    "Oslo": (59.91, 10.75, "Europe/Oslo"),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--days", default="1:365:14")
    args = parser.parse_args()
    import foldopt
    from foldopt.engine.search import Axis, grid_search
    from foldopt.studies.designs import Blocks, design_hours
    from foldopt.studies.objectives import objective_quantum
    from foldopt.studies.objectives import objective_value

    base = foldopt.load_study(ROOT / "configs" / "optimize.yaml").base
    for name, (latitude, longitude, timezone) in SITES.items():
        plan = foldopt.make_request("run", base.data(), fields={
            "site": {"latitude": latitude, "longitude": longitude, "timezone": timezone},
            "date": args.days, "optimize": None}).plan
        study = plan.base
        dates = dict(plan.axes)["date"]
        blocks = Blocks.of_dates(study, dates)
        parts = [(blocks[part], blocks[part].sky()) for part in blocks.chunks(1)]
        months = np.array([date.month for date in dates])
        loads = np.array([study.p_load])

        def evaluate(points):
            return objective_value(design_hours(parts, points, loads), months, "mean")

        equator = study.panel.azimuth
        axes = [Axis("fold_angle", 10, 180, 2), Axis("tilt", 0, 90, 2), Axis("azimuth", equator - 60, equator + 60, 4)]
        start = time.perf_counter()
        found = grid_search(evaluate, axes, 0.01, objective_quantum("mean", parts[0][1].step_hours, len(dates), months))
        searched = time.perf_counter() - start
        grid = np.stack(np.meshgrid(*[axis.values() for axis in axes], indexing="ij"), axis=-1).reshape(-1, 3)
        start = time.perf_counter()
        values = evaluate(grid)[:, 0]
        brute = time.perf_counter() - start
        best = int(np.argmax(values))
        share = 100 * found.index.shape[0] / grid.shape[0]
        print(f"{name}: search {found.best_point[0].tolist()} {found.best_value[0]:.4f} h in {searched:.1f} s, "
              f"{found.index.shape[0]:,} of {grid.shape[0]:,} designs ({share:.1f} %); grid {grid[best].tolist()} "
              f"{values[best]:.4f} h in {brute:.1f} s; short by {values[best] - found.best_value[0]:.5f} h "
              f"(tolerance {found.tolerance:g} h)")


if __name__ == "__main__":
    main()
