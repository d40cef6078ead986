"""Incidence: exact mode against pvlib, paper Eq. 5 against its own limits."""

import numpy as np
import pvlib
import pytest
from hypothesis import given
from hypothesis import strategies as st

from foldopt.physics.irradiance import beam_incidence_factor
from foldopt.physics.trackers import tracker_orientation


@given(
    tilt=st.floats(0, 180),
    surface_azimuth=st.floats(0, 360),
    zenith=st.floats(0, 89.9),
    solar_azimuth=st.floats(0, 360),
)
def test_exact_factor_is_cosine_of_pvlib_aoi(tilt, surface_azimuth, zenith, solar_azimuth):
    aoi = pvlib.irradiance.aoi(tilt, surface_azimuth, zenith, solar_azimuth)
    expected = max(np.cos(np.radians(aoi)), 0.0)
    factor = beam_incidence_factor(tilt, surface_azimuth, zenith, solar_azimuth, "exact")
    assert factor == pytest.approx(expected, abs=1e-9)


@given(tilt=st.floats(0, 90), zenith=st.floats(0, 89.9), solar_azimuth=st.floats(0, 360))
def test_paper_eq5_is_exact_when_facing_the_sun_azimuth(tilt, zenith, solar_azimuth):
    # PVEducation: a module facing the sun's azimuth receives S sin(elevation + tilt).
    paper = beam_incidence_factor(tilt, solar_azimuth, zenith, solar_azimuth, "paper")
    exact = beam_incidence_factor(tilt, solar_azimuth, zenith, solar_azimuth, "exact")
    assert paper == pytest.approx(exact, abs=1e-9)


def test_paper_eq5_departs_from_exact_off_azimuth():
    # Morning sun in the east, south-facing panel tilted 34 deg: Eq. 5 drops the horizontal
    # component of the beam, so it underestimates (here 0 vs about 0.3).
    paper = beam_incidence_factor(34.0, 180.0, 70.0, 90.0, "paper")
    exact = beam_incidence_factor(34.0, 180.0, 70.0, 90.0, "exact")
    assert paper == pytest.approx(0.0, abs=1e-12)
    assert exact == pytest.approx(np.cos(np.radians(34.0)) * np.cos(np.radians(70.0)), rel=1e-9)


def test_factor_broadcasts_orientations_against_time():
    factor = beam_incidence_factor(
        np.array([10.0, 30.0])[:, None], np.array([150.0, 210.0])[:, None],
        np.linspace(20, 80, 5), np.linspace(100, 260, 5),
    )
    assert factor.shape == (2, 5)
    with pytest.raises(ValueError, match="paper, exact"):
        beam_incidence_factor(0, 0, 0, 0, "perez")


@pytest.mark.parametrize("model", ["exact", "paper"])
def test_ideal_tracker_sees_all_of_the_beam_in_both_modes(model):
    zenith, azimuth = np.array([5.0, 40.0, 85.0]), np.array([100.0, 180.0, 250.0])
    tilt, surface_azimuth, _ = tracker_orientation("dual-axis", zenith, azimuth, np.zeros(3), np.zeros(3), 30.0)
    np.testing.assert_allclose(beam_incidence_factor(tilt, surface_azimuth, zenith, azimuth, model), 1.0, atol=1e-12)
    with pytest.raises(ValueError, match="dual-axis, equatorial, dual-axis-steps, single-axis"):
        tracker_orientation("azimuthal", zenith, azimuth, np.zeros(3), np.zeros(3), 30.0)


def test_day_incidence_by_matrix_product_equals_pvlib(shin_study):
    from foldopt.physics.geometry import subpanel_orientation
    from foldopt.studies.day import Day

    # The beam alone, as the reference has it: exact mode's own sky adds Perez's diffuse light.
    day = Day(shin_study.variant(mode="exact", geometry="hinge", sky="meinel", step_min=10))
    sides = subpanel_orientation(np.array([20.0, 90.0, 180.0]), 34.05, 180.0, "hinge")
    tilt, azimuth = sides["surface_tilt_east"], sides["surface_azimuth_east"]
    expected = day.dni * np.clip(pvlib.irradiance.aoi_projection(
        tilt[:, None], azimuth[:, None], day.solar_zenith, day.solar_azimuth), 0, None)
    np.testing.assert_allclose(day._poa(tilt, azimuth), expected, rtol=1e-12, atol=1e-9)
