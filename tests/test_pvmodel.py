"""PV models against datasheet / database values and the b-model paper."""

import numpy as np
import pvlib
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from foldopt.physics.pvmodel import A300_CELL, ROBLES_200W, IVCurve, PVModel, cec_module, fit_b
from foldopt.physics.temperature import cell_temperature


def test_a300_cell_reproduces_its_datasheet_point():
    # SunPower A-300 typical STC ratings: Voc 0.670 V, Isc 5.90 A, Vmp 0.560 V, Imp 5.54 A (3.10 W).
    curve = PVModel("single-diode").curves(np.array([1000.0]), 25.0, A300_CELL.area)
    mpp = pvlib.pvsystem.max_power_point(*curve.params, method="newton")
    assert float(mpp["v_mp"][0]) == pytest.approx(0.560, rel=1e-4)
    assert float(mpp["i_mp"][0]) == pytest.approx(5.54, rel=1e-4)
    assert curve.v_oc[0] == pytest.approx(0.670, rel=1e-4)
    assert curve.i_sc[0] == pytest.approx(5.90, rel=1e-4)
    # dVoc/dT -1.9 mV/C, the fifth equation of the De Soto fit.
    warm = PVModel("single-diode").curves(np.array([1000.0]), 35.0, A300_CELL.area)
    assert (warm.v_oc[0] - curve.v_oc[0]) / 10 == pytest.approx(-0.0019, rel=1e-3)


def test_panel_power_scales_with_area_in_series():
    model = PVModel("single-diode")
    one = model.max_power(np.array([800.0]), 40.0, A300_CELL.area)
    assert model.max_power(np.array([800.0]), 40.0, 6.5 * A300_CELL.area) == pytest.approx(6.5 * one, rel=1e-9)
    curve = model.curves(np.array([800.0]), 40.0, 6.5 * A300_CELL.area)
    single = model.curves(np.array([800.0]), 40.0, A300_CELL.area)
    assert curve.v_oc[0] == pytest.approx(6.5 * single.v_oc[0], rel=1e-6)


def test_cec_module_stc_power_matches_the_database():
    from foldopt.physics.pvmodel import _cec_modules

    name = "Canadian_Solar_Inc__CS5P_220M"
    unit = cec_module(name)
    # The database's rated power, from pvlib's table as the process read it once (retrieve_sam).
    stc = float(_cec_modules()[name]["STC"])
    power = PVModel("single-diode", module=name).max_power(np.array([1000.0]), 25.0, unit.area)
    assert power[0] == pytest.approx(stc, rel=2e-3)
    # Any part of the name, without regard to case and punctuation; ambiguous parts and unknown
    # names are told so, with the closest names.
    assert cec_module("cs5p-220m").name == name
    with pytest.raises(ValueError, match="matches .* modules .* give more of the name"):
        cec_module("Canadian_Solar_Inc__CS5P")
    with pytest.raises(ValueError, match="not in pvlib's CEC database; did you mean .*CS5P_220M"):
        cec_module("Canadian Solar CS5P 220N")


def test_b_fitted_from_table1_is_the_papers():
    # Robles Algarin et al.: Vx 32.1 V, Ix 8.21 A, I 7.69 A at V 26.01 V give b = 0.0683; the
    # same Eq. 11 approximation evaluated exactly gives 0.06876 (the paper rounds differently).
    assert ROBLES_200W.b == pytest.approx(0.0683, abs=0.0005)
    assert fit_b(32.1, 8.21, 26.01, 7.69) == pytest.approx(0.068757, abs=1e-6)


def test_b_model_curve_and_closed_form_mpp():
    model = PVModel("b-model", efficiency=0.15)
    curve = model.curves(np.array([1000.0, 400.0]), 25.0, model.unit_area)
    # Eq. 9-10 at STC: Vx = Voc, Ix = Isc.
    assert curve.v_oc[0] == pytest.approx(32.1)
    assert curve.i_sc[0] == pytest.approx(8.21, rel=1e-6)
    # The closed-form maximum equals a brute-force search on Eq. 8, and is Table 1's 200 W
    # within the Eq. 11 approximation (0.2 %).
    voltage = np.linspace(0, 32.1, 200001)
    brute = (voltage * curve.current(np.broadcast_to(voltage, (2, voltage.size)))).max(axis=1)
    np.testing.assert_allclose(curve.max_power(), brute, rtol=1e-7)
    assert curve.max_power()[0] == pytest.approx(200.0, rel=2e-3)
    np.testing.assert_allclose(curve.voltage(curve.current(np.array([12.0, 20.0]))), [12.0, 20.0], rtol=1e-9)


def test_zero_irradiance_gives_zero_power_for_every_model():
    for model in (PVModel("ideal"), PVModel("single-diode"), PVModel("b-model")):
        assert model.max_power(np.array([0.0]), 25.0, 0.1)[0] == pytest.approx(0.0, abs=1e-12)


def test_cell_temperature_models():
    assert cell_temperature(np.array([800.0]), 20.0, 1.0, "fixed")[0] == 20.0
    sapm = pvlib.temperature.sapm_cell(800.0, 20.0, 1.0, -3.56, -0.075, 3)  # open rack glass/polymer
    assert cell_temperature(np.array([800.0]), 20.0, 1.0, "sapm")[0] == pytest.approx(sapm)
    with pytest.raises(ValueError, match="fixed, sapm"):
        cell_temperature(np.array([800.0]), 20.0, 1.0, "noct")
    with pytest.raises(ValueError, match="ideal, single-diode, b-model"):
        PVModel("two-diode")


@pytest.mark.parametrize("model", ["single-diode", "b-model"])
@pytest.mark.parametrize("poa", [500.0, np.array([0.0, 250.0, 1000.0])])
def test_a_curves_points_are_kept_and_its_maximum_power_is_the_callers(model, poa):
    """A curve works out its maximum-power point once (an electrical table's pair asks twice): the
    same values however often it is asked, pvlib's own maximum for the single diode, and
    max_power a new array the caller may write."""
    pv = PVModel(model=model)
    curve = pv.curves(poa, 25.0, 0.054)
    first, again = curve.mpp(), curve.mpp()
    assert all(np.array_equal(a, b) for a, b in zip(first, again, strict=True))
    if model == "single-diode":
        expected = pvlib.pvsystem.max_power_point(*curve.params, method="newton")["p_mp"]
        np.testing.assert_allclose(first[0], np.where(np.asarray(poa) > 0, expected, 0.0), rtol=1e-12)
    power = pv.max_power(poa, 25.0, 0.054)
    power += 1.0  # the caller's own array
    assert np.array_equal(curve.mpp()[0], first[0]) and np.array_equal(pv.max_power(poa, 25.0, 0.054), first[0])


def _diode_curves(poa, temp_cell, module):
    """Single-diode curves of the A-300 cell or a CEC module, with dark ones (R_sh infinite, where
    pvlib's v_from_i takes its explicit form) among them."""
    pv = PVModel("single-diode", module=module)
    return pv.curves(np.asarray(poa), temp_cell, 3.0 * pv.unit_area)


@settings(max_examples=40, deadline=None)
@given(
    poa=st.lists(st.sampled_from([0.0, 1e-9, 1e-3]) | st.floats(0.0, 2000.0), min_size=1, max_size=12),
    temp_cell=st.floats(-70.0, 90.0),
    module=st.sampled_from([None, "CS5P-220M"]),
    fractions=st.lists(st.floats(-0.5, 1.5), min_size=3, max_size=3),
)
def test_current_and_voltage_are_pvlibs_to_the_bit(poa, temp_cell, module, fractions):
    """A curve's current and voltage (its terms of the parameters alone worked out once) are
    pvlib's i_from_v and v_from_i to the bit, inside and beyond the curve, dark curves included,
    at the curves' shape and with a trailing axis of operating points."""
    curve = _diode_curves(poa, temp_cell, module)
    with np.errstate(all="ignore"):
        v_oc = np.nan_to_num(pvlib.pvsystem.v_from_i(0.0, *curve.params))
        i_sc = np.nan_to_num(pvlib.pvsystem.i_from_v(0.0, *curve.params))
    for scale, ours, theirs in ((v_oc, curve.current, pvlib.pvsystem.i_from_v),
                                (i_sc, curve.voltage, pvlib.pvsystem.v_from_i)):
        for point in (fractions[0] * scale, np.asarray(fractions) * scale[:, None]):
            params = [np.reshape(p, p.shape + (1,) * (point.ndim - p.ndim)) for p in curve.params]
            with np.errstate(all="ignore"):
                expected = theirs(point, *params)
            assert np.array_equal(ours(point), expected, equal_nan=True)


def test_current_and_voltage_without_series_or_shunt_resistance_are_pvlibs():
    """Where R_s = 0 (pvlib's i_from_v explicit) or R_sh is infinite (v_from_i explicit), mixed with
    curves that take Lambert W, the values are still pvlib's to the bit."""
    curve = _diode_curves(np.array([800.0, 300.0, 0.0]), 25.0, None)
    il, io, rs, rsh, a = (np.array(p, dtype=float) for p in curve.params)
    rs[0], rsh[1] = 0.0, np.inf
    mixed = IVCurve("single-diode", (il, io, rs, rsh, a))
    points = np.array([0.0, 0.3, 0.9])
    with np.errstate(all="ignore"):
        currents, voltages = (f(points, il, io, rs, rsh, a) for f in (pvlib.pvsystem.i_from_v, pvlib.pvsystem.v_from_i))
    assert np.array_equal(mixed.current(points), currents, equal_nan=True)
    assert np.array_equal(mixed.voltage(points), voltages, equal_nan=True)


@pytest.mark.parametrize("model", ["single-diode", "b-model"])
def test_taken_curves_are_the_curves_at_the_taken_irradiances(model):
    """Curves taken at indices, a curve many times (their points worked out once a curve), are, to
    the bit, the curves of the irradiances so taken with every point worked out again."""
    pv = PVModel(model=model)
    poa = np.array([0.0, 1e-6, 120.0, 640.0, 1500.0])
    index = np.array([4, 0, 2, 2, 1, 4, 3, 3, 0, 2])
    taken = pv.curves(poa, cell_temperature(poa, 30.0, 1.0, "sapm"), 0.054).taken(index)
    again = pv.curves(poa[index], cell_temperature(poa[index], 30.0, 1.0, "sapm"), 0.054)
    assert all(np.array_equal(a, b) for a, b in zip(taken.params, again.params, strict=True))
    for name in ("i_sc", "v_oc"):
        assert np.array_equal(getattr(taken, name), getattr(again, name))
    assert all(np.array_equal(a, b) for a, b in zip(taken.mpp(), again.mpp(), strict=True))
    points = np.linspace(0.0, 1.0, index.size) * again.v_oc
    assert np.array_equal(taken.current(points), again.current(points), equal_nan=True)
    assert np.array_equal(taken.voltage(points / 10), again.voltage(points / 10), equal_nan=True)
    # A function of each curve alone, worked out once a distinct curve, is the same.
    def half_voc_current(curve):
        return curve.current(0.5 * curve.v_oc), curve.v_oc

    assert all(np.array_equal(a, b, equal_nan=True)
               for a, b in zip(taken.per_curve(half_voc_current), half_voc_current(again), strict=True))


def test_a_pvlib_without_its_own_lambert_w_is_called_itself(monkeypatch):
    """Where pvlib does not solve by its own Lambert W (older releases), the curve calls pvlib's
    i_from_v and v_from_i: their values whatever they are."""
    import types

    curve = _diode_curves(np.array([0.0, 300.0, 1000.0]), 25.0, None)
    # pvlib's own functions keep the module they imported; the curve finds no Lambert W in it.
    monkeypatch.setattr(pvlib, "singlediode", types.SimpleNamespace())
    points = np.array([0.1, 0.5, 0.9])
    with np.errstate(all="ignore"):
        currents, voltages = (f(points, *curve.params) for f in (pvlib.pvsystem.i_from_v, pvlib.pvsystem.v_from_i))
    # Were the terms used, the Lambert W hidden above would be called and fail.
    assert np.array_equal(curve.current(points), currents, equal_nan=True)
    assert np.array_equal(curve.voltage(points), voltages, equal_nan=True)
