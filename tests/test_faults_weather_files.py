"""Weather and other input files under faults (issue 38): what is no file foldopt reads (a folder,
a device, a FIFO, a file of gigabytes, a broken link) is named for what it is before anything reads
it, by every reader; a cloud ensemble over one day runs; a weather option given a list is one line;
stamps that span decades are refused at once; a word where a station file holds a number is refused
by every reader; and messages name what is wrong (the day left out and why, the file that cannot be
parsed, the option given, the format a file looks like), with no raw control characters. Each
refusal is exit code 2, one line, no traceback and nothing written."""

from __future__ import annotations

import json
import os
import re
import time
from pathlib import Path

import pandas as pd
import pytest
import yaml
from typer.testing import CliRunner

from foldopt.cli.app import app
from foldopt.errors import WeatherError
from foldopt.inputs.study_file import default_study_path
from foldopt.inputs.weather.measured import read_measured

runner = CliRunner()
ROOT = Path(__file__).resolve().parent.parent
TMY3 = ROOT / "configs" / "weather" / "723170TYA.CSV"
MEASURED = ROOT / "tests" / "data" / "measured"
#: The embedded study made cheap, without its site and day (a weather file brings them).
FAST = {key: value for key, value in yaml.safe_load(default_study_path().read_text()).items()
        if key not in ("site", "date", "sky", "geometry", "mode")}
FAST.update(step_min=30, fold_angles={"start": 30, "stop": 180, "step": 30})
#: Sites of the sample files that hold none (tests/data/measured/README.md).
UAT = {"latitude": 32.22969, "longitude": -110.95534, "altitude": 786}
EUGENE = {"latitude": 44.0468, "longitude": -123.0742, "altitude": 150}
M2 = {"latitude": 39.9106, "longitude": -105.2347, "altitude": 1855}


@pytest.fixture
def here(tmp_path, monkeypatch):
    """A working folder; nothing a refusal leaves may appear in it."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


def refused(folder: Path, args, *words) -> str:
    """``args`` run in ``folder``: exit code 2, one ``error:`` line holding ``words``, nothing written."""
    before = sorted(path.name for path in folder.iterdir())
    result = runner.invoke(app, [*map(str, args), "--out", "out"])
    assert result.exit_code == 2, (result.exit_code, result.output)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert "Traceback" not in result.output and "internal error" not in result.output
    for word in words:
        assert word in lines[0], (word, lines[0])
    assert sorted(path.name for path in folder.iterdir()) == before
    return lines[0]


# --- files that are no files foldopt reads --------------------------------------------------------


def _make(folder: Path, kind: str) -> str:
    """An input path of ``kind`` in ``folder``: what it is, as messages say it."""
    if kind == "folder":
        (folder / "input.csv").mkdir()
        return "input.csv"
    if kind == "FIFO":
        os.mkfifo(folder / "input.csv")  # no writer: a read would wait for ever
        return "input.csv"
    if kind == "huge":
        with open(folder / "input.csv", "wb") as handle:
            handle.truncate(2_000_000_000)  # sparse: 2.0 GB that take no time to write
        return "input.csv"
    if kind == "dangling":
        (folder / "input.csv").symlink_to(folder / "gone.csv")  # the link exists, its file does not
        return "input.csv"
    return "/dev/zero"  # never ends


#: What the message says each kind is.
KINDS = {"folder": "is a folder, not a file", "FIFO": "is a FIFO, not a regular file",
         "device": "is a character device, not a regular file",
         "huge": "is 2,000,000,000 bytes (2.0 GB): larger than any",
         "dangling": "is a symbolic link to"}

#: Every file foldopt reads as input, by the command line that names it.
READERS = {
    "weather": ["sweep", "angle", "--weather", "{file}"],
    "weather-surfrad": ["sweep", "angle", "--weather", "{file}", "--weather-format", "surfrad"],
    "weather-csv": ["sweep", "angle", "--weather", "{file}", "--weather-format", "csv", "--lat", "32.2", "--lon",
                    "-110.9", "--altitude", "786"],
    "horizon": ["sweep", "angle", "--horizon", "{file}", "--step-min", "60", "--angle-step", "30"],
    "sites": ["map", "--sites", "{file}"],
    "load-profile": ["sweep", "angle", "--load-profile", "{file}", "--step-min", "60", "--angle-step", "30"],
    "study": ["run", "{file}"],
}
OPTION = {"weather": "--weather", "weather-surfrad": "--weather", "weather-csv": "--weather", "horizon": "--horizon",
          "sites": "--sites", "load-profile": "--load-profile", "study": "config"}


@pytest.mark.parametrize("kind", list(KINDS))
@pytest.mark.parametrize("reader", list(READERS))
def test_an_input_that_is_no_file_foldopt_reads_is_named_for_what_it_is(here, reader, kind):
    name = _make(here, kind)
    start = time.monotonic()
    line = refused(here, [arg.format(file=name) for arg in READERS[reader]], OPTION[reader], name, KINDS[kind])
    assert "not found" not in line
    assert time.monotonic() - start < 20


def test_a_weather_file_of_a_study_that_is_a_folder_is_not_called_missing(here):
    (here / "weather.csv").mkdir()
    (here / "study.yaml").write_text(yaml.safe_dump({**FAST, "weather": "weather.csv"}))
    line = refused(here, ["run", "study.yaml"], "weather", "weather.csv", "is a folder, not a file")
    assert "not found" not in line


@pytest.mark.parametrize("fmt", [None, "surfrad", "csv"])
def test_the_library_refuses_a_folder_as_a_weather_file(tmp_path, fmt):
    from foldopt.inputs.weather.reader import measured_weather, read_weather

    with pytest.raises(WeatherError, match="is a folder, not a file"):
        if fmt is None:
            read_weather(tmp_path)
        else:
            measured_weather(tmp_path, fmt, site=UAT)


# --- a cloud ensemble over one day ----------------------------------------------------------------


def test_a_cloud_ensemble_over_one_day_runs_its_members(here):
    result = runner.invoke(app, ["sweep", "angle", "--weather", str(TMY3), "--members", "2", "--days", "2025-06-21",
                                 "--step-min", "30", "--angle-step", "30", "--out", "out"])
    assert result.exit_code == 0, result.output
    assert "over 2 cloud members" in result.stdout and "1 day" in result.stdout
    assert (here / "out" / "results.csv").is_file()


def test_a_study_file_of_a_cloud_ensemble_over_one_day_runs_its_members(here, figures_drawn_elsewhere):
    study = {**FAST, "date": "2025-06-21", "objective": "mean", "weather": {"path": str(TMY3), "members": 2}}
    (here / "study.yaml").write_text(yaml.safe_dump(study))
    with figures_drawn_elsewhere():  # the command line's ensemble over this day, above: its folder's
        result = runner.invoke(app, ["run", "study.yaml", "--out", "out"])
    assert result.exit_code == 0, result.output
    assert "over 2 cloud members" in result.stdout


# --- one value where one is expected ---------------------------------------------------------------


@pytest.mark.parametrize("weather,words", [
    ({"path": str(MEASURED / "five_minute.csv"), "format": ["csv", "surfrad"]},
     ["weather.format = ['csv', 'surfrad']", "one name is expected, not a list"]),
    ({"path": str(TMY3), "format": ["tmy3", "epw"]}, ["weather.format", "not a list"]),
    ({"path": str(MEASURED / "surfrad-slv16001.dat"), "format": "surfrad", "label": ["start", "end"]},
     ["weather.label = ['start', 'end']", "not a list"]),
    ({"path": str(MEASURED / "surfrad-slv16001.dat"), "format": "surfrad", "max_gap_min": [30, 60]},
     ["weather.max_gap_min = [30, 60]", "one number is expected"]),
    ({"path": str(MEASURED / "five_minute.csv"), "format": {"name": "csv"}}, ["weather.format", "not a dict"]),
], ids=["format-measured", "format-hourly", "label", "max-gap", "format-mapping"])
def test_a_weather_option_given_a_list_is_one_line(here, weather, words):
    (here / "study.yaml").write_text(yaml.safe_dump({**FAST, "site": UAT, "weather": weather}))
    refused(here, ["run", "study.yaml"], *words)


# --- stamps that span decades ----------------------------------------------------------------------


@pytest.mark.parametrize("minutes,rows,steps", [(1, 10, "15,780,960 steps for 11 rows"),
                                                (60, 48, "263,016 steps for 49 rows")])
def test_stamps_that_span_decades_are_refused_at_once(tmp_path, minutes, rows, steps):
    # A slip in a year: ten minutes (or two days of hours) and one stamp thirty years on: 10,959
    # local days (30 years, 8 of them leap) of 1440 (or 24) steps.
    path = tmp_path / "decades.csv"
    start = pd.Timestamp("2018-10-18T12:00:00-07:00")
    stamps = [start + pd.Timedelta(minutes=minutes * i) for i in range(rows)] + [start + pd.DateOffset(years=30)]
    path.write_text("timestamp,ghi\n" + "".join(f"{stamp.isoformat()},500\n" for stamp in stamps))
    began = time.monotonic()
    with pytest.raises(WeatherError, match=rf"decades.csv: the stamps span 2018-10-18 12:00:00-07:00 to 2048-10-18 "
                                           rf".* {minutes}-min step: {steps}; at most"):
        read_measured(path, "csv", site=UAT)
    assert time.monotonic() - began < 10


# --- a word where a number belongs -----------------------------------------------------------------


def _word_in_cell(source: Path, target: Path, line: int, field: int, separator: str | None) -> str:
    """``source`` with field ``field`` of line ``line`` (0-based) made ``abc``, columns kept in
    place (fixed-width files); returns the value it replaced."""
    lines = source.read_text().splitlines(True)
    if separator is None:
        cell = list(re.finditer(r"\S+", lines[line]))[field]
        lines[line] = lines[line][:cell.start()] + "abc".rjust(cell.end() - cell.start()) + lines[line][cell.end():]
        old = cell.group()
    else:
        cells = lines[line].rstrip("\n").split(separator)
        old, cells[field] = cells[field], "abc"
        lines[line] = separator.join(cells) + "\n"
    target.write_text("".join(lines))
    return old


@pytest.mark.parametrize("name,fmt,site,line,field,separator,column", [
    ("surfrad-slv16001.dat", "surfrad", None, 2 + 19 * 60, 8, None, "ghi"),  # local noon
    ("surfrad-slv16001.dat", "surfrad", None, 2 + 19 * 60, 9, None, "ghi_flag"),
    ("abq19056.dat", "solrad", None, 3, 8, None, "ghi"),
    ("SRML-day-EUPO1801.txt", "srml", EUGENE, 1 + 12 * 60, 2, "\t", "ghi"),
    ("midc_20181014.txt", "midc", M2, 1 + 12 * 60, 2, ",", "ghi"),
    ("CRNS0101-05-2019-AZ_Tucson_11_W.txt", "crn", None, 2, 10, None, "SOLAR_RADIATION"),
    ("five_minute.csv", "csv", UAT, 4 + 144, 1, ",", "ghi"),
], ids=["surfrad", "surfrad-flag", "solrad", "srml", "midc", "crn", "csv"])
def test_a_word_in_an_irradiance_cell_is_refused_by_every_reader(tmp_path, name, fmt, site, line, field, separator,
                                                                 column):
    path = tmp_path / name
    old = _word_in_cell(MEASURED / name, path, line, field, separator)
    float(old)  # the cell held a number
    read_measured(MEASURED / name, fmt, site=site)  # the file as it was is read
    with pytest.raises(WeatherError, match=rf"{re.escape(name)}: (?=.*{column})(?=.*'abc')"):
        read_measured(path, fmt, site=site)


# --- messages that blame the wrong thing -----------------------------------------------------------

SITE_OPTIONS = ["--lat", "32.22969", "--lon", "-110.95534", "--altitude", "786"]


def _day_without_noon(folder: Path, how: str, days: int = 1) -> Path:
    """``five_minute.csv`` (of ``days`` days, the first repeated) with its 10:00-13:00 stamps made
    unusable: ``negative`` irradiance, ``absurd`` irradiance (beyond any sun) or ``gone`` (a 3-hour
    gap)."""
    lines = (MEASURED / "five_minute.csv").read_text().splitlines(True)
    rows = [line for line in lines if line.startswith("2018-")]
    lines += [line.replace("2018-10-18T", f"2018-10-{18 + day}T") for day in range(1, days) for line in rows]
    kept = []
    for line in lines:
        noon = re.match(r"2018-10-\d\dT1[0-2]:", line)
        if noon and how == "gone":
            continue
        if noon:
            cells = line.rstrip("\n").split(",")
            cells[1:4] = ["-500"] * 3 if how == "negative" else ["5000"] * 3
            line = ",".join(cells) + "\n"
        kept.append(line)
    path = folder / f"{how}.csv"
    path.write_text("".join(kept))
    return path


@pytest.mark.parametrize("how,found", [("negative", "values beyond physical bounds made missing"),
                                       ("absurd", "values beyond physical bounds made missing"),
                                       ("gone", "steps the file lacks")])
def test_a_measured_file_whose_only_day_is_left_out_says_which_and_why(here, how, found):
    path = _day_without_noon(here, how)
    line = refused(here, ["sweep", "angle", "--weather", path.name, "--weather-format", "csv", *SITE_OPTIONS],
                   f"--weather {path.name}: its only day, 2018-10-18, is left out", "daylight gap of 180 min",
                   "max_gap_min = 60 min", found)
    assert "empty list" not in line and "--days" not in line


def test_a_measured_file_whose_every_day_is_left_out_says_so(here):
    path = _day_without_noon(here, "gone", days=2)
    refused(here, ["sweep", "angle", "--weather", path.name, "--weather-format", "csv", *SITE_OPTIONS],
            "all 2 of its days are left out; the first, 2018-10-18, has a daylight gap of 180 min",
            "max_gap_min = 60 min")


@pytest.mark.parametrize("fmt,label", [("surfrad", "SURFRAD"), ("bsrn", "BSRN"), ("solrad", "SOLRAD"),
                                       ("crn", "CRN"), ("midc", "MIDC"), ("srml", "SRML"),
                                       ("csv", "CSV")])
def test_a_station_file_that_cannot_be_parsed_says_what_is_wrong_with_it(here, fmt, label):
    (here / "junk.dat").write_text("junk\nmore junk\n1 2 3\n")
    # No site given: a file that holds none (MIDC, SRML, CSV) is parsed before a site is asked for.
    line = refused(here, ["sweep", "angle", "--weather", "junk.dat", "--weather-format", fmt], "--weather junk.dat",
                   "no timestamp column" if fmt == "csv" else f"not a readable {label} file")
    assert "not read yet" not in line and "holds no site" not in line


def test_a_latitude_sweep_over_a_measured_file_without_a_site_names_the_site(here):
    line = refused(here, ["sweep", "latitude", "--weather", MEASURED / "five_minute.csv", "--weather-format", "csv",
                          "--lat", "30:40:5", "--lon", "-110.96", "--altitude", "786"],
                   "--lat", "varies", "a csv file holds no site", "give one site")
    assert "step" not in line


@pytest.mark.parametrize("option,value", [("--members", "3"), ("--seed", "3"), ("--weather-format", "csv")])
@pytest.mark.parametrize("axis", ["angle", "day"])
def test_a_weather_option_without_a_weather_file_names_the_options(here, axis, option, value):
    line = refused(here, ["sweep", axis, option, value], f"error: {option}: an option of a weather file",
                   "give one with --weather")
    assert "weather.path" not in line and "objective" not in line


def test_a_horizon_beside_a_weather_files_site_takes_the_files_site(here, folders_written_elsewhere):
    horizon = ROOT / "tests" / "data" / "horizon" / "street_canyon.csv"
    quick = ["--step-min", "60", "--angle-step", "30", "--days", "172:172:1", "--format", "json"]
    with folders_written_elsewhere():  # its answer alone is read; the canyon's folder, of its kind, is written
        open_sky = runner.invoke(app, ["sweep", "angle", "--weather", str(TMY3), *quick, "--out", "open"])
    canyon = runner.invoke(app, ["sweep", "angle", "--weather", str(TMY3), "--horizon", str(horizon), *quick,
                                 "--out", "canyon"])
    assert open_sky.exit_code == 0 and canyon.exit_code == 0, canyon.output
    run = json.loads((here / "canyon" / "run.json").read_text())
    assert "GREENSBORO" in canyon.stdout and "horizon" in json.dumps(run["study"]["site"])
    assert json.loads(canyon.stdout)["answer"] != json.loads(open_sky.stdout)["answer"]  # the canyon shades


#: Bytes a terminal acts on: an escape that turns text red, a bell, NUL.
BINARY = b"\x1b[31mred\x07,\x00\x01,3\n1,2,3\n"


@pytest.mark.parametrize("fmt", ["tmy3", "epw", "surfrad", "midc", "srml", "bsrn", "solrad", "crn", "csv"])
def test_binary_bytes_reach_no_message_raw(here, fmt):
    (here / "binary.dat").write_bytes(BINARY)
    line = refused(here, ["sweep", "angle", "--weather", "binary.dat", "--weather-format", fmt, *SITE_OPTIONS],
                   "--weather binary.dat")
    assert not re.search(r"[\x00-\x08\x0b-\x1f\x7f]", line), line
    assert len(line) < 400


@pytest.mark.parametrize("name,fmt", [("surfrad-slv16001.dat", "surfrad"), ("abq19056.dat", "solrad"),
                                      ("CRNS0101-05-2019-AZ_Tucson_11_W.txt", "crn"),
                                      ("SRML-day-EUPO1801.txt", "srml"), ("midc_20181014.txt", "midc"),
                                      ("midc_raw_20181018.txt", "midc"), ("five_minute.csv", "csv")])
def test_a_station_file_read_as_tmy3_names_its_likely_format(here, name, fmt):
    from foldopt.inputs.weather.reader import sniff_format

    assert sniff_format(MEASURED / name) == fmt
    (here / "station.csv").write_bytes((MEASURED / name).read_bytes())  # .csv: read as TMY3 by its extension
    refused(here, ["sweep", "angle", "--weather", "station.csv"], "--weather station.csv",
            "read as tmy3 (by its extension .csv)", f"looks like a {fmt} file: give --weather-format {fmt}")
    refused(here, ["sweep", "angle", "--weather", MEASURED / name], f"--weather {name}",
            "(by its extension .csv)" if name.endswith(".csv") else "(no format given)", f"looks like a {fmt} file")


def test_the_hourly_formats_are_told_by_their_content():
    from foldopt.inputs.weather.reader import sniff_format

    assert sniff_format(TMY3) == "tmy3"
    assert sniff_format(ROOT / "tests" / "data" / "horizon" / "street_canyon.csv") is None


@pytest.mark.parametrize("weather", [[TMY3], [MEASURED / "surfrad-slv16001.dat", "--weather-format", "surfrad"]],
                         ids=["tmy3", "surfrad"])
def test_a_latitude_sweep_over_a_weather_file_of_one_site_is_one_line(here, weather):
    refused(here, ["sweep", "latitude", "--weather", *weather],
            "sweep latitude's default range = '-60:60:5': varies",
            "a weather file is of one site", "--force-site")


@pytest.mark.parametrize("option", ["--weather", "--horizon", "--load-profile"])
def test_a_file_name_with_terminal_escapes_is_printed_escaped(here, option):
    line = refused(here, ["sweep", "angle", option, "red\x1b[31m\x07.csv", "--step-min", "60"],
                   option, "red\\x1b[31m\\x07.csv")
    assert not re.search(r"[\x00-\x08\x0b-\x1f\x7f]", line), line
