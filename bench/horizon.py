"""The time of the horizon's sky view factors for many surfaces in one call.

    python bench/horizon.py                 # 1e5 surfaces under PVGIS's recorded profile
    python bench/horizon.py --surfaces 1e6 --runs 5

Workload: random tilts in [0, 180] deg and azimuths in [0, 360) deg under the PVGIS horizon
profile of the tests' data (tests/data/horizon/pvgis_horizon.json), through
:func:`foldopt.physics.horizon.sky_view_factors` in one call, as a map's or the optimiser's
designs ask for them; printed as the minimum of ``--runs`` calls and per surface, near-vertical
surfaces (tilt 80-100 deg, whose quadrature has the most sectors to cut) beside. The test of the
same call (tests/test_horizon.py) checks the factors, not the time.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def _timed(tilt, facing, azimuth, elevation, runs: int) -> float:
    from foldopt.physics.horizon import sky_view_factors

    times = []
    for _ in range(runs):
        start = time.perf_counter()
        sky_view_factors(tilt, facing, azimuth, elevation)
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--surfaces", type=float, default=1e5)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    from foldopt.inputs.horizon import read_horizon

    azimuth, elevation = read_horizon(ROOT / "tests" / "data" / "horizon" / "pvgis_horizon.json")
    n, rng = int(args.surfaces), np.random.default_rng(3)
    facing = rng.uniform(0.0, 360.0, n)
    for label, low, high in (("any tilt", 0.0, 180.0), ("near-vertical", 80.0, 100.0)):
        seconds = _timed(rng.uniform(low, high, n), facing, azimuth, elevation, args.runs)
        print(
            f"{n:,} surfaces, {label}: {seconds:.3f} s ({seconds / n * 1e6:.1f} us a surface; "
            f"minimum of {args.runs})"
        )


if __name__ == "__main__":
    main()
