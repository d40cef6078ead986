"""The compiled clear sky and its diffuse terms against pvlib's own functions on the same inputs.

References: ``pvlib.clearsky.ineichen`` with ``pvlib.atmosphere``'s Kasten & Young air mass and
pressure; the terms through pvlib's ``irradiance.perez``/``haydavies``/``isotropic`` (with
``return_components``) and ``get_ground_diffuse`` on random surfaces, where each pvlib component
is a term times its view factor (foldopt.physics.irradiance's module docstring). Tolerance: 1e-9
relative and 1e-9 W/m^2 (the same double-precision formulas; observed about 1e-13).
"""

from __future__ import annotations

import numpy as np
import pvlib
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from foldopt.physics.clearsky import ineichen_terms

RTOL, ATOL = 1e-9, 1e-9


def _inputs(seed: int, n_blocks: int = 3, n_steps: int = 400):
    rng = np.random.default_rng(seed)
    zenith = rng.uniform(0.0, 100.0, (n_blocks, n_steps))
    zenith[0, :5] = [89.999, 90.0, 90.5, np.nan, 0.0]
    dni_extra = rng.uniform(1310.0, 1420.0, (n_blocks, n_steps))
    turbidity = rng.uniform(1.0, 7.0, (n_blocks, n_steps))
    altitude = rng.uniform(-100.0, 5000.0, n_blocks)
    return zenith, dni_extra, turbidity, altitude


def _pvlib_ineichen(zenith, dni_extra, turbidity, altitude):
    """pvlib's clear sky per block, the sun down as 0 (foldopt's convention for the dark)."""
    out = {key: np.zeros(zenith.shape) for key in ("dni", "ghi", "dhi")}
    for b in range(zenith.shape[0]):
        up = zenith[b] < 90.0
        relative = pvlib.atmosphere.get_relative_airmass(zenith[b, up])
        absolute = pvlib.atmosphere.get_absolute_airmass(relative, pvlib.atmosphere.alt2pres(altitude[b]))
        sky = pvlib.clearsky.ineichen(zenith[b, up], absolute, turbidity[b, up], altitude[b], dni_extra[b, up])
        for key in out:
            out[key][b, up] = sky[key]
    return out


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_ineichen_is_pvlibs(seed):
    zenith, dni_extra, turbidity, altitude = _inputs(seed)
    dni, ghi, dhi, terms = ineichen_terms(zenith, dni_extra, turbidity, altitude, "none")
    expected = _pvlib_ineichen(zenith, dni_extra, turbidity, altitude)
    assert terms is None
    for key, value in (("dni", dni), ("ghi", ghi), ("dhi", dhi)):
        np.testing.assert_allclose(value, expected[key], rtol=RTOL, atol=ATOL, err_msg=key)
    dark = ~(zenith < 90.0)
    assert not np.any(dni[dark]) and not np.any(ghi[dark]) and not np.any(dhi[dark])
    assert np.all(ghi[~dark] > 0.0)


@settings(max_examples=10, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(["perez", "haydavies", "isotropic"]))
@example(32768, "perez")  # a horizon band that outweighs the rest of the sky on a surface
def test_terms_are_pvlibs_components(seed, transposition):
    zenith, dni_extra, turbidity, altitude = _inputs(seed)
    albedo = 0.25
    dni, ghi, dhi, layout = ineichen_terms(zenith, dni_extra, turbidity, altitude, transposition, albedo)
    iso, circ, hor, ground = layout.transpose(1, 0, 2)
    rng = np.random.default_rng(seed + 1)
    azimuth = rng.uniform(0.0, 360.0, zenith.shape)
    up = zenith < 90.0
    for tilt, surface_azimuth in zip(rng.uniform(0.0, 180.0, 3), rng.uniform(0.0, 360.0, 3), strict=True):
        z, a = zenith[up], azimuth[up]
        cos_aoi = np.maximum(pvlib.irradiance.aoi_projection(tilt, surface_azimuth, z, a), 0.0)
        cos_tilt, sin_tilt = np.cos(np.radians(tilt)), np.sin(np.radians(tilt))
        views = {"poa_isotropic": iso[up] * (1.0 + cos_tilt) / 2.0, "poa_circumsolar": circ[up] * cos_aoi,
                 "poa_horizon": hor[up] * sin_tilt}
        if transposition == "perez":
            airmass = pvlib.atmosphere.get_relative_airmass(z)
            parts = pvlib.irradiance.perez(tilt, surface_azimuth, dhi[up], dni[up], dni_extra[up], z, a, airmass,
                                           model="allsitescomposite1990", return_components=True)
            parts = {key: np.nan_to_num(np.asarray(value)) for key, value in parts.items()}
        elif transposition == "haydavies":
            parts = pvlib.irradiance.haydavies(tilt, surface_azimuth, dhi[up], dni[up], dni_extra[up], z, a,
                                               return_components=True)
            parts = {key: np.asarray(value) for key, value in parts.items()}
        else:
            parts = {"poa_isotropic": pvlib.irradiance.isotropic(tilt, dhi[up])}
            parts["poa_sky_diffuse"] = parts["poa_isotropic"]
        # The sky's diffuse light on the surface, clipped at 0 (a negative horizon band can outweigh
        # the rest); pvlib then zeroes its components, so they are compared where it is not.
        total = np.maximum(views["poa_isotropic"] + views["poa_circumsolar"] + views["poa_horizon"], 0.0)
        np.testing.assert_allclose(total, parts["poa_sky_diffuse"], rtol=RTOL, atol=ATOL)
        shown = parts["poa_sky_diffuse"] > 0
        for key, value in views.items():
            np.testing.assert_allclose(value[shown], np.broadcast_to(parts.get(key, 0.0), shown.shape)[shown],
                                       rtol=RTOL, atol=ATOL, err_msg=key)
        np.testing.assert_allclose(ground[up] * (1.0 - cos_tilt) / 2.0,
                                   pvlib.irradiance.get_ground_diffuse(tilt, ghi[up], albedo), rtol=RTOL, atol=ATOL)
    assert not np.any(layout[:, :, ~up[0]][0])


def test_a_fixed_turbidity_broadcasts_and_bad_names_are_refused():
    zenith, dni_extra, _, altitude = _inputs(7, n_blocks=2, n_steps=50)
    one = ineichen_terms(zenith, dni_extra, 3.0, altitude, "perez")
    full = ineichen_terms(zenith, dni_extra, np.full(zenith.shape, 3.0), altitude, "perez")
    for a, b in zip(one, full, strict=True):
        np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError, match="transposition must be one of .*perez"):
        ineichen_terms(zenith, dni_extra, 3.0, altitude, "reindl")
