"""The light over many days and sites at once: everything that does not depend on the panel.

A :class:`Sky` holds, for every *block* (one local day at one site) and every time step, the sun's
position and unit vector, the direct normal irradiance and, with a transposition model, the four
orientation-free diffuse terms of :func:`foldopt.physics.irradiance.sky_diffuse_terms`. It is built as
one array program over all blocks (:func:`build_sky`): one clock grid, one solar-position
evaluation, and the light of :mod:`foldopt.engine.light` (a clear sky and its diffuse terms in one
compiled pass, or a weather file's light). The engine then evaluates any number of panel
orientations against it. Blocks may be different sites and days; they share one set of settings
(:class:`foldopt.engine.options.SkyOptions`: mode, sky model, step...).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from foldopt.engine.light import (
    clear_light,
    diffuse_terms,
    file_wind_ref,
    measured_light,
    member_light,
    weather_light,
)
from foldopt.engine.options import SkyOptions
from foldopt.inputs.load_profile import load_shape
from foldopt.inputs.sections import parse_timezone
from foldopt.names import CLEAR_SKIES
from foldopt.physics.atmosphere import clear_sky_dni, extraterrestrial_spencer
from foldopt.physics.horizon import sun_visible
from foldopt.physics.solarposition import (
    ClockGrid,
    by_dayofyear,
    clock_grid,
    solar_position_grid,
)
from foldopt.physics.spa import SunTerms
from foldopt.physics.temperature import equivalent_temp_air


def step_span(some) -> np.ndarray:
    """(n_rows, 2) the first and last true step of each row of ``some``, (n_rows, n_steps) bool,
    widened by one step either side within the row ((0, 0) for a row with none): the steps the
    engine walks (light, or power, and the dark step that ends it on each side)."""
    n_steps = some.shape[1]
    first = np.argmax(some, axis=1)
    last = n_steps - 1 - np.argmax(some[:, ::-1], axis=1)
    return np.ascontiguousarray(
        np.where(
            some.any(axis=1)[:, None],
            np.stack([np.maximum(first - 1, 0), np.minimum(last + 1, n_steps - 1)], 1),
            0,
        )
    )


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
        (n_blocks, n_steps, 4) diffuse terms; None for a beam-only sky.
    temp_air : numpy.ndarray
        (n_blocks,) the air temperature the cells of each block see [C]; with a weather file, its
        mean over the block's lit steps (``temp_steps`` holds every step's).
    latitude : numpy.ndarray
        (n_blocks,) [deg north].
    iam : {'none', 'ashrae', 'physical'}
    load_shape : numpy.ndarray or None
        With a load profile, P_load(t) per block and step for a scale of 1 [W]
        (:func:`foldopt.inputs.load_profile.load_shape`); None for a constant load.
    weather_balance : dict or None
        With a weather file: per component (``dni``, ``ghi``, ``dhi``), the file's summed interval
        means and what the steps keep of them [W/m^2 x intervals]
        (:func:`foldopt.inputs.weather.downscale.hourly_light`).
    temp_steps : numpy.ndarray or None
        With a weather file, (n_blocks, n_steps) the air temperature the cells see at each step
        [C]: the file's, linear between its stamps, and with the SAPM cell temperature the
        file's wind folded in as an equivalent air temperature (:func:`equivalent_temp_air`).
    wind_speed : numpy.ndarray or None
        With a weather file, (n_blocks, n_steps) the file's wind speed at each step [m/s].
    air_steps : numpy.ndarray or None
        With a weather file, (n_blocks, n_steps) the file's air temperature at each step [C],
        linear between its stamps (no wind folded in: a buffer's, issue 50).
    wind_ref : float or None
        With a weather file, the wind speed of the electrical tables [m/s]: the file's mean over
        its lit rows, to 0.5 m/s, so that the wind folded into ``temp_steps`` stays small
        (:func:`foldopt.engine.light.file_wind_ref`: the file's, whichever of its days a run takes).
    weather_notes : tuple of str
        With a measured weather file, what reading it did (its step, derived components, gaps:
        :meth:`foldopt.inputs.weather.measured.MeasuredWeather.report`).
    horizons : tuple of (numpy.ndarray, numpy.ndarray)
        The sites' horizon profiles, (azimuth, elevation) [deg] each, once per profile.
    horizon_of : numpy.ndarray or None
        (n_blocks,) the profile of each block's site in ``horizons``, -1 for an open plain; None
        where no site has a horizon. The beam and the circumsolar term are already blocked where
        the sun is below the horizon line; the sky's other diffuse terms are reduced per surface
        (:func:`foldopt.physics.horizon.sky_view_factors`).
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
    temp_steps: np.ndarray | None = None
    wind_speed: np.ndarray | None = None
    wind_ref: float | None = None
    weather_notes: tuple = ()
    horizons: tuple = ()
    horizon_of: np.ndarray | None = None
    air_steps: np.ndarray | None = None

    @property
    def n_blocks(self) -> int:
        """Number of blocks (days at sites)."""
        return self.dni.shape[0]

    @property
    def n_steps(self) -> int:
        """Number of time steps of each block."""
        return self.dni.shape[1]

    @property
    def step_hours(self) -> float:
        """Step length [h]."""
        return self.grid.step_hours

    @functools.cached_property
    def lit(self) -> np.ndarray:
        """Steps with any light on some orientation (worked out once: many callers ask)."""
        if self.terms is None:
            return self.dni > 0
        return (self.dni > 0) | np.any(self.terms != 0, axis=-1)

    @functools.cached_property
    def _layout(self) -> tuple:
        """The sun vector, the beam and the diffuse terms as the kernel reads them, each component
        along the time steps, contiguous: (n_blocks, 3, n_steps), (n_blocks, n_steps) and
        (n_blocks, 4, n_steps) (or (n_blocks, 0, 1) for a beam-only sky); and each block's span,
        (n_blocks, 2), its first and last step with light and one dark step either side."""
        terms = (
            np.ascontiguousarray(np.moveaxis(self.terms, -1, 1))
            if self.terms is not None
            else np.zeros((self.n_blocks, 0, 1))
        )
        return (
            np.ascontiguousarray(np.moveaxis(self.sun_vector, -1, 1)),
            np.ascontiguousarray(self.dni),
            terms,
            step_span(self.lit),
        )

    def kernel_layout(self, paper: bool) -> tuple:
        """``sun, paper_sun, beam, terms, span``: the sky as :func:`foldopt.engine.kernel.fold_rows`
        reads it (worked out once a sky: every engine call over it takes it), ``paper_sun``
        (:attr:`paper_sun` along the steps, (n_blocks, 4, n_steps)) only for ``paper`` incidence,
        a placeholder (1, 4, 1) otherwise.

        Parameters
        ----------
        paper : bool
            Shin et al.'s Eq. 5 for the beam's incidence.
        """
        sun, dni, terms, span = self._layout
        paper_sun = (
            np.ascontiguousarray(np.moveaxis(self.paper_sun, -1, 1))
            if paper
            else np.zeros((1, 4, 1))
        )
        return sun, paper_sun, dni, terms, span

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
        parts = [
            np.where(~rises, "polar night", ""),
            np.where(~sets, "polar day", ""),
            np.where(overcast, "overcast", ""),
        ]
        return np.array(
            ["; ".join(p for p in block if p) for block in zip(*parts, strict=True)], dtype=object
        )

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
        grid = ClockGrid(
            self.grid.utc_ns[keep],
            self.grid.utc_offset_ns[keep],
            self.grid.timezones[keep],
            self.grid.step_hours,
        )
        take = {
            name: None if getattr(self, name) is None else getattr(self, name)[keep]
            for name in (
                "solar_zenith",
                "solar_azimuth",
                "hour_angle",
                "declination",
                "sun_vector",
                "dni",
                "ghi",
                "dhi",
                "terms",
                "temp_air",
                "latitude",
                "temp_steps",
                "wind_speed",
                "air_steps",
            )
        }
        shape = None if self.load_shape is None else self.load_shape[keep]
        horizon_of = None if self.horizon_of is None else self.horizon_of[keep]
        return Sky(
            grid=grid,
            mode=self.mode,
            iam=self.iam,
            weather_balance=self.weather_balance,
            wind_ref=self.wind_ref,
            weather_notes=self.weather_notes,
            load_shape=shape,
            horizons=self.horizons,
            horizon_of=horizon_of,
            **take,
        )


def _horizon_blocks(sites):
    """Each distinct horizon profile of the sites once, and the profile of each site (-1: none)."""
    profiles, index, of = [], {}, []
    for site in sites:
        horizon = site.horizon
        if horizon is None or horizon.flat():
            of.append(-1)
            continue
        key = tuple(map(tuple, horizon.points))
        if key not in index:
            index[key] = len(profiles)
            profiles.append(horizon.profile())
        of.append(index[key])
    if not profiles:
        return (), None
    return tuple(profiles), np.array(of, dtype=np.int64)


def block_behind_horizon(horizons, horizon_of, solar_zenith, solar_azimuth, dni, terms):
    """The beam and the circumsolar light with the sun below each block's horizon line taken out.

    Parameters
    ----------
    horizons, horizon_of
        As :class:`Sky`'s.
    solar_zenith, solar_azimuth : numpy.ndarray
        (n_blocks, n_steps) [deg].
    dni : numpy.ndarray
        (n_blocks, n_steps) [W/m^2].
    terms : numpy.ndarray or None
        (n_blocks, n_steps, 4) diffuse terms (:func:`foldopt.physics.irradiance.sky_diffuse_terms`).

    Returns
    -------
    dni, terms : numpy.ndarray
        Copies, blocked.
    """
    dni = dni.copy()
    terms = None if terms is None else terms.copy()
    for k, (azimuth, elevation) in enumerate(horizons):
        blocks = np.flatnonzero(horizon_of == k)
        hidden = ~sun_visible(solar_zenith[blocks], solar_azimuth[blocks], azimuth, elevation)
        dni[blocks] = np.where(hidden, 0.0, dni[blocks])
        if terms is not None:
            terms[blocks, :, 1] = np.where(hidden, 0.0, terms[blocks, :, 1])
    return dni, terms


def _clock(sites, dates, step_min) -> ClockGrid:
    """One clock grid for every block, one localisation per time zone, blocks in their order."""
    zones: dict[str, list[int]] = {}
    for index, site in enumerate(sites):
        zones.setdefault(site.timezone, []).append(index)
    parts = [
        clock_grid([dates[i] for i in members], parse_timezone(zone), step_min)
        for zone, members in zones.items()
    ]
    order = np.argsort(np.concatenate(list(zones.values())), kind="stable")
    stacked = ClockGrid.stack(parts)
    if np.array_equal(order, np.arange(order.size)):
        return stacked  # each zone's blocks together already (a map's batch of sites)
    return ClockGrid(
        stacked.utc_ns[order],
        stacked.utc_offset_ns[order],
        tuple(stacked.timezones[i] for i in order),
        stacked.step_hours,
    )


def build_sky(
    options: SkyOptions, sites, dates, member=None, *, sun_terms: SunTerms | None = None
) -> Sky:
    """The sky of one set of settings over blocks, one per (site, date), as one array program.

    Parameters
    ----------
    options : SkyOptions
        Mode, sky model, weather file (read), step, transposition, albedo, incidence-angle
        modifier, air temperature.
    sites : sequence of foldopt.inputs.sections.Site
        One per block: latitude, longitude, altitude and time zone.
    dates : sequence of datetime.date
        The local day of each block, one per site.
    member : array_like of int, optional
        With a cloud ensemble (``weather.members``), the member of each block: its light is that
        member's draw (:func:`foldopt.inputs.weather.ensemble.cloud_members`) of its day.
    sun_terms : foldopt.physics.spa.SunTerms, optional
        SPA's time-only terms shared by the run's skies (a year's chunks, a map's sites); default:
        this sky's own.

    Returns
    -------
    Sky

    Raises
    ------
    ValueError
        If ``sites`` and ``dates`` differ in length, or a weather file's intervals do not fit the
        step.
    """
    if len(sites) != len(dates):
        raise ValueError(f"{len(sites)} sites for {len(dates)} dates")
    weather = options.weather
    if weather is not None:
        # The file's readers (and pandas) load with a weather file: a clear sky needs neither.
        from foldopt.inputs.weather.reader import read_weather, study_weather, weather_site

        # A weather file's days are on its own clock, whatever time zone the site names.
        zone = (
            study_weather(weather, options.weather_site).site
            if weather.measured
            else weather_site(weather.path, weather.format)
        )["timezone"]
        sites = [site.model_copy(update={"timezone": zone}) for site in sites]
    share = None
    if member is not None and weather is not None and weather.members:
        # The members of a day share its sun, clear sky and air: they are worked out once a day
        # and a site, and only the light is drawn per member.
        keys = [
            (site.latitude, site.longitude, site.altitude, date)
            for site, date in zip(sites, dates, strict=True)
        ]
        first = {key: index for index, key in reversed(list(enumerate(keys)))}
        unique = sorted(first.values())
        position = {keys[index]: k for k, index in enumerate(unique)}
        share = (np.array([position[key] for key in keys]), np.asarray(member, dtype=np.int64))
        sites, dates = [sites[i] for i in unique], [dates[i] for i in unique]
    horizons, horizon_of = _horizon_blocks(sites)
    latitude = np.array([site.latitude for site in sites], dtype=float)[:, None]
    longitude = np.array([site.longitude for site in sites], dtype=float)[:, None]
    altitude = np.array([site.altitude for site in sites], dtype=float)[:, None]
    grid = _clock(sites, dates, options.step_min)
    sun = solar_position_grid(grid, latitude, longitude, altitude, options.mode, sun_terms)
    solar_zenith = sun["solar_zenith"]
    dni_extra = by_dayofyear(extraterrestrial_spencer, grid.dayofyear)
    temp_air, balance = np.full(len(sites), float(options.temp_air)), None
    temp_steps = wind_speed = wind_ref = terms = None
    notes = ()
    transposition = options.transposition
    if weather is not None and weather.measured:
        light, measured = measured_light(options, grid, dates)
        temp_steps, wind_speed = light.pop("temp_air"), light.pop("wind_speed")
        notes = tuple(measured.report())
        wind_ref = file_wind_ref(measured.frame, options.wind_speed)
    elif weather is not None:
        # The file as read for the first date's year (cached): its rows' values are every year's.
        frame = read_weather(weather.path, weather.format, dates[0].year, weather.label)
        wind_ref = file_wind_ref(frame, options.wind_speed)
        clear, _ = clear_light(
            grid, solar_zenith, dni_extra, sites, "ineichen", options.linke_turbidity
        )
        light, temp_steps, wind_speed, balance, (hourly, per_interval) = weather_light(
            weather, grid, dates, clear, solar_zenith, dni_extra
        )
        if share is not None:
            light, balance = member_light(
                options, hourly, per_interval, clear, solar_zenith, dates, share
            )
    sun_vector = sun.pop("sun_vector")
    if share is not None:
        inverse = share[0]
        sun_vector = sun_vector[inverse]
        grid = ClockGrid(
            grid.utc_ns[inverse],
            grid.utc_offset_ns[inverse],
            tuple(grid.timezones[i] for i in inverse),
            grid.step_hours,
        )
        sun = {key: value[inverse] for key, value in sun.items()}
        solar_zenith, latitude, altitude = sun["solar_zenith"], latitude[inverse], altitude[inverse]
        dni_extra = dni_extra[inverse]
        temp_steps, wind_speed = temp_steps[inverse], wind_speed[inverse]
        dates = [dates[i] for i in inverse]
    air_steps = temp_steps
    if weather is not None:
        lit = light["ghi"] > 0
        temp_steps = equivalent_temp_air(
            temp_steps, wind_speed, wind_ref, light["ghi"], options.temperature_model
        )
        # The block's representative temperature: its lit steps' mean (its whole day's if dark).
        temp_air = np.where(
            lit.any(axis=1),
            (temp_steps * lit).sum(axis=1) / np.maximum(lit.sum(axis=1), 1),
            temp_steps.mean(axis=1),
        )
    elif options.model in CLEAR_SKIES:
        light, terms = clear_light(
            grid,
            solar_zenith,
            dni_extra,
            sites,
            options.model,
            options.linke_turbidity,
            transposition,
            options.albedo,
        )
    else:
        beam_altitude = altitude if options.mode == "exact" else 0.0
        light = {
            "dni": clear_sky_dni(
                solar_zenith,
                beam_altitude,
                options.model,
                dayofyear=grid.dayofyear,
                climate=options.climate,
            )
        }
    dni = light["dni"]
    ghi, dhi = light.get("ghi"), light.get("dhi")
    if transposition != "none" and terms is None:
        terms = diffuse_terms(transposition, solar_zenith, dni, ghi, dhi, dni_extra, options.albedo)
    if horizons:
        dni, terms = block_behind_horizon(
            horizons, horizon_of, solar_zenith, sun["solar_azimuth"], dni, terms
        )
    return Sky(
        grid=grid,
        mode=options.mode,
        solar_zenith=solar_zenith,
        solar_azimuth=sun["solar_azimuth"],
        hour_angle=sun["hour_angle"],
        declination=np.ascontiguousarray(sun["declination"]),
        sun_vector=sun_vector,
        dni=dni,
        ghi=ghi,
        dhi=dhi,
        terms=terms,
        temp_air=temp_air,
        latitude=latitude[:, 0],
        iam=options.iam,
        weather_balance=balance,
        load_shape=None
        if options.load_profile is None
        else load_shape(options.load_profile, grid.clock_hours, dates),
        temp_steps=temp_steps,
        wind_speed=wind_speed,
        wind_ref=wind_ref,
        weather_notes=notes,
        air_steps=air_steps,
        horizons=horizons,
        horizon_of=horizon_of,
    )
