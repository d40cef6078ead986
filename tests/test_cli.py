"""The command line end to end, through typer's CliRunner."""

import json

import pandas as pd
import pytest
import yaml
from typer.testing import CliRunner

from foldopt.cli.app import app
from foldopt.inputs.study_file import default_study_path
from foldopt.studies.reproduce import PAPER_VALUES

runner = CliRunner()
FOLDER = {"summary.csv", "sweep.csv", "timeseries.csv", "power_curves.png",
          "t_solar_vs_fold_angle.png", "comparison.png", "switching.png", "run.json",
          "tracker_standby.png", "tracker_standby.csv", "report.html"}
FAST_SWEEP = ["--lat", "34.05", "--lon", "-118.25", "--date", "2014-09-23", "--p-load", "4.4",
              "--area", "0.108", "--step-min", "10", "--angle-step", "5"]


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def assert_one_line_error(result, *words):
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("error: ")
    assert "Traceback" not in result.output
    for word in words:
        assert word in lines[0]


@pytest.fixture
def fast_config(tmp_path):
    """The paper study with 10-min steps and a 5-deg sweep, as a YAML file."""
    data = yaml.safe_load(default_study_path().read_text())
    data.update(step_min=10, fold_angles={"start": 5, "stop": 180, "step": 5})
    path = tmp_path / "fast.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_run_default_study_writes_the_whole_folder(tmp_path):
    out = tmp_path / "shin"
    result = invoke("run", "--out", out)
    assert result.exit_code == 0, result.output
    assert {p.name for p in out.iterdir()} == FOLDER
    summary = pd.read_csv(out / "summary.csv")
    assert list(summary["design"])[:5] == ["flat", "twofold", "twofold-heuristic", "tracker", "tracker-net"]
    assert ({"tracker:dual-axis-steps", "tracker:dual-axis-steps-net", "tracker:single-axis-net"}
            <= set(summary["design"]))
    meta = json.loads((out / "run.json").read_text())
    assert meta["mode"] == "paper" and meta["study"]["geometry"] == "azimuth-split"
    assert meta["study"]["p_load"] == pytest.approx(4.398)
    assert {"foldopt", "numpy", "pvlib", "python"} <= set(meta["versions"])
    assert meta["command"] == ["foldopt", "run", "--out", str(out)]  # as typed, not the script's path
    # The short answer: the optimum and the flat panel's 7.73 h that P_load was inferred from.
    assert "best fold angle 28.5 deg" in result.stdout and "over flat (7.73 h)" in result.stdout
    assert str(out) in result.stdout and "sweep.csv" not in result.stdout


def test_the_answer_comes_before_the_folder_and_a_failing_folder_still_fails(tmp_path, fast_config, monkeypatch):
    """The figures and report take most of a warm run: the answer's lines are printed before the
    folder is written, and a folder that cannot be written is still one error line and code 2;
    the JSON document, which a program reads, only with its folder."""
    from foldopt import api
    from foldopt.errors import OutputError

    seen = []

    def write(result, out, *args):
        seen.append(runner_stdout())
        raise OutputError(f"cannot write {out}: disk full")

    monkeypatch.setattr(api, "write", write)
    for output_format, printed in (("table", True), ("json", False)):
        seen.clear()
        result = runner.invoke(app, ["run", str(fast_config), "--out", str(tmp_path / "o"), "--format",
                                     output_format])
        assert_one_line_error(result, "disk full")
        assert ("best fold angle" in result.stdout) is printed and "wrote" not in result.stdout
        assert seen == [printed] and not (tmp_path / "o").exists()


def runner_stdout() -> bool:
    """Whether the answer was on stdout already when the folder's writing began."""
    import sys

    sys.stdout.flush()
    return b"best fold angle" in sys.stdout.buffer.getvalue()


def test_existing_folder_is_kept_unless_overwrite(tmp_path, fast_config):
    out = tmp_path / "r"
    assert invoke("run", fast_config, "--out", out).exit_code == 0
    before = (out / "sweep.csv").read_bytes()
    (out / "note.txt").write_text("mine")
    assert_one_line_error(invoke("run", fast_config, "--out", out), "already exists", "--overwrite")
    assert (out / "note.txt").exists()
    assert invoke("run", fast_config, "--out", out, "--overwrite").exit_code == 0
    assert not (out / "note.txt").exists()
    assert (out / "sweep.csv").read_bytes() == before  # a rerun writes identical CSVs
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no staging left


@pytest.mark.parametrize(
    "change,words",
    [
        ({"site": {"latitude": 95, "longitude": 0}}, ["site.latitude", "[-90, 90]"]),
        ({"site": {"latitude": 10, "longitude": -200}}, ["site.longitude", "[-180, 180]"]),
        ({"p_load": -1}, ["p_load", "(0, 1e+06]"]),
        ({"panel": {"area": 0}}, ["panel.area", "(0, 1000]"]),
        ({"panel": {"area": 1, "efficiency": 1.5}}, ["panel.efficiency", "(0, 1]"]),
        ({"mode": "fast"}, ["mode", "must be one of paper, exact"]),
        ({"geometry": "tent"}, ["geometry", "azimuth-split, hinge"]),
        ({"date": "2014-02-30"}, ["date"]),
        ({"colour": "red"}, ["colour", "unknown field"]),
        ({"site": {"latitude": "north", "longitude": 0}}, ["site.latitude", "number"]),
        ({"site": {"latitude": 1, "longitude": 0, "timezone": "Mars/Olympus"}}, ["site.timezone", "Mars/Olympus"]),
        ({"step_min": 7}, ["step_min", "1440"]),
        ({"fold_angles": {"start": 90, "stop": 30}}, ["fold_angles", "must not exceed"]),
    ],
)
def test_bad_config_values(tmp_path, fast_config, change, words):
    data = yaml.safe_load(fast_config.read_text())
    data.update(change)
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data))
    out = tmp_path / "out"
    assert_one_line_error(invoke("run", path, "--out", out), *words)
    assert not out.exists()


@pytest.mark.parametrize(
    "text,words",
    [
        ("name: x\nsite: [1, 2\n", ["line", "bad.yaml"]),
        ("- just\n- a list\n", ["expected a mapping"]),
        ("name: x\n", ["site", "required field is missing"]),
    ],
)
def test_malformed_config(tmp_path, text, words):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    result = invoke("run", path, "--out", tmp_path / "out")
    assert result.exit_code == 2
    assert "Traceback" not in result.output
    assert all(word in result.stderr for word in words)
    assert not (tmp_path / "out").exists()


def test_missing_config(tmp_path):
    assert_one_line_error(invoke("run", tmp_path / "nope.yaml", "--out", tmp_path / "o"), "not found", "nope.yaml")


def test_sweep_angle_writes_sweep_and_summary(tmp_path):
    out = tmp_path / "sweep"
    result = invoke("sweep", "angle", *FAST_SWEEP, "--mode", "exact", "--out", out)
    assert result.exit_code == 0, result.output
    assert FOLDER <= {p.name for p in out.iterdir()}
    sweep = pd.read_csv(out / "sweep.csv")
    assert {"fold_angle_deg", "t_solar_h", "t_solar_contiguous_h", "energy_harvested_wh"} <= set(sweep.columns)
    assert sweep["fold_angle_deg"].iloc[0] == 5 and sweep["fold_angle_deg"].iloc[-1] == 180
    summary = pd.read_csv(out / "summary.csv")
    assert {"flat", "twofold", "tracker"} <= set(summary["design"])
    assert json.loads((out / "run.json").read_text())["study"]["geometry"] == "hinge"


@pytest.mark.parametrize(
    "option,value,words",
    [
        ("--lat", "91", ["--lat", "[-90, 90]"]),
        ("--lon", "200", ["--lon", "[-180, 180]"]),
        ("--p-load", "0", ["--p-load", "(0, 1e+06]"]),
        ("--area", "-1", ["--area", "(0, 1000]"]),
        ("--efficiency", "1.5", ["--efficiency", "(0, 1]"]),
        ("--tilt", "120", ["--tilt", "[0, 90]"]),
        ("--mode", "fast", ["--mode", "paper, exact"]),
        ("--geometry", "tent", ["--geometry"]),
        ("--sky", "cloudy", ["--sky", "meinel"]),
        ("--tracker", "heliostat", ["--tracker", "single-axis"]),
        ("--tracker-standby", "-1", ["--tracker-standby", "[0, 1000]"]),
        ("--climate", "arctic", ["--climate", "tropical"]),
        ("--date", "2014-13-01", ["--date"]),
        ("--step-min", "7", ["--step-min", "1440"]),
        ("--pv-model", "two-diode", ["--pv-model", "single-diode"]),
        ("--module", "NoSuchModule", ["--module", "only used with pv_model single-diode"]),
        ("--connection", "star", ["--connection", "series"]),
        ("--converter-efficiency", "1.2", ["--converter-efficiency", "(0, 1]"]),
        ("--lat", "abc", ["--lat", "expected a number"]),
    ],
)
def test_sweep_angle_bad_input(tmp_path, option, value, words):
    args = list(FAST_SWEEP)
    if option in args:
        args[args.index(option) + 1] = value
    else:
        args += [option, value]
    out = tmp_path / "out"
    assert_one_line_error(invoke("sweep", "angle", *args, "--out", out), *words)
    assert not out.exists()


def test_sweep_angle_with_single_diode_switching(tmp_path):
    out = tmp_path / "sd"
    # The paper's beam-only sky, which the switch's east and west states were seen under: with
    # exact mode's own diffuse light both halves are lit all day at the best angle (parallel only).
    result = invoke("sweep", "angle", *FAST_SWEEP, "--sky", "meinel", "--pv-model", "single-diode", "--switch-series",
                    "--out", out)
    assert result.exit_code == 0, result.output
    summary = pd.read_csv(out / "summary.csv").set_index("design")
    assert {"twofold-parallel", "twofold-series", "twofold-independent"} <= set(summary.index)
    sweep = pd.read_csv(out / "sweep.csv")
    for name in ("east", "west", "parallel", "series", "independent", "switching"):
        assert f"t_solar_{name}_h" in sweep and f"energy_harvested_{name}_wh" in sweep
    states = set(pd.read_csv(out / "timeseries.csv")["switch_state"])
    assert {"east", "west", "parallel"} <= states


def test_unknown_cec_module_is_named(tmp_path):
    args = [*FAST_SWEEP, "--pv-model", "single-diode", "--module", "NoSuchModule", "--out", tmp_path / "o"]
    assert_one_line_error(invoke("sweep", "angle", *args), "--module", "CEC database")


def test_sweep_angle_takes_what_is_not_given_from_the_embedded_study(tmp_path):
    result = invoke("sweep", "angle", "--lat", "40", "--out", tmp_path / "o")
    assert result.exit_code == 0, result.output
    study = json.loads((tmp_path / "o" / "run.json").read_text())["study"]
    assert study["site"]["latitude"] == 40 and study["site"]["longitude"] == -118.25
    assert study["panel"]["tilt"] == 40  # tilt follows the new latitude
    assert (study["p_load"], study["date"]) == (4.398, "2014-09-23")
    assert "from configs/shin2015.yaml: date 2014-09-23, panel 0.108 m^2, P_load 4.398 W" in result.stdout


def test_reproduce_writes_the_agreed_table(tmp_path):
    out = tmp_path / "repro"
    result = invoke("reproduce", "--out", out)
    assert result.exit_code == 0, result.output
    for name in ("reproduction", "reproduction_single_diode"):
        table = pd.read_csv(out / f"{name}.csv")
        assert list(table.columns) == ["quantity", "unit", "paper", "paper_mode", "exact_mode"]
        assert list(table["quantity"]) == list(PAPER_VALUES)
    assert "fold_angle_twofold_deg" in result.stdout
    assert_one_line_error(invoke("reproduce", "--out", out), "already exists")


@pytest.mark.parametrize("args, words", [
    (["sweep", "angle", "--date", "2025-06-21", "--days", "2025-06-22"], ["--days: given twice (first as --date)"]),
    (["sweep", "angle", "--quiet", "-q"], ["-q: given twice (first as --quiet)"]),
    (["map", "--lat=10", "--lat", "20"], ["--lat: given twice (first as --lat)"]),
])
def test_an_option_given_twice_is_refused(tmp_path, args, words):
    """click keeps the last of a repeated option; the command line refuses it, naming both."""
    assert_one_line_error(invoke(*args, "--out", tmp_path / "out"), *words, "give each option once")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("before", [None, "0"])
def test_quiet_silences_notices_for_the_command_only_and_sets_no_variable(monkeypatch, capsys, before):
    """--quiet silences foldopt's notices (a damaged cache entry, here weather list's) while the
    command runs, through a context variable: the caller's environment is untouched, and its own
    notices are heard again once the command ends, on a refusal as on a success."""
    import os

    import foldopt.inputs.weather.sources as sources
    from foldopt.cache import notice, quiet

    if before is None:
        monkeypatch.delenv("FOLDOPT_QUIET", raising=False)
    else:
        monkeypatch.setenv("FOLDOPT_QUIET", before)
    monkeypatch.setattr(sources, "damaged_entries", lambda: [("entry.json", "truncated")])
    environment = dict(os.environ)
    loud = invoke("weather", "list")
    assert "foldopt: the cached copy entry.json is damaged (truncated)" in loud.stderr
    hushed = invoke("weather", "list", "--quiet")
    assert (hushed.exit_code, hushed.stderr, hushed.stdout) == (0, "", "")
    assert_one_line_error(invoke("sweep", "angle", "--quiet", "--lat", "95"), "--lat")
    assert dict(os.environ) == environment and not quiet()
    capsys.readouterr()
    notice("heard")  # in this process, after the commands: not silenced
    assert capsys.readouterr().err == "foldopt: heard\n"
    monkeypatch.setenv("FOLDOPT_QUIET", "yes")  # the environment's word for it still holds
    assert invoke("weather", "list").stderr == "" and quiet()
