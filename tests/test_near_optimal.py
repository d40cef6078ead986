"""The near-optimal range of the fold angle and the recommended angle at its centre, against a plain
loop written here (the reference), over random plateaus (hypothesis) and on the paper's study."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import foldopt
from foldopt.inputs.sections import NearOptimal
from foldopt.studies.objectives import near_optimal


def reference(angles, values, fraction, minutes):
    """The plateau by walking out from the best angle (ties to the least folded) one step at a time."""
    best = max(range(len(values)), key=lambda i: (values[i], i))
    tolerance = max(fraction * values[best], minutes / 60.0)
    lo = best
    while lo > 0 and values[lo - 1] >= values[best] - tolerance:
        lo -= 1
    hi = best
    while hi < len(values) - 1 and values[hi + 1] >= values[best] - tolerance:
        hi += 1
    centre = (angles[lo] + angles[hi]) / 2
    recommended = min(range(lo, hi + 1), key=lambda i: (abs(angles[i] - centre), -i))
    return angles[lo], angles[hi], angles[recommended], tolerance


@settings(max_examples=200, deadline=None)
@given(values=st.lists(st.floats(0.0, 14.0), min_size=1, max_size=40), fraction=st.floats(0.0, 0.2),
       minutes=st.floats(0.0, 30.0), step=st.sampled_from([1.0, 2.5, 10.0]))
def test_the_range_is_the_best_angles_plateau(values, fraction, minutes, step):
    angles = 1.0 + step * np.arange(len(values))
    found = near_optimal(angles, np.array(values), NearOptimal(fraction=fraction, minutes=minutes))
    if max(values) <= 0:  # no angle carries the load: no range
        assert np.isnan(found["recommended_fold_angle_deg"])
        return
    lo, hi, recommended, tolerance = reference(angles, values, fraction, minutes)
    assert found["near_optimal_lo_deg"] == lo and found["near_optimal_hi_deg"] == hi
    assert found["recommended_fold_angle_deg"] == recommended
    assert found["near_optimal_tolerance_h"] == pytest.approx(tolerance, rel=1e-12)


def test_rows_are_independent():
    angles = np.arange(1.0, 6.0)
    values = np.array([[1, 2, 5, 2, 1], [5, 5, 5, 5, 5], [0, 0, 0, 0, 0.0]], dtype=float)
    found = near_optimal(angles, values, NearOptimal(fraction=0.0, minutes=0.0))
    assert found["near_optimal_lo_deg"].tolist()[:2] == [3.0, 1.0]
    assert found["recommended_fold_angle_deg"].tolist()[:2] == [3.0, 3.0]
    assert np.isnan(found["near_optimal_lo_deg"][2])


def test_the_papers_plateau_holds_its_optimum_and_the_recommended_angle_keeps_the_tolerance():
    """Shin et al. Fig. 12a: t_solar is flat over a range of fold angles around the optimum."""
    result = foldopt.run(foldopt.default_study())
    near = result.near_optimal
    sweep = result.sweep.set_index("fold_angle_deg")["t_solar_h"]
    assert near["near_optimal_lo_deg"] - 1 <= result.optimal_fold_angle <= near["near_optimal_hi_deg"]
    inside = sweep.loc[near["near_optimal_lo_deg"]:near["near_optimal_hi_deg"]]
    assert (inside >= sweep.max() - near["near_optimal_tolerance_h"]).all()
    # 1 % of the best t_solar (9.44 h: 5.7 min) is more than 1 min here.
    assert near["near_optimal_tolerance_h"] == pytest.approx(0.01 * sweep.max(), rel=1e-12)
    wider = foldopt.run(foldopt.default_study().variant(near_optimal={"fraction": 0.05}))
    assert wider.near_optimal["near_optimal_hi_deg"] >= near["near_optimal_hi_deg"]


@settings(max_examples=40, deadline=None)
@given(values=st.lists(st.floats(0, 12), min_size=3, max_size=40), fraction=st.floats(0, 0.1),
       minutes=st.floats(0, 30))
def test_the_range_on_a_grid_is_the_plain_range_where_every_angle_is_known(values, fraction, minutes):
    """near_optimal_on_grid with every grid angle evaluated has no gap to place an edge in: it is
    near_optimal (the reference loop above), to the bit."""
    from foldopt.studies.objectives import near_optimal_on_grid

    angles = np.arange(1.0, len(values) + 1.0)
    tolerance = NearOptimal(fraction=fraction, minutes=minutes)
    got = near_optimal_on_grid(angles, np.array([values]), tolerance, angles)
    expected = reference(angles, values, fraction, minutes)
    carried = max(values) > 0
    for name, value in zip(("near_optimal_lo_deg", "near_optimal_hi_deg", "recommended_fold_angle_deg",
                            "near_optimal_tolerance_h"), expected, strict=True):
        assert got[name][0] == (value if carried else pytest.approx(np.nan, nan_ok=True))


def test_an_edge_between_evaluated_angles_is_where_the_cubic_meets_the_threshold():
    """A plateau known at a few angles: the range's edges are the last grid angles inside where
    SciPy's pchip through the known values stays above the best less the tolerance."""
    from scipy.interpolate import PchipInterpolator

    from foldopt.studies.objectives import near_optimal_on_grid

    grid = np.arange(1.0, 181.0)
    curve = 10.0 - 1e-4 * (grid - 70.0) ** 2  # a broad plateau around 70 deg
    known = np.array([1.0, 17.0, 33.0, 49.0, 61.0, 65.0, 69.0, 70.0, 71.0, 77.0, 97.0, 129.0, 180.0])
    values = curve[known.astype(int) - 1][None, :]
    tolerance = NearOptimal(fraction=0.01, minutes=0.0)
    got = near_optimal_on_grid(known, values, tolerance, grid)
    above = PchipInterpolator(known, values[0])(grid) >= values.max() - 0.1
    assert got["near_optimal_lo_deg"][0] == grid[above].min() and got["near_optimal_hi_deg"][0] == grid[above].max()
    # The full curve's own range, which the cubic finds here exactly: 70 +- 31.6 deg.
    full = near_optimal(grid, curve[None, :], tolerance)
    assert (got["near_optimal_lo_deg"][0], got["near_optimal_hi_deg"][0]) == (full["near_optimal_lo_deg"][0],
                                                                            full["near_optimal_hi_deg"][0])
