"""One study, one answer: the same request through the command line (its entry point with
``--format json``) and through the Python API gives the same table to the bit, and every view (the
terminal, the JSON, report.html and ``result.answer``) shows the objective's own value, the
re-fold schedule and the near-optimal range.

The reference of each comparison is the other route: the CLI's numbers are read back from its JSON
(exact floats) and compared with ``==`` to the API's, so a policy decided in one place only (a mode,
a geometry, a tilt, a default range) shows up as a difference."""

from __future__ import annotations

import contextlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import foldopt
from foldopt.cli.app import app
from foldopt.studies.answer import records

ROOT = Path(__file__).resolve().parent.parent
TMY3 = ROOT / "configs" / "weather" / "723170TYA.CSV"
#: Names a session replaced by one name per quantity (foldopt.output.columns); none may be written again.
OLD_NAMES = ("pct_of_tracker_t_solar", "t_solar_pct_of_tracker", "t_solar_gain_vs_flat_pct", "energy_wh",
             "energy_flat_kwh", "energy_twofold_kwh", "energy_tracker_kwh", "tracker_net_t_solar_h",
             "twofold_t_solar_h", "mean_h", "p10_h", "min_h", "flat_objective_h", "tracker_objective_h")


def cli(tmp_path: Path, *args, terminal=None) -> tuple[dict, Path, str]:
    """Run ``foldopt ARGS --format json`` through the command line's own entry point (in-process:
    what is compared is the command's answer, not a process; a process of its own cost some 4 s of
    interpreter, imports and compiled-code loading a call): its document and folder; and, with
    ``terminal`` (the fixture ``two_views``), the terminal's text of the same command, whose run then writes the
    folder over the JSON run's (made, not filled: the same answer's folder, tables and figures,
    written once), the two commands one run of their request (the same answer, decided once)."""
    out = tmp_path / "cli"
    args = [*map(str, args), "--out", str(out)]
    runner = CliRunner(env={"COLUMNS": "200"})
    not_written, shared = terminal or (contextlib.nullcontext, contextlib.nullcontext)
    with contextlib.chdir(ROOT), shared():
        with not_written():
            done = runner.invoke(app, [*args, "--format", "json"])
        assert done.exit_code == 0, done.output
        text = ""
        if terminal:
            shown = runner.invoke(app, [*args, "--overwrite"])
            assert shown.exit_code == 0, shown.output
            text = shown.stdout
    document = json.loads(done.stdout)
    # Without a run of its own, the terminal's words are the answer's lines the document holds
    # (Answer.lines(), which the terminal prints).
    return document, out, text or "\n".join(document["answer"]["lines"])


@pytest.fixture
def two_views(folders_written_elsewhere, runs_shared):
    """For :func:`cli`: the terminal's view too, of the JSON's run (conftest's
    ``folders_written_elsewhere`` and ``runs_shared``)."""
    return folders_written_elsewhere, runs_shared


@pytest.fixture(autouse=True)
def _figures_not_drawn(figures_drawn_elsewhere):
    """No test here reads a figure (the folders' tables, report.html and the answers are what is
    compared): their figures are written without being drawn (conftest's
    ``figures_drawn_elsewhere``), each kind drawn by the tests of the shipped studies and reports
    (test_cli_studies.py, test_camera_winter.py, test_report_html.py)."""
    with figures_drawn_elsewhere():
        yield


def same_rows(document: dict, table: pd.DataFrame) -> None:
    """The CLI's rows equal the API's table, value for value (floats to the bit, NaN as null)."""
    expected = json.loads(json.dumps(records(table)))
    assert document["rows"] == expected


def assert_views_agree(document: dict, folder: Path, terminal: str, answer) -> None:
    """The near-optimal range and recommended angle are in all four views, and the JSON answer is
    the API's answer."""
    api = json.loads(json.dumps(answer.to_dict()))
    for key in ("kind", "result", "designs", "near_optimal", "schedule", "notes"):
        assert document["answer"][key] == api[key], key
    assert len(answer.near_optimal) and "recommended_deg" in answer.near_optimal
    page = (folder / "report.html").read_text()
    assert "Near-optimal fold angles" in page and "recommended_deg" in page
    assert "near-optimal" in terminal and "recommended" in terminal
    for line in answer.lines()[2:]:  # beyond the title and "from" lines (the API's source differs)
        assert line in terminal


def no_old_names(folder: Path, document: dict) -> None:
    written = set()
    for path in folder.rglob("*.csv"):
        written |= set(pd.read_csv(path, nrows=0).columns)
    text = json.dumps(document)
    for name in OLD_NAMES:
        assert name not in written, name
        assert f'"{name}"' not in text, name


def test_embedded_run(tmp_path, two_views):
    document, folder, terminal = cli(tmp_path, "run", terminal=two_views)
    result = foldopt.run(foldopt.default_study())
    same_rows(document, result.summary)
    assert_views_agree(document, folder, terminal, result.answer)
    no_old_names(folder, document)
    # Shin et al. Fig. 12a: the optimum is a plateau; the recommended angle lies on it, inside the range.
    near = result.answer.near_optimal.iloc[0]
    assert near["near_optimal_lo_deg"] <= near["recommended_deg"] <= near["near_optimal_hi_deg"]


def test_latitude_sweep_plans_the_same_study(tmp_path):
    document, folder, terminal = cli(tmp_path, "sweep", "latitude", "--lat", "0,20")
    result = foldopt.sweep(foldopt.default_study(), latitude=[0, 20])
    same_rows(document, result.table)
    assert_views_agree(document, folder, terminal, result.answer)
    study = json.loads((folder / "run.json").read_text())["study"]
    # The policy, whichever route: exact mode, the hinge, the panel at |latitude| toward the equator.
    assert (study["mode"], study["geometry"], study["panel"]["tilt"]) == ("exact", "hinge", 0.0)
    assert (result.plan.base.mode, result.plan.base.geometry) == ("exact", "hinge")


def test_an_angle_sweep_is_the_api_sweep_over_angle(tmp_path, two_views):
    """``foldopt.sweep(study, "angle", ...)`` runs the request as the command line does: one case is
    a day's study with its refined best angle (it was a one-case plan, its grid's 23 deg for 22.6)."""
    document, folder, terminal = cli(tmp_path, "sweep", "angle", "--lat", "52.5", "--lon", "13.4", "--p-load", "2",
                                     terminal=two_views)
    result = foldopt.sweep(foldopt.default_study(), "angle", latitude=52.5, longitude=13.4, p_load=2)
    same_rows(document, result.summary)
    assert_views_agree(document, folder, terminal, result.answer)


def test_worst_month_year_at_nairobi(tmp_path, two_views):
    args = ("--lat", "-1.29", "--lon", "36.82", "--days", "year", "--objective", "worst-month", "--p-load", "3",
            "--step-min", "10")
    document, folder, terminal = cli(tmp_path, "sweep", "day", *args, terminal=two_views)
    result = foldopt.sweep(foldopt.default_study(), "day", latitude=-1.29, longitude=36.82, date="year",
                           objective="worst-month", p_load=3, step_min=10)
    same_rows(document, result.table)
    assert_views_agree(document, folder, terminal, result.answer)
    case = document["answer"]["result"]["per_case"][0]
    # The objective in its own terms: each design's lowest monthly mean and the month it falls in,
    # checked against the daily rows the same document holds.
    daily = pd.DataFrame(document["rows"])
    daily["month"] = pd.to_datetime(daily["date"]).dt.month
    monthly = daily[daily["design"] == "twofold"].groupby("month")["t_solar_h"].mean()
    assert case["t_solar_objective_h"]["twofold"] == pytest.approx(monthly.min(), abs=1e-12)
    assert case["worst_month"]["twofold"] == int(monthly.idxmin())
    page = (folder / "report.html").read_text()
    month = __import__("calendar").month_name[case["worst_month"]["twofold"]]
    assert f"worst-month t_solar {case['t_solar_objective_h']['twofold']:.2f} h (in {month})" in page
    assert f"(in {month})" in terminal
    # The report shows the year's summary, not 1,460 daily rows.
    assert page.count("<tr>") < 100 and len(page) < 600_000
    no_old_names(folder, document)


def test_weather_year_with_a_profile_and_two_visits(tmp_path):
    profile = tmp_path / "camera.csv"
    profile.write_text("time,watts\n00:00,1.5\n07:00,6\n19:00,1.5\n")
    # 30 deg between fold angles: what is checked (both routes' rows to the bit, the schedules of one
    # and two settings in every view, the profile's name) holds on any grid of angles.
    document, folder, terminal = cli(tmp_path, "sweep", "angle", "--weather", TMY3, "--load-profile", profile,
                                     "--visits", "2", "--angle-step", "30", "--step-min", "15")
    result = foldopt.sweep(foldopt.default_study(), "angle", weather=str(TMY3), load_profile={"file": str(profile)},
                           visits=2, fold_angles={"step": 30}, step_min=15)
    same_rows(document, result.table)
    assert_views_agree(document, folder, terminal, result.answer)
    schedule = pd.DataFrame(document["answer"]["schedule"])
    written = pd.read_csv(folder / "refold_schedule.csv")
    assert schedule[["settings_n", "visit", "date", "fold_angle_deg"]].to_dict("list") == written[
        ["settings_n", "visit", "date", "fold_angle_deg"]].to_dict("list")
    assert sorted(set(schedule["settings_n"])) == [1, 2]
    page = (folder / "report.html").read_text()
    for row in schedule.itertuples():
        assert f"{row.date} at {row.fold_angle_deg:g} deg" in page and f"{row.date} at" in terminal
    # A profile is reported as its profile, never as its scale.
    for view in (terminal, page, json.dumps(document["answer"]["question"])):
        assert "load profile camera (mean 3.75 W, peak 6 W)" in view
        assert "P_load 1 W" not in view
    no_old_names(folder, document)


def test_size(tmp_path):
    document, folder, terminal = cli(tmp_path, "size")
    result = foldopt.size(foldopt.default_study())
    same_rows(document, result.table)
    assert document["answer"]["result"] == json.loads(json.dumps(result.answer.to_dict()))["result"]
    no_old_names(folder, document)


@pytest.mark.parametrize("option,parameter,value", [
    ("--cost-per-m2", "cost_per_m2", 1e308), ("--cost-per-m2", "cost_per_m2", float("nan")),
    ("--cost-per-w", "cost_per_w", 0.0), ("--c-grid", "c_grid", 1e306), ("--years", "years", -1.0),
    ("--days-per-year", "days_per_year", 367.0),
])
def test_size_refuses_what_the_api_refuses(option, parameter, value):
    """One limit of the sizing (foldopt.studies.request.SIZING_LIMITS), whichever way it is asked: the
    command line's line is the API's, said with the option's name."""
    from typer.testing import CliRunner

    from foldopt.cli.app import app

    shown = CliRunner().invoke(app, ["size", option, repr(value)])
    with pytest.raises(foldopt.ConfigError) as refused:
        foldopt.size(foldopt.default_study(), **{parameter: value})
    [line] = refused.value.errors
    assert shown.exit_code == 2 and shown.stdout == ""
    assert shown.stderr == f"error: {option}{line[line.index(' = '):]}\n"
    assert "must be a finite number > 0 and at most" in line


def test_a_map_request_is_the_api_request(tmp_path, monkeypatch, scheduler):
    """A map of named sites at the study's load through the command line, and the same request
    made with foldopt.studies.request.make_request and run by foldopt.world_map: the same rows
    to the bit, the same answer, the same things taken from the study; every view carries the
    near-optimal range and the recommended angle. world_map runs the request it is given: it does
    not build and check it again (it did, after the command line had). Both on the in-process
    cluster (conftest.scheduler): an embedded one (workers=1) started a process for each map,
    which imported foldopt and loaded its compiled code again."""
    import foldopt.studies.map_request
    from foldopt.studies.request import make_request

    sites = tmp_path / "sites.csv"
    sites.write_text("name,latitude,longitude\nquito,-0.18,-78.47\noslo,59.91,10.75\nsydney,-33.87,151.21\n")
    document, folder, _ = cli(tmp_path, "map", "--sites", sites, "--scheduler", scheduler, "--step-min", "60",
                              "--angle-step", "10")
    request = make_request("map", options={"step_min": 60.0, "angle_step": 10.0}, where={"sites": str(sites)})
    assert [site["name"] for site in request.plan.sites] == ["quito", "oslo", "sydney"]
    assert isinstance(request.plan.study, foldopt.Study)  # what the map ships to its workers
    monkeypatch.setattr(foldopt.studies.map_request, "map_request", None)  # a second build would fail
    result, _, answer = foldopt.world_map(request=request, out=tmp_path / "api", scheduler=scheduler)
    year = result.table[result.table["period"] == "year"].reset_index(drop=True)
    same_rows(document, year)
    api = json.loads(json.dumps(answer.to_dict()))
    for key in ("kind", "designs", "near_optimal", "notes"):
        assert document["answer"][key] == api[key], key
    run = ("dashboard", "seconds")  # the cluster's, not the map's
    assert ({k: v for k, v in document["answer"]["result"].items() if k not in run}
            == {k: v for k, v in api["result"].items() if k not in run})
    assert document["answer"]["defaults"]["taken"] == request.defaults["taken"]
    assert "P_load 4.398 W" in request.defaults["taken"]
    assert document["answer"]["near_optimal"] == json.loads(json.dumps(records(answer.near_optimal)))
    assert any("recommended" in line and "near-optimal ranges" in line for line in document["answer"]["lines"])
    assert "Near-optimal fold angles" in (folder / "report.html").read_text()
    assert np.isfinite(year["recommended_deg"]).all()
    no_old_names(folder, document)


def test_a_map_says_whose_step_it_takes():
    """A map takes the study's step, as every command does (the embedded study's 1 min; maps had
    their own 5 min), and says so; a study that names no step, and no mode, was a TypeError."""
    from foldopt.studies.request import make_request

    grid = {"latitudes": [0], "longitudes": [0]}
    embedded = make_request("map", where=grid)
    assert "1-min steps" in embedded.defaults["taken"]
    assert "exact mode" in embedded.defaults["taken"]
    own = make_request("map", {"name": "own", "panel": {"area": 0.1}, "p_load": 1.0}, where=grid)
    assert {"1-min steps", "exact mode", "pvwatts PV model (SAPM cells, -0.37 %/C, 8.7 % losses)"} <= set(
        own.defaults["taken"])
    assert "10-min steps" not in make_request("map", where=grid, settings=["step_min=10"]).defaults["taken"]


def test_variant_merges_sections_and_speaks_in_config_errors():
    study = foldopt.default_study()
    smaller = study.variant(panel={"area": 0.1})
    assert (smaller.panel.area, smaller.panel.efficiency, smaller.panel.tilt) == (0.1, 0.1905, 34.05)
    with pytest.raises(foldopt.ConfigError, match="year: unknown field"):
        study.variant(year=2014)
    with pytest.raises(foldopt.ConfigError, match=r"site.latitude = 100.0: must be in \[-90, 90\]"):
        study.variant(site={"latitude": 100.0})
    # The policy the command line applies: another latitude leaves the paper's site.
    moved = study.variant(site={"latitude": 10.0})
    assert (moved.mode, moved.geometry, moved.panel.tilt) == ("exact", "hinge", 10.0)
    assert study.variant(mode="exact").geometry == "hinge"
    assert study.variant(objective="worst-month").objective.statistic == "worst-month"


def test_version():
    done = subprocess.run([sys.executable, "-m", "foldopt.cli.app", "--version"], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0 and done.stdout.strip() == f"foldopt {foldopt.__version__}"
