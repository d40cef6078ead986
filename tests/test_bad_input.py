"""Bad input never crashes, hangs or destroys: a table of hostile inputs through the command line
(values, YAML study files, weather files, output folders), each answered by one line naming the
field and exit code 2, with no traceback and an earlier results folder left as it was; and
generated YAML studies that either run or fail that same clean way."""

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import pvlib
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from foldopt.cli.app import app
from foldopt.inputs.study_file import default_study_path

runner = CliRunner()
TMY3 = Path(pvlib.__file__).parent / "data" / "723170TYA.CSV"
#: The embedded study made cheap: hourly steps, a 30-degree fold-angle grid.
FAST = {**yaml.safe_load(default_study_path().read_text()), "step_min": 60,
        "fold_angles": {"start": 30, "stop": 180, "step": 30}}
QUICK = ["--step-min", "60", "--angle-step", "30"]


def snapshot(folder: Path) -> dict:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture
def place(tmp_path, monkeypatch):
    """A working folder holding an earlier results folder (``prior``) that no error may touch."""
    monkeypatch.chdir(tmp_path)
    prior = tmp_path / "prior"
    prior.mkdir()
    (prior / "run.json").write_text(json.dumps({"versions": {"foldopt": "0"}}))
    (prior / "sweep.csv").write_text("kept\n")
    return tmp_path


def study_file(folder: Path, name: str, text: str | bytes) -> Path:
    path = folder / name
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    return path


def fast_yaml(**changes) -> str:
    return yaml.safe_dump({**FAST, **changes}, sort_keys=False)


# (id, files to create {name: text}, command line, words the one error line must hold)
VALUES = [
    ("lat-high", ["sweep", "angle", "--lat", "95"], ["--lat", "[-90, 90]"]),
    ("lat-text", ["sweep", "angle", "--lat", "north"], ["--lat", "number"]),
    ("lat-nan", ["sweep", "angle", "--lat", "nan"], ["--lat"]),
    ("lon-high", ["sweep", "angle", "--lon", "200"], ["--lon", "[-180, 180]"]),
    ("p-load-zero", ["sweep", "angle", "--p-load", "0"], ["--p-load", "(0, 1e+06]"]),
    ("p-load-range-negative", ["sweep", "load", "--p-load=-1:3:1"], ["--p-load", "(0, 1e+06]"]),
    ("p-load-million", ["sweep", "load", "--p-load", "1:1000000:1"], ["--p-load", "at most 10,000 per axis"]),
    ("lat-9e10", ["sweep", "latitude", "--lat", "-90:90:0.000000002"], ["--lat", "at most 10,000 per axis"]),
    ("area-zero", ["sweep", "angle", "--area", "0"], ["--area", "(0, 1000]"]),
    ("area-inf", ["sweep", "angle", "--area", "inf"], ["--area"]),
    ("efficiency", ["sweep", "angle", "--efficiency", "1.5"], ["--efficiency", "(0, 1]"]),
    ("tilt", ["sweep", "angle", "--tilt", "120"], ["--tilt", "[0, 90]"]),
    ("azimuth", ["sweep", "angle", "--azimuth", "400"], ["--azimuth", "[0, 360)"]),
    ("mode", ["sweep", "angle", "--mode", "fast"], ["--mode", "paper, exact"]),
    ("geometry", ["sweep", "angle", "--geometry", "tent"], ["--geometry", "azimuth-split, hinge"]),
    ("sky", ["sweep", "angle", "--sky", "cloudy"], ["--sky", "meinel"]),
    ("climate", ["sweep", "angle", "--sky", "hottel", "--climate", "arctic"], ["--climate", "tropical"]),
    ("date-month", ["sweep", "angle", "--date", "2014-13-01"], ["--date"]),
    ("date-feb-30", ["sweep", "angle", "--date", "2025-02-30"], ["--date"]),
    ("day-of-year", ["sweep", "day", "--days", "1:400:7"], ["--days", "day of year 400 is outside 2014"]),
    ("step-min", ["sweep", "angle", "--step-min", "7"], ["--step-min", "1440"]),
    ("angle-step", ["sweep", "angle", "--angle-step", "0"], ["--angle-step", "(0, 180]"]),
    ("pv-model", ["sweep", "angle", "--pv-model", "two-diode"], ["--pv-model", "single-diode"]),
    ("module", ["sweep", "angle", "--pv-model", "single-diode", "--module", "NoSuchModule"], ["--module", "CEC"]),
    ("connection", ["sweep", "angle", "--connection", "star"], ["--connection", "switching"]),
    ("converter", ["sweep", "angle", "--connection", "independent", "--converter-efficiency", "1.2"],
     ["--converter-efficiency", "(0, 1]"]),
    ("tracker", ["sweep", "angle", "--tracker", "heliostat"], ["--tracker", "single-axis"]),
    ("standby", ["sweep", "angle", "--tracker-standby", "-1"], ["--tracker-standby", "[0, 1000]"]),
    ("objective", ["sweep", "day", "--objective", "best"], ["--objective", "pNN"]),
    ("timezone", ["sweep", "angle", "--timezone", "Mars/Olympus"], ["--timezone", "Mars/Olympus"]),
    ("year", ["sweep", "day", "--year", "1800"], ["--year", "[1901, 2099]"]),
    ("albedo", ["sweep", "angle", "--mode", "exact", "--sky", "ineichen", "--albedo", "2"], ["--albedo", "[0, 1]"]),
    ("idle-climate", ["sweep", "angle", "--climate", "tropical"], ["--climate", "only used by sky hottel"]),
    # A tracker option the model does not read is refused like any idle setting (physics.trackers.TRACKER_MODELS).
    ("idle-tracker-gcr", ["sweep", "angle", "--set", "tracker.gcr=0.9"],
     ["error: tracker.gcr = 0.9", "only used by tracker.model single-axis"]),
    ("idle-tracker-steps", ["sweep", "angle", "--tracker", "single-axis", "--set", "tracker.steps=10"],
     ["error: tracker.steps = 10", "only used by tracker.model dual-axis-steps"]),
    ("paper-perez", ["sweep", "angle", "--mode", "paper", "--transposition", "perez"], ["paper mode is beam-only"]),
    ("set-no-value", ["sweep", "angle", "--set", "albedo"], ["--set", "KEY=VALUE"]),
    ("set-unknown", ["sweep", "angle", "--set", "panel.colour=red"], ["panel.colour", "unknown field"]),
    ("set-bad-date", ["sweep", "angle", "--set", "date=2025-02-30"], ["date", "valid date"]),
    # A study's date is held to the years a study's year is (inputs.fields.YEARS).
    ("set-date-1800", ["sweep", "angle", "--set", "date=1800-06-21"], ["date", "[1901, 2099]"]),
    ("run-date-2100", ["run", "--set", "date=2100-01-01"], ["date", "[1901, 2099]"]),
    ("set-alias", ["sweep", "angle", "--set", "p_load=*x"], ["--set p_load"]),
    ("blocking-diode", ["sweep", "angle", "--blocking-diode", "zener"], ["--blocking-diode", "shockley"]),
    ("bypass-diode", ["sweep", "angle", "--bypass-diode", "shockly"], ["--bypass-diode", "did you mean 'shockley'"]),
    ("converter-model", ["sweep", "angle", "--converter", "mppt"], ["--converter", "pvwatts, curve"]),
    ("converter-curve-missing", ["sweep", "angle", "--converter", "curve"], ["circuit.converter.curve"]),
    ("converter-curve-order", ["sweep", "angle", "--converter", "curve", "--set",
                               "circuit.converter.curve=[[0.5, 0.9], [0.2, 0.95]]"], ["must increase"]),
    ("load-voltage", ["sweep", "angle", "--load-voltage", "0"], ["--load-voltage", "(0, 1000] V"]),
    ("load-voltage-ideal-pv", ["sweep", "angle", "--pv-model", "ideal", "--load-voltage", "5"],
     ["circuit.coupling", "single-diode or b-model"]),
    ("direct-without-voltage", ["sweep", "angle", "--set", "circuit.coupling=direct"], ["circuit.load_voltage"]),
    ("direct-and-converter", ["sweep", "angle", "--load-voltage", "5", "--converter", "pvwatts"],
     ["direct-coupled load has no converter"]),
    ("direct-independent", ["sweep", "angle", "--pv-model", "single-diode", "--load-voltage", "5", "--connection",
                            "independent"],
     ["--connection", "needs a converter per sub-panel"]),
    ("switch-resistance", ["sweep", "angle", "--switch-resistance", "20"], ["--switch-resistance", "[0, 10] ohm"]),
    ("idle-switch-resistance", ["sweep", "angle", "--pv-model", "single-diode", "--connection", "parallel",
                                "--switch-resistance", "0.1"],
     ["--switch-resistance", "only used by connection switching"]),
    ("diode-part", ["sweep", "angle", "--blocking-diode", "constant", "--set", "circuit.blocking_diode.part=1N4148"],
     ["circuit.blocking_diode.part", "mbr745, pds760"]),
    ("horizon-missing", ["sweep", "angle", "--horizon", "nope.csv"], ["--horizon", "file not found"]),
    ("horizon-folder", ["sweep", "angle", "--horizon", "prior"], ["--horizon", "folder"]),
    ("horizon-points", ["sweep", "angle", "--set", "site.horizon=[[0, 95]]"], ["site.horizon = [[0, 95]]", "above 90"]),
    ("optimize-vary", ["optimize", "--step-min", "60", "--vary", "bogus"], ["--vary", "fold_angle, tilt, azimuth"]),
    ("optimize-vary-twice", ["optimize", "--step-min", "60", "--vary", "tilt,tilt"], ["--vary", "once"]),
    ("optimize-tilt-range", ["optimize", "--step-min", "60", "--tilt-range", "0:100:1"], ["--tilt-range", "[0, 90]"]),
    ("optimize-fold-range", ["optimize", "--step-min", "60", "--fold-range", "x"], ["--fold-range", "min:max:step"]),
    ("optimize-azimuth-order", ["optimize", "--step-min", "60", "--azimuth-range", "10:5:1"],
     ["--azimuth-range", "must not exceed"]),
    ("optimize-tolerance", ["optimize", "--step-min", "60", "--tolerance", "5"], ["--tolerance", "[0, 1] h"]),
    ("optimize-idle-range", ["optimize", "--step-min", "60", "--vary", "tilt", "--fold-range", "10:180:5"],
     ["--fold-range = 10:180:5", "optimize.vary names fold_angle"]),
    ("optimize-latitudes", ["optimize", "--step-min", "60", "--lat", "10:20:5"], ["optimize", "site.latitude vary"]),
    ("format", ["run", "--format", "xml"], ["--format", "table, json"]),
    ("engine", ["run", "--engine", "gpu"], ["--engine", "numba, numpy"]),
    ("unknown-option", ["run", "--colour", "red"], ["No such option"]),
    ("unknown-axis", ["sweep", "tilt"], ["No such command 'tilt'"]),
    ("size-empty", ["size", "--areas", "0.5:0.1:0.1"], ["--areas", "empty range"]),
    ("size-cost", ["size", "--cost-per-w", "-1"], ["--cost-per-w", "> 0"]),
    ("size-both-costs", ["size", "--cost-per-w", "1", "--cost-per-m2", "100"], ["not both"]),
    ("size-million-areas", ["size", "--areas", "0.0001:100:0.0001"], ["--areas", "at most 10,000 per axis"]),
    ("size-years", ["size", "--years", "0"], ["--years", "> 0"]),
    ("weather-missing", ["sweep", "angle", "--weather", "nope.csv"], ["--weather", "file not found"]),
    ("config-missing", ["run", "nope.yaml"], ["config", "file not found", "nope.yaml"]),
    ("config-folder", ["run", "prior"], ["config", "prior"]),
    ("scale-without-profile", ["sweep", "load", "--p-load-scale", "0.5:2:0.5"], ["--p-load-scale", "--load-profile"]),
    ("scale-and-load", ["sweep", "load", "--load-profile", "p.csv", "--p-load", "1:3:1", "--p-load-scale", "1"],
     ["--p-load / --p-load-scale"]),
    ("profile-missing", ["sweep", "angle", "--load-profile", "nope.csv"], ["--load-profile", "file not found"]),
    ("visits-13", ["sweep", "day", "--objective", "mean", "--visits", "13"], ["--visits", "12"]),
    ("visits-p10", ["sweep", "day", "--objective", "p10", "--visits", "2"], ["visits", "mean or worst-month"]),
    ("map-lat", ["map", "--lat", "95"], ["--lat", "[-90, 90]"]),
    ("map-lon-range", ["map", "--lon", "0:10"], ["--lon", "start:stop:step"]),
    ("map-load", ["map", "--p-load", "-1"], ["--p-load", "(0, 1e+06]"]),
    ("map-fraction", ["map", "--p-load-fraction", "0:0.5:0.1"], ["--p-load-fraction", "(0, 2]"]),
    ("map-two-loads", ["map", "--p-load", "1", "--p-load-fraction", "0.5"], ["one way"]),
    ("map-two-sources", ["map", "--lat", "0", "--sites", "s.csv"], ["one source of sites"]),
    ("map-sites-missing", ["map", "--sites", "nope.csv"], ["--sites", "file not found"]),
    ("map-weather-dir", ["map", "--weather-dir", "nope"], ["--weather-dir", "not a folder"]),
    ("map-period", ["map", "--show-period", "winter"], ["--show-period", "year, DJF"]),
    ("map-show-load", ["map", "--p-load", "1,2", "--show-load", "3"], ["--show-load", "[1, 2]"]),
    ("map-objective", ["map", "--objective", "best"], ["--objective", "pNN"]),
    ("map-optimize-azimuth", ["map", "--set", "optimize={vary: [fold_angle, azimuth]}"],
     ["optimize.vary", "the fold angle, or the fold angle and the tilt"]),
    ("map-optimize-bogus", ["map", "--optimize", "tilt,bogus"], ["optimize", "fold_angle, tilt, azimuth"]),
    ("map-step", ["map", "--step-min", "7"], ["--step-min", "divide the 1440 min"]),
    ("map-workers", ["map", "--workers", "0"], ["--workers", "at least 1"]),
    ("map-set", ["map", "--set", "panel.area=-1"], ["panel.area = -1", "(0, 1000]"]),
    ("map-year-0", ["map", "--year", "0"], ["--year = 0", "[1901, 2099]"]),
    ("map-year-10000", ["map", "--year", "10000"], ["--year = 10000", "[1901, 2099]"]),
    ("year-10000", ["sweep", "angle", "--year", "10000"], ["--year = 10000", "[1901, 2099]"]),
    ("map-lat-empty", ["map", "--lat", ""], ["--lat = ''", "no value"]),
    ("map-lat-million", ["map", "--lat", "0:1:0.000001"], ["--lat", "1,000,001 values", "at most 10,000 per axis",
                                                            "FOLDOPT_MAX_AXIS_VALUES"]),
    ("size-cost-1e308", ["size", "--cost-per-m2", "1e308"], ["--cost-per-m2 = 1e+308", "at most 1e+09 $/m^2"]),
    ("size-cost-per-w-huge", ["size", "--cost-per-w", "1e300"], ["--cost-per-w", "at most 1e+06 $/W"]),
    ("size-c-grid-huge", ["size", "--c-grid", "1e306"], ["--c-grid = 1e+306", "at most 1000 $/kWh"]),
    ("size-days-huge", ["size", "--days-per-year", "1e300"], ["--days-per-year", "at most 366 days"]),
    ("set-unquoted-range", ["sweep", "angle", "--set", "p_load=1:9:4"], ["--set p_load", "number 4144",
                                                                          "write '1:9:4' in quotes"]),
]

YAML_FILES = [
    ("malformed", "name: x\nsite: [1, 2\n", ["line", "bad.yaml"]),
    ("a-list", "- just\n- a list\n", ["expected a mapping"]),
    ("empty", "", ["expected a mapping"]),
    ("missing-site", yaml.safe_dump({k: v for k, v in FAST.items() if k != "site"}),
     ["site", "required field is missing"]),
    ("unknown-field", fast_yaml(colour="red"), ["colour", "unknown field"]),
    ("aliases", "a: &a [1, 2]\nb: [*a, *a]\nname: x\n", ["aliases", "line 2"]),
    ("billion-laughs", "a: &a [lol, lol, lol, lol, lol, lol, lol, lol, lol]\nb: &b [*a, *a, *a, *a, *a, *a]\n"
     "c: &c [*b, *b, *b, *b, *b, *b]\nd: [*c, *c, *c, *c, *c, *c]\n", ["aliases"]),
    ("duplicate-key", "name: x\np_load: 1\np_load: 2\n", ["'p_load' appears twice", "line 3", "first at line 2"]),
    ("feb-30", fast_yaml(date="2025-02-30"), ["date", "valid date"]),
    ("date-text", fast_yaml(date="sometime"), ["date"]),
    ("date-list", fast_yaml(date=["2025-03-20", "2025-02-31"]), ["date", "2025-02-31"]),
    ("deep", "name: " + "[" * 20000 + "]" * 20000 + "\n", ["nested too deeply"]),
    ("big", "name: x\n" + "#" * 1_100_000 + "\n", ["bytes", "at most 1,000,000"]),
    ("binary", b"\xff\xfe\x00name: x\n", ["config", "cannot read"]),
    ("sweep-list", fast_yaml(sweep=[1, 2]), ["sweep", "mapping"]),
    ("idle-tracker-option", fast_yaml(tracker={"model": "equatorial", "backtrack": True}),
     ["tracker.backtrack = True", "only used by tracker.model single-axis"]),
    ("huge-range", fast_yaml(p_load="1:2000000:1"), ["p_load", "at most 10,000 per axis"]),
    ("huge-plan", fast_yaml(step_min=1, fold_angles={"start": 0.1, "stop": 180, "step": 0.1},
                            site={"latitude": "-60:60:0.1", "longitude": 0}, date="1:365:30"),
     ["evaluations", "FOLDOPT_MAX_EVALUATIONS"]),
    ("huge-annual", fast_yaml(p_load="1:500:1", date="year", objective={"statistic": "mean"},
                              fold_angles={"start": 0.1, "stop": 180, "step": 0.1}),
     ["objective", "FOLDOPT_MAX_ANNUAL_CELLS"]),
    ("site-text", fast_yaml(site="Los Angeles"), ["site"]),
    ("year-1800", fast_yaml(year=1800, date="1:365:7"), ["year", "[1901, 2099]"]),
    ("date-1800", fast_yaml(date="1800-06-21"), ["date", "[1901, 2099]"]),
    ("objective-one-day", fast_yaml(objective={"statistic": "mean"}), ["objective", "several dates"]),
    ("weather-missing", fast_yaml(weather="nope.csv"), ["weather", "file not found"]),
    ("tags", "name: !!python/object:os.system x\n", ["config", "line 1"]),
    ("name-list", fast_yaml(name=["a", "b"]), ["name", "not sweepable", "give one name"]),
    ("sweep-name", fast_yaml(sweep={"name": ["a", "b"]}), ["sweep.name", "not sweepable"]),
    ("unquoted-clock", fast_yaml() + "load_profile:\n  daily: {'07:00': 6, 19:00: 1.5}\n",
     ["bad.yaml", "19:00 is read by YAML as the number 1140", "write '19:00' in quotes"]),
    ("unquoted-range", fast_yaml() + "sweep: {p_load: 1:9:4}\n", ["1:9:4", "write '1:9:4' in quotes"]),
    ("profile-time-twice", fast_yaml(load_profile={"daily": {"07:00": 6, "7:00": 3}}),
     ["load_profile.daily", "'7:00' is the time '07:00' again"]),
]

OUTPUTS = [
    ("a-file", lambda d: (d / "afile").write_text("x") and ["run", "fast.yaml", "--out", "afile", "--overwrite"],
     ["--out afile", "is a file"]),
    ("working-folder", lambda d: ["run", "fast.yaml", "--out", ".", "--overwrite"], ["--out .", "working folder"]),
    ("parent-folder", lambda d: ["run", "fast.yaml", "--out", "..", "--overwrite"], ["--out ..", "working folder"]),
    ("foreign-folder", lambda d: (d / "mine").mkdir() or (d / "mine" / "thesis.tex").write_text("x") and
     ["run", "fast.yaml", "--out", "mine", "--overwrite"], ["--out mine", "foldopt did not write"]),
    ("under-a-file", lambda d: (d / "afile").write_text("x") and ["run", "fast.yaml", "--out", "afile/sub"],
     ["--out afile/sub", "is a file"]),
    ("exists", lambda d: ["run", "fast.yaml", "--out", "prior"], ["prior already exists", "--overwrite"]),
    ("symlink", lambda d: (d / "link").symlink_to(d / "prior") or ["run", "fast.yaml", "--out", "link", "--overwrite"],
     ["--out link", "symbolic link"]),
]


def damaged_tmy3(line: int | None = None, column: str | None = None, value: str = "", header=None, keep=None) -> str:
    """The TMY3 sample with one cell, its header line or its length changed."""
    lines = TMY3.read_text().splitlines()
    if header is not None:
        lines[header[0]] = header[1](lines[header[0]])
    if line is not None:
        cells = lines[line - 1].split(",")
        cells[lines[1].split(",").index(column)] = value
        lines[line - 1] = ",".join(cells)
    return "\n".join(lines[:keep]) + "\n"


WEATHER_FILES = [
    ("empty", "w.csv", lambda: "", ["w.csv", "empty"]),
    ("header-only", "w.csv", lambda: damaged_tmy3(keep=2), ["w.csv", "no data rows"]),
    ("not-weather", "w.csv", lambda: "a,b\n1,2\n3,4\n", ["w.csv", "line 1", "header"]),
    ("no-ghi-column", "w.csv", lambda: damaged_tmy3(header=(1, lambda h: h.replace("GHI (W/m^2)", "G"))),
     ["w.csv", "column ghi missing"]),
    ("nan-ghi", "w.csv", lambda: damaged_tmy3(500, "GHI (W/m^2)", "nan"), ["w.csv", "line 500", "ghi has no value"]),
    ("negative-dni", "w.csv", lambda: damaged_tmy3(300, "DNI (W/m^2)", "-5"), ["w.csv", "line 300", "must be >= 0"]),
    ("dhi-above-ghi", "w.csv", lambda: damaged_tmy3(302, "DHI (W/m^2)", "900"), ["w.csv", "line 302", "dhi = 900"]),
    ("temperature", "w.csv", lambda: damaged_tmy3(40, "Dry-bulb (C)", "99.9"), ["w.csv", "line 40", "temp_air"]),
    ("latitude", "w.csv", lambda: damaged_tmy3(header=(0, lambda h: h.replace(",36.100,", ",95,"))),
     ["w.csv", "latitude = 95"]),
    ("truncated-year", "w.csv", lambda: damaged_tmy3(keep=4000), ["w.csv", "no data for", "the file holds"]),
    ("duplicate-hour", "w.csv", lambda: "\n".join(
        (lambda ls: ls[:100] + [ls[99]] + ls[101:])(TMY3.read_text().splitlines())) + "\n", ["w.csv", "same hour"]),
    ("pvgis-not-json", "w.json", lambda: "{not json", ["w.json", "not valid JSON"]),
]


def assert_clean_failure(result, words, place: Path, before: dict):
    assert result.exit_code == 2, (result.exit_code, result.output)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert "Traceback" not in result.output and result.stdout == ""
    for word in words:
        assert word in lines[0], (word, lines[0])
    assert snapshot(place / "prior") == before
    assert not [p.name for p in place.iterdir() if p.name.startswith(".")]  # nothing staged left


@pytest.mark.parametrize("args,words", [case[1:] for case in VALUES], ids=[case[0] for case in VALUES])
def test_bad_values(place, args, words):
    before = snapshot(place / "prior")
    extra = [a for a in QUICK if args[0] == "sweep" and not set(QUICK[::2]) & set(args)]
    result = runner.invoke(app, [*args, *extra, "--out", "prior", "--overwrite"])
    assert_clean_failure(result, words, place, before)


@pytest.mark.parametrize("text,words", [case[1:] for case in YAML_FILES], ids=[case[0] for case in YAML_FILES])
def test_bad_study_files(place, text, words):
    before = snapshot(place / "prior")
    study_file(place, "bad.yaml", text)
    result = runner.invoke(app, ["run", "bad.yaml", "--out", "prior", "--overwrite"])
    assert_clean_failure(result, words, place, before)


@pytest.mark.parametrize("name,text,words", [case[1:] for case in WEATHER_FILES],
                         ids=[case[0] for case in WEATHER_FILES])
def test_bad_weather_files(place, name, text, words):
    before = snapshot(place / "prior")
    study_file(place, name, text())
    result = runner.invoke(app, ["sweep", "angle", "--weather", name, "--p-load", "2", *QUICK, "--out", "prior",
                                 "--overwrite"])
    assert_clean_failure(result, words, place, before)


@pytest.mark.parametrize("make,words", [case[1:] for case in OUTPUTS], ids=[case[0] for case in OUTPUTS])
def test_bad_output_folders(place, make, words):
    study_file(place, "fast.yaml", fast_yaml())
    args = make(place)
    before = snapshot(place / "prior")
    assert_clean_failure(runner.invoke(app, args), words, place, before)


def test_every_tracker_option_is_a_field_of_one_model():
    """The registry the study's idle check reads names the models a study may choose, and options
    the tracker has; every model option belongs to some model."""
    from foldopt import names
    from foldopt.inputs.sections import Tracker
    from foldopt.physics.trackers import TRACKER_MODELS, TrackerOptions

    assert tuple(TRACKER_MODELS) == tuple(names.TRACKERS)
    used = {option for entry in TRACKER_MODELS.values() for option in entry.options}
    assert used == set(TrackerOptions.__dataclass_fields__) and used <= set(Tracker.model_fields)


def test_the_battery_is_large_enough():
    assert len(VALUES) + len(YAML_FILES) + len(WEATHER_FILES) + len(OUTPUTS) >= 60


def test_overwrite_replaces_a_results_folder_and_an_empty_one(place, figures_drawn_elsewhere):
    study_file(place, "fast.yaml", fast_yaml())
    (place / "empty").mkdir()
    for out in ("prior", "empty"):
        # The same answer twice: its figures drawn in the first folder, the second's not drawn.
        with figures_drawn_elsewhere() if out == "empty" else contextlib.nullcontext():
            result = runner.invoke(app, ["run", "fast.yaml", "--out", out, "--overwrite", "-q"])
        assert result.exit_code == 0, result.output
        assert (place / out / "summary.csv").exists() and not (place / out / "sweep.csv").read_text() == "kept\n"
    assert not [p.name for p in place.iterdir() if p.name.startswith(".")]


def test_an_internal_error_is_one_line_and_debug_shows_the_traceback(place, monkeypatch):
    def broken(*args, **kwargs):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr("foldopt.studies.day.run_study", broken)
    study_file(place, "fast.yaml", fast_yaml())
    result = runner.invoke(app, ["run", "fast.yaml", "--out", "new"])
    assert result.exit_code == 1
    assert result.stderr.strip().splitlines() == [
        "error: internal error (ZeroDivisionError: float division by zero); run again as foldopt --debug ... for "
        "the traceback, and please report it"]
    debug = runner.invoke(app, ["--debug", "run", "fast.yaml", "--out", "new"])
    assert debug.exit_code == 1 and "Traceback" in debug.stderr and "ZeroDivisionError" in debug.stderr
    assert not (place / "new").exists()


class Command:
    """A ``foldopt`` command in a process of its own, forked from this one as the console script
    runs it (``app()`` on its ``sys.argv``, the exit code its ``SystemExit``'s): its start costs no
    interpreter and no imports (a ``python -m foldopt.cli.app`` some 0.8 s of CPU before its
    first file). What it is killed for is its own process's: its signal handler, its figure
    workers, its staging folder (its figures drawn as the test's are, conftest's
    ``_no_pixels_unless_marked``). ``poll``, ``wait``, ``send_signal`` and ``returncode`` as
    :class:`subprocess.Popen`'s."""

    def __init__(self, args: list[str], cwd: Path):
        sys.stdout.flush()
        sys.stderr.flush()
        self.returncode, self.pid = None, os.fork()
        if self.pid == 0:  # the child: the command, then its exit, past this process's own ends
            code = 1
            try:
                os.chdir(cwd)
                for fd in (0, 1, 2):
                    os.dup2(os.open(os.devnull, os.O_RDWR), fd)
                sys.argv = ["foldopt", *args]
                app()
            except SystemExit as end:
                code = end.code if isinstance(end.code, int) else int(end.code is not None)
            finally:
                os._exit(code)

    def poll(self) -> int | None:
        if self.returncode is None:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
            if pid:
                self.returncode = os.waitstatus_to_exitcode(status)
        return self.returncode

    def wait(self, timeout: float) -> int:
        deadline = time.monotonic() + timeout
        while self.poll() is None:
            assert time.monotonic() < deadline, f"the command {self.pid} did not end in {timeout} s"
            time.sleep(0.01)
        return self.returncode

    def send_signal(self, sig: int) -> None:
        os.kill(self.pid, sig)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_a_run_killed_while_it_writes_leaves_nothing_behind(tmp_path, sig):
    # The run is killed as soon as its staging folder appears, while it writes. With SIGTERM it
    # removes the folder itself; after SIGKILL the next results folder written beside it does.
    # On a loaded machine the run can finish between its staging folder being seen and the
    # signal: then it must have finished whole (tried again, as test_faults_inputs' Ctrl-C).
    for attempt in range(5):
        folder = tmp_path / str(attempt)
        folder.mkdir()
        study_file(folder, "fast.yaml", fast_yaml(step_min=5))
        prior = folder / "out"
        prior.mkdir()
        (prior / "run.json").write_text(json.dumps({"versions": {"foldopt": "0"}}))
        before = snapshot(prior)
        process = Command(["run", "fast.yaml", "--out", "out", "--overwrite", "-q"], folder)
        deadline, staged = time.monotonic() + 120, []
        while time.monotonic() < deadline and process.poll() is None and not staged:
            staged = list(folder.glob(".out.tmp-*"))
            time.sleep(0.002)
        assert staged, "the run ended before it was seen writing"
        process.send_signal(sig)
        process.wait(timeout=60)
        if process.returncode != 0:
            break
        assert sorted(p.name for p in folder.iterdir()) == ["fast.yaml", "out"]
        assert (prior / "summary.csv").is_file() and snapshot(prior) != before  # the new run, whole
    assert process.returncode != 0, "the run finished before the signal five times"
    assert process.returncode == (128 + sig if sig == signal.SIGTERM else -sig)
    assert snapshot(prior) == before  # the earlier results are intact
    if sig == signal.SIGKILL:
        assert staged[0].exists()  # nothing can clean up after SIGKILL...
        neighbour = runner.invoke(app, ["run", str(folder / "fast.yaml"), "--out", str(folder / "other"), "-q"])
        assert neighbour.exit_code == 0, neighbour.output  # ...but the next run beside it does
    assert sorted(p.name for p in folder.iterdir()) == sorted(["fast.yaml", "out"] + (
        ["other"] if sig == signal.SIGKILL else []))


def test_a_folder_retired_by_a_killed_run_is_put_back(tmp_path):
    import socket

    from foldopt.files import MARKER, clear_leftovers

    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    retired = tmp_path / f".results.old-{dead.pid}"
    (retired / "results").mkdir(parents=True)
    # Only a folder that carries foldopt's marker is foldopt's to put back (issue 21: never the name alone).
    (retired / MARKER).write_text(json.dumps({"writer": "foldopt", "pid": dead.pid, "host": socket.gethostname(),
                                              "token": "0"}))
    (retired / "results" / "run.json").write_text("{}")
    clear_leftovers(tmp_path)
    assert (tmp_path / "results" / "run.json").exists() and not retired.exists()


FIELDS = {
    "name": st.text(max_size=8),
    "mode": st.sampled_from(["paper", "exact", "fast", 3]),
    "date": st.one_of(st.dates().map(str), st.sampled_from(["2025-02-30", "year", "1:365:90", "x"])),
    "p_load": st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from(["1:9:4", "0:1:0"])),
    "step_min": st.sampled_from([60, 30, 7, 0, -5, "x"]),
    "sky": st.sampled_from(["meinel", "hottel", "ineichen", "simplified_solis", "cloudy"]),
    "pv_model": st.sampled_from(["ideal", "single-diode", "b-model", "x"]),
    "connection": st.sampled_from(["switching", "parallel", "independent", "x"]),
    "site": st.one_of(st.fixed_dictionaries({"latitude": st.floats(-100, 100), "longitude": st.floats(-200, 200)}),
                      st.text(max_size=5), st.none()),
    "panel": st.fixed_dictionaries({"area": st.floats(-1, 2), "tilt": st.floats(-10, 100)}),
    "fold_angles": st.fixed_dictionaries({"start": st.floats(-10, 200), "stop": st.floats(-10, 200),
                                          "step": st.sampled_from([30, 45, 0, -1])}),
    "tracker": st.sampled_from(["dual-axis", "single-axis", "x", 5]),
    "objective": st.sampled_from([{"statistic": "mean"}, {"statistic": "p50"}, "best", None]),
}


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(changes=st.dictionaries(st.sampled_from(sorted(FIELDS)), st.none()).flatmap(
    lambda keys: st.fixed_dictionaries({key: FIELDS[key] for key in keys})))
def test_generated_studies_run_or_fail_cleanly(tmp_path, changes):
    folder = tmp_path / f"case-{abs(hash(repr(changes)))}"
    folder.mkdir()
    study = study_file(folder, "s.yaml", yaml.safe_dump({**FAST, "fold_angles": {"start": 60, "stop": 180, "step": 60},
                                                         **changes}))
    result = runner.invoke(app, ["run", str(study), "--out", str(folder / "out"), "-q"])
    assert result.exit_code in (0, 2), (changes, result.output)
    assert "Traceback" not in result.output
    if result.exit_code == 0:
        assert (folder / "out" / "run.json").exists()
    else:
        lines = result.stderr.strip().splitlines()
        assert lines and all(line.startswith("error: ") for line in lines), result.stderr
        assert not (folder / "out").exists()


#: A map's request that cannot be, as the API gives it (make_request's where, --set, a study) and as
#: the command line does: (id, where, settings, study, the API's lines, options, the command line's
#: lines). Nothing is read: none of the files named exists, and the conflict is the only line.
_SOURCES = "give one source of sites: a grid ({}/{}), a CSV of sites ({}) or a folder of weather files ({})"
_API_SOURCES = _SOURCES.format("latitudes", "longitudes", "sites", "weather_dir")
_CLI_SOURCES = _SOURCES.format("--lat", "--lon", "--sites", "--weather-dir")
_FOLDER = "a folder's files are its sites' weather; give one"
_YEARS = "the years of a weather source; give one with {}"
MAP_CONFLICTS = [
    ("grid-and-sites", {"latitudes": "0", "sites": "s.csv"}, [], None, [f"latitudes, sites: {_API_SOURCES}"],
     ["--lat", "0", "--sites", "s.csv"], [f"--lat, --sites: {_CLI_SOURCES}"]),
    ("longitudes-and-folder", {"longitudes": "0", "weather_dir": "w"}, [], None,
     [f"longitudes, weather_dir: {_API_SOURCES}"], ["--lon", "0", "--weather-dir", "w"],
     [f"--lon, --weather-dir: {_CLI_SOURCES}"]),
    ("all-three", {"latitudes": "0", "longitudes": "0", "sites": "s.csv", "weather_dir": "w"}, [], None,
     [f"latitudes/longitudes, sites, weather_dir: {_API_SOURCES}"],
     ["--lat", "0", "--lon", "0", "--sites", "s.csv", "--weather-dir", "w"],
     [f"--lat/--lon, --sites, --weather-dir: {_CLI_SOURCES}"]),
    ("land-of-sites", {"sites": "s.csv", "land_only": True}, [], None,
     ["land_only: only for a latitudes/longitudes grid, not sites"], ["--sites", "s.csv", "--land-only"],
     ["--land-only: only for a --lat/--lon grid, not --sites"]),
    ("land-of-a-folder", {"weather_dir": "w", "land_only": True}, [], None,
     ["land_only: only for a latitudes/longitudes grid, not weather_dir"], ["--weather-dir", "w", "--land-only"],
     ["--land-only: only for a --lat/--lon grid, not --weather-dir"]),
    ("source-and-folder", {"weather_dir": "w", "weather": {"source": "pvgis-tmy"}}, [], None,
     [f"weather.source / weather_dir: {_FOLDER}"], ["--weather-dir", "w", "--weather", "pvgis-tmy"],
     [f"--weather / --weather-dir: {_FOLDER}"]),
    ("set-source-and-folder", {"weather_dir": "w"}, ["weather.source=pvgis-tmy"], None,
     [f"weather.source / weather_dir: {_FOLDER}"], ["--weather-dir", "w", "--set", "weather.source=pvgis-tmy"],
     [f"weather.source / --weather-dir: {_FOLDER}"]),
    ("study-source-and-folder", {"weather_dir": "w"}, [], {"weather": {"source": "pvgis-tmy"}},
     [f"weather.source (the study's) / weather_dir: {_FOLDER}"], ["--weather-dir", "w"],
     [f"weather.source (the study's) / --weather-dir: {_FOLDER}"]),
    ("years-alone", {"sites": "s.csv", "weather": {"years": "2005:2020"}}, [], None,
     [f"weather.years: {_YEARS.format('weather.source')}"], ["--sites", "s.csv", "--years", "2005:2020"],
     [f"--years: {_YEARS.format('--weather')}"]),
    ("set-years-alone", {"sites": "s.csv"}, ["weather.years=2005:2020"], None,
     [f"weather.years: {_YEARS.format('weather.source')}"], ["--sites", "s.csv", "--set", "weather.years=2005:2020"],
     [f"weather.years: {_YEARS.format('--weather')}"]),
    ("study-years-alone", {"sites": "s.csv"}, [], {"weather": {"years": "2005:2020"}},
     [f"weather.years (the study's): {_YEARS.format('weather.source')}"], ["--sites", "s.csv"],
     [f"weather.years (the study's): {_YEARS.format('--weather')}"]),
    ("two-sources-and-land", {"sites": "s.csv", "weather_dir": "w", "land_only": True}, [], None,
     [f"sites, weather_dir: {_API_SOURCES}", "land_only: only for a latitudes/longitudes grid, not sites"],
     ["--sites", "s.csv", "--weather-dir", "w", "--land-only"],
     [f"--sites, --weather-dir: {_CLI_SOURCES}", "--land-only: only for a --lat/--lon grid, not --sites"]),
]


@pytest.mark.parametrize("where,settings,study,api,options,cli", [case[1:] for case in MAP_CONFLICTS],
                         ids=[case[0] for case in MAP_CONFLICTS])
def test_a_maps_sites_and_weather_are_checked_at_the_front_door(place, where, settings, study, api, options, cli):
    """The front door refuses what a map's sites and weather cannot be together, for the API in its
    parameters' names and for ``foldopt map`` in its options' (the command line checks only how it
    asks for its cluster), each before any site or weather file is read."""
    from foldopt.errors import ConfigError
    from foldopt.studies.request import make_request

    data = {**FAST, **study} if study else None
    with pytest.raises(ConfigError) as refused:
        make_request("map", data, settings=settings, where=where)
    assert refused.value.errors == api
    if study:
        study_file(place, "study.yaml", fast_yaml(**study))
        options = [*options, "--config", "study.yaml"]
    before = snapshot(place / "prior")
    result = runner.invoke(app, ["map", *options, "--out", "prior", "--overwrite"])
    assert (result.exit_code, result.stdout) == (2, "")
    assert result.stderr.splitlines() == [f"error: {line}" for line in cli]
    assert snapshot(place / "prior") == before


def test_a_maps_loads_are_given_one_way():
    """--p-load and --p-load-fraction both give a map's loads: one of them, said in one line."""
    result = runner.invoke(app, ["map", "--p-load", "1", "--p-load-fraction", "0.5", "--out", "never"])
    assert (result.exit_code, result.stderr.splitlines()) == (2, [
        "error: --p-load / --p-load-fraction: give loads one way, in watts or as fractions of each site's flat peak"])


def test_world_map_refuses_a_studys_years_without_a_source(tmp_path):
    """foldopt.world_map makes its request at the same front door: a study's weather years with no
    source to take them from are refused, not ignored, before any site is read."""
    import foldopt
    from foldopt.errors import ConfigError

    with pytest.raises(ConfigError) as refused:
        foldopt.world_map(sites=str(tmp_path / "none.csv"), out=tmp_path / "map",
                          study={**FAST, "weather": {"years": "2005:2020"}})
    assert refused.value.errors == [f"weather.years (the study's): {_YEARS.format('weather.source')}"]
    assert not (tmp_path / "map").exists()
