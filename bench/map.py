"""W4: a world map on the embedded Dask cluster, and what a finer map would cost.

    python bench/map.py                  # 2,000 sites, printed
    python bench/map.py --write          # ... and written to results/bench/map.md and map.json
    python bench/map.py --sites 200      # a quicker look
    python bench/map.py --phases         # a site's cost by phase, one core (W4's sites: every angle)
    python bench/map.py --w5 --phases    # ... W5's: a chunk of land sites, fold angles searched; 100 workers' time
    python bench/map.py --w5 --sites 1000 # W5 on 1,000 of the 1-degree land grid's sites, the grid projected
    python bench/map.py --w5             # W5: the whole 1-degree land grid (target 600 s)
    python bench/map.py --w5 --sites 1000 --step-min 10  # ... projected at 10-min steps
    python bench/map.py --w5 --phases --step-min 30      # a site's cost by phase at 30-min steps

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
    from foldopt.inputs.study_file import default_study_path, read_study
    from foldopt.inputs.sites import grid_sites
    from foldopt.studies.map_request import MapSpec, map_study

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


def _phase_timers():
    """Wrap the functions a site's evaluation spends its time in with timers: ``{phase: seconds}``
    accumulating while they run, and a function that unwraps them. Each phase is the wall time of
    its functions' calls (nested calls are counted once, in the outer), and ``phase (CPU)`` the
    process's CPU time over them."""
    import functools

    from foldopt.engine import kernel
    from foldopt.studies import blocks, designs, worldmap

    spent: dict[str, float] = {}
    wrapped = [(blocks.Blocks, "sky", "sky"), (kernel, "fold_rows", "kernel: twofold and flat"),
               (designs, "tracker_curves", "trackers"), (designs, "standby_available", "trackers"),
               (worldmap, "break_even_standby", "break-even")]
    originals = [(owner, name, getattr(owner, name)) for owner, name, _ in wrapped]

    def timed(phase, function):
        @functools.wraps(function)
        def wrapper(*args, **kwargs):
            started, cpu = time.perf_counter(), time.process_time()
            try:
                return function(*args, **kwargs)
            finally:
                spent[phase] = spent.get(phase, 0.0) + time.perf_counter() - started
                spent[f"{phase} (CPU)"] = spent.get(f"{phase} (CPU)", 0.0) + time.process_time() - cpu
        return wrapper

    for owner, name, phase in wrapped:
        setattr(owner, name, timed(phase, getattr(owner, name)))
    return spent, lambda: [setattr(owner, name, function) for owner, name, function in originals]


def phases(study: dict, sites: list, loads, relative: bool, year: int = 2025, repeats: int = 3) -> dict:
    """Seconds per site of each phase on one core, as a map's worker runs its chunks (its task,
    :func:`foldopt.studies.cluster.evaluate_chunk`: numba on one thread, its memory settings):
    ``sites[0]`` first, untimed, so that compiling and the tables' caches are not counted, then the
    rest, the minimum of ``repeats`` runs of each phase and of the whole (``per_site_s``), and of the
    process's CPU time over the whole (``cpu_s``)."""
    import functools

    import numba

    from foldopt.studies.cluster import evaluate_chunk

    evaluate_sites = functools.partial(evaluate_chunk, engine="numba")

    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    spent, restore = _phase_timers()
    try:
        evaluate_sites(study, sites[:1], loads, relative, year)
        best: dict[str, float] = {}
        for _ in range(repeats):
            spent.clear()
            started, cpu = time.perf_counter(), time.process_time()
            evaluate_sites(study, sites[1:], loads, relative, year)
            run = {"per_site_s": time.perf_counter() - started, **spent,
                   "cpu_s": time.process_time() - cpu}
            best = {phase: min(value, best.get(phase, value)) for phase, value in run.items()}
    finally:
        restore()
        numba.set_num_threads(threads)
    per_site = {phase: value / (len(sites) - 1) for phase, value in best.items()}
    per_site["rest"] = per_site["per_site_s"] - sum(
        v for k, v in per_site.items() if k not in ("per_site_s", "cpu_s") and not k.endswith("(CPU)"))
    per_site["rest (CPU)"] = per_site["cpu_s"] - sum(v for k, v in per_site.items() if k.endswith("(CPU)"))
    return per_site


def _print_phases(cost: dict) -> None:
    """The phases' wall time, and the process's CPU time beside it: on a machine shared with other
    work, the CPU time is the steadier measure of the code (the wall time counts the waits)."""
    print(f"per site on one core: {cost['per_site_s'] * 1e3:.0f} ms (CPU {cost['cpu_s'] * 1e3:.0f} ms); "
          + ", ".join(f"{phase} {value * 1e3:.0f} ms" + (f" ({cost[f'{phase} (CPU)'] * 1e3:.0f})"
                                                       if f"{phase} (CPU)" in cost else "")
                      for phase, value in cost.items()
                      if phase not in ("per_site_s", "cpu_s") and not phase.endswith("(CPU)")))


def _land_sites(subset: int | None) -> tuple[list, list]:
    """The 1-degree grid's land sites, and ``subset`` of them spread over it (all of them: None)."""
    from foldopt.inputs.sites import grid_sites

    land = grid_sites(list(range(-90, 91)), list(range(-180, 180)), land_only=True)
    return land, land if subset is None else land[::max(1, len(land) // subset)][:subset]


W5_TARGET_S = 600.0  # the 1-degree land grid on this machine's embedded cluster


def w5(subset: int | None, check_sites: int = 200, step_min: float = 5.0) -> None:
    """W5: the 1-degree land grid (a year each, 10 loads, 5 periods, 5-min steps) on the embedded
    cluster of two workers, its fold angles searched (``--fold-search``); ``subset`` sites spread over
    the grid instead, the whole grid's time projected from them. Then ``check_sites`` of them
    evaluated again with every fold angle, in this process: each objective within the search's
    0.01 h of the full sweep's.

    The projection keeps what a run costs once apart from what each site costs: the cluster's start
    and each worker's first chunk (it imports foldopt and loads its compiled kernels and tables:
    some 7 s to every worker's first chunk done, on 1,000 sites) once, the steady pace after them
    (sites a second, from the chunks that finished after every worker's first) for the rest of the
    grid, and the tables written at the end (their rows scale with the sites). Scaling the whole
    subset's time instead would count the once-only costs some 50 times for 400 sites.

    ``step_min`` other than 5 measures W5 at another time step (``--step-min``), what the issue's
    target would cost with a coarser clock; the check is then against the full sweep at that step."""
    import pandas as pd

    from foldopt.inputs.study_file import default_study_path, read_study
    from foldopt.studies.cluster import run_map
    from foldopt.studies.map_request import MapSpec, map_study
    from foldopt.studies.worldmap import evaluate_sites

    land, sites = _land_sites(subset)
    loads = tuple(np.round(np.arange(1, 11) * 0.05, 6))
    full = {**map_study(read_study(default_study_path())[0]), "step_min": step_min}
    searched = {**full, "optimize": {"vary": ["fold_angle"]}}
    workers = 2
    ready, done = {}, []
    with tempfile.TemporaryDirectory() as folder:
        started = time.perf_counter()
        result = run_map(MapSpec(searched, tuple(sites), loads, relative=True), Path(folder) / "w5", workers=workers,
                         announce=lambda *_: ready.setdefault("at", time.perf_counter()),
                         progress=lambda finished, _: done.append((time.perf_counter(), finished)))
        wall = time.perf_counter() - started
    start_up = ready["at"] - started
    print(f"W5{'' if step_min == 5.0 else f' at {step_min:g}-min steps'}: {len(sites):,} of the {len(land):,} "
          f"land sites in {wall:.1f} s on {workers} workers, of which "
          f"{start_up:.1f} s the cluster's start")
    finishes = [(at, finished) for at, finished in done if finished > 0]
    if subset is not None and len(finishes) > workers + 1:
        # From every worker's first chunk done to the last chunk done: the steady pace.
        (first_at, first_sites), (last_at, last_sites) = finishes[workers - 1], finishes[-1]
        pace = (last_sites - first_sites) / (last_at - first_at)
        once = first_at - started
        tables = (started + wall - last_at) * len(land) / len(sites)
        whole = once + (len(land) - first_sites) / pace + tables
        print(f"  steady pace {pace:.2f} sites/s ({1e3 * workers / pace:.0f} ms a site a worker); once: "
              f"{once:.1f} s to every worker's first chunk done; the whole grid projected {whole:.0f} s "
              f"(= {once:.0f} + {len(land) - first_sites:,} sites at that pace + {tables:.0f} s of tables; "
              f"target {W5_TARGET_S:.0f} s)")
    elif subset is None:
        print(f"  the whole grid: {wall:.0f} s (target {W5_TARGET_S:.0f} s)")
    chosen = [{**site, "site_id": index} for index, site in enumerate(sites)][::max(1, len(sites) // check_sites)]
    chosen = chosen[:check_sites]
    reference = evaluate_sites(full, chosen, loads, relative=True)
    ids = [site["site_id"] for site in chosen]
    mine = result.table[result.table["site_id"].isin(ids)].reset_index(drop=True)
    keys = ["site_id", "p_load_frac", "period"]
    merged = pd.merge(mine.assign(p_load_frac=mine["p_load_frac"].round(12)),
                      reference.assign(p_load_frac=reference["p_load_frac"].round(12)), on=keys,
                      suffixes=("_search", "_full"))
    short = merged["t_solar_twofold_objective_h_full"] - merged["t_solar_twofold_objective_h_search"]
    print(f"check on {len(chosen)} sites ({len(merged):,} rows): the search short of the full sweep by at most "
          f"{short.max():.5f} h, never above it by more than {max(0.0, -short.min()):.2e} h (tolerance 0.01 h)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sites", type=int, default=2000)
    parser.add_argument("--write", action="store_true", help="write results/bench/map.md and map.json")
    parser.add_argument("--phases", action="store_true", help="only the per-site cost by phase (one core, timed)")
    parser.add_argument("--w5", action="store_true", help="W5: the 1-degree land grid with the fold search "
                                                          "(--sites N: N of its sites, the whole extrapolated)")
    parser.add_argument("--step-min", type=float, default=5.0, help="W5 (and --w5 --phases) at another time step [min] "
                                                                        "(default 5)")
    args = parser.parse_args()
    if args.w5 and args.phases:
        from foldopt.inputs.study_file import default_study_path, read_study
        from foldopt.studies.map_request import MapSpec, map_study

        searched = {**map_study(read_study(default_study_path())[0]), "optimize": {"vary": ["fold_angle"]},
                    "step_min": args.step_min}
        loads = tuple(np.round(np.arange(1, 11) * 0.05, 6))
        # As many sites as a run's chunk holds, in one call as a worker runs a chunk: what a chunk
        # works out once (SPA's lattice of the year) is shared as in a run.
        land, _ = _land_sites(None)
        chunk = MapSpec(searched, tuple(land[:1]), loads, relative=True).sites_per_chunk
        _, sites = _land_sites(chunk + 1)
        cost = phases(searched, sites, loads, relative=True)
        print(f"W5's sites ({chunk} of the 1-degree land grid, a run's chunk, fold angles searched, "
              f"{args.step_min:g}-min steps): ", end="")
        _print_phases(cost)
        per_site = cost["per_site_s"]
        print(f"the {len(land):,} land sites at that cost: {len(land) * per_site / 3600:.2f} core-hours; "
              f"on 100 workers {len(land) * per_site / 100:.0f} s of compute plus the cluster's start")
        return
    if args.w5:
        w5(args.sites if "--sites" in sys.argv else None, step_min=args.step_min)
        return
    spec = _spec(args.sites)
    if args.phases:
        _print_phases(phases(spec.study, list(spec.sites[:21]), spec.loads, spec.relative, spec.year))
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
