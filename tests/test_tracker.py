"""Trackers as built: the step law, single-axis against pvlib, tracker energy, and Hottel's sky."""

import numpy as np
import pvlib
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from foldopt.physics.atmosphere import extraterrestrial_normal, hottel_transmittance
from foldopt.inputs.study_file import default_study_path
from foldopt.api import load_study
from foldopt.engine.metrics import t_solar
from foldopt.studies.day import Day
from foldopt.physics.trackers import (
    ALEXANDRU_STEP_OFFSETS_H,
    TURN_BATCH,
    TURN_TOLERANCE_S,
    TrackerDrive,
    _time_to_turn,
    moved_degrees,
    singleaxis_orientation,
    step_law,
    tracker_draw,
    tracker_orientation,
)


@settings(max_examples=100)
@given(hour=st.floats(0.0, 9.0), field=st.floats(10, 180))
def test_step_law_is_odd_about_solar_noon_and_spans_its_field(hour, field):
    # Away from the actuating instants the daily angle at -h is minus that at +h.
    offsets = np.asarray(ALEXANDRU_STEP_OFFSETS_H)
    if np.min(np.abs(offsets - hour)) < 1e-6:
        return
    morning, afternoon = step_law(np.array([-15 * hour, 15 * hour]), 12, field)
    assert morning == pytest.approx(-afternoon)
    angles = step_law(np.linspace(-180, 180, 3601), 12, field)
    assert angles.min() == pytest.approx(-field / 2) and angles.max() == pytest.approx(field / 2)
    assert np.allclose(np.unique(np.diff(np.unique(angles))), field / 12)
    assert len(np.flatnonzero(np.diff(angles))) == 12  # twelve moves a day


def test_alexandru_actuating_times_are_his():
    # His 12 local times pair up symmetrically about 13.319 h (Alexandru 2013, Sec. 4).
    times = np.array([8.839, 9.819, 10.619, 11.489, 12.189, 12.919, 13.719, 14.449, 15.149, 16.019, 16.819, 17.799])
    np.testing.assert_allclose(np.sort(np.abs(times - 13.319))[::2], ALEXANDRU_STEP_OFFSETS_H, atol=1e-9)


def test_single_axis_matches_pvlib():
    zenith = np.linspace(10, 85, 40)
    azimuth = np.linspace(70, 290, 40)
    tilt, surface_azimuth, _ = tracker_orientation("single-axis", zenith, azimuth, np.zeros(40), np.zeros(40), 34.0)
    expected = pvlib.tracking.singleaxis(zenith, azimuth, axis_tilt=0, axis_azimuth=180, max_angle=90,
                                         backtrack=False, gcr=0.35)
    np.testing.assert_allclose(tilt, expected["surface_tilt"], atol=1e-9)
    np.testing.assert_allclose(surface_azimuth, expected["surface_azimuth"], atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(
    sun=st.lists(st.tuples(st.floats(0.0, 120.0), st.floats(0.0, 360.0)), min_size=1, max_size=40),
    axis_tilt=st.sampled_from([0.0, 10.0, 35.5]),
    axis_azimuth=st.one_of(st.floats(0.0, 360.0), st.just(180.0)),
    max_angle=st.floats(5.0, 90.0),
    backtrack=st.booleans(),
    gcr=st.floats(0.05, 0.95),
)
def test_single_axis_is_pvlibs_to_the_bit(sun, axis_tilt, axis_azimuth, max_angle, backtrack, gcr):
    """pvlib's operations in pvlib's order: the same surface angles, bit for bit (NaN at night),
    an axis azimuth per step as the tracker passes it."""
    zenith, azimuth = np.array(sun).T
    expected = pvlib.tracking.singleaxis(zenith, azimuth, axis_tilt=axis_tilt,
                                         axis_azimuth=np.full(zenith.shape, axis_azimuth),
                                         max_angle=max_angle, backtrack=backtrack, gcr=gcr)
    axis_azimuths = np.full(zenith.shape, axis_azimuth)
    tilt, surface_azimuth = singleaxis_orientation(
        zenith, azimuth, axis_tilt, axis_azimuths, max_angle, backtrack, gcr
    )
    np.testing.assert_array_equal(tilt, expected["surface_tilt"])
    np.testing.assert_array_equal(surface_azimuth, expected["surface_azimuth"])


@pytest.mark.parametrize("zenith", [30.0, 95.0])
def test_single_axis_of_one_instant_is_pvlibs(zenith):
    """Scalars in, 0-d arrays out, by day and (NaN) by night."""
    expected = pvlib.tracking.singleaxis(zenith, 120.0, 0.0, 180.0, 60.0, True, 0.4)
    tilt, surface_azimuth = singleaxis_orientation(zenith, 120.0, 0.0, 180.0, 60.0, True, 0.4)
    assert np.shape(tilt) == np.shape(surface_azimuth) == ()
    np.testing.assert_array_equal([tilt, surface_azimuth],
                                  [expected["surface_tilt"][0], expected["surface_azimuth"][0]])


@pytest.fixture(scope="session")
def day():
    study = load_study(default_study_path())
    return Day(study.model_copy(update={"mode": "exact", "geometry": "hinge", "step_min": 2}))


def test_continuous_equatorial_tracker_without_consumption_is_the_ideal_one(day):
    # Only the declination's drift during the day separates them (cos of ~0.2 deg).
    np.testing.assert_allclose(day.tracker_power("equatorial"), day.tracker_power("dual-axis"), rtol=1e-4, atol=1e-9)
    free = day.study.variant(tracker={"model": "equatorial", "drive": "wh-per-degree"})
    free_day = Day(free)
    np.testing.assert_allclose(free_day.tracker_draw(), 0.0)
    load = day.study.p_load
    assert t_solar(free_day.tracker_power() - free_day.tracker_draw(), load, free_day.step_hours) == pytest.approx(
        t_solar(day.tracker_power("dual-axis"), load, day.step_hours), abs=1 / 60
    )


@pytest.mark.parametrize("model", ["dual-axis", "equatorial", "dual-axis-steps", "single-axis"])
def test_net_never_exceeds_gross(day, model):
    draw = Day(day.study.variant(tracker={"model": model, "standby_w": 0.2})).tracker_draw()
    assert np.all(draw >= 0) and draw.sum() > 0
    gross = day.tracker_power(model)
    assert t_solar(gross - draw, day.study.p_load, day.step_hours) <= t_solar(gross, day.study.p_load, day.step_hours)
    # The step law moves 12 times plus the night return; its drive energy is the sum of those moves.
    if model == "dual-axis-steps":
        moves = TrackerDrive().move_energy_wh(np.array([7.5] * 12 + [90.0])).sum()
        standby = 0.2 * (day.dni > 0).sum() * day.step_hours
        assert draw.sum() * day.step_hours == pytest.approx(standby + moves, rel=1e-3)


def test_motor_drive_energy_grows_with_the_move():
    drive = TrackerDrive()
    energy = drive.move_energy_wh(np.array([0.0, 1.0, 7.5, 90.0]))
    assert energy[0] == 0 and np.all(np.diff(energy) > 0)
    # Long moves approach the free-running cost: 12 V x 0.3 A over 653 x 90 deg at 78 rpm, plus start-up.
    speed = 5571.57 / 4288 * 360  # deg/s of the gear-motor output
    assert energy[3] > 12 * 0.3 * (653 * 90 / speed) / 3600
    drive = TrackerDrive(drive="wh-per-degree", wh_per_degree=0.01)
    assert drive.move_energy_wh(np.array([10.0]))[0] == pytest.approx(0.1)


def test_a_moves_energy_is_the_same_bits_among_many_as_alone_and_its_time_turns_the_angle():
    # More moves than one batch of the Newton steps, standstills among them: each move's time
    # is its own (the same bits alone), and in it the motor turns the move's angle, to within
    # what it turns at full speed in the time's tolerance.
    rng = np.random.default_rng(7)
    degrees = rng.choice([0.0, 1.0], 2 * TURN_BATCH + 5) * np.concatenate(
        [rng.exponential(1.5, TURN_BATCH), rng.uniform(0.0, 180.0, TURN_BATCH + 5)]
    )
    drive = TrackerDrive()
    together = drive.move_energy_wh(degrees)
    picked = np.r_[0:3, TURN_BATCH - 3 : TURN_BATCH + 3, rng.integers(0, degrees.size, 50)]
    for k in picked:
        assert drive.move_energy_wh(degrees[k : k + 1])[0] == together[k]
    speed = drive.gain / drive.counts_per_revolution * 360.0
    tau_1, tau_2 = drive.tau_1, drive.tau_2
    target = degrees[degrees > 0] * drive.gear_ratio
    t = _time_to_turn(target, speed, tau_1, tau_2)
    lag = (tau_1**2 * -np.expm1(-t / tau_1) - tau_2**2 * -np.expm1(-t / tau_2)) / (tau_1 - tau_2)
    np.testing.assert_allclose(speed * (t - lag), target, rtol=0, atol=speed * TURN_TOLERANCE_S)


def _normals(rng, shape, still, nudge=0.0):
    """Random unit normals, ``shape`` + (3,), each step holding the one before with probability
    ``still`` (where held, half of them moved by some ``nudge``), and where they hold."""
    normal = rng.normal(size=(*shape, 3))
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    hold = rng.random(shape) < still
    for step in range(1, shape[1]):
        moved = rng.normal(scale=nudge, size=(shape[0], 3)) * rng.integers(0, 2, (shape[0], 1))
        normal[:, step][hold[:, step]] = (normal[:, step - 1] + moved)[hold[:, step]]
    return normal, hold


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), still=st.floats(0.0, 1.0))
def test_the_moves_compiled_passes_are_numpys_bits(seed, still):
    # The turns and the moves' times in compiled passes around NumPy's arcsin and expm1 (SVML's
    # on some CPUs, not the C library's): the bits of NumPy's expressions, whatever the normals'
    # layout (a dual-axis tracker's is the sky's, each component along the steps), with moves
    # that hold still or nearly.
    normal, hold = _normals(np.random.default_rng(seed), (4, 60), still, nudge=1e-9)
    rng = np.random.default_rng(seed + 1)
    along_steps = np.moveaxis(np.ascontiguousarray(np.moveaxis(normal, -1, 1)), 1, -1)
    for given_normal in (normal, along_steps, normal[0], normal[:, :1], normal[:, :0]):
        np.testing.assert_array_equal(
            moved_degrees(given_normal, "numba"), moved_degrees(given_normal, "numpy")
        )
    drive = TrackerDrive(standby_w=0.3)
    degrees = np.concatenate([moved_degrees(normal).ravel(), rng.exponential(2.0, 50), [0.0]])
    np.testing.assert_array_equal(
        drive.move_energy_wh(degrees, "numba"), drive.move_energy_wh(degrees, "numpy")
    )
    np.testing.assert_array_equal(
        tracker_draw(along_steps, hold, 1 / 12, drive, "numba"),
        tracker_draw(along_steps, hold, 1 / 12, drive, "numpy"),
    )


@settings(max_examples=50)
@given(seed=st.integers(0, 2**32 - 1), still=st.floats(0.0, 1.0))
def test_moved_degrees_is_the_angle_between_consecutive_normals(seed, still):
    # The angle between unit vectors by atan2(|a x b|, a . b), accurate at every angle; the
    # steps that hold still turn exactly 0.
    normal, hold = _normals(np.random.default_rng(seed), (3, 40), still)
    a, b = normal[:, :-1], normal[:, 1:]
    expected = np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), (a * b).sum(-1)))
    turn = moved_degrees(normal)
    assert np.all(turn[:, 0] == 0) and np.all(turn[:, 1:][hold[:, 1:]] == 0)
    np.testing.assert_allclose(turn[:, 1:], np.where(expected > 1e-6, expected, 0.0), atol=1e-6)


def test_hottel_against_duffie_beckman_example_2_8_1():
    # Duffie & Beckman, "Solar Engineering of Thermal Processes", Example 2.8.1: Madison (270 m),
    # 22 August, 11:30 solar time, cos(zenith) = 0.846, midlatitude summer: tau_b = 0.62,
    # G_on = 1339 W/m^2, G_cnb = 830 W/m^2.
    zenith = np.degrees(np.arccos(0.846))
    tau = hottel_transmittance(zenith, 270.0, "midlatitude-summer")
    assert tau == pytest.approx(0.62, abs=0.005)
    assert extraterrestrial_normal(234) == pytest.approx(1339, abs=1)
    assert extraterrestrial_normal(234) * tau == pytest.approx(830, abs=5)
    assert hottel_transmittance(95.0) == 0.0
    with pytest.raises(ValueError, match="tropical"):
        hottel_transmittance(30.0, climate="arctic")


def test_hottel_sky_runs_a_study(day):
    hottel = Day(day.study.model_copy(update={"sky": "hottel", "climate": "tropical"}))
    assert 0 < hottel.dni.max() < 1100
    assert (hottel.dni[day.dni == 0] == 0).all()


@pytest.mark.parametrize("model", ["dual-axis", "equatorial", "dual-axis-steps", "single-axis"])
def test_trackers_over_many_days_at_once_equal_each_day_alone(model):
    import datetime as dt

    from foldopt.engine.sky import build_sky
    from foldopt.studies.designs import sky_tracker_draw, sky_tracker_orientation
    from foldopt.studies.engine_options import engine_options

    study = load_study(default_study_path()).variant(mode="exact", geometry="hinge", step_min=5,
                                                     tracker={"model": model, "standby_w": 0.3})
    dates = [dt.date(2025, 3, 1), dt.date(2025, 6, 21), dt.date(2025, 12, 21)]
    sky = build_sky(engine_options(study).sky, [study.site] * 3, dates)
    orientation = sky_tracker_orientation(sky, study)
    draw = sky_tracker_draw(sky, study, orientation)
    for index, date in enumerate(dates):
        day = Day(study.variant(date=date))
        np.testing.assert_allclose(orientation[0][index], day.tracker_orientation()[0], atol=1e-9)
        np.testing.assert_allclose(orientation[1][index], day.tracker_orientation()[1], atol=1e-9)
        np.testing.assert_allclose(draw[index], day.tracker_draw(), atol=1e-12)


@settings(max_examples=6, deadline=None)
@given(st.floats(-65.0, 65.0), st.floats(-180.0, 180.0), st.integers(0, 364),
       st.sampled_from(["dual-axis", "equatorial", "dual-axis-steps", "single-axis"]),
       st.sampled_from([("ineichen", "perez"), ("ineichen", "isotropic"), ("meinel", "none")]))
def test_a_trackers_compiled_irradiance_is_the_reference_paths(latitude, longitude, day, model, sky_model):
    """The compiled tracker irradiance of an open plain (sky_tracker_poa's above the auto engine's
    size, or for a request that decided on the kernel: a map's worker) is
    foldopt.engine.evaluation.poa's NumPy expression to the bit, beam-only skies included."""
    import datetime as dt

    from foldopt.engine import evaluation as engines
    from foldopt.engine.incidence import turning_poa
    from foldopt.engine.sky import build_sky
    from foldopt.studies.designs import sky_tracker_orientation, sky_tracker_poa
    from foldopt.studies.engine_options import engine_options

    sky_name, transposition = sky_model
    study = load_study(default_study_path()).variant(mode="exact", step_min=5, sky=sky_name,
                                                     transposition=transposition, tracker={"model": model})
    site = study.site.model_copy(update={"latitude": latitude, "longitude": longitude, "timezone": "UTC"})
    dates = [dt.date(2025, 1, 1) + dt.timedelta(days=(day + k * 121) % 365) for k in range(3)]
    sky = build_sky(engine_options(study).sky, [site] * 3, dates)
    orientation = sky_tracker_orientation(sky, study)
    reference = engines.poa(sky, orientation[0], orientation[1], normal=orientation[2])
    sun, _, beam, terms, span = sky.kernel_layout(False)
    compiled = np.empty(beam.shape)
    # The normal as sky_tracker_poa hands it (each component along the steps): one array type.
    along = np.ascontiguousarray(np.moveaxis(orientation[2], -1, 1), dtype=float)
    turning_poa(along, sun, beam, terms, span, compiled)
    np.testing.assert_array_equal(compiled, reference)
    np.testing.assert_array_equal(sky_tracker_poa(sky, orientation, "numba"), reference)
    # One array type compiled (the suite's warm-up compiles it too: tests/conftest.py).
    assert len(turning_poa.signatures) == 1
