"""Sweeps: many sites, days, loads and designs, as one tidy table.

Cases that differ only in the load share a day: its power is computed once for every fold angle
and ``t_solar`` for all loads comes from one broadcast pass. Days of the same electrical setup
share their tables. The optimal fold angle of a case is the best point of the sweep grid (no
local refinement, which a single-study run adds).
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from foldopt.config import Plan
from foldopt.metrics import daily_metrics, t_solar, t_solar_many_loads
from foldopt.study import Day

DESIGNS = ("flat", "twofold", "tracker", "tracker-net")
_MANY_LOADS = 4  # from this many loads, one sorted pass beats a pass per load


@dataclass(frozen=True)
class SweepResult:
    """A plan and its tidy table: one row per case x design."""

    plan: Plan
    table: pd.DataFrame
    extras: dict = dataclasses.field(default_factory=dict)  # day x hour curves of an annual objective

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


def _angle_hours(day: Day, loads: np.ndarray):
    """Fold-angle grid, twofold power (k, n_time) and t_solar for every load and angle (L, k)."""
    angles = np.asarray(day.study.fold_angles.grid())
    power = day.combined_power(angles)
    if loads.size >= _MANY_LOADS:
        return angles, power, t_solar_many_loads(power, loads, day.step_hours).T
    return angles, power, t_solar(power, loads[:, None], day.step_hours)


def _day_rows(day: Day, loads: np.ndarray, case: dict, fixed_angles=None) -> list[dict]:
    """Rows of one day for every load; the twofold panel at its best angle of the day, or at
    ``fixed_angles`` (one per load) when a study-wide objective chose them."""
    step = day.step_hours
    if fixed_angles is None:
        angles, power, hours = _angle_hours(day, loads)
        best = _best_angle_index(hours)
    else:
        angles = np.asarray(fixed_angles, dtype=float)
        power = day.combined_power(angles)
        best = np.arange(loads.size)
    p_tracker = day.tracker_power()
    curves = {
        "flat": (np.full(loads.size, 180.0), np.broadcast_to(day.flat_power(), (loads.size, power.shape[1]))),
        "twofold": (angles[best], power[best]),
        "tracker": (np.full(loads.size, np.nan), np.broadcast_to(p_tracker, (loads.size, power.shape[1]))),
        "tracker-net": (
            np.full(loads.size, np.nan),
            np.broadcast_to(p_tracker - day.tracker_draw(), (loads.size, power.shape[1])),
        ),
    }
    metrics = {name: daily_metrics(curve, loads, step) for name, (_, curve) in curves.items()}
    flat_hours, tracker_hours = metrics["flat"]["t_solar_h"], metrics["tracker"]["t_solar_h"]
    sun_up = bool(np.any(day.dni > 0))
    rows = []
    for index, load in enumerate(loads):
        for name in DESIGNS:
            values = {key: float(value[index]) for key, value in metrics[name].items()}
            hours_now = values["t_solar_h"]
            note = "polar night" if not sun_up else ("load above peak" if hours_now == 0 else "")
            with np.errstate(divide="ignore", invalid="ignore"):
                gain = (hours_now / flat_hours[index] - 1.0) * 100.0 if flat_hours[index] > 0 else np.nan
                share = hours_now / tracker_hours[index] * 100.0 if tracker_hours[index] > 0 else np.nan
            rows.append(
                {
                    **case,
                    "p_load_w": float(load),
                    "design": name,
                    "fold_angle_deg": float(curves[name][0][index]),
                    **values,
                    "gain_vs_flat_pct": gain,
                    "pct_of_tracker_t_solar": share,
                    "note": note,
                }
            )
    return rows


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


def run_plan(plan: Plan, progress: Callable[[int, int], None] | None = None) -> SweepResult:
    """Evaluate every case of a plan: flat, optimal twofold and tracker per case.

    Parameters
    ----------
    plan : Plan
    progress : callable, optional
        Called as ``progress(done, total)`` after each day.

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
    groups = list(itertools.product(*axes.values()))
    tables: dict = {}
    rows, extras = [], {}
    total = len(groups) * (2 * len(dates) if dates else 1)  # an annual group is two passes
    done = 0

    def day_of(choice):
        return Day(plan.study({**choice, "p_load": float(loads[0])}), tables)

    for values in groups:
        choice = dict(zip(paths, values, strict=True))
        if not dates:
            day = day_of(choice)
            rows += _day_rows(day, loads, _case(day, choice))
            done += 1
            if progress is not None:
                progress(done, total)
            continue
        # A fixed panel keeps one fold angle all year: first t_solar of every angle on every day,
        # then the angle that maximises the objective, then each day at that angle.
        days, daily = [], []
        for date in dates:
            days.append(day_of({**choice, "date": date}))  # a day keeps only a few arrays of n_time
            angles, _, hours = _angle_hours(days[-1], loads)
            daily.append(hours)
            done += 1
            if progress is not None:
                progress(done, total)
        months = [date.month for date in dates]
        score = objective_value(np.stack(daily), months, objective.statistic, objective.months)
        fixed = angles[_best_angle_index(score)]
        series = {"p_twofold_w": [], "switch_state": []}
        for day in days:
            rows += _day_rows(day, loads, _case(day, choice), fixed)
            powers, state = day.connections(fixed[:1], series=day.study.switch_series)
            series["p_twofold_w"].append(powers[day.study.connection][0])
            series["switch_state"].append(np.where(powers["switching"][0] > 0, state[0], -1))
            done += 1
            if progress is not None:
                progress(done, total)
        if not extras and len({len(p) for p in series["p_twofold_w"]}) == 1:
            hours_of_day = (day.times - day.times.normalize()) / pd.Timedelta(hours=1)
            extras = {"dates": list(dates), "hours": np.asarray(hours_of_day), "fold_angle": float(fixed[0]),
                      **{key: np.stack(value) for key, value in series.items()}}
    return SweepResult(plan, pd.DataFrame(rows), extras)


def _case(day: Day, choice: dict) -> dict:
    site = day.study.site
    return {
        "site_name": site.name or "",
        "latitude": site.latitude,
        "longitude": site.longitude,
        "date": day.study.date.isoformat(),
        "day_of_year": day.study.date.timetuple().tm_yday,
        **{path: _plain(value) for path, value in choice.items() if path not in _AXIS_COLUMNS},
    }


def _plain(value):
    return value.isoformat() if hasattr(value, "isoformat") else value
