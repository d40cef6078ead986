"""The connections as built (foldopt.physics.circuit, foldopt.physics.diodes) against references
computed here: each sub-panel's curve sampled densely (pvlib's bishop88 for the single-diode model,
the curve's own closed form for the b-model), each diode's drop by its own formula, the branches
combined by interpolation on a common voltage or current grid, and the maximum taken."""

import json

import numpy as np
import pandas as pd
import pvlib
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pvlib.singlediode import bishop88
from typer.testing import CliRunner

import foldopt
from foldopt import names
from foldopt.cli.app import app
from foldopt.engine.cell_tables import electrical_for
from foldopt.studies.engine_options import engine_options
from foldopt.physics import circuit, connections
from foldopt.physics.diodes import DEFAULT_DIODE_PART, DIODE_PARTS, Diode, diode
from foldopt.physics.pvmodel import PVModel

AREA = 0.054  # a sub-panel of the paper's 0.108 m^2 panel
MODELS = {"single-diode": PVModel("single-diode"), "b-model": PVModel("b-model", efficiency=0.19)}
SAMPLES = 20001
#: The drops the tests combine, written out here: MBR745's SPICE model (LTspice standard.dio:
#: Is = 159 uA, N = 1.76, Rs = 0.02 ohm) at 25 C, and a constant 0.45 V.
KT_Q = 1.380649e-23 * 298.15 / 1.602176634e-19
DROPS = {
    "constant": (diode("constant", forward_voltage=0.45), lambda i: np.full_like(i, 0.45)),
    "shockley": (diode("shockley"), lambda i: 1.76 * KT_Q * np.log(1 + i / 159e-6) + 0.02 * i),
}
#: Relative tolerance of the sampled references (their grids' resolution; seen: 3e-8).
RTOL = 2e-6

irradiance = st.floats(0.0, 1200.0)
temperature = st.floats(0.0, 60.0)


def curves(poa_east, poa_west, temp=25.0, model="single-diode"):
    pv = MODELS[model]
    return (pv.curves(np.atleast_1d(np.asarray(poa, dtype=float)), temp, AREA) for poa in (poa_east, poa_west))


def sampled(curve):
    """Current and voltage of a one-element curve from slightly past short circuit to open circuit,
    the voltage increasing; geometrically denser towards open circuit, where a Shockley diode's
    turn-on (its drop falls to 0 with the current) makes the output voltage rise steeply."""
    voc = float(curve.v_oc[0])
    near_open = voc - np.geomspace(1e-12, voc + 0.05, SAMPLES)
    diode_voltage = np.unique(np.concatenate([np.linspace(-0.05, voc, SAMPLES), near_open]))
    if curve.model == "single-diode":
        params = [float(np.ravel(p)[0]) for p in curve.params]
        current, voltage, _ = bishop88(diode_voltage, *params)
    else:
        voltage = diode_voltage
        current = curve.current(voltage[None, :])[0]
    keep = current >= 0
    return current[keep], voltage[keep]


def reference_parallel(east, west, drop, switch_resistance, bus=None, samples=None):
    """The pair's best power on a bus grid (or at the bus voltage ``bus``); ``samples``: the two
    curves' :func:`sampled`, where the caller has them."""
    grid = np.linspace(0.0, max(float(east.v_oc[0]), float(west.v_oc[0]), 1e-9), SAMPLES) if bus is None else bus
    total = np.zeros_like(np.atleast_1d(grid))
    for current, voltage in samples or map(sampled, (east, west)):
        if current.size:
            out = voltage - drop(current) - current * switch_resistance  # increasing along the sample
            total = total + np.interp(grid, out, current, right=0.0)
    return float(np.max(grid * total, initial=0.0))


def string(east, west, drop, switch_resistance, current, samples=None):
    """The series string's voltage at ``current``, each sub-panel bypassed past its Isc;
    ``samples`` as :func:`reference_parallel`'s."""
    total = -current * switch_resistance
    for curve, (i, v) in zip((east, west), samples or map(sampled, (east, west)), strict=True):
        isc = float(curve.i_sc[0])
        inside = np.interp(np.minimum(current, isc), i[::-1], v[::-1]) if i.size else np.zeros_like(current)
        total = total + np.where(current <= isc, inside, -drop(np.maximum(current - isc, 0.0)))
    return total


def reference_series(east, west, drop, switch_resistance):
    """The string's best power on a current grid; ``drop`` None: no bypass diodes."""
    iscs = float(east.i_sc[0]), float(west.i_sc[0])
    current = np.linspace(0.0, max(iscs) if drop is not None else min(iscs), SAMPLES)
    voltage = string(east, west, drop if drop is not None else (lambda i: np.zeros_like(i)), switch_resistance,
                     current)
    return float(np.max(current * voltage, initial=0.0))


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("kind", DROPS)
@settings(max_examples=12, deadline=None)
@given(poa_east=irradiance, poa_west=irradiance, temp=temperature, switch_resistance=st.sampled_from([0.0, 0.04]))
def test_parallel_matches_the_sampled_curves(model, kind, poa_east, poa_west, temp, switch_resistance):
    built, drop = DROPS[kind]
    east, west = curves(poa_east, poa_west, temp, model)
    expected = reference_parallel(east, west, drop, switch_resistance)
    power = circuit.parallel_power(east, west, built, switch_resistance=switch_resistance)[0]
    assert power == pytest.approx(expected, rel=RTOL, abs=1e-9)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("kind", [*DROPS, None])
@settings(max_examples=12, deadline=None)
@given(poa_east=irradiance, poa_west=irradiance, temp=temperature, switch_resistance=st.sampled_from([0.0, 0.04]))
def test_series_matches_the_sampled_curves(model, kind, poa_east, poa_west, temp, switch_resistance):
    built, drop = DROPS[kind] if kind else (None, None)
    east, west = curves(poa_east, poa_west, temp, model)
    expected = reference_series(east, west, drop, switch_resistance)
    power = circuit.series_power(east, west, built, switch_resistance=switch_resistance)[0]
    assert power == pytest.approx(expected, rel=RTOL, abs=1e-9)


@pytest.mark.parametrize("model", MODELS)
@settings(max_examples=15, deadline=None)
@given(poa=irradiance, temp=temperature, switch_resistance=st.floats(0.0, 0.2))
def test_alone_through_a_switch_matches_the_sampled_curve(model, poa, temp, switch_resistance):
    curve, _ = curves(poa, poa, temp, model)
    current, voltage = sampled(curve)
    expected = float(np.max(current * (voltage - current * switch_resistance), initial=0.0))
    assert circuit.alone_power(curve, switch_resistance=switch_resistance)[0] == pytest.approx(expected, rel=RTOL,
                                                                                               abs=1e-9)


def test_direct_coupling_is_the_current_at_the_load_voltage():
    # pvlib's i_from_v at the load voltage (and at the load voltage plus a constant drop).
    poa = np.array([0.0, 20.0, 150.0, 600.0, 1000.0, 1200.0])
    east, west = curves(poa, poa[::-1], 40.0)
    for load in (0.3, 1.2, 1.9, 2.3, 3.0):
        def i_from_v(curve, v):
            return np.clip(np.nan_to_num(pvlib.pvsystem.i_from_v(v, *curve.params)), 0.0, None)

        np.testing.assert_allclose(circuit.alone_power(east, load_voltage=load), load * i_from_v(east, load),
                                   rtol=1e-12, atol=1e-12)
        expected = load * (i_from_v(east, load + 0.45) + i_from_v(west, load + 0.45))
        np.testing.assert_allclose(circuit.parallel_power(east, west, DROPS["constant"][0], load_voltage=load),
                                   expected, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("kind", DROPS)
def test_direct_coupling_matches_the_sampled_curves(model, kind):
    built, drop = DROPS[kind]
    for poa_east, poa_west in ((1000.0, 1000.0), (900.0, 250.0), (60.0, 700.0)):
        east, west = curves(poa_east, poa_west, 30.0, model)
        samples = sampled(east), sampled(west)  # the loads' references read the same samples
        for load in (0.5, 1.0, 1.6, 2.2):
            expected = reference_parallel(east, west, drop, 0.03, bus=np.array([load]), samples=samples)
            power = circuit.parallel_power(east, west, built, load_voltage=load, switch_resistance=0.03)[0]
            assert power == pytest.approx(expected, rel=1e-6, abs=1e-9)
            current, voltage = samples[0]
            out = voltage - current * 0.03
            assert circuit.alone_power(east, load_voltage=load, switch_resistance=0.03)[0] == pytest.approx(
                load * np.interp(load, out, current, right=0.0), rel=1e-6, abs=1e-9)
            # Series: the current where the string's voltage (decreasing in I) meets the load.
            # Both sides of each Isc, where a constant bypass drop steps the string's voltage.
            iscs = [float(east.i_sc[0]), float(west.i_sc[0])]
            grid = np.unique(np.concatenate([np.linspace(0.0, max(iscs), SAMPLES), iscs,
                                             np.nextafter(iscs, np.inf)]))
            volts = string(east, west, drop, 0.03, grid, samples)
            at = np.interp(2 * load, volts[::-1], grid[::-1], left=grid[-1], right=0.0)
            series = circuit.series_power(east, west, built, load_voltage=2 * load, switch_resistance=0.03)[0]
            assert series == pytest.approx(2 * load * at, rel=1e-4, abs=1e-6)


@pytest.mark.parametrize("model", MODELS)
def test_ideal_parts_are_todays_connections(model):
    rng = np.random.default_rng(3)
    east, west = curves(rng.uniform(0, 1200, 300), rng.uniform(0, 1200, 300), rng.uniform(0, 60, 300), model)
    ideal = Diode("ideal")
    np.testing.assert_allclose(circuit.parallel_power(east, west, ideal), connections.parallel_power(east, west),
                               rtol=1e-9)
    for bypass in (True, False):
        np.testing.assert_allclose(circuit.series_power(east, west, ideal if bypass else None),
                                   connections.series_power(east, west, bypass), rtol=1e-9)
    np.testing.assert_allclose(circuit.alone_power(east), east.max_power(), rtol=1e-9)
    # The solver's own path (a constant 0 V drop is not delegated) reaches the same.
    zero = Diode("constant", forward_voltage=0.0)
    np.testing.assert_allclose(circuit.parallel_power(east, west, zero), connections.parallel_power(east, west),
                               rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(circuit.series_power(east, west, zero), connections.series_power(east, west, True),
                               rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(circuit.alone_power(east, switch_resistance=1e-300), east.max_power(),
                               rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("model", MODELS)
def test_drops_and_resistance_never_help(model):
    rng = np.random.default_rng(4)
    east, west = curves(rng.uniform(0, 1200, 200), rng.uniform(0, 1200, 200), rng.uniform(0, 60, 200), model)
    slack = 1e-9

    def never_above(lower, upper):
        assert np.all(lower <= upper * (1 + slack) + 1e-12)

    drops = [diode("constant", forward_voltage=v) for v in (0.0, 0.2, 0.4, 0.6)]
    for weaker, stronger in zip(drops[1:], drops[:-1]):
        never_above(circuit.parallel_power(east, west, weaker), circuit.parallel_power(east, west, stronger))
        never_above(circuit.series_power(east, west, weaker), circuit.series_power(east, west, stronger))
    ideal = Diode("ideal")
    for part in (diode("shockley"), diode("constant")):
        never_above(circuit.parallel_power(east, west, part), connections.parallel_power(east, west))
        never_above(circuit.series_power(east, west, part), connections.series_power(east, west, True))
        # A bypass diode, however lossy, never does worse than none.
        never_above(circuit.series_power(east, west, None), circuit.series_power(east, west, part))
    for resistance in (0.01, 0.1):
        never_above(circuit.alone_power(east, switch_resistance=resistance), circuit.alone_power(east))
        never_above(circuit.parallel_power(east, west, ideal, switch_resistance=resistance),
                    circuit.parallel_power(east, west, ideal))
        never_above(circuit.series_power(east, west, diode("shockley"), switch_resistance=resistance),
                    circuit.series_power(east, west, diode("shockley")))


def test_switching_takes_the_best_state():
    east, west = curves([1000.0, 1000.0, 900.0, 0.0], [1000.0, 30.0, 0.0, 0.0])
    blocking, bypass = diode("constant", forward_voltage=0.4), diode("shockley")
    power, state = circuit.switching_power(east, west, blocking, bypass, switch_series=True, switch_resistance=0.02)
    states = np.stack([circuit.alone_power(east, switch_resistance=0.02),
                       circuit.alone_power(west, switch_resistance=0.02),
                       circuit.parallel_power(east, west, blocking, switch_resistance=0.02),
                       circuit.series_power(east, west, bypass, switch_resistance=0.02)])
    np.testing.assert_array_equal(power, states.max(axis=0))
    # Equal light: series (no diode in the string's path). A weak or dark west: east alone, which
    # passes no diode, beats parallel through its 0.4 V drop (10.6 W against 8.6 W at 1000 and
    # 30 W/m^2) and series through the weak one's bypass diode. Both dark: 0, the simplest state.
    assert [circuit.SWITCH_STATES[s] for s in state] == ["series", "east", "east", "east"]
    assert power[-1] == 0.0
    _, state = circuit.switching_power(east, west, blocking, bypass, switch_series=False)
    assert 3 not in state


def test_a_blocking_drop_costs_a_fifth_of_parallel_power():
    # The default embedded sub-panel at 1000 W/m^2, cells at 25 C: 22.42 W in parallel through ideal
    # diodes at 2.02 V. A constant 0.4 V drop costs 19.7 % (the issue estimates 15-22 %); the
    # default part, MBR745, costs 28.0 % as a constant 0.57 V and 28.5 % as its SPICE model.
    east, west = curves(1000.0, 1000.0)
    ideal = connections.parallel_power(east, west)[0]
    loss = 1 - circuit.parallel_power(east, west, diode("constant", forward_voltage=0.4))[0] / ideal
    assert 0.10 < loss < 0.25
    assert loss == pytest.approx(0.197, abs=0.002)
    for model in ("constant", "shockley"):
        assert 1 - circuit.parallel_power(east, west, diode(model))[0] / ideal == pytest.approx(0.28, abs=0.01)


def test_diodes_are_their_datasheets():
    # MBR745: datasheet 0.57 V at 7.5 A (T_J = 125 C); SPICE model Is 159 uA, N 1.76, Rs 0.02 ohm.
    assert DEFAULT_DIODE_PART == "mbr745" and DIODE_PARTS["mbr745"].average_current >= 6.0
    np.testing.assert_array_equal(diode().drop([0.0, 5.5]), [0.57, 0.57])
    current = np.array([0.0, 1e-3, 1.0, 5.5, 7.5])
    np.testing.assert_allclose(diode("shockley").drop(current), DROPS["shockley"][1](current), rtol=1e-6)
    assert 0.55 < float(diode("shockley").drop(5.5)) < 0.62
    np.testing.assert_array_equal(diode("ideal").drop(current), 0.0)
    # The differential resistance is the drop's slope.
    shockley, step = diode("shockley", temperature=60.0), 1e-6
    slope = (shockley.drop(current + step) - shockley.drop(current)) / step
    np.testing.assert_allclose(shockley.resistance(current + step / 2), slope, rtol=1e-4)


def test_bad_diodes_are_refused_with_the_valid_names():
    with pytest.raises(ValueError, match="ideal, constant, shockley"):
        diode("schottky")
    with pytest.raises(ValueError, match="ideal, constant, shockley"):
        Diode("schottky")
    with pytest.raises(ValueError, match=", ".join(DIODE_PARTS)):
        diode("constant", part="1n4007")
    with pytest.raises(ValueError, match="no datasheet forward voltage"):
        diode("constant", part="pds760")
    with pytest.raises(ValueError, match="forward_voltage"):
        diode("constant", vf=0.4)
    with pytest.raises(ValueError, match=">= 0"):
        diode("constant", forward_voltage=-0.1)
    assert names.DIODE_MODELS in names.REGISTRIES
    assert tuple(names.DIODE_MODELS) == ("ideal", "constant", "shockley")


@pytest.mark.filterwarnings("error")  # pvlib's overflow at a load far above open circuit once reached stderr
@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("switch_resistance", [0.0, 0.03])
def test_a_load_beyond_the_panels_reach_draws_nothing_and_warns_nothing(model, switch_resistance):
    """Wired directly, a connection delivers ``V I`` with ``0 <= I <= I_sc``: nothing where the load's
    voltage is above every open-circuit voltage it could reach (a string's is the sum of its two), and
    at most ``V`` times the short-circuit currents at a load voltage near 0 V. Cold cells (-20 C) have
    the highest open-circuit voltage, dark ones none."""
    rng = np.random.default_rng(5)
    poa = np.concatenate([[0.0, 1e-6, 1000.0, 1500.0], rng.uniform(0, 1500, 8)])
    for temp in (-20.0, 80.0):
        east, west = curves(poa, poa[::-1], temp, model)
        string_voc = float(np.max(east.v_oc + west.v_oc))
        isc = east.i_sc + west.i_sc
        for blocking, bypass in ((Diode("ideal"), Diode("ideal")), (DROPS["shockley"][0], DROPS["constant"][0])):
            def every(load):
                return [circuit.alone_power(east, load, switch_resistance), circuit.alone_power(west, load,
                                                                                                  switch_resistance),
                        circuit.parallel_power(east, west, blocking, load, switch_resistance),
                        circuit.series_power(east, west, bypass, load, switch_resistance),
                        circuit.series_power(east, west, None, load, switch_resistance),
                        circuit.switching_power(east, west, blocking, bypass, True, load, switch_resistance)[0]]

            for load in (string_voc * 1.001, 900.0):
                for power in every(load):
                    np.testing.assert_array_equal(power, 0.0)
            for load in (1e-3,):
                for power in every(load):
                    assert np.all(np.isfinite(power)) and np.all(power >= 0.0)
                    assert np.all(power <= load * isc * (1 + 1e-9))


def _designs_of(answer_designs) -> pd.DataFrame:
    return pd.DataFrame(answer_designs).set_index("design")


@pytest.mark.parametrize(("load_voltage", "fresh"), [(900.0, True), (0.001, False)], ids=["900V", "1mV"])
def test_a_load_wired_out_of_reach_runs_no_design_wired_to_it(tmp_path, monkeypatch, recwarn, load_voltage, fresh):
    """A load wired directly above the panel's open-circuit voltage (some 5 V for the paper's panel)
    draws nothing, and at 1 mV at most 1 mV times the short-circuit current: every design wired to it
    runs 0 h, in summary.csv and in the JSON answer alike. The independent connection keeps its two
    converters (Shin et al.'s upper bound): its row says so. No warning is raised, the tables at 900 V
    built afresh (where pvlib once overflowed)."""
    if fresh:
        monkeypatch.setenv("FOLDOPT_CACHE_DIR", str(tmp_path / "cache"))
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["sweep", "angle", "--pv-model", "single-diode", "--load-voltage",
                                      str(load_voltage), "--angle-step", "10", "--out", str(out), "--format",
                                      "json"])
    assert result.exit_code == 0, result.output
    assert result.stderr == "" and not [str(w.message) for w in recwarn]
    answer = json.loads(result.stdout)["answer"]
    summary = pd.read_csv(out / "summary.csv", keep_default_na=False).set_index("design")
    shown = _designs_of(answer["designs"])
    assert list(shown.index) == list(summary.index)
    wired = summary.index != "twofold-independent"
    assert {"flat", "twofold", "twofold-parallel", "twofold-series", "tracker", "tracker-net"} <= set(summary.index)
    assert (summary.loc[wired, "t_solar_h"] == 0).all() and (shown.loc[wired, "t_solar_h"] == 0).all()
    assert answer["result"]["t_solar_h"] == 0 and set(answer["result"]["t_solar_by_design_h"].values()) == {0}
    # Their peak: V times at most both halves' short-circuit current (bounded at 1500 W/m^2, 85 C).
    isc = 2 * float(MODELS["single-diode"].curves(np.array([1500.0]), 85.0, AREA).i_sc[0])
    assert (summary.loc[wired, "peak_power_w"] <= load_voltage * isc).all()
    assert (summary.loc[wired, "peak_power_w"] == 0).all() == (load_voltage > 1)
    # The paper's panel behind its converters runs most of the day: the row says it is not wired directly.
    note = f"with a converter per sub-panel, not the load wired directly at {load_voltage:g} V"
    assert summary.loc["twofold-independent", "t_solar_h"] > 8
    assert summary.loc["twofold-independent", "note"].split("; ")[0] == note
    assert {"note": note, "designs": ["twofold-independent"]} in answer["notes"]
    assert not any(note in text for text in summary.loc[wired, "note"])
    # Why the others run 0 h: at 900 V, the panel's open-circuit voltage (at STC, pvlib's) on every row
    # wired to the load; at 1 mV it is the load that is above their peak.
    stc = pvlib.pvsystem.v_from_i(0.0, *MODELS["single-diode"].curves(np.array([1000.0]), 25.0, 2 * AREA).params)
    reach = (f"the load's 900 V is above the panel's open-circuit voltage, {stc[0]:.3g} V at STC with all its "
             f"cells in series")
    firsts = [text.split("; ")[0] for text in summary["note"]]
    if load_voltage > 1:
        assert [first == reach for first in firsts] == list(wired)
        assert {"note": reach, "designs": list(summary.index[wired])} in answer["notes"]
    else:
        assert not any("open-circuit" in text for text in summary["note"])
        assert (summary.loc[wired, "note"].str.contains("load above peak")).all()


@pytest.mark.parametrize("model", MODELS)
def test_a_load_is_called_beyond_reach_only_where_no_wiring_reaches_it(model):
    """The note that a load wired directly is above the panel's open-circuit voltage is given where
    every wiring of its cells (each half alone, the halves in parallel or in series, the whole panel
    as one string) delivers nothing in any light up to 2000 W/m^2 on cells from -70 to 85 C, and is
    not given where the whole string in the brightest light on the coldest cells still delivers."""
    def study(load):
        return foldopt.default_study().variant(pv_model=model, circuit={"coupling": "direct", "load_voltage": load})

    pv = electrical_for(engine_options(study(5.0)).electrical, 25.0).pv  # the paper's panel, its halves of AREA
    highest = float(pv.curves(np.array([2000.0]), -70.0, 2 * AREA).v_oc[0])
    poa, temp = (grid.ravel() for grid in np.meshgrid([50.0, 1000.0, 2000.0], [-70.0, 25.0, 85.0]))
    half, whole = pv.curves(poa, temp, AREA), pv.curves(poa, temp, 2 * AREA)
    for factor, beyond in ((1.001, True), (0.999, False)):
        load = factor * highest
        assert bool(electrical_for(engine_options(study(load)).electrical, 25.0).beyond_reach) == beyond
        delivered = [circuit.alone_power(half, load), circuit.alone_power(whole, load),
                     circuit.parallel_power(half, half, Diode("ideal"), load),
                     circuit.series_power(half, half, Diode("ideal"), load)]
        assert (max(float(np.max(power)) for power in delivered) == 0.0) == beyond
