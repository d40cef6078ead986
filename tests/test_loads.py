"""Load profiles, P_load(t) = scale x profile(t): a constant profile is today's constant load to the
bit, a load confined to a window never counts time outside it, t_solar never rises with the scale,
and the compiled kernel agrees with the NumPy reference on random profiles."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from foldopt.engine import evaluation as engines
from foldopt.api import default_study, run
from foldopt.inputs.sections import LoadProfile
from foldopt.inputs.study import make_study
from foldopt.errors import ConfigError
from foldopt.inputs.load_profile import load_shape
from foldopt.inputs.study_file import read_profile
from foldopt.engine.metrics import energy_served, t_solar
from foldopt.studies.designs import Blocks, fold_hours

EXACT = default_study().variant(mode="exact", geometry=None, step_min=10,
                                fold_angles={"start": 10, "stop": 180, "step": 10})
DAYS = [dt.date(2025, 1, 1) + dt.timedelta(days=d) for d in range(0, 365, 45)]


def test_a_constant_profile_is_the_constant_load_bit_for_bit():
    constant = run(EXACT)
    # A profile given without a scale runs as written (foldopt.inputs.policy): the scale is the constant load.
    profiled = run(EXACT.variant(load_profile={"daily": {"00:00": 1.0}}, p_load=EXACT.p_load))
    # The flat-area multiple is for constant loads: a profile has none.
    columns = [c for c in constant.summary.columns if c != "flat_area_ratio"]
    assert constant.summary[columns].equals(profiled.summary[columns])
    assert profiled.summary["flat_area_ratio"].isna().all()
    assert constant.sweep.equals(profiled.sweep)
    assert constant.timeseries.equals(profiled.timeseries)
    # Over several days, every angle and load, both engines.
    loads = np.array([1.0, 4.4, 9.0])
    for engine in ("numba", "numpy"):
        results = []
        for study in (EXACT, EXACT.variant(load_profile={"daily": {"06:00": 1.0}})):
            blocks = Blocks.of_dates(study, DAYS)
            results.append(fold_hours(blocks.sky(), blocks, loads, engine))
        np.testing.assert_array_equal(results[0][1], results[1][1])
        np.testing.assert_array_equal(results[0][2], results[1][2])


@pytest.mark.parametrize("engine", ["numba", "numpy"])
def test_a_load_in_a_window_never_counts_time_outside_it(engine):
    window = EXACT.variant(load_profile={"daily": {"00:00": 0.0, "10:00": 2.0, "14:00": 0.0}})
    blocks = Blocks.of_dates(window, DAYS)
    _, hours, _ = fold_hours(blocks.sky(), blocks, np.array([0.01, 1.0, 3.0]), engine)
    assert hours.max() <= 4.0 + 1e-12
    # A tiny load is carried through the whole window but for the half steps at its edges.
    assert hours[..., 0].max() == pytest.approx(4.0 - window.step_min / 60.0, abs=1e-9)


def test_served_energy_follows_the_profile():
    power = np.r_[0, 0, 2, 6, 9, 10, 9, 6, 2, 0, 0.0]
    assert energy_served(power, 3.0, np.ones_like(power), 0.5) == pytest.approx(3.0 * t_solar(power, 3.0, 0.5))
    shape = np.r_[0, 0, 0, 1, 1, 1, 1, 1, 0, 0, 0.0]
    assert energy_served(power, 3.0, shape, 0.5) <= 3.0 * shape.sum() * 0.5
    camera = run(EXACT.variant(load_profile={"daily": {"00:00": 1.5, "07:00": 6.0, "19:00": 1.5}}, p_load=1.0))
    summary = camera.summary.set_index("design")
    # Served energy lies between the idle and the recording load times t_solar.
    for design in ("flat", "twofold", "tracker"):
        served, hours = summary.loc[design, "energy_served_wh"], summary.loc[design, "t_solar_h"]
        assert 1.5 * hours - 1e-9 <= served <= 6.0 * hours + 1e-9
    # Eq. 8 sets the noon valley to the load at solar noon: the 6 W of a constant 6 W load.
    recording = run(EXACT.variant(p_load=6.0))
    assert camera.heuristic_fold_angle == recording.heuristic_fold_angle
    assert np.isnan(camera.standby[1])
    np.testing.assert_allclose(camera.timeseries["p_load_w"].unique(), [1.5, 6.0])


profiles = st.dictionaries(st.sampled_from([f"{h:02d}:{m:02d}" for h in range(24) for m in (0, 30)]),
                           st.one_of(st.just(0.0), st.floats(0.1, 10)), min_size=1, max_size=6)


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(daily=profiles, interpolation=st.sampled_from(["step", "linear"]), latitude=st.floats(-60, 60),
       scales=st.lists(st.floats(0.05, 3), min_size=2, max_size=5, unique=True))
def test_kernel_equals_reference_and_t_solar_never_rises_with_the_scale(daily, interpolation, latitude, scales):
    study = EXACT.variant(site={"latitude": latitude, "longitude": 20.0}, panel={"area": 0.1},
                          load_profile={"daily": daily, "interpolation": interpolation})
    blocks = Blocks.of_dates(study, DAYS[:3])
    sky = blocks.sky()
    scales = np.sort(scales)
    _, fast, fast_energy = fold_hours(sky, blocks, scales, "numba")
    _, slow, slow_energy = fold_hours(sky, blocks, scales, "numpy")
    np.testing.assert_allclose(fast, slow, atol=1e-9)
    np.testing.assert_allclose(fast_energy, slow_energy, rtol=1e-12)
    assert (np.diff(fast, axis=-1) <= 1e-12).all()
    curves = engines.curve_metrics(np.ones((sky.n_blocks, sky.dni.shape[1])), scales, sky.step_hours,
                                   load_shape=sky.load_shape)
    loaded = (sky.load_shape > 0).mean(axis=1) * 24
    assert (curves.t_solar[:, 0].max(axis=-1) <= loaded + 1e-9).all()


def test_load_shape_interpolation_weekend_and_months():
    hours = np.array([[0.0, 6.5, 7.0, 12.0, 19.5, 23.9]])
    step = LoadProfile(daily={"07:00": 6.0, "19:00": 1.5})
    np.testing.assert_allclose(load_shape(step, hours, [dt.date(2025, 6, 2)])[0], [1.5, 1.5, 6.0, 6.0, 1.5, 1.5])
    linear = LoadProfile(daily={"06:00": 0.0, "12:00": 6.0}, interpolation="linear")
    np.testing.assert_allclose(load_shape(linear, np.array([[9.0, 0.0]]), [dt.date(2025, 6, 2)])[0], [3.0, 2.0])
    variants = LoadProfile(daily={"00:00": 1.0}, weekend={"00:00": 2.0}, months={7: {"00:00": 3.0}})
    dates = [dt.date(2025, 6, 2), dt.date(2025, 6, 7), dt.date(2025, 7, 1), dt.date(2025, 7, 5)]  # Mon, Sat, Tue, Sat
    np.testing.assert_allclose(load_shape(variants, np.zeros((4, 1)), dates)[:, 0], [1.0, 2.0, 3.0, 2.0])


def test_bad_profiles(tmp_path):
    base = EXACT.model_dump(mode="json")
    for profile, words in (({"daily": {"25:00": 1}}, "not a clock time"), ({"daily": {"07:00": -1}}, ">= 0"),
                           ({}, "daily"), ({"daily": {"07:00": 1}, "interpolation": "cubic"}, "interpolation")):
        with pytest.raises(ConfigError, match=words):
            make_study({**base, "load_profile": profile})
    bad = tmp_path / "p.csv"
    bad.write_text("time,watts\n07:00,six\n")
    with pytest.raises(ConfigError, match="line 2: expected time,watts"):
        read_profile(bad)
    good = tmp_path / "q.csv"
    good.write_text("time,watts\n19:00,1.5\n7:00,6\n")
    assert read_profile(good) == {"07:00": 6.0, "19:00": 1.5}


def test_a_constant_profile_sweep_is_the_constant_load_sweep():
    from foldopt.inputs.plan import make_plan
    from foldopt.studies.sweeps import run_plan

    data = {**EXACT.model_dump(mode="json", exclude_none=True), "date": [d.isoformat() for d in DAYS[:4]],
            "p_load": [1.0, 4.0], "objective": {"statistic": "mean", "visits": 2}}
    constant = run_plan(make_plan(data))
    profiled = run_plan(make_plan({**data, "load_profile": {"daily": {"00:00": 1.0}}}))
    assert constant.table.equals(profiled.table)
    assert constant.extras["refold_value"].equals(profiled.extras["refold_value"])
