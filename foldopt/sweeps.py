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
from foldopt.metrics import energy, energy_served, metric_columns, notes, relative_to
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
    weather_light: dict | None = None  # a weather file's irradiation and what the steps keep of it


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


@dataclass(frozen=True)
class Blocks:
    """Blocks that share one setup (:func:`_setup_key`): the study's settings at each (site, date),
    and each block's flat panel orientation [deg]."""

    study: Study
    sites: tuple
    dates: tuple
    tilt: np.ndarray
    azimuth: np.ndarray

    @classmethod
    def of(cls, studies) -> Blocks:
        """One block per study (its site, date and panel)."""
        resolved = [s.resolved() for s in studies]
        return cls(resolved[0], tuple(s.site for s in resolved), tuple(s.date for s in resolved),
                   np.array([s.panel.tilt for s in resolved]), np.array([s.panel.azimuth for s in resolved]))

    @classmethod
    def of_dates(cls, study: Study, dates) -> Blocks:
        """The days of one study at its own site."""
        study = study.resolved()
        count = len(dates)
        return cls(study, (study.site,) * count, tuple(dates), np.full(count, study.panel.tilt),
                   np.full(count, study.panel.azimuth))

    def __len__(self) -> int:
        return len(self.dates)

    def __getitem__(self, part: slice) -> Blocks:
        return Blocks(self.study, self.sites[part], self.dates[part], self.tilt[part], self.azimuth[part])

    def sky(self) -> Sky:
        return build_sky(self.study, self.sites, self.dates)

    def chunks(self, n_loads: int):
        """Slices of blocks whose rows x loads and time steps stay within the chunk bounds."""
        per_block = len(self.study.fold_angles.grid()) * max(n_loads, 1)
        n_steps = round(24 * 60 / self.study.step_min)
        size = max(1, min(CHUNK_ROW_LOADS // per_block, CHUNK_STEPS // n_steps))
        return [slice(start, min(start + size, len(self))) for start in range(0, len(self), size)]


def fold_hours(sky: Sky, blocks: Blocks, loads, engine: str = "numba"):
    """t_solar [h] of every block's twofold panel at every angle of the grid, for every load.

    Returns
    -------
    angles : numpy.ndarray
        The study's fold-angle grid [deg], (n_angles,).
    hours : numpy.ndarray
        (n_blocks, n_angles, n_loads).
    energy : numpy.ndarray
        Harvested energy [Wh], (n_blocks, n_angles).
    """
    study = blocks.study
    angles = np.asarray(study.fold_angles.grid())
    orientation = engines.fold_orientations(study, blocks.tilt, blocks.azimuth, angles)
    rows = np.repeat(np.arange(sky.n_blocks), angles.size)
    metrics = engines.row_metrics(sky, study, rows, orientation.reshape(-1, 4), loads, outputs=(study.connection,),
                                  engine=engine)
    return (angles, metrics.t_solar.reshape(sky.n_blocks, angles.size, -1),
            metrics.energy.reshape(sky.n_blocks, angles.size))


def _design_metrics(sky: Sky, blocks: Blocks, loads, angles, chosen, engine: str) -> dict:
    """Metrics of every design per block and load, each (n_blocks, n_loads, 4 designs): the twofold
    panel at grid index ``chosen`` (n_blocks, n_loads), the flat panel, the tracker gross and net."""
    study = blocks.study
    n_blocks, n_loads = sky.n_blocks, loads.size
    tilt, azimuth = blocks.tilt, blocks.azimuth
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
    tracker_poa = energy(engines.poa(sky, *orientation, incident=True), sky.step_hours)
    net = gross - sky_tracker_draw(sky, study, orientation)
    shape = sky.load_shape
    trackers = engines.curve_metrics(np.concatenate([gross, net]), loads, sky.step_hours, contiguous=True,
                                     engine=engine, load_shape=None if shape is None else np.concatenate([shape, shape]))

    def per_design(twofold_values, flat_values, tracker_values):
        return np.stack([flat_values, twofold_values.reshape(n_blocks, n_loads), tracker_values[:n_blocks],
                         tracker_values[n_blocks:]], axis=-1)

    hours = per_design(twofold.t_solar[:, 0, 0], flat.t_solar[:, 0], trackers.t_solar[:, 0])
    served = None
    if shape is not None:
        # A load profile's served energy integrates P_load(t) over the solar-powered time: from the curves.
        step = sky.step_hours
        curves = [engines.powers(sky, study, every[np.arange(n_blocks), chosen[:, index]], series=study.switch_series
                                 )[0][study.connection] for index in range(n_loads)]
        twofold_served = np.stack([energy_served(curve, load, shape, step, twofold.t_solar[index::n_loads, 0, 0])
                                   for index, (curve, load) in enumerate(zip(curves, loads, strict=True))], 1)
        flat_curve = engines.powers(sky, study, engines.flat_orientation(tilt, azimuth), series=False)[0]["panel"]
        served = np.stack([energy_served(flat_curve, loads, shape, step, flat.t_solar[:, 0]), twofold_served,
                           energy_served(gross, loads, shape, step, trackers.t_solar[:n_blocks, 0]),
                           energy_served(net, loads, shape, step, trackers.t_solar[n_blocks:, 0])], axis=-1)
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
            served,
        ),
        "poa_kwh_m2": per_design(twofold.irradiation, np.repeat(flat.irradiation[:, None], n_loads, axis=1),
                                 np.repeat(np.r_[tracker_poa, tracker_poa][:, None], n_loads, axis=1)) / 1000.0,
        "condition": np.broadcast_to(sky.conditions()[:, None, None], hours.shape),
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
        Called as ``progress(done, total)`` with the days done so far, counted once per case
        (an annual objective passes over each day twice: halves count).
    engine : {'numba', 'numpy'}
        :data:`foldopt.engine.ENGINES`.

    Returns
    -------
    SweepResult
        Columns: the case (``site_name``, ``latitude``, ``longitude``, ``date``, ``day_of_year``,
        ``p_load_w`` and any other swept field by its path), ``design``, ``fold_angle_deg`` and the
        daily metrics, ``gain_vs_flat_pct``, ``pct_of_tracker_t_solar`` and ``note``
        (:func:`foldopt.metrics.notes`: polar night, polar day, overcast, load above peak).
    """
    axes = dict(plan.axes)
    loads = np.asarray(axes.pop("p_load", (plan.data.get("p_load"),)), dtype=float)
    objective = plan.base.objective
    dates = axes.pop("date", None) if objective is not None else None
    paths = list(axes)
    choices = [dict(zip(paths, values, strict=True)) for values in itertools.product(*axes.values())]
    # A fixed panel keeps one fold angle all year: an annual group is the dates of one choice.
    studies = [plan.study({**choice, "p_load": float(loads[0]), **({"date": dates[0]} if dates else {})})
               for choice in choices]
    passes = 2 if dates else 1  # an annual group: find the angle over the days, then evaluate them
    total = len(choices) * (len(dates) if dates else 1)
    done = 0

    def advance(count):
        nonlocal done
        done += count
        if progress is not None:
            progress(done / passes, total)

    results: list = [None] * len(choices)
    extras: dict = {}
    light: dict = {}

    def counted(sky: Sky) -> Sky:
        for key, (total, kept) in (sky.weather_balance or {}).items():
            light[key] = np.add(light.get(key, (0.0, 0.0)), (total, kept))
        return sky

    if dates:
        refolds: dict[str, list] = {}
        for index, study in enumerate(studies):
            results[index], group_extras = _annual_group(Blocks.of_dates(study, dates), loads, objective, advance,
                                                         engine, counted)
            extras = extras or group_extras
            for key in REFOLD_TABLES:
                if key in group_extras:
                    refolds.setdefault(key, []).append(group_extras[key].assign(
                        **{path: _plain(value) for path, value in choices[index].items() if path not in _AXIS_COLUMNS}))
        extras.update({key: pd.concat(frames, ignore_index=True) for key, frames in refolds.items()})
        cases = [(study.site, date, choice) for study, choice in zip(studies, choices, strict=True) for date in dates]
    else:
        # Cases of one setup share skies and engine calls, whatever their order in the plan.
        setups: dict[str, list[int]] = {}
        for index, study in enumerate(studies):
            setups.setdefault(_setup_key(study), []).append(index)
        for members in setups.values():
            blocks = Blocks.of([studies[i] for i in members])
            for part in blocks.chunks(loads.size):
                chunk = blocks[part]
                sky = counted(chunk.sky())
                angles, hours, _ = fold_hours(sky, chunk, loads, engine)
                metrics = _design_metrics(sky, chunk, loads, angles, _best_angle_index(hours.transpose(0, 2, 1)),
                                          engine)
                for offset, index in enumerate(members[part]):
                    results[index] = {name: values[offset:offset + 1] for name, values in metrics.items()}
                advance(len(chunk))
        cases = [(study.site, study.date, choice) for study, choice in zip(studies, choices, strict=True)]
    table = _table(cases, loads, {name: np.concatenate([r[name] for r in results]) for name in results[0]})
    kept = {key: {"file_wh_m2": float(total), "kept_pct": float(100 * kept / total) if total else 100.0}
            for key, (total, kept) in light.items()} or None
    return SweepResult(plan, table, extras, engine, kept)


def _annual_group(blocks: Blocks, loads, objective, advance, engine, counted):
    """One fold angle per load for all the days of a group: the one that maximises the objective
    over the days' t_solar at every angle. Returns the group's metrics and its day x hour curves."""
    parts = blocks.chunks(loads.size)
    skies, daily = [], []
    for part in parts:
        skies.append(counted(blocks[part].sky()))
        angles, hours, _ = fold_hours(skies[-1], blocks[part], loads, engine)
        daily.append(hours)
        advance(len(blocks[part]))
    months = [date.month for date in blocks.dates]
    daily = np.concatenate(daily).transpose(0, 2, 1)  # (days, loads, angles)
    score = objective_value(daily, months, objective.statistic, objective.months)
    fixed = _best_angle_index(score)  # (n_loads,)
    metrics, series = [], {"p_twofold_w": [], "switch_state": []}
    study = blocks.study
    for part, sky in zip(parts, skies, strict=True):
        chunk = blocks[part]
        metrics.append(_design_metrics(sky, chunk, loads, angles, np.broadcast_to(fixed, (sky.n_blocks, loads.size)),
                                       engine))
        # The day x hour maps of the first load's angle, every day at once.
        orientation = engines.fold_orientations(study, chunk.tilt, chunk.azimuth, angles[fixed[:1]])[:, 0]
        powers, state = engines.powers(sky, study, orientation, series=study.switch_series, with_state=True)
        series["p_twofold_w"].append(powers[study.connection])
        series["switch_state"].append(np.where(powers["switching"] > 0, state, -1))
        advance(len(chunk))
    clock = skies[0].grid.clock_hours[0]
    refold = {}
    if objective.visits:
        hours = np.concatenate([m["t_solar_h"] for m in metrics])  # (days, loads, designs)
        refold = refold_tables(blocks, loads, angles, daily, months, objective, hours)
    extras = {"dates": list(blocks.dates), "hours": clock, "fold_angle": float(angles[fixed[0]]), **refold,
              **{key: np.concatenate(value) for key, value in series.items()},
              "by_angle": pd.DataFrame({
                  "p_load_w": np.repeat(loads, angles.size), "fold_angle_deg": np.tile(angles, loads.size),
                  "objective_h": score.ravel(), "mean_t_solar_h": daily.mean(axis=0).ravel(),
                  "min_t_solar_h": daily.min(axis=0).ravel(), "chosen": np.ravel(np.arange(angles.size) == fixed[:, None]),
              })}
    return {name: np.concatenate([m[name] for m in metrics]) for name in metrics[0]}, extras


def _table(cases, loads, metrics) -> pd.DataFrame:
    """The tidy table: per case (site, date, axis choice), load and design, in that order."""
    n_cases, n_loads, n_designs = len(cases), loads.size, len(DESIGNS)
    repeat = n_loads * n_designs
    columns = {}
    case_rows = [_case(*case) for case in cases]
    for name in case_rows[0]:
        columns[name] = np.repeat(np.array([row[name] for row in case_rows], dtype=object), repeat)
    columns["p_load_w"] = np.tile(np.repeat(loads, n_designs), n_cases)
    columns["design"] = np.tile(np.array(DESIGNS, dtype=object), n_cases * n_loads)
    columns["fold_angle_deg"] = metrics["fold_angle_deg"].ravel()
    hours = metrics["t_solar_h"]
    for name in metrics:
        if name not in ("fold_angle_deg", "condition"):
            columns[name] = metrics[name].ravel()
    columns["gain_vs_flat_pct"] = ((relative_to(hours, hours[..., :1]) - 1.0) * 100.0).ravel()
    columns["pct_of_tracker_t_solar"] = (relative_to(hours, hours[..., 2:3]) * 100.0).ravel()
    columns["note"] = notes(metrics["condition"], hours).ravel()
    table = pd.DataFrame(columns)
    for name in case_rows[0]:
        table[name] = table[name].infer_objects()
    return table


def _case(site, date, choice: dict) -> dict:
    return {
        "site_name": site.name or "",
        "latitude": site.latitude,
        "longitude": site.longitude,
        "date": date.isoformat(),
        "day_of_year": date.timetuple().tm_yday,
        **{path: _plain(value) for path, value in choice.items() if path not in _AXIS_COLUMNS},
    }


def _plain(value):
    return value.isoformat() if hasattr(value, "isoformat") else value


REFOLD_TABLES = ("refold_value", "refold_schedule")


def refold_tables(blocks: Blocks, loads, angles, daily, months, objective, design_hours) -> dict:
    """The best re-fold schedules of one annual group (:func:`foldopt.schedule.best_schedules`):

    ``refold_value``, per load and number of settings k: the objective and the mean daily t_solar
    [h], the gain over the single fixed angle [%] and what the k-th setting adds [h], beside the
    flat panel's and the tracker's objective; ``refold_schedule``, per load, k and visit: the date
    and the fold angle set until the next visit (the last runs on over New Year).

    ``daily`` is (days, loads, angles) t_solar, ``design_hours`` (days, loads, designs) in
    :data:`DESIGNS` order."""
    from foldopt.schedule import best_schedules

    statistic = objective.statistic
    site = blocks.study.site
    where = {"site_name": site.name or "", "latitude": site.latitude, "longitude": site.longitude}
    values, visits = [], []
    for index, load in enumerate(loads):
        schedules = best_schedules(daily[:, index, :], months, objective.visits, statistic)
        flat, tracker = (objective_value(design_hours[:, index, d], months, statistic) for d in (0, 2))
        fixed = schedules[0].objective_h
        previous = None
        for k, schedule in enumerate(schedules, start=1):
            chosen = daily[np.arange(len(months)), index, schedule.daily_angles(len(months))]
            values.append({**where, "p_load_w": float(load), "settings": k, "objective": statistic,
                           "objective_h": schedule.objective_h, "mean_t_solar_h": float(chosen.mean()),
                           "gain_vs_fixed_pct": 100.0 * (schedule.objective_h / fixed - 1.0) if fixed > 0 else np.nan,
                           "added_by_setting_h": np.nan if previous is None else schedule.objective_h - previous,
                           "flat_objective_h": float(flat), "tracker_objective_h": float(tracker)})
            previous = schedule.objective_h
            for visit, (start, angle) in enumerate(zip(schedule.starts, schedule.angles, strict=True), start=1):
                visits.append({**where, "p_load_w": float(load), "settings": k, "visit": visit,
                               "date": blocks.dates[start].isoformat(), "fold_angle_deg": float(angles[angle])})
    return {"refold_value": pd.DataFrame(values), "refold_schedule": pd.DataFrame(visits)}