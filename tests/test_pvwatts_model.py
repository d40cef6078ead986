"""The PVWatts model (``pv_model: pvwatts``) against pvlib's ``pvwatts_dc``, ``pvwatts_losses`` and
``sapm_cell`` computed here on the same inputs, and its identities: no losses and no temperature
coefficient is the ideal model, a 180 deg fold is the flat panel, t_solar never rises with the
load; the same on both engines."""

import inspect

import numpy as np
import pvlib
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import foldopt
from foldopt.engine import evaluation as engine
from foldopt.engine.sky import build_sky
from foldopt.errors import ConfigError
from foldopt.inputs.pvwatts_section import LOSSES, PVWatts, total_losses
from foldopt.inputs.study import make_study
from foldopt.physics.pvmodel import PVModel
from foldopt.studies.engine_options import engine_options

SAPM = pvlib.temperature.TEMPERATURE_MODEL_PARAMETERS["sapm"]["open_rack_glass_polymer"]
SECOND = 1 / 3600  # [h]


def study(**fields):
    return make_study({"name": "pvw", "mode": "exact", "site": {"latitude": 34.05, "longitude": -118.25},
                       "date": "2025-06-21", "panel": {"area": 0.108, "efficiency": 0.19}, "p_load": 4.0,
                       "pv_model": "pvwatts", "fold_angles": {"start": 10, "stop": 180, "step": 10}, **fields})


losses = st.fixed_dictionaries({name: st.floats(0, 30) for name in LOSSES})


@settings(max_examples=100, deadline=None)
@given(breakdown=losses)
def test_the_total_loss_is_pvlibs(breakdown):
    assert total_losses(breakdown) == pytest.approx(pvlib.pvsystem.pvwatts_losses(**breakdown), rel=1e-12, abs=1e-12)
    assert PVWatts(**breakdown).losses == pytest.approx(pvlib.pvsystem.pvwatts_losses(**breakdown), rel=1e-12,
                                                        abs=1e-12)


def test_the_default_losses_are_pvwatts_less_shading_and_availability():
    """PVWatts' defaults (pvlib's) but for shading (foldopt casts the horizon itself) and
    availability (the time a grid-tied system is down, no loss of a working panel's power)."""
    defaults = {name: p.default for name, p in inspect.signature(pvlib.pvsystem.pvwatts_losses).parameters.items()}
    assert {**defaults, "shading": 0.0, "availability": 0.0} == LOSSES
    assert PVWatts().losses == pytest.approx(pvlib.pvsystem.pvwatts_losses(**{**defaults, "shading": 0,
                                                                               "availability": 0}))


@settings(max_examples=100, deadline=None)
@given(poa=st.lists(st.floats(0, 1500), min_size=1, max_size=20), temp_air=st.floats(-40, 50),
       wind=st.floats(0, 20), gamma=st.floats(-0.01, 0.01), breakdown=losses,
       pdc0=st.one_of(st.none(), st.floats(1, 500)))
def test_the_study_power_is_pvlibs_pvwatts_dc_with_sapm_cells(poa, temp_air, wind, gamma, breakdown, pdc0):
    """Through the study's options: the rating (efficiency x area x 1000 W/m^2, or pdc0), the
    temperature coefficient, SAPM open-rack cells, the losses."""
    area = 0.108
    given = study(pvwatts={"gamma_pdc": gamma, "pdc0": pdc0, **breakdown}, temp_air=temp_air, wind_speed=wind)
    options = engine_options(given).electrical
    pv = PVModel(options.pv_model, options.efficiency, options.module, options.gamma_pdc, options.losses)
    poa = np.array(poa)
    temp_cell = pvlib.temperature.sapm_cell(poa, temp_air, wind, **SAPM)
    rating = 0.19 * area * 1000 if pdc0 is None else pdc0
    expected = pvlib.pvsystem.pvwatts_dc(poa, temp_cell, rating / 2, gamma) * (
        1 - pvlib.pvsystem.pvwatts_losses(**breakdown) / 100)
    from foldopt.engine.cell_tables import electrical_for

    half = electrical_for(options, temp_air).subpanel_power(poa)
    np.testing.assert_allclose(half, expected, rtol=1e-12, atol=1e-12)
    # The kernel's form of it: a E + q E^2 at the air temperature and wind.
    a, q = pv.power_terms(temp_air, wind, "sapm", area / 2)
    np.testing.assert_allclose((a + q * poa) * poa, expected, rtol=1e-9, atol=1e-9)


def test_pvwatts_settings_need_pvwatts():
    with pytest.raises(ConfigError, match=r"pvwatts.gamma_pdc = -0.004: is only used by pv_model pvwatts"):
        study(pv_model="single-diode", pvwatts={"gamma_pdc": -0.004})
    with pytest.raises(ConfigError, match=r"pvwatts.soiling = 120: must be in \[0, 100\) %"):
        study(pvwatts={"soiling": 120})
    with pytest.raises(ConfigError, match=r"pvwatts.gamma_pdc = 0.5: must be in \[-0.01, 0.01\] 1/C"):
        study(pvwatts={"gamma_pdc": 0.5})


def test_the_question_names_the_model_its_cells_and_losses():
    models = foldopt.run(study(), engine="numpy").answer.question["models"]
    assert "pvwatts PV model (SAPM cells, -0.37 %/C, 8.7 % losses)" in models
    given = foldopt.run(study(temperature_model="fixed", pvwatts={"pdc0": 20.0, "wiring": 0}), engine="numpy")
    assert "pvwatts PV model (20 W, cells at the air's temperature, -0.37 %/C, 6.8 % losses)" in (
        given.answer.question["models"])


def _t_solar(given, engine_name, loads):
    sky = build_sky(engine_options(given).sky, [given.site], [given.date])
    orientation = engine.fold_orientations(given.geometry, [given.panel.tilt], [given.panel.azimuth],
                                           np.array([40.0, 90.0, 180.0]))
    rows = engine.PanelRows(np.zeros(3, dtype=int), orientation.reshape(-1, 4))
    return engine.row_metrics(sky, rows=rows, loads=loads, electrical=engine_options(given).electrical,
                              outputs=("switching", "panel", "parallel", "series"), engine=engine_name)


@pytest.mark.parametrize("engine_name", ["numpy", "numba"])
def test_no_losses_and_no_temperature_coefficient_is_the_ideal_model(engine_name):
    """PVWatts at gamma 0 and no losses is P = efficiency x area x E, the ideal model (cells at
    any temperature then give the rating)."""
    loads = np.linspace(0.5, 18, 12)
    flat = {name: 0.0 for name in LOSSES}
    pvwatts = _t_solar(study(pvwatts={"gamma_pdc": 0.0, **flat}), engine_name, loads)
    ideal = _t_solar(study(pv_model="ideal"), engine_name, loads)
    np.testing.assert_allclose(pvwatts.t_solar, ideal.t_solar, rtol=0, atol=SECOND)
    np.testing.assert_allclose(pvwatts.energy, ideal.energy, rtol=1e-12)


@pytest.mark.parametrize("engine_name", ["numpy", "numba"])
def test_a_flat_fold_is_the_flat_panel_and_t_solar_never_rises_with_the_load(engine_name):
    loads = np.linspace(0.2, 20, 40)
    result = _t_solar(study(), engine_name, loads)
    # Row 2 is the 180 deg fold: switching, parallel and series deliver the whole panel's power.
    for index in (0, 2, 3):
        np.testing.assert_allclose(result.t_solar[2, index], result.t_solar[2, 1], rtol=0, atol=SECOND)
        np.testing.assert_allclose(result.energy[2, index], result.energy[2, 1], rtol=1e-9)
    assert np.all(np.diff(result.t_solar, axis=-1) <= 1e-12)


@settings(max_examples=25, deadline=None)
@given(temp_air=st.floats(-30, 45), wind=st.floats(0, 15), gamma=st.floats(-0.006, 0.0),
       soiling=st.floats(0, 10), load=st.floats(0.1, 18))
def test_warmer_cells_and_more_loss_never_lengthen_t_solar(temp_air, wind, gamma, soiling, load):
    """With a negative temperature coefficient a warmer day, and a larger loss, never raise the
    power, so never t_solar (the numpy path, each case against its neighbour)."""
    base = study(temp_air=temp_air, wind_speed=wind, pvwatts={"gamma_pdc": gamma, "soiling": soiling})
    warmer = study(temp_air=temp_air + 5, wind_speed=wind, pvwatts={"gamma_pdc": gamma, "soiling": soiling})
    dirtier = study(temp_air=temp_air, wind_speed=wind, pvwatts={"gamma_pdc": gamma, "soiling": soiling + 5})
    hours = [_t_solar(s, "numpy", [load]).t_solar for s in (base, warmer, dirtier)]
    assert np.all(hours[1] <= hours[0] + 1e-12)
    assert np.all(hours[2] <= hours[0] + 1e-12)


def test_the_rating_is_the_nameplate_before_the_losses():
    """A converter and a price per watt are sized on the nameplate, pdc0, not on the power left
    after the system losses; the other models' rating is their STC power."""
    from foldopt.studies.sizing import stc_power_per_area

    pvwatts = PVModel("pvwatts", efficiency=0.19, losses=0.0868)
    assert pvwatts.rating(0.108) == pytest.approx(0.19 * 0.108 * 1000, rel=1e-12)
    assert stc_power_per_area(pvwatts) == pytest.approx(190.0, rel=1e-12)
    assert pvwatts.max_power(np.array([1000.0]), 25.0, 0.108)[0] == pytest.approx(0.19 * 108 * (1 - 0.0868))
    assert PVModel("ideal", efficiency=0.2).rating(0.5) == pytest.approx(100.0, rel=1e-12)
