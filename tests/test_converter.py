"""The converter models (foldopt.physics.converter) against their published formulas, written here."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from foldopt.physics.converter import ZETA_MAX, Converter, delivered_table, table_delivered

ETA_REF = 0.9637  # PVWatts v5 manual (Dobos 2014), inverter model: the reference efficiency


def pvwatts_by_hand(p_in, p_rated, eta_nom):
    """Dobos 2014, PVWatts v5 inverter model Eq. 1-2: the part-load efficiency, the output clipped
    at eta_nom * p_rated and never negative."""
    zeta = p_in / p_rated
    # At no input the curve's -0.0059 / zeta is infinite, a value np.where sets aside.
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        eta = eta_nom / ETA_REF * (-0.0162 * zeta - 0.0059 / zeta + 0.9858)
        return np.clip(np.where(p_in > 0, eta * p_in, 0.0), 0.0, eta_nom * p_rated)


def test_ideal_delivers_its_input():
    p = np.array([0.0, 0.3, 7.0, 1e4])
    assert np.array_equal(Converter("ideal").delivered(p), p)


def test_pvwatts_is_dobos_part_load_curve():
    converter = Converter("pvwatts", p_rated=20.0, efficiency=0.95)
    p = np.linspace(0.0, 40.0, 4001)
    assert np.allclose(converter.delivered(p), pvwatts_by_hand(p, 20.0, 0.95), rtol=1e-12, atol=1e-12)
    # Below about 0.6 % of its rating it delivers nothing; at its rating eta_nom / eta_ref x 0.9637 = 0.9497 of it.
    assert converter.delivered(np.array([0.1]))[0] == 0.0
    assert converter.delivered(np.array([20.0]))[0] == pytest.approx(0.95 / ETA_REF * (0.9858 - 0.0162 - 0.0059) * 20)


def test_curve_is_linear_between_points_and_falls_to_zero():
    converter = Converter("curve", p_rated=10.0, curve=((0.1, 0.8), (0.5, 0.95), (1.0, 0.93)))
    p = np.array([0.0, 0.5, 1.0, 3.0, 5.0, 10.0, 15.0])
    expected_eta = np.array([0.0, 0.4, 0.8, 0.8 + 0.15 * (0.3 - 0.1) / 0.4, 0.95, 0.93, 0.93])
    assert np.allclose(converter.delivered(p), p * expected_eta, rtol=1e-12)


def test_unknown_model_lists_the_valid_ones():
    with pytest.raises(ValueError, match="ideal, pvwatts, curve"):
        Converter("sandia")


@settings(max_examples=60, deadline=None)
@given(st.floats(0.0, 300.0), st.floats(1.0, 50.0), st.floats(0.85, 0.99))
def test_table_reads_the_model_within_a_ten_thousandth_of_its_rating(p_in, p_rated, eta_nom):
    """The kernel's table (nodes uniform in sqrt(P / P_rated)) against the exact curve: PVWatts bends
    hardest near 0.6 % of the rating; 2049 nodes keep the error below 1e-4 of the rating."""
    converter = Converter("pvwatts", p_rated=p_rated, efficiency=eta_nom)
    table = delivered_table(converter)
    read = table_delivered(np.array([p_in]), table, p_rated)[0]
    # Beyond ZETA_MAX times its rating (an overload no study reaches) it delivers what it does there.
    taken = min(p_in, ZETA_MAX * p_rated)
    assert abs(read - pvwatts_by_hand(np.array([taken]), p_rated, eta_nom)[0]) <= 1e-4 * p_rated


def test_independent_converters_work_at_the_part_load_of_their_sub_panel():
    """Each of two converters rated for half takes half the power at the same part load: together they
    deliver what the whole panel's converter does."""
    whole = Converter("pvwatts", p_rated=20.0)
    half = whole.scaled(0.5)
    p = np.linspace(0.0, 30.0, 301)
    assert np.allclose(2 * half.delivered(p / 2), whole.delivered(p), rtol=1e-12, atol=1e-12)
