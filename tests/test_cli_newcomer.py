"""The command line from a newcomer's chair: every command from its defaults, help that keeps its
units, one JSON document per command, silence under --quiet, true notes, pvlib's spellings, and
options that would do nothing refused."""

import json
from pathlib import Path

import pandas as pd
import pytest
import pvlib
from typer.testing import CliRunner

from foldopt import names
from foldopt.cli.app import app
from test_cli import assert_one_line_error

runner = CliRunner()
TMY3 = Path(pvlib.__file__).parent / "data" / "723170TYA.CSV"


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def flat_text(text: str) -> str:
    """Help text with its line wrapping undone."""
    return " ".join(text.split())


@pytest.mark.parametrize(
    "command,check",
    [
        (["sweep", "angle"], lambda table: table["fold_angle_deg"].tolist() == [float(a) for a in range(1, 181)]),
        (["sweep", "latitude"], lambda table: sorted(set(table["latitude"])) == list(range(-60, 65, 5))),
        (["sweep", "day"], lambda table: table["date"].nunique() == 53 and table["date"].min() == "2014-01-01"),
        (["sweep", "load"], lambda table: sorted(set(table["p_load_w"]))[-1] == pytest.approx(0.108 * 1000 * 0.1905)
         and table["p_load_w"].nunique() == 20),
        (["size"], lambda table: table["area_m2"].min() == pytest.approx(0.01) and table["area_m2"].max()
         == pytest.approx(0.5)),
    ],
    ids=["angle", "latitude", "day", "load", "size"],
)
def test_every_command_runs_with_no_option(tmp_path, command, check):
    out = tmp_path / "o"
    result = invoke(*command, "--out", out, "--format", "json")
    assert result.exit_code == 0, result.output
    document = json.loads(result.stdout)  # exactly one document
    assert document["out"] == str(out)
    table = pd.read_csv(out / {"angle": "sweep.csv", "size": "sizing.csv"}.get(command[-1], "results.csv"))
    assert check(table)
    if command[0] == "sweep" and command[1] != "angle":
        taken = document["answer"]["defaults"]["taken"]
        assert document["answer"]["defaults"]["study"] == "configs/shin2015.yaml"
        assert "(default range)" in taken[0] and "panel 0.108 m^2" in taken


def test_the_summary_says_which_values_were_defaults(tmp_path, figures_drawn_elsewhere,
                                                     folders_written_elsewhere):
    with figures_drawn_elsewhere():  # the answer of test_every_command_runs_with_no_option[day]
        result = invoke("sweep", "day", "--out", tmp_path / "o")
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert lines[1] == ("  from configs/shin2015.yaml: day 1:365:7 of 2014 (default range), site 34.05, -118.25, "
                        "panel 0.108 m^2, P_load 4.398 W, exact mode (paper mode is for the paper's own site and "
                        "day: set mode paper to keep it), pvwatts PV model (SAPM cells, -0.37 %/C, 8.7 % "
                        "losses)")
    assert "(--table prints the full table)" in lines and len(lines) < 8
    study = json.loads((tmp_path / "o" / "run.json").read_text())["study"]
    assert (study["mode"], study["geometry"]) == ("exact", "hinge")  # the geometry follows the mode
    with folders_written_elsewhere():  # its terminal's table is what is read
        table = invoke("sweep", "day", "--days", "1:365:120", "--out", tmp_path / "t", "--table")
    assert "t_solar_h" in table.stdout and len(table.stdout.splitlines()) > 4


@pytest.mark.parametrize("command", [[], ["sweep"]], ids=["foldopt", "foldopt sweep"])
def test_a_bare_command_prints_its_help(command):
    result = invoke(*command)
    assert result.exit_code == 0 and result.stdout.startswith("Usage:") and result.stderr == ""
    assert "error:" not in result.stdout and "..." not in result.stdout.split("Commands:")[1]


def test_help_keeps_units_and_lists_every_accepted_name():
    top = invoke("--help")
    assert top.exit_code == 0 and "Examples:" in top.stdout and "--install-completion" in top.stdout
    helps = {axis: invoke("sweep", axis, "--help").stdout for axis in ("angle", "latitude", "day", "load")}
    assert len(set(helps.values())) == 4  # each axis its own help
    text = flat_text(helps["latitude"])
    for unit in ("[deg north]", "[deg east]", "[m^2]", "[W]", "[min]", "[deg]", "[m]"):
        assert unit in text, unit
    assert "<bool>" not in text and "-60:60:5" in text and "foldopt sweep latitude --lat" in text
    for registry, option in ((names.SKIES, "--sky"), (names.PV_MODELS, "--pv-model"),
                             (names.TRACKERS, "--tracker"), (names.TRANSPOSITIONS, "--transposition")):
        listed = text.split(option, 1)[1][:300]
        assert " | ".join(registry) in listed, option
    size = flat_text(invoke("size", "--help").stdout)
    assert "[$/m^2]" in size and "[default: 164" in size


@pytest.mark.parametrize(
    "command",
    [["run"], ["reproduce"], ["size", "--areas", "0.05:0.15:0.05"],
     ["sweep", "load", "--p-load", "2:6:2", "--step-min", "10"]],
    ids=["run", "reproduce", "size", "sweep"],
)
def test_one_json_document_and_quiet_silence(tmp_path, command, folders_written_elsewhere):
    with folders_written_elsewhere():  # the same answer's folder is the quiet run's, below
        result = invoke(*command, "--out", tmp_path / "j", "--format", "json")
    assert result.exit_code == 0, result.output
    document = json.loads(result.stdout)
    assert document["command"] == " ".join(command[:2] if command[0] == "sweep" else command[:1])
    assert set(document) == {"command", "out", "answer", "rows"}
    assert document["answer"]["lines"] and document["answer"]["question"]
    assert result.stderr == ""  # no progress, no status line in the document's way
    quiet = invoke(*command, "--out", tmp_path / "q", "--quiet")  # its folder written whole
    assert quiet.exit_code == 0, quiet.output
    assert quiet.stdout == "" and quiet.stderr == ""
    assert (tmp_path / "q" / "run.json").exists()


@pytest.mark.parametrize(
    "args,note,line",
    [
        (["--lat", "80", "--date", "2025-12-21"], ["polar night"], "no fold angle reaches the load"),
        (["--lat", "80", "--date", "2025-06-21"], ["polar day"], "best fold angle"),
        (["--p-load", "30"], ["load above peak"], "no fold angle reaches the load"),
        # The paper's ideal model: PVWatts' power, 8.7 % less, stays below 2 W that day.
        (["--weather", TMY3, "--days", "2025-11-27", "--p-load", "2", "--pv-model", "ideal"], ["overcast"],
         "best fold angle"),
        (["--weather", TMY3, "--days", "2025-06-21", "--p-load", "2"], [], "best fold angle"),
    ],
    ids=["polar-night", "polar-day", "above-peak", "overcast", "clear"],
)
def test_notes_name_the_day(tmp_path, args, note, line, folders_written_elsewhere):
    result = invoke("sweep", "angle", *args, "--angle-step", "10", "--out", tmp_path / "o", "--format", "json")
    assert result.exit_code == 0, result.output
    document = json.loads(result.stdout)
    assert [entry["note"] for entry in document["answer"]["notes"]] == note
    assert {row["note"] for row in document["rows"]} == {"; ".join(note)}
    with folders_written_elsewhere():  # the same answer's folder again
        text = invoke("sweep", "angle", *args, "--angle-step", "10", "--out", tmp_path / "t").stdout
    assert line in text and (f"note: {note[0]}" in text if note else "note:" not in text)


def test_overcast_is_no_polar_night_in_a_year(tmp_path, folders_written_elsewhere):
    # 2.25 W: above the peak of the tracker net of its drive on 3 days that are not overcast, below
    # every other design's peak on those days (the paper's ideal model's peaks). Its document is
    # what is read: the folder a weather file's year writes is test_cli_studies'.
    with folders_written_elsewhere():
        result = invoke("sweep", "angle", "--weather", TMY3, "--p-load", "2.25", "--angle-step", "30",
                        "--pv-model", "ideal", "--out", tmp_path / "y", "--format", "json")
    assert result.exit_code == 0, result.output
    notes = {entry["note"]: entry for entry in json.loads(result.stdout)["answer"]["notes"]}
    assert "polar night" not in notes and 0 < notes["overcast"]["cases"] < 30
    assert notes["overcast"]["designs"] == []  # the day's own condition concerns every design
    # A load above a design's peak names that design only (here the tracker net of its drive).
    assert all(notes["load above peak"]["designs"]) and "twofold" not in notes["load above peak"]["designs"]


def test_pvlib_spellings_and_cec_names(tmp_path):
    out = tmp_path / "o"
    result = invoke("sweep", "angle", "--mode", "exact", "--sky", "simplified_solis", "--pv-model", "singlediode",
                    "--module", "cs5p 220m", "--tracker", "singleaxis", "--angle-step", "30", "--out", out, "-q")
    assert result.exit_code == 0, result.output
    study = json.loads((out / "run.json").read_text())["study"]
    assert (study["sky"], study["pv_model"], study["tracker"]["model"]) == ("simplified-solis", "single-diode",
                                                                            "single-axis")
    assert study["module"] == "Canadian_Solar_Inc__CS5P_220M"
    assert_one_line_error(invoke("sweep", "angle", "--sky", "meinell", "--out", tmp_path / "b"),
                          "--sky", "did you mean 'meinel'")
    assert_one_line_error(invoke("sweep", "angle", "--pv-model", "single-diode", "--module", "CS5P-220",
                                 "--out", tmp_path / "b"), "--module", "matches 2 modules", "CS5P_220M")


@pytest.mark.parametrize(
    "args,words",
    [
        (["--climate", "tropical"], ["--climate", "only used by sky hottel"]),
        (["--converter-efficiency", "0.9"], ["--converter-efficiency", "only used by connection independent"]),
        (["--switch-series", "--connection", "east"], ["--switch-series", "only used by connection switching"]),
        (["--albedo", "0.3"], ["--albedo", "only used with a transposition"]),
        (["--temp-air", "30"], ["--temp-air", "single-diode, b-model, pvwatts"]),
    ],
)
def test_options_that_do_nothing_are_refused(tmp_path, args, words):
    out = tmp_path / "o"
    assert_one_line_error(invoke("sweep", "angle", *args, "--out", out), *words)
    assert not out.exists()


def test_idle_setting_in_a_yaml_study_is_refused_the_same_way(tmp_path):
    study = tmp_path / "s.yaml"
    study.write_text("name: s\nsite: {latitude: 34, longitude: -118}\ndate: 2025-03-20\np_load: 3\n"
                     "panel: {area: 0.1}\nclimate: tropical\n")
    assert_one_line_error(invoke("run", study, "--out", tmp_path / "o"), "climate", "only used by sky hottel")
