"""One default policy for every command (issue 39, item 4): exact mode means Ineichen's clear sky
with Perez diffuse light at the site's Linke turbidity, whichever command asks, and the question
says the whole sky in force.

A sweep of a year's days and a map of the same site ask the same question (the embedded study's
panel, one fold angle all year for the mean daily t_solar): they must give the same answer. The
two commands differ in one default still: a map's year is 2025, a sweep's the embedded study's
2014, which moves the mean t_solar by 6e-4 h, below the answer's 0.01 h. Maps took 5-min steps of
their own until both took the study's; the step moves the best fold angle (Berlin, 2 W: 19 deg at
1-min steps, 20 at 5-min).
"""

from __future__ import annotations

import json

import pandas as pd
import pvlib
import pytest
from typer.testing import CliRunner

import foldopt
from foldopt.cli.app import app
from foldopt.studies.result_answers import study_question

runner = CliRunner()
#: Berlin, a 2 W load: the issue's own example.
BERLIN = ("--lat", "52.5", "--lon", "13.4", "--p-load", "2")
#: What the answers say at their rounding: angles to the degree, t_solar to 0.01 h, gain to 0.1 %.
ANGLES = ("fold_angle_deg", "near_optimal_lo_deg", "near_optimal_hi_deg", "recommended_deg")
#: Exact mode's sky over a year's days (or many sites), as a question says it.
SKY = "Ineichen clear sky at Linke turbidity from pvlib climatology for each site and day, Perez diffuse, albedo 0.2"


def _answer(*args) -> dict:
    shown = runner.invoke(app, [*map(str, args), "--format", "json"])
    assert shown.exit_code == 0, shown.output
    return json.loads(shown.stdout)["answer"]


def sweep_answer(out, *options) -> dict:
    """``foldopt sweep angle`` over the year of one site, as the map's answer reads."""
    answer = _answer("sweep", "angle", *BERLIN, "--days", "year", "--objective", "mean", *options, "--out", out)
    near = answer["near_optimal"][0]
    t_solar = {row["design"]: row["t_solar_mean_h"] for row in answer["designs"]}
    return {**{key: near[key] for key in ANGLES}, **{f"t_solar_{design}_h": t_solar[design]
                                                     for design in ("flat", "twofold", "tracker")},
            "gain_vs_flat_pct": 100 * (t_solar["twofold"] / t_solar["flat"] - 1),
            "models": answer["question"]["models"]}


def map_answer(out, scheduler, *options) -> dict:
    """``foldopt map`` of the one site, its year's row."""
    answer = _answer("map", *BERLIN, "--scheduler", scheduler, *options, "--out", out)
    near, = answer["near_optimal"]
    row, = answer["designs"]
    return {**{key: near[key] for key in ANGLES},
            **{f"t_solar_{design}_h": row[f"t_solar_{design}_mean_h"] for design in ("flat", "twofold", "tracker")},
            "gain_vs_flat_pct": row["gain_vs_flat_pct"], "models": answer["question"]["models"]}


def assert_same_answer(sweep: dict, world: dict) -> None:
    assert {key: sweep[key] for key in ANGLES} == {key: world[key] for key in ANGLES}
    for key in ("t_solar_flat_h", "t_solar_twofold_h", "t_solar_tracker_h"):
        assert sweep[key] == pytest.approx(world[key], abs=0.005), key
    assert sweep["gain_vs_flat_pct"] == pytest.approx(world["gain_vs_flat_pct"], abs=0.05)


def test_a_sweep_and_a_map_of_a_site_agree_at_the_same_step(tmp_path, scheduler, figures_drawn_elsewhere,
                                                           folders_written_elsewhere):
    # Before exact mode had one sky, the sweep ran under the paper's beam-only Meinel sky and the
    # map under Ineichen's: another fold angle, another gain.
    # The paper's ideal PV model in both, as before exact mode's default became PVWatts'.
    # The answers are the point: the sweep's folder is not written (a year's folder is the shipped
    # studies' tests'), the map's figures are PNGs of one pixel, not drawn.
    with folders_written_elsewhere():
        sweep = sweep_answer(tmp_path / "sweep", "--step-min", "5", "--pv-model", "ideal")
    with figures_drawn_elsewhere():
        world = map_answer(tmp_path / "map", scheduler, "--step-min", "5", "--set", "pv_model=ideal")
    assert_same_answer(sweep, world)
    assert sweep["recommended_deg"] == 40 and round(sweep["gain_vs_flat_pct"], 1) == 11.4
    # And both say so: the same sky in their questions.
    for answer in (sweep, world):
        assert answer["models"].startswith("exact mode") and answer["models"].endswith(SKY), answer["models"]


def test_a_sweep_and_a_map_of_a_site_agree_with_no_option(tmp_path, scheduler, figures_drawn_elsewhere,
                                                         folders_written_elsewhere):
    with folders_written_elsewhere():  # the answers are the point, as above
        sweep = sweep_answer(tmp_path / "sweep")
    with figures_drawn_elsewhere():
        world = map_answer(tmp_path / "map", scheduler)
    assert_same_answer(sweep, world)


@pytest.mark.filterwarnings("ignore:DatetimeIndex.dayofyear is deprecated")  # in pvlib's lookup, not ours to fix
def test_the_question_says_the_sky_in_force():
    paper = foldopt.default_study()
    assert study_question(paper)["models"].endswith(", Meinel clear sky, beam only (Shin et al.)")
    berlin = paper.variant(site={"latitude": 52.52, "longitude": 13.40}, date="2025-06-21")
    # pvlib's own lookup of its climatology on the UTC day of the site's solar noon.
    noon = pd.DatetimeIndex([pd.Timestamp("2025-06-21 12:00", tz="UTC") - pd.Timedelta(hours=13.40 / 15)])
    turbidity = float(pvlib.clearsky.lookup_linke_turbidity(noon, 52.52, 13.40).iloc[0])
    assert study_question(berlin)["models"].endswith(
        f", Ineichen clear sky at Linke turbidity {turbidity:.1f} (pvlib climatology for the site and day), "
        "Perez diffuse, albedo 0.2")
    assert study_question(berlin.variant(sky="meinel"))["models"].endswith(", Meinel clear sky, beam only")
    given = berlin.variant(linke_turbidity=2.5, transposition="isotropic", albedo=0.3)
    assert study_question(given)["models"].endswith(
        ", Ineichen clear sky at Linke turbidity 2.5, isotropic diffuse, albedo 0.3")
    # Across sites or days the climatology's turbidity varies: said, not one number.
    across = study_question(berlin, ("site.latitude",))["models"]
    assert "Linke turbidity from pvlib climatology for each site and day" in across
