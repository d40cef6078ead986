"""Measured minutes and cloud ensembles in studies: a measured file at its own step and its own
days, from the command line and the API alike; an hourly file's ensemble, reproducible, its
members drawn per day, each keeping the file's hours; the day's time series carrying the light
and air the study used."""

import datetime as dt
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pvlib
import pytest

import foldopt
from foldopt.engine.sky import build_sky
from foldopt.inputs.study_file import with_files
from foldopt.inputs.plan import make_plan
from foldopt.inputs.weather.reader import read_weather
from foldopt.studies.designs import Blocks
from foldopt.studies.sweeps import run_plan
from test_cli import assert_one_line_error, invoke

DATA = Path(__file__).resolve().parent / "data" / "measured"
SURFRAD = DATA / "surfrad-slv16001.dat"
FIVE = DATA / "five_minute.csv"
UAT = {"latitude": 32.22969, "longitude": -110.95534, "altitude": 786.0}
TMY3 = Path(pvlib.__file__).parent / "data" / "723170TYA.CSV"  # NREL TMY3 sample pvlib ships
DAYS = "150:160:5"


def test_a_measured_day_through_the_cli_and_the_api_gives_the_same_answer(tmp_path):
    out = tmp_path / "s"
    result = invoke("sweep", "angle", "--weather", SURFRAD, "--weather-format", "surfrad", "--p-load", "2",
                    "--angle-step", "10", "--out", out, "--format", "json")
    assert result.exit_code == 0, result.output
    cli = json.loads(result.stdout)["answer"]
    notes = [note["note"] for note in cli["notes"]]
    assert notes[0].startswith("measured weather surfrad-slv16001.dat: 1-min steps")
    # the UTC day's evening: night, no day of the file
    assert any(note.startswith("2015-12-31 not counted") for note in notes)
    study = json.loads((out / "run.json").read_text())["study"]
    assert study["step_min"] == 1.0 and study["site"]["name"] == "Alamosa"
    api = foldopt.sweep(foldopt.default_study(), "angle", weather={"path": str(SURFRAD), "format": "surfrad"},
                        p_load=2.0, fold_angles={"step": 10}).answer.to_dict()
    assert api["result"] == cli["result"]  # the same numbers to the bit


def test_a_five_minute_csv_runs_at_its_own_step(tmp_path, figures_drawn_elsewhere):
    with figures_drawn_elsewhere():  # a measured day's: test_a_measured_day_through_the_cli_and_the_api's
        result = invoke("sweep", "angle", "--weather", FIVE, "--weather-format", "csv", "--lat", UAT["latitude"],
                        "--lon", UAT["longitude"], "--altitude", UAT["altitude"], "--p-load", "2", "--angle-step",
                        "15", "--out", tmp_path / "c", "-q")
    assert result.exit_code == 0, result.output
    assert json.loads((tmp_path / "c" / "run.json").read_text())["study"]["step_min"] == 5.0
    table = pd.read_csv(tmp_path / "c" / "results.csv")
    assert set(table["date"]) == {"2018-10-18"}


@pytest.mark.parametrize("args,words", [
    (["--weather", FIVE, "--weather-format", "csv"], ["--weather", "holds no site", "latitude, longitude and "
                                                                                    "altitude"]),
    (["--weather", FIVE, "--weather-format", "csv", "--lat", "32.2", "--lon", "-110.9", "--altitude", "786",
      "--step-min", "1"], ["--step-min", "its own step, 5 min"]),
    (["--weather", SURFRAD, "--weather-format", "surfrad", "--days", "2015-12-31"],
     ["2015-12-31", "the file holds 2016-01-01 to 2016-01-01"]),
    (["--weather", SURFRAD, "--weather-format", "surfrad", "--members", "5"], ["--members", "hourly file"]),
    (["--weather", TMY3, "--seed", "3"], ["--seed", "only used by a cloud ensemble"]),
    (["--weather", TMY3, "--members", "1"], ["--members", "greater than or equal to 2"]),
    (["--weather", FIVE, "--weather-format", "srml9"], ["--weather-format", "did you mean 'srml'"]),
    (["--weather", SURFRAD, "--weather-format", "surfrad", "--set", "weather.max_gap_min=-5"],
     ["weather.max_gap_min = -5", "[0, 1440]"]),
    (["--weather", SURFRAD, "--weather-format", "surfrad", "--set", "weather.decomposition=disc"],
     ["weather.decomposition", "erbs, boland, dirint"]),
    (["--weather", SURFRAD, "--weather-format", "surfrad", "--set", "weather.timezone=Europe/Berlin"],
     ["timezone", "fixed"]),
])
def test_bad_measured_and_ensemble_input_is_one_line(tmp_path, args, words):
    assert_one_line_error(invoke("sweep", "angle", *args, "--out", tmp_path / "b"), *words)


@pytest.fixture(scope="session")
def ensemble_plan():
    return make_plan({"name": "e", "weather": {"path": str(TMY3), "members": 6, "seed": 4}, "panel": {"area": 0.108},
                      "p_load": [1.0, 3.0], "objective": "mean", "date": DAYS, "year": 2025,
                      "fold_angles": {"step": 15}})


def test_each_member_keeps_the_files_hours(ensemble_plan):
    # Each member's hourly GHI and DHI are the file's (cloud_members' guarantee, checked on the
    # study's own sky), their DNI closes them, and the members differ within the hours.
    study = ensemble_plan.base
    dates = [dt.date(2025, 5, 30), dt.date(2025, 6, 4)]
    blocks = Blocks.of_dates(study, dates)
    assert len(blocks) == 12 and list(blocks.member) == list(range(6)) * 2
    sky = blocks.sky()
    frame = read_weather(TMY3)
    whole = (sky.solar_zenith.reshape(12, 24, 60) < 85).all(axis=-1)
    for key in ("ghi", "dhi"):
        file = np.concatenate([frame[key][frame.index.date == date].to_numpy() for date in dates]).reshape(2, 24)
        hourly = getattr(sky, key).reshape(12, 24, 60).mean(axis=-1)
        np.testing.assert_allclose(hourly[whole], np.repeat(file, 6, axis=0)[whole], rtol=1e-9, atol=1e-6)
    closure = sky.ghi - sky.dni * np.clip(np.cos(np.radians(sky.solar_zenith)), 0, None) - sky.dhi
    assert np.abs(closure).max() < 1e-6
    assert np.ptp(sky.ghi[:6], axis=0).max() > 50.0  # the members' clouds pass at different minutes


def test_members_are_reproducible_and_a_days_own(ensemble_plan):
    study = ensemble_plan.base
    day, other = dt.date(2025, 6, 4), dt.date(2025, 5, 30)
    alone = Blocks.of_dates(study, [day]).sky()
    together = Blocks.of_dates(study, [other, day]).sky()
    np.testing.assert_array_equal(alone.ghi, together.ghi[6:])  # the same seed, the same day: the same bits
    reseeded = Blocks.of_dates(with_files(study.variant(weather={"path": str(TMY3), "members": 6, "seed": 5},
                                                        date="2025-06-04")), [day])
    assert not np.array_equal(alone.ghi, build_sky(reseeded.options.sky, reseeded.sites, reseeded.dates,
                                                   reseeded.member).ghi)


def test_the_ensemble_answer_has_its_spread(ensemble_plan):
    result = run_plan(ensemble_plan)
    objective = result.extras["annual_objective"]
    # The objective is the members' mean; its P10 <= P50 <= P90; the twofold panel says how sure.
    for _, row in objective.iterrows():
        p10, p50, p90 = (row[f"t_solar_objective_members_p{pct}_h"] for pct in (10, 50, 90))
        assert p10 <= p50 <= p90 and p10 - 1e-9 <= row["t_solar_objective_h"] <= p90 + 1e-9
    twofold = objective[objective["design"] == "twofold"]
    assert twofold["chosen_wins_pct"].between(0, 100).all() and twofold["within_tolerance_pct"].between(0, 100).all()
    table = result.table
    assert len(table) == 3 * 2 * 4  # a row per day, load and design: the members' mean day
    assert (table["t_solar_members_p10_h"] <= table["t_solar_members_p50_h"] + 1e-12).all()
    assert (table["t_solar_members_p50_h"] <= table["t_solar_members_p90_h"] + 1e-12).all()
    lines = result.answer.lines()
    assert any("over 6 cloud members" in line for line in lines)
    assert any("best angle of" in line and "near-optimal tolerance" in line for line in lines)
    wins = result.extras["by_angle"].groupby("p_load_w")["wins_pct"].sum()
    np.testing.assert_allclose(wins, 100.0)


def test_a_days_time_series_carries_the_light_and_air_it_used(tmp_path):
    result = invoke("sweep", "angle", "--weather", TMY3, "--date", "2025-06-21", "--pv-model", "single-diode",
                    "--out", tmp_path / "d", "-q")
    assert result.exit_code == 0, result.output
    series = pd.read_csv(tmp_path / "d" / "timeseries.csv")
    for column in ("ghi", "dni", "dhi", "temp_air", "wind_speed"):
        assert column in series, column
    beam = series["dni"] * np.clip(np.cos(np.radians(series["apparent_zenith"])), 0, None)
    np.testing.assert_allclose(series["ghi"], beam + series["dhi"], atol=1e-6)
    assert series["temp_air"].nunique() > 100  # the cells follow the air through the day


def test_an_ensemble_through_the_cli_and_the_api_gives_the_same_answer(tmp_path, folders_written_elsewhere):
    with folders_written_elsewhere():  # its answer alone is read (an ensemble of days: test_weather_ensemble)
        result = invoke("sweep", "angle", "--weather", TMY3, "--members", "4", "--seed", "2", "--days", DAYS,
                        "--year", "2025", "--p-load", "3", "--angle-step", "30", "--out", tmp_path / "e",
                        "--format", "json")
    assert result.exit_code == 0, result.output
    cli = json.loads(result.stdout)["answer"]
    api = foldopt.sweep(foldopt.default_study(), "angle", weather={"path": str(TMY3), "members": 4, "seed": 2},
                        date=DAYS, year=2025, p_load=3.0, fold_angles={"step": 30}).answer.to_dict()
    assert api["result"] == cli["result"]
    assert cli["result"]["per_case"][0]["members"] == 4


def test_a_files_sky_cover_reaches_the_ensemble(ensemble_plan):
    # TMY3's total sky cover (tenths), as pvlib reads it, is the frame's cloud_cover; a member's
    # hour the file calls overcast (10 tenths) is smooth, one it calls broken (3 to 7) is not
    # (cloud_members: the sun obscured for the part of the hour the sky is covered).
    frame = read_weather(TMY3)
    data, _ = pvlib.iotools.read_tmy3(TMY3, map_variables=True)
    np.testing.assert_allclose(frame["cloud_cover"].to_numpy(), data["TotCld (tenths)"].to_numpy() / 10.0)
    study = ensemble_plan.base
    dates = [dt.date(2025, 1, 1) + dt.timedelta(days=d) for d in range(0, 365, 15)]
    sky = Blocks.of_dates(study, dates).sky()
    spread = sky.ghi.reshape(len(dates), 6, 24, 60).std(axis=-1).mean(axis=1)  # (days, hours)
    cover = np.stack([frame["cloud_cover"][frame.index.date == date].to_numpy() for date in dates])
    lit = (sky.solar_zenith.reshape(len(dates), 6, 24, 60)[:, 0] < 80).all(axis=-1)
    overcast, broken = lit & (cover == 1.0), lit & (cover >= 0.3) & (cover <= 0.7)
    assert overcast.sum() > 10 and broken.sum() > 10
    assert np.median(spread[broken]) > 3 * np.median(spread[overcast])
