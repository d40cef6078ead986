"""Measured sub-hourly weather files (foldopt.inputs.weather.measured) against references computed
here: pvlib.iotools' own reading of each file, pvlib's decompositions, clear sky and solar position,
and means taken by hand. The files are in tests/data/measured (README.md there)."""

from __future__ import annotations

import datetime
import shutil
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pvlib
import pytest

from foldopt.errors import WeatherError
from foldopt.inputs.weather.reader import weather_days
from foldopt import names
from foldopt.inputs.weather.measured import STATION_FORMATS, MeasuredWeather, StationFormat, read_measured

DATA = Path(__file__).resolve().parent / "data" / "measured"
SURFRAD = DATA / "surfrad-slv16001.dat"
SRML = DATA / "SRML-day-EUPO1801.txt"
MIDC_GHI = DATA / "midc_20181014.txt"
MIDC_UAT = DATA / "midc_raw_20181018.txt"
SOLRAD = DATA / "abq19056.dat"
CRN = DATA / "CRNS0101-05-2019-AZ_Tucson_11_W.txt"
FIVE = DATA / "five_minute.csv"
#: The sites of the files that hold none (solarstations.org, station pages).
EUGENE = {"name": "Eugene", "latitude": 44.0468, "longitude": -123.0742, "altitude": 150.0}
NWTC = {"name": "NWTC M2", "latitude": 39.9106, "longitude": -105.2347, "altitude": 1855.0}
UAT = {"name": "UA OASIS", "latitude": 32.22969, "longitude": -110.95534, "altitude": 786.0}


def _sun(frame: pd.DataFrame, site: dict) -> pd.DataFrame:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return pvlib.solarposition.get_solarposition(frame.index, site["latitude"], site["longitude"],
                                                     site["altitude"])


def _closure(weather: MeasuredWeather) -> np.ndarray:
    frame = weather.frame
    cosz = np.cos(np.radians(_sun(frame, weather.site)["zenith"].to_numpy()))
    return (frame.ghi - frame.dni * np.maximum(cosz, 0) - frame.dhi).to_numpy()


def _lit(frame: pd.DataFrame, site: dict) -> np.ndarray:
    """Steps whose clear sky is lit (pvlib's Ineichen): a measured file's light is 0 at the others."""
    location = pvlib.location.Location(site["latitude"], site["longitude"], altitude=site["altitude"])
    return location.get_clearsky(frame.index, model="ineichen")["ghi"].to_numpy() > 0


def _of_the_files_days(weather: MeasuredWeather, raw: pd.DataFrame, centres: pd.DatetimeIndex):
    """The rows of ``raw`` (centred at ``centres``) on the days the file counts: a MIDC day's file
    begins with the stamp 00:00, which ends the minute before midnight, the night of a day the file
    holds nothing else of (not counted, and said so)."""
    held = centres.isin(weather.frame.index)
    assert (~held).sum() == 1 and centres[0].strftime("%H:%M:%S") == "23:59:30"
    assert f"{centres[0].date()} not counted: the file holds only 1 min of it, all at night" in (
        weather.report()
    )
    return raw[held], centres[held]


def _drop_lines(source: Path, target: Path, header: int, rows: slice) -> Path:
    """``source`` without data rows ``rows`` (0-based after ``header`` lines), as ``target``."""
    lines = source.read_text().splitlines(keepends=True)
    keep = lines[:header] + [line for i, line in enumerate(lines[header:]) if not rows.start <= i < rows.stop]
    target.write_text("".join(keep))
    return target


def _write_bsrn(path: Path, frame: pd.DataFrame, site: dict, station: int = 99) -> Path:
    """A BSRN station-to-archive file (LR0001, LR0004, LR0100) in the layout pvlib.iotools.read_bsrn
    parses, of ``frame``'s values at its (UTC, interval-start) stamps, all in one month."""
    t0 = frame.index[0]
    lines = ["*U0001", f"{station:3d}{t0.month:3d} {t0.year:4d} {1:5d}", "*U0004", "01/01/00", " 11  2",
             "test station", " " * 20, " " * 15,
             f"{site['latitude'] + 90:8.3f}{site['longitude'] + 180:8.3f}{int(site['altitude']):5d} SYNOP",
             "01/01/00", "  0  0 -1 -1", "*U0100"]

    def field(value, width):
        return f"{-999 if np.isnan(value) else value:{width}.0f}"

    for stamp, row in zip(frame.index, frame.itertuples(), strict=True):
        day, minute = stamp.day, stamp.hour * 60 + stamp.minute
        lines.append(f"{day:3d} {minute:4d} " + field(row.ghi, 6) + "   0.0" + field(row.ghi, 5) * 2
                     + field(row.dni, 7) + "   0.0" + field(row.dni, 5) * 2 + " " * 20)
        lines.append(" " * 9 + field(row.dhi, 6) + "   0.0" + field(row.dhi, 5) * 2
                     + "    300   0.0  300  300" + f"{row.temp_air:9.1f}" + "  50.0  775")
    path.write_text("\n".join(lines) + "\n")
    return path


# --- The registry and the arguments ---------------------------------------------------------------------------


def test_registry_names_every_format():
    assert set(STATION_FORMATS) == {"surfrad", "midc", "srml", "bsrn", "solrad", "crn", "csv",
                                    "pvgis-hourly"}
    for name, entry in STATION_FORMATS.items():
        assert isinstance(entry, StationFormat) and entry.name == name
        assert entry.interval_label in ("start", "end") and callable(entry.reader)
        assert names.WEATHER_FORMATS.describe(name)  # its description, for help and the docs
    assert {name for name, entry in STATION_FORMATS.items() if not entry.has_site} == {"midc", "srml", "csv"}


def test_unknown_format_lists_the_names():
    with pytest.raises(ValueError) as caught:
        read_measured(SURFRAD, "tmy3")
    assert all(name in str(caught.value) for name in STATION_FORMATS)
    with pytest.raises(ValueError, match="decomposition must be one of erbs, boland, dirint"):
        read_measured(SURFRAD, "surfrad", decomposition="perez")
    with pytest.raises(ValueError, match="label must be one of"):
        read_measured(SURFRAD, "surfrad", label="middle")


# --- Each network's reader against pvlib.iotools' own reading ------------------------------------------------


def test_surfrad_values_are_pvlibs_at_the_interval_centres():
    weather = read_measured(SURFRAD, "surfrad")
    data, meta = pvlib.iotools.read_surfrad(SURFRAD)
    zone = datetime.timezone(datetime.timedelta(hours=-7))
    centres = (data.index - pd.Timedelta(seconds=30)).tz_convert(zone)  # stamps end their minute
    # The UTC day's file holds the evening of 31 December, local time, and none of its daylight:
    # no day of the file (the notes say so).
    held = centres >= pd.Timestamp("2016-01-01", tz=zone)
    assert (centres[~held] >= pd.Timestamp("2015-12-31 16:59", tz=zone)).all() and (~held).sum() == 421
    assert "2015-12-31 not counted: the file holds only 421 min of it, all at night" in weather.report()
    site = weather.site
    location = pvlib.location.Location(site["latitude"], site["longitude"], altitude=site["altitude"])
    assert not (location.get_clearsky(centres[~held], model="ineichen")["ghi"] > 0).any()  # night indeed
    data, centres = data[held], centres[held]
    frame = weather.frame.loc[centres]
    clear = location.get_clearsky(centres, model="ineichen")["ghi"].to_numpy() > 0
    for key in ("dni", "dhi", "temp_air", "wind_speed"):
        expected = data[key].to_numpy()
        if key in ("dni", "dhi"):
            # Night offsets of a few W/m^2 below zero become 0, and there is no light at night.
            expected = np.where(clear, np.maximum(expected, 0.0), 0.0)
        np.testing.assert_allclose(frame[key].to_numpy(), expected, atol=1e-9, err_msg=key)
    # All three measured: the global light is the component sum (BSRN's best estimate of it).
    zenith = pvlib.solarposition.get_solarposition(centres, site["latitude"], site["longitude"], site["altitude"])
    cosz = np.maximum(np.cos(np.radians(zenith["zenith"].to_numpy())), 0.0)
    np.testing.assert_allclose(frame.ghi.to_numpy(), frame.dni.to_numpy() * cosz + frame.dhi.to_numpy(), atol=1e-9)
    assert np.abs(frame.ghi.to_numpy() - np.where(clear, np.maximum(data["ghi"].to_numpy(), 0), 0)).max() < 30.0
    assert weather.site == {"name": "Alamosa", "latitude": 37.7, "longitude": -105.92, "altitude": 2317.0,
                            "timezone": "UTC-07:00"}  # the file writes 105.92 (west positive)
    assert meta["longitude"] == 105.92
    assert weather.step == pd.Timedelta(minutes=1) and weather.derived == {}


def test_surfrad_stamps_end_their_minute_as_its_zenith_column_says():
    """The convention itself: the file's solar zenith is pvlib's apparent zenith at the centres foldopt
    gives its rows (30 s before each stamp), and clearly not at the stamps."""
    data, _ = pvlib.iotools.read_surfrad(SURFRAD)
    weather = read_measured(SURFRAD, "surfrad")
    centres = (data.index - pd.Timedelta(seconds=30)).tz_convert(weather.frame.index.tz)
    low = (data["solar_zenith"] < 80).to_numpy()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        at = {shift: pvlib.solarposition.get_solarposition(data.index + pd.Timedelta(seconds=shift), 37.7, -105.92,
                                                           2317)["apparent_zenith"].to_numpy() for shift in (-30, 0)}
    assert np.abs(at[-30] - data["solar_zenith"].to_numpy())[low].max() < 0.05
    assert np.abs(at[0] - data["solar_zenith"].to_numpy())[low].max() > 0.09
    assert (weather.frame.index.isin(centres)).sum() == len(data) - 421  # 31 Dec's night: no day


def test_a_one_day_file_gives_1440_steps_of_one_minute():
    weather = read_measured(SRML, "srml", site=EUGENE)
    index = weather.frame.index
    assert len(index) == 1440 and weather.step == pd.Timedelta(minutes=1)
    assert index[0] == pd.Timestamp("2018-01-01 00:00:30-08:00") and set(np.diff(index.asi8)) == {60 * 10**9}
    assert weather.site["timezone"] == "UTC-08:00" and weather.flagged_days == () and weather.gaps == ()
    data = pvlib.iotools.read_srml(SRML)  # stamps moved to the start of each minute by pvlib
    lit = _lit(weather.frame, weather.site)
    np.testing.assert_allclose(weather.frame.ghi.to_numpy()[lit], data["ghi_0"].clip(lower=0).to_numpy()[lit])
    assert np.all(weather.frame[["ghi", "dni", "dhi"]].to_numpy()[~lit] == 0)
    assert not weather.frame.isna().any().any()


def test_srml_dhi_by_closure_within_1_w_m2():
    weather = read_measured(SRML, "srml", site=EUGENE)
    assert weather.derived == {"dhi": "closure"}
    assert np.abs(_closure(weather)).max() <= 1.0
    assert (weather.frame.dhi >= 0).all()


def test_midc_ghi_alone_gives_erbs_dni_and_dhi():
    weather = read_measured(MIDC_GHI, "midc", site=NWTC)
    assert weather.derived == {"dni": "erbs", "dhi": "erbs"}
    frame = weather.frame.loc["2018-10-14"]
    zenith = _sun(frame, NWTC)["zenith"]
    expected = pvlib.irradiance.erbs(frame.ghi, zenith, frame.index)
    np.testing.assert_allclose(frame.dni, expected["dni"], atol=1e-9)
    np.testing.assert_allclose(frame.dhi, expected["dhi"], atol=1e-9)
    assert np.nanmax(np.abs(_closure(weather))) <= 1.0
    raw = pvlib.iotools.read_midc(MIDC_GHI)  # stamps end their minute
    centres = (raw.index - pd.Timedelta(seconds=30)).tz_convert(frame.index.tz)
    raw, centres = _of_the_files_days(weather, raw, centres)
    np.testing.assert_allclose(weather.frame.temp_air.loc[centres], raw["Temperature @ 2m [deg C]"])
    np.testing.assert_allclose(weather.frame.ghi.loc[centres], raw["Global PSP [W/m^2]"].clip(lower=0))
    assert "no wind speed in the file: 1 m/s throughout" in weather.report()


@pytest.mark.parametrize("model", ["boland", "dirint"])
def test_other_decompositions(model):
    weather = read_measured(MIDC_GHI, "midc", site=NWTC, decomposition=model)
    assert weather.derived == {"dni": model, "dhi": model}
    frame = weather.frame.loc["2018-10-14"]
    if model == "boland":
        expected = pvlib.irradiance.boland(frame.ghi, _sun(frame, NWTC)["zenith"], frame.index)
        np.testing.assert_allclose(frame.dhi, expected["dhi"], atol=1e-9)
    assert np.nanmax(np.abs(_closure(weather))) <= 1.0 and (frame.dhi >= 0).all()


def test_midc_raw_all_three_measured_are_kept():
    weather = read_measured(MIDC_UAT, "midc", site=UAT)
    raw = pvlib.iotools.read_midc(MIDC_UAT, raw_data=True)
    centres = (raw.index - pd.Timedelta(seconds=30)).tz_convert(weather.frame.index.tz)
    raw, centres = _of_the_files_days(weather, raw, centres)
    frame = weather.frame.loc[centres]
    lit = _lit(frame, weather.site)
    np.testing.assert_allclose(frame.dni[lit], raw["Direct Normal [W/m^2]"].clip(lower=0)[lit])
    np.testing.assert_allclose(frame.wind_speed, raw["Avg Wind Speed @ 3m [m/s]"])
    assert weather.derived == {}
    assert any(line.startswith("ghi, dni and dhi all measured: ghi is their component sum") for line in
               weather.report())


def test_solrad_site_zone_and_values():
    weather = read_measured(SOLRAD, "solrad")
    assert weather.site["timezone"] == "UTC-07:00" and weather.site["latitude"] == 35.03796
    # 00:00 UTC, the minute it ends: the file's dni and dhi there (its ghi, 104.5 W/m^2, gives way
    # to their component sum).
    assert weather.frame.dhi.loc["2019-02-24 16:59:30-07:00"] == pvlib.iotools.read_solrad(SOLRAD)[0].dhi.iloc[0]
    # The file's 4 minutes: the rest of its daylight is a gap too long to fill.
    assert weather.flagged_days == (datetime.date(2019, 2, 24),)


def test_crn_five_minutes_site_from_rows():
    weather = read_measured(CRN, "crn")
    assert weather.step == pd.Timedelta(minutes=5) and len(weather.frame) == 288
    assert weather.site["timezone"] == "UTC-07:00"  # LST 09:10 at 16:10 UTC
    assert weather.site["altitude"] == pvlib.location.lookup_altitude(32.24, -111.17)
    row = weather.frame.loc["2019-01-01 09:12:30-07:00"]  # the 5 minutes ending 16:15 UTC
    assert (row.ghi, row.temp_air, row.wind_speed) == (183.0, 3.3, 0.36)
    assert weather.derived == {"dni": "erbs", "dhi": "erbs"}


def test_bsrn_station_to_archive_file(tmp_path):
    """BSRN's own files may not be passed on (README.md): a station-to-archive file is written here, in
    BSRN's layout, of SURFRAD's minutes moved to BSRN's interval-start stamps."""
    surfrad = read_measured(SURFRAD, "surfrad")
    site = {key: surfrad.site[key] for key in ("latitude", "longitude", "altitude")}
    day = surfrad.frame.loc["2016-01-01 00:00":"2016-01-01 16:58:59"].round(0)
    utc = day.copy()
    utc.index = (day.index - pd.Timedelta(seconds=30)).tz_convert("UTC")
    path = _write_bsrn(tmp_path / "bsrn0116.dat", utc, site)
    weather = read_measured(path, "bsrn")
    assert weather.site == {"name": "BSRN station 99", **site, "timezone": "UTC-07:00"}
    frame = weather.frame.loc[day.index]
    for key in ("dni", "dhi"):
        np.testing.assert_allclose(frame[key], day[key])
    np.testing.assert_allclose(frame.temp_air, day.temp_air.round(1))
    assert (weather.frame.wind_speed == 1.0).all()


# --- Gaps --------------------------------------------------------------------------------------------------------


def test_a_short_gap_is_filled_along_the_clear_sky_index(tmp_path):
    path = _drop_lines(SRML, tmp_path / "srml_gap.txt", 1, slice(660, 680))  # 11:00-11:20 PST
    weather = read_measured(path, "srml", site=EUGENE)
    assert weather.filled_steps == 20 and weather.flagged_days == ()
    (start, stop, minutes), = weather.gaps
    assert (start, stop, minutes) == (pd.Timestamp("2018-01-01 11:00-08:00"), pd.Timestamp("2018-01-01 11:20-08:00"),
                                      20.0)
    frame = weather.frame
    clear = pvlib.location.Location(EUGENE["latitude"], EUGENE["longitude"], altitude=EUGENE["altitude"]) \
        .get_clearsky(frame.index)["ghi"]
    kt = frame.ghi / clear
    before, after = kt.iloc[659], kt.iloc[680]
    expected = (before + (after - before) * np.arange(1, 21) / 21) * clear.iloc[660:680]
    np.testing.assert_allclose(frame.ghi.iloc[660:680], expected, rtol=1e-9)
    assert np.abs(_closure(weather)).max() <= 1.0 and not frame.isna().any().any()
    untouched = read_measured(SRML, "srml", site=EUGENE).frame
    pd.testing.assert_frame_equal(frame.drop(frame.index[660:680]), untouched.drop(untouched.index[660:680]))


def test_a_long_gap_flags_the_day_and_stays_missing(tmp_path):
    path = _drop_lines(SRML, tmp_path / "srml_long.txt", 1, slice(600, 690))  # 10:00-11:30 PST
    weather = read_measured(path, "srml", site=EUGENE)
    assert weather.flagged_days == (datetime.date(2018, 1, 1),) and weather.filled_steps == 0
    assert [gap[2] for gap in weather.gaps] == [90.0]
    assert weather.frame.ghi.iloc[600:690].isna().all() and weather.frame.drop(weather.frame.index[600:690]).notna() \
        .all().all()
    assert any("too long to fill" in line for line in weather.report())
    longer = read_measured(path, "srml", site=EUGENE, max_gap_min=120)
    assert longer.filled_steps == 90 and longer.flagged_days == () and longer.frame.notna().all().all()


def test_a_night_gap_is_dark(tmp_path):
    path = _drop_lines(SRML, tmp_path / "srml_night.txt", 1, slice(120, 240))  # 02:00-04:00 PST
    weather = read_measured(path, "srml", site=EUGENE)
    assert weather.gaps == () and weather.filled_steps == 0
    assert (weather.frame.iloc[120:240][["ghi", "dni", "dhi"]] == 0).all().all()


def test_a_spike_is_dropped_and_filled(tmp_path):
    lines = SRML.read_text().splitlines(keepends=True)
    fields = lines[1 + 720].split("\t")
    fields[2] = "2500"  # ghi at 12:00-12:01 PST, far above 1.5 E0 mu0^1.2 + 100
    lines[1 + 720] = "\t".join(fields)
    (tmp_path / "srml_spike.txt").write_text("".join(lines))
    weather = read_measured(tmp_path / "srml_spike.txt", "srml", site=EUGENE)
    assert weather.filled_steps == 1 and weather.frame.ghi.iloc[720] < 500
    assert "values beyond physical bounds made missing: ghi 1" in weather.report()


# --- The generic CSV ---------------------------------------------------------------------------------------------


def test_five_minute_csv_is_the_mean_of_the_one_minute_day():
    five = read_measured(FIVE, "csv", site=UAT)
    one = read_measured(MIDC_UAT, "midc", site=UAT)
    assert five.step == pd.Timedelta(minutes=5) and len(five.frame) == 288
    assert five.frame.index[0] == pd.Timestamp("2018-10-18 00:02:30-07:00")
    # The means by hand: the file's minutes ending 00:01 to 00:05 make 00:00-00:05 (centre 00:02:30)...
    raw = pvlib.iotools.read_midc(MIDC_UAT, raw_data=True).iloc[1:]
    means = raw.groupby(np.arange(len(raw)) // 5).mean().iloc[:287]
    lit = _lit(five.frame, five.site)[:287]
    np.testing.assert_allclose(five.frame.dhi.iloc[:287][lit], means["Diffuse Horiz [W/m^2]"].clip(
        lower=0)[lit], atol=0.051)
    np.testing.assert_allclose(five.frame.temp_air.iloc[:287], means["Air Temperature [deg C]"], atol=0.0051)
    # ...and the 1-min reading gives the same light, but where night offsets are clipped before averaging.
    day = one.frame.loc["2018-10-18"].iloc[:-5].groupby(np.arange(1435) // 5).mean()
    np.testing.assert_allclose(five.frame.dni.iloc[:287], day.dni, atol=0.3)
    assert five.frame.ghi.iloc[287] == 0  # 23:55-24:00: not in the file, dark
    assert five.site["timezone"] == "UTC-07:00" and five.derived == {}


def _csv(path: Path, rows: list[str], header: str = "timestamp,ghi,dni,dhi") -> Path:
    path.write_text(header + "\n" + "\n".join(rows) + "\n")
    return path


def _stamps(start: str, count: int, minutes: int = 5, fmt: str = "%Y-%m-%dT%H:%M:%S%z") -> list[str]:
    times = pd.date_range(start, periods=count, freq=f"{minutes}min")
    return [f"{t.strftime(fmt)[:-2]}:{t.strftime(fmt)[-2:]}" if t.tzinfo else t.strftime(fmt) for t in times]


def test_csv_without_site_names_the_field(tmp_path):
    path = _csv(tmp_path / "x.csv", [f"{t},0,0,0" for t in _stamps("2020-06-01 00:05-07:00", 3)])
    with pytest.raises(WeatherError) as caught:
        read_measured(path, "csv")
    assert str(caught.value) == ("weather x.csv: the csv format holds no site; give site latitude, longitude and "
                                 "altitude")
    with pytest.raises(WeatherError) as caught:
        read_measured(path, "csv", site={"latitude": 32.2, "longitude": -110.9})
    assert str(caught.value) == "weather x.csv: site has no altitude: give site latitude, longitude and altitude"
    with pytest.raises(WeatherError, match=r"^weather x.csv: site: latitude = 95 deg: must be in \[-90, 90\] deg$"):
        read_measured(path, "csv", site={"latitude": 95, "longitude": -110.9, "altitude": 0})


def test_csv_naive_stamps_need_a_timezone(tmp_path):
    rows = [f"{t},0,0,0" for t in _stamps("2020-06-01 00:05", 3, fmt="%Y-%m-%d %H:%M")]
    path = _csv(tmp_path / "naive.csv", rows)
    with pytest.raises(WeatherError, match="^weather naive.csv: the timestamps carry no UTC offset: give timezone"):
        read_measured(path, "csv", site=UAT)
    weather = read_measured(path, "csv", site=UAT, timezone="UTC-07:00")
    assert weather.frame.index[0] == pd.Timestamp("2020-06-01 00:02:30-07:00") and len(weather.frame) == 288
    aware = _csv(tmp_path / "aware.csv", [f"{t},0,0,0" for t in _stamps("2020-06-01 07:05Z", 3)])
    pd.testing.assert_frame_equal(read_measured(aware, "csv", site=UAT, timezone="UTC-07:00").frame, weather.frame)
    assert read_measured(aware, "csv", site=UAT).site["timezone"] == "UTC+00:00"  # the stamps' own offset


@pytest.mark.parametrize("rows, message", [
    (["2020-06-01T00:05-07:00,0,0,0", "2020-06-01T00:05-07:00,0,0,0", "2020-06-01T00:10-07:00,0,0,0"],
     "1 duplicate stamp, the first 2020-06-01 00:05:00-07:00"),
    (["2020-06-01T00:05-07:00,0,0,0", "2020-06-01T00:10-07:00,0,0,0", "2020-06-01T00:12:30-07:00,0,0,0",
      "2020-06-01T00:15-07:00,0,0,0", "2020-06-01T00:20-07:00,0,0,0"],
     "1 stamp off the 5-min grid of the others, the first 2020-06-01 00:12:30-07:00"),
    (["2020-06-01T00:07-07:00,0,0,0", "2020-06-01T00:14-07:00,0,0,0"], "step 7-min: a measured file's step must"),
    (["2020-06-01T00:05-07:00,0,0,0", "2020-06-01 00:10,0,0,0"], "row 2: timestamp '2020-06-01 00:10' has no UTC"),
    (["2020-06-01T00:05-07:00,abc,0,0", "2020-06-01T00:10-07:00,0,0,0"], "row 1: ghi = 'abc': not a number"),
    (["yesterday,0,0,0"], "row 1: timestamp = 'yesterday': not an ISO 8601 date and time"),
])
def test_bad_csv_gives_one_line(tmp_path, rows, message):
    with pytest.raises(WeatherError) as caught:
        read_measured(_csv(tmp_path / "bad.csv", rows), "csv", site=UAT)
    text = str(caught.value)
    assert text.startswith(f"weather bad.csv: {message}") and "\n" not in text


def test_csv_components_by_closure_or_refused(tmp_path):
    five = read_measured(FIVE, "csv", site=UAT).frame.loc["2018-10-18 09:00":"2018-10-18 10:00"]
    stamps = [t.isoformat() for t in five.index + pd.Timedelta(minutes=2.5)]
    rows = [f"{t},{r.dni},{r.dhi}" for t, r in zip(stamps, five.itertuples(), strict=True)]
    weather = read_measured(_csv(tmp_path / "beam.csv", rows, "timestamp,dni,dhi"), "csv", site=UAT)
    assert weather.derived == {"ghi": "closure"} and np.nanmax(np.abs(_closure(weather))) <= 1.0
    with pytest.raises(WeatherError, match="^weather dni.csv: no ghi column, nor dni and dhi"):
        read_measured(_csv(tmp_path / "dni.csv", [f"{t},{r.dni}" for t, r in zip(stamps, five.itertuples(),
                                                                                strict=True)], "timestamp,dni"),
                      "csv", site=UAT)


# --- Files that cannot be used, options, and the study's use -----------------------------------------------------


def test_unusable_files_give_one_line(tmp_path):
    (tmp_path / "empty.dat").write_text("")
    (tmp_path / "junk.dat").write_text("not\na\nsurfrad file\n")
    for name, fmt, message in (("empty.dat", "surfrad", "the file is empty"),
                               ("junk.dat", "surfrad", "not a readable SURFRAD file"),
                               ("missing.dat", "solrad", "file not found"),
                               ("junk.dat", "bsrn", "not a readable BSRN file")):
        with pytest.raises(WeatherError) as caught:
            read_measured(tmp_path / name, fmt)
        assert str(caught.value).startswith(f"weather {name}: {message}") and "\n" not in str(caught.value)
    with pytest.raises(WeatherError, match="^weather midc_20181014.txt: the midc format holds no site"):
        read_measured(MIDC_GHI, "midc")


def test_label_and_timezone_arguments():
    end = read_measured(SURFRAD, "surfrad")
    start = read_measured(SURFRAD, "surfrad", label="start")
    shifted = start.frame.dni.copy()
    shifted.index = shifted.index - pd.Timedelta(minutes=1)
    common = end.frame.index.intersection(shifted.index)[1:-1]
    # The same minutes of light, a minute apart (but at sunrise and sunset, where a minute moves
    # the dark clear sky's edge).
    both = end.frame.dni.loc[common].notna() & shifted.loc[common].notna() & (shifted.loc[common] > 0)
    assert both.sum() > 400
    np.testing.assert_allclose(end.frame.dni.loc[common][both][1:-1], shifted.loc[common][both][1:-1])
    utc = read_measured(SURFRAD, "surfrad", timezone="UTC")
    # On UTC the file's minutes run from 23:59-00:00 on December 31 (the stamp 00:00 ends it) to
    # 23:58-23:59: December 31 is no day of the file, and the minute it leaves on January 1 is
    # filled and said so.
    assert utc.site["timezone"] == "UTC+00:00" and len(utc.frame) == 1440
    assert utc.frame.index[0] == pd.Timestamp("2016-01-01 00:00:30Z")
    assert utc.flagged_days == () and utc.gaps == ()
    assert "2015-12-31 not counted: the file holds only 1 min of it, all at night" in utc.report()
    assert ("1 min after the file's last period filled (2016-01-01 23:59 to 00:00; night: light 0; air "
            "temperature and wind speed the nearest step's)") in utc.report()


def test_report_and_the_studys_days():
    weather = read_measured(SURFRAD, "surfrad")
    lines = weather.report()
    assert lines[0].startswith("measured weather surfrad-slv16001.dat: 1-min steps, 1 day (2016-01-01 to 2016-01-01)")
    assert all(isinstance(line, str) and "\n" not in line for line in lines)
    assert (weather.frame[["ghi", "dni", "dhi"]].dropna() >= 0).all().all()
    rows = weather_days(weather.frame, [datetime.date(2016, 1, 1)])
    assert rows.shape == (1, 1440)
    assert weather.frame.iloc[rows[0]].notna().all().all()


def test_copy_keeps_the_name(tmp_path):
    copy = shutil.copy(SOLRAD, tmp_path / "abq.dat")
    assert read_measured(copy, "solrad").frame.attrs["weather"] == "abq.dat"
