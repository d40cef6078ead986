"""The light over many days and sites at once: everything that does not depend on the panel.

A :class:`Sky` holds, for every *block* (one local day at one site) and every time step, the sun's
position and unit vector, the direct normal irradiance and, with a transposition model, the four
orientation-free diffuse terms of :func:`foldopt.irradiance.sky_diffuse_terms`. It is built as
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

from foldopt.atmosphere import clear_sky_dni, relative_airmass
from foldopt.config import Study, parse_timezone
from foldopt.geometry import normal_vector
from foldopt.irradiance import sky_diffuse_terms
from foldopt.solarposition import ClockGrid, clock_grid, solar_position_grid
from foldopt.weather import CLEAR_SKIES, clear_sky, read_weather, weather_days

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

    @property
    def n_blocks(self) -> int:
        return self.dni.shape[0]

    @property
    def step_hours(self) -> float:
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

    def block(self, index: int) -> Sky:
        """One block as a sky of its own (arrays keep their leading axis, of length 1)."""
        keep = slice(index, index + 1)
        grid = ClockGrid(self.grid.utc_ns[keep], self.grid.utc_offset_ns[keep], self.grid.timezones[keep],
                         self.grid.step_hours)
        take = {name: None if getattr(self, name) is None else getattr(self, name)[keep]
                for name in ("solar_zenith", "solar_azimuth", "hour_angle", "declination", "sun_vector", "dni",
                             "ghi", "dhi", "terms", "temp_air", "latitude")}
        return Sky(grid=grid, mode=self.mode, iam=self.iam, **take)


def _weather_grid(study: Study, dates):
    """Clock grid, light and cell air temperature of each date from the study's weather file."""
    weather, columns = study.weather, ("dni", "ghi", "dhi", "temp_air")
    pieces = []
    # The file is coerced to each date's year: read once per year, the days picked as arrays.
    for year in sorted({date.year for date in dates}):
        positions = [i for i, date in enumerate(dates) if date.year == year]
        frame = read_weather(weather.path, weather.format, year, weather.label)
        rows = weather_days(frame, [dates[i] for i in positions])
        index = pd.DatetimeIndex(frame.index)
        pieces.append((positions, index.tz_convert("UTC").tz_localize(None).as_unit("ns").asi8[rows],
                       index.tz_localize(None).as_unit("ns").asi8[rows],
                       {key: frame[key].to_numpy(dtype=float)[rows] for key in columns}, index.tz))
    order = np.argsort(np.concatenate([piece[0] for piece in pieces]), kind="stable")

    def gather(parts):
        return np.concatenate(parts)[order]

    utc, local = gather([piece[1] for piece in pieces]), gather([piece[2] for piece in pieces])
    light = {key: gather([piece[3][key] for piece in pieces]) for key in columns}
    step_hours = float(np.median(np.diff(utc[0]))) / 3.6e12 if utc.shape[1] > 1 else 24.0
    grid = ClockGrid(utc, local - utc, (pieces[0][4],) * len(dates), step_hours)
    # Cells follow each day's mean air temperature (the electrical tables assume one per day),
    # rounded to 5 C so that days share their tables; wind stays the study's.
    temp_air = np.round(light.pop("temp_air").mean(axis=1) / 5.0) * 5.0
    return grid, light, temp_air


def build_sky(study: Study, sites, dates) -> Sky:
    """The sky of a study's settings over blocks, one per (site, date), as one array program.

    Parameters
    ----------
    study : Study
        Mode, sky model, weather file, step, transposition, albedo, incidence-angle modifier, air
        temperature (its site and date are not used).
    sites : sequence of foldopt.config.Site
    dates : sequence of datetime.date
        One per site.

    Returns
    -------
    Sky
    """
    study = study.resolved()
    sites = [site.resolved() for site in sites]
    if len(sites) != len(dates):
        raise ValueError(f"{len(sites)} sites for {len(dates)} dates")
    latitude = np.array([site.latitude for site in sites], dtype=float)[:, None]
    longitude = np.array([site.longitude for site in sites], dtype=float)[:, None]
    altitude = np.array([site.altitude for site in sites], dtype=float)[:, None]
    light = {}
    if study.weather is not None:
        grid, light, temp_air = _weather_grid(study, dates)
    else:
        # One localisation per time zone, blocks back in their order.
        zones: dict[str, list[int]] = {}
        for index, site in enumerate(sites):
            zones.setdefault(site.timezone, []).append(index)
        parts = [clock_grid([dates[i] for i in members], parse_timezone(zone), study.step_min)
                 for zone, members in zones.items()]
        order = np.argsort(np.concatenate(list(zones.values())), kind="stable")
        stacked = ClockGrid.stack(parts)
        grid = ClockGrid(stacked.utc_ns[order], stacked.utc_offset_ns[order],
                         tuple(stacked.timezones[i] for i in order), stacked.step_hours)
        temp_air = np.full(len(sites), float(study.temp_air))
    sun = solar_position_grid(grid, latitude, longitude, altitude, study.mode)
    zenith = sun["solar_zenith"]
    if study.weather is None and study.sky in CLEAR_SKIES:
        light = {key: np.empty_like(zenith) for key in ("dni", "ghi", "dhi")}
        for index, site in enumerate(sites):
            sky = clear_sky(grid.times(index), zenith[index], site.latitude, site.longitude, site.altitude, study.sky,
                            study.linke_turbidity)
            for key in light:
                light[key][index] = sky[key]
    elif study.weather is None:
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
        temp_air=temp_air, latitude=latitude[:, 0], iam=study.iam,
    )
