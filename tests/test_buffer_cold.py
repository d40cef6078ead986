"""The buffer in the cold (issue 50, part 2): the physics against its cited datasheet values, the
engine's cold against its identities (no cold and a warm one are today's answer to the bit, energy
conserved, no charge below the charge limit, a colder series never powers more where the model
says so, the compiled loop equals the NumPy reference), and the storage section's fields."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from pydantic import ValidationError

import foldopt
from foldopt.engine import storage
from foldopt.engine.storage import Buffer, ColdSteps, simulate
from foldopt.inputs.storage_section import PRESETS, Storage
from foldopt.inputs.study import make_study
from foldopt.physics.buffer_temperature import (
    capacity_fraction,
    cold_cut_off,
    leak_factor,
)
from foldopt.studies.storage_cold import cold_columns, cold_steps
from tests.test_storage_engine import balance, buffers, curves, own_draws

ENGINES = storage.STORAGE_ENGINES
SOME = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def temperatures(data, power, lo=-30.0, hi=40.0):
    """Air temperatures [C] at each step of ``power``'s days: one for every series, or one per
    series."""
    shape = power.shape if data.draw(st.booleans()) else (1, *power.shape[1:])
    return data.draw(arrays(float, shape, elements=st.floats(lo, hi)))


def storages(data):
    """A storage section of a preset (or a custom cold), cold on."""
    preset = data.draw(st.sampled_from(sorted(PRESETS)))
    offset = data.draw(st.floats(-10.0, 20.0))
    return Storage(capacity_wh=1.0, preset=preset, enclosure_offset_c=offset)


# The physics against its sources.


def test_lifepo4_capacity_and_limits_are_the_cited_datasheets():
    """Canbat CLI100-12: about 80 Ah of 100 at 0 C and 70 Ah at -20 C, all of it at 25 C; Sunland
    IFR10440 and EPEVER: no charge below 0 C, no discharge below -20 C."""
    lfp = Storage(capacity_wh=1.0, preset="lifepo4")
    share = capacity_fraction([-20.0, 0.0, 25.0, -30.0, 35.0], lfp.capacity_curve)
    np.testing.assert_allclose(share, [70 / 100, 80 / 100, 1.0, 0.70, 1.0])
    assert (lfp.charge_min_c, lfp.discharge_min_c) == (0.0, -20.0)
    steps = cold_steps(lfp, np.array([-20.5, -0.1, 0.0, 10.0]))
    np.testing.assert_array_equal(steps.charge, [False, False, True, True])
    np.testing.assert_array_equal(steps.discharge, [False, True, True, True])


def test_nmc_capacity_and_limits_are_the_cited_datasheets():
    """Li-ion 18650: charge 0 to 45 C, discharge -20 to 60 C (Yok Energy); 70 % of the rated
    capacity at 0 F = -17.8 C (X2Power); 5 %/month self-discharge at 25 C."""
    nmc = Storage(capacity_wh=1.0, preset="nmc")
    assert (nmc.charge_min_c, nmc.discharge_min_c) == (0.0, -20.0)
    assert capacity_fraction(-18.0, nmc.capacity_curve) == pytest.approx(0.70)
    assert 1.0 - (1.0 - nmc.self_discharge) ** 30 == pytest.approx(0.05, abs=1e-3)


def test_supercapacitor_leak_is_the_cited_leakage_ratio():
    """Nanoramic: leakage below 1 uA at -55 C and below 30 uA at 85 C: the rate's doubling every
    28.5 C gives the ratio 30 across the two; the rate at 25 C is the stated one."""
    cap = Storage(capacity_wh=1.0, preset="supercapacitor")
    ratio = leak_factor(85.0, cap.self_discharge_doubling_c) / leak_factor(
        -55.0, cap.self_discharge_doubling_c
    )
    assert ratio == pytest.approx(30.0, rel=0.01)
    assert leak_factor(25.0, cap.self_discharge_doubling_c) == 1.0
    assert leak_factor(35.0, 10.0) == pytest.approx(2.0)
    assert (cap.charge_min_c, cap.discharge_min_c) == (-40.0, -40.0)  # Maxwell HC: -40 to 65 C


@given(st.floats(0.0, 1.0), st.floats(0.01, 1.0))
def test_the_cold_cut_off_keeps_the_usable_share(min_soc, share):
    """The raised cut-off leaves ``share`` of the usable range; a share of 1 is the cut-off to
    the bit."""
    floor = cold_cut_off(min_soc, share)
    assert 1.0 - floor == pytest.approx(share * (1.0 - min_soc), abs=1e-12)
    assert cold_cut_off(min_soc, 1.0) == min_soc


# The engine's cold.


def warm(shape):
    """A temperature that changes nothing: every charge and discharge allowed, all the capacity,
    the stated leak."""
    return ColdSteps(np.ones(shape, bool), np.ones(shape, bool), np.ones(shape), np.ones(shape))


@SOME
@given(curves(), st.data())
def test_no_cold_and_a_warm_one_are_today_to_the_bit(curve, data):
    """A warm temperature's arrays run the loops' cold path and give every output of the run
    without them, to the bit, on both engines."""
    power, step = curve
    buffer, draw = data.draw(buffers()), own_draws(data, power)
    for engine in ENGINES:
        today = simulate(power, 2.0, buffer, step, engine, soc_curves=True, draw=draw)
        same = simulate(
            power, 2.0, buffer, step, engine, soc_curves=True, draw=draw, cold=warm(power.shape)
        )
        for name in storage.StorageResult._fields:
            np.testing.assert_array_equal(getattr(today, name), getattr(same, name), name)


def test_the_cold_off_or_no_cold_data_is_no_cold():
    """``cold: false``, a buffer without cold data, or a temperature at which nothing acts gives
    the engine no cold (the run without it); a preset's cold data acts in the cold."""
    temperature = np.full((2, 24), -15.0)
    assert cold_steps(Storage(capacity_wh=5.0, preset="lifepo4", cold=False), temperature) is None
    assert cold_steps(Storage(capacity_wh=5.0), temperature) is None
    assert cold_steps(Storage(capacity_wh=5.0, preset="lifepo4"), temperature) is not None
    assert cold_steps(Storage(capacity_wh=5.0, preset="lifepo4"), temperature + 40.0) is None
    # A supercapacitor leaks its stated rate at 25 C only.
    assert cold_steps(Storage(capacity_wh=5.0, preset="supercapacitor"), 25.0) is None
    assert cold_steps(Storage(capacity_wh=5.0, preset="supercapacitor"), 24.0) is not None


@SOME
@given(curves(), st.data())
def test_energy_is_conserved_in_the_cold(curve, data):
    """served + drawn + lost + delta stored + losses + self-discharge = harvested, each day, for
    every buffer, load and temperature of every preset, on both engines, which agree to the
    bit."""
    power, step = curve
    loads = data.draw(arrays(float, power.shape[0], elements=st.floats(0.0, 15.0)))
    buffer, draw = data.draw(buffers()), own_draws(data, power)
    cold = cold_steps(storages(data), temperatures(data, power))
    results = [
        simulate(power, loads, buffer, step, engine, draw=draw, cold=cold, soc_curves=True)
        for engine in ENGINES
    ]
    for result in results:
        np.testing.assert_allclose(balance(result), 0.0, atol=1e-9 * (1 + power.sum()))
        needed = np.broadcast_to(loads[:, None] * 24.0, result.served_wh.shape)
        np.testing.assert_allclose(result.served_wh + result.missing_wh, needed, atol=1e-9)
    for name in storage.StorageResult._fields:
        np.testing.assert_array_equal(getattr(results[0], name), getattr(results[1], name), name)


@SOME
@given(curves(max_series=2), st.data())
def test_lifepo4_never_charges_below_its_charge_limit(curve, data):
    """Between two step centres at least one of which is below 0 C the content of a LiFePO4
    never rises (it leaks or is drawn); it does charge where it is warm."""
    power, step = curve
    lfp = Storage(capacity_wh=1.0, preset="lifepo4")
    temperature = temperatures(data, power, -10.0, 10.0)
    buffer = Buffer(capacity_wh=data.draw(st.floats(1.0, 60.0)), min_soc=0.2, initial_soc=0.5)
    for engine in ENGINES:
        result = simulate(
            power, 0.5, buffer, step, engine, soc_curves=True, cold=cold_steps(lfp, temperature)
        )
        cold = np.broadcast_to(temperature < 0.0, power.shape)
        # Within a day, a segment with a cold end; across midnight, the two half steps held at
        # the days' ends, each its own day's (both cold).
        rises = np.diff(result.soc, axis=-1) > 1e-12
        assert not (rises & (cold[..., 1:] | cold[..., :-1])).any()
        overnight = result.soc[:, 1:, 0] - result.soc[:, :-1, -1] > 1e-12
        assert not (overnight & cold[:, 1:, 0] & cold[:, :-1, -1]).any()


@SOME
@given(curves(), st.data())
def test_a_colder_series_never_powers_more(curve, data):
    """Powered time does not rise as every step gets colder, to within one step, where a charge
    limit is what the cold does, for a buffer without hysteresis that does not leak, from an
    empty buffer: less is stored at every instant (the step: the load reconnects at a part's
    start). Not asserted where the cold blocks the discharge or raises the cut-off (energy kept
    for a later, warmer step can run the load longer then), for a leak that slows in the cold,
    or between periodic states (the cold one may be another)."""
    power, step = curve
    section = Storage(capacity_wh=1.0, charge_min_c=data.draw(st.floats(-10.0, 10.0)))
    base = data.draw(buffers(hysteresis=False, leak=False))
    buffer = base._replace(initial_soc=base.min_soc)
    temperature = temperatures(data, power)
    colder = temperature - data.draw(st.floats(0.0, 30.0))
    for engine in ENGINES:
        runs = [
            simulate(power, 1.5, buffer, step, engine, cold=cold_steps(section, t)).powered_h
            for t in (temperature, colder)
        ]
        assert (runs[1].sum(axis=1) <= runs[0].sum(axis=1) + step + 1e-9).all()


def test_a_blocked_charger_loses_the_surplus_and_a_blocked_discharge_cuts_the_load():
    """A bright day with the charge blocked stores nothing (the surplus is lost, as over a full
    buffer); a dark day with the discharge blocked runs nothing (the energy stays stored)."""
    power = np.array([[0.0, 5.0, 5.0, 0.0]])
    buffer = Buffer(capacity_wh=10.0, initial_soc=0.5)
    blocked = ColdSteps(np.zeros(4, bool), np.ones(4, bool), np.ones(4), np.ones(4))
    for engine in ENGINES:
        result = simulate(power, 1.0, buffer, 6.0, engine, cold=blocked)
        assert result.stored_wh[0, -1] <= result.stored_wh[0, 0]
        assert result.charge_loss_wh.sum() == 0.0
        dark = simulate(
            np.zeros((1, 4)),
            1.0,
            buffer,
            6.0,
            engine,
            cold=blocked._replace(charge=np.ones(4, bool), discharge=np.zeros(4, bool)),
        )
        assert dark.powered_h.sum() == 0.0
        assert dark.stored_wh[0, -1] == dark.stored_wh[0, 0]


def test_the_cold_capacity_raises_the_cut_off():
    """At half the capacity usable, a buffer carries a dark load on half its usable energy: the
    load runs half as long, and the rest stays stored."""
    buffer = Buffer(capacity_wh=10.0, min_soc=0.2, initial_soc=1.0)
    half = ColdSteps(np.ones(24, bool), np.ones(24, bool), np.full(24, 0.5), np.ones(24))
    for engine in ENGINES:
        full = simulate(np.zeros((1, 24)), 1.0, buffer, 1.0, engine)
        cold = simulate(np.zeros((1, 24)), 1.0, buffer, 1.0, engine, cold=half)
        assert full.powered_h[0, 0] == pytest.approx(8.0)
        assert cold.powered_h[0, 0] == pytest.approx(4.0)
        assert cold.stored_wh[0, -1] == pytest.approx(6.0)


def test_cold_columns_say_the_worst_month():
    """The powered time lost is the warm run's less the cold one's, per day, and the worst month
    is the one with the largest mean loss."""
    powered = np.array([[24.0, 20.0, 24.0, 24.0]])
    warm_run = np.array([[24.0, 24.0, 24.0, 24.0]])
    said = cold_columns(powered, warm_run, [1, 1, 2, 2])
    assert said["cold_lost_mean_h"][0] == 1.0
    assert said["cold_lost_worst_month_h"][0] == 2.0
    assert said["cold_worst_month"][0] == 1
    assert (said["cold_lost_month01_mean_h"][0], said["cold_lost_month02_mean_h"][0]) == (2.0, 0.0)
    assert cold_columns(powered, powered, [1, 1, 2, 2])["cold_worst_month"][0] == 0


# The section's fields.


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"charge_min_c": 61.0}, "charge_min_c"),
        ({"discharge_min_c": -70.0}, "discharge_min_c"),
        ({"capacity_curve": [[0.0, 0.9], [-5.0, 1.0]]}, "capacity_curve"),
        ({"capacity_curve": [[0.0, 0.9], [5.0, 0.8]]}, "capacity_curve"),
        ({"capacity_curve": [[0.0, 0.0]]}, "capacity_curve"),
        ({"self_discharge_doubling_c": 0.0}, "self_discharge_doubling_c"),
        ({"enclosure_offset_c": 80.0}, "enclosure_offset_c"),
    ],
)
def test_a_bad_cold_field_is_refused_naming_it(change, field):
    with pytest.raises(ValidationError, match=field):
        Storage(capacity_wh=1.0, **change)


def test_a_bad_cold_field_exits_2_in_one_line(tmp_path):
    """The command line refuses a charge limit above 60 C in one line naming the field, exit 2,
    writing nothing."""
    study = tmp_path / "cold.yaml"
    study.write_text(
        "name: cold\nmode: exact\nsite: {latitude: 45.0, longitude: 8.0}\ndate: 2021-01-15\n"
        "panel: {area: 0.4, efficiency: 0.19}\np_load: 1.0\n"
        "storage: {preset: lifepo4, capacity_wh: 5, charge_min_c: 70}\n"
    )
    out = tmp_path / "out"
    run = subprocess.run(
        [sys.executable, "-m", "foldopt.cli.app", "run", str(study), "--out", str(out)],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 2, run.stderr
    said = (run.stdout + run.stderr).strip().splitlines()
    assert len(said) == 1 and "charge_min_c" in said[0], said
    assert "Traceback" not in run.stderr
    assert not out.exists()


def test_a_cold_preset_fills_and_a_given_field_wins():
    section = Storage(capacity_wh=1.0, preset="lifepo4", charge_min_c=5.0)
    assert section.charge_min_c == 5.0
    assert section.discharge_min_c == -20.0
    assert "charge_min_c" not in section.decided
    assert "discharge_min_c" in section.decided
    assert math.isclose(section.min_soc, 0.2)


# Through the studies: the cold off, and a warm temperature, are today's answers to the bit.

ROOT = Path(__file__).resolve().parent.parent
#: The camera of issue 50 at 45 N 8 E (a clear-sky day in January), quick: 5-min steps, every
#: 10 deg.
CAMERA = {
    "name": "camera",
    "mode": "exact",
    "site": {"latitude": 45.0, "longitude": 8.0},
    "date": "2021-01-15",
    "panel": {"area": 0.4, "efficiency": 0.1905},
    "p_load": 2.0,
    "step_min": 5,
    "fold_angles": {"start": 10, "stop": 180, "step": 10},
}
SERIES = {
    "weather": {
        "path": str(ROOT / "tests/data/pvgis/seriescalc_45.000_8.000_2020_2021.json"),
        "format": "pvgis-hourly",
    },
}
LFP = {"preset": "lifepo4", "capacity_wh": 20, "target": {"powered_h": 12}}


def _shared(cold: pd.DataFrame, off: pd.DataFrame) -> None:
    """Every column of the run with the cold off is the cold run's, to the bit."""
    pd.testing.assert_frame_equal(cold[list(off.columns)], off, check_exact=True)


def test_a_warm_day_is_the_day_with_the_cold_off_to_the_bit():
    """The clear-sky day at 25 C (a LiFePO4 at full capacity, charging) is the day with ``cold:
    false`` and says nothing of the cold; at -5 C its charger is blocked all day."""
    runs = {
        name: foldopt.run(
            make_study({**CAMERA, "temp_air": t, "storage": {**LFP, **cold}}),
            engine="numba",
        ).storage
        for name, t, cold in [
            ("warm", 25.0, {}),
            ("off", -5.0, {"cold": False}),
            ("cold", -5.0, {}),
            ("warm_off", 25.0, {"cold": False}),
        ]
    }
    _shared(runs["warm"].designs, runs["warm_off"].designs)
    _shared(runs["warm"].sizing.table, runs["warm_off"].sizing.table)
    np.testing.assert_array_equal(runs["warm"].powered_by_angle, runs["warm_off"].powered_by_angle)
    assert "cold_lost_h" not in runs["warm"].designs
    assert "cold_lost_h" not in runs["off"].designs
    cold = runs["cold"].designs.set_index("design")
    assert (cold["charge_blocked_h"] == 24.0).all()
    off = runs["off"].designs.set_index("design")
    np.testing.assert_allclose(cold["cold_lost_h"], off["powered_h"] - cold["powered_h"])


@pytest.mark.parametrize(
    "days", [["2021-01-05", "2021-01-06", "2021-01-07"], ["2021-01-05", "2021-01-08"]]
)
def test_a_warm_series_is_the_series_with_the_cold_off_to_the_bit(days):
    """Recorded January days at 45 N 8 E, in sequence and each repeated alone: the buffer 60 C
    above the air (nothing acts) is the run with ``cold: false``; as it is, the cold blocks the
    charger on some days and the table says what it costs, beside the run with the cold off."""

    def year(storage):
        study = make_study({**CAMERA, **SERIES, "step_min": 60, "storage": storage})
        return foldopt.sweep(study, "day", date=days, objective="mean").extras["storage_annual"]

    off = year({**LFP, "cold": False})
    warm = year({**LFP, "enclosure_offset_c": 60.0})
    cold = year(LFP)
    _shared(warm, off)
    assert "cold_lost_mean_h" not in warm and "capacity_cold_off_wh" not in off
    np.testing.assert_array_equal(cold["capacity_cold_off_wh"], off["capacity_wh"])
    assert (cold["charge_blocked_h"] > 0).all()
    np.testing.assert_allclose(
        cold["cold_lost_mean_h"], off["powered_mean_h"] - cold["powered_mean_h"], atol=1e-12
    )
