"""The site and circuit as built through the engine: the kernel against the reference path, and
physical identities of the horizon."""

import numpy as np
import pvlib

import foldopt
from foldopt.engine.rows import poa
from foldopt.engine.sky import build_sky


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
    study = _study(site={"horizon": [[0, 89], [120, 89], [240, 89]]}).resolved()
    sky = build_sky(study, [study.site], [study.date])
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
