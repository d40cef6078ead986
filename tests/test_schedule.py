"""Re-fold schedules: the dynamic programme against brute force on small years, and on a real
year against the single fixed angle and the day-by-day optimum that bound it."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from foldopt.engine.schedule import best_schedules


def _brute_force_mean(hours, k):
    """Every set of k visit days, each arc at its best angle: the best mean daily t_solar."""
    n_days = hours.shape[0]
    best = -np.inf
    for starts in itertools.combinations(range(n_days), k):
        total = 0.0
        for position, start in enumerate(starts):
            stop = starts[position + 1] if position + 1 < k else starts[0] + n_days
            days = [(start + d) % n_days for d in range(stop - start)]
            total += hours[days].sum(axis=0).max()
        best = max(best, total / n_days)
    return best


def _brute_force_worst_month(hours, months, k):
    """Every set of k month starts and every angle of every arc: the best lowest monthly mean."""
    present = np.unique(months)
    n_angles = hours.shape[1]
    best = -np.inf
    for cuts in itertools.combinations(range(present.size), k):
        for angles in itertools.product(range(n_angles), repeat=k):
            daily = np.empty(hours.shape[0], dtype=int)
            for position, cut in enumerate(cuts):
                stop = cuts[position + 1] if position + 1 < k else cuts[0] + present.size
                for m in range(cut, stop):
                    daily[months == present[m % present.size]] = angles[position]
            chosen = hours[np.arange(hours.shape[0]), daily]
            best = max(best, min(chosen[months == m].mean() for m in present))
    return best


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), n_days=st.integers(5, 13), n_angles=st.integers(1, 4))
def test_mean_schedule_is_the_brute_force_optimum(seed, n_days, n_angles):
    hours = np.random.default_rng(seed).uniform(0, 12, (n_days, n_angles))
    schedules = best_schedules(hours, np.ones(n_days), min(4, n_days))
    for k, schedule in enumerate(schedules, start=1):
        assert schedule.objective_h == pytest.approx(_brute_force_mean(hours, k), abs=1e-12)
        # The stated schedule reaches the stated value, with k settings on k distinct days.
        daily = schedule.daily_angles(n_days)
        assert hours[np.arange(n_days), daily].mean() == pytest.approx(schedule.objective_h, abs=1e-12)
        assert len(set(schedule.starts)) == k and list(schedule.starts) == sorted(schedule.starts)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10_000), n_months=st.integers(2, 6), n_angles=st.integers(1, 3))
def test_worst_month_schedule_is_the_brute_force_optimum(seed, n_months, n_angles):
    months = np.repeat(np.arange(1, n_months + 1), 3)
    hours = np.random.default_rng(seed).uniform(0, 12, (months.size, n_angles))
    schedules = best_schedules(hours, months, min(3, n_months), "worst-month")
    for k, schedule in enumerate(schedules, start=1):
        assert schedule.objective_h == pytest.approx(_brute_force_worst_month(hours, months, k), abs=1e-12)
        daily = schedule.daily_angles(months.size)
        chosen = hours[np.arange(months.size), daily]
        assert min(chosen[months == m].mean() for m in np.unique(months)) == pytest.approx(schedule.objective_h)


def test_the_year_wraps_around_new_year():
    """Winter straddles 31 December: two settings, one for the winter arc across New Year."""
    days = np.arange(365)
    winter = (days < 60) | (days >= 334)
    hours = np.where(winter[:, None], [1.0, 5.0], [5.0, 1.0])
    one, two = best_schedules(hours, np.ones(365), 2)
    assert two.objective_h == pytest.approx(5.0)
    assert two.starts == (60, 334) and two.angles == (0, 1)
    assert one.objective_h == pytest.approx((274 * 5 + 91 * 1) / 365)  # 91 winter days


def test_bad_arguments():
    with pytest.raises(ValueError, match="max_visits must be in"):
        best_schedules(np.ones((10, 2)), np.ones(10), 13)
    with pytest.raises(ValueError, match="objective must be one of"):
        best_schedules(np.ones((10, 2)), np.ones(10), 2, "min")


def test_a_weather_year_schedule_agrees_with_the_annual_sweep():
    """`objective.visits` on a TMY3 year: one setting is the sweep's fixed angle and mean; more
    settings never do worse and never beat re-folding every day; flat and tracker as the sweep's."""
    from pathlib import Path

    from foldopt.inputs.plan import make_plan
    from foldopt.studies.designs import Blocks, fold_hours
    from foldopt.studies.sweeps import run_plan

    weather = str(Path(__file__).resolve().parent.parent / "configs" / "weather" / "723170TYA.CSV")
    data = {"name": "refold", "weather": weather, "p_load": [1.0, 3.0], "panel": {"area": 0.108}, "mode": "exact",
            "step_min": 15, "fold_angles": {"start": 10, "stop": 180, "step": 10},
            "objective": {"statistic": "mean", "visits": 4}}
    result = run_plan(make_plan(data))
    values, visits = result.extras["refold_value"], result.extras["refold_schedule"]
    table = result.table
    for load, rows in values.groupby("p_load_w"):
        designs = table[table["p_load_w"] == load].groupby("design")["t_solar_h"].mean()
        one = rows[rows["settings_n"] == 1].iloc[0]
        assert one["t_solar_objective_h"] == pytest.approx(designs["twofold"], abs=1e-9)
        fixed = table[(table["p_load_w"] == load) & (table["design"] == "twofold")]["fold_angle_deg"].iloc[0]
        assert visits[(visits["p_load_w"] == load) & (visits["settings_n"] == 1)]["fold_angle_deg"].iloc[0] == fixed
        assert one["t_solar_flat_objective_h"] == pytest.approx(designs["flat"], abs=1e-9)
        assert one["t_solar_tracker_objective_h"] == pytest.approx(designs["tracker"], abs=1e-9)
        assert (np.diff(rows["t_solar_objective_h"]) >= -1e-12).all()
    # Re-folding every day is the bound: the best angle of each day.
    plan = make_plan({**data, "p_load": 1.0})
    blocks = Blocks.of_dates(plan.base, list(dict(plan.axes)["date"]))
    _, daily, _ = fold_hours(blocks.sky(), blocks, np.array([1.0]))
    every_day = daily[:, :, 0].max(axis=1).mean()
    assert values[values["p_load_w"] == 1.0]["t_solar_objective_h"].max() <= every_day + 1e-12
