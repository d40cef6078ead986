"""The cost of a cloud ensemble: a TMY3 year with 20 members against the same year with one
(the smooth minutes), in one process, side by side.

    python bench/ensemble.py              # 3 repeats of each, the minimum printed
    python bench/ensemble.py --members 50 --repeats 5

The study: the Greensboro TMY3 sample pvlib ships, 1-minute steps, the single-diode A-300
sub-panels with switching, Perez diffuse light, two loads, fold angles every 5 deg, one fold angle
for the year maximising the mean daily t_solar (``foldopt.studies.sweeps.run_plan``). Printed per
run: the whole plan, and its phases over the ensemble's blocks: the sky (sun, clear sky, the
members' draws, the diffuse terms) and the kernel passes. The target of issue 24: the ensemble
costs at most 10 times one member, its sun, clear sky and electrical tables shared.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pvlib

from foldopt.inputs.plan import make_plan
from foldopt.studies.designs import Blocks, fold_hours
from foldopt.studies.sweeps import run_plan

TMY3 = Path(pvlib.__file__).parent / "data" / "723170TYA.CSV"


def plan(members: int | None):
    weather = {"path": str(TMY3), **({"members": members} if members else {})}
    return make_plan({"name": "bench", "weather": weather, "panel": {"area": 0.108}, "p_load": [2.0, 4.4],
                      "pv_model": "single-diode", "transposition": "perez", "objective": "mean",
                      "fold_angles": {"step": 5}})


def timed(function, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return best


def phases(members: int | None) -> dict:
    """The sky and the kernel's pass over the year's blocks, one chunk after another."""
    study = plan(members).base
    dates = sorted(dict(plan(members).axes)["date"])
    blocks = Blocks.of_dates(study, dates)
    sky_s = kernel_s = 0.0
    for part in blocks.chunks(2):
        start = time.perf_counter()
        sky = blocks[part].sky()
        middle = time.perf_counter()
        fold_hours(sky, blocks[part], np.array([2.0, 4.4]))
        sky_s += middle - start
        kernel_s += time.perf_counter() - middle
    return {"sky_s": sky_s, "kernel_s": kernel_s}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--members", type=int, default=20)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    run_plan(plan(None))  # compile the kernel, build the tables' cache
    run_plan(plan(args.members))
    one = timed(lambda: run_plan(plan(None)), args.repeats)
    many = timed(lambda: run_plan(plan(args.members)), args.repeats)
    print(f"a TMY3 year, 1-min steps, {len(plan(None).base.fold_angles.grid())} fold angles, 2 loads")
    print(f"  one member (smooth minutes): {one:7.2f} s")
    print(f"  {args.members} members:                {many:7.2f} s   ({many / one:.1f} x; target <= 10 x)")
    for label, members in (("one member", None), (f"{args.members} members", args.members)):
        split = phases(members)
        print(f"  phases, {label}: sky {split['sky_s']:.2f} s, fold-angle kernel {split['kernel_s']:.2f} s")


if __name__ == "__main__":
    main()
