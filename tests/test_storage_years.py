"""A buffer over real years in sequence (issue 50, part 1): the days' simulation by calendar year
(``storage_years.csv``) and month in PVGIS SHScalc's names (``storage_monthly.csv``), the target
met in a share of the years (``storage.target.years``), the worst-year lines.

References are physical identities: the days partition the years and the months, so the
periods' sums are the series' and their day-weighted means its means; with one year the year's
row is the series' to the bit, and so is the sizing; a month's energy delivered a day times its
days is the energy served; the charge-state histogram fills the month's hours. The sizing for a
share of the years is checked against a brute force over a grid of capacities written here.
Weather is the recorded PVGIS 2020-2021 hourly answer at 45 N 8 E, read from its file (offline).
"""

from __future__ import annotations

import datetime
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

import foldopt
from foldopt.cli.app import app
from foldopt.engine.storage import Buffer, simulate
from foldopt.inputs.storage_section import Storage, StorageTarget
from foldopt.studies.answer import plain
from foldopt.studies.request import make_request
from foldopt.studies.storage_periods import (
    CS_COLUMNS,
    by_period,
    storage_monthly,
    storage_years,
    years_meeting,
)
from foldopt.studies.storage_sizing import (
    CAPACITY_RTOL,
    bracketed_buffers,
    buffer_of,
    capacity_grid,
    smallest_buffers,
)

ROOT = Path(__file__).resolve().parent.parent
HOURLY = ROOT / "tests" / "data" / "pvgis" / "seriescalc_45.000_8.000_2020_2021.json"
runner = CliRunner(env={"COLUMNS": "200"})
#: The camera of issue 50 at 45 N 8 E, a small buffer it cannot carry all day with, a coarse
#: grid of fold angles (a few seconds a run).
CAMERA = {
    "name": "camera-years",
    "mode": "exact",
    "site": {"latitude": 45.0, "longitude": 8.0},
    "panel": {"area": 0.4, "efficiency": 0.1905},
    "p_load": 2.0,
    "objective": {"statistic": "mean"},
    "fold_angles": {"start": 30, "stop": 180, "step": 30},
    "storage": {"preset": "lifepo4", "capacity_wh": 20, "target": {"powered_h": 20}},
}
#: Columns a year's row shares with the series' (storage_annual.csv).
SHARED = (
    "powered_mean_h",
    "powered_min_h",
    "powered_days_ge24h_pct",
    "energy_missing_wh",
    "energy_lost_wh",
    "days_full_pct",
    "days_empty_pct",
)


def _study(folder: Path, years=(2020, 2021), **storage) -> Path:
    """The camera's study over the recorded answer's ``years`` (a copy of the file keeping
    them)."""
    answer = json.loads(HOURLY.read_text())
    kept = tuple(str(year) for year in years)
    answer["outputs"]["hourly"] = [r for r in answer["outputs"]["hourly"] if r["time"][:4] in kept]
    weather = folder / f"seriescalc_{'_'.join(kept)}.json"
    weather.write_text(json.dumps(answer))
    study = {
        **CAMERA,
        "weather": {"path": str(weather), "format": "pvgis-hourly"},
        "storage": {**CAMERA["storage"], **storage},
    }
    path = folder / f"study_{'_'.join(kept)}.yaml"
    path.write_text(yaml.safe_dump(study))
    return path


@pytest.fixture(scope="module")
def two_years(tmp_path_factory, runs_shared, figures_drawn_elsewhere):
    """The two years' study, its API's result, and the command line's ``--format json`` document
    and folder of the same request: one request evaluated once (conftest's ``runs_shared``).
    The folder's figures are not drawn: storage_years.png is drawn by test_camera_winter.py's
    study (whole) and by test_the_figure_draws_each_design_s_years below."""
    folder = tmp_path_factory.mktemp("two")
    path = _study(folder)
    with runs_shared():
        result = foldopt.run(request=make_request("run", path))
        with figures_drawn_elsewhere():
            done = runner.invoke(
                app, ["run", str(path), "--format", "json", "--out", str(folder / "out"), "-q"]
            )
    assert done.exit_code == 0, done.output
    return path, result, json.loads(done.stdout), folder / "out"


@pytest.fixture(scope="module")
def one_year(tmp_path_factory):
    path = _study(tmp_path_factory.mktemp("one"), years=(2021,))
    return foldopt.run(request=make_request("run", path))


def test_one_year_is_the_series_to_the_bit(one_year):
    annual = one_year.extras["storage_annual"].set_index("design")
    years = one_year.extras["storage_years"].set_index("design")
    assert (years["year"] == 2021).all() and years["worst_year"].all()
    for column in SHARED:
        assert (years[column] == annual.loc[years.index, column]).all(), column
    assert (years["days_n"] == annual["days_n"]).all()
    assert (years["powered_vs_typical_h"] == 0).all()
    # Over one year the answer says nothing of years: no worst year, the sizing as it was.
    lines = one_year.answer.lines()
    assert not any("worst year" in line or "in every year" in line for line in lines)
    assert "worst_years" not in one_year.answer.result["storage"]
    assert any(line.startswith("  for 20 h every day: flat needs") for line in lines)


def test_one_year_sizes_the_same_buffer_whatever_the_share_of_years():
    # One year: every share of it is the same target, and the same capacity to the bit as the
    # target over the days as one.
    power, dates = _days(years=1, seed=3)
    storage = Storage(capacity_wh=5, target={"powered_h": 24, "days_pct": 80})
    labels = [date.year for date in dates]
    plain_need, _ = smallest_buffers(power, 1.0, storage, 0.5, "numba", True)
    for share in ("every", 50.0, 100.0):
        target = StorageTarget(powered_h=24, days_pct=80, years=share)
        need, _ = smallest_buffers(
            power, 1.0, storage.model_copy(update={"target": target}), 0.5, "numba", True,
            years=labels,
        )  # fmt: skip
        assert np.array_equal(need, plain_need, equal_nan=True), share


def test_a_bracket_known_on_the_grid_sizes_the_buffer_the_grid_s_search_sizes():
    # bracketed_buffers, given each design's least capacity of the grid meeting the target
    # (found here by simulate over the whole grid), gives smallest_buffers' capacities to the
    # bit, and NaN where none meets.
    power, dates = _days(years=2, seed=5)
    power = np.stack([power[0] * factor for factor in (0.3, 0.8, 1.0, 1.6)])
    target = StorageTarget(powered_h=24, days_pct=90, years="every")
    storage = Storage(capacity_wh=5, target=target)
    labels = [date.year for date in dates]
    grid = capacity_grid(1.0, storage, 0.5, power.shape[-1])
    first = []
    for curve in power:
        series = np.repeat(curve[None], grid.size, 0)
        result = simulate(series, 1.0, buffer_of(storage, capacity_wh=grid), 0.5, "numba")
        days = result.powered_h >= 24 - 1e-9
        ok = years_meeting(days, labels, 90, target.years_pct) & result.converged
        first.append(int(np.argmax(ok)) if ok.any() else -1)
    need, _ = smallest_buffers(power, 1.0, storage, 0.5, "numba", True, years=labels)
    found = bracketed_buffers(power, np.array(first), 1.0, storage, 0.5, "numba", True,
                              years=labels)  # fmt: skip
    assert np.array_equal(found, need, equal_nan=True)
    assert np.isnan(need).any() and np.isfinite(need).any()


def test_the_years_partition_the_series(two_years):
    result = two_years[1]
    annual = result.extras["storage_annual"].set_index("design")
    years = result.extras["storage_years"]
    assert sorted(years["year"].unique()) == [2020, 2021]
    for design, rows in years.groupby("design"):
        whole = annual.loc[design]
        days = rows["days_n"].to_numpy()
        assert days.sum() == whole["days_n"] == 731
        for column in SHARED:
            if column == "powered_min_h":
                assert rows[column].min() == whole[column]
            else:
                weighted = (rows[column] * days).sum() / days.sum()
                assert weighted == pytest.approx(whole[column], rel=1e-12, abs=1e-12), column
        assert rows["energy_missing_total_wh"].sum() == pytest.approx(
            whole["energy_missing_wh"] * 731, rel=1e-12
        )
        # The worst month's mean is a month's, at most the year's mean.
        assert (rows["powered_worst_month_h"] <= rows["powered_mean_h"] + 1e-12).all()
        assert rows["worst_month"].between(1, 12).all()


def test_the_worst_year_is_the_least_and_said(two_years):
    result = two_years[1]
    years = result.extras["storage_years"]
    for _, rows in years.groupby("design"):
        flagged = rows[rows["worst_year"]]
        assert len(flagged) == 1
        assert flagged["powered_mean_h"].iloc[0] == rows["powered_mean_h"].min()
        typical = np.median(rows["powered_mean_h"])
        assert flagged["powered_vs_typical_h"].iloc[0] == pytest.approx(
            rows["powered_mean_h"].min() - typical, abs=1e-12
        )
    worst = pd.DataFrame(result.answer.result["storage"]["worst_years"]).set_index("design")
    lines = result.answer.lines()
    line = next(line for line in lines if line.startswith("  worst year: "))
    flat = worst.loc["flat"]
    assert f"flat {flat['year']}: {flat['powered_mean_h']:.2f} h a day" in line
    assert f"all 24 h on {flat['powered_days_ge24h_pct']:.0f} % of its days" in line
    assert any(line.startswith("  for 20 h every day in every year: flat needs") for line in lines)


def test_the_month_s_energy_a_day_times_its_days_is_the_energy_served(two_years):
    result = two_years[1]
    monthly = result.extras["storage_monthly"]
    annual = result.extras["storage_annual"].set_index("design")
    demand = 2.0 * 24.0  # Wh a day
    for design, rows in monthly.groupby("design"):
        assert rows["month"].tolist() == list(range(1, 13)) and rows["d_total"].sum() == 731
        served = (rows["E_d"] * rows["d_total"]).sum()
        # Served and missing make the demand (PVGIS's E_miss = demand - mean E_d).
        assert served / 731 + rows["E_miss"].iloc[0] == pytest.approx(demand, rel=1e-12)
        assert rows["E_miss"].iloc[0] == annual.loc[design, "energy_missing_wh"]
        assert (rows["E_lost_d"] * rows["d_total"]).sum() / 731 == pytest.approx(
            rows["E_lost"].iloc[0], rel=1e-12
        )
        assert (rows["f_e"] * rows["d_total"]).sum() / 731 == pytest.approx(
            annual.loc[design, "days_empty_pct"], rel=1e-12
        )
        assert rows[list(CS_COLUMNS)].sum(axis=1).to_numpy() == pytest.approx(100.0, rel=1e-12)


def _days(years: int, seed: int, steps: int = 48):
    """``years`` calendar years of days from 2019-01-01: each a sine of a random height (some
    cloudy), half-hour steps, as one series (1, n_days, n_steps) [W]."""
    first = datetime.date(2019, 1, 1)
    dates = [
        first + datetime.timedelta(n)
        for n in range((datetime.date(2019 + years, 1, 1) - first).days)
    ]
    rng = np.random.default_rng(seed)
    heights = rng.choice([0.5, 2.0, 5.0, 6.0], size=len(dates), p=[0.1, 0.2, 0.4, 0.3])
    hours = (np.arange(steps) + 0.5) * 24.0 / steps
    sine = np.clip(np.sin(np.pi * (hours - 6.0) / 12.0), 0.0, None)
    return (heights[:, None] * sine[None, :])[None], dates


def test_the_sizing_for_a_share_of_years_is_the_brute_force_least():
    # Three years of random days, 1 W all day, an ideal buffer (powered time does not fall as
    # it grows): 24 h on 95 % of a year's days, in 2 of the 3 years.
    power, dates = _days(years=3, seed=11, steps=24)
    labels = np.array([date.year for date in dates])
    target = StorageTarget(powered_h=24, days_pct=95, years=60)
    storage = Storage(capacity_wh=5, target=target.model_dump())
    need, monotone = smallest_buffers(power, 1.0, storage, 1.0, "numba", True, years=labels)
    # Brute force: every capacity of a fine grid, the share of years checked here.
    grid = np.linspace(0.0, 200.0, 801)
    found = simulate(np.repeat(power, grid.size, 0), 1.0, Buffer(capacity_wh=grid), 1.0, "numba")
    day_ok = found.powered_h >= 24.0 - 1e-9
    years_ok = np.stack(
        [100.0 * day_ok[:, labels == y].mean(axis=1) >= 95.0 for y in np.unique(labels)], axis=1
    )
    meets = (years_ok.sum(axis=1) >= 2) & found.converged
    assert meets.any() and not meets[0]
    least = grid[np.argmax(meets)]
    assert monotone[0] and meets[np.argmax(meets) :].all()
    # The search's capacity meets it, and is within the grid's step and the search's
    # tolerance of the least that does.
    step = grid[1] - grid[0]
    assert least - step - CAPACITY_RTOL * least <= need[0] <= least * (1 + CAPACITY_RTOL)
    check = simulate(power, 1.0, Buffer(capacity_wh=need[0]), 1.0, "numba")
    assert years_meeting(check.powered_h >= 24.0 - 1e-9, labels, 95.0, 60.0)[0]
    # Here every year asks for more: its worst year's days.
    every = Storage(capacity_wh=5, target={**target.model_dump(), "years": "every"})
    assert smallest_buffers(power, 1.0, every, 1.0, "numba", True, years=labels)[0][0] > need[0]


@settings(max_examples=15, deadline=None)
@given(
    years=st.integers(1, 3),
    seed=st.integers(0, 2**16),
    load=st.floats(0.2, 3.0),
    capacity=st.floats(0.0, 40.0),
    min_soc=st.floats(0.0, 0.5),
)
def test_periods_partition_any_series(years, seed, load, capacity, min_soc):
    power, dates = _days(years, seed, steps=24)
    buffer = Buffer(capacity_wh=capacity, min_soc=min_soc)
    result = simulate(power, load, buffer, 1.0, "numba", soc_curves=True)
    keys = pd.DataFrame({"design": ["flat"]})
    table = storage_years(keys, result, dates)
    summary = result.summary()
    days = table["days_n"].to_numpy()
    assert days.sum() == len(dates)
    assert (table["powered_mean_h"] * days).sum() / days.sum() == pytest.approx(
        summary["powered_h"][0], rel=1e-12, abs=1e-12
    )
    assert table["powered_min_h"].min() == result.powered_h.min()
    assert table["energy_missing_total_wh"].sum() == pytest.approx(
        result.missing_wh.sum(), rel=1e-12, abs=1e-9
    )
    assert table.loc[table["worst_year"], "powered_mean_h"].iloc[0] == table["powered_mean_h"].min()
    monthly = storage_monthly(keys, result, dates, min_soc, 1.0)
    assert (monthly["E_d"] * monthly["d_total"]).sum() == pytest.approx(
        result.served_wh.sum(), rel=1e-12, abs=1e-9
    )
    # The histogram, counted here from the state of charge at the end of each hour.
    months = np.array([date.month for date in dates])
    edges = np.linspace(min_soc, 1.0, 11)  # the last edge 1 itself: a full buffer counts
    for _, row in monthly.iterrows():
        soc = result.soc[0, months == row["month"]].ravel()
        counts = np.histogram(np.clip(soc, min_soc, 1.0), bins=edges)[0]
        hours = np.array([row[c] for c in CS_COLUMNS]) / 100.0 * row["d_total"] * 24.0
        assert hours.sum() == pytest.approx(row["d_total"] * 24.0, rel=1e-12)
        assert hours == pytest.approx(counts, abs=1e-6)
    # The reduction by any labels partitions the days.
    labels = np.random.default_rng(seed).integers(0, 5, len(dates))
    _, columns = by_period(result, labels)
    assert columns["days_n"].sum() == len(dates)
    assert columns["energy_missing_total_wh"].sum() == pytest.approx(
        result.missing_wh.sum(), rel=1e-12, abs=1e-9
    )


def test_the_command_line_is_the_api_to_the_bit(two_years):
    _, api, document, out = two_years
    printed = document["answer"]
    assert printed["lines"] == api.answer.lines()
    assert printed["result"]["storage"] == json.loads(
        json.dumps(plain(api.answer.result["storage"]))
    )
    for table in ("storage_years", "storage_monthly"):
        written = pd.read_csv(out / f"{table}.csv")
        expected = api.extras[table]
        assert list(written.columns) == list(expected.columns)
        numbers = expected.select_dtypes("number").columns
        assert np.allclose(written[numbers], expected[numbers], rtol=1e-9, equal_nan=True)
    assert (out / "storage_years.png").exists()
    html = (out / "report.html").read_text()
    assert "worst year: " in html and "storage_years.png" in html


@pytest.mark.parametrize("value", ["some", "0", "101", "-5"])
def test_a_bad_share_of_years_is_one_line_and_exit_2(two_years, tmp_path, monkeypatch, value):
    path = two_years[0]
    monkeypatch.chdir(tmp_path)
    done = runner.invoke(
        app, ["run", str(path), "--set", f"storage.target.years={value}", "--out", "out", "-q"]
    )
    assert done.exit_code == 2, done.output
    lines = done.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.output, done.output
    assert "storage.target.years" in lines[0] and "every or a share" in lines[0], lines[0]
    assert not (tmp_path / "out").exists()


def test_the_figure_draws_each_design_s_years(two_years):
    # The lines' points are the table's powered time per year, per design; the worst ringed.
    result = two_years[1]
    years = result.extras["storage_years"]
    ax = foldopt.plot_powered_by_year(years, "t")
    lines = {line.get_label(): line for line in ax.get_lines()}
    rows = years[years["design"] == "flat"]
    assert list(lines["flat"].get_xdata()) == rows["year"].tolist()
    assert list(lines["flat"].get_ydata()) == rows["powered_mean_h"].tolist()
    ringed = [
        line
        for line in ax.get_lines()
        if line.get_markersize() == 12 and line.get_color() == "0.35"
    ]
    assert [list(line.get_ydata()) for line in ringed] == [
        rows.loc[rows["worst_year"], "powered_mean_h"].tolist()
    ]
