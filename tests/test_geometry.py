"""Sub-panel orientation: identities of both twofold parametrisations."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from foldopt.inputs.sections import default_orientation
from foldopt.physics.geometry import normal_vector, subpanel_orientation

tilts = st.floats(0, 90)
azimuths = st.floats(0, 359.999)
folds = st.floats(1, 180)


@pytest.mark.parametrize("geometry", ["hinge", "azimuth-split"])
@given(tilt=tilts, azimuth=azimuths)
def test_fold_of_180_is_the_flat_panel(geometry, tilt, azimuth):
    sides = subpanel_orientation(180.0, tilt, azimuth, geometry)
    flat = normal_vector(tilt, azimuth)
    for side in ("east", "west"):
        normal = normal_vector(sides[f"surface_tilt_{side}"], sides[f"surface_azimuth_{side}"])
        np.testing.assert_allclose(normal, flat, atol=1e-12)


@given(fold=folds, tilt=tilts, azimuth=azimuths)
def test_hinge_normals_open_by_180_minus_fold_symmetrically(fold, tilt, azimuth):
    sides = subpanel_orientation(fold, tilt, azimuth, "hinge")
    east = normal_vector(sides["surface_tilt_east"], sides["surface_azimuth_east"])
    west = normal_vector(sides["surface_tilt_west"], sides["surface_azimuth_west"])
    flat = normal_vector(tilt, azimuth)
    between = np.degrees(np.arctan2(np.linalg.norm(np.cross(east, west)), east @ west))
    assert between == pytest.approx(180.0 - fold, abs=1e-6)
    # Each half turns by the same amount about the fold line, which lies in the flat panel plane.
    assert east @ flat == pytest.approx(west @ flat, abs=1e-9)
    np.testing.assert_allclose(np.cross(east, west) @ flat, 0.0, atol=1e-9)


# Tilt from 0.5 deg: at zero tilt the azimuth-split panel is degenerate (both halves horizontal).
@given(fold=st.floats(1, 179), tilt=st.floats(0.5, 89), latitude=st.floats(-89, 89))
def test_east_sub_panel_faces_east_on_both_hemispheres(fold, tilt, latitude):
    _, azimuth = default_orientation(latitude)
    for geometry in ("hinge", "azimuth-split"):
        sides = subpanel_orientation(fold, tilt, azimuth, geometry)
        east = normal_vector(sides["surface_tilt_east"], sides["surface_azimuth_east"])
        west = normal_vector(sides["surface_tilt_west"], sides["surface_azimuth_west"])
        assert east[0] > west[0]


def test_paper_fig6_azimuths():
    # Shin et al. Sec. IV-B: a 90 deg fold at azimuth 180 gives sub-panels facing 135 and 225 deg.
    sides = subpanel_orientation(90.0, 34.05, 180.0, "azimuth-split")
    assert sides["surface_azimuth_east"] == pytest.approx(135.0)
    assert sides["surface_azimuth_west"] == pytest.approx(225.0)
    assert sides["surface_tilt_east"] == sides["surface_tilt_west"] == pytest.approx(34.05)


def test_hinge_at_zero_tilt_is_a_ridge_tent():
    sides = subpanel_orientation(90.0, 0.0, 180.0, "hinge")
    assert sides["surface_tilt_east"] == pytest.approx(45.0)
    assert sides["surface_azimuth_east"] == pytest.approx(90.0)
    assert sides["surface_tilt_west"] == pytest.approx(45.0)
    assert sides["surface_azimuth_west"] == pytest.approx(270.0)


def test_vectorised_over_fold_angles_and_default_orientation():
    sides = subpanel_orientation(np.array([30.0, 90.0, 180.0]), 34.0, 180.0, "hinge")
    assert sides["surface_tilt_east"].shape == (3,)
    assert default_orientation(34.05) == (34.05, 180.0)
    assert default_orientation(-33.9) == (33.9, 0.0)
    with pytest.raises(ValueError, match="azimuth-split, hinge"):
        subpanel_orientation(90.0, 30.0, 180.0, "tent")
