"""Real skies: weather files, clear skies with diffuse light, transposition, annual objectives."""

import datetime as dt
from pathlib import Path

import numpy as np
import pvlib
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from foldopt.inputs.study import make_study
from foldopt.physics.geometry import subpanel_orientation
from foldopt.studies.day import Day
from foldopt.studies.sweeps import objective_value
from foldopt.inputs.weather.reader import read_weather, weather_day

TMY3 = Path(pvlib.__file__).parent / "data" / "723170TYA.CSV"  # NREL TMY3 sample pvlib ships
SITE = {"latitude": 36.1, "longitude": -79.95, "altitude": 273, "timezone": "UTC-05:00"}
BASE = {"name": "w", "mode": "exact", "site": SITE, "date": "2025-06-21", "panel": {"area": 0.108},
        "p_load": 3.0, "fold_angles": {"start": 10, "stop": 180, "step": 10}}


def test_tmy3_timestamps_move_to_interval_centres():
    frame = read_weather(TMY3)
    assert len(frame) == 8760
    # TMY3 stamps the end of each hour: 01:00 is the hour 00:00-01:00, centred at 00:30.
    assert frame.index[0].strftime("%H:%M %z") == "00:30 -0500"
    day = weather_day(frame, dt.date(2025, 6, 21))
    assert len(day) == 24 and day.index[-1].hour == 23
    raw, _ = pvlib.iotools.read_tmy3(TMY3, coerce_year=2025, map_variables=True)
    np.testing.assert_allclose(frame["ghi"].iloc[:48], raw["ghi"].iloc[:48])


def test_beam_only_equals_transposition_without_diffuse():
    # Meinel gives beam only; through the isotropic transposition with no diffuse and no ground
    # reflection, the sub-panels must see exactly the beam-only irradiance.
    beam = Day(make_study({**BASE, "sky": "meinel", "transposition": "none"}))
    transposed = Day(make_study({**BASE, "sky": "meinel", "transposition": "isotropic", "albedo": 0.0}))
    angles = np.array([30.0, 90.0, 180.0])
    for name in ("east", "west", "switching"):
        np.testing.assert_allclose(transposed.connections(angles)[0][name], beam.connections(angles)[0][name],
                                   rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("model", ["isotropic", "haydavies", "perez"])
def test_subpanel_irradiance_is_pvlibs_total_irradiance(model):
    day = Day(make_study({**BASE, "weather": str(TMY3), "transposition": model, "albedo": 0.25}))
    sides = subpanel_orientation(np.array([60.0]), 36.1, 180.0, "hinge")
    for side in ("east", "west"):
        tilt, azimuth = sides[f"surface_tilt_{side}"][0], sides[f"surface_azimuth_{side}"][0]
        expected = pvlib.irradiance.get_total_irradiance(
            tilt, azimuth, day.solar_zenith, day.solar_azimuth, day.dni, day.ghi, day.dhi,
            dni_extra=pvlib.irradiance.get_extra_radiation(day.times.day_of_year),
            airmass=np.nan_to_num(pvlib.atmosphere.get_relative_airmass(np.minimum(day.solar_zenith, 90.0))),
            albedo=0.25, model=model,
        )["poa_global"]
        np.testing.assert_allclose(day._poa(np.array([tilt]), np.array([azimuth]))[0],
                                   np.nan_to_num(np.asarray(expected)), rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("sky", ["ineichen", "simplified-solis"])
def test_clear_skies_give_diffuse_light(sky):
    day = Day(make_study({**BASE, "sky": sky}))
    assert day.transposition == "perez"
    assert day.dhi.max() > 30 and day.dni.max() > 700
    np.testing.assert_allclose(day.ghi, day.dni * np.clip(np.cos(np.radians(day.solar_zenith)), 0, None) + day.dhi,
                               rtol=0.02, atol=15)  # closure of the clear-sky components


def test_iam_only_reduces_the_beam():
    plain = Day(make_study({**BASE, "sky": "ineichen"}))
    modified = Day(make_study({**BASE, "sky": "ineichen", "iam": "ashrae"}))
    assert np.all(modified.flat_power() <= plain.flat_power() + 1e-12)
    assert modified.flat_power().sum() < plain.flat_power().sum()


def test_objective_statistics():
    hours = np.array([[1.0, 5.0], [3.0, 5.0], [8.0, 5.0], [10.0, 5.0]])  # 4 days x 2 angles
    months = [1, 1, 7, 7]
    np.testing.assert_allclose(objective_value(hours, months, "mean"), [5.5, 5.0])
    np.testing.assert_allclose(objective_value(hours, months, "min"), [1.0, 5.0])
    np.testing.assert_allclose(objective_value(hours, months, "worst-month"), [2.0, 5.0])
    np.testing.assert_allclose(objective_value(hours, months, "p50"), [5.5, 5.0])
    np.testing.assert_allclose(objective_value(hours, months, "mean", season=[7]), [9.0, 5.0])


def test_an_annual_objective_keeps_one_angle_all_year():
    from foldopt.inputs.plan import make_plan
    from foldopt.studies.sweeps import run_plan

    plan = make_plan({**BASE, "weather": str(TMY3), "date": "1:365:30", "p_load": [2.0, 4.0],
                      "objective": {"statistic": "mean"}})
    result = run_plan(plan)
    twofold = result.table[result.table.design == "twofold"]
    assert (twofold.groupby("p_load_w")["fold_angle_deg"].nunique() == 1).all()
    assert result.extras["p_twofold_w"].shape == (13, 1440)  # the study's 1-min steps, not the file's hours
    # The chosen angle maximises the mean over the days among the grid's angles.
    flat = result.table[result.table.design == "flat"]
    assert twofold["t_solar_h"].mean() >= flat["t_solar_h"].mean() - 1e-9


def write_epw(path, ghi_at_noon=800.0):
    """A minimal two-day EPW (8 header lines, 35 fields a row) with a half-sine day."""
    header = [
        "LOCATION,Test,XX,XXX,Synthetic,000000,36.10,-79.95,-5.0,273.0",
        "DESIGN CONDITIONS,0", "TYPICAL/EXTREME PERIODS,0", "GROUND TEMPERATURES,0",
        "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0", "COMMENTS 1,synthetic", "COMMENTS 2,",
        "DATA PERIODS,1,1,Data,Sunday, 6/21,6/22",
    ]
    rows = []
    for day in (21, 22):
        for hour in range(1, 25):  # EPW hour h is the interval (h-1, h]
            centre = hour - 0.5
            ghi = max(0.0, ghi_at_noon * np.sin(np.pi * (centre - 6) / 12)) if 6 < centre < 18 else 0.0
            fields = [2005, 6, day, hour, 60, "?", 25.0, 15.0, 50, 100000, 0, 1415, 300, ghi, 0.8 * ghi,
                      0.2 * ghi, 0, 0, 0, 0, 180, 2.0, 0, 0, 20, 99999, 9, 999999999, 0, 0.1, 0, 88, 0.2, 0, 1]
            rows.append(",".join(str(f) for f in fields))
    path.write_text("\n".join(header + rows) + "\n")


def test_epw_timestamps_move_to_interval_centres(tmp_path):
    path = tmp_path / "site.epw"
    write_epw(path)
    frame = read_weather(path)
    assert len(frame) == 48
    day = weather_day(frame, dt.date(2025, 6, 21))
    # The row for EPW hour 13 (12:00-13:00) is centred at 12:30 and carries the noon-side value.
    assert day.index[12].strftime("%H:%M") == "12:30"
    assert day["ghi"].iloc[12] == pytest.approx(800.0 * np.sin(np.pi * 6.5 / 12))
    assert day["dni"].iloc[12] == pytest.approx(0.8 * day["ghi"].iloc[12])
    # The study runs on its own 1-minute steps; each hour of the file keeps its direct and diffuse
    # means, and the global light is their sum (ghi = dni cos(zenith) + dhi) at every step.
    day = Day(make_study({**BASE, "weather": str(path), "date": "2025-06-22"}))
    assert day.step_hours == pytest.approx(1 / 60)
    hourly = weather_day(frame, dt.date(2025, 6, 22))
    for key in ("dni", "dhi"):
        np.testing.assert_allclose(getattr(day, key).reshape(24, 60).mean(axis=1), hourly[key], rtol=1e-12, atol=1e-9)
    beam = day.dni * np.clip(np.cos(np.radians(day.solar_zenith)), 0, None)
    np.testing.assert_allclose(day.ghi, beam + day.dhi, atol=1e-9)


def test_the_formats_registry_is_the_names_a_study_accepts():
    """A format is one module and one entry of FORMATS; validation and help read the names'."""
    from foldopt import names
    from foldopt.inputs.weather.reader import FORMATS, MEASURED_FORMATS, weather_format

    assert tuple(FORMATS) + tuple(MEASURED_FORMATS) == tuple(names.WEATHER_FORMATS)
    assert tuple(FORMATS) == names.HOURLY_WEATHER_FORMATS
    assert {entry.interval_label for entry in FORMATS.values()} <= set(names.INTERVAL_LABELS)
    assert [weather_format(Path(f"x{suffix.upper()}")) for suffix in (".csv", ".epw", ".json", ".txt")] == [
        "tmy3", "epw", "pvgis", "tmy3"]


@settings(max_examples=60, deadline=None)
@given(start=st.datetimes(dt.datetime(1999, 12, 31), dt.datetime(2101, 1, 1)).map(lambda t: t.replace(microsecond=0)),
       hours=st.integers(1, 80), offset_min=st.integers(-14 * 60, 14 * 60), year=st.integers(1970, 2200),
       unit=st.sampled_from(["s", "us", "ns"]))
@example(start=dt.datetime(2024, 2, 28, 20), hours=3, offset_min=-300, year=2025, unit="us")  # February 29
@example(start=dt.datetime(2024, 12, 31, 20), hours=3, offset_min=840, year=2025, unit="ns")  # the next year
def test_a_pvgis_years_stamps_take_the_year_as_timestamp_replace_gives_them(start, hours, offset_min, year, unit):
    """PVGIS's stamps moved to the study's year in one step are, stamp by stamp, pandas'
    ``Timestamp.replace(year=year)`` (the reference), on a fixed offset or none; a February 29
    and a year without one are refused as it refuses them."""
    import pandas as pd

    from foldopt.inputs.weather.formats import offset_zone
    from foldopt.inputs.weather.pvgis import in_year

    utc = pd.date_range(start, periods=hours, freq="7h", tz="UTC", unit=unit)
    for stamps in (utc.tz_convert(offset_zone(offset_min / 60)), utc.tz_localize(None)):
        try:
            expected = pd.DatetimeIndex([stamp.replace(year=year) for stamp in stamps])
        except ValueError:
            with pytest.raises(ValueError):
                in_year(stamps, year)
            continue
        moved = in_year(stamps, year)
        assert moved.equals(expected) and moved.dtype == expected.dtype and moved.freq is None
