"""Sweeps: many sites, days, loads and designs, as one tidy table.

Cases that differ only in the load share a day: its power is computed once for every fold angle
and ``t_solar`` for all loads comes from one broadcast pass. Days of the same electrical setup
share their tables. The optimal fold angle of a case is the best point of the sweep grid (no
local refinement, which a single-study run adds).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from foldopt.config import Plan
from foldopt.metrics import daily_metrics, t_solar
from foldopt.study import Day

DESIGNS = ("flat", "twofold", "tracker", "tracker-net")
_LOAD_CHUNK_VALUES = 4_000_000  # floats per t_solar pass, to bound memory


@dataclass(frozen=True)
class SweepResult:
    """A plan and its tidy table: one row per case x design."""

    plan: Plan
    table: pd.DataFrame

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


def _day_rows(day: Day, loads: np.ndarray, case: dict) -> list[dict]:
    study, step = day.study, day.step_hours
    angles = np.asarray(study.fold_angles.grid())
    power = day.combined_power(angles)
    chunk = max(1, _LOAD_CHUNK_VALUES // power.size)
    hours = np.concatenate(
        [t_solar(power, loads[i : i + chunk, None], step) for i in range(0, loads.size, chunk)]
    )
    best = _best_angle_index(hours)
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


def _electrical_key(study) -> tuple:
    s = study.resolved()
    return (s.pv_model, s.module, s.panel.efficiency, s.panel.area, s.temp_air, s.wind_speed,
            s.temperature_model, s.bypass_diodes, s.switch_series, s.converter_efficiency, s.exact_electrical)


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
    paths = list(axes)
    groups = list(itertools.product(*axes.values()))
    tables: dict[tuple, object] = {}
    rows = []
    for done, values in enumerate(groups, start=1):
        choice = dict(zip(paths, values, strict=True))
        study = plan.study({**choice, "p_load": float(loads[0])})
        key = _electrical_key(study)
        day = Day(study, tables.get(key))
        tables[key] = day.electrical
        site = day.study.site
        case = {
            "site_name": site.name or "",
            "latitude": site.latitude,
            "longitude": site.longitude,
            "date": day.study.date.isoformat(),
            "day_of_year": day.study.date.timetuple().tm_yday,
            **{path: _plain(value) for path, value in choice.items() if path not in _AXIS_COLUMNS},
        }
        rows += _day_rows(day, loads, case)
        if progress is not None:
            progress(done, len(groups))
    return SweepResult(plan, pd.DataFrame(rows))


def _plain(value):
    return value.isoformat() if hasattr(value, "isoformat") else value
