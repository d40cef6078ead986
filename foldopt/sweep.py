"""Sweeps: many sites, days, loads and designs, as one tidy table.

The cases of a plan are blocks of skies (:mod:`foldopt.sky`): cases that share everything but the
site, the date and the load share one sky and one engine call, in chunks of bounded size. Every
(case, fold angle) row gets ``t_solar`` for all loads in one pass; the best angle per case and
load is the best point of the grid (no local refinement, which a single-study run adds), and its
full metrics come from a second, targeted pass. The flat panel is a row of its own; trackers go
through the same metrics from their power curves.
"""

from __future__ import annotations

import dataclasses
import itertools
import json
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from foldopt import engine as engines
from foldopt.config import Plan, Study
from foldopt.metrics import metric_columns
from foldopt.sky import Sky, build_sky
from foldopt.study import sky_tracker_draw, sky_tracker_orientation, sky_tracker_power

DESIGNS = ("flat", "twofold", "tracker", "tracker-net")
#: Rows (blocks x fold angles) x loads of one engine call: bounds the memory of a chunk.
CHUNK_ROW_LOADS = 4_000_000
#: Time steps of the blocks of one chunk's sky.
CHUNK_STEPS = 1_100_000


@dataclass(frozen=True)
class SweepResult:
    """A plan and its tidy table: one row per case x design."""

    plan: Plan
    table: pd.DataFrame
    extras: dict = dataclasses.field(default_factory=dict)  # day x hour curves of an annual objective
    engine: str = "numba"

    @property
    def varied(self) -> list[str]:
        """Table columns that vary across cases."""
        columns = [c for c in CASE_COLUMNS if c in self.table and self.table[c].nunique(dropna=False) > 1]
        extra = [path for path, values in self.plan.axes if path not in _AXIS_COLUMNS and len(values) > 1]
        return columns + extra


CASE_COLUMNS = ("site_name", "latitude", "longitude", "date", "day_of_year", "p_load_w")
#: Axes whose values the case columns above already show.
_AXIS_COLUMNS = frozenset({"site", "site.name", "site.latitude", "site.longitude", "date", "p_load"})


def _best_angle_index(hours):
    """Index of the longest t_solar along the last axis; ties go to the least folded angle."""
    return hours.shape[-1] - 1 - np.argmax(hours[..., ::-1], axis=-1)


def _setup_key(study: Study) -> str:
    """What the blocks of one engine call share: everything but the site, the date and the load
    (and the panel's orientation, which follows the site)."""
    data = study.model_dump(mode="json", exclude={"site", "date", "p_load", "name", "description"})
    data["panel"] = {k: v for k, v in data["panel"].items() if k not in ("tilt", "azimuth")}
    return json.dumps(data, sort_keys=True)


def _chunks(count: int, per_block_rows: int, n_loads: int, n_steps: int):
    """Slices of ``count`` blocks whose rows x loads and time steps stay within the chunk bounds."""
    size = max(1, min(CHUNK_ROW_LOADS // max(per_block_rows * n_loads, 1), CHUNK_STEPS // max(n_steps, 1)))
    return [slice(start, min(start + size, count)) for start in range(0, count, size)]


def _sky(studies) -> Sky:
    return build_sky(studies[0], [s.site for s in studies], [s.date for s in studies])


def _panels(studies):
    resolved = [s.resolved() for s in studies]
    return np.array([s.panel.tilt for s in resolved]), np.array([s.panel.azimuth for s in resolved])


def fold_hours(sky: Sky, studies, loads, engine: str = "numba"):
    """t_solar [h] of every block's twofold panel at every angle of the grid, for every load.

    Returns
    -------
    angles : numpy.ndarray
        The study's fold-angle grid [deg], (n_angles,).
    hours : numpy.ndarray
        (n_blocks, n_angles, n_loads).
    """
    study = studies[0]
    angles = np.asarray(study.fold_angles.grid())
    orientation = engines.fold_orientations(study, *_panels(studies), angles)
    rows = np.repeat(np.arange(sky.n_blocks), angles.size)
    metrics = engines.row_metrics(sky, study, rows, orientation.reshape(-1, 4), loads,
                                  outputs=(study.resolved().connection,), engine=engine)
    return angles, metrics.t_solar.reshape(sky.n_blocks, angles.size, -1)


def _design_metrics(sky: Sky, studies, loads, angles, chosen, engine: str) -> dict:
    """Metrics of every design per block and load, each (n_blocks, n_loads, 4 designs): the twofold
    panel at grid index ``chosen`` (n_blocks, n_loads), the flat panel, the tracker gross and net."""
    study = studies[0].resolved()
    n_blocks, n_loads = sky.n_blocks, loads.size
    tilt, azimuth = _panels(studies)
    every = engines.fold_orientations(study, tilt, azimuth, angles)
    blocks = np.repeat(np.arange(n_blocks), n_loads)
    # One row per block and load, at that load's angle, with the load alone.
    twofold = engines.row_metrics(sky, study, blocks, every[blocks, chosen.ravel()], loads[:, None],
                                  np.tile(np.arange(n_loads), n_blocks), outputs=(study.connection,),
                                  contiguous=True, engine=engine)
    flat = engines.row_metrics(sky, study, np.arange(n_blocks), engines.flat_orientation(tilt, azimuth), loads,
                               outputs=("panel",), contiguous=True, engine=engine)
    orientation = sky_tracker_orientation(sky, study)
    gross = sky_tracker_power(sky, study, orientation)
    net = gross - sky_tracker_draw(sky, study, orientation)
    trackers = engines.curve_metrics(np.concatenate([gross, net]), loads, sky.step_hours, contiguous=True,
                                     engine=engine)

    def per_design(twofold_values, flat_values, tracker_values):
        return np.stack([flat_values, twofold_values.reshape(n_blocks, n_loads), tracker_values[:n_blocks],
                         tracker_values[n_blocks:]], axis=-1)

    hours = per_design(twofold.t_solar[:, 0, 0], flat.t_solar[:, 0], trackers.t_solar[:, 0])
    fold = np.stack([np.full((n_blocks, n_loads), 180.0), angles[chosen], np.full((n_blocks, n_loads), np.nan),
                     np.full((n_blocks, n_loads), np.nan)], axis=-1)
    return {
        "fold_angle_deg": fold,
        **metric_columns(
            hours,
            per_design(twofold.t_solar_contiguous[:, 0, 0], flat.t_solar_contiguous[:, 0],
                       trackers.t_solar_contiguous[:, 0]),
            per_design(twofold.energy[:, 0], np.repeat(flat.energy, n_loads, axis=1),
                       np.repeat(trackers.energy, n_loads, axis=1)),
            per_design(twofold.peak[:, 0], np.repeat(flat.peak, n_loads, axis=1),
                       np.repeat(trackers.peak, n_loads, axis=1)),
            loads[None, :, None],
        ),
        "sun_up": np.broadcast_to(np.any(sky.dni > 0, axis=1)[:, None, None], hours.shape),
    }


def objective_value(hours, months, statistic: str, season=None):
    """A study-wide statistic of daily t_solar: ``hours`` (days, ...) -> (...).

    ``mean``, ``min``, ``pNN`` (the NN-th percentile over days) or ``worst-month`` (the lowest
    monthly mean); ``season`` (months) restricts the days.
    """
    hours, months = np.asarray(hours, dtype=float), np.asarray(months)
    if season:
        keep = np.isin(months, season)
        hours, months = hours[keep], months[keep]
    if statistic == "mean":
        return hours.mean(axis=0)
    if statistic == "min":
        return hours.min(axis=0)
    if statistic == "worst-month":
        return np.min([hours[months == m].mean(axis=0) for m in np.unique(months)], axis=0)
    return np.percentile(hours, float(statistic[1:]), axis=0)


def run_plan(plan: Plan, progress: Callable[[int, int], None] | None = None, engine: str = "numba") -> SweepResult:
    """Evaluate every case of a plan: flat, optimal twofold and tracker per case.

    Parameters
    ----------
    plan : Plan
    progress : callable, optional
        Called as ``progress(done, total)`` with the cases (days) done so far.
    engine : {'numba', 'numpy'}
        :data:`foldopt.engine.ENGINES`.

    Returns
    -------
    SweepResult
        Columns: the case (``site_name``, ``latitude``, ``longitude``, ``date``, ``day_of_year``,
        ``p_load_w`` and any other swept field by its path), ``design``, ``fold_angle_deg`` and the
        daily metrics, ``gain_vs_flat_pct``, ``pct_of_tracker_t_solar`` and ``note`` (``polar
        night`` or ``load above peak`` when ``t_solar`` is 0 for those reasons).
    """
    axes = dict(plan.axes)
    loads = np.asarray(axes.pop("p_load", (plan.data.get("p_load"),)), dtype=float)
    objective = plan.base.objective
    dates = axes.pop("date", None) if objective is not None else None
    paths = list(axes)
    choices = [dict(zip(paths, values, strict=True)) for values in itertools.product(*axes.values())]
    # A fixed panel keeps one fold angle all year: an annual group is the dates of one choice.
    groups = [[{**choice, "date": date} for date in dates] if dates else [choice] for choice in choices]
    studies = [[plan.study({**case, "p_load": float(loads[0])}) for case in group] for group in groups]
    total = sum(len(group) for group in groups) * (2 if dates else 1)
    done = 0

    def advance(count):
        nonlocal done
        done += count
        if progress is not None:
            progress(done, total)

    results: list = [None] * len(groups)
    extras: dict = {}
    if dates:
        for index, group in enumerate(studies):
            results[index], group_extras = _annual_group(group, loads, objective, advance, engine)
            extras = extras or group_extras
    else:
        # Cases of one setup share skies and engine calls, whatever their order in the plan.
        setups: dict[str, list[int]] = {}
        for index, (study,) in enumerate(studies):
            setups.setdefault(_setup_key(study), []).append(index)
        for members in setups.values():
            member_studies = [studies[i][0] for i in members]
            k = len(member_studies[0].fold_angles.grid())
            n_steps = round(24 / (member_studies[0].step_min / 60))
            for part in _chunks(len(members), k, loads.size, n_steps):
                chunk = member_studies[part]
                sky = _sky(chunk)
                angles, hours = fold_hours(sky, chunk, loads, engine)
                metrics = _design_metrics(sky, chunk, loads, angles, _best_angle_index(hours.transpose(0, 2, 1)),
                                          engine)
                for offset, index in enumerate(members[part]):
                    results[index] = {name: values[offset:offset + 1] for name, values in metrics.items()}
                advance(len(chunk))
    table = _table([study for group in studies for study in group],
                   [case for group in groups for case in group], loads,
                   {name: np.concatenate([r[name] for r in results]) for name in results[0]})
    return SweepResult(plan, table, extras, engine)


def _annual_group(studies, loads, objective, advance, engine):
    """One fold angle per load for all the days of a group: the one that maximises the objective
    over the days' t_solar at every angle. Returns the group's metrics and its day x hour curves."""
    n_steps = round(24 / (studies[0].step_min / 60))
    k = len(studies[0].fold_angles.grid())
    parts = _chunks(len(studies), k, loads.size, n_steps)
    skies, daily = [], []
    for part in parts:
        skies.append(_sky(studies[part]))
        angles, hours = fold_hours(skies[-1], studies[part], loads, engine)
        daily.append(hours)
        advance(len(studies[part]))
    months = [study.date.month for study in studies]
    score = objective_value(np.concatenate(daily).transpose(0, 2, 1), months, objective.statistic, objective.months)
    fixed = _best_angle_index(score)  # (n_loads,)
    metrics, series = [], {"p_twofold_w": [], "switch_state": []}
    for part, sky in zip(parts, skies, strict=True):
        chunk = studies[part]
        metrics.append(_design_metrics(sky, chunk, loads, angles, np.broadcast_to(fixed, (sky.n_blocks, loads.size)),
                                       engine))
        # The day x hour maps of the first load's angle, every day at once.
        study = chunk[0].resolved()
        orientation = engines.fold_orientations(study, *_panels(chunk), angles[fixed[:1]])[:, 0]
        powers, state = engines.powers(sky, study, orientation, series=study.switch_series, with_state=True)
        series["p_twofold_w"].append(powers[study.connection])
        series["switch_state"].append(np.where(powers["switching"] > 0, state, -1))
        advance(len(chunk))
    clock = skies[0].grid.clock_hours[0]
    extras = {"dates": [study.date for study in studies], "hours": clock, "fold_angle": float(angles[fixed[0]]),
              **{key: np.concatenate(value) for key, value in series.items()}}
    return {name: np.concatenate([m[name] for m in metrics]) for name in metrics[0]}, extras


def _table(studies, cases, loads, metrics) -> pd.DataFrame:
    """The tidy table: per case, load and design (in that order), the case columns and metrics."""
    n_cases, n_loads, n_designs = len(studies), loads.size, len(DESIGNS)
    repeat = n_loads * n_designs
    columns = {}
    case_rows = [_case(study, case) for study, case in zip(studies, cases, strict=True)]
    for name in case_rows[0]:
        columns[name] = np.repeat(np.array([row[name] for row in case_rows], dtype=object), repeat)
    columns["p_load_w"] = np.tile(np.repeat(loads, n_designs), n_cases)
    columns["design"] = np.tile(np.array(DESIGNS, dtype=object), n_cases * n_loads)
    columns["fold_angle_deg"] = metrics["fold_angle_deg"].ravel()
    hours = metrics["t_solar_h"]
    for name in metrics:
        if name not in ("fold_angle_deg", "sun_up"):
            columns[name] = metrics[name].ravel()
    with np.errstate(divide="ignore", invalid="ignore"):
        flat, tracker = hours[..., :1], hours[..., 2:3]
        columns["gain_vs_flat_pct"] = np.where(flat > 0, (hours / flat - 1.0) * 100.0, np.nan).ravel()
        columns["pct_of_tracker_t_solar"] = np.where(tracker > 0, hours / tracker * 100.0, np.nan).ravel()
    sun_up = metrics["sun_up"].ravel()
    columns["note"] = np.where(~sun_up, "polar night", np.where(hours.ravel() == 0, "load above peak", ""))
    table = pd.DataFrame(columns)
    for name in case_rows[0]:
        table[name] = table[name].infer_objects()
    return table


def _case(study: Study, choice: dict) -> dict:
    site = study.site
    return {
        "site_name": site.name or "",
        "latitude": site.latitude,
        "longitude": site.longitude,
        "date": study.date.isoformat(),
        "day_of_year": study.date.timetuple().tm_yday,
        **{path: _plain(value) for path, value in choice.items() if path not in _AXIS_COLUMNS},
    }


def _plain(value):
    return value.isoformat() if hasattr(value, "isoformat") else value
