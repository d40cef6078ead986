"""What the least-cost search (foldopt.studies.least_cost) adds to a year's buffered run.

    python bench/least_cost.py              # 3 runs of each, alternated
    python bench/least_cost.py --runs 5

The study is the camera-winter shape of issue 50: a 2 W camera at 45 N 8 E over the recorded
2020-2021 PVGIS hourly answer (``tests/data/pvgis/``, 731 days), a 0.4 m^2 pvwatts panel, a
200 Wh LiFePO4 sized for 24 h every day, one fold angle for the mean. It runs as typed, ``foldopt
run STUDY``, without and with its ``costs`` (panel, buffer, hinge and a dual-axis drive: flat,
twofold at 8 angles and the tracker at 17 areas), alternated, each in a fresh process with this
tree on ``PYTHONPATH`` after one run that fills numba's cache. Each figure is the minimum of the
runs: wall time, and CPU time (user and system, which the machine's other load moves less).
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
RECORDED = ROOT / "tests" / "data" / "pvgis" / "seriescalc_45.000_8.000_2020_2021.json"
STUDY = {
    "name": "camera-winter",
    "mode": "exact",
    "site": {"latitude": 45.0, "longitude": 8.0},
    "weather": {"path": str(RECORDED), "format": "pvgis-hourly"},
    "panel": {"area": 0.4, "efficiency": 0.1905},
    "p_load": 2.0,
    "objective": {"statistic": "mean"},
    "storage": {"preset": "lifepo4", "capacity_wh": 200, "target": {"powered_h": 24}},
}
COSTS = {
    "panel_usd_per_m2": 150,
    "buffer_usd_per_wh": 0.5,
    "hinge_usd": 3,
    "drive_dual_axis_usd": 40,
}


def timed(study: Path, out: Path) -> tuple[float, float]:
    """``foldopt run study``'s wall and CPU time [s] in a fresh process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "foldopt.cli.app", "run", str(study), "--out", str(out),
         "--overwrite", "-q"],
        check=True, env={**os.environ, "PYTHONPATH": str(ROOT)},
    )  # fmt: skip
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    return wall, cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    runs = parser.parse_args().runs
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        studies = {}
        for name, extra in (("without", {}), ("with", {"costs": COSTS})):
            studies[name] = folder / f"{name}.yaml"
            studies[name].write_text(yaml.safe_dump({**STUDY, **extra}))
        timed(studies["with"], folder / "warm")
        times = {name: [] for name in studies}
        for _ in range(runs):
            for name, study in studies.items():
                times[name].append(timed(study, folder / name))
    best = {
        name: tuple(min(t[i] for t in values) for i in (0, 1)) for name, values in times.items()
    }
    for name, (wall, cpu) in best.items():
        print(f"{name} costs: wall {wall:.2f} s, CPU {cpu:.2f} s (min of {runs})")
    print(
        f"the search adds: wall {best['with'][0] - best['without'][0]:.2f} s, "
        f"CPU {best['with'][1] - best['without'][1]:.2f} s"
    )


if __name__ == "__main__":
    main()
