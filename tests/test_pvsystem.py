"""foldopt.twofold_arrays: the sub-panels as pvlib Arrays, and a pvlib ModelChain on them seeing
the plane-of-array irradiance foldopt computes for the same orientations."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pvlib
import pytest

import foldopt
from foldopt.physics.atmosphere import relative_airmass
from foldopt.engine.evaluation import poa
from foldopt.inputs.sections import default_orientation
from foldopt.physics.geometry import normal_vector, subpanel_orientation
from foldopt.physics.irradiance import sky_diffuse_terms
from foldopt.engine.sky import Sky

PVWATTS = {"pdc0": 120.0, "gamma_pdc": -0.004}
SAPM_TEMP = pvlib.temperature.TEMPERATURE_MODEL_PARAMETERS["sapm"]["open_rack_glass_glass"]
ALBEDO = 0.2
# pvlib 0.16 reads DatetimeIndex.dayofyear, which pandas deprecates; not foldopt's to fix.
pytestmark = pytest.mark.filterwarnings("ignore:DatetimeIndex.dayofyear is deprecated")


def _orientation(array):
    return array.mount.surface_tilt, array.mount.surface_azimuth


def _unit_normal(tilt, azimuth):
    """East-north-up unit normal from pvlib's tilt and azimuth (written here, not foldopt's)."""
    t, a = np.radians(tilt), np.radians(azimuth)
    return np.array([np.sin(t) * np.sin(a), np.sin(t) * np.cos(a), np.cos(t)])


@pytest.mark.parametrize("geometry", ["hinge", "azimuth-split"])
@pytest.mark.parametrize("fold_angle, tilt, azimuth", [(30, 34.05, 180), (120, 10, 200), (75, 33.9, 0)])
def test_arrays_are_the_subpanels_east_first(geometry, fold_angle, tilt, azimuth):
    east, west = foldopt.twofold_arrays(fold_angle, tilt, azimuth, geometry, module_parameters=PVWATTS,
                                        temperature_model_parameters=SAPM_TEMP, modules_per_string=6,
                                        strings=2, name_prefix="roof-", albedo=ALBEDO)
    sides = subpanel_orientation(fold_angle, tilt, azimuth, geometry)
    # Exactly foldopt's orientations (the function only converts them to float).
    assert _orientation(east) == (sides["surface_tilt_east"], sides["surface_azimuth_east"])
    assert _orientation(west) == (sides["surface_tilt_west"], sides["surface_azimuth_west"])
    for array, name in ((east, "roof-east"), (west, "roof-west")):
        assert isinstance(array, pvlib.pvsystem.Array) and isinstance(array.mount, pvlib.pvsystem.FixedMount)
        assert (array.name, array.modules_per_string, array.strings, array.albedo) == (name, 3, 2, ALBEDO)
        assert array.module_parameters == PVWATTS
    # "East first": the east sub-panel's normal leans further east than the west one's, whichever
    # way the panel faces.
    assert _unit_normal(*_orientation(east))[0] > _unit_normal(*_orientation(west))[0]


@pytest.mark.parametrize("geometry", ["hinge", "azimuth-split"])
@pytest.mark.parametrize("tilt, azimuth", [(34.05, 180.0), (0.0, 180.0), (60.0, 30.0)])
def test_flat_panel_is_both_arrays(geometry, tilt, azimuth):
    for array in foldopt.twofold_arrays(180, tilt, azimuth, geometry):
        assert _orientation(array) == pytest.approx((tilt, azimuth), abs=1e-12)  # [deg]


@pytest.mark.parametrize("fold_angle", [1.0, 30.0, 90.0, 150.0, 179.0, 180.0])
@pytest.mark.parametrize("tilt, azimuth", [(34.05, 180.0), (0.0, 90.0), (70.0, 0.0), (15.0, 250.0)])
def test_hinge_normals_open_by_the_supplement_of_the_fold(fold_angle, tilt, azimuth):
    east, west = foldopt.twofold_arrays(fold_angle, tilt, azimuth, "hinge")
    a, b = _unit_normal(*_orientation(east)), _unit_normal(*_orientation(west))
    angle = np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b)), a @ b))  # well conditioned near 0
    assert angle == pytest.approx(180.0 - fold_angle, abs=1e-9)  # [deg], rounding only


def test_azimuth_split_at_90_deg_faces_135_and_225():
    # Shin et al. Fig. 6: folded to 90 deg, a south-facing panel's halves face SE and SW.
    east, west = foldopt.twofold_arrays(90, 34.05, 180, "azimuth-split")
    assert _orientation(east) == pytest.approx((34.05, 135.0), abs=1e-12)
    assert _orientation(west) == pytest.approx((34.05, 225.0), abs=1e-12)
    assert _orientation(foldopt.twofold_arrays(90, 34.05, 180, "azimuth_split")[0]) == _orientation(east)


def _clear_day(latitude, longitude, tz, date="2014-09-23"):
    location = pvlib.location.Location(latitude, longitude, tz, altitude=100)
    times = pd.date_range(date, periods=24 * 12, freq="5min", tz=tz)
    return location, location.get_clearsky(times, model="ineichen")


def _model_chain(arrays, location, weather, transposition):
    system = pvlib.pvsystem.PVSystem(arrays=arrays, inverter_parameters={"pdc0": 240.0})
    mc = pvlib.modelchain.ModelChain(system, location, dc_model="pvwatts", ac_model="pvwatts", aoi_model="no_loss",
                                     spectral_model="no_loss", transposition_model=transposition)
    return mc.run_model(weather)


def _foldopt_poa(arrays, mc, weather, transposition, dni_extra):
    """foldopt's reference path (engine.poa over a Sky) with the ModelChain's sun and light."""
    sun = mc.results.solar_position
    zenith, azimuth = sun["apparent_zenith"].to_numpy(), sun["azimuth"].to_numpy()
    dni, ghi, dhi = (weather[name].to_numpy() for name in ("dni", "ghi", "dhi"))
    airmass = np.nan_to_num(relative_airmass(np.minimum(zenith, 90.0)), nan=0.0)  # as foldopt.engine.sky
    terms = sky_diffuse_terms(transposition, zenith, dni, ghi, dhi, dni_extra, airmass, ALBEDO)
    sky = Sky(grid=None, mode="exact", solar_zenith=zenith[None], solar_azimuth=azimuth[None], hour_angle=None,
              declination=None, sun_vector=normal_vector(zenith, azimuth)[None], dni=dni[None], ghi=ghi[None],
              dhi=dhi[None], terms=terms[None], temp_air=np.array([25.0]), latitude=np.array([0.0]), iam="none")
    return [poa(sky, np.array([[a.mount.surface_tilt]]), np.array([[a.mount.surface_azimuth]]))[0] for a in arrays]


@pytest.mark.parametrize("transposition, geometry, site", [
    ("isotropic", "hinge", "los-angeles"), ("haydavies", "hinge", "los-angeles"),
    ("perez", "hinge", "los-angeles"), ("perez", "azimuth-split", "los-angeles"), ("haydavies", "hinge", "sydney"),
])
def test_model_chain_poa_is_foldopts(transposition, geometry, site):
    latitude, longitude, tz = {"los-angeles": (34.05, -118.25, "America/Los_Angeles"),
                               "sydney": (-33.87, 151.21, "Australia/Sydney")}[site]
    tilt, azimuth = default_orientation(latitude)
    location, weather = _clear_day(latitude, longitude, tz)
    arrays = foldopt.twofold_arrays(30, tilt, azimuth, geometry, module_parameters=PVWATTS,
                                    temperature_model_parameters=SAPM_TEMP, albedo=ALBEDO)
    mc = _model_chain(arrays, location, weather, transposition)
    # pvlib's Array takes dni_extra from the UTC day of year (see the next test); given the same,
    # both sides evaluate the same formulas and differ by floating-point rounding only (measured
    # ~1e-15 relative), so 1e-9 W/m^2 plus 1e-9 relative leaves no room for a model difference.
    dni_extra = pvlib.irradiance.get_extra_radiation(weather.index).to_numpy()
    for index, ours in enumerate(_foldopt_poa(arrays, mc, weather, transposition, dni_extra)):
        theirs = mc.results.total_irrad[index]["poa_global"].to_numpy()
        assert np.nanmax(theirs) > 500.0  # a clear day, not a night of zeros
        np.testing.assert_allclose(ours, theirs, rtol=1e-9, atol=1e-9)
    assert mc.results.ac.max() > 0.0


def test_foldopts_local_day_dni_extra_is_the_only_difference():
    # foldopt.engine.sky takes dni_extra from the *local* day of year, pvlib's Array from the UTC day
    # (pvlib.tools._pandas_to_doy). In Los Angeles (UTC-7) they differ from 17:00 on, and the Hay &
    # Davies anisotropy index A = DNI / dni_extra with it: the POA then differs by exactly
    # DHI * dA * (R_b - (1 + cos tilt) / 2) (pvlib.irradiance.haydavies); ~0.04 W/m^2 here.
    location, weather = _clear_day(34.05, -118.25, "America/Los_Angeles")
    arrays = foldopt.twofold_arrays(30, 34.05, 180, "hinge", module_parameters=PVWATTS,
                                    temperature_model_parameters=SAPM_TEMP, albedo=ALBEDO)
    mc = _model_chain(arrays, location, weather, "haydavies")
    table = np.asarray(pvlib.irradiance.get_extra_radiation(np.arange(367)), dtype=float)
    # As foldopt.engine.sky.build_sky: the table indexed by ClockGrid.dayofyear, the local day.
    local, utc = table[weather.index.day_of_year], table[weather.index.tz_convert("UTC").day_of_year]
    zenith, azimuth = (mc.results.solar_position[name].to_numpy() for name in ("apparent_zenith", "azimuth"))
    dni, dhi = weather["dni"].to_numpy(), weather["dhi"].to_numpy()
    for array, ours, result in zip(arrays, _foldopt_poa(arrays, mc, weather, "haydavies", local),
                                   mc.results.total_irrad, strict=True):
        tilt, surface_azimuth = _orientation(array)
        ratio = np.maximum(pvlib.irradiance.aoi_projection(tilt, surface_azimuth, zenith, azimuth), 0.0) / np.maximum(
            np.cos(np.radians(zenith)), 0.01745)
        expected = dhi * (dni / local - dni / utc) * (ratio - (1.0 + np.cos(np.radians(tilt))) / 2.0)
        difference = ours - result["poa_global"].to_numpy()
        assert np.abs(difference[local != utc]).max() > 1e-3  # [W/m^2]: the effect is there
        np.testing.assert_allclose(difference, expected, rtol=0, atol=1e-9)


@pytest.mark.parametrize("kwargs, match", [
    ({"modules_per_string": 3}, "even integer of at least 2"),
    ({"modules_per_string": 1}, "even integer of at least 2"),
    ({"modules_per_string": 0}, "even integer of at least 2"),
    ({"modules_per_string": 2.0}, "even integer of at least 2"),
    ({"fold_angle": 0}, r"fold_angle must be in \(0, 180\]"),
    ({"fold_angle": 200}, r"fold_angle must be in \(0, 180\]"),
    ({"fold_angle": float("nan")}, r"fold_angle must be in \(0, 180\]"),
    ({"geometry": "hinj"}, r"geometry = 'hinj': must be one of azimuth-split, hinge; did you mean 'hinge'\?"),
    ({"geometry": "tent"}, "geometry = 'tent': must be one of azimuth-split, hinge$"),
    ({"geometry": 3}, "geometry = 3: must be one of azimuth-split, hinge"),
])
def test_bad_input_is_refused(kwargs, match):
    arguments = {"fold_angle": 30, "surface_tilt": 34.05, "surface_azimuth": 180, **kwargs}
    with pytest.raises(ValueError, match=match):
        foldopt.twofold_arrays(**arguments)
