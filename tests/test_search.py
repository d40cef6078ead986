"""The coarse-to-fine search (foldopt.engine.search) against the brute-force grid it replaces: on
functions with known maxima, and on the study's own objective at random sites, days, loads and
objectives (the grid evaluated in full in the test, through the same design evaluation)."""

from __future__ import annotations

import datetime as dt
import functools

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import foldopt
from foldopt.engine.search import Axis, grid_search
from foldopt.inputs.plan import make_plan
from foldopt.engine.evaluation import design_orientations
from foldopt.studies.designs import Blocks, requested_hours
from foldopt.studies.objectives import objective_quantum
from foldopt.studies.objectives import objective_value


def _full_grid(axes):
    return np.stack(np.meshgrid(*[axis.values() for axis in axes], indexing="ij"), axis=-1).reshape(-1, len(axes))


def test_axis_ends_on_its_bound():
    assert list(Axis("a", 1, 10, 4).values()) == [1, 5, 9, 10]
    assert list(Axis("a", 0, 8, 4).values()) == [0, 4, 8]
    assert Axis("a", 3, 3, 1).size == 1


@settings(max_examples=60, deadline=None)
@given(centres=st.lists(st.tuples(st.floats(0, 100), st.floats(0, 60), st.floats(-1, 1)), min_size=1, max_size=4),
       widths=st.lists(st.floats(16, 60), min_size=4, max_size=4), tolerance=st.sampled_from([1e-4, 1e-2]))
def test_sums_of_broad_bumps_match_the_grid(centres, widths, tolerance):
    """Smooth landscapes of up to four bumps (or dips) no narrower than the coarse lattice (its
    spacing along x is 16: a bump of width w falls to exp(-1) at w from its centre): the search's
    best is the grid's within the tolerance."""
    axes = [Axis("x", 0, 100, 1), Axis("y", 0, 60, 2)]

    def bumps(points):
        value = np.zeros(points.shape[0])
        for (cx, cy, height), width in zip(centres, widths, strict=False):
            value += height * np.exp(-(((points[:, 0] - cx) / width) ** 2 + ((points[:, 1] - cy) / width) ** 2))
        return value[:, None]

    result = grid_search(bumps, axes, tolerance)
    brute = bumps(_full_grid(axes)).max()
    assert result.best_value[0] >= brute - tolerance - 1e-12
    assert result.best_value[0] <= brute + 1e-12  # it is a grid point's value


@settings(max_examples=25, deadline=None)
@given(landscapes=st.lists(st.tuples(st.floats(0, 100), st.floats(0, 60), st.floats(2, 40), st.integers(0, 3)),
                           min_size=2, max_size=5),
       two_axes=st.booleans(), quantum=st.sampled_from([0.0, 0.004]))
def test_searches_told_together_evaluate_and_find_what_each_does_alone(landscapes, two_axes, quantum):
    """A map's sites' searches advance together (tell_together: one pass over every search's boxes);
    each evaluates the points, level by level, and finds the best it does on its own, to the bit:
    landscapes of a bump with a kink or plateau beside it, some ending their search early (an
    objective flat at its lattice), of one or two axes and two targets each."""
    from foldopt.engine.search import GridSearch, tell_together

    axes = [Axis("x", 0, 100, 1), *([Axis("y", 0, 60, 2)] if two_axes else [])]

    def landscape(cx, cy, width, kind):
        def values(points):
            x = points[:, 0]
            y = points[:, 1] if two_axes else cy
            bump = np.exp(-(((x - cx) / width) ** 2 + ((y - cy) / width) ** 2))
            second = [bump, np.minimum(bump, 0.5), np.abs(x - cx) * 0.0, -np.abs(x - cx) / width][kind]
            return np.stack([bump, second], axis=1)
        return values

    functions = [landscape(*parameters) for parameters in landscapes]
    alone = []
    for function in functions:
        search = GridSearch(axes, 1e-3, quantum)
        while (points := search.ask()) is not None:
            search.tell(function(points))
        alone.append(search.result())
    searches = [GridSearch(axes, 1e-3, quantum) for _ in functions]
    asked = {k: search.ask() for k, search in enumerate(searches)}
    while asked := {k: points for k, points in asked.items() if points is not None}:
        tell_together([searches[k] for k in asked], [functions[k](points) for k, points in asked.items()])
        asked = {k: searches[k].ask() for k in asked}
    for own, search in zip(alone, searches, strict=True):
        together = search.result()
        assert together.levels == own.levels
        np.testing.assert_array_equal(together.index, own.index)
        np.testing.assert_array_equal(together.values, own.values)
        np.testing.assert_array_equal(together.best, own.best)


def test_it_evaluates_a_small_share_of_a_smooth_3d_grid():
    axes = [Axis("fold", 2, 180, 1), Axis("tilt", 0, 90, 1), Axis("azimuth", 90, 270, 2)]

    def bowl(points):
        return -(((points - [63.3, 31.0, 181.0]) / [40.0, 30.0, 60.0]) ** 2).sum(axis=1, keepdims=True)

    result = grid_search(bowl, axes, 1e-3)
    assert result.best_point[0].tolist() == [63, 31, 182] or result.best_point[0].tolist() == [63, 31, 180]
    assert result.index.shape[0] < 0.01 * result.grid_size


def test_a_seed_keeps_the_best_from_falling_below_it():
    axes = [Axis("x", 0, 64, 1)]

    def spike(points):  # a one-point spike the coarse lattice cannot see
        return np.where(points[:, :1] == 37, 1.0, 0.0)

    assert grid_search(spike, axes, 1e-3).best_value[0] == 0.0  # the argument's stated limit
    assert grid_search(spike, axes, 1e-3, seeds=[[37.0]]).best_value[0] == 1.0


def test_a_kinked_peak_between_lattice_points_is_found():
    """A concave objective with a corner (the shape of a map site's summer objective against the
    fold angle at 65 N: up 0.012 h from 1 to 2 deg, then down 0.01 h a degree): its second
    differences on the coarse lattice are small, the chords beside the first box are not."""
    axes = [Axis("fold_angle", 1, 180, 1)]

    def kinked(points):
        x = points[:, :1]
        return np.where(x < 2, -0.012 * (2 - x), -0.01 * (x - 2))

    result = grid_search(kinked, axes, 0.01)
    assert result.best_value[0] >= 0.0 - 0.01 and result.best_point[0, 0] == 2.0


def test_a_concave_kink_on_a_flank_is_not_refined():
    """A load's objective against the fold angle on the 1-degree land grid (a site at 18 N, 44 E,
    the year's mean at 25 % of its flat peak, 5-min clear-sky steps, fitted: a steep flank, 0.27 h a
    degree, meeting at 18 deg a plateau of curvature 1.4e-4 h/deg^2 that peaks at 37 deg): the
    kink's second differences are large, but the lattice is concave around it and its chords bound
    it below the plateau, so its boxes are dropped (the curvature alone refined 18-23 deg to the
    last degree) and the best stays within the tolerance."""
    axes = [Axis("fold_angle", 1, 180, 1)]

    def flank(points):
        x = points[:, :1]
        return np.where(x <= 18, 9.7037 - 0.27 * (18 - x), 9.729 - 0.00007 * (x - 37) ** 2)

    result = grid_search(flank, axes, 0.01, quantum=0.00023)
    assert result.best_value[0] >= 9.729 - 0.01
    assert not set(range(18, 24)) & set(result.points[:, 0].astype(int).tolist())


#: A site's objective against the fold angle (61 N, 43 W, the JJA mean at 20 % of its flat peak,
#: 5-min clear-sky steps) at 1..40 deg and every 10 deg from 40: 0.054 h a degree up to 12 deg, then
#: 0.43, 0.37 and 0.16 h to a peak at 15 deg, and down ever faster beyond.
NARROW_PEAK = ([*range(1, 41), *range(50, 181, 10)], [
    13.3157, 13.3718, 13.4275, 13.483, 13.5382, 13.5931, 13.6478, 13.7021, 13.7562, 13.81, 13.8635, 13.9168,
    14.3471, 14.7156, 14.8745, 14.8655, 14.854, 14.8423, 14.8304, 14.8182, 14.8059, 14.7932, 14.7804, 14.7674,
    14.7541, 14.7405, 14.7268, 14.7128, 14.6985, 14.6841, 14.6694, 14.6544, 14.6392, 14.6237, 14.608, 14.592,
    14.5757, 14.5592, 14.5425, 14.5254, 14.3391, 14.1227, 13.8739, 13.5909, 13.2735, 12.9207, 12.5331, 12.1127,
    11.662, 11.1843, 10.6831, 10.3933, 10.4083, 10.4133])


def test_a_narrow_peak_behind_a_convex_kink_is_found():
    """:data:`NARROW_PEAK`: the lattice's second differences at the ends of the box that holds the
    peak are negative, but one beside it is not (the convex kink at 12 deg), so the box is not taken
    as concave and its peak is found; bounded by its chords alone, it was missed by 0.020 h."""
    axes = [Axis("fold_angle", 1, 180, 1)]

    def narrow(points):
        return np.interp(points[:, 0], *NARROW_PEAK)[:, None]

    result = grid_search(narrow, axes, 0.01, quantum=0.00023)
    assert result.best_value[0] >= 14.8745 - 0.01


def test_several_targets_each_get_their_own_best():
    axes = [Axis("x", 0, 90, 1)]

    def two(points):
        return np.stack([-(points[:, 0] - 10.0) ** 2, -(points[:, 0] - 70.0) ** 2], axis=-1)

    result = grid_search(two, axes, 1e-6)
    assert result.best_point[:, 0].tolist() == [10, 70]


STEP_MIN = 10.0


def _axes(equator):
    """The fold angle x tilt x azimuth grid searched around the equator's azimuth [deg]."""
    return [Axis("fold_angle", 10, 180, 2), Axis("tilt", 0, 90, 3), Axis("azimuth", equator - 60, equator + 60, 6)]


@functools.cache
def _grid(equator):
    """:func:`_axes`' full grid and its designs' sub-panel orientations, worked out once for each
    azimuth as the design evaluation works them out (:func:`foldopt.studies.designs.requested_hours`;
    one geometry call over the designs), and read by the search's
    points as :func:`foldopt.studies.joint.optimize_plan` reads its grid's."""
    axes = _axes(equator)
    points = _full_grid(axes)
    return axes, points, design_orientations("hinge", points[:, 0], points[:, 1], points[:, 2] % 360.0)


def _objective(latitude, longitude, dates, loads, statistic):
    data = {**foldopt.default_study().data(), "mode": "exact", "sky": "ineichen", "step_min": STEP_MIN,
            "site": {"latitude": latitude, "longitude": longitude}, "geometry": "hinge"}
    study = make_plan(data).base
    blocks = Blocks.of_dates(study, dates)
    parts = [(blocks[part], blocks[part].sky()) for part in blocks.chunks(len(loads))]
    months = np.array([date.month for date in dates])
    axes, _, orientations = _grid(study.panel.azimuth)

    def evaluate(points):
        at = [np.searchsorted(axis.values(), points[:, k]) for k, axis in enumerate(axes)]
        every = np.arange(sum(sky.n_blocks for _, sky in parts))
        chosen = orientations[np.ravel_multi_index(at, [axis.size for axis in axes])]
        hours = requested_hours(parts, [(every, points)], loads, orientations=[chosen])[0][0]
        return objective_value(hours, months, statistic)

    return study, evaluate


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(latitude=st.floats(-55, 55), longitude=st.floats(-170, 170), day=st.integers(1, 330),
       n_days=st.integers(1, 10), loads=st.lists(st.floats(0.5, 15), min_size=1, max_size=2),
       statistic=st.sampled_from(["mean", "min", "p50", "worst-month"]))
def test_the_study_objective_matches_the_brute_force_grid(latitude, longitude, day, n_days, loads, statistic):
    """t_solar of the twofold panel over fold angle x tilt x azimuth at a random site, days, loads
    and objective: the search's best equals the full grid's within the stated tolerance, per load."""
    dates = [dt.date(2025, 1, 1) + dt.timedelta(days=day - 1 + 5 * k) for k in range(n_days)]
    loads = np.asarray(loads)
    study, evaluate = _objective(latitude, longitude, dates, loads, statistic)
    months = np.array([date.month for date in dates])
    axes, points, _ = _grid(study.panel.azimuth)
    result = grid_search(evaluate, axes, 0.01, quantum=objective_quantum(statistic, STEP_MIN / 60, n_days, months))
    brute = evaluate(points).max(axis=0)
    np.testing.assert_array_less(brute - result.best_value, result.tolerance + 1e-9)
    assert np.all(result.best_value <= brute + 1e-9)


@pytest.fixture(scope="session")
def joint():
    return foldopt.optimize(foldopt.default_study(), vary="fold_angle,tilt", mode="exact", step_min=15,
                            fold_angle="10:180:5", tilt="0:90:5", p_load=[2.0, 4.398])


def test_the_twofold_optimum_is_never_below_the_flat_panels(joint):
    """The fold grid holds 180 deg, the flat panel (ideal PV model: identical), and the flat
    panel's search varies the same tilts: the twofold optimum cannot fall below it by more than
    the tolerance, nor below the default mounting's fold-only optimum (on the study's own 1 deg
    grid, the search's is 5 deg)."""
    table = joint.table.set_index(["p_load_w", "design"])["t_solar_objective_h"]
    for load in joint.loads:
        assert table[(load, "twofold")] >= table[(load, "flat")] - 0.01
        assert table[(load, "twofold")] >= table[(load, "twofold-default")] - 0.01
        assert table[(load, "flat")] >= table[(load, "flat-default")] - 1e-12


def test_what_each_variable_adds_sums_to_the_gain_over_the_default_flat(joint):
    table = joint.table.set_index(["p_load_w", "design"])["t_solar_objective_h"]
    for load in joint.loads:
        added = joint.added[joint.added["p_load_w"] == load]["added_h"].sum()
        assert added == pytest.approx(table[(load, "twofold")] - table[(load, "flat-default")], abs=1e-12)


def test_the_near_optimal_region_holds_the_optimum(joint):
    best = joint.table[joint.table["design"] == "twofold"].set_index("p_load_w")
    for row in joint.near_optimal.itertuples():
        value = best.loc[row.p_load_w, {"fold_angle": "fold_angle_deg", "tilt": "surface_tilt"}[row.variable]]
        assert row.near_optimal_lo_deg <= value <= row.near_optimal_hi_deg


def test_the_command_line_and_the_api_give_the_same_answer(tmp_path, joint):
    import json

    from typer.testing import CliRunner

    from foldopt.cli.app import app

    result = CliRunner().invoke(app, ["optimize", "--vary", "fold_angle,tilt", "--mode", "exact", "--step-min", "15",
                                      "--fold-range", "10:180:5", "--tilt-range", "0:90:5", "--p-load", "2,4.398",
                                      "--format", "json", "--out", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    cli = json.loads(result.stdout)["answer"]
    api = json.loads(json.dumps(joint.answer.to_dict()))
    assert cli["result"] == api["result"] and cli["designs"] == api["designs"]
    assert (tmp_path / "out" / "landscape.png").exists()


def test_a_mounting_search_leaves_paper_mode_and_a_fold_search_keeps_it():
    """Shin et al.'s Eq. 5 is the angle of incidence only for a surface facing the sun's azimuth: an
    optimisation that re-tilts or turns the paper's panel runs in exact mode, and says so."""
    from foldopt.studies.request import make_request

    data = foldopt.default_study().data()
    assert data["mode"] == "paper"
    mounting = make_request("optimize", data, optimize={"vary": ["fold_angle", "tilt"]})
    assert mounting.plan.base.mode == "exact" and any("Eq. 5" in item for item in mounting.taken)
    fold = make_request("optimize", data, optimize={"vary": ["fold_angle"]})
    assert fold.plan.base.mode == "paper"
    kept = make_request("optimize", data, optimize={"vary": ["tilt"]}, fields={"mode": "paper"})
    assert kept.plan.base.mode == "paper"


def test_a_weather_year_with_a_load_profile_is_optimised():
    """A TMY3 year and a camera's day/night profile, judged by the worst month: the optimum holds
    its fold angle and tilt, never below the flat panel at its own best, and says the load is the
    profile's scale."""
    from pathlib import Path

    weather = Path(__file__).resolve().parent.parent / "configs" / "weather" / "723170TYA.CSV"
    result = foldopt.optimize(foldopt.default_study(), vary="fold_angle,tilt", weather=str(weather), step_min=30,
                              panel={"area": 0.3}, objective="worst-month",
                              load_profile={"daily": {"00:00": 1.5, "07:00": 6, "19:00": 1.5}})
    table = result.table.set_index("design")["t_solar_objective_h"]
    assert table["twofold"] >= table["flat"] - 0.01 and table["twofold"] >= table["flat-default"] - 1e-12
    assert len(result.dates) == 365 and result.statistic == "worst-month"
    assert result.answer.summary[1].startswith("load profile x 1:")
