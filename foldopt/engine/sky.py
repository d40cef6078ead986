"""The light over many days and sites at once: everything that does not depend on the panel.

A :class:`Sky` holds, for every *block* (one local day at one site) and every time step, the sun's
position and unit vector, the direct normal irradiance and, with a transposition model, the four
orientation-free diffuse terms of :func:`foldopt.physics.irradiance.sky_diffuse_terms`. It is built as
one array program over all blocks (:func:`build_sky`): one clock grid, one solar-position
evaluation, one air mass and clear-sky pass. The engine then evaluates any number of panel
orientations against it. Blocks may be different sites and days; they share the study's settings
(mode, sky model, step...).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
import pvlib

from foldopt.physics.atmosphere import clear_sky_dni, relative_airmass
from foldopt.inputs.sections import parse_timezone
from foldopt.inputs.study import Study
from foldopt.physics.geometry import normal_vector
from foldopt.physics.irradiance import sky_diffuse_terms
from foldopt.inputs.loads import load_shape
from foldopt.physics.solarposition import ClockGrid, clock_grid, solar_position_grid
from foldopt.inputs.weather import read_weather, weather_days, weather_site
from foldopt.names import CLEAR_SKIES
from foldopt.inputs.weather.downscale import clear_sky, sub_hourly


@dataclass(frozen=True)
class Sky:
    """Sun and light per block (a day at a site) and time step; arrays are (n_blocks, n_steps).

    Attributes
    ----------
    grid : ClockGrid
    mode : {'paper', 'exact'}
    solar_zenith, solar_azimuth, hour_angle, declination : numpy.ndarray
        [deg]; the apparent zenith in exact mode.
    sun_vector : numpy.ndarray
        (n_blocks, n_steps, 3) unit vectors east, north, up.
    dni : numpy.ndarray
        Direct normal irradiance [W/m^2].
    ghi, dhi : numpy.ndarray or None
        Global and diffuse horizontal irradiance [W/m^2], where the sky has them.
    terms : numpy.ndarray or None
        (n_blocks, n_steps, 4) diffuse terms; None when the study is beam only.
    temp_air : numpy.ndarray
        (n_blocks,) the air temperature the cells of each block see [C].
    latitude : numpy.ndarray
        (n_blocks,) [deg north].
    iam : {'none', 'ashrae', 'physical'}
    load_shape : numpy.ndarray or None
        With a load profile, P_load(t) per block and step for a scale of 1 [W]
        (:func:`foldopt.inputs.loads.load_shape`); None for a constant load.
    weather_balance : dict or None
        With a weather file: per component (``dni``, ``ghi``, ``dhi``), the file's summed interval
        means and what the steps keep of them [W/m^2 x intervals] (:func:`foldopt.inputs.weather.downscale.sub_hourly`).
    """

    grid: ClockGrid
    mode: str
    solar_zenith: np.ndarray
    solar_azimuth: np.ndarray
    hour_angle: np.ndarray
    declination: np.ndarray
    sun_vector: np.ndarray
    dni: np.ndarray
    ghi: np.ndarray | None
    dhi: np.ndarray | None
    terms: np.ndarray | None
    temp_air: np.ndarray
    latitude: np.ndarray
    iam: str
    weather_balance: dict | None = None
    load_shape: np.ndarray | None = None

    @property
    def n_blocks(self) -> int:
        """Number of blocks (days at sites)."""
        return self.dni.shape[0]

    @property
    def step_hours(self) -> float:
        """Step length [h]."""
        return self.grid.step_hours

    @property
    def lit(self) -> np.ndarray:
        """Steps with any light on some orientation."""
        if self.terms is None:
            return self.dni > 0
        return (self.dni > 0) | np.any(self.terms != 0, axis=-1)

    @property
    def paper_sun(self) -> np.ndarray:
        """cos(zenith), sin(zenith), sin(azimuth), cos(azimuth): the sun's part of Eq. 5."""
        zenith, azimuth = np.radians(self.solar_zenith), np.radians(self.solar_azimuth)
        return np.stack([np.cos(zenith), np.sin(zenith), np.sin(azimuth), np.cos(azimuth)], axis=-1)

    def conditions(self) -> np.ndarray:
        """What kind of day each block is, for the notes of reports: ``polar night`` (the sun does
        not rise), ``polar day`` (it does not set), ``overcast`` (it is up but no direct light
        arrives all day), joined by ``; ``, or ``""``. (n_blocks,) of str."""
        up = self.solar_zenith < 90.0
        rises, sets = up.any(axis=1), ~up.all(axis=1)
        overcast = rises & ~((self.dni > 0) & up).any(axis=1)
        parts = [np.where(~rises, "polar night", ""), np.where(~sets, "polar day", ""),
                 np.where(overcast, "overcast", "")]
        return np.array(["; ".join(p for p in block if p) for block in zip(*parts, strict=True)], dtype=object)

    def block(self, index: int) -> Sky:
        """One block as a sky of its own.

        Parameters
        ----------
        index : int
            The block.

        Returns
        -------
        Sky
            Of one block: every array keeps its leading axis, of length 1.
        """
        keep = slice(index, index + 1)
        grid = ClockGrid(self.grid.utc_ns[keep], self.grid.utc_offset_ns[keep], self.grid.timezones[keep],
                         self.grid.step_hours)
        take = {name: None if getattr(self, name) is None else getattr(self, name)[keep]
                for name in ("solar_zenith", "solar_azimuth", "hour_angle", "declination", "sun_vector", "dni",
                             "ghi", "dhi", "terms", "temp_air", "latitude")}
        return Sky(grid=grid, mode=self.mode, iam=self.iam, weather_balance=self.weather_balance,
                   load_shape=None if self.load_shape is None else self.load_shape[keep], **take)


def _clock(sites, dates, step_min) -> ClockGrid:
    """One clock grid for every block, one localisation per time zone, blocks in their order."""
    zones: dict[str, list[int]] = {}
    for index, site in enumerate(sites):
        zones.setdefault(site.timezone, []).append(index)
    parts = [clock_grid([dates[i] for i in members], parse_timezone(zone), step_min) for zone, members in zones.items()]
    order = np.argsort(np.concatenate(list(zones.values())), kind="stable")
    stacked = ClockGrid.stack(parts)
    return ClockGrid(stacked.utc_ns[order], stacked.utc_offset_ns[order],
                     tuple(stacked.timezones[i] for i in order), stacked.step_hours)


def _clear_sky(grid: ClockGrid, zenith, sites, model: str, linke_turbidity) -> dict:
    """pvlib's clear sky at every step, one call per site (its blocks' steps together)."""
    light = {key: np.empty_like(zenith) for key in ("dni", "ghi", "dhi")}
    groups: dict[tuple, list[int]] = {}
    for index, site in enumerate(sites):
        groups.setdefault((site.latitude, site.longitude, site.altitude, site.timezone), []).append(index)
    for (latitude, longitude, altitude, zone), members in groups.items():
        times = pd.DatetimeIndex(grid.utc_ns[members].ravel().astype("datetime64[ns]"), tz="UTC").tz_convert(
            parse_timezone(zone))
        sky = clear_sky(times, zenith[members].ravel(), latitude, longitude, altitude, model, linke_turbidity)
        for key in light:
            light[key][members] = sky[key].reshape(len(members), -1)
    return light


def _weather_light(study: Study, grid: ClockGrid, dates, clear: dict):
    """Light at every step of the grid from the study's weather file
    (:func:`foldopt.inputs.weather.downscale.sub_hourly` against the clear sky), the cell air
    temperature of each day, and how much of the file's irradiation the steps keep."""
    weather = study.weather
    columns = ("dni", "ghi", "dhi", "temp_air")
    hourly = {key: np.empty((len(dates), 0)) for key in columns}
    starts = np.empty((len(dates), 0), dtype=np.int64)
    # The file is coerced to each date's year: read once per year, the days picked as arrays.
    for year in sorted({date.year for date in dates}):
        positions = [i for i, date in enumerate(dates) if date.year == year]
        frame = read_weather(weather.path, weather.format, year, weather.label)
        rows = weather_days(frame, [dates[i] for i in positions])
        index = pd.DatetimeIndex(frame.index)
        centres = index.tz_localize(None).as_unit("ns").asi8[rows]
        interval = int(np.median(np.diff(index.as_unit("ns").asi8)))
        if starts.shape[1] == 0:
            starts = np.zeros((len(dates), rows.shape[1]), dtype=np.int64)
            hourly = {key: np.zeros((len(dates), rows.shape[1])) for key in columns}
        starts[positions] = centres - interval // 2
        for key in columns:
            hourly[key][positions] = frame[key].to_numpy(dtype=float)[rows]
    step_ns = round(grid.step_hours * 3.6e12)
    day_start = grid.local_ns[:, :1] - step_ns // 2
    per_interval = interval // step_ns
    if interval % step_ns or not np.array_equal(starts, day_start + np.arange(starts.shape[1]) * interval):
        raise ValueError(f"weather: the study's step ({grid.step_hours * 60:g} min) must divide the file's "
                         f"intervals ({interval / 6e10:g} min), which must start at the day's midnight")
    light, balance = {}, {}
    # The diffuse light of a cloudy sky is far above a clear sky's; it follows the sun like the
    # clear sky's global light does, which is its shape here.
    for key, shape in (("dni", "dni"), ("ghi", "ghi"), ("dhi", "ghi")):
        light[key], placed = sub_hourly(hourly[key], clear[shape], per_interval)
        balance[key] = (float(hourly[key].sum()), float(placed.sum()))
    # Cells follow each day's mean air temperature (the electrical tables assume one per day),
    # rounded to 5 C so that days share their tables; wind stays the study's.
    temp_air = np.round(hourly["temp_air"].mean(axis=1) / 5.0) * 5.0
    return light, temp_air, balance


def build_sky(study: Study, sites, dates) -> Sky:
    """The sky of a study's settings over blocks, one per (site, date), as one array program.

    Parameters
    ----------
    study : Study
        Mode, sky model, weather file, step, transposition, albedo, incidence-angle modifier, air
        temperature (its site and date are not used).
    sites : sequence of foldopt.inputs.sections.Site
        One per block: latitude, longitude, altitude and time zone.
    dates : sequence of datetime.date
        The local day of each block, one per site.

    Returns
    -------
    Sky

    Raises
    ------
    ValueError
        If ``sites`` and ``dates`` differ in length, or a weather file's intervals do not fit the
        study's step.
    """
    study = study.resolved()
    sites = [site.resolved() for site in sites]
    if len(sites) != len(dates):
        raise ValueError(f"{len(sites)} sites for {len(dates)} dates")
    if study.weather is not None:
        # A weather file's days are on its own clock, whatever time zone the site names.
        zone = weather_site(study.weather.path, study.weather.format)["timezone"]
        sites = [site.model_copy(update={"timezone": zone}) for site in sites]
    latitude = np.array([site.latitude for site in sites], dtype=float)[:, None]
    longitude = np.array([site.longitude for site in sites], dtype=float)[:, None]
    altitude = np.array([site.altitude for site in sites], dtype=float)[:, None]
    grid = _clock(sites, dates, study.step_min)
    sun = solar_position_grid(grid, latitude, longitude, altitude, study.mode)
    zenith = sun["solar_zenith"]
    temp_air, balance = np.full(len(sites), float(study.temp_air)), None
    if study.weather is not None:
        clear = _clear_sky(grid, zenith, sites, "ineichen", study.linke_turbidity)
        light, temp_air, balance = _weather_light(study, grid, dates, clear)
    elif study.sky in CLEAR_SKIES:
        light = _clear_sky(grid, zenith, sites, study.sky, study.linke_turbidity)
    else:
        beam_altitude = altitude if study.mode == "exact" else 0.0
        light = {"dni": clear_sky_dni(zenith, beam_altitude, study.sky, dayofyear=grid.day_of_year,
                                      climate=study.climate)}
    dni = light["dni"]
    ghi, dhi = light.get("ghi"), light.get("dhi")
    terms = None
    transposition = study.sky_transposition()
    if transposition != "none":
        dni_extra = np.asarray(pvlib.irradiance.get_extra_radiation(np.arange(367)), dtype=float)[grid.day_of_year]
        airmass = np.nan_to_num(relative_airmass(np.minimum(zenith, 90.0)), nan=0.0)
        terms = sky_diffuse_terms(
            transposition, zenith, dni,
            ghi if ghi is not None else dni * np.clip(np.cos(np.radians(zenith)), 0, None),
            dhi if dhi is not None else np.zeros_like(dni), dni_extra, airmass, study.albedo,
        )
    return Sky(
        grid=grid, mode=study.mode, solar_zenith=zenith, solar_azimuth=sun["solar_azimuth"],
        hour_angle=sun["hour_angle"], declination=np.ascontiguousarray(sun["declination"]),
        sun_vector=normal_vector(zenith, sun["solar_azimuth"]), dni=dni, ghi=ghi, dhi=dhi, terms=terms,
        temp_air=temp_air, latitude=latitude[:, 0], iam=study.iam, weather_balance=balance,
        load_shape=None if study.load_profile is None else load_shape(study.load_profile, grid.clock_hours, dates),
    )
