"""A far horizon, against references the module does not use: the open plain's formulas, a
brute-force sum over the sky dome, the closed forms of a uniform ridge and of a street canyon's
infinite walls (the 2-D view factor), pvlib's PVGIS parser and the rule of pvlib's horizon example;
and the horizon files, good and bad.

The files are in tests/data/horizon (README.md there).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pvlib
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from foldopt.errors import ConfigError
from foldopt.inputs.horizon import horizon_profile, read_horizon
from foldopt.physics.horizon import horizon_elevation_at, sky_view_factors, sun_visible

DATA = Path(__file__).resolve().parent / "data" / "horizon"
PVGIS_JSON, PVGIS_CSV, CANYON = DATA / "pvgis_horizon.json", DATA / "pvgis_horizon.csv", DATA / "street_canyon.csv"
#: The site of the PVGIS files (README.md): the foot of the Sandia Mountains, NM.
LATITUDE, LONGITUDE = 35.171051, -106.465158
#: The brute-force dome (0.5 deg in azimuth, 1/16 deg in elevation) is within 6e-5 of a
#: 2e5-azimuth closed-form reference on random profiles, the module's quadrature within 2e-5.
DOME_TOLERANCE = 2e-4

tilts = st.floats(0.0, 180.0)
azimuths = st.floats(0.0, 360.0, exclude_max=True)


def dome_factor(tilt, azimuth, horizon_azimuth, horizon_elevation, n_az=720, n_el=1440):
    """The isotropic factor by brute force: 1/pi sum of max(cos(incidence), 0) cos(e) de dphi at
    the midpoints of cells of the dome, each cell counted by the share of its elevation span above
    the horizon line (numpy's periodic interpolation of the profile at the cell's azimuth)."""
    phi = np.radians((np.arange(n_az) + 0.5) * (360.0 / n_az))[:, None]
    step = np.radians(90.0 / n_el)
    e = (np.arange(n_el)[None, :] + 0.5) * step
    line = np.radians(np.interp(np.degrees(phi[:, 0]), horizon_azimuth, horizon_elevation, period=360.0))[:, None]
    t, a = np.radians(tilt), np.radians(azimuth)
    cos_incidence = np.sin(t) * np.cos(e) * np.cos(phi - a) + np.cos(t) * np.sin(e)
    above = np.clip((e + 0.5 * step - line) / step, 0.0, 1.0)
    cell = np.cos(e) * step * np.radians(360.0 / n_az)
    return float(np.sum(above * np.maximum(cos_incidence, 0.0) * cell) / np.pi)


def band_sum(tilt, azimuth, horizon_azimuth, horizon_elevation, width=6.5, n=200_000):
    """The band factor by a fine midpoint sum: sin(tilt) / 2 sum of the band's visible share times
    max(cos(phi - A), 0) dphi."""
    phi = (np.arange(n) + 0.5) * (360.0 / n)
    visible = 1.0 - np.clip(np.interp(phi, horizon_azimuth, horizon_elevation, period=360.0) / width, 0.0, 1.0)
    weight = np.maximum(np.cos(np.radians(phi - azimuth)), 0.0)
    return float(np.sin(np.radians(tilt)) * 0.5 * np.sum(visible * weight) * np.radians(360.0 / n))


@st.composite
def profiles(draw, max_points=16, max_elevation=60.0):
    """Random horizon profiles: 2 to ``max_points`` azimuths on a 0.5 deg grid, elevations up to
    ``max_elevation`` (some exactly 0)."""
    count = draw(st.integers(2, max_points))
    grid = draw(st.lists(st.integers(0, 719), min_size=count, max_size=count, unique=True))
    azimuth = np.sort(np.array(grid) * 0.5)
    elevation = np.array(draw(st.lists(st.one_of(st.just(0.0), st.floats(0.0, max_elevation)), min_size=count,
                                       max_size=count)))
    return azimuth, elevation


# The open plain ------------------------------------------------------------------------------


@settings(max_examples=200, deadline=None)
@given(tilt=tilts, azimuth=azimuths)
def test_no_horizon_gives_the_plain_formulas(tilt, azimuth):
    iso, band = sky_view_factors(tilt, azimuth, [0.0, 90.0, 200.0], [0.0, 0.0, 0.0])
    assert abs(iso - 0.5 * (1.0 + np.cos(np.radians(tilt)))) < 1e-12
    assert abs(band - np.sin(np.radians(tilt))) < 1e-12


def test_the_quadrature_itself_gives_the_plain_formulas():
    """A horizon of 1e-9 deg takes the general path: within 1e-6 of the plain formulas, at every
    tilt (near-vertical planes, whose integrand turns sharply at A -/+ 90, included)."""
    tilt = np.concatenate([np.linspace(0.0, 180.0, 361), 90.0 + np.geomspace(1e-6, 12.0, 60),
                           90.0 - np.geomspace(1e-6, 12.0, 60)])
    azimuth = np.random.default_rng(1).uniform(0.0, 360.0, tilt.size)
    iso, band = sky_view_factors(tilt, azimuth, [0.0, 123.0], [0.0, 1e-9])
    assert np.abs(iso - 0.5 * (1.0 + np.cos(np.radians(tilt)))).max() < 1e-6
    assert np.abs(band - np.sin(np.radians(tilt))).max() < 1e-9


# Against brute force and closed forms --------------------------------------------------------


@settings(max_examples=40, deadline=None)
@given(profile=profiles(), tilt=tilts, azimuth=azimuths)
def test_isotropic_factor_matches_a_brute_force_dome(profile, tilt, azimuth):
    iso, band = sky_view_factors(tilt, azimuth, *profile)
    assert abs(iso - dome_factor(tilt, azimuth, *profile)) < DOME_TOLERANCE
    assert 0.0 <= iso <= 0.5 * (1.0 + np.cos(np.radians(tilt))) + 1e-12


@settings(max_examples=40, deadline=None)
@given(profile=profiles(max_elevation=20.0), tilt=tilts, azimuth=azimuths, width=st.sampled_from([6.5, 2.0, 15.0]))
def test_band_factor_matches_a_fine_sum(profile, tilt, azimuth, width):
    _, band = sky_view_factors(tilt, azimuth, *profile, band_width=width)
    assert abs(band - band_sum(tilt, azimuth, *profile, width)) < 1e-7
    assert 0.0 <= band <= np.sin(np.radians(tilt)) + 1e-12


def test_band_as_a_line_is_hidden_by_any_horizon():
    """``band_width=0``: the model's line at elevation 0; a horizon above it anywhere in front hides
    it there, all of it (a horizon at 0 nowhere in front: no band at all)."""
    _, band = sky_view_factors(60.0, 180.0, [0.0, 90.0, 180.0, 270.0], [0.0, 0.0, 1.0, 0.0], band_width=0.0)
    assert band == pytest.approx(band_sum(60.0, 180.0, [0.0, 90.0, 180.0, 270.0], [0.0, 0.0, 1.0, 0.0], 1e-12),
                                 abs=1e-5)
    assert sky_view_factors(60.0, 180.0, [0.0, 180.0], [1.0, 1.0], band_width=0.0)[1] == 0.0


@pytest.mark.parametrize("ridge", [1.0, 10.0, 20.0, 45.0, 80.0])
def test_uniform_ridge_on_a_horizontal_plane(ridge):
    """(1/pi) 2 pi int_h^90 sin(e) cos(e) de = cos^2(h)."""
    iso, band = sky_view_factors(0.0, 123.0, [0.0, 120.0, 240.0], [ridge] * 3)
    assert iso == pytest.approx(np.cos(np.radians(ridge)) ** 2, abs=1e-12)
    assert band == 0.0


def canyon_profile(north, south, step=0.5):
    """Two infinite walls along an east-west street, ``north`` and ``south`` deg high across it:
    tan(h) = tan(wall) |cos(phi)|."""
    phi = np.arange(0.0, 360.0, step)
    c = np.cos(np.radians(phi))
    wall = np.where(c > 0, np.tan(np.radians(north)), np.tan(np.radians(south)))
    return phi, np.degrees(np.arctan(wall * np.abs(c)))


@pytest.mark.parametrize("tilt", [0.0, 20.0, 45.0, 60.0, 89.0, 90.0, 91.0, 120.0, 150.0, 170.0])
@pytest.mark.parametrize("facing", [180.0, 0.0])
def test_street_canyon_is_the_2d_view_factor(tilt, facing):
    """Walls infinitely long and a plane whose axis is along them: the dome reduces to the
    street's cross-section, where the plane sees the sky between the front wall's top (its
    elevation psi_front) and the lower of the back wall's top and its own back edge, and the 2-D
    view factor is (sin theta_2 - sin theta_1) / 2: V = [cos(max(psi_back - tilt, 0)) +
    cos(psi_front + tilt)] / 2, at least 0. The profile is sampled every 0.5 deg (error below 3e-6)."""
    north, south = 45.0, 35.0
    front, back = (south, north) if facing == 180.0 else (north, south)
    upper, lower = np.radians(max(back - tilt, 0.0)), np.radians(min(front + tilt, 180.0))
    expected = max(0.0, 0.5 * (np.cos(upper) + np.cos(lower)))
    iso, _ = sky_view_factors(tilt, facing, *canyon_profile(north, south))
    assert iso == pytest.approx(expected, abs=1e-5)


def test_factors_broadcast_and_keep_nan():
    tilt = np.array([[0.0, 30.0, np.nan], [90.0, 150.0, 180.0]])
    iso, band = sky_view_factors(tilt, 180.0, *read_horizon(PVGIS_JSON))
    assert iso.shape == band.shape == (2, 3)
    assert np.isnan(iso[0, 2]) and np.isnan(band[0, 2]) and np.isfinite(iso[1]).all()
    assert band[1, 2] == pytest.approx(0.0, abs=1e-15)  # facing straight down: no band


def test_a_higher_horizon_never_shows_more_sky():
    azimuth, elevation = read_horizon(PVGIS_JSON)
    rng = np.random.default_rng(7)
    tilt, facing = rng.uniform(0.0, 180.0, 2000), rng.uniform(0.0, 360.0, 2000)
    low, low_band = sky_view_factors(tilt, facing, azimuth, elevation)
    high, high_band = sky_view_factors(tilt, facing, azimuth, np.minimum(elevation + 5.0, 90.0))
    assert (high <= low + 1e-6).all() and (high_band <= low_band + 1e-12).all()


@pytest.mark.parametrize("bad, match", [
    (dict(horizon_azimuth=[10.0, 5.0], horizon_elevation=[1.0, 2.0]), "strictly increasing"),
    (dict(horizon_azimuth=[0.0, 360.0], horizon_elevation=[1.0, 2.0]), r"\[0, 360\)"),
    (dict(horizon_azimuth=[0.0, 90.0], horizon_elevation=[1.0, 91.0]), r"\[0, 90\]"),
    (dict(horizon_azimuth=[0.0, 90.0], horizon_elevation=[1.0]), "one length"),
    (dict(horizon_azimuth=[0.0, 90.0], horizon_elevation=[1.0, 2.0], surface_tilt=181.0), r"\[0, 180\]"),
    (dict(horizon_azimuth=[0.0, 90.0], horizon_elevation=[1.0, 2.0], n_azimuth=3), "n_azimuth"),
])
def test_bad_arguments_are_refused(bad, match):
    arguments = dict(surface_tilt=30.0, surface_azimuth=180.0) | bad
    with pytest.raises(ValueError, match=match):
        sky_view_factors(**arguments)


def test_many_surfaces_at_once_are_each_surface_alone():
    """1e5 surfaces under the PVGIS profile in one call (the map's and the optimiser's use) give each
    surface's own factors, within the bounds of its plane (the time: ``python bench/horizon.py``)."""
    azimuth, elevation = read_horizon(PVGIS_JSON)
    rng = np.random.default_rng(3)
    tilt, facing = rng.uniform(0.0, 180.0, 100_000), rng.uniform(0.0, 360.0, 100_000)
    isotropic, band = sky_view_factors(tilt, facing, azimuth, elevation)
    radians = np.radians(tilt)
    assert (isotropic >= 0).all() and (isotropic <= (1 + np.cos(radians)) / 2 + 1e-12).all()
    assert (band >= 0).all() and (band <= np.sin(radians) + 1e-12).all()
    for k in rng.choice(tilt.size, 20, replace=False):
        alone = tuple(map(float, sky_view_factors(tilt[k], facing[k], azimuth, elevation)))
        assert (isotropic[k], band[k]) == pytest.approx(alone, rel=1e-12, abs=1e-15)


# The sun and the horizon line ----------------------------------------------------------------


def _solstice(day, latitude=LATITUDE, longitude=LONGITUDE):
    times = pd.date_range(f"{day} 00:00", periods=1440, freq="1min", tz="UTC")
    return pvlib.solarposition.get_solarposition(times, latitude, longitude)


def test_horizon_line_wraps_across_north():
    azimuth, elevation = [0.0, 90.0, 352.5], [9.9, 20.0, 9.2]
    assert horizon_elevation_at([356.25, -3.75, 716.25], azimuth, elevation) == pytest.approx([9.55] * 3)
    assert horizon_elevation_at(45.0, azimuth, elevation) == pytest.approx(14.95)


def test_a_horizon_above_the_sun_path_hides_it_all_day():
    sun = _solstice("2023-12-21")
    top = float(sun.apparent_elevation.max())  # about 31.4 deg at the December solstice
    hidden = sun_visible(sun.apparent_zenith, sun.azimuth, [0.0, 180.0], [top + 0.1] * 2)
    assert not hidden.any()
    # The street canyon's south fronts (35 deg across the street) hide the winter sun all day too.
    assert not sun_visible(sun.apparent_zenith, sun.azimuth, *read_horizon(CANYON)).any()
    assert sun_visible(sun.apparent_zenith, sun.azimuth, [0.0, 180.0], [0.0, 0.0]).sum() == \
        (sun.apparent_elevation > 0).sum()


@pytest.mark.parametrize("day", ["2023-12-21", "2023-06-21", "2023-09-22"])
def test_sun_visibility_is_pvlib_examples_rule(day):
    """pvlib 0.16 has no horizon-shading function (``pvlib.shading`` shades rows; ``iotools``
    fetches PVGIS horizons); its gallery example "Simple irradiance adjustment for horizon shading"
    keeps the beam where ``apparent_elevation > np.interp(azimuth, horizon.index, horizon)``.
    foldopt's test is that rule, except between the profile's last point (352.5 deg) and north,
    where np.interp without ``period`` holds the last elevation and foldopt joins it to north's."""
    sun = _solstice(day)
    azimuth, elevation = read_horizon(PVGIS_JSON)
    example = sun.apparent_elevation.to_numpy() > np.interp(sun.azimuth, azimuth, elevation)
    ours = sun_visible(sun.apparent_zenith, sun.azimuth, azimuth, elevation)
    inside = sun.azimuth.to_numpy() <= azimuth[-1]
    assert np.array_equal(ours[inside], example[inside])
    periodic = sun.apparent_elevation.to_numpy() > np.interp(sun.azimuth, azimuth, elevation, period=360.0)
    assert np.array_equal(ours, periodic)


# Horizon files -------------------------------------------------------------------------------


def _pvlib_reading(monkeypatch, path):
    """pvlib.iotools.get_pvgis_horizon's reading of a printhorizon JSON, its request answered by the file."""
    class Response:
        ok = True

        @staticmethod
        def json():
            return json.loads(path.read_text())

    monkeypatch.setattr(pvlib.iotools.pvgis.requests, "get", lambda *args, **kwargs: Response())
    series, _ = pvlib.iotools.get_pvgis_horizon(LATITUDE, LONGITUDE)
    return series.index.to_numpy(dtype=float), series.to_numpy(dtype=float)


@pytest.mark.filterwarnings("ignore:The inplace keyword")  # pvlib's own set_index(inplace=True), pandas 3.1
def test_pvgis_json_reads_as_pvlib_reads_it(monkeypatch):
    azimuth, elevation = read_horizon(PVGIS_JSON)
    pvlib_azimuth, pvlib_elevation = _pvlib_reading(monkeypatch, PVGIS_JSON)
    assert np.array_equal(azimuth, pvlib_azimuth) and np.array_equal(elevation, pvlib_elevation)
    assert azimuth.size == 48 and np.array_equal(azimuth, np.arange(0.0, 360.0, 7.5))


def test_pvgis_azimuths_turn_from_south_to_north():
    """PVGIS's A = 0 is south (180 from north), A = -90 east (90), A = -180 north (0)."""
    entries = {entry["A"]: entry["H_hor"] for entry in json.loads(PVGIS_JSON.read_text())["outputs"]["horizon_profile"]}
    for path in (PVGIS_JSON, PVGIS_CSV):
        profile = dict(zip(*read_horizon(path)))
        assert profile[180.0] == entries[0.0] == 4.6
        assert profile[90.0] == entries[-90.0] == 10.3
        assert profile[270.0] == entries[90.0] == 0.0
        assert profile[0.0] == entries[-180.0] == 9.9


def test_the_three_formats_read_to_one_profile(tmp_path):
    azimuth, elevation = read_horizon(PVGIS_JSON)
    plain = tmp_path / "plain.csv"
    plain.write_text("azimuth,elevation\n" + "".join(f"{a:g},{e:g}\n" for a, e in zip(azimuth[::-1], elevation[::-1])))
    for other in (PVGIS_CSV, plain):
        other_azimuth, other_elevation = read_horizon(other)
        assert np.array_equal(other_azimuth, azimuth) and np.array_equal(other_elevation, elevation)


def test_street_canyon_file():
    azimuth, elevation = read_horizon(CANYON)
    assert azimuth.size == 72
    c = np.cos(np.radians(azimuth))
    shape = np.degrees(np.arctan(np.where(c > 0, 1.0, 0.7) * np.abs(c)))
    assert np.allclose(elevation, np.maximum(shape, 3.0), atol=0.05)
    assert dict(zip(azimuth, elevation))[0.0] == 45.0 and dict(zip(azimuth, elevation))[180.0] == 35.0


def test_profile_points_are_checked_and_sorted():
    azimuth, elevation = horizon_profile([(360.0, 5.0), (90, 20.5), (180.0, -2.0), (90.0, 20.5)])
    assert azimuth.tolist() == [0.0, 90.0, 180.0] and elevation.tolist() == [5.0, 20.5, 0.0]


@pytest.mark.parametrize("pairs, match", [
    ("0,5", "list of"),
    ([(0.0, 5.0)], "at least 2 distinct azimuths; got 1"),
    ([(0.0, 5.0), (360.0, 5.0)], "at least 2 distinct azimuths; got 1"),
    ([(0.0, 5.0), (90.0, 1.0), (90.0, 2.0)], "azimuth 90 deg is given twice, at point 2 and point 3"),
    ([(0.0, 5.0), (0.0, 6.0)], "given twice"),
    ([(0.0, 5.0), (361.0, 6.0)], r"point 2: azimuth 361 deg is outside \[0, 360\]"),
    ([(0.0, 5.0), (-1.0, 6.0)], "outside"),
    ([(0.0, 5.0), (10.0, 91.0)], "point 2: elevation 91 deg is above 90"),
    ([(0.0, 5.0), (10.0, float("nan"))], "finite numbers"),
    ([(0.0, 5.0), (10.0, "6")], "finite numbers"),
    ([(0.0, 5.0), (10.0, True)], "finite numbers"),
    ([(0.0, 5.0), (10.0,)], "point 2: expected an \\[azimuth, elevation\\] pair"),
    ([(0.0, 5.0), (10.0, 1.0, 2.0)], "pair"),
])
def test_bad_points_give_one_line(pairs, match):
    with pytest.raises(ValueError, match=match) as caught:
        horizon_profile(pairs)
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize("name, content, match", [
    ("missing.csv", None, "file not found"),
    ("empty.csv", "", "is empty"),
    ("blank.csv", " \n\n", "is empty"),
    ("binary.dat", b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", "binary"),
    ("latin1.csv", "azimuth,elevation\n0,5\n180,caf\xe9\n".encode("latin-1"), "not UTF-8"),
    ("other.csv", "time,watts\n06:00,5\n", "none of the horizon formats"),
    ("truncated.json", '{"outputs": {"horizon_profile": [{"A": -180, "H_hor": 1.0}', "not valid JSON"),
    ("tmy.json", '{"inputs": {}, "outputs": {"tmy_hourly": []}}', "without outputs.horizon_profile"),
    ("entry.json", '{"outputs": {"horizon_profile": [{"A": -180}]}}', r"outputs.horizon_profile\[0\]"),
    ("row.csv", "azimuth,elevation\n0,5\n90,x\n", "line 3: expected azimuth,elevation"),
    ("wide.csv", "azimuth,elevation\n0,5,1\n90,2\n", "line 2"),
    ("north.csv", "azimuth,elevation\n400,5\n90,2\n", "line 2: azimuth 400 deg is outside"),
    ("high.csv", "azimuth,elevation\n0,5\n90,95\n", "line 3: elevation 95 deg is above 90"),
    ("twice.csv", "azimuth,elevation\n0,5\n90,2\n90,3\n", "azimuth 90 deg is given twice, at line 3 and line 4"),
    ("one.csv", "azimuth,elevation\n0,5\n", "at least 2 distinct azimuths"),
    ("table.csv", "Latitude (decimal degrees):\t45.0\n\nA\tH_hor\n-180.0\tx\n", "line 4: expected the numbers"),
    ("folder", "folder", "is a folder"),
])
def test_bad_horizon_files_give_one_line(tmp_path, name, content, match):
    path = tmp_path / name
    if content == "folder":
        path.mkdir()
    elif isinstance(content, bytes):
        path.write_bytes(content)
    elif content is not None:
        path.write_text(content)
    with pytest.raises(ConfigError, match=match) as caught:
        read_horizon(path)
    (line,) = caught.value.errors
    assert line.startswith("site.horizon: ") and "\n" not in line and str(path) in line
    assert "PVGIS printhorizon JSON" in line and "azimuth,elevation" in line  # what a horizon file may be


def test_negative_pvgis_elevations_are_the_plain(tmp_path):
    path = tmp_path / "summit.json"
    profile = [{"A": a, "H_hor": -0.8 if a > 0 else 2.0} for a in np.arange(-180.0, 180.1, 45.0)]
    path.write_text(json.dumps({"outputs": {"horizon_profile": profile}}))
    azimuth, elevation = read_horizon(path)
    assert azimuth.tolist() == [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0]
    assert elevation.tolist() == [2.0, 2.0, 2.0, 2.0, 2.0, 0.0, 0.0, 0.0]
