"""Two planes as they stand (issue 51, item 2): the twofold panel that makes an existing array's
two planes (foldopt.physics.geometry.fold_from_planes, the inverse of subpanel_orientation), its
refusals, and the design evaluated beside the best fold by every path."""

import json
import math

import numpy as np
import pvlib
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

import foldopt
from foldopt.cli.app import app
from foldopt.inputs.sections import PLANES_TOLERANCE_DEG
from foldopt.physics.geometry import fold_from_planes, normal_vector, subpanel_orientation
from foldopt.studies.day import Day
from foldopt.studies.designs import PLANES_DESIGN
from foldopt.studies.request import make_request

runner = CliRunner()
GEOMETRIES = ("hinge", "azimuth-split")
#: A quick day: the issue's roofs on the embedded study's site and day, 10-min steps.
QUICK = ["--step-min", "10", "--angle-step", "2"]


def _between(a, b):
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1)))


def _halves(fold, tilt, azimuth, geometry):
    sides = subpanel_orientation(fold, tilt, azimuth, geometry)
    return [
        (float(sides[f"surface_tilt_{side}"]), float(sides[f"surface_azimuth_{side}"]))
        for side in ("east", "west")
    ]


# --- the inverse against the forward function ---------------------------------------------------


@pytest.mark.parametrize("geometry", GEOMETRIES)
@settings(max_examples=300, deadline=None)
@given(
    fold=st.floats(0.5, 180),
    tilt=st.floats(0, 90),
    azimuth=st.floats(0, 359.999),
    swap=st.booleans(),
)
def test_the_planes_a_panel_makes_give_that_panel_back(geometry, fold, tilt, azimuth, swap):
    """forward -> inverse -> forward: the planes come back within 1e-9 deg, in either order; where
    they are two (not a flat panel, nor an azimuth-split panel lying level, whose halves are one
    plane whatever the fold) the east half is the forward function's and the fold angle the
    panel's to 1e-9 deg. A base facing due east or west is the east-half convention's tie
    (``geometry._east_sign``: the sign of cos(azimuth)), which the base found back decides by its
    last bit (90.00000000000001 deg from planes given west first): there the planes come back
    as a pair, whichever half is named east."""
    east, west = _halves(fold, tilt, azimuth, geometry)
    first, second = (west, east) if swap else (east, west)
    panel = fold_from_planes(*first, *second, geometry=geometry)
    assert panel["residual"] <= 1e-9
    again = _halves(panel["fold_angle"], panel["surface_tilt"], panel["surface_azimuth"], geometry)
    tie = abs(math.cos(math.radians(azimuth))) < 1e-9
    if tie and _between(normal_vector(*east), normal_vector(*again[0])) > 1e-9:
        again = again[::-1]
    for given_plane, made in zip((east, west), again, strict=True):
        assert _between(normal_vector(*given_plane), normal_vector(*made)) <= 1e-9
    if _between(normal_vector(*east), normal_vector(*west)) > 1e-6:  # two planes, not one
        if not tie:
            assert bool(panel["first_east"]) is (not swap)
        assert float(panel["fold_angle"]) == pytest.approx(fold, abs=1e-9)


@settings(max_examples=300, deadline=None)
@given(fold=st.floats(1, 179), tilt=st.floats(0.01, 90), azimuth=st.floats(0, 359.999))
def test_a_hinge_panel_above_level_is_found_as_it_was(fold, tilt, azimuth):
    """Away from the level base (where a ridge's two ends make the same planes) the hinge's base
    is unique: tilt and azimuth come back as they were."""
    east, west = _halves(fold, tilt, azimuth, "hinge")
    panel = fold_from_planes(*east, *west)
    assert float(panel["surface_tilt"]) == pytest.approx(tilt, abs=1e-7)
    turn = (float(panel["surface_azimuth"]) - azimuth + 180.0) % 360.0 - 180.0
    assert turn == pytest.approx(0.0, abs=1e-6)


@given(tilt_1=st.floats(0, 90), azimuth_1=st.floats(0, 359.999), tilt_2=st.floats(0, 90),
       azimuth_2=st.floats(0, 359.999))
def test_any_two_planes_give_a_panel_and_its_miss(tilt_1, azimuth_1, tilt_2, azimuth_2):
    """Planes of one tilt are made exactly by the hinge (unless they face opposite ways); for
    others the miss is at least half the tilts' difference (both halves share a tilt)."""
    panel = fold_from_planes(tilt_1, azimuth_1, tilt_2, azimuth_2)
    if float(panel["fold_angle"]) == 0.0:
        assert math.isnan(panel["residual"])
        return
    assert 0.0 < float(panel["fold_angle"]) <= 180.0
    assert float(panel["residual"]) >= abs(tilt_1 - tilt_2) / 2.0 - 1e-9


def test_the_issues_roofs_are_a_ridge_tent_folded_to_162_deg():
    """By hand: two 9 deg roofs facing 14 and 194 deg have normals 18 deg apart (fold 180 - 18),
    mirror images about the vertical (a level base), the ridge between them along 104 deg. The
    roof facing 14 deg (north-north-east) takes the morning sun: the east half."""
    for first, second, east_first in (((9, 14), (9, 194), True), ((9, 194), (9, 14), False)):
        panel = fold_from_planes(*first, *second)
        assert float(panel["fold_angle"]) == pytest.approx(162.0, abs=1e-12)
        assert float(panel["surface_tilt"]) == 0.0
        assert float(panel["surface_azimuth"]) == pytest.approx(104.0, abs=1e-12)
        assert bool(panel["first_east"]) is east_first
    # no azimuth-split panel: its halves would be folded shut (azimuths 180 deg apart)
    assert float(fold_from_planes(9, 14, 9, 194, "azimuth-split")["fold_angle"]) == 0.0


def test_the_papers_fig6_halves_in_both_geometries():
    """By hand: halves of tilt 30 facing 135 and 225 deg. Azimuth-split: base 30/180 folded to
    90 (Shin et al. Fig. 6). Hinge: the normals (+-s/sqrt2, -s/sqrt2, c) with s = 1/2,
    c = sqrt(3)/2 have dot 3/4, so fold = 180 - arccos(3/4); their bisector (0, -1/sqrt2, sqrt3)
    has tilt atan(1/sqrt6), azimuth 180."""
    split = fold_from_planes(30, 135, 30, 225, "azimuth-split")
    assert [float(split[k]) for k in ("surface_tilt", "surface_azimuth", "fold_angle")] == \
        pytest.approx([30.0, 180.0, 90.0], abs=1e-12)
    hinge = fold_from_planes(30, 225, 30, 135, "hinge")
    assert float(hinge["fold_angle"]) == pytest.approx(180.0 - math.degrees(math.acos(0.75)), abs=1e-12)
    assert float(hinge["surface_tilt"]) == pytest.approx(math.degrees(math.atan(1 / math.sqrt(6))), abs=1e-12)
    assert float(hinge["surface_azimuth"]) == pytest.approx(180.0, abs=1e-12)
    assert not hinge["first_east"]  # the second plane, facing 135 deg (south-east), is the east half


@pytest.mark.parametrize("geometry", GEOMETRIES)
def test_parallel_planes_are_the_flat_panel_and_opposite_ones_no_panel(geometry):
    for plane in ((20, 180), (0, 14), (90, 270)):
        flat = fold_from_planes(*plane, *plane, geometry=geometry)
        assert float(flat["fold_angle"]) == 180.0 and float(flat["residual"]) == 0.0
        assert (float(flat["surface_tilt"]), float(flat["surface_azimuth"])) == pytest.approx(plane)
    shut = fold_from_planes(90, 0, 90, 180, geometry=geometry)
    assert float(shut["fold_angle"]) == 0.0 and math.isnan(shut["residual"])


def test_arrays_in_arrays_out():
    tilts = np.array([[9.0, 30.0], [20.0, 0.0]])
    panel = fold_from_planes(tilts, [[14.0, 135.0], [180.0, 0.0]], tilts, [[194.0, 225.0], [180.0, 0.0]])
    assert panel["fold_angle"].shape == (2, 2)
    np.testing.assert_allclose(panel["fold_angle"], [[162.0, 180 - math.degrees(math.acos(0.75))],
                                                     [180.0, 180.0]], atol=1e-12)


# --- the study: the base it decides, and its refusals ---------------------------------------------


def _study(*settings_):
    return make_request("sweep angle", settings=list(settings_)).plan.base


def test_the_study_runs_at_the_base_the_planes_make():
    study = _study("panel.planes=[[9, 14], [9, 194]]", "step_min=10")
    # the embedded paper-mode study leaves paper mode (Eq. 5 is no angle of incidence for them)
    assert (study.mode, study.geometry) == ("exact", "hinge")
    assert (study.panel.tilt, study.panel.azimuth) == (0.0, 104.0)
    assert {"panel.tilt", "panel.azimuth"} <= set(study.decided)  # decided, not given
    assert study.planes_design() == {"fold_angle": pytest.approx(162.0, abs=1e-12), "first_east": True}
    # the day's sub-panels at that fold are the planes given
    halves = Day(study).orientation([study.planes_design()["fold_angle"]])[0]
    np.testing.assert_allclose(halves, [9.0, 14.0, 9.0, 194.0], atol=1e-9)
    # a ridge's other end makes the same planes: a given azimuth of 284 deg is kept
    other_end = _study("panel.planes=[[9, 14], [9, 194]]", "panel.azimuth=284")
    assert (other_end.panel.tilt, other_end.panel.azimuth) == (0.0, 284.0)
    # paper mode with its azimuth-split geometry makes planes of one tilt whose azimuths differ by less
    # than 180 deg
    paper = _study("panel.planes=[[34.05, 135], [34.05, 225]]", "mode=paper")
    assert (paper.mode, paper.geometry, paper.panel.tilt, paper.panel.azimuth) == \
        ("paper", "azimuth-split", 34.05, 180.0)
    assert paper.planes_design()["fold_angle"] == pytest.approx(90.0)


@pytest.mark.parametrize(
    ("settings_", "words"),
    [
        (["panel.planes=[[9, 14]]"], "panel.planes = [[9, 14]]: expected two [surface_tilt, surface_azimuth]"),
        (["panel.planes=[[9, 14], [9, 194], [9, 0]]"], "expected two [surface_tilt"),
        (["panel.planes=[[9, 14, 3], [9, 194]]"], "expected two [surface_tilt"),
        (["panel.planes=[[9, a], [9, 194]]"], "expected two [surface_tilt"),
        (["panel.planes=[[true, 14], [9, 194]]"], "panel.planes"),
        (["panel.planes=[[9, 14], [95, 194]]"], "plane 2's tilt 95 must be in [0, 90] deg"),
        (["panel.planes=[[-1, 14], [9, 194]]"], "plane 1's tilt -1 must be in [0, 90] deg"),
        (["panel.planes=[[9, 360], [9, 194]]"], "plane 1's azimuth 360 must be in [0, 360) deg"),
        (["panel.planes=[[9, 14], [9, -5]]"], "plane 2's azimuth -5 must be in [0, 360) deg"),
        (["panel.planes=[[9, 14], [12, 194]]"],
         f"panel.planes: no hinge panel makes them within {PLANES_TOLERANCE_DEG:g} deg: tilts 9 and 12 deg differ"),
        (["panel.planes=[[90, 0], [90, 180]]"], "the halves face opposite ways"),
        (["panel.planes=[[9, 14], [9, 194]]", "geometry=azimuth-split"],
         "no azimuth-split panel makes them within 0.1 deg: azimuths 180 deg apart would be an azimuth-split "
         "panel folded shut (0 deg); the hinge geometry makes them (base tilt 0, azimuth 104, fold 162 deg)"),
        (["panel.planes=[[9, 14], [9, 194]]", "panel.tilt=5"], "not of the given tilt 5 deg; leave the tilt out"),
        (["panel.planes=[[9, 14], [9, 194]]", "panel.azimuth=180"], "not of the given azimuth 180 deg"),
        (["panel.planes=[[9, 14], [9, 194]]", "panel.tilt=0", "panel.azimuth=280"],
         "not of the given azimuth 280 deg; leave the azimuth out"),
        (["panel.planes=[[9, 14], [9, 194]]", "panel.tilt=5", "panel.azimuth=200"],
         "not of the given tilt 5 deg and azimuth 200 deg; leave the tilt and azimuth out"),
    ],
)
def test_planes_no_twofold_panel_makes_are_refused_in_one_line(settings_, words):
    with pytest.raises(foldopt.ConfigError) as error:
        _study(*settings_)
    assert len(error.value.errors) == 1, error.value.errors
    assert error.value.errors[0].startswith("panel.planes")
    assert words in error.value.errors[0]


def test_a_study_file_with_planes_and_a_tilt_that_disagree_is_refused(tmp_path):
    path = tmp_path / "roofs.yaml"
    path.write_text("name: roofs\nsite: {latitude: 47, longitude: 8}\ndate: 2025-06-21\np_load: 2\n"
                    "panel: {area: 0.5, tilt: 20, azimuth: 104, planes: [[9, 14], [9, 194]]}\n")
    with pytest.raises(foldopt.ConfigError, match=r"^panel.planes: the planes are a hinge panel of base tilt 0"):
        foldopt.load_study(path)
    path.write_text(path.read_text().replace("tilt: 20", "tilt: 0"))
    assert foldopt.load_study(path).planes_design()["fold_angle"] == pytest.approx(162.0)


# --- the design as it stands, beside the best fold ----------------------------------------------


@pytest.fixture(scope="module")
def roofs():
    """The issue's roofs on the embedded study's day (exact mode, ideal PV model, switching): the
    geometry checked against pvlib's plane-of-array irradiance times the ideal model's efficiency."""
    return foldopt.sweep(foldopt.default_study(), "angle", planes=[[9, 14], [9, 194]], step_min=10,
                         fold_angles={"start": 2, "stop": 180, "step": 2}, pv_model="ideal")


def test_the_planes_design_is_the_two_given_planes_under_pvlibs_sky(roofs):
    """Independent: each half's power is efficiency x half the area x pvlib's plane-of-array
    irradiance on the given plane (the ideal model), the row's energy their switched sum's."""
    study, day = roofs.study, roofs.day
    fold = study.planes_design()["fold_angle"]
    east, west, _ = day.subpanel_power([fold])
    for power, (tilt, azimuth) in ((east[0], (9, 14)), (west[0], (9, 194))):
        poa = pvlib.irradiance.get_total_irradiance(
            tilt, azimuth, day.solar_zenith, day.solar_azimuth, day.dni, day.ghi, day.dhi,
            dni_extra=pvlib.irradiance.get_extra_radiation(day.times.day_of_year),
            airmass=np.nan_to_num(pvlib.atmosphere.get_relative_airmass(np.minimum(day.solar_zenith, 90.0))),
            albedo=study.albedo, model="perez",
        )["poa_global"]
        expected = study.panel.efficiency * study.panel.area / 2 * np.nan_to_num(np.asarray(poa))
        np.testing.assert_allclose(power, expected, rtol=1e-9, atol=1e-9)
    row = roofs.summary.set_index("design").loc[PLANES_DESIGN]
    # switching an ideal model's halves: both in parallel, energy is their sum over the day
    assert row["energy_harvested_wh"] == pytest.approx(float((east[0] + west[0]).sum() * day.step_hours), rel=1e-9)
    # 162 deg is on the grid: the sweep's own t_solar there, by the engine's path
    swept = roofs.sweep.set_index("fold_angle_deg").loc[162.0]
    assert row["t_solar_h"] == pytest.approx(swept["t_solar_h"], abs=1e-9)
    assert row["energy_harvested_wh"] == pytest.approx(swept["energy_harvested_wh"], rel=1e-9)


def test_the_answer_holds_the_planes_design_beside_the_best_fold(roofs):
    answer = roofs.answer
    part = answer.result["planes"]
    assert part["plane_east"] == [9.0, 14.0] and part["plane_west"] == [9.0, 194.0]
    assert (part["surface_tilt"], part["surface_azimuth"], part["geometry"]) == (0.0, 104.0, "hinge")
    assert part["fold_angle_deg"] == pytest.approx(162.0)
    row = roofs.summary.set_index("design").loc[PLANES_DESIGN]
    assert part["t_solar_h"] == row["t_solar_h"] and part["energy_harvested_wh"] == row["energy_harvested_wh"]
    assert part["t_solar_h"] <= answer.result["t_solar_h"] + 1e-12  # the best fold is at least as long
    line = next(line for line in answer.lines() if line.startswith("the planes as they stand"))
    assert "9/14 east, 9/194 west" in line and "hinge folded to 162.0 deg" in line
    assert PLANES_DESIGN in set(answer.designs["design"])
    assert "the base of the planes 9/14, 9/194" in answer.question["panel"]
    json.dumps(answer.to_dict())  # JSON-ready


def test_the_command_line_and_the_api_give_one_answer_to_the_bit(tmp_path):
    result = runner.invoke(app, ["sweep", "angle", "--planes", "9/14,9/194", *QUICK, "--format", "json",
                                 "--out", str(tmp_path / "cli")])
    assert result.exit_code == 0, result.output
    cli = json.loads(result.stdout)["answer"]
    api = foldopt.sweep(foldopt.default_study(), "angle", planes=[[9, 14], [9, 194]], step_min=10,
                        fold_angles={"start": 2, "stop": 180, "step": 2})
    assert cli["result"] == json.loads(json.dumps(api.answer.to_dict()))["result"]
    assert cli["designs"] == json.loads(json.dumps(api.answer.to_dict()))["designs"]
    report = (tmp_path / "cli" / "report.html").read_text()
    assert "the planes as they stand" in report and PLANES_DESIGN in report


def test_one_fold_angle_is_the_one_angle_grid_to_the_bit(tmp_path):
    answers = []
    for index, args in enumerate((["--fold-angle", "162"],
                                  ["--set", "fold_angles={start: 162, stop: 162, step: 1}"])):
        result = runner.invoke(app, ["sweep", "angle", "--step-min", "10", *args, "--format", "json",
                                     "--out", str(tmp_path / str(index))])
        assert result.exit_code == 0, result.output
        answers.append(json.loads(result.stdout)["answer"])
    assert answers[0]["result"] == answers[1]["result"] and answers[0]["designs"] == answers[1]["designs"]
    assert answers[0]["result"]["fold_angle_deg"] == 162.0
    keyword = foldopt.sweep(foldopt.default_study(), "angle", fold_angle=162, step_min=10)
    assert json.loads(json.dumps(keyword.answer.to_dict()))["result"] == answers[0]["result"]


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["sweep", "angle", "--planes", "9/14"], "--planes = '9/14': expected two planes TILT/AZIMUTH,TILT/AZIMUTH"),
        (["sweep", "angle", "--planes", "9/14,9/194,9/0"], "expected two planes"),
        (["sweep", "angle", "--planes", "9,14"], "expected two planes"),
        (["sweep", "angle", "--planes", "nine/14,9/194"], "expected two planes"),
        (["sweep", "angle", "--planes", "9/14,91/194"], "plane 2's tilt 91 must be in [0, 90] deg"),
        (["sweep", "angle", "--planes", "9/400,9/194"], "plane 1's azimuth 400 must be in [0, 360) deg"),
        (["sweep", "angle", "--planes", "9/14,12/194"], "--planes: no hinge panel makes them"),
        (["sweep", "angle", "--planes", "9/14,9/194", "--geometry", "azimuth-split"],
         "the hinge geometry makes them"),
        (["sweep", "angle", "--planes", "9/14,9/194", "--tilt", "30"], "not of the given tilt 30 deg"),
        (["sweep", "angle", "--planes", "9/14,9/194", "--set", "panel.planes=[[9, 14], [9, 194]]"],
         "given twice"),
        (["sweep", "day", "--planes", "9/14,9/194"], "--planes: foldopt sweep day"),
        (["sweep", "latitude", "--planes", "9/14,9/194"], "--planes: foldopt sweep latitude"),
        (["optimize", "--planes", "9/14,9/194"], "--planes: foldopt optimize"),
        (["sweep", "angle", "--fold-angle", "0"], "--fold-angle = 0.0: must be one fold angle in (0, 180] deg"),
        (["sweep", "angle", "--fold-angle", "181"], "must be one fold angle in (0, 180] deg"),
        (["sweep", "angle", "--fold-angle", "90", "--angle-step", "2"], "--fold-angle / --angle-step"),
        (["optimize", "--fold-angle", "90"], "--fold-angle: foldopt optimize searches the mounting"),
    ],
)
def test_bad_input_is_one_line_exit_2_nothing_written(tmp_path, args, words):
    out = tmp_path / "out"
    result = runner.invoke(app, [*args, "--out", str(out)])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), lines
    assert words in lines[0], lines[0]
    assert "Traceback" not in result.output
    assert not out.exists()


def test_an_api_keyword_out_of_range_is_one_line():
    for value in (0, 200, "x", True):
        with pytest.raises(foldopt.ConfigError) as error:
            foldopt.sweep(foldopt.default_study(), "angle", fold_angle=value)
        assert error.value.errors == [f"fold_angle = {value!r}: must be one fold angle in (0, 180] deg"]
    with pytest.raises(foldopt.ConfigError, match=r"^planes: foldopt sweep day"):
        foldopt.sweep(foldopt.default_study(), "day", planes=[[9, 14], [9, 194]], date=["2014-09-23"])


def test_planes_given_to_a_run_of_many_days_say_the_design_to_give_instead():
    with pytest.raises(foldopt.ConfigError) as error:
        make_request("sweep day", settings=["panel.planes=[[9, 14], [9, 194]]"])
    assert "--tilt, --azimuth, --fold-angle" in error.value.errors[0]


def test_over_the_days_of_an_objective_the_planes_are_the_one_angle_design_they_make():
    """An annual run: the planes' row is the twofold panel pinned at their base and fold angle (the
    refusal elsewhere says to give exactly that), by another path (design_metrics)."""
    days = {"date": "2025-03-01:2025-09-30:30", "objective": "worst-month", "p_load": [1.0, 3.0],
            "step_min": 30, "site.latitude": 47.0, "site.longitude": 8.0}
    planes = foldopt.run(request=make_request("sweep day", fields={**days, "planes": [[9, 14], [9, 194]]}))
    pinned = foldopt.run(request=make_request("sweep day", fields={**days, "tilt": 0.0, "azimuth": 104.0,
                                                                   "fold_angle": 162.0, "mode": "exact"}))
    table = planes.extras["annual_objective"].set_index(["p_load_w", "design"])
    same = pinned.extras["annual_objective"].set_index(["p_load_w", "design"])
    for load in (1.0, 3.0):
        row, twofold = table.loc[(load, PLANES_DESIGN)], same.loc[(load, "twofold")]
        assert row["fold_angle_deg"] == pytest.approx(162.0)
        for column in ("t_solar_objective_h", "t_solar_mean_h"):
            assert row[column] == pytest.approx(twofold[column], abs=1e-9)
        assert row["worst_month"] == twofold["worst_month"]
        # the flat panel at the planes' base is the pinned study's flat panel
        assert table.loc[(load, "flat"), "t_solar_objective_h"] == same.loc[(load, "flat"), "t_solar_objective_h"]
    part = planes.answer.result["planes"]
    assert [case["p_load_w"] for case in part["per_case"]] == [1.0, 3.0]
    assert part["fold_angle_deg"] == pytest.approx(162.0)
    assert sum(line.count("the planes as they stand") for line in planes.answer.lines()) == 2
    assert PLANES_DESIGN in set(planes.answer.designs["design"])
