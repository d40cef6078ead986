"""A study's time series (foldopt.studies.series): every study over many days writes one, each step
from the evaluation its numbers come from, checked against references computed here: t_solar
re-integrated from the series' own power by the trapezoid of the linear curve, pvlib's solar
position and isotropic transposition on the series' own light, and the file the command line
writes against the API's table, byte for byte."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pvlib
import pytest

import foldopt
from foldopt.output.folders import write_series
from foldopt.studies import series as series_module
from foldopt.studies.request import make_request
from foldopt.tables import write_csv
from test_cli import invoke

ROOT = Path(__file__).resolve().parents[1]
MEASURED = ROOT / "configs" / "measured-minutes.yaml"
PVGIS = ROOT / "tests" / "data" / "pvgis" / "seriescalc_45.000_8.000_2020_2021.json"
DESIGNS = ("flat", "twofold", "tracker")


def _hours_above(power: np.ndarray, load: float, step_h: float) -> float:
    """Time with ``power >= load`` of step-centred samples taken as linear between them, the first
    and last half steps flat: an interval-by-interval reference, written here."""
    total = 0.5 * step_h * ((power[0] >= load) + (power[-1] >= load))
    for a, b in zip(power[:-1] - load, power[1:] - load, strict=True):
        if a >= 0 and b >= 0:
            total += step_h
        elif a >= 0 or b >= 0:
            total += step_h * max(a, b) / abs(a - b)
    return total


@pytest.fixture(scope="module")
def measured():
    """configs/measured-minutes.yaml: measured 5-min light, one fold angle per load for the days."""
    return foldopt.run(MEASURED)


@pytest.fixture(scope="module")
def pvgis_years():
    """Two of PVGIS's hourly years, one fold angle for the 731 days."""
    request = make_request("sweep angle", options={"weather": PVGIS, "weather_format": "pvgis-hourly"})
    return foldopt.run(request=request)


@pytest.fixture(scope="module")
def days_at_sites():
    """configs/annual.yaml on every 91st day: clear days at three latitudes, each at its own best
    fold angle (no objective)."""
    return foldopt.run(request=make_request("run", ROOT / "configs" / "annual.yaml", fields={"date": "1:365:91"}))


@pytest.mark.parametrize("name", ["measured", "pvgis_years", "days_at_sites"])
def test_the_series_is_the_evaluation_the_answer_comes_from(request, name):
    """Every site, day, load and design: the series' power re-integrated (the reference above) is
    the table's t_solar, and its solar_powered steps times the step are within half a step of it
    at each crossing of the load; the twofold panel's fold angle is the table's."""
    result = request.getfixturevalue(name)
    series, table = result.timeseries, result.table
    step_h = result.plan.base.step_min / 60 if result.plan.base.step_min else None
    days = pd.DatetimeIndex(series.index).tz_localize(None).normalize()
    step_h = float(np.median(np.diff(series.index.asi8[:50]))) / 3.6e12 if step_h is None else step_h
    assert set(np.unique(series["p_load_w"])) == set(table["p_load_w"])
    assert len(series) == len(table) // 4 * round(24 / step_h)  # every step of every case's day
    checked = 0
    keys = [series["latitude"].to_numpy(), series["p_load_w"].to_numpy(), days.date]
    for (latitude, load, day), rows in series.groupby(keys):
        case = table[(table["latitude"] == latitude) & (table["p_load_w"] == load)
                     & (table["date"] == day.isoformat())].set_index("design")
        assert len(case) == 4
        assert rows["fold_angle_deg"].nunique() == 1
        assert rows["fold_angle_deg"].iloc[0] == case.loc["twofold", "fold_angle_deg"]
        for design in DESIGNS:
            power = rows[f"p_{design}_w"].to_numpy()
            expected = case.loc[design, "t_solar_h"]
            assert _hours_above(power, load, step_h) == pytest.approx(expected, abs=1e-9)
            flag = rows[f"solar_powered_{design}"].to_numpy()
            crossings = np.count_nonzero(np.diff(flag.astype(int)))
            assert abs(flag.sum() * step_h - expected) <= 0.5 * step_h * crossings + 1e-9
            checked += 1
    assert checked == len(table) // 4 * 3


@pytest.mark.parametrize("angle", [100.0, 180.0])
def test_the_series_sun_and_halves_are_pvlibs(angle):
    """One measured day, isotropic sky: the series' apparent zenith and azimuth are pvlib's SPA at
    its times, and each half's poa_global pvlib's isotropic transposition of the series' own
    light at the half's orientation; at the flat panel's 180 deg both halves see the same."""
    result = foldopt.run(request=make_request("run", MEASURED, fields={
        "transposition": "isotropic", "p_load": 2.0, "fold_angles": {"start": angle, "stop": angle, "step": 1}}))
    series = result.timeseries
    day = series[series.index.normalize() == series.index[0].normalize()]
    site = result.plan.base.site
    sun = pvlib.solarposition.get_solarposition(day.index, site.latitude, site.longitude, site.altitude)
    np.testing.assert_allclose(day["apparent_zenith"], sun["apparent_zenith"], atol=1e-4)
    np.testing.assert_allclose(day["solar_azimuth"], sun["azimuth"], atol=1e-4)
    assert (series["fold_angle_deg"] == angle).all()
    halves = foldopt.physics.geometry.subpanel_orientation(
        angle, result.plan.base.panel.tilt, result.plan.base.panel.azimuth, result.plan.base.geometry)
    for side in ("east", "west"):
        poa = pvlib.irradiance.get_total_irradiance(
            halves[f"surface_tilt_{side}"], halves[f"surface_azimuth_{side}"], day["apparent_zenith"],
            day["solar_azimuth"], day["dni"], day["ghi"], day["dhi"], albedo=result.plan.base.albedo,
            model="isotropic")["poa_global"]
        np.testing.assert_allclose(day[f"poa_global_{side}_w_m2"], poa, atol=1e-6, rtol=1e-9)
    same = np.array_equal(series["poa_global_east_w_m2"], series["poa_global_west_w_m2"])
    assert same == (angle == 180.0) and series["poa_global_east_w_m2"].max() > 100


def test_the_cli_writes_the_apis_series_to_the_bit(tmp_path, measured):
    out = tmp_path / "m"
    result = invoke("run", MEASURED, "--out", out)
    assert result.exit_code == 0, result.output
    assert (out / "timeseries.csv").read_bytes() == write_csv(
        measured.timeseries, tmp_path / "api.csv", index=True).read_bytes()


def test_a_long_series_is_parquet(tmp_path, measured, monkeypatch):
    """Above PARQUET_ROWS rows the series is timeseries.parquet, the same table read back."""
    monkeypatch.setattr(series_module, "PARQUET_ROWS", len(measured.timeseries) - 1)
    assert write_series(measured.timeseries, tmp_path) == "timeseries.parquet"
    back = pd.read_parquet(tmp_path / "timeseries.parquet")
    pd.testing.assert_frame_equal(back, measured.timeseries, check_freq=False)
    monkeypatch.setattr(series_module, "PARQUET_ROWS", len(measured.timeseries))
    assert write_series(measured.timeseries, tmp_path) == "timeseries.csv"


@pytest.mark.parametrize("mode", ["exact", "paper"])
def test_a_days_series_names_its_zenith_and_integrates_to_its_t_solar(mode):
    """The day's series: exact mode's sun is refracted (pvlib's apparent_zenith), paper mode's is
    geometric (pvlib's zenith, to the paper's formulas' degree); each design's power re-integrated
    is its summary's t_solar; the halves' poa_global are there at the optimum."""
    result = foldopt.run(request=make_request("run", settings=[f"mode={mode}"]))
    series, summary = result.timeseries, result.summary.set_index("design")
    study = result.study
    sun = pvlib.solarposition.get_solarposition(series.index, study.site.latitude, study.site.longitude,
                                                study.site.altitude)
    name, other = ("apparent_zenith", "zenith") if mode == "exact" else ("zenith", "apparent_zenith")
    assert name in series and other not in series and "solar_zenith" not in series
    np.testing.assert_allclose(series[name], sun[name], atol=1e-4 if mode == "exact" else 1.0)
    step_h = study.step_min / 60
    for design in DESIGNS:
        power = series[f"p_{design}_w"].to_numpy()
        assert _hours_above(power, study.p_load, step_h) == pytest.approx(
            summary.loc[design, "t_solar_h"], abs=1e-9)
        flag = series[f"solar_powered_{design}"].to_numpy()
        assert flag.sum() * step_h == pytest.approx(summary.loc[design, "t_solar_h"], abs=step_h)
    assert (series["poa_global_east_w_m2"] >= 0).all() and series["poa_global_west_w_m2"].max() > 0


def test_a_series_too_long_to_hold_is_not_made_and_the_answer_says_so(monkeypatch):
    """Above MAX_ROWS rows (days x loads x steps) no series is made; the answer says why and how to
    get one; the table is the same."""
    monkeypatch.setattr(series_module, "MAX_ROWS", 1727)  # measured-minutes: 3 days x 2 loads x 288 steps
    result = foldopt.run(MEASURED)
    assert result.timeseries is None
    notes = [note["note"] for note in result.answer.to_dict()["notes"]]
    assert ("no timeseries: its 1,728 rows (days x loads x steps) are above 1,727; fewer days or loads, "
            "or a longer step_min, write it") in notes
    monkeypatch.setattr(series_module, "MAX_ROWS", 1728)
    kept = foldopt.run(MEASURED)
    assert len(kept.timeseries) == 1728 and not any(note["note"].startswith("no timeseries")
                                                    for note in kept.answer.to_dict()["notes"])
    pd.testing.assert_frame_equal(result.table, kept.table)
