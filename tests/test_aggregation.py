"""Aggregation: relations between the connections, solved exactly from the sub-panels' I-V
curves, and a year's days gathered into ``annual_summary.csv``."""

import numpy as np
import pandas as pd
import pvlib
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from foldopt.physics.connections import connection_powers, pair_powers, parallel_power, series_power
from foldopt.physics.pvmodel import PVModel
from foldopt.physics.temperature import cell_temperature

AREA = 0.054  # a sub-panel of the paper's 0.108 m^2 panel
MODELS = {"single-diode": PVModel("single-diode"), "b-model": PVModel("b-model", efficiency=0.19)}


def curves(model, poa_east, poa_west, temp=25.0):
    pv = MODELS[model]
    east = pv.curves(np.atleast_1d(np.asarray(poa_east, float)), temp, AREA)
    west = pv.curves(np.atleast_1d(np.asarray(poa_west, float)), temp, AREA)
    return east, west


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("poa", [50.0, 300.0, 1000.0])
def test_equal_irradiance_parallel_and_series_are_twice_one(model, poa):
    east, west = curves(model, poa, poa)
    one = east.max_power()
    assert parallel_power(east, west) == pytest.approx(2 * one, rel=1e-6)
    assert series_power(east, west, bypass=False) == pytest.approx(2 * one, rel=1e-6)


@pytest.mark.parametrize("model", MODELS)
@settings(max_examples=40, deadline=None)
@given(poa_east=st.floats(0, 1200), poa_west=st.floats(0, 1200), temp=st.floats(-10, 70),
       bypass=st.booleans())
# Practically dark cells, for which pvlib's v_from_i returns NaN or absurd voltages.
@example(poa_east=1.0, poa_west=1.7e-44, temp=38.0, bypass=False)
@example(poa_east=0.0, poa_west=1.03e-134, temp=69.0, bypass=False)
def test_single_converter_never_beats_independent_and_switching_beats_its_states(model, poa_east, poa_west, temp,
                                                                                  bypass):
    east, west = curves(model, poa_east, poa_west, temp)
    p_east, p_west = east.max_power(), west.max_power()
    p_parallel, p_series = pair_powers(east, west, bypass)
    powers, _ = connection_powers(p_east, p_west, p_parallel, p_series, switch_series=True)
    bound = powers["independent"] * (1 + 1e-9) + 1e-12
    assert np.all(powers["parallel"] <= bound)
    assert np.all(powers["series"] <= bound)
    for state in ("east", "west", "parallel", "series"):
        assert np.all(powers["switching"] >= powers[state] - 1e-12)
    # Blocking diodes: parallel never falls below the better sub-panel alone.
    assert np.all(powers["parallel"] >= np.maximum(p_east, p_west) * (1 - 1e-6) - 1e-12)


@pytest.mark.parametrize("model", MODELS)
def test_series_without_bypass_is_limited_by_the_weaker_current(model):
    east, west = curves(model, 1000.0, 150.0)
    limited = series_power(east, west, bypass=False)[0]
    # No operating point can carry more than the weaker sub-panel's short-circuit current, so
    # the pair delivers at most that current times the two open-circuit voltages.
    assert limited <= west.i_sc[0] * (east.v_oc[0] + west.v_oc[0])
    # Brute force over currents up to the weaker Isc matches the solver.
    current = np.linspace(0, west.i_sc[0], 100001)
    voltage = east.voltage(current[None, :]) + west.voltage(current[None, :])
    assert limited == pytest.approx(np.nanmax(current * voltage), rel=1e-6)
    # A bypass diode lets the strong sub-panel run alone at its maximum when that is better.
    assert series_power(east, west, bypass=True)[0] >= max(limited, east.max_power()[0]) * (1 - 1e-6)


def test_bypassed_series_finds_the_peak_before_the_weaker_current_collapses():
    # Found by the fast-path check (paper's day, exact mode, 142 deg fold, 15:53): both sub-panels
    # conducting just below the weaker Isc beat the stronger one alone (7.4205 W against 7.3663 W);
    # a search across the cliff where the weaker voltage collapses had missed it.
    pv = MODELS["single-diode"]
    poa = np.array([324.309, 705.093])
    temp = cell_temperature(poa, 25.0, 1.0, "sapm")
    east, west = (pv.curves(poa[i : i + 1], temp[i : i + 1], AREA) for i in (0, 1))
    current = np.linspace(0, west.i_sc[0], 400001)[None, :]

    def side(curve):
        volts = np.nan_to_num(curve.voltage(np.minimum(current, curve.i_sc[0])))
        return np.where(current < curve.i_sc[0], np.clip(volts, 0, curve.v_oc[0]), 0.0)

    brute = np.max(current * (side(east) + side(west)))
    assert series_power(east, west, bypass=True)[0] == pytest.approx(brute, rel=1e-6)
    assert series_power(east, west, bypass=True)[0] > west.max_power()[0] * 1.005


def test_parallel_solver_matches_a_brute_force_scan_of_the_summed_curve():
    east, west = curves("single-diode", [900.0, 600.0, 20.0], [100.0, 550.0, 800.0], 45.0)
    voltage = np.linspace(0, 3.0, 300001)
    total = sum(
        np.clip(pvlib.pvsystem.i_from_v(voltage[None, :], *[p[:, None] for p in c.params]), 0, None)
        for c in (east, west)
    )
    np.testing.assert_allclose(parallel_power(east, west), (voltage * total).max(axis=1), rtol=1e-6)


@pytest.mark.parametrize("model", MODELS)
def test_pair_solvers_never_fall_below_a_brute_force_scan(model):
    # Parallel is searched only between the two maximum-power voltages and series only up to the
    # weaker short-circuit current (foldopt.physics.connections): on random pairs, weak and near-dark
    # sub-panels and hot or cold cells included, neither may land below a dense scan.
    rng = np.random.default_rng(11)
    poa_east = rng.uniform(0, 1500, 120)
    poa_west = rng.uniform(0, 1500, 120) * rng.choice([1.0, 0.1, 0.01, 1e-4, 0.0], 120)
    temp = rng.uniform(-10, 70, 120)
    east = MODELS[model].curves(poa_east, cell_temperature(poa_east, temp, 1.0, "sapm"), AREA)
    west = MODELS[model].curves(poa_west, cell_temperature(poa_west, temp, 1.0, "sapm"), AREA)
    fraction = np.linspace(0.0, 1.0, 20001)[None, :]
    voltage = np.maximum(east.v_oc, west.v_oc)[:, None] * fraction
    current = sum(np.nan_to_num(np.clip(side.current(voltage), 0, None)) for side in (east, west))
    brute = (voltage * current).max(axis=1)
    assert np.all(parallel_power(east, west) >= brute * (1 - 1e-9) - 1e-15)
    np.testing.assert_allclose(parallel_power(east, west), brute, rtol=1e-6, atol=1e-12)
    string = np.minimum(east.i_sc, west.i_sc)[:, None] * fraction
    volts = sum(np.clip(np.nan_to_num(side.voltage(string)), 0, side.v_oc[:, None]) for side in (east, west))
    brute = (string * volts).max(axis=1)
    assert np.all(series_power(east, west, bypass=False) >= brute * (1 - 1e-9) - 1e-15)
    np.testing.assert_allclose(series_power(east, west, bypass=False), brute, rtol=1e-6, atol=1e-12)


def test_ideal_model_connections_are_sums():
    powers, state = connection_powers(np.array([3.0, 0.0]), np.array([1.0, 2.0]), converter_efficiency=0.9)
    np.testing.assert_allclose(powers["parallel"], [4.0, 2.0])
    np.testing.assert_allclose(powers["independent"], [3.6, 1.8])
    # Ties go to the single sub-panel (west alone equals parallel when east is dark).
    assert list(state) == [2, 1]


#: Two days six months apart: the twofold panel's best angle differs (at 52.5 N it is flat at the
#: winter solstice under a 2 W load); and three days in a row, whose best angle is the same.
SOLSTICES, MIDSUMMER = "2025-06-21,2025-12-21", "2025-06-20,2025-06-21,2025-06-22"


def _sweep_folder(tmp_path, figures_drawn_elsewhere, *extra):
    from typer.testing import CliRunner

    from foldopt.cli.app import app

    out = tmp_path / "out"
    # What is read is the folder's tables: a day sweep's figures are drawn whole by
    # tests/test_cli_studies.py (days with different angles too).
    with figures_drawn_elsewhere():
        result = CliRunner().invoke(app, ["sweep", "day", "--lat", "52.52", "--lon", "13.40", "--p-load", "2",
                                          "--step-min", "15", "--angle-step", "2", "-q", *extra, "--out",
                                          str(out)])
    assert result.exit_code == 0, result.output
    return out


@pytest.mark.parametrize("dates,objective,angles", [(SOLSTICES, (), 2), (SOLSTICES, ("--objective", "mean"), 1),
                                                   (MIDSUMMER, (), 1)],
                         ids=["solstices", "solstices-one-angle", "days-in-a-row"])
def test_the_annual_summary_says_what_its_angle_and_totals_stand_for(tmp_path, figures_drawn_elsewhere, dates,
                                                                      objective, angles):
    """A design's fold_angle_deg in annual_summary.csv is the angle of every one of its days in
    results.csv; where the days differ (each day's own best) it is empty, the range of the days'
    angles is given and a note says so (it was the first day's). Where the days skip some of their
    period, the note says the totals are the days' only."""
    out = _sweep_folder(tmp_path, figures_drawn_elsewhere, "--days", dates, *objective)
    days = pd.read_csv(out / "results.csv")
    summary = pd.read_csv(out / "annual_summary.csv", keep_default_na=False, na_values=[""]).set_index("design")
    assert set(summary.index) == set(days["design"])
    for design, rows in days.groupby("design"):
        angles_of_days, row = rows["fold_angle_deg"], summary.loc[design]
        assert row["days_n"] == len(rows)
        assert row["energy_harvested_wh"] == pytest.approx(rows["energy_harvested_wh"].sum(), rel=1e-9)
        if angles_of_days.isna().all():  # a tracker: no angle
            assert np.isnan(row[["fold_angle_deg", "fold_angle_min_deg", "fold_angle_max_deg"]].astype(float)).all()
        else:
            assert (row["fold_angle_min_deg"], row["fold_angle_max_deg"]) == (angles_of_days.min(),
                                                                              angles_of_days.max())
        expected = []
        if angles_of_days.nunique() > 1:
            assert np.isnan(row["fold_angle_deg"])
            expected.append(f"fold angle varies by day, {angles_of_days.min():g} to {angles_of_days.max():g} deg "
                            "(each day's: results.csv)")
        else:
            assert row["fold_angle_deg"] == angles_of_days.iloc[0] or angles_of_days.isna().all()
        span = (pd.to_datetime(rows["date"]).max() - pd.to_datetime(rows["date"]).min()).days + 1
        if len(rows) < span:
            expected.append(f"totals over the {len(rows)} days evaluated, not the {span} from "
                            f"{rows['date'].min()} to {rows['date'].max()}")
        assert (row["note"] if isinstance(row["note"], str) else "") == "; ".join(expected)
    # The case each run is about: each solstice its own best angle, or one angle for all days.
    assert days[days["design"] == "twofold"]["fold_angle_deg"].nunique() == angles


def _bits(values):
    return np.asarray(values, dtype=float).view(np.int64)


@pytest.mark.parametrize("model", MODELS)
def test_pair_searches_a_block_at_a_time_are_the_searches_at_once(model, monkeypatch):
    """Over many pairs (an electrical table's 51,681) the searches run a block of curves at a time:
    every pair's power is, to the bit, that of one pass over all of them, at the curves' shape."""
    from foldopt.physics import connections

    rng = np.random.default_rng(5)
    poa_east = rng.uniform(0, 1500, (12, 25))
    poa_west = poa_east * rng.choice([1.0, 0.5, 0.01, 1e-6, 0.0], poa_east.shape)
    temp = rng.uniform(-10, 70, poa_east.shape)

    def solved():
        east = MODELS[model].curves(poa_east, cell_temperature(poa_east, temp, 1.0, "sapm"), AREA)
        west = MODELS[model].curves(poa_west, cell_temperature(poa_west, temp, 1.0, "sapm"), AREA)
        return [parallel_power(east, west), series_power(east, west, False), series_power(east, west, True)]

    at_once = solved()
    monkeypatch.setattr(connections, "_BLOCK", 128)  # three blocks of 100
    for blocked, whole in zip(solved(), at_once, strict=True):
        assert blocked.shape == poa_east.shape
        assert np.array_equal(_bits(blocked), _bits(whole))


@settings(max_examples=25, deadline=None)
@given(values=st.lists(st.floats() | st.sampled_from([0.0, -0.0, np.inf, np.nan, np.finfo(float).max]), min_size=1,
                       max_size=20),
       voc=st.floats(0.0, 1e3) | st.sampled_from([0.0, -0.0]))
def test_the_searches_clip_and_replace_nan_as_numpy_does(values, voc):
    """The searches' short forms of numpy.nan_to_num and clip give NumPy's values to the bit
    (signed zeros too): a sourced current, a voltage within [0, Voc], a power NaN is least."""
    from foldopt.physics.connections import _finite, _inside, _sourced

    x, vocs = np.array(values), np.full(len(values), voc)
    with np.errstate(all="ignore"):
        assert np.array_equal(_bits(_sourced(x)), _bits(np.nan_to_num(np.clip(x, 0.0, None))))
        assert np.array_equal(_bits(_inside(x, vocs)), _bits(np.clip(np.nan_to_num(x), 0.0, vocs)))
        powers = x[x != -np.inf]  # a power is never -inf (voltages and currents >= 0)
        assert np.array_equal(_bits(_finite(powers)), _bits(np.nan_to_num(powers, nan=-np.inf)))
