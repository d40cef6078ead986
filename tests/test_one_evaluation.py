"""A day's study evaluates each design once (issue 39, item 2): every tracker model, the heuristic's
angle and each connection's refined angle; the figures draw the curves the table was reduced from.
A map evaluates its flat panel once."""

import numpy as np

from foldopt.api import load_study
from foldopt.engine import evaluation as engines
from foldopt.names import TRACKERS
from foldopt.studies import designs
from foldopt.studies.day import run_study
from foldopt.studies.map_request import map_study
from foldopt.studies.worldmap import evaluate_sites


def _recorded(monkeypatch, module, name):
    """The arguments of every call of ``module.name`` from now on."""
    calls, original = [], getattr(module, name)

    def recording(*args, **kwargs):
        calls.append((args, kwargs))
        return original(*args, **kwargs)

    monkeypatch.setattr(module, name, recording)
    return calls


def test_each_tracker_model_is_evaluated_once(monkeypatch, shin_study):
    """The study's tracker was evaluated by Day and again by design_metrics (its draw three times)."""
    orientations = _recorded(monkeypatch, designs, "sky_tracker_orientation")
    draws = _recorded(monkeypatch, designs, "sky_tracker_draw")
    result = run_study(shin_study)
    assert len(orientations) == len(draws) == len(TRACKERS)
    # The tracker curve the figures draw is the one the table's row was reduced from.
    curve = engines.curve_metrics(result.timeseries["p_tracker_w"].to_numpy()[None], [shin_study.p_load],
                                  result.day.step_hours, contiguous=True)
    row = result.summary.set_index("design").loc["tracker"]
    assert (curve.t_solar[0, 0, 0], curve.energy[0, 0]) == (row["t_solar_h"], row["energy_harvested_wh"])


def test_no_angle_is_evaluated_twice(monkeypatch):
    """No single fold angle's curves are worked out twice with the same connections: the heuristic's
    bracket and angle, and each other connection's refined angle, were (an I-V model's study)."""
    study = load_study("configs/shin2015-single-diode.yaml")
    calls = _recorded(monkeypatch, engines, "powers")
    # The kernel's rows (the NumPy reference path's rows call powers too, a day's auto engine).
    result = run_study(study, "numba")
    assert {"twofold-heuristic", "twofold-parallel", "twofold-series"} <= set(result.summary["design"])
    seen = set()
    for _, kwargs in calls:
        orientation = np.asarray(kwargs["orientation"])
        series, state = kwargs.get("series", True), kwargs.get("with_state", False)
        rows = {(row.tobytes(), series, state) for row in orientation}
        if len(orientation) == 1:
            assert not rows & seen, "one fold angle's curves worked out twice"
        seen |= rows


def test_a_map_evaluates_its_flat_panel_once(monkeypatch):
    """A map in watts took its flat peak from a pass of its own, then evaluated the flat panel
    again with the loads (site_designs); its rows' flat peak is now that pass's."""
    study = map_study({"name": "coarse", "panel": {"area": 0.108, "efficiency": 0.1905}, "p_load": 2.0,
                       "pv_model": "ideal"}, fold_angles={"start": 10, "stop": 180, "step": 10}, step_min=30.0)
    calls = _recorded(monkeypatch, engines, "row_metrics")
    table = evaluate_sites(study, [{"latitude": 34.05, "longitude": -118.25}], [1.0, 4.0])
    flat = [kwargs for _, kwargs in calls if kwargs.get("outputs") == ("panel",)]
    assert len(flat) == 1
    assert table["peak_power_flat_w"].gt(0).all()


def test_the_figures_draw_the_curves_the_table_was_reduced_from(shin_study):
    """The time series' flat and twofold curves (the figures') were the reference path's while the
    table's rows were the kernel's: each row's metrics are now those of its drawn curve."""
    result = run_study(shin_study)
    series, row = result.timeseries, result.summary.set_index("design")
    span = result.day.sky.kernel_layout(False)[4]
    for design, column in (("flat", "p_flat_w"), ("twofold", "p_twofold_w")):
        curve = engines.curve_metrics(series[column].to_numpy()[None], [shin_study.p_load], result.day.step_hours,
                                      contiguous=True, span=span)
        assert (curve.t_solar[0, 0, 0], curve.energy[0, 0], curve.peak[0, 0]) == (
            row.loc[design, "t_solar_h"], row.loc[design, "energy_harvested_wh"], row.loc[design, "peak_power_w"])
