"""The sweep engine against single-study runs and physical identities, and its edge cases."""

import numpy as np
import pytest

from foldopt.inputs.plan import make_plan
from foldopt.studies.day import run_study
from foldopt.studies.sweeps import run_plan

BASE = {"name": "t", "mode": "exact", "site": {"latitude": 34.05, "longitude": -118.25},
        "date": "2025-09-22", "panel": {"area": 0.108, "efficiency": 0.1905}, "p_load": 4.4,
        "fold_angles": {"start": 2, "stop": 180, "step": 2}, "step_min": 5}


def rows(table, design):
    return table[table["design"] == design].reset_index(drop=True)


def test_each_case_matches_a_single_study_run():
    plan = make_plan({**BASE, "p_load": [2.0, 4.4, 7.0]})
    table = run_plan(plan).table
    for (_, study), flat, twofold, tracker in zip(
        plan.cases(), rows(table, "flat").itertuples(), rows(table, "twofold").itertuples(),
        rows(table, "tracker").itertuples(), strict=True,
    ):
        single = run_study(study).summary.set_index("design")
        assert flat.t_solar_h == pytest.approx(single.loc["flat", "t_solar_h"], abs=1e-12)
        assert tracker.t_solar_h == pytest.approx(single.loc["tracker", "t_solar_h"], abs=1e-12)
        # The sweep takes the grid's best angle; a single run refines it, so it can only be longer.
        assert twofold.t_solar_h <= single.loc["twofold", "t_solar_h"] + 1e-12
        assert twofold.t_solar_h == pytest.approx(single.loc["twofold", "t_solar_h"], abs=0.02)


def test_hemispheres_mirror_at_a_zero_declination_equinox():
    # Paper mode, day 81: the paper's declination is exactly 0, and the default orientation faces
    # the equator on both hemispheres, so +phi and -phi are mirror images.
    plan = make_plan({**BASE, "mode": "paper", "date": "2025-03-22",
                      "site": {"latitude": [34.0, -34.0], "longitude": 0, "timezone": "UTC"}})
    table = run_plan(plan).table
    north, south = table[table.latitude > 0].reset_index(), table[table.latitude < 0].reset_index()
    for column in ("t_solar_h", "energy_harvested_wh", "fold_angle_deg"):
        np.testing.assert_allclose(north[column], south[column], rtol=1e-9, equal_nan=True)


def test_polar_night_and_polar_day():
    plan = make_plan({**BASE, "site": {"latitude": 80.0, "longitude": 0, "timezone": "UTC"},
                      "date": ["2025-12-21", "2025-06-21"], "p_load": 0.5})
    table = run_plan(plan).table
    night = table[table.date == "2025-12-21"]
    assert (night["t_solar_h"] == 0).all()
    assert set(night["note"]) == {"polar night"}
    day = table[table.date == "2025-06-21"].set_index("design")
    assert day.loc["tracker", "t_solar_h"] == pytest.approx(24.0)
    assert day.loc["tracker", "t_solar_contiguous_h"] == pytest.approx(24.0)
    assert 0 < day.loc["flat", "t_solar_h"] <= day.loc["twofold", "t_solar_h"] <= 24.0


def test_loads_above_the_peak_are_reported_not_errors():
    table = run_plan(make_plan({**BASE, "p_load": [4.4, 500.0]})).table
    high = table[table.p_load_w == 500.0]
    assert (high["t_solar_h"] == 0).all()
    assert set(high["note"]) == {"load above peak"}
    assert (rows(table, "twofold")["t_solar_h"] >= rows(table, "flat")["t_solar_h"]).all()


@pytest.mark.parametrize("objective", [None, {"statistic": "mean"}], ids=["per-day", "annual"])
def test_progress_counts_days_to_the_total(objective):
    plan = make_plan({**BASE, "date": "1:60:10", "year": 2025, "p_load": [2.0, 4.4], "objective": objective})
    calls = []
    run_plan(plan, lambda done, total: calls.append((done, total)))
    days = plan.n_cases // 2
    assert days == 6
    assert {total for _, total in calls} == {days}
    assert calls[-1][0] == days
    assert all(b >= a for (a, _), (b, _) in zip(calls, calls[1:]))
