"""Many of foldopt's answers, dumped to compare two trees bit for bit (a kernel change's check).

    PYTHONPATH=/work/main python bench/same_bits.py dump /tmp/before.npz
    PYTHONPATH=$PWD      python bench/same_bits.py dump /tmp/after.npz
    python bench/same_bits.py compare /tmp/before.npz /tmp/after.npz

``dump`` runs, with the tree on ``PYTHONPATH``: the compiled kernel (``row_metrics``) over random
cases drawn from a fixed seed (every mode, sky, transposition, modifier, PV model, connection
alone and all together, geometry, step, loads, the longest runs, kept curves) on one and two
threads; the common case's loop (switching alone, exact, no modifier) over many random sites
and days at 1-min steps; W1's and W3's slices (``bench/run.py``'s studies); given power curves
(``curve_metrics``, with and without a load profile); the shipped studies of ``configs/`` that run
in seconds (their answers' tables); and a map's sites (``evaluate_chunk``, fold angles searched).
``compare`` asserts every array identical (NaNs in the same places), and names those that differ.
Not a golden file: both sides are computed on this machine, the same day.
"""

from __future__ import annotations

import datetime as dt
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
#: The shipped studies run here (the others take minutes: a year of weather, an ensemble, a map).
STUDIES = (
    "shin2015.yaml",
    "shin2015-single-diode.yaml",
    "site-as-built.yaml",
    "mppt-or-direct.yaml",
    "camera-buffer.yaml",
    "camera-profile.yaml",
    "load-sweep.yaml",
)


def _metrics(prefix: str, result, out: dict) -> None:
    for name in ("t_solar", "t_solar_contiguous", "energy", "peak", "irradiation", "power"):
        value = getattr(result, name)
        if value is not None:
            out[f"{prefix}/{name}"] = np.asarray(value)


def _drawn(study, rng, n_blocks: int, bounds: tuple, angles):
    """The engine's options, a sky of ``n_blocks`` sites and days drawn from ``rng`` (latitudes
    within ``bounds[0]`` deg of the equator, altitudes up to ``bounds[1]`` m) and its rows at
    fold ``angles``."""
    from foldopt.engine import evaluation as engine
    from foldopt.engine.sky import build_sky
    from foldopt.studies.engine_options import engine_options

    latitude, altitude = bounds
    sites = [study.variant(site={"latitude": float(rng.uniform(-latitude, latitude)),
                                 "longitude": float(rng.uniform(-180, 180)),
                                 "altitude": float(rng.uniform(0, altitude))}).site for _ in range(n_blocks)]
    dates = [dt.date(2025, 1, 1) + dt.timedelta(days=int(rng.integers(0, 365))) for _ in range(n_blocks)]
    options = engine_options(study)
    resolved = [study.variant(site=site.model_dump()).panel for site in sites]
    orientation = engine.fold_orientations(study.geometry, [p.tilt for p in resolved],
                                           [p.azimuth for p in resolved], angles)
    rows = engine.PanelRows(np.repeat(np.arange(n_blocks), angles.size), orientation.reshape(-1, 4))
    return options, build_sky(options.sky, sites, dates), rows


def _random_cases(out: dict, n_cases: int) -> None:
    import numba

    from foldopt.engine import evaluation as engine
    from foldopt.inputs.study import make_study

    rng = np.random.default_rng(49)
    for case in range(n_cases):
        mode = rng.choice(["paper", "exact"])
        skies = ["meinel", "hottel"] + (["ineichen", "simplified-solis"] if mode == "exact" else [])
        sky = str(rng.choice(skies))
        diffuse = sky in ("ineichen", "simplified-solis") or (mode == "exact" and rng.random() < 0.5)
        connection = str(rng.choice(["switching", "series", "independent"]))
        switch_series = connection == "switching" and rng.random() < 0.3
        series_used = connection == "series" or switch_series
        study = make_study({
            "name": "bits", "mode": str(mode), "sky": sky,
            "geometry": str(rng.choice(["azimuth-split", "hinge"])),
            "transposition": str(rng.choice(["isotropic", "haydavies", "perez"])) if diffuse else "none",
            "albedo": float(rng.uniform(0, 0.5)) if diffuse else 0.2,
            "iam": str(rng.choice(["none", "none", "ashrae", "physical"])),
            "pv_model": str(rng.choice(["ideal", "single-diode", "single-diode", "b-model", "pvwatts"])),
            "connection": connection, "switch_series": bool(switch_series),
            "bypass_diodes": bool(rng.random() < 0.5) if series_used else True,
            "converter_efficiency": float(rng.uniform(0.8, 1.0)) if connection == "independent" else 1.0,
            "site": {"latitude": 0.0, "longitude": 0.0}, "date": "2025-01-01",
            "panel": {"area": float(rng.choice([0.108, 0.2])), "efficiency": 0.19,
                      "tilt": None if rng.random() < 0.5 else float(rng.uniform(0, 90)),
                      "azimuth": None if rng.random() < 0.5 else float(rng.uniform(0, 359.9))},
            "p_load": 1.0, "step_min": int(rng.choice([1, 5, 10, 15])),
        })
        angles = np.r_[rng.uniform(1, 180, int(rng.integers(1, 12))), 180.0]
        options, the_sky, rows = _drawn(study, rng, int(rng.integers(1, 4)), (70.0, 2000.0), angles)
        loads = np.sort(rng.uniform(0.01, 25.0, int(rng.integers(1, 12))))
        contiguous = bool(rng.random() < 0.4)
        for threads in (1, 2):
            numba.set_num_threads(threads)
            for outputs in (engine.OUTPUTS, (connection,)):
                result = engine.row_metrics(
                    the_sky, rows=rows, loads=loads, electrical=options.electrical, outputs=outputs,
                    contiguous=contiguous, engine="numba", curves=[0, rows.block.size - 1],
                )
                _metrics(f"random/{case}/{threads}/{len(outputs)}", result, out)


def _common_cases(out: dict, n_cases: int) -> None:
    """Switching alone, exact, no modifier, constant loads: ``_chunk_switching``'s rows."""
    import numba

    from foldopt.engine import evaluation as engine
    from foldopt.inputs.study import make_study

    rng = np.random.default_rng(50)
    for case in range(n_cases):
        sky = str(rng.choice(["meinel", "ineichen", "hottel"]))
        study = make_study({
            "name": "common", "mode": "exact", "sky": sky, "pv_model": "single-diode",
            "transposition": "perez" if sky == "ineichen" else "none",
            "connection": "switching", "geometry": str(rng.choice(["azimuth-split", "hinge"])),
            "site": {"latitude": 0.0, "longitude": 0.0}, "date": "2025-01-01", "p_load": 1.0,
            "panel": {"area": 0.108, "efficiency": 0.19},
            "step_min": int(rng.choice([1, 1, 2, 5])),
        })
        angles = np.r_[np.sort(rng.uniform(1, 180, int(rng.integers(5, 60)))), 180.0]
        options, the_sky, rows = _drawn(study, rng, int(rng.integers(1, 6)), (66.0, 0.0), angles)
        loads = np.sort(rng.uniform(0.01, 30.0, int(rng.integers(1, 40))))
        for threads in (1, 2):
            numba.set_num_threads(threads)
            result = engine.row_metrics(the_sky, rows=rows, loads=loads, electrical=options.electrical,
                                        outputs=("switching",), engine="numba")
            _metrics(f"common/{case}/{threads}", result, out)


def _bench_slices(out: dict) -> None:
    sys.path.insert(0, str(ROOT / "bench"))
    import run as bench

    base = bench._study()
    loads = np.array([base.p_load])
    for name, days in (("W3", 14), ("W1", 40)):
        dates = [dt.date(2014, 1, 1) + dt.timedelta(days=int(d)) for d in np.linspace(0, 364, days)]
        _, hours, energy, sky, *_ = bench._fold_pass(base, [base.site] * days, dates, loads)
        out[f"{name}/hours"], out[f"{name}/energy"] = hours, energy
        out[f"{name}/sun"], out[f"{name}/dni"] = np.asarray(sky.sun_vector), sky.dni
        out[f"{name}/zenith"], out[f"{name}/azimuth"] = sky.solar_zenith, sky.solar_azimuth


def _curves(out: dict) -> None:
    from foldopt.engine import evaluation as engine

    rng = np.random.default_rng(51)
    for case in range(20):
        power = np.clip(rng.normal(5, 4, (6, 288)), 0, None) * (rng.random((6, 288)) < 0.8)
        power[:, :40] = 0.0
        shape = rng.uniform(0.2, 1.5, (6, 288)) if case % 2 else None
        loads = np.sort(rng.uniform(0.1, 8.0, 5))
        result = engine.curve_metrics(power, loads, 1 / 12, contiguous=bool(case % 3 == 0),
                                      engine="numba", load_shape=shape)
        _metrics(f"curves/{case}", result, out)


def _frames(prefix: str, value, out: dict) -> None:
    """Every numeric column of the DataFrames an answer holds."""
    import pandas as pd

    if isinstance(value, pd.DataFrame):
        for column in value.columns:
            data = value[column].to_numpy()
            if data.dtype.kind in "fiub":
                out[f"{prefix}/{column}"] = data
    elif isinstance(value, pd.Series) and value.dtype.kind in "fiub":
        out[prefix] = value.to_numpy()


def _studies(out: dict) -> None:
    from foldopt import api

    for name in STUDIES:
        result = api.run(ROOT / "configs" / name, engine="numba")
        for field in ("summary", "sweep", "timeseries", "table"):
            _frames(f"study/{name}/{field}", getattr(result, field, None), out)
        angle = getattr(result, "optimal_fold_angle", None)
        if angle is not None:
            out[f"study/{name}/optimal_fold_angle"] = np.asarray(angle, dtype=float)


def _map_sites(out: dict) -> None:
    import numba

    from foldopt.inputs.sites import grid_sites
    from foldopt.inputs.study_file import default_study_path, read_study
    from foldopt.studies.cluster import evaluate_chunk
    from foldopt.studies.map_request import map_study

    land = grid_sites(list(range(-90, 91)), list(range(-180, 180)), land_only=True)
    sites = land[:: len(land) // 6][:6]
    searched = {**map_study(read_study(default_study_path())[0]), "optimize": {"vary": ["fold_angle"]}}
    loads = tuple(np.round(np.arange(1, 11) * 0.05, 6))
    threads = numba.get_num_threads()
    try:
        table = evaluate_chunk(searched, sites, loads, True, 2025, "numba")
    finally:
        numba.set_num_threads(threads)
    _frames("map", table, out)


def dump(path: str) -> None:
    import foldopt

    print("foldopt from", foldopt.__file__)
    out: dict = {}
    for part in (lambda o: _random_cases(o, 120), lambda o: _common_cases(o, 60), _bench_slices,
                 _curves, _studies, _map_sites):
        started = time.perf_counter()
        before = len(out)
        part(out)
        print(f"{len(out) - before} arrays in {time.perf_counter() - started:.1f} s")
    np.savez(path, **out)
    print(f"{len(out)} arrays to {path}")


def compare(first: str, second: str) -> None:
    a, b = np.load(first), np.load(second)
    differ = sorted(set(a.files) ^ set(b.files))
    for name in sorted(set(a.files) & set(b.files)):
        x, y = a[name], b[name]
        if x.shape != y.shape or x.dtype != y.dtype or x.tobytes() != y.tobytes():
            differ.append(name)
    print(f"{len(a.files)} and {len(b.files)} arrays; {len(differ)} differ" + (":" if differ else ""))
    for name in differ[:40]:
        print("  ", name)
    sys.exit(1 if differ else 0)


if __name__ == "__main__":
    {"dump": dump, "compare": compare}[sys.argv[1]](*sys.argv[2:])
