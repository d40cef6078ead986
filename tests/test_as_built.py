"""The site and circuit as built through the engine: the kernel against the reference path, and
physical identities of the horizon."""

import numpy as np
import pvlib
import pytest

import foldopt
from foldopt.engine.cell_tables import electrical_for
from foldopt.engine.evaluation import poa
from foldopt.engine.sky import build_sky
from foldopt.studies.engine_options import engine_options


def _study(**changes):
    return foldopt.default_study().variant(mode="exact", pv_model="single-diode", sky="ineichen",
                                           fold_angles={"start": 10, "stop": 180, "step": 10}, **changes)


def test_kernel_equals_reference_path_as_built():
    """Direct coupling at 5 V, Shockley blocking diodes, a switch resistance and a horizon: the
    compiled kernel and the NumPy reference path read the same tables."""
    study = _study(panel={"area": 0.3}, p_load=3.0, site={"horizon": [[0, 10], [90, 5], [180, 20], [270, 30]]},
                   circuit={"coupling": "direct", "load_voltage": 5.0, "blocking_diode": "shockley",
                            "switch_resistance": 0.02})
    fast, reference = foldopt.run(study, engine="numba"), foldopt.run(study, engine="numpy")
    columns = fast.sweep.select_dtypes("number").columns
    assert np.allclose(fast.sweep[columns], reference.sweep[columns], rtol=1e-9, atol=1e-9)


def test_converter_curve_through_kernel_and_reference():
    study = _study(circuit={"converter": {"model": "pvwatts", "efficiency": 0.95}})
    fast, reference = foldopt.run(study, engine="numba"), foldopt.run(study, engine="numpy")
    columns = fast.sweep.select_dtypes("number").columns
    assert np.allclose(fast.sweep[columns], reference.sweep[columns], rtol=1e-9, atol=1e-9)
    ideal = foldopt.run(_study(), engine="numba")
    # A converter never delivers more than it takes.
    assert (fast.sweep["energy_harvested_switching_wh"] <= ideal.sweep["energy_harvested_switching_wh"] + 1e-9).all()


def test_horizon_above_the_sun_path_leaves_only_diffuse_and_reflected_light():
    """A horizon at 89 deg all around hides the sun all day: a surface gets its ground-reflected light
    (pvlib's get_ground_diffuse on the same GHI) and a sliver of sky (cos^2(89 deg) of the dome)."""
    study = _study(site={"horizon": [[0, 89], [120, 89], [240, 89]]})
    sky = build_sky(engine_options(study).sky, [study.site], [study.date])
    assert not sky.dni.any()
    tilt = 30.0
    light = poa(sky, np.array([[tilt]]), np.array([[180.0]]))[0]
    ground = pvlib.irradiance.get_ground_diffuse(tilt, sky.ghi[0], albedo=study.albedo)
    sky_part = light - ground
    assert (sky_part >= -1e-9).all()
    assert (sky_part <= sky.dhi[0] * np.cos(np.radians(89.0)) ** 2 * 3 + 1e-9).all()


def test_flat_horizon_is_none():
    plain = foldopt.run(_study(), engine="numba")
    flat = foldopt.run(_study(site={"horizon": [[0, 0], [180, 0]]}), engine="numba")
    columns = plain.sweep.select_dtypes("number").columns
    assert np.array_equal(plain.sweep[columns].to_numpy(), flat.sweep[columns].to_numpy())


def _direct(load_voltage, **changes):
    return _study(panel={"area": 0.3}, p_load=3.0, connection="parallel", exact_electrical=True,
                  circuit={"coupling": "direct", "load_voltage": load_voltage,
                           "blocking_diode": {"model": "constant", "forward_voltage": 0.45}}, **changes)


def test_flat_panel_for_a_direct_load_is_the_unfolded_pair():
    """A 180 deg fold is the flat panel: wired for a 5 V load its halves are in parallel, behind the
    same blocking diodes, so the flat row and the twofold panel at 180 deg in parallel agree."""
    answer = foldopt.run(_direct(5.0))
    flat = answer.summary.set_index("design").loc["flat"]
    unfolded = answer.sweep.set_index("fold_angle_deg").loc[180.0]
    assert flat["t_solar_h"] == pytest.approx(unfolded["t_solar_parallel_h"], rel=1e-12)
    assert flat["energy_harvested_wh"] == pytest.approx(unfolded["energy_harvested_parallel_wh"], rel=1e-12)


@pytest.mark.parametrize(("load_voltage", "wiring"), [(5.0, "parallel"), (9.0, "series")])
def test_flat_panel_is_wired_for_its_load(load_voltage, wiring):
    """At STC the flat panel delivers the better of its halves in parallel behind the diodes'
    0.45 V drop and its one string, each from pvlib's i_from_v at the load's voltage."""
    study = _direct(load_voltage)
    electrical = electrical_for(engine_options(study).electrical, study.temp_air, study.wind_speed)
    poa_stc = np.array([1000.0])
    temp = electrical._temperature(poa_stc)
    half = electrical.pv.curves(poa_stc, temp, study.panel.area / 2)
    whole = electrical.pv.curves(poa_stc, temp, study.panel.area)
    current = [np.clip(pvlib.pvsystem.i_from_v(v, *curve.params), 0.0, None)[0]
               for curve, v in ((half, load_voltage + 0.45), (whole, load_voltage))]
    parallel, series = 2 * load_voltage * current[0], load_voltage * current[1]
    assert electrical.flat_wiring == wiring == ("parallel" if parallel > series else "series")
    assert electrical.panel_power(poa_stc, study.panel.area)[0] == pytest.approx(max(parallel, series), rel=1e-9)
