"""Many-site studies: where in the world a folded panel pays, for which loads, in which season.

A map is one study (panel, PV and electrical models, tracker, objective) evaluated over a whole
year at every site of a list (:mod:`foldopt.inputs.sites`): a latitude x longitude grid, a table of
named sites or a folder of weather files, each file a site.
Without weather the sky is the study's clear sky (pvlib's Ineichen model with pvlib's monthly
Linke turbidity climatology for a map). Per site, load and period (the year and the four
three-month seasons) the table gives the fold angle that maximises the study's objective over the
period's days, the objective, the mean daily t_solar and the harvested energy of the flat panel,
the twofold panel at that angle and the tracker, and the tracker's break-even standby draw.

Loads are in watts or, with ``relative=True``, fractions of each site's flat peak (the largest
power of the flat panel over the year), so that one map compares like with like from the tropics
to the poles. :mod:`foldopt.studies.map_request` checks a map's sites, loads, year and period once
and makes the map's study a :class:`~foldopt.inputs.study.Study`; the command line hands that
request to :func:`foldopt.world_map` as it is. Each site's study is the map's moved to the site
(:func:`~foldopt.studies.map_request.site_study`).

This module computes; :mod:`foldopt.studies.cluster` spreads the sites over a Dask cluster and writes
the files.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from foldopt.engine import evaluation as engines
from foldopt.engine.choice import engine_for
from foldopt.engine.search import Axis
from foldopt.inputs.optimize_section import DEFAULT_TILT, Optimize
from foldopt.inputs.study import Study
from foldopt.names import DEFAULT_ENGINE, FLAT_FOLD_ANGLE
from foldopt.physics.spa import SunTerms
from foldopt.studies.break_even import break_even_standby
from foldopt.studies.designs import Blocks, setup_key, site_designs
from foldopt.studies.map_request import PERIODS, SEASONS, SITES_PER_BATCH, map_data, site_study
from foldopt.studies.objectives import (
    best_angle_index,
    near_optimal_on_grid,
    objective_value,
    period_days,
    period_values,
)
from foldopt.studies.site_search import fold_search

if TYPE_CHECKING:
    import pandas as pd


def evaluate_sites(
    study: Study | dict,
    sites: Sequence[dict],
    loads: Sequence[float],
    relative: bool = False,
    year: int = 2025,
    engine: str = DEFAULT_ENGINE,
) -> pd.DataFrame:
    """The map's rows for some sites: per site, load and period (:data:`PERIODS`).

    Parameters
    ----------
    study : Study or dict
        The map's study (:func:`map_template`), or a study's fields but ``site``, ``date`` and
        ``p_load``; its ``objective`` (default mean) chooses each period's fold angle.
    sites : sequence of dict
        Each a site's fields (``name``, ``latitude``, ``longitude``, ``altitude``, ``timezone``) or a
        weather file's site (``weather``, the path). A ``site_id`` key, if given, is kept.
    loads : sequence of float
        Loads [W], or with ``relative`` fractions [-] of each site's flat peak.
    relative : bool
    year : int
        The year of clear-sky days, or what a weather file's typical year stands for.
    engine : {'auto', 'numba', 'numpy'}
        ``auto`` is the compiled kernel: a site's numbers are then the same whichever sites share
        its batch (:func:`foldopt.studies.request.request_engine`, a map's).

    Returns
    -------
    pandas.DataFrame
        One row per site, load and period: ``site_id``, ``site_name``, ``latitude``,
        ``longitude``, ``weather``, ``peak_power_flat_w``, ``p_load_w``, ``p_load_frac``,
        ``period``, ``days_n``, ``fold_angle_deg``; the objective [h] of each design
        (``t_solar_flat_objective_h``, ``t_solar_twofold_objective_h``,
        ``t_solar_tracker_objective_h``); mean daily t_solar [h] (``t_solar_flat_mean_h``,
        ``t_solar_twofold_mean_h``, ``t_solar_tracker_mean_h``, the tracker's net of its own draw
        ``t_solar_tracker_net_mean_h``); harvested energy [Wh] (``energy_harvested_flat_wh``,
        ``energy_harvested_twofold_wh``, ``energy_harvested_tracker_wh``); ``gain_vs_flat_pct`` and
        ``share_of_tracker_pct`` (of the objective), ``energy_harvested_gain_vs_flat_pct``; and
        the near-optimal range of the fold angle and the recommended angle at its centre
        (``near_optimal_lo_deg``, ``near_optimal_hi_deg``, ``recommended_deg``,
        ``near_optimal_tolerance_h``: :func:`foldopt.studies.objectives.near_optimal`);
        ``break_even_standby_tracker_w``, the standby draw [W] above which the twofold panel's
        objective exceeds the tracker's (0 where it already does; NaN where the twofold panel
        never carries the load).
    """
    import pandas as pd

    loads = np.asarray(loads, dtype=float)
    engine = engine_for(engine, math.inf)
    frames, batch, key = [], [], None
    study = map_data(study)  # once, not per site
    sun_terms = SunTerms()  # the sites of one year share every instant of SPA's time-only terms
    for site in sites:
        here, dates = site_study(study, site, year)
        this = setup_key(here)
        if batch and (this != key or len(batch) == SITES_PER_BATCH):
            frames.append(_evaluate_batch(batch, loads, relative, engine, sun_terms))
            batch = []
        batch.append((site, here, dates))
        key = this
    if batch:
        frames.append(_evaluate_batch(batch, loads, relative, engine, sun_terms))
    return pd.concat(frames, ignore_index=True)


def _evaluate_batch(batch, loads, relative: bool, engine: str, sun_terms: SunTerms) -> pd.DataFrame:
    """The rows of sites that share a setup (:func:`foldopt.studies.designs.setup_key`), their days
    one set of blocks: every engine call runs over all of them (:func:`site_designs`)."""
    import pandas as pd

    blocks = Blocks.join([Blocks.of_dates(study, dates) for _, study, dates in batch])
    study = blocks.study
    objective = study.objective
    statistic = objective.statistic if objective is not None else "mean"
    starts = np.cumsum([0, *(len(dates) for _, _, dates in batch)])
    sites = [range(first, stop) for first, stop in zip(starts[:-1], starts[1:], strict=True)]
    parts = [(blocks[part], blocks[part].sky(sun_terms)) for part in blocks.chunks(loads.size)]
    step_hours = parts[0][1].step_hours
    flat_peak = None
    if relative:
        # Loads as fractions of each site's flat peak over all its days: the flat panel's pass for
        # its peak comes before the loads, and site_designs' flat pass needs them.
        peak = np.concatenate(
            [
                engines.row_metrics(
                    sky,
                    rows=engines.PanelRows(
                        np.arange(sky.n_blocks), engines.flat_orientation(chunk.tilt, chunk.azimuth)
                    ),
                    loads=[1.0],
                    electrical=chunk.options.electrical,
                    outputs=("panel",),
                    engine=engine,
                ).peak[:, 0]
                for chunk, sky in parts
            ]
        )
        flat_peak = np.array([float(peak[days].max()) for days in sites])
    p_load = (
        loads[None, :] * flat_peak[:, None]
        if relative
        else np.broadcast_to(loads, (len(batch), loads.size))
    )
    # A load of 0 W (a site whose flat panel never sees the sun) has no t_solar to speak of.
    p_load_evaluated = np.where(p_load > 0, p_load, np.inf)
    months = [np.array([date.month for date in dates]) for _, _, dates in batch]
    seasons = [None, *SEASONS.values()]
    # A map searches the fold angles (foldopt.studies.site_search) unless its study sweeps them all.
    search = study.optimize
    searcher = (
        None
        if search is None
        else fold_search(months, statistic, seasons, search.tolerance_h, _tilt_axis(search))
    )
    designs = site_designs(parts, sites, p_load_evaluated, engine, searcher)
    if flat_peak is None:
        # Loads in watts: the peak of the flat panel's one pass, the one its rows come from.
        flat_peak = np.array([float(days_of.peak_power_flat_w.max()) for days_of in designs])
    columns: dict[str, list] = {}
    for (site, here, _), days_of, site_months, peak_w, site_p_load, site_p_load_evaluated in zip(
        batch, designs, months, flat_peak, p_load, p_load_evaluated, strict=True
    ):
        for name, values in _site_rows(
            days_of, site_months, statistic, seasons, site_p_load_evaluated, study, here.panel.tilt
        ).items():
            columns.setdefault(name, []).append(values)
        count = len(PERIODS) * loads.size
        fixed = {
            "site_id": site.get("site_id", 0),
            "site_name": site.get("name") or "",
            "latitude": here.site.latitude,
            "longitude": here.site.longitude,
            "weather": Path(site["weather"]).name if "weather" in site else "",
            "peak_power_flat_w": peak_w,
        }
        for name, value in fixed.items():
            columns.setdefault(name, []).append(
                np.full(count, value, dtype=object if isinstance(value, str) else None)
            )
        columns.setdefault("p_load_w", []).append(np.tile(site_p_load, len(PERIODS)))
        fraction = site_p_load / peak_w if peak_w > 0 else np.full(loads.size, np.nan)
        columns.setdefault("p_load_frac", []).append(np.tile(fraction, len(PERIODS)))
    # The tracker's break-even standby of every site of the same days at once (their sites' own else).
    targets = np.stack(columns["t_solar_twofold_objective_h"]).reshape(
        len(batch), len(PERIODS), loads.size
    )
    same_days = all(np.array_equal(site_months, months[0]) for site_months in months)
    groups = [list(range(len(batch)))] if same_days else [[site] for site in range(len(batch))]
    standby = np.empty(targets.shape)
    for group in groups:
        standby[group] = break_even_standby(
            np.concatenate([designs[i].available for i in group]),
            targets[group],
            p_load_evaluated[group],
            months[group[0]],
            statistic,
            seasons,
            step_hours,
            engine,
        )
    columns["break_even_standby_tracker_w"] = list(standby.reshape(len(batch), -1))
    order = [
        "site_id",
        "site_name",
        "latitude",
        "longitude",
        "weather",
        "peak_power_flat_w",
        "p_load_w",
        "p_load_frac",
        "period",
        "days_n",
        "fold_angle_deg",
        "surface_tilt",
        "surface_tilt_flat_deg",
        *ROW_VALUES,
        "gain_vs_flat_pct",
        "energy_harvested_gain_vs_flat_pct",
        "share_of_tracker_pct",
        "break_even_standby_tracker_w",
    ]
    return pd.DataFrame({name: np.concatenate(columns[name]) for name in order})


def searched_tilt(study: Study) -> Axis | None:
    """The base tilt's range [deg] a map's study searches with the fold angle (``foldopt map
    --optimize tilt``), or None where the panel keeps the site's tilt."""
    return None if study.optimize is None else _tilt_axis(study.optimize)


def _tilt_axis(search: Optimize) -> Axis | None:
    """The base tilt's range a map's ``optimize`` section searches, or None (the site's tilt)."""
    return Axis("tilt", *search.range_of("tilt", DEFAULT_TILT)) if "tilt" in search.vary else None


#: The values of a map's row from the designs (in the order of its table).
ROW_VALUES = (
    "t_solar_flat_objective_h",
    "t_solar_twofold_objective_h",
    "t_solar_tracker_objective_h",
    "t_solar_tracker_net_objective_h",
    "t_solar_flat_mean_h",
    "t_solar_twofold_mean_h",
    "t_solar_tracker_mean_h",
    "t_solar_tracker_net_mean_h",
    "energy_harvested_flat_wh",
    "energy_harvested_twofold_wh",
    "energy_harvested_tracker_wh",
    "near_optimal_lo_deg",
    "near_optimal_hi_deg",
    "recommended_deg",
    "near_optimal_tolerance_h",
)


def _chosen(hours, energy, months, statistic: str, seasons, member):
    """Each period's and load's best of some designs, and the objective, the mean daily t_solar and
    the harvested energy there: ``hours`` (days, loads, n), ``energy`` (days, n) -> ``best``,
    ``objective``, ``mean_h`` and ``energy_wh``, each (periods, loads); also every design's
    objective, (periods, loads, n)."""
    n_loads = hours.shape[1]
    every = period_values(hours, months, statistic, seasons, member)  # (periods, loads, n)
    # (periods, loads); ties to the last (the least folded, the steepest)
    best = best_angle_index(every)
    at_best = hours[:, np.arange(n_loads)[None, :], best]  # (days, periods, loads)
    objective = np.stack(
        [
            objective_value(at_best[:, period], months, statistic, season)
            for period, season in enumerate(seasons)
        ]
    )
    mean_h = np.stack([at_best[days, period].mean(axis=0) for period, days in enumerate(member)])
    energy_wh = np.stack(
        [energy[days][:, best[period]].sum(axis=0) for period, days in enumerate(member)]
    )
    return best, objective, mean_h, energy_wh, every


def _site_rows(
    days_of, months, statistic: str, seasons, p_load_evaluated, study, surface_tilt: float
) -> dict:
    """One site's columns, per period and load (periods slowest), from its :class:`DailyDesigns`."""
    angles, tilts, twofold_h, twofold_energy = (
        days_of.angles,
        days_of.tilts,
        days_of.twofold_h,
        days_of.twofold_wh,
    )
    n_loads = p_load_evaluated.size
    member = period_days(months, seasons)
    # The flat panel at the site's mounting, or at each period's and load's own best tilt.
    flat_hours, flat_energy, flat_tilts = (
        days_of.flat_h[..., None],
        days_of.flat_wh[:, None],
        np.array([surface_tilt]),
    )
    if days_of.flat_tilted is not None:
        flat_tilts, flat_hours, flat_energy = days_of.flat_tilted
        # A 180 deg fold is the flat panel: each search's designs are the other's too (the
        # twofold panel's where its fold angles reach 180 deg), so that neither's best misses one
        # the other evaluated.
        unfolded = angles == FLAT_FOLD_ANGLE
        flat_tilts = np.concatenate([flat_tilts, tilts[unfolded]])
        order = np.argsort(flat_tilts, kind="stable")  # ties to the steepest, as the search's
        flat_tilts, flat_hours, flat_energy = (
            flat_tilts[order],
            np.concatenate([flat_hours, twofold_h[..., unfolded]], axis=-1)[..., order],
            np.concatenate([flat_energy, twofold_energy[:, unfolded]], axis=-1)[:, order],
        )
        if study.fold_angles.stop == FLAT_FOLD_ANGLE:
            angles = np.concatenate([angles, np.full(flat_tilts.size, FLAT_FOLD_ANGLE)])
            tilts = np.concatenate([tilts, flat_tilts])
            # In ascending order of the fold angle, then the tilt, as the search's designs are.
            order = np.lexsort((tilts, angles))
            angles, tilts = angles[order], tilts[order]
            twofold_h = np.concatenate([twofold_h, flat_hours], axis=-1)[..., order]
            twofold_energy = np.concatenate([twofold_energy, flat_energy], axis=-1)[:, order]
    best, twofold, twofold_mean, twofold_wh, objective = _chosen(
        twofold_h, twofold_energy, months, statistic, seasons, member
    )
    flat_best, flat, flat_mean, flat_wh, _ = _chosen(
        flat_hours, flat_energy, months, statistic, seasons, member
    )
    trackers = np.stack([days_of.tracker_h, days_of.tracker_net_h], axis=1)  # (days, 2, loads)
    tracker, tracker_mean = (
        period_values(trackers, months, kind, seasons, member) for kind in (statistic, "mean")
    )
    tracker_wh = np.stack([days_of.tracker_wh[days].sum() for days in member])
    # The fold angle's near-optimal range: over the tilts too (the best of them at each angle) where searched.
    fold_angles, profile = angles, objective.reshape(-1, angles.size)
    if tilts is not None:
        fold_angles, column = np.unique(angles, return_inverse=True)
        profile = np.full((profile.shape[0], fold_angles.size), -np.inf)
        np.maximum.at(profile, (slice(None), column.ravel()), objective.reshape(-1, angles.size))
    ranges = near_optimal_on_grid(
        fold_angles, profile, study.near_optimal, np.asarray(study.fold_angles.grid())
    )
    carried = np.isfinite(p_load_evaluated)
    rows = {
        "period": np.repeat(np.array(PERIODS, dtype=object), n_loads),
        "days_n": np.repeat(member.sum(axis=1), n_loads),
        "fold_angle_deg": np.where(carried, angles[best], np.nan).ravel(),
        "surface_tilt": np.where(
            carried,
            tilts[best] if tilts is not None else np.full(best.shape, surface_tilt),
            np.nan,
        ).ravel(),
        "surface_tilt_flat_deg": np.where(carried, flat_tilts[flat_best], np.nan).ravel(),
        "t_solar_flat_objective_h": flat.ravel(),
        "t_solar_twofold_objective_h": twofold.ravel(),
        "t_solar_tracker_objective_h": tracker[:, 0].ravel(),
        "t_solar_tracker_net_objective_h": tracker[:, 1].ravel(),
        "t_solar_flat_mean_h": flat_mean.ravel(),
        "t_solar_twofold_mean_h": twofold_mean.ravel(),
        "t_solar_tracker_mean_h": tracker_mean[:, 0].ravel(),
        "t_solar_tracker_net_mean_h": tracker_mean[:, 1].ravel(),
        "energy_harvested_flat_wh": flat_wh.ravel(),
        "energy_harvested_twofold_wh": twofold_wh.ravel(),
        "energy_harvested_tracker_wh": np.repeat(tracker_wh, n_loads),
        **ranges,
    }
    with np.errstate(divide="ignore", invalid="ignore"):
        gain = 100.0 * (
            rows["t_solar_twofold_objective_h"] / rows["t_solar_flat_objective_h"] - 1.0
        )
        energy_gain = 100.0 * (
            rows["energy_harvested_twofold_wh"] / rows["energy_harvested_flat_wh"] - 1.0
        )
        share = 100.0 * rows["t_solar_twofold_objective_h"] / rows["t_solar_tracker_objective_h"]
    rows["gain_vs_flat_pct"] = np.where(rows["t_solar_flat_objective_h"] > 0, gain, np.nan)
    rows["energy_harvested_gain_vs_flat_pct"] = energy_gain
    rows["share_of_tracker_pct"] = np.where(rows["t_solar_tracker_objective_h"] > 0, share, np.nan)
    return rows
