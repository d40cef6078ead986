"""Issue 50's example, ``configs/camera-winter.yaml`` (a 2 W camera at 45 N 8 E over PVGIS's
recorded hourly 2020-2021, a LiFePO4 in the cold sized for 24 h on every day of every year, costs
given): its per-year, cold and least-cost lines through every view (the terminal, ``--format
json``, report.html and the API say the same lines and write the same tables), and the same
request with its buffer emptied reduces to the storage-less answer."""

from __future__ import annotations

import html
import json
from pathlib import Path

import pandas as pd
import pytest
from typer.testing import CliRunner

import foldopt
from foldopt.cli.app import app
from foldopt.studies.annual import annual_cases, annual_summary
from foldopt.studies.request import make_request
from foldopt.tables import write_csv
from test_cli_studies import WHOLE_IN_CAMERA_WINTER, assert_a_users_folder, assert_drawn_whole

ROOT = Path(__file__).resolve().parents[1]
STUDY = ROOT / "configs" / "camera-winter.yaml"
#: The lines each part of the issue adds, by the words that open them.
PARTS = ("  worst year: ", "  the cold: charge blocked ", "the cheapest panel and buffer for ")
TABLES = ("storage_annual", "storage_years", "storage_monthly", "design_space")


@pytest.fixture(scope="module")
def views(tmp_path_factory, folders_written_elsewhere, runs_shared):
    """The study through the command line (JSON and terminal) and through the API, one request
    evaluated once (conftest's ``runs_shared``: the API's request, made by
    :func:`foldopt.run` from the file, is the command line's, and is given its result). The
    terminal's folder is the one a user gets, its figures drawn whole (set up before any test's
    own fixtures, it is drawn outside conftest's patch; it stands in test_cli_studies' run of
    every shipped study); the JSON's folder is made, not filled (the terminal's is the same
    answer's); of the API's result the tables the folder holds are written
    (:func:`foldopt.tables.write_csv`, as :func:`foldopt.api.write` writes them)."""
    folder = tmp_path_factory.mktemp("camera-winter")
    runner = CliRunner()
    with runs_shared():
        with folders_written_elsewhere():
            done = runner.invoke(
                app, ["run", str(STUDY), "--out", str(folder / "json"), "--format", "json"]
            )
        assert done.exit_code == 0, done.output
        terminal = runner.invoke(app, ["run", str(STUDY), "--out", str(folder / "cli")])
        assert terminal.exit_code == 0, terminal.output
        result = foldopt.run(STUDY)
    (folder / "api").mkdir()
    for name in TABLES:
        write_csv(result.extras[name], folder / "api" / f"{name}.csv")
    return {
        "terminal": terminal.stdout.splitlines(),
        "json": json.loads(done.stdout)["answer"],
        "api": result,
        "folder": folder,
    }


def test_every_view_says_the_years_the_cold_and_the_least_cost(views):
    lines = views["json"]["lines"]
    for opening in PARTS:
        said = [line for line in lines if line.startswith(opening)]
        assert len(said) == 1, (opening, lines)
        assert said[0] in views["terminal"]
        assert said[0] in views["api"].answer.lines()
        page = (views["folder"] / "cli" / "report.html").read_text(encoding="utf-8")
        assert said[0].strip() in html.unescape(page)
    assert views["api"].answer.lines() == lines
    assert_a_users_folder(views["folder"] / "cli")
    # Drawn whole here, these stand in test_cli_studies' pixels of the weather years' figures.
    for name in WHOLE_IN_CAMERA_WINTER:
        assert_drawn_whole(views["folder"] / "cli" / name)
    # The JSON's parts the lines come from.
    part = views["json"]["result"]
    assert part["storage"]["worst_years"] and part["least_cost"]["least_cost"]


def test_the_command_line_and_the_api_write_the_same_tables(views):
    for name in TABLES:
        cli = (views["folder"] / "cli" / f"{name}.csv").read_bytes()
        assert cli == (views["folder"] / "api" / f"{name}.csv").read_bytes(), name


def test_the_worst_year_and_the_least_cost_hold_against_their_tables(views):
    """The worst year flagged is the year of least mean powered time, for every design; the
    least-cost design of each kind meets the target and is its kind's cheapest meeting row."""
    years = pd.read_csv(views["folder"] / "cli" / "storage_years.csv")
    for _, rows in years.groupby("design"):
        flagged = rows[rows["worst_year"]]
        assert len(flagged) == 1
        assert flagged["powered_mean_h"].iloc[0] == rows["powered_mean_h"].min()
    space = pd.read_csv(views["folder"] / "cli" / "design_space.csv")
    for _, rows in space.groupby("design"):
        least = rows[rows["least_cost"]]
        assert len(least) == 1 and least["meets"].iloc[0]
        assert least["cost_usd"].iloc[0] == rows.loc[rows["meets"], "cost_usd"].min()


def test_an_empty_buffer_is_the_storage_less_answer(tmp_path):
    """A buffer of 0 Wh (the cold and the target kept): each design's powered time is its t_solar,
    day by day, as the storage-less run's annual table gives it. The command line's request
    (``--set``) through the API: the two tables as the folder writes them, without the figures and
    the series nothing here reads."""
    request = make_request(
        "run", STUDY, settings=["storage.capacity_wh=0", "storage.target=null", "costs=null"]
    )
    result = foldopt.run(request=request)
    annual = pd.read_csv(
        write_csv(result.extras["storage_annual"], tmp_path / "storage_annual.csv")
    ).set_index("design")
    assert (annual["powered_mean_h"] == annual["t_solar_mean_h"]).all()
    summary = pd.read_csv(
        write_csv(annual_summary(result.table, annual_cases(result)), tmp_path / "annual_summary.csv")
    )
    flat = summary.loc[summary["design"] == "flat", "t_solar_mean_h"].iloc[0]
    assert annual.loc["flat", "powered_mean_h"] == pytest.approx(flat, abs=1e-12)
