"""Weather files are checked when read: every fault is one WeatherError line naming the file, the
line (TMY3 and EPW files count their 2 and 8 header lines), record or column, and the reason. The
bad files are the TMY3 sample pvlib ships, or an EPW or PVGIS file written from it, damaged."""

import datetime as dt
import json
import re
from pathlib import Path

import pandas as pd
import pvlib
import pytest
from test_weather_year import write_epw_year

from foldopt.inputs.plan import make_plan
from foldopt.errors import ConfigError
from foldopt.studies.sweeps import run_plan
from foldopt.inputs.weather.reader import read_weather, weather_days, weather_site
from foldopt.errors import WeatherError

DATA = Path(pvlib.__file__).parent / "data"
TMY3 = DATA / "723170TYA.CSV"  # Greensboro, NC: 2 header lines, then 8760 rows from line 3
#: One worker runs this module (pytest-xdist --dist loadgroup), so that the session's written EPW and
#: PVGIS years are written once, not by each worker that runs a test of it.
pytestmark = pytest.mark.xdist_group("weather_validation")
STUDY = {"name": "g", "panel": {"area": 0.108}, "p_load": 2.0}
# Columns of a TMY3 row (0-based), as the sample's line 2 names them.
GHI, DNI, DHI, DRY_BULB = 4, 7, 10, 31
# EPW fields (0-based): dry bulb, GHI, DNI, DHI.
EPW_TEMP, EPW_GHI, EPW_DNI, EPW_DHI = 6, 13, 14, 15
CLEAR_NOON = 2391  # TMY3 line of 1980-04-10 13:00 (the hour 12:00-13:00): GHI 880, DNI 878, DHI 106
EPW_CLEAR_NOON = CLEAR_NOON - 2 + 8  # the same hour in an EPW written from the sample


def tmy3_lines() -> list[str]:
    return TMY3.read_text().splitlines()


def set_field(lines: list[str], line: int, column: int, value) -> list[str]:
    """``lines`` with field ``column`` of file line ``line`` (1-based) set to ``value``."""
    lines = list(lines)
    fields = lines[line - 1].split(",")
    fields[column] = str(value)
    lines[line - 1] = ",".join(fields)
    return lines


def write_pvgis_year(path, frame, site):
    """A PVGIS TMY JSON file (hour-start stamps in UTC, a cyclic year from January 1 00:00 UTC)
    holding the hourly light, air temperature and wind of ``frame``."""
    records = []
    starts = (frame.index - pd.Timedelta(minutes=30)).tz_convert("UTC")
    # Rows as tuples of floats (a whole year's iterrows cost a second of the module's setup).
    values = frame[["temp_air", "ghi", "dni", "dhi", "wind_speed"]].astype(float).itertuples(index=False)
    for start, (temp_air, ghi, dni, dhi, wind_speed) in zip(starts, values, strict=True):
        start = start.replace(year=2025)  # the last local hours of the year are UTC's first
        records.append((start, {"T2m": temp_air, "RH": 50.0, "G(h)": ghi, "Gb(n)": dni,
                                "Gd(h)": dhi, "IR(h)": 300.0, "WS10m": wind_speed, "WD10m": 180.0,
                                "SP": 100000.0}))
    records.sort(key=lambda item: item[0])
    hourly = [{"time(UTC)": start.strftime("%Y%m%d:%H%M"), **values} for start, values in records]
    source = {
        "inputs": {"location": {"latitude": site["latitude"], "longitude": site["longitude"],
                                "elevation": site["altitude"]},
                   "meteo_data": {"radiation_db": "test", "meteo_db": "test", "year_min": 2025, "year_max": 2025}},
        "outputs": {"months_selected": [{"month": m, "year": 2025} for m in range(1, 13)], "tmy_hourly": hourly},
        "meta": {"inputs": {}, "outputs": {}},
    }
    path.write_text(json.dumps(source, indent=1))


@pytest.fixture(scope="session")
def written(tmp_path_factory):
    """The TMY3 sample written as EPW and as PVGIS JSON: (epw lines, pvgis text)."""
    folder = tmp_path_factory.mktemp("written")
    frame, site = read_weather(TMY3), weather_site(TMY3)
    write_epw_year(folder / "g.epw", frame, site)
    write_pvgis_year(folder / "g.json", frame, site)
    return (folder / "g.epw").read_text().splitlines(), (folder / "g.json").read_text()


def _tmy3(change):
    return lambda written: ("\n".join(change(tmy3_lines())) + "\n")


def _epw(change):
    return lambda written: "\n".join(change(written[0])) + "\n"


def _duplicate(lines, line):
    return lines[:line] + [lines[line - 1]] + lines[line:]


def _negative_dni(lines):
    # DNI of -5 W/m^2 on 23 hours from 2025-02-03 11:00 (line 795 holds February 3, 00:00-01:00).
    for line in range(3 + 24 * 33 + 11, 3 + 24 * 33 + 11 + 23):
        lines = set_field(lines, line, DNI, -5)
    return lines


# (case, file name, its text from the written fixture, the message after "weather NAME: ")
CASES = [
    ("empty file", "empty.csv", lambda w: "", r"the file is empty"),
    ("blank file", "blank.epw", lambda w: "\n \n", r"the file is empty"),
    ("header only", "header.csv", _tmy3(lambda lines: lines[:2]),
     r"no data rows: a TMY3 file has 2 header lines, then one row per hour; this one ends at line 2"),
    ("EPW header only", "header.epw", _epw(lambda lines: lines[:8]),
     r"no data rows: a EPW file has 8 header lines, then one row per hour; this one ends at line 8"),
    ("not weather", "prices.csv", lambda w: "item,price\napple,1.20\npear,0.90\n",
     r"line 1: the TMY3 header has no TZ, latitude, longitude, altitude \(2 fields; it holds 7: USAF, "),
    ("wide CSV, not weather", "results.csv",
     lambda w: "date,design,p_load_w,t_solar_h,a,b,c\n2025-01-01,flat,2,5,1,2,3\n",
     r"line 1: USAF = 'date': not a station number, so not a TMY3 header"),
    ("CSV named .epw", "prices.epw", lambda w: "item,price\napple,1.20\n",
     r"line 1: not an EPW header: it starts 'item,price', not 'LOCATION,'"),
    ("no date column", "nodate.csv", _tmy3(lambda lines: [lines[0], lines[1].replace("Date (MM/DD/YYYY)", "Day"),
                                                            *lines[2:]]),
     r"not a readable TMY3 file \(missing 'Date \(MM/DD/YYYY\)'\)"),
    ("missing ghi column", "noghi.csv", _tmy3(lambda lines: [lines[0], lines[1].replace("GHI (W/m^2)", "Global"),
                                                               *lines[2:]]),
     r"column ghi missing: no 'GHI \(W/m\^2\)' in line 2, the column names of this TMY3 file"),
    ("NaN in ghi", "nan.csv", _tmy3(lambda lines: set_field(set_field(lines, 1234, GHI, ""), 4000, GHI, "NaN")),
     r"line 1234 \(2025-02-21 07:00-08:00\): ghi has no value \(empty or NaN\); and 1 more rows"),
    ("text in dhi", "text.csv", _tmy3(lambda lines: set_field(lines, 1234, DHI, "abc")),
     r"line 1234 \(2025-02-21 07:00-08:00\): dhi = abc: not a finite number"),
    ("negative dni", "negative.csv", _tmy3(_negative_dni),
     r"line 806 \(2025-02-03 11:00-12:00\): dni = -5 W/m\^2: must be >= 0; and 22 more rows"),
    ("EPW 9999 in dni", "missing.epw", _epw(lambda lines: set_field(lines, EPW_CLEAR_NOON, EPW_DNI, 9999)),
     (rf"line {EPW_CLEAR_NOON} \(2025-04-10 12:00-13:00\): dni = 9999 W/m\^2 \(EPW's missing-value marker\): "
      r"must be <= 1\d{3} W/m\^2, the extraterrestrial normal irradiance that day")),
    ("EPW 9999 in ghi", "missingghi.epw", _epw(lambda lines: set_field(lines, EPW_CLEAR_NOON, EPW_GHI, 9999)),
     (rf"line {EPW_CLEAR_NOON} \(2025-04-10 12:00-13:00\): ghi = 9999 W/m\^2 \(EPW's missing-value marker\): "
      r"must be <= 2\d{3} W/m\^2, 1.5 times the extraterrestrial normal irradiance that day")),
    ("DHI > GHI", "diffuse.csv", _tmy3(lambda lines: set_field(lines, CLEAR_NOON, DHI, 1200)),
     (rf"line {CLEAR_NOON} \(2025-04-10 12:00-13:00\): dhi = 1200 W/m\^2 exceeds ghi = 880 W/m\^2: the diffuse "
      r"light is part of the global \(tolerance 10% \+ 10 W/m\^2\)")),
    ("DNI cos Z >> GHI", "beam.csv", _tmy3(lambda lines: set_field(set_field(lines, CLEAR_NOON, GHI, 100),
                                                                  CLEAR_NOON, DHI, 100)),
     (rf"line {CLEAR_NOON} \(2025-04-10 12:00-13:00\): dni = 878 W/m\^2 at solar zenith 2\d\.\d deg brings 7\d\d "
      r"W/m\^2 to the ground, more than ghi = 100 W/m\^2 \(tolerance 50 W/m\^2\): is the file's site, clock or "
      r"a column wrong\?")),
    ("EPW temp_air 99.9", "hot.epw", _epw(lambda lines: set_field(lines, 100, EPW_TEMP, 99.9)),
     (r"line 100 \(2025-01-04 19:00-20:00\): temp_air = 99.9 C \(EPW's missing-value marker\): must be in "
      r"\[-90, 65\] C")),
    ("TMY3 temp_air 99.9", "hot.csv", _tmy3(lambda lines: set_field(lines, 100, DRY_BULB, 99.9)),
     r"line 100 \(2025-01-05 01:00-02:00\): temp_air = 99.9 C: must be in \[-90, 65\] C"),
    ("duplicated timestamp", "twice.csv", _tmy3(lambda lines: _duplicate(lines, 1000)),
     r"line 1001 \(2025-02-11 13:00-14:00\): the same hour as line 1000"),
    ("rows out of order", "order.csv", _tmy3(lambda lines: lines[:999] + [lines[1000], lines[999]] + lines[1001:]),
     r"line 1001 \(2025-02-11 13:00-14:00\): before line 1000 \(2025-02-11 14:00-15:00\): rows must run forward"),
    ("a missing hour", "gap.csv", _tmy3(lambda lines: lines[:999] + lines[1000:]),
     (r"line 1000 \(2025-02-11 14:00-15:00\): 2 h after line 999 \(2025-02-11 12:00-13:00\): rows must be "
      r"hourly")),
    ("TMY3 February 29", "leap.csv", _tmy3(lambda lines: lines[:1418] + [line.replace("02/28/", "02/29/")
                                                                          for line in lines[1394:1418]] + lines[1418:]),
     (r"line 1419: February 29 \(24 rows\): pvlib reads a TMY3 file's February 29 as March 1; a typical year has "
      r"365 days, remove that day")),
    ("EPW February 29", "leap.epw", _epw(lambda lines: lines[:1424] + [line.replace("2005,2,28,", "2005,2,29,")
                                                                       for line in lines[1400:1424]] + lines[1424:]),
     r"line 1425: February 29 \(24 rows\): 2025 has none; a typical year has 365 days, remove that day"),
    ("bad latitude", "lat.csv", _tmy3(lambda lines: set_field(lines, 1, 4, 136.1)),
     r"line 1: latitude = 136.1 deg: must be in \[-90, 90\] deg"),
    ("latitude not a number", "latx.csv", _tmy3(lambda lines: set_field(lines, 1, 4, "N36")),
     r"line 1: latitude = 'N36': not a number"),
    ("bad time zone", "tz.csv", _tmy3(lambda lines: set_field(lines, 1, 3, -50)),
     r"line 1: time zone TZ = -50 h: must be in \[-12, 14\] h"),
    ("header without altitude", "alt.csv", _tmy3(lambda lines: [lines[0].rsplit(",", 1)[0], *lines[1:]]),
     r"line 1: the TMY3 header has no altitude \(6 fields; it holds 7: "),
    ("PVGIS JSON not valid", "broken.json", lambda w: w[1][:300],
     r"not valid JSON: .+ at line \d+ column \d+$"),
    ("PVGIS JSON without records", "norecords.json",
     lambda w: json.dumps({**json.loads(w[1]), "outputs": {"months_selected": [], "tmy_hourly": []}}),
     r"no data rows: outputs.tmy_hourly is empty"),
    ("PVGIS JSON, not PVGIS", "other.json", lambda w: json.dumps({"a": [1, 2]}),
     r"not a PVGIS TMY file: no outputs.tmy_hourly list of hourly records"),
    ("PVGIS without G(h)", "noghi.json",
     lambda w: w[1].replace('"G(h)"', '"Global"'), r"column ghi missing: no 'G\(h\)' in outputs.tmy_hourly"),
    ("PVGIS negative DHI", "dhi.json", lambda w: w[1].replace('"Gd(h)": 0.0', '"Gd(h)": -3.0', 1),
     r"record 1 \(2025-01-01 00:00-01:00 UTC\): dhi = -3 W/m\^2: must be >= 0"),
]


@pytest.mark.parametrize(("name", "text", "expected"), [case[1:] for case in CASES], ids=[case[0] for case in CASES])
def test_a_bad_file_is_one_line_naming_file_place_and_reason(tmp_path, written, name, text, expected):
    path = tmp_path / name
    path.write_text(text(written))
    for read in (weather_site, read_weather):
        with pytest.raises(WeatherError) as caught:
            read(path)
        error = caught.value
        assert isinstance(error, ConfigError) and isinstance(error, ValueError)
        assert len(error.errors) == 1 and str(error) == error.errors[0] and "\n" not in str(error)
        prefix = f"weather {name}: "
        assert str(error).startswith(prefix), str(error)
        assert re.search(expected, str(error)[len(prefix):]), str(error)


def _truncated(tmp_path, rows: int) -> Path:
    path = tmp_path / "half.csv"
    path.write_text("\n".join(tmy3_lines()[:2 + rows]) + "\n")
    return path


def test_a_truncated_year_serves_the_days_it_holds_and_names_the_missing_ones(tmp_path):
    path = _truncated(tmp_path, 181 * 24)  # January 1 to June 30, 24:00
    frame = read_weather(path)
    assert len(frame) == 181 * 24 and frame.index[-1].strftime("%Y-%m-%d %H:%M") == "2025-06-30 23:30"
    plan = make_plan({**STUDY, "weather": str(path)})  # the whole year by default
    with pytest.raises(WeatherError, match=r"^weather half.csv: no data for 2025-07-01, 2025-07-02, 2025-07-03 and "
                                           r"181 more dates; the file holds 2025-01-01 to 2025-06-30$"):
        run_plan(plan)
    table = run_plan(make_plan({**STUDY, "weather": str(path), "date": "2025-03-01"})).table
    assert set(table["date"]) == {"2025-03-01"} and table["t_solar_h"].notna().all()


def test_a_truncated_day_is_named_by_its_date(tmp_path):
    path = _truncated(tmp_path, 181 * 24 - 12)  # June 30 ends at noon
    frame = read_weather(path)
    assert len(weather_days(frame, [dt.date(2025, 6, 29)])[0]) == 24
    with pytest.raises(WeatherError, match=r"^weather half.csv: 2025-06-30 holds 12 rows, a whole day 24; "
                                           r"the file holds 2025-01-01 to 2025-06-30$"):
        weather_days(frame, [dt.date(2025, 6, 29), dt.date(2025, 6, 30)])
    with pytest.raises(WeatherError, match=r"^weather half.csv: 2025-06-30 holds 12 rows"):
        run_plan(make_plan({**STUDY, "weather": str(path), "date": "2025-06-30"}))


@pytest.mark.parametrize("source", ["723170TYA.CSV", "703165TY.csv", "written EPW", "written PVGIS"])
def test_real_files_pass(tmp_path, written, source):
    if source == "written EPW":
        path = tmp_path / "g.epw"
        path.write_text("\n".join(written[0]) + "\n")
    elif source == "written PVGIS":
        path = tmp_path / "g.json"
        path.write_text(written[1])
    else:
        path = DATA / source
    # The light and air (the sky cover, which only a cloud ensemble reads, may be unknown).
    frame = read_weather(path)[["ghi", "dni", "dhi", "temp_air", "wind_speed"]]
    assert len(frame) == 8760 and frame.notna().all().all()
    assert frame.index.is_monotonic_increasing and frame.index.is_unique
    assert weather_days(frame, [dt.date(2025, 1, 1) + dt.timedelta(days=d) for d in range(365)]).shape == (365, 24)
    site = weather_site(path)
    assert -90 <= site["latitude"] <= 90 and -180 <= site["longitude"] <= 180
    if source.startswith("written"):  # the same hours as the sample they were written from
        sample = read_weather(TMY3)[frame.columns]
        pd.testing.assert_frame_equal(frame, sample, check_freq=False, check_exact=False, rtol=1e-9)
        assert site["timezone"] == "UTC-05:00"


def test_a_file_without_temperature_or_wind_gets_the_defaults(tmp_path):
    lines = tmy3_lines()
    header = lines[1].replace("Dry-bulb (C)", "Tdb").replace("Wspd (m/s)", "W")
    path = tmp_path / "still.csv"
    path.write_text("\n".join([lines[0], header, *lines[2:]]) + "\n")
    frame = read_weather(path)
    assert (frame["temp_air"] == 20.0).all() and (frame["wind_speed"] == 1.0).all()
    pd.testing.assert_frame_equal(frame[["ghi", "dni", "dhi"]], read_weather(TMY3)[["ghi", "dni", "dhi"]])


def test_a_file_without_direct_light_reads_as_it_is(tmp_path):
    # The beam test's sun is asked for the rows with direct light only: a file without any (a
    # week of overcast) has no row to ask for, and reads with its diffuse light whole.
    header, rows = tmy3_lines()[:2], [row.split(",") for row in tmy3_lines()[2:2 + 7 * 24]]
    path = tmp_path / "overcast.csv"
    path.write_text("\n".join([*header, *(",".join([*row[:DNI], "0", *row[DNI + 1:]]) for row in rows)]) + "\n")
    frame, sample = read_weather(path), read_weather(TMY3).iloc[:7 * 24]
    assert (frame["dni"] == 0).all() and (frame["ghi"] > 0).any()
    pd.testing.assert_frame_equal(frame[["ghi", "dhi"]], sample[["ghi", "dhi"]], check_freq=False)


def test_a_leap_year_study_on_a_typical_year_lacks_only_february_29():
    # A TMY holds 365 days. In a leap year its days keep their dates, and February 29 is a day the
    # file does not hold, with the same light around it as in a common year.
    common, leap = read_weather(TMY3, year=2025), read_weather(TMY3, year=2024)
    assert len(leap) == len(common) == 8760
    for day in ("02-28", "03-01", "12-31"):
        a, b = (weather_days(frame, [dt.date.fromisoformat(f"{y}-{day}")])[0] for frame, y in
                ((common, 2025), (leap, 2024)))
        pd.testing.assert_frame_equal(common.iloc[a].reset_index(drop=True), leap.iloc[b].reset_index(drop=True))
    with pytest.raises(WeatherError, match=r"no data for 2024-02-29; .*\(a typical year has no February 29\)"):
        weather_days(leap, [dt.date(2024, 2, 28), dt.date(2024, 2, 29)])
