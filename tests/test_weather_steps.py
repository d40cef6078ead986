"""Cells at every step's own air temperature: the electrical tables of a weather study at air
temperatures 5 C apart, each step between two of them, against pvlib's single-diode model solved
at the step's own cell temperature, and the kernel against the NumPy reference path."""

import datetime as dt
from pathlib import Path

import numpy as np
import pvlib
import pytest

from foldopt.engine import evaluation as engine
from foldopt.engine.sky import build_sky
from foldopt.studies.engine_options import engine_options
from foldopt.inputs.plan import make_plan
from foldopt.physics.pvmodel import A300_CELL

TMY3 = Path(pvlib.__file__).parent / "data" / "723170TYA.CSV"  # NREL TMY3 sample pvlib ships
DAYS = [dt.date(2025, 1, 14), dt.date(2025, 4, 2), dt.date(2025, 7, 17), dt.date(2025, 10, 10)]


@pytest.fixture(scope="session")
def weather_day():
    plan = make_plan({"name": "g", "weather": str(TMY3), "panel": {"area": 0.108}, "p_load": 2.0,
                      "pv_model": "single-diode", "step_min": 5, "transposition": "perez"})
    study = plan.base
    return study, build_sky(engine_options(study).sky, [study.site] * len(DAYS), DAYS)


def test_flat_panel_power_follows_each_steps_cell_temperature(weather_day):
    # Reference: pvlib's De Soto single-diode model of the A-300 cell (its parameters, the data of
    # foldopt.physics.pvmodel) solved by pvlib.pvsystem.singlediode at each step's plane-of-array
    # irradiance and SAPM cell temperature (pvlib.temperature.sapm_cell, open rack glass/polymer)
    # at the step's own (equivalent) air temperature; 7.2 cells in series make the 0.108 m^2 panel.
    # Stated tolerance: 0.3 % of the panel's peak, the tables' irradiance interpolation (README,
    # "Fast path": energy within 0.1 %) plus the 5 C temperature interpolation.
    study, sky = weather_day
    tilt, azimuth = study.panel.tilt, study.panel.azimuth
    poa = engine.poa(sky, np.full((len(DAYS), 1), tilt), np.full((len(DAYS), 1), azimuth))
    power = engine.panel_power(sky, poa_global=poa, electrical=engine_options(study).electrical)
    params = pvlib.temperature.TEMPERATURE_MODEL_PARAMETERS["sapm"]["open_rack_glass_polymer"]
    # The cells' temperature the engine means: SAPM at the step's equivalent air temperature and
    # the tables' wind (foldopt.physics.temperature.equivalent_temp_air)...
    temp_cell = pvlib.temperature.sapm_cell(poa, sky.temp_steps, sky.wind_ref, **params)
    # ... which differs from SAPM at the file's air temperature and wind only by the documented
    # term (E_poa - E_ghi)(exp(a + b WS) - exp(a + b WS_ref)), under 3 C on these days.
    true_cell = pvlib.temperature.sapm_cell(poa, _air(sky, study), sky.wind_speed, **params)
    term = (poa - sky.ghi) * (np.exp(params["a"] + params["b"] * sky.wind_speed)
                              - np.exp(params["a"] + params["b"] * sky.wind_ref))
    np.testing.assert_allclose(true_cell - temp_cell, term, atol=1e-9)
    assert np.abs(term).max() < 3.0
    u = A300_CELL
    with np.errstate(divide="ignore", over="ignore"):
        il, io, rs, rsh, nnsvth = pvlib.pvsystem.calcparams_desoto(
            poa, temp_cell, u.alpha_sc, u.a_ref, u.I_L_ref, u.I_o_ref, u.R_sh_ref, u.R_s, EgRef=u.EgRef,
            dEgdT=u.dEgdT)
    lit = poa > 1.0
    reference = np.zeros_like(poa)
    reference[lit] = pvlib.pvsystem.singlediode(il[lit], io[lit], rs[lit], rsh[lit], nnsvth[lit])["p_mp"]
    reference *= study.panel.area / u.area
    assert np.ptp(temp_cell[lit]) > 20.0  # the cells' temperature moves through the days
    np.testing.assert_allclose(power, reference, atol=3e-3 * reference.max())
    # Fixed at each day's mean air temperature instead, the error is several times larger.
    fixed = sky.temp_air[:, None] + poa * np.exp(params["a"] + params["b"] * sky.wind_ref) + poa / 1000 * params[
        "deltaT"]
    assert np.abs(temp_cell - fixed)[lit].max() > 5.0


def _air(sky, study):
    """The file's air temperature at every step, independent of the engine's equivalent air
    temperature: the wind term it folds in is taken back out at the sky's global light."""
    params = pvlib.temperature.TEMPERATURE_MODEL_PARAMETERS["sapm"]["open_rack_glass_polymer"]
    return sky.temp_steps - sky.ghi * (np.exp(params["a"] + params["b"] * sky.wind_speed)
                                       - np.exp(params["a"] + params["b"] * sky.wind_ref))


def test_kernel_matches_the_reference_between_temperatures(weather_day):
    # The compiled kernel and the NumPy reference take the same two tables a step and the same
    # weights: t_solar within 1 s a day, energy within 1e-9 (tests/test_engine.py's bound).
    study, sky = weather_day
    orientation = engine.fold_orientations(study.geometry, [study.panel.tilt], [study.panel.azimuth],
                                           np.array([40.0, 90.0, 150.0, 180.0]))[0]
    rows = engine.PanelRows(np.repeat(np.arange(len(DAYS)), len(orientation)), np.tile(orientation, (len(DAYS), 1)))
    loads = np.array([0.2, 1.0, 3.0, 6.0])
    outputs = ("east", "parallel", "series", "switching", "independent", "panel")
    electrical = engine_options(study).electrical
    fast = engine.row_metrics(sky, rows=rows, loads=loads, electrical=electrical, outputs=outputs)
    slow = engine.row_metrics(sky, rows=rows, loads=loads, electrical=electrical, outputs=outputs, engine="numpy")
    np.testing.assert_allclose(fast.t_solar, slow.t_solar, atol=1 / 3600)
    np.testing.assert_allclose(fast.energy, slow.energy, rtol=1e-9)
    nodes, table, weight = engine.temperature_nodes(sky)
    assert nodes.size >= 4 and np.all(np.diff(nodes) == engine.TEMPERATURE_NODE_STEP)
    assert np.all((weight >= 0) & (weight < 1)) and np.any(weight > 0.1)
    np.testing.assert_allclose(nodes[table] + weight * engine.TEMPERATURE_NODE_STEP, sky.temp_steps, atol=1e-9)
