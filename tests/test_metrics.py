"""Daily metrics against analytic power curves."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from foldopt.engine.metrics import daily_metrics, load_for_t_solar, relative_to, t_solar, t_solar_contiguous
from foldopt.studies.sizing import flat_area_ratio

P_MAX = 10.0


def centres(step_min):
    step_hours = step_min / 60.0
    return (np.arange(round(24 / step_hours)) + 0.5) * step_hours, step_hours


def sine_day(hours):
    """A 12-hour half sine from 06:00 to 18:00 peaking at P_MAX [W]."""
    return np.where((hours > 6) & (hours < 18), P_MAX * np.sin(np.pi * (hours - 6) / 12), 0.0)


def sine_t_solar(load):
    return 12.0 - 24.0 / np.pi * np.arcsin(load / P_MAX)


@pytest.mark.parametrize("load", [0.5, 3.0, 7.07, 9.9])
def test_t_solar_of_a_half_sine_interpolates_the_crossings(load):
    hours, step = centres(1)
    # Whole-step counting would be off by up to a step (0.0167 h); interpolation is exact to
    # the curvature term, < 1e-4 h here.
    assert t_solar(sine_day(hours), load, step) == pytest.approx(sine_t_solar(load), abs=1e-4)


def test_contiguous_takes_the_longest_hump():
    hours, step = centres(1)
    two_humps = np.where((hours > 6) & (hours < 18), P_MAX * np.abs(np.sin(np.pi * (hours - 6) / 6)), 0.0)
    hump = 6.0 - 12.0 / np.pi * np.arcsin(0.4)
    assert t_solar(two_humps, 4.0, step) == pytest.approx(2 * hump, abs=1e-4)
    assert t_solar_contiguous(two_humps, 4.0, step) == pytest.approx(hump, abs=1e-4)
    uneven = np.where(hours < 12, two_humps, 0.5 * two_humps)
    assert t_solar_contiguous(uneven, 4.0, step) == pytest.approx(hump, abs=1e-4)


def test_energy_and_peak_of_a_half_sine():
    hours, step = centres(1)
    metrics = daily_metrics(sine_day(hours), 5.0, step)
    assert metrics["energy_harvested_wh"] == pytest.approx(P_MAX * 24 / np.pi, rel=1e-5)
    assert metrics["peak_power_w"] == pytest.approx(P_MAX, rel=1e-4)
    assert metrics["energy_served_wh"] == pytest.approx(5.0 * sine_t_solar(5.0), rel=1e-4)
    assert metrics["energy_wasted_wh"] == pytest.approx(metrics["energy_harvested_wh"] - metrics["energy_served_wh"])


def test_polar_day_night_and_load_above_peak():
    hours, step = centres(10)
    assert t_solar(np.full_like(hours, 3.0), 2.0, step) == pytest.approx(24.0)
    assert t_solar_contiguous(np.full_like(hours, 3.0), 2.0, step) == pytest.approx(24.0)
    assert t_solar(np.zeros_like(hours), 2.0, step) == 0.0
    assert t_solar(sine_day(hours), 2 * P_MAX, step) == 0.0


def test_step_length_barely_matters():
    fine, coarse = centres(0.5), centres(5)
    assert t_solar(sine_day(fine[0]), 4.0, fine[1]) == pytest.approx(
        t_solar(sine_day(coarse[0]), 4.0, coarse[1]), abs=2e-3
    )


def test_vectorised_over_curves_and_loads():
    hours, step = centres(1)
    curves = np.stack([sine_day(hours), 0.5 * sine_day(hours)])
    loads = np.array([1.0, 2.0, 4.0])[:, None]
    result = t_solar(curves, loads, step)
    assert result.shape == (3, 2)
    assert result[1, 1] == pytest.approx(sine_t_solar(4.0), abs=1e-4)
    np.testing.assert_allclose(
        t_solar_contiguous(curves, loads, step), result, atol=1e-12
    )  # one hump each


def test_load_for_t_solar_and_flat_area_multiple_invert_the_sine():
    hours, step = centres(1)
    target = 8.0
    expected_load = P_MAX * np.sin(np.pi * (12 - target) / 24)
    assert load_for_t_solar(sine_day(hours), target, step) == pytest.approx(expected_load, rel=1e-4)
    assert flat_area_ratio(sine_day(hours), 2 * expected_load, target, step) == pytest.approx(2.0, rel=1e-4)
    assert np.isnan(load_for_t_solar(sine_day(hours), 12.5, step))  # longer than daylight


power_curves = arrays(np.float64, 48, elements=st.floats(0, 20))


@settings(max_examples=200)
@given(curve=power_curves, low=st.floats(0.01, 20), rise=st.floats(0, 10))
def test_t_solar_never_rises_with_the_load_and_contiguous_never_exceeds_total(curve, low, rise):
    step = 0.5
    assert t_solar(curve, low + rise, step) <= t_solar(curve, low, step) + 1e-12
    assert t_solar_contiguous(curve, low, step) <= t_solar(curve, low, step) + 1e-12
    assert 0.0 <= t_solar(curve, low, step) <= 24.0 + 1e-12


def test_relative_to_has_no_value_over_nothing():
    ratio = relative_to([2.0, 0.0, 3.0, 0.0], [1.0, 1.0, 0.0, 0.0])
    np.testing.assert_array_equal(ratio[:2], [2.0, 0.0])
    assert np.isnan(ratio[2:]).all()  # no inf, no warning: a gain over 0 h has no value


@settings(max_examples=100, deadline=None)
@given(st.integers(1, 400), st.integers(1, 6), st.integers(1, 11), st.sampled_from(["mean", "worst-month"]),
       st.lists(st.one_of(st.none(), st.sets(st.integers(1, 12), min_size=1, max_size=4)), min_size=1, max_size=5),
       st.integers(0, 2**32 - 1))
def test_period_values_are_each_periods_own_statistic_to_the_bit(days, n, loads, statistic, seasons, seed):
    """The periods' means and worst months summed in one pass over the days (a map's search) are
    the bits of the statistic taken over each period's own days (objective_value, NumPy's mean of
    the period's days): a map's answers stay those of a study of the same site."""
    import warnings

    from foldopt.studies.objectives import objective_value, period_values

    rng = np.random.default_rng(seed)
    months = rng.integers(1, 13, days)
    if statistic == "worst-month":  # a worst month needs a day in the period
        seasons = [season for season in seasons if season is None or np.isin(months, list(season)).any()] or [None]
    hours = rng.random((days, n, loads)) * 12.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # the mean of a period without days: NaN
        expected = np.stack([objective_value(hours, months, statistic, season) for season in seasons])
    np.testing.assert_array_equal(period_values(hours, months, statistic, seasons), expected)
