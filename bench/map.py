"""W4: a world map on the embedded Dask cluster, and what a finer map would cost.

    python bench/map.py                  # 2,000 sites, printed
    python bench/map.py --write          # ... and written to results/bench/map.md and map.json
    python bench/map.py --sites 200      # a quicker look
    python bench/map.py --phases         # a site's cost by phase (profiled)
    python bench/map.py --w5 --sites 400 # W5 on 400 of the 1-degree land grid's sites, extrapolated
    python bench/map.py --w5             # W5: the whole 1-degree land grid (target 600 s)

W4: 2,000 sites (a 40 x 50 latitude x longitude grid from 58.5 S to 58.5 N) x 365 days x 180
fold angles (1..180 deg) x 10 loads (5 % to 50 % of each site's flat peak), the map's defaults:
Ineichen clear sky with pvlib's Linke turbidity climatology, exact mode, 5-min steps, ideal PV
model with switching, objective mean, every season. Run on an embedded LocalCluster of one worker,
then of two, each timed from the call to the finished tables (cluster start-up included, and
reported on its own). Reported: sites per second, the single-core cost of a site, the speed-up
from one worker to two, and from the per-site cost the time of a 1-degree world grid of land
sites on this machine and on 100 workers.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
TARGET_SPEEDUP = 1.8


def _spec(n_sites: int):
    from foldopt.studies.cluster import MapSpec
    from foldopt.inputs.load import default_study_path, read_study
    from foldopt.inputs.sites import grid_sites
    from foldopt.studies.worldmap import map_study

    n_lat = max(1, round(np.sqrt(n_sites * 0.8)))
    n_lon = -(-n_sites // n_lat)
    latitudes = np.linspace(-58.5, 58.5, n_lat)
    longitudes = -180 + 360 * (np.arange(n_lon) + 0.5) / n_lon
    sites = grid_sites([round(v, 6) for v in latitudes], [round(v, 6) for v in longitudes])[:n_sites]
    study = map_study(read_study(default_study_path())[0])
    return MapSpec(study, tuple(sites), tuple(np.round(np.arange(1, 11) * 0.05, 6)), relative=True)


def _run(spec, workers: int, folder: Path) -> dict:
    from distributed import Client, LocalCluster  # noqa: F401  (imported before the clock starts)

    from foldopt.studies.cluster import run_map

    started = time.perf_counter()
    ready = {}
    result = run_map(spec, folder / f"w{workers}", workers=workers,
                     announce=lambda *_: ready.setdefault("at", time.perf_counter()))
    wall = time.perf_counter() - started
    start_up = ready["at"] - started
    return {"workers": workers, "wall_s": round(wall, 2), "cluster_start_s": round(start_up, 2),
            "sites_per_s": round(len(spec.sites) / wall, 2), "rows": len(result.table),
            "table": result.table}


#: The phases of a site's evaluation, by the functions whose cumulative time is each's.
PHASES = {"sky": ("foldopt/engine/sky.py", "build_sky"), "fold angles": ("foldopt/studies/designs.py", "fold_hours"),
          "flat": ("foldopt/engine/rows.py", "row_metrics"), "trackers": ("foldopt/studies/designs.py", "sky_tracker_"),
          "break-even": ("foldopt/studies/worldmap.py", "_break_even_standby")}


def phases(spec, n_sites: int = 20) -> dict:
    """Seconds per site of each phase on one core, from a profile of ``n_sites`` sites of the spec
    (the first site first, unprofiled, so that compiling and the tables' cache are not counted).
    ``flat`` is every kernel call but the fold angles' (the flat panel's peak and its year)."""
    import cProfile
    import pstats

    from foldopt.studies.worldmap import evaluate_sites

    sites = list(spec.sites[:n_sites + 1])
    evaluate_sites(spec.study, sites[:1], spec.loads, spec.relative, spec.year)
    profile = cProfile.Profile()
    started = time.perf_counter()
    profile.runcall(evaluate_sites, spec.study, sites[1:], spec.loads, spec.relative, spec.year)
    total = (time.perf_counter() - started) / n_sites
    stats = pstats.Stats(profile).stats
    seconds = {}
    for phase, (file, function) in PHASES.items():
        seconds[phase] = sum(entry[3] for (path, _, name), entry in stats.items()
                             if path.endswith(file) and name.startswith(function)) / n_sites
    seconds["flat"] -= sum(entry[3] for (path, _, name), entry in stats.items()
                           if path.endswith("foldopt/studies/designs.py") and name == "fold_hours") / n_sites
    seconds["other"] = total - sum(seconds.values())
    return {"per_site_s": total, **seconds}


W5_TARGET_S = 600.0  # the 1-degree land grid on this machine's embedded cluster


def w5(subset: int | None, check_sites: int = 200) -> None:
    """W5: the 1-degree land grid (a year each, 10 loads, 5 periods, 5-min steps) on the embedded
    cluster of two workers, its fold angles searched (``--fold-search``); ``subset`` sites spread over
    the grid instead, the whole grid's time extrapolated from them. Then ``check_sites`` of them
    evaluated again with every fold angle, in this process: each objective within the search's
    0.01 h of the full sweep's."""
    import pandas as pd

    from foldopt.inputs.load import default_study_path, read_study
    from foldopt.inputs.sites import grid_sites
    from foldopt.studies.cluster import MapSpec, run_map
    from foldopt.studies.worldmap import evaluate_sites, map_study

    land = grid_sites(list(range(-90, 91)), list(range(-180, 180)), land_only=True)
    sites = land if subset is None else land[::max(1, len(land) // subset)][:subset]
    loads = tuple(np.round(np.arange(1, 11) * 0.05, 6))
    full = map_study(read_study(default_study_path())[0])
    searched = {**full, "optimize": {"vary": ["fold_angle"]}}
    with tempfile.TemporaryDirectory() as folder:
        started = time.perf_counter()
        result = run_map(MapSpec(searched, tuple(sites), loads, relative=True), Path(folder) / "w5", workers=2)
        wall = time.perf_counter() - started
    whole = wall * len(land) / len(sites)
    print(f"W5: {len(sites):,} of the {len(land):,} land sites in {wall:.1f} s on 2 workers "
          f"({len(sites) / wall:.2f} sites/s); the whole grid at that pace {whole:.0f} s (target {W5_TARGET_S:.0f} s)")
    chosen = [{**site, "site_id": index} for index, site in enumerate(sites)][::max(1, len(sites) // check_sites)]
    chosen = chosen[:check_sites]
    reference = evaluate_sites(full, chosen, loads, relative=True)
    ids = [site["site_id"] for site in chosen]
    mine = result.table[result.table["site_id"].isin(ids)].reset_index(drop=True)
    keys = ["site_id", "p_load_fraction", "period"]
    merged = pd.merge(mine.assign(p_load_fraction=mine["p_load_fraction"].round(12)),
                      reference.assign(p_load_fraction=reference["p_load_fraction"].round(12)), on=keys,
                      suffixes=("_search", "_full"))
    short = merged["objective_twofold_h_full"] - merged["objective_twofold_h_search"]
    print(f"check on {len(chosen)} sites ({len(merged):,} rows): the search short of the full sweep by at most "
          f"{short.max():.5f} h, never above it by more than {max(0.0, -short.min()):.2e} h (tolerance 0.01 h)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sites", type=int, default=2000)
    parser.add_argument("--write", action="store_true", help="write results/bench/map.md and map.json")
    parser.add_argument("--phases", action="store_true", help="only the per-site cost by phase (20 sites, profiled)")
    parser.add_argument("--w5", action="store_true", help="W5: the 1-degree land grid with the fold search "
                                                          "(--sites N: N of its sites, the whole extrapolated)")
    args = parser.parse_args()
    if args.w5:
        w5(args.sites if "--sites" in sys.argv else None)
        return
    spec = _spec(args.sites)
    if args.phases:
        cost = phases(spec)
        print(f"per site on one core (profiled, so slower than unprofiled): {cost.pop('per_site_s'):.3f} s; "
              + ", ".join(f"{phase} {value:.3f} s" for phase, value in cost.items()))
        return
    with tempfile.TemporaryDirectory() as folder:
        runs = [_run(spec, workers, Path(folder)) for workers in (1, 2)]
    one, two = runs
    import pandas as pd

    pd.testing.assert_frame_equal(one.pop("table"), two.pop("table"), check_exact=True)
    speedup = one["wall_s"] / two["wall_s"]
    per_site = (one["wall_s"] - one["cluster_start_s"]) / len(spec.sites)  # one core, one site, everything
    land_sites = 21_637  # 1-degree grid points on land, foldopt.inputs.sites.grid_sites(..., land_only=True)
    lines = [
        f"# W4: world map on the embedded Dask cluster ({platform.node()}, {os.cpu_count()} cores, "
        f"{time.strftime('%Y-%m-%d')})",
        "",
        f"{len(spec.sites):,} sites x 365 days x 180 fold angles x {len(spec.loads)} loads x 5 periods, "
        f"{spec.sites_per_chunk} sites per chunk ({len(spec.chunks())} chunks), 5-min steps.",
        "",
        "| workers | wall [s] | of which cluster start [s] | sites/s |",
        "|---|---|---|---|",
        *[f"| {r['workers']} | {r['wall_s']:.1f} | {r['cluster_start_s']:.1f} | {r['sites_per_s']:.2f} |"
          for r in runs],
        "",
        f"Speed-up from 1 to 2 workers: **{speedup:.2f}x** (target >= {TARGET_SPEEDUP}x). Tables bit-identical.",
        f"Single-core cost of a site (a year, 180 angles, 10 loads, 5 periods): {per_site:.3f} s.",
        "",
        f"A 1-degree world grid of land sites ({land_sites:,}) at that cost: "
        f"{land_sites * per_site / 3600:.2f} core-hours; on this machine's 2 workers, at the measured speed-up, "
        f"{land_sites * per_site / speedup / 60:.0f} min; on 100 workers {land_sites * per_site / 100:.0f} s of "
        "compute plus start-up.",
    ]
    text = "\n".join(lines)
    print(text)
    if args.write:
        out = ROOT / "results" / "bench"
        out.mkdir(parents=True, exist_ok=True)
        (out / "map.md").write_text(text + "\n")
        (out / "map.json").write_text(json.dumps({"sites": len(spec.sites), "runs": runs, "speedup": speedup,
                                                   "per_site_s": per_site}, indent=2) + "\n")
    if speedup < TARGET_SPEEDUP:
        print(f"speed-up {speedup:.2f}x is below the target {TARGET_SPEEDUP}x", file=sys.stderr)


if __name__ == "__main__":
    main()
