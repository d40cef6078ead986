"""Paper-mode sun position against pvlib's implementations of the same textbook formulas,
and against NREL SPA for the size of the paper's approximation."""

import datetime as dt

import numpy as np
import pandas as pd
import pvlib
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from foldopt.physics.solarposition import (
    clock_grid,
    day_times,
    declination_paper,
    equation_of_time_paper,
    get_solar_position,
    hour_angle_paper,
    sun_from_angles,
)

DAYS = np.arange(1, 366)


def test_equation_of_time_matches_pvlib_pvcdrom():
    # pvlib.solarposition.equation_of_time_pvcdrom implements the same PVCDROM formula.
    expected = pvlib.solarposition.equation_of_time_pvcdrom(DAYS)
    np.testing.assert_allclose(equation_of_time_paper(DAYS), expected, atol=1e-9)


def test_declination_close_to_cooper69():
    # Cooper (1969): 23.45 sin(360 (284 + d) / 365), the same phase as (d - 81); the sine-of-sines
    # form differs by at most 23.45 - asin(sin 23.45) * ... = 0.26 deg at the solstices' flanks.
    cooper = np.degrees(pvlib.solarposition.declination_cooper69(DAYS))
    diff = np.abs(declination_paper(DAYS) - cooper)
    assert diff.max() < 0.27
    assert declination_paper(81) == pytest.approx(0.0, abs=1e-12)
    assert declination_paper(81 + 365 / 4) == pytest.approx(23.45, abs=1e-9)


def test_hour_angle_matches_pvlib():
    times = day_times(dt.date(2014, 9, 23), "America/Los_Angeles", 10)
    eot = pvlib.solarposition.equation_of_time_pvcdrom(times.day_of_year)
    expected = pvlib.solarposition.hour_angle(times, -118.25, eot)
    wrapped = (np.asarray(expected) + 180.0) % 360.0 - 180.0
    np.testing.assert_allclose(hour_angle_paper(times, -118.25), wrapped, atol=1e-9)


@pytest.mark.parametrize("latitude", [-66.0, -34.0, 0.0, 34.05, 60.0])
def test_zenith_and_azimuth_match_pvlib_analytical(latitude):
    declination = np.array([-23.0, -10.0, 0.0, 12.0, 23.4])[:, None]
    # pvlib's analytical azimuth returns 180 at an hour angle of exactly 0 even when the noon sun
    # stands north (southern sites); that case is checked on its own below.
    hour_angle = np.linspace(-170, 170, 34)[None, :]
    zenith, azimuth = sun_from_angles(declination, hour_angle, latitude)
    lat, dec, ha = np.radians(latitude), np.radians(declination), np.radians(hour_angle)
    expected_zenith = pvlib.solarposition.solar_zenith_analytical(lat, ha, dec)
    expected_azimuth = pvlib.solarposition.solar_azimuth_analytical(lat, ha, dec, expected_zenith)
    np.testing.assert_allclose(zenith, np.degrees(expected_zenith), atol=1e-7)
    # Azimuth is undefined with the sun at the zenith; compare where it is not.
    valid = np.degrees(expected_zenith) > 0.5
    np.testing.assert_allclose(azimuth[valid], np.degrees(expected_azimuth)[valid] % 360, atol=1e-6)


def test_noon_sun_stands_toward_the_equator_side_of_the_declination():
    _, azimuth = sun_from_angles(np.array([-23.0, 0.0, 23.0]), 0.0, -34.0)
    np.testing.assert_allclose(azimuth, [0.0, 0.0, 0.0], atol=1e-6)
    _, azimuth = sun_from_angles(np.array([-23.0, 0.0, 23.0]), 0.0, 34.0)
    np.testing.assert_allclose(azimuth, [180.0, 180.0, 180.0], atol=1e-6)


def test_paper_position_close_to_spa_on_the_paper_day():
    # The paper's formulas are approximate. On its own day (day 266) the sine-of-sines declination
    # gives -0.98 deg where SPA has about -0.3 deg, and the PVCDROM equation of time 8.4 min where
    # SPA has about 7.6 min; measured against SPA's geometric position (sun > 5 deg) this leaves
    # 0.71 deg in zenith and 0.83 deg in azimuth, hence the 1 deg bound.
    times = day_times(dt.date(2014, 9, 23), "America/Los_Angeles", 5)
    paper = get_solar_position(times, 34.05, -118.25, model="paper")
    spa = pvlib.solarposition.get_solarposition(times, 34.05, -118.25)
    up = spa["elevation"].to_numpy() > 5
    np.testing.assert_allclose(paper["solar_zenith"][up], spa["zenith"][up], atol=1.0)
    np.testing.assert_allclose(paper["solar_azimuth"][up], spa["azimuth"][up], atol=1.0)


def test_exact_position_is_apparent_spa():
    times = day_times(dt.date(2020, 6, 21), "Europe/Berlin", 30)
    exact = get_solar_position(times, 52.5, 13.4, altitude=34, model="exact")
    spa = pvlib.solarposition.get_solarposition(times, 52.5, 13.4, altitude=34)
    np.testing.assert_allclose(exact["solar_zenith"], spa["apparent_zenith"])


def test_day_times_are_interval_centred_over_the_local_day():
    times = day_times(dt.date(2014, 9, 23), "America/Los_Angeles", 1)
    assert len(times) == 1440
    assert times[0] == pd.Timestamp("2014-09-23 00:00:30", tz="America/Los_Angeles")
    assert times[-1] == pd.Timestamp("2014-09-23 23:59:30", tz="America/Los_Angeles")
    with pytest.raises(ValueError, match="1440"):
        day_times(dt.date(2014, 9, 23), "UTC", 7)


#: Zones whose clocks jump: forward and back by an hour (both hemispheres), by half an hour (Lord
#: Howe), at midnight (Havana, Santiago, Beirut), on a half-hour offset (St John's), none (Kolkata).
JUMPING_ZONES = (
    "America/Los_Angeles",
    "Europe/Berlin",
    "Australia/Sydney",
    "Australia/Lord_Howe",
    "America/Havana",
    "America/Santiago",
    "Asia/Beirut",
    "America/St_Johns",
    "Asia/Kolkata",
)


def _pandas_grid(dates, zone, step_min):
    """UTC [ns] and UTC offset [ns] of the clock grid's steps as pandas localises them."""
    n_steps = round(1440 / step_min)
    offsets = np.round((np.arange(n_steps) + 0.5) * step_min * 60e9).astype(np.int64)
    midnights = np.array(dates, dtype="datetime64[D]").astype("datetime64[ns]").astype(np.int64)
    naive = (midnights[:, None] + offsets[None, :]).ravel().astype("datetime64[ns]")
    local = pd.DatetimeIndex(naive).tz_localize(
        zone, ambiguous=np.ones(naive.size, dtype=bool), nonexistent="shift_forward"
    )
    utc = local.tz_convert("UTC").tz_localize(None).as_unit("ns").asi8
    clock = local.tz_localize(None).as_unit("ns").asi8
    return utc.reshape(len(dates), -1), (clock - utc).reshape(len(dates), -1)


@pytest.mark.parametrize("name", JUMPING_ZONES)
def test_the_clock_grid_of_a_zone_is_pandas_localisation_to_the_bit(name):
    """The clock grid of an IANA zone (localised with the standard library, no pandas) gives
    every step the instant and offset pandas' ``tz_localize`` gives it (a repeated clock time at
    its first instant, a skipped one shifted forward), every day of years whose rules differ,
    DST days included, for steps of a minute, 7.5 min and an hour."""
    import zoneinfo

    zone = zoneinfo.ZoneInfo(name)
    for year in (1995, 2014, 2024):
        start = dt.date(year, 1, 1)
        dates = [start + dt.timedelta(days=i) for i in range(365)]
        for step_min in (1.0, 7.5, 60.0):
            grid = clock_grid(dates, zone, step_min)
            utc, offset = _pandas_grid(dates, zone, step_min)
            assert np.array_equal(grid.utc_ns, utc), (name, year, step_min)
            assert np.array_equal(grid.utc_offset_ns, offset), (name, year, step_min)
            assert grid.timezones[0] is zone


def test_unknown_model_lists_valid_names():
    times = day_times(dt.date(2014, 9, 23), "UTC", 60)
    with pytest.raises(ValueError, match="paper, exact"):
        get_solar_position(times, 0, 0, model="spa")


@pytest.mark.parametrize(
    "latitude,longitude,date,zone",
    [(34.05, -118.25, dt.date(2014, 9, 23), "America/Los_Angeles"), (70.0, 20.0, dt.date(2025, 6, 21), "UTC"),
     (-33.9, 151.2, dt.date(2025, 6, 21), "Australia/Sydney"), (0.0, 0.0, dt.date(2025, 3, 20), "UTC")],
)
def test_the_sun_of_every_step_stays_on_full_spa(latitude, longitude, date, zone):
    from foldopt.physics.geometry import normal_vector

    times = day_times(date, zone, 1)
    fast = get_solar_position(times, latitude, longitude, altitude=100, model="exact")
    full = pvlib.solarposition.get_solarposition(times, latitude, longitude, altitude=100)
    up = full["apparent_elevation"].to_numpy() > -1
    a = normal_vector(fast["solar_zenith"].to_numpy(), fast["solar_azimuth"].to_numpy())[up]
    b = normal_vector(full["apparent_zenith"].to_numpy(), full["azimuth"].to_numpy())[up]
    angle = np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1)))
    # The geocentric terms interpolated between whole hours (within 1e-5 deg, tested below) are
    # all that departs from SPA: measured 1.7e-6 deg.
    assert angle.max() < 1e-5
    np.testing.assert_allclose(fast["solar_zenith"].to_numpy()[up], full["apparent_zenith"].to_numpy()[up], atol=1e-5)


def test_exact_hour_angle_is_pvlibs_and_zero_at_solar_noon():
    times = day_times(dt.date(2025, 3, 20), "America/New_York", 30)
    exact = get_solar_position(times, 40.7, -74.0, model="exact")
    spa = pvlib.solarposition.get_solarposition(times, 40.7, -74.0)
    expected = pvlib.solarposition.hour_angle(times, -74.0, spa["equation_of_time"].to_numpy())
    np.testing.assert_allclose(exact["hour_angle"], (np.asarray(expected) + 180.0) % 360.0 - 180.0, atol=1e-9)
    # On a DST switch day pvlib's hour_angle is an hour off after the switch (its docs warn of DST
    # days); foldopt's works from UTC, so the sun is highest where its hour angle crosses zero.
    times = day_times(dt.date(2025, 3, 9), "America/New_York", 1)
    exact = get_solar_position(times, 40.7, -74.0, model="exact")
    noon = np.argmin(exact["solar_zenith"].to_numpy())
    assert abs(exact["hour_angle"].iloc[noon]) < 0.3


def test_exact_hour_angle_of_the_compiled_pass_is_pvlibs_formula_in_numpy():
    """The per-site pass works out the hour angle, ``15 (UTC hours - 12) + longitude + EoT / 4``
    wrapped to [-180, 180), with the bits of the NumPy expression (a float's remainder by Python's
    rule in both) at sites of every longitude, days from 1950 to 2080."""
    import foldopt.physics.spa as spa
    from foldopt.physics.solarposition import clock_grid, solar_position_grid

    rng = np.random.default_rng(8)
    n = 16
    dates = [dt.date(1950, 1, 1) + dt.timedelta(days=int(d)) for d in rng.integers(0, 130 * 365, n)]
    # Local days that cross a UTC midnight (the pass carries the UTC day from step to step).
    for zone in ("UTC", "Pacific/Kiritimati", "America/St_Johns", "Asia/Kathmandu"):
        grid = clock_grid(dates, zone, 7.5)
        longitude = rng.uniform(-180, 180, (n, 1))
        sun = solar_position_grid(grid, rng.uniform(-80, 80, (n, 1)), longitude, 10.0, "exact")
        first, terms = spa.equatorial_once(grid.utc_ns)
        eot = terms[4][first[:, None] + np.arange(grid.utc_ns.shape[1])]
        utc_hours = (grid.utc_ns % (24 * spa.NS_PER_HOUR)) / spa.NS_PER_HOUR
        expected = (15.0 * (utc_hours - 12.0) + longitude + eot / 4.0 + 180.0) % 360.0 - 180.0
        np.testing.assert_array_equal(sun["hour_angle"], expected)


@settings(max_examples=200, deadline=None)
@given(st.one_of(st.floats(-2000.0, 2000.0), st.sampled_from([-720.0, -360.0, -0.0, 0.0, 360.0,
                                                                 720.0, 359.99999999999994,
                                                                 -1e-300, np.nan])))
def test_the_hour_angles_wrap_is_pythons_remainder(angle):
    """The per-site pass's wrap of the hour angle takes no ``fmod`` on its usual range: the same
    bits as Python's ``% 360.0`` once the pass's ``- 180`` is taken (which makes -0.0 and 0.0
    alike)."""
    from foldopt.physics.spa_site import _turn_mod

    np.testing.assert_array_equal(_turn_mod(angle) - 180.0, angle % 360.0 - 180.0)


@pytest.mark.parametrize("zone", ["America/Los_Angeles", "Australia/Lord_Howe", "Pacific/Apia",
                                  "Africa/Casablanca", "Antarctica/Troll", "Asia/Kolkata"])
@pytest.mark.parametrize("step_min", [1, 7.5, 240])
def test_the_clock_grid_is_pandas_shift_of_the_whole_grid(zone, step_min):
    """The clock grid localises every step and shifts only the clock times a DST change skips
    (Lord Howe's half hour, Apia's lost 30 December 2011, Casablanca's Ramadan breaks, Troll's two
    hours): the bits of pandas shifting the whole grid forward and converting it back, over every
    day of 2011 and 2024."""
    from foldopt.physics.solarposition import clock_grid

    for year in (2011, 2024):
        dates = [dt.date(year, 1, 1) + dt.timedelta(days=d) for d in range(365)]
        grid = clock_grid(dates, zone, step_min)
        offsets = np.round((np.arange(round(1440 / step_min)) + 0.5) * step_min * 60e9).astype(np.int64)
        naive = (np.array(dates, dtype="datetime64[D]").astype("datetime64[ns]").astype(np.int64)[:, None]
                 + offsets[None, :])
        flat = pd.DatetimeIndex(naive.ravel().astype("datetime64[ns]")).tz_localize(
            zone, ambiguous=np.ones(naive.size, dtype=bool), nonexistent="shift_forward")
        utc = flat.tz_convert("UTC").tz_localize(None).as_unit("ns").asi8.reshape(naive.shape)
        local = flat.tz_localize(None).as_unit("ns").asi8.reshape(naive.shape)
        np.testing.assert_array_equal(grid.utc_ns, utc)
        np.testing.assert_array_equal(grid.utc_offset_ns, local - utc)


def test_geocentric_terms_interpolated_between_hours_stay_on_spa():
    from foldopt.physics.spa import _GEOCENTRIC, SunTerms, _geocentric_hourly, spa_geocentric

    # Random instants from 1990 to 2060: linear interpolation between whole UTC hours.
    unix = np.sort(np.random.default_rng(5).uniform(6.3e8, 2.9e9, 5000))
    exact = spa_geocentric(unix)
    utc_ns = (unix * 1e9).astype(np.int64)
    at_nodes, change, index = _geocentric_hourly(utc_ns, SunTerms())
    weight = (utc_ns % 3_600_000_000_000) / 3.6e12
    for row, name in enumerate(_GEOCENTRIC):
        difference = exact[name] - (at_nodes[row, index] + weight * change[row, index])
        if name in ("alpha", "v"):
            difference = (difference + 180.0) % 360.0 - 180.0
        bound = 4e-5 if name == "eot" else 1e-5  # 1e-5 deg; the equation of time in minutes (4 min a degree)
        assert np.abs(difference).max() < bound, name


def _equatorial_by_numpy(utc_ns):
    """SPA's time-only terms at instants (:func:`foldopt.physics.spa._equatorial`) as NumPy
    expressions: the interpolation of each geocentric term between its hours, and its trigonometry."""
    from foldopt.physics.spa import _GEOCENTRIC, NS_PER_HOUR, SunTerms, _geocentric_hourly

    at_nodes, change, index = _geocentric_hourly(utc_ns, SunTerms())
    index = index.reshape(utc_ns.shape)
    hours = np.floor_divide(utc_ns, NS_PER_HOUR)
    weight = (utc_ns - hours * NS_PER_HOUR) / NS_PER_HOUR
    geo = {name: at_nodes[row][index] + weight * change[row][index] for row, name in enumerate(_GEOCENTRIC)}
    greenwich, delta = np.radians(geo["v"] - geo["alpha"]), np.radians(geo["delta"])
    return np.stack([np.cos(delta) * np.cos(greenwich), np.cos(delta) * np.sin(greenwich), np.sin(delta),
                     np.sin(np.radians(geo["xi"])), geo["eot"]])


@pytest.mark.parametrize("least", [1_000_000, 1])
def test_equatorial_terms_in_a_compiled_pass_are_numpys_bits(monkeypatch, least):
    """The compiled pass of SPA's time-only terms at every instant, on one thread or three, gives
    the bits of their NumPy expressions (the C library's sines and cosines, which NumPy's float64
    ones call), at 2-min steps over days from 1950 to 2090."""
    import numba

    import foldopt.physics.spa as spa

    monkeypatch.setattr(spa, "EQUATORIAL_STEPS_A_THREAD", least)
    monkeypatch.setattr(numba, "get_num_threads", lambda: 3)
    days = np.random.default_rng(3).integers(-7_300, 43_800, 40)
    utc_ns = (days[:, None] * 86_400 + np.arange(0, 86_400, 120)[None, :]) * 1_000_000_000
    np.testing.assert_array_equal(spa._equatorial(utc_ns, spa.SunTerms()), _equatorial_by_numpy(utc_ns))


def test_geocentric_periodic_terms_are_pvlib_spa_bits():
    """SPA's periodic series (the Earth's heliocentric longitude, latitude and radius, and the
    nutation), summed over all their terms at once, are the bits of pvlib.spa's loops over the
    terms, at instants from 1900 to 2100 and around the present."""
    from foldopt.physics import spa as split

    spa = pvlib.spa
    rng = np.random.default_rng(11)
    unix = np.concatenate([rng.uniform(-2.2e9, 4.1e9, 20_000), 1.7e9 + 3600.0 * np.arange(9_000)])
    jce = spa.julian_ephemeris_century(spa.julian_ephemeris_day(spa.julian_day(unix), split.SPA_DELTA_T))
    jme = spa.julian_ephemeris_millennium(jce)
    args = (spa.mean_elongation(jce), spa.mean_anomaly_sun(jce), spa.mean_anomaly_moon(jce),
            spa.moon_argument_latitude(jce), spa.moon_ascending_longitude(jce))
    sums, (psi, epsilon) = split._periodic(spa, jme, jce, args)
    np.testing.assert_array_equal(split._heliocentric(sums["R"], jme), spa.heliocentric_radius_vector(jme))
    np.testing.assert_array_equal(np.rad2deg(split._heliocentric(sums["L"], jme)) % 360,
                                  spa.heliocentric_longitude(jme))
    np.testing.assert_array_equal(np.rad2deg(split._heliocentric(sums["B"], jme)),
                                  spa.heliocentric_latitude(jme))
    nutation = np.empty((2, unix.size))
    spa.longitude_obliquity_nutation(jce, *args, nutation)
    np.testing.assert_array_equal(psi, nutation[0])
    np.testing.assert_array_equal(epsilon, nutation[1])


def test_geocentric_terms_of_a_long_series_are_pvlib_spa_s_bits_chunk_by_chunk():
    """A series longer than a chunk of instants (and shaped, not a multiple of the chunk): its
    right ascension and declination are the bits of pvlib.spa's own steps at every instant."""
    from foldopt.physics import spa as split

    spa = pvlib.spa
    unix = (1.1e9 + 3600.0 * np.arange(3 * split.GEOCENTRIC_CHUNK + 7)).reshape(-1, 1)
    found = split.spa_geocentric(unix)
    flat = unix.ravel()
    jd = spa.julian_day(flat)
    jde = spa.julian_ephemeris_day(jd, split.SPA_DELTA_T)
    jce = spa.julian_ephemeris_century(jde)
    jme = spa.julian_ephemeris_millennium(jce)
    radius = spa.heliocentric_radius_vector(jme)
    theta = spa.geocentric_longitude(spa.heliocentric_longitude(jme))
    beta = spa.geocentric_latitude(spa.heliocentric_latitude(jme))
    args = (spa.mean_elongation(jce), spa.mean_anomaly_sun(jce), spa.mean_anomaly_moon(jce),
            spa.moon_argument_latitude(jce), spa.moon_ascending_longitude(jce))
    nutation = np.empty((2, flat.size))
    spa.longitude_obliquity_nutation(jce, *args, nutation)
    epsilon = spa.true_ecliptic_obliquity(spa.mean_ecliptic_obliquity(jme), nutation[1])
    lamd = spa.apparent_sun_longitude(theta, nutation[0], spa.aberration_correction(radius))
    assert found["alpha"].shape == unix.shape
    np.testing.assert_array_equal(
        found["alpha"].ravel(), spa.geocentric_sun_right_ascension(lamd, epsilon, beta)
    )
    np.testing.assert_array_equal(
        found["delta"].ravel(), spa.geocentric_sun_declination(lamd, epsilon, beta)
    )


def test_many_sites_at_once_equal_pvlib_at_each():
    from foldopt.physics.solarposition import clock_grid, solar_position_grid

    dates = [dt.date(2025, 1, 5), dt.date(2025, 6, 30), dt.date(2025, 10, 1)]
    latitude = np.array([[-70.0], [12.5], [64.0]])
    longitude = np.array([[-150.0], [33.0], [179.0]])
    altitude = np.array([[0.0], [1500.0], [40.0]])
    grid = clock_grid(dates, "UTC", 30)
    sun = solar_position_grid(grid, latitude, longitude, altitude, "exact")
    for block in range(3):
        spa = pvlib.solarposition.get_solarposition(grid.times(block), latitude[block, 0], longitude[block, 0],
                                                    altitude=altitude[block, 0])
        np.testing.assert_allclose(sun["solar_zenith"][block], spa["apparent_zenith"], atol=1e-6)
        np.testing.assert_allclose(sun["solar_azimuth"][block], spa["azimuth"], atol=1e-6)


def test_split_spa_equals_pvlib_spa_python_on_random_sites():
    # The split calls pvlib.spa's step functions, not pvlib's public API (see foldopt.physics.spa and
    # the pin in pyproject.toml); this holds it to the public spa_python. Random sites and days at
    # 1-min steps: the sun's direction within 1e-5 deg (measured 1.7e-6). SPA switches its
    # refraction off 0.8334 deg below the horizon, a jump of up to 0.6 deg that any difference in
    # the geometric elevation can move across a step: those steps are left out.
    from foldopt.physics.geometry import normal_vector
    from foldopt.physics.solarposition import clock_grid, solar_position_grid
    from foldopt.physics.spa_site import SPA_ATMOS_REFRACT

    rng = np.random.default_rng(2024)
    n = 12
    latitude, longitude = rng.uniform(-66, 70, (n, 1)), rng.uniform(-180, 180, (n, 1))
    altitude = rng.uniform(0, 3000, (n, 1))
    dates = [dt.date(1995, 1, 1) + dt.timedelta(days=int(d)) for d in rng.integers(0, 60 * 365, n)]
    grid = clock_grid(dates, "UTC", 1)
    sun = solar_position_grid(grid, latitude, longitude, altitude, "exact")
    for block in range(n):
        spa = pvlib.solarposition.spa_python(grid.times(block), latitude[block, 0], longitude[block, 0],
                                             altitude[block, 0], pvlib.atmosphere.alt2pres(altitude[block, 0]))
        cut_off = np.abs(spa["elevation"].to_numpy() + 0.26667 + SPA_ATMOS_REFRACT) < 0.01
        compared = (spa["apparent_elevation"].to_numpy() > -1) & ~cut_off
        a = normal_vector(sun["solar_zenith"][block], sun["solar_azimuth"][block])[compared]
        b = normal_vector(spa["apparent_zenith"].to_numpy(), spa["azimuth"].to_numpy())[compared]
        angle = np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1)))
        assert angle.max() < 1e-5, (latitude[block, 0], longitude[block, 0], dates[block])


def test_hours_kept_for_a_run_are_the_same_bits():
    """The time-only SPA terms a run keeps per UTC hour (a map's sites share them) are the bits a
    direct evaluation gives, whichever calls filled the store first."""
    import foldopt.physics.spa as spa

    hours = np.arange(482_000, 482_000 + 9_000, dtype=np.int64)
    direct = spa.spa_geocentric(hours * 3600.0)
    kept = spa.SunTerms()
    kept.at_hours(hours[1000:3000])
    kept.at_hours(hours[::7])
    again = kept.at_hours(hours)
    for name, values in direct.items():
        np.testing.assert_array_equal(again[name], values)
    # Past its bound a store starts again, and still answers with the same bits.
    small = spa.SunTerms(hours_kept=2_500)
    small.at_hours(hours[:2_000])
    again = small.at_hours(hours[4_000:6_000])
    assert small._hours[0].size == 2_000
    for name, values in direct.items():
        np.testing.assert_array_equal(again[name], values[4_000:6_000])


def test_steps_kept_per_lattice_are_the_same_bits():
    """The time-only terms a run keeps per UTC step (a map's sites of one year share them whatever
    their time zone) are the bits a direct evaluation gives, whichever calls filled the store
    first, and the sun a shared store gives is the sun each call's own store gives."""
    import foldopt.physics.spa as spa
    from foldopt.physics.solarposition import clock_grid, solar_position_grid

    grid = clock_grid([dt.date(2025, 1, 1) + dt.timedelta(days=d) for d in range(0, 40, 3)], "UTC+03:00", 5)
    direct = spa._equatorial(grid.utc_ns, spa.SunTerms())
    kept = spa.SunTerms()
    kept.on_lattice(grid.utc_ns[5:9])
    kept.on_lattice(grid.utc_ns[::4])
    first, terms = kept.on_lattice(grid.utc_ns)
    again = np.stack([terms[:, start:start + grid.utc_ns.shape[1]] for start in first], axis=1)
    np.testing.assert_array_equal(again, direct)
    other = clock_grid([dt.date(2025, 1, 1) + dt.timedelta(days=d) for d in range(0, 40, 3)], "UTC-07:00", 5)
    shared = solar_position_grid(other, 40.0, -105.0, 1600.0, "exact", kept)
    alone = solar_position_grid(other, 40.0, -105.0, 1600.0, "exact")
    for name in ("solar_zenith", "solar_azimuth", "hour_angle", "sun_vector"):
        np.testing.assert_array_equal(shared[name], alone[name])


@pytest.mark.parametrize(
    "days, zones",
    [
        (range(0, 365, 28), ["UTC-08:00"]),  # days spread over a year, apart
        (range(0, 6), ["UTC+03:00", "UTC-07:00", "UTC+05:30"]),  # consecutive, overlapping in UTC
        ([0, 0, 3], ["UTC"]),  # a block twice
        ([68, 69, 70], ["America/Los_Angeles"]),  # 10 March, a DST day: off the lattice
    ],
)
def test_a_call_alone_evaluates_the_instants_it_spans_to_the_bit(days, zones):
    """A sky built with no run's store evaluates SPA's time-only terms at the instants its blocks
    span alone (not a year's lattice for days spread over it): each block's terms are the bits a
    direct evaluation at its own instants gives, and so is the sun."""
    import foldopt.physics.spa as spa
    from foldopt.physics.solarposition import ClockGrid, clock_grid, solar_position_grid

    dates = [dt.date(2024, 1, 1) + dt.timedelta(days=d) for d in days]
    grid = ClockGrid.stack([clock_grid(dates, zone, 5) for zone in zones])
    direct = spa._equatorial(grid.utc_ns, spa.SunTerms())
    first, terms = spa.equatorial_once(grid.utc_ns)
    assert terms.shape[1] <= grid.utc_ns.size
    again = np.stack([terms[:, start:start + grid.utc_ns.shape[1]] for start in first], axis=1)
    np.testing.assert_array_equal(again, direct)
    kept = solar_position_grid(grid, 40.0, -105.0, 1600.0, "exact", spa.SunTerms())
    alone = solar_position_grid(grid, 40.0, -105.0, 1600.0, "exact")
    for name in ("solar_zenith", "solar_azimuth", "hour_angle", "sun_vector"):
        np.testing.assert_array_equal(alone[name], kept[name])


@pytest.mark.parametrize("starts", [[0, 1440, 4320], [4320, 0], [0, 700, 1440, 9000], [5, 5, 1445], [3]])
def test_instants_blocks_span_are_the_union_of_their_days(starts):
    """The lattice's instants a run's blocks span: apart (days of one time zone) or overlapping
    (days of several zones, a block twice), the sorted union of every block's own instants."""
    from foldopt.physics.spa import _spanned

    starts = np.array(starts)
    union = np.unique(np.concatenate([start + np.arange(1440) for start in starts]))
    np.testing.assert_array_equal(_spanned(starts, 1440, starts.max() + 1440), union)


def test_the_sun_keeps_nothing_between_calls():
    """Issue 48: no hidden state. A call given no store leaves the module as it found it (no
    module-level store of SPA's terms), and a store lives as long as the run that made it."""
    import foldopt.physics.spa as spa
    from foldopt.physics.solarposition import clock_grid, solar_position_grid

    before = {name: id(value) for name, value in vars(spa).items()}
    grid = clock_grid([dt.date(2025, 6, 1)], "UTC", 10)
    solar_position_grid(grid, 10.0, 20.0, 0.0, "exact")
    assert {name: id(value) for name, value in vars(spa).items()} == before
    mutable = [name for name, value in vars(spa).items()
               if isinstance(value, (dict, list, set, tuple)) and not name.startswith("__")]
    assert sorted(mutable) == ["_GEOCENTRIC", "_SERIES", "_WRAPPED"], mutable  # constant tuples of names


def test_a_lattice_evaluates_only_the_instants_its_days_span(monkeypatch):
    """Days spread over a year on one lattice (a sweep's 24 days, W2's sites) evaluate SPA's
    time-only terms at their own instants, not at every step between the first and the last; a
    later call evaluates only what no call has, and every answer is the direct evaluation's bits."""
    import foldopt.physics.spa as spa
    from foldopt.physics.solarposition import clock_grid

    evaluated = []

    def counted(utc_ns, sun_terms):
        evaluated.append(np.size(utc_ns))
        return direct_equatorial(utc_ns, sun_terms)

    direct_equatorial = spa._equatorial
    monkeypatch.setattr(spa, "_equatorial", counted)
    dates = [dt.date(2025, m, d) for m in range(1, 13) for d in (1, 15)]
    grid = clock_grid(dates, "UTC", 10)
    kept = spa.SunTerms()
    first, terms = kept.on_lattice(grid.utc_ns[::2])
    assert evaluated == [12 * 144]
    first, terms = kept.on_lattice(grid.utc_ns)
    assert evaluated == [12 * 144, 12 * 144]
    again = np.stack([terms[:, start:start + 144] for start in first], axis=1)
    np.testing.assert_array_equal(again, direct_equatorial(grid.utc_ns, spa.SunTerms()))


@pytest.mark.parametrize("spread_ns", [3.6e12 * 24 * 400, 3.6e12 * 24 * 365 * 200])
def test_hour_nodes_are_uniques_and_their_places(spread_ns):
    """The hours an interpolation reads (SPA's geocentric terms): those of np.unique and
    np.searchsorted, for instants over a year and over centuries (the two ways they are found)."""
    from foldopt.physics.spa import NS_PER_HOUR, _hour_nodes

    utc_ns = np.random.default_rng(3).integers(0, int(spread_ns), (40, 30))
    hours = np.floor_divide(utc_ns, NS_PER_HOUR)
    nodes, index = _hour_nodes(hours)
    expected = np.unique(np.concatenate([hours.ravel(), hours.ravel() + 1]))
    np.testing.assert_array_equal(nodes, expected)
    np.testing.assert_array_equal(index, np.searchsorted(expected, hours))


def test_the_per_site_pass_on_threads_has_the_bits_of_one(monkeypatch):
    """SPA's per-site pass over many blocks runs on numba's threads, a slice of the blocks each: the
    same bits as one pass (each block's steps are its own)."""
    import numba

    import foldopt.physics.spa as spa
    from foldopt.physics.solarposition import clock_grid

    dates = [dt.date(2025, 1, 1) + dt.timedelta(days=d) for d in range(0, 365, 30)]
    grid = clock_grid(dates, "UTC", 30)
    latitude = np.linspace(-80, 80, len(dates))[:, None]
    one = spa.spa_solar_position(grid.utc_ns, latitude, 20.0, 100.0)
    monkeypatch.setattr(spa, "SITE_STEPS_A_THREAD", 1)
    monkeypatch.setattr(numba, "get_num_threads", lambda: 3)
    threads = spa.spa_solar_position(grid.utc_ns, latitude, 20.0, 100.0)
    for a, b in zip(one, threads, strict=True):
        np.testing.assert_array_equal(a, b)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_a_grids_day_of_year_is_the_calendars(seed, across):
    """Each step's local day of year is the calendar's (pandas'), for blocks of one local day
    (looked up once a block) and blocks whose steps a clock's change carries over midnight."""
    from foldopt.physics.solarposition import ClockGrid

    rng = np.random.default_rng(seed)
    n_blocks, n_steps = int(rng.integers(1, 6)), int(rng.integers(1, 40))
    day = 86_400 * 10**9
    start = rng.integers(-80 * 365, 80 * 365, (n_blocks, 1)) * day
    spread = day if across else day // n_steps
    utc = start + np.cumsum(rng.integers(0, spread, (n_blocks, n_steps)), axis=1)
    offset = np.zeros((n_blocks, n_steps), dtype=np.int64)
    grid = ClockGrid(utc, offset, ("UTC",) * n_blocks, 24.0 / n_steps)
    expected = pd.DatetimeIndex(grid.local_ns.ravel().astype("datetime64[ns]")).day_of_year
    np.testing.assert_array_equal(grid.dayofyear, np.reshape(expected, grid.shape))


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_a_day_table_looked_up_is_the_function_at_each_step(seed):
    """by_dayofyear's table (worked out once a process) gives pvlib's declination and the
    extraterrestrial irradiance evaluated at each step's day directly, to the bit, whichever days
    and shape (and however often it is asked)."""
    import pvlib

    from foldopt.physics.atmosphere import extraterrestrial_spencer
    from foldopt.physics.solarposition import _declination_spencer, by_dayofyear

    rng = np.random.default_rng(seed)
    days = rng.integers(1, 367, tuple(rng.integers(1, 6, 2)))
    for _ in range(2):
        np.testing.assert_array_equal(
            by_dayofyear(_declination_spencer, days),
            np.degrees(pvlib.solarposition.declination_spencer71(days)),
        )
        np.testing.assert_array_equal(
            by_dayofyear(extraterrestrial_spencer, days), extraterrestrial_spencer(days)
        )
