"""The fast path (tables) against the exact per-step I-V solve."""

import numpy as np
import pytest

from foldopt.engine.metrics import energy, t_solar
from foldopt.studies.day import Day

ANGLES = np.array([15.0, 30.0, 60.0, 120.0, 180.0])


@pytest.mark.parametrize("pv_model", ["single-diode", "b-model"])
@pytest.mark.parametrize("mode,geometry", [("paper", "azimuth-split"), ("exact", "hinge")])
def test_tables_match_the_exact_solve(shin_study, pv_model, mode, geometry):
    # Stated bound (README, "Fast path"): every connection's t_solar within 30 s and energy within
    # 0.1 % of the exact solve, for loads from 10 % to 90 % of the peak.
    study = shin_study.model_copy(
        update={"pv_model": pv_model, "mode": mode, "geometry": geometry, "step_min": 2, "switch_series": True}
    )
    fast, fast_state = Day(study).connections(ANGLES)
    exact, exact_state = Day(study.model_copy(update={"exact_electrical": True})).connections(ANGLES)
    loads = np.linspace(0.1, 0.9, 9)[:, None] * exact["switching"].max()
    step = study.step_min / 60
    for connection in ("east", "west", "parallel", "series", "independent", "switching"):
        hours = np.abs(t_solar(fast[connection], loads, step) - t_solar(exact[connection], loads, step))
        assert hours.max() * 3600 < 30.0, connection
        relative = np.abs(energy(fast[connection], step) / energy(exact[connection], step) - 1)
        assert relative.max() < 1e-3, connection
    # Wherever one state wins clearly (by > 0.1 % over the runner-up), the switch picks it too.
    candidates = np.sort(np.stack([exact[name] for name in ("east", "west", "parallel", "series")]), axis=0)
    clear = candidates[-1] > 1.001 * candidates[-2]
    assert clear.sum() > 100
    assert np.array_equal(fast_state[clear], exact_state[clear])


def test_flat_panel_is_two_sub_panels_in_series(shin_study):
    day = Day(shin_study.model_copy(update={"pv_model": "single-diode", "exact_electrical": True}))
    flat = day.flat_power()
    twofold_at_180 = day.connections(np.array([180.0]))[0]
    np.testing.assert_allclose(flat, 2 * twofold_at_180["east"][0], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(flat, twofold_at_180["parallel"][0], rtol=1e-6, atol=1e-9)


def test_tables_are_cached_on_disk_by_their_settings(tmp_path, monkeypatch):
    from foldopt.engine import electrical
    from foldopt.physics.pvmodel import PVModel

    monkeypatch.setenv("FOLDOPT_CACHE_DIR", str(tmp_path))
    # Tables of few nodes (they name their files too): what is checked is where a table comes from,
    # not its values, and the test builds four.
    monkeypatch.setattr(electrical, "TABLE_NODES_2D", 9)
    monkeypatch.setattr(electrical, "TABLE_NODES_RATIO", 17)
    settings = dict(pv=PVModel("b-model", 0.19), subpanel_area=0.054, temp_air=25.0, temperature_model="sapm")
    built = electrical.Electrical(**settings)._table("parallel")
    assert built.shape == (9, 17)
    files = list((tmp_path / "tables").glob("parallel-*.npz"))
    assert len(files) == 1
    # A second model of the same settings loads the table instead of solving I-V curves.
    monkeypatch.setattr(PVModel, "curves", lambda *args: pytest.fail("rebuilt a cached table"))
    np.testing.assert_array_equal(electrical.Electrical(**settings)._table("parallel"), built)
    monkeypatch.undo()
    monkeypatch.setenv("FOLDOPT_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(electrical, "TABLE_NODES_2D", 9)
    monkeypatch.setattr(electrical, "TABLE_NODES_RATIO", 17)
    # Other settings, another file; a damaged file is rebuilt; no writable cache is no error.
    electrical.Electrical(**{**settings, "temp_air": 30.0})._table("parallel")
    assert len(list((tmp_path / "tables").glob("parallel-*.npz"))) == 2
    files[0].write_bytes(b"not a table")
    np.testing.assert_array_equal(electrical.Electrical(**settings)._table("parallel"), built)
    monkeypatch.setenv("FOLDOPT_CACHE_DIR", "/proc/foldopt-cannot-write-here")
    np.testing.assert_array_equal(electrical.Electrical(**settings)._table("parallel"), built)


def _dense_pair_fraction(pv, strong, weak, temp_cell, area, connection):
    """The pair's power as a fraction of its two maxima from I-V curves sampled at 200,001 points:
    pvlib's i_from_v / v_from_i (single diode) or the b-model's Eq. 8, no search."""
    import pvlib

    curves = pv.curves(np.array([strong, weak]), temp_cell, area)
    lit = curves.i_sc > 1e-9
    if pv.model == "single-diode":
        maxima = pvlib.pvsystem.max_power_point(*curves.params, method="brentq")["p_mp"]
    else:
        voltages = np.linspace(0.0, 1.0, 200_001) * curves.v_oc[:, None]
        maxima = (voltages * np.clip(curves.current(voltages), 0.0, None)).max(axis=1)
    maxima = np.where(lit, maxima, 0.0)
    if connection == "parallel":
        voltage = np.linspace(0.0, curves.v_oc.max(), 200_001)
        if pv.model == "single-diode":
            currents = [pvlib.pvsystem.i_from_v(voltage, *(p[k] for p in curves.params)) for k in (0, 1)]
        else:
            currents = list(curves.current(np.broadcast_to(voltage, (2, voltage.size))))
        power = voltage * sum(np.where(lit[k], np.clip(np.nan_to_num(currents[k]), 0.0, None), 0.0) for k in (0, 1))
    else:
        current = np.linspace(0.0, curves.i_sc.min(), 200_001)
        if pv.model == "single-diode":
            with np.errstate(all="ignore"):
                voltages = [pvlib.pvsystem.v_from_i(current, *(p[k] for p in curves.params)) for k in (0, 1)]
        else:
            voltages = list(curves.voltage(np.broadcast_to(current, (2, current.size))))
        power = current * sum(np.clip(np.nan_to_num(voltages[k]), 0.0, curves.v_oc[k]) for k in (0, 1))
    return power.max() / maxima.sum()


@pytest.mark.parametrize("pv_model", ["single-diode", "b-model"])
@pytest.mark.parametrize("connection", ["parallel", "series"])
def test_pair_tables_hold_the_pairs_power_at_their_nodes(tmp_path, monkeypatch, pv_model, connection):
    """A pair table's entries (the strong sub-panel's curve worked out once a node, the weaker's
    once a distinct irradiance) are the pair's maximum from densely sampled curves, to the
    samples' resolution, across the mesh: dark weaker sub-panels, equal irradiances, the kinks."""
    from foldopt.engine import electrical
    from foldopt.physics.pvmodel import PVModel
    from foldopt.physics.temperature import cell_temperature

    monkeypatch.setenv("FOLDOPT_CACHE_DIR", str(tmp_path))
    pv, area = PVModel(pv_model, 0.19), 0.054
    table = electrical.Electrical(pv=pv, subpanel_area=area, temp_air=30.0, temperature_model="sapm")._table(
        connection
    )
    assert table.shape == (electrical.TABLE_NODES_2D, electrical.TABLE_NODES_RATIO)
    strong_nodes = electrical._nodes(electrical.TABLE_NODES_2D)
    ratio_nodes = electrical._ratio_nodes(connection)
    for i, j in [(160, 0), (160, 320), (150, 300), (120, 200), (100, 260), (80, 37), (40, 120), (5, 64)]:
        strong, weak = strong_nodes[i], strong_nodes[i] * ratio_nodes[j]
        temp_cell = cell_temperature(np.array([strong, weak]), 30.0, 1.0, "sapm")
        expected = _dense_pair_fraction(pv, strong, weak, temp_cell, area, connection)
        # Samples 5e-6 of the range apart: a maximum at a kink (the weaker sub-panel's Voc) is
        # found within that; on a smooth maximum within its square.
        assert table[i, j] == pytest.approx(expected, rel=1e-5, abs=1e-9), (i, j)
