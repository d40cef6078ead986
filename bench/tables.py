"""The electrical tables' cold builds: every table kind, PV model with I-V curves and circuit.

    python bench/tables.py                          # CPU and wall seconds a table, minimum of 3
    python bench/tables.py --repeats 1 --only sd/25   # the tables whose key contains a text
    python bench/tables.py --save tables.npz        # also every table's arrays, for --compare
    python bench/tables.py --compare tables.npz     # the same bits as a saved run (another tree)?

Workload: :meth:`foldopt.engine.electrical.Electrical._table` built cold (a fresh
``FOLDOPT_CACHE_DIR`` each time) for 0.15 m^2 sub-panels: the A-300 cell, a CEC module
(CS5P-220M) and the b-model, the ideal circuit's ``subpanel``, ``parallel`` and ``series`` tables
at -10 C (cells at the air) and 25 and 45 C (Sandia's cell temperature); and, at 25 C, the circuit
as built of the configs' presets (``configs/site-as-built.yaml``, ``configs/mppt-or-direct.yaml``:
Shockley blocking diodes and a 20 mOhm switch behind an MPPT converter's curve or direct at 5 V)
and of constant and Shockley diodes and a direct 9 V load, each table it builds (``parallel``,
``series``, ``switching`` where the switch has a resistance, ``alone`` and ``panel`` where coupled
directly). CPU seconds (``time.process_time``) stand up to a shared machine better than wall
seconds; both are printed. Timing two trees: run each tree's copy of this file (it imports the
foldopt beside it), alternated, and compare minima; ``--save`` in one and ``--compare`` in the other
checks every table is the same bits (``numpy.array_equal``).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from foldopt.engine.as_built import circuit_parts  # noqa: E402
from foldopt.engine.electrical import Electrical  # noqa: E402
from foldopt.inputs.circuit_section import Circuit  # noqa: E402
from foldopt.physics.pvmodel import PVModel  # noqa: E402

AREA = 0.15  # [m^2], a sub-panel of configs/site-as-built.yaml's 0.3 m^2 panel
MODELS = {
    "sd": PVModel("single-diode", 0.2),
    "cec": PVModel("single-diode", 0.2, module="CS5P-220M"),
    "b": PVModel("b-model", 0.19),
}
CIRCUITS = {
    "mppt-curve": {
        "blocking_diode": "shockley",
        "switch_resistance": 0.02,
        "converter": {"model": "curve", "curve": [[0.02, 0.70], [0.1, 0.91], [1.0, 0.95]]},
    },
    "direct5": {
        "blocking_diode": "shockley",
        "switch_resistance": 0.02,
        "coupling": "direct",
        "load_voltage": 5.0,
    },
    "constant": {"blocking_diode": "constant", "bypass_diode": "constant"},
    "bypass-shockley": {"blocking_diode": "constant", "bypass_diode": "shockley"},
    "direct9": {
        "blocking_diode": {"model": "constant", "forward_voltage": 0.45},
        "coupling": "direct",
        "load_voltage": 9.0,
    },
}


def cases():
    """(key, Electrical's settings, table name) of every table of the workload."""
    for model, pv in MODELS.items():
        for temp, temperature_model in ((-10.0, "fixed"), (25.0, "sapm"), (45.0, "sapm")):
            settings = dict(pv=pv, subpanel_area=AREA, temp_air=temp, temperature_model=temperature_model)
            for name in ("subpanel", "parallel", "series"):
                yield f"{model}/{temp:g}/{temperature_model}/ideal/{name}", settings, name
    for model in ("sd", "b"):
        pv = MODELS[model]
        for label, spec in CIRCUITS.items():
            parts = circuit_parts(Circuit(**spec), pv.rating(2 * AREA))
            names = (
                ["parallel", "series"]
                + (["switching"] if parts.switch_table else [])
                + (["alone", "panel"] if parts.direct else [])
            )
            settings = dict(
                pv=pv, subpanel_area=AREA, temp_air=25.0, temperature_model="sapm", circuit=parts,
                switch_series=True,
            )
            for name in names:
                yield f"{model}/25/sapm/{label}/{name}", settings, name


def build(settings, name):
    """One table built cold: its arrays, CPU and wall seconds."""
    os.environ["FOLDOPT_CACHE_DIR"] = tempfile.mkdtemp(prefix="foldopt-bench-tables-")
    electrical = Electrical(**settings)
    cpu, wall = time.process_time(), time.perf_counter()
    table = electrical._table(name)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    return (table if isinstance(table, tuple) else (table,)), cpu, wall


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--only", default="", help="only the tables whose key contains this")
    parser.add_argument("--save", help="write every table's arrays to this .npz")
    parser.add_argument("--compare", help="compare every table's arrays with this .npz")
    args = parser.parse_args()

    # pvlib's and SciPy's imports, and their first calls, outside the timings.
    MODELS["sd"].max_power(np.array([500.0]), 25.0, AREA)
    arrays, total_cpu, total_wall = {}, 0.0, 0.0
    print(f"{'table':42s} {'CPU s':>7s} {'wall s':>7s}  (minimum of {args.repeats})")
    for key, settings, name in cases():
        if args.only not in key:
            continue
        runs = [build(settings, name) for _ in range(args.repeats)]
        cpu, wall = min(run[1] for run in runs), min(run[2] for run in runs)
        total_cpu, total_wall = total_cpu + cpu, total_wall + wall
        arrays.update({f"{key}#{i}": array for i, array in enumerate(runs[0][0])})
        print(f"{key:42s} {cpu:7.3f} {wall:7.3f}", flush=True)
    print(f"{'sum':42s} {total_cpu:7.3f} {total_wall:7.3f}")
    if args.save:
        np.savez(args.save, **arrays)
    if args.compare:
        saved = np.load(args.compare)
        differ = [
            key
            for key in arrays
            if key not in saved.files or not np.array_equal(arrays[key], saved[key], equal_nan=True)
        ]
        print(f"{len(arrays)} arrays compared with {args.compare}: {len(differ)} differ {differ[:10]}")


if __name__ == "__main__":
    main()
