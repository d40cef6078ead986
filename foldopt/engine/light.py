"""The light at every step of a sky's blocks: a clear sky, a weather file's hours drawn along it,
a measured file's own steps or a cloud ensemble's members, and the diffuse terms of any of them.

:func:`foldopt.engine.sky.build_sky` takes its light from here. The clear sky of a map (Ineichen, no
weather) is one compiled pass over the lit steps that gives the diffuse terms with it
(:func:`foldopt.physics.clearsky.ineichen_terms`); every other light gets its terms from
:func:`diffuse_terms` (:func:`foldopt.physics.irradiance.sky_diffuse_terms` at the steps with light).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from foldopt.engine.options import SkyOptions
from foldopt.errors import WeatherError
from foldopt.inputs.turbidity import linke_turbidity as climatology_turbidity
from foldopt.inputs.weather.downscale import clear_sky, hourly_light, interpolate_points
from foldopt.inputs.weather.ensemble import cloud_members
from foldopt.physics.atmosphere import relative_airmass
from foldopt.physics.irradiance import sky_diffuse_terms
from foldopt.physics.solarposition import ClockGrid

if TYPE_CHECKING:
    import pandas as pd


def _airmass(solar_zenith) -> np.ndarray:
    """Kasten & Young's relative air mass with the sun up, 0 with it down (as the sky's arrays
    hold it)."""
    airmass = np.zeros(np.shape(solar_zenith))
    up = solar_zenith < 90.0
    airmass[up] = relative_airmass(solar_zenith[up])
    return airmass


def clear_light(
    grid: ClockGrid,
    solar_zenith,
    dni_extra,
    sites,
    model: str,
    linke_turbidity,
    transposition: str = "none",
    albedo: float = 0.2,
) -> tuple[dict, np.ndarray | None]:
    """A clear sky at every step of the blocks (0 with the sun down), with its diffuse terms.

    Ineichen's is one compiled pass (:func:`foldopt.physics.clearsky.ineichen_terms`), the
    climatology's turbidity at each site where the study sets none
    (:func:`foldopt.inputs.turbidity.linke_turbidity`); the other clear skies are pvlib's,
    one call per site (its blocks' steps together), their terms from :func:`diffuse_terms`.

    Parameters
    ----------
    grid : ClockGrid
    solar_zenith, dni_extra : numpy.ndarray
        (n_blocks, n_steps) apparent solar zenith [deg] and extraterrestrial irradiance [W/m^2].
    sites : sequence of foldopt.inputs.sections.Site
        One per block.
    model : str
        One of :data:`foldopt.names.CLEAR_SKIES`.
    linke_turbidity : float or None
        The study's turbidity [-]; None: the climatology's.
    transposition : str, default 'none'
        One of :data:`foldopt.names.TRANSPOSITIONS`.
    albedo : float, default 0.2
        [-].

    Returns
    -------
    light : dict
        ``dni``, ``ghi``, ``dhi``, (n_blocks, n_steps) [W/m^2].
    terms : numpy.ndarray or None
        (n_blocks, n_steps, 4) diffuse terms, None for ``'none'``.
    """
    if model == "ineichen":
        turbidity = linke_turbidity
        if turbidity is None:
            turbidity = climatology_turbidity(
                np.array([site.latitude for site in sites], dtype=float),
                np.array([site.longitude for site in sites], dtype=float),
                grid.utc_ns,
            )
        altitude = np.array([site.altitude for site in sites], dtype=float)
        from foldopt.physics.clearsky import ineichen_terms  # numba's compiled pass

        dni, ghi, dhi, layout = ineichen_terms(
            solar_zenith, dni_extra, turbidity, altitude, transposition, albedo
        )
        return {"dni": dni, "ghi": ghi, "dhi": dhi}, None if layout is None else np.moveaxis(
            layout, 1, -1
        )
    groups: dict[tuple, list[int]] = {}
    for index, site in enumerate(sites):
        groups.setdefault((site.latitude, site.longitude, site.altitude), []).append(index)
    light = {key: np.zeros_like(solar_zenith) for key in ("dni", "ghi", "dhi")}
    airmass = _airmass(solar_zenith)
    for (_, _, altitude), members in groups.items():
        up = solar_zenith[members] < 90.0
        sky = clear_sky(
            solar_zenith[members][up],
            airmass[members][up],
            dni_extra[members][up],
            altitude,
            model,
            linke_turbidity,
        )
        for key, values in light.items():
            placed = np.zeros(up.shape)
            placed[up] = sky[key]
            values[members] = placed
    terms = None
    if transposition != "none":
        terms = diffuse_terms(
            transposition, solar_zenith, light["dni"], light["ghi"], light["dhi"], dni_extra, albedo
        )
    return light, terms


def diffuse_terms(
    transposition: str, solar_zenith, dni, ghi, dhi, dni_extra, albedo: float
) -> np.ndarray:
    """The diffuse terms of a transposition at every step
    (:func:`foldopt.physics.irradiance.sky_diffuse_terms` at the steps with light, 0 elsewhere).

    Parameters
    ----------
    transposition : str
        One of :data:`foldopt.physics.irradiance.TRANSPOSITIONS`.
    solar_zenith, dni, dni_extra : numpy.ndarray
        (n_blocks, n_steps) [deg], [W/m^2], [W/m^2].
    ghi, dhi : numpy.ndarray or None
        (n_blocks, n_steps) [W/m^2]; None for a beam-only sky: the beam's horizontal share and no
        diffuse light.
    albedo : float
        [-].

    Returns
    -------
    numpy.ndarray
        (n_blocks, n_steps, 4), a view of an array laid out (n_blocks, 4, n_steps) as the engine
        reads it.
    """
    ghi_of = ghi if ghi is not None else dni * np.clip(np.cos(np.radians(solar_zenith)), 0, None)
    dhi_of = dhi if dhi is not None else np.zeros_like(dni)
    shown = np.flatnonzero((dni > 0) | (ghi_of > 0) | (dhi_of > 0))
    # Placed a term at a time by flat index: block b's step s is b * 4 n_steps + s.
    n_steps = dni.shape[1]
    layout = np.zeros((dni.shape[0], 4, n_steps))
    at = shown + shown // n_steps * (3 * n_steps)
    values = [array.ravel()[shown] for array in (solar_zenith, dni, ghi_of, dhi_of, dni_extra)]
    found = sky_diffuse_terms(transposition, *values, _airmass(values[0]), albedo)
    for k in range(4):
        layout.reshape(-1)[at + k * n_steps] = found[:, k]
    return np.moveaxis(layout, 1, -1)


def file_wind_ref(frame: pd.DataFrame, default: float) -> float:
    """The wind speed of the electrical tables [m/s] for a weather file: the file's mean wind over
    its lit rows, to 0.5 m/s (``default``, the study's, where it has none).

    A property of the file, not of the days a run takes from it: the step's wind is folded into
    an equivalent air temperature about it with the horizontal light standing for the sub-panels'
    (:func:`foldopt.physics.temperature.equivalent_temp_air`), whose small error depends on it, so
    a day's answer is the same alone and among the file's other days.
    """
    lit = frame["ghi"].to_numpy(dtype=float) > 0
    wind = frame["wind_speed"].to_numpy(dtype=float)[lit]
    wind = wind[np.isfinite(wind)]
    return float(np.round(2.0 * wind.mean()) / 2.0) if wind.size else float(default)


def weather_light(weather, grid: ClockGrid, dates, clear: dict, solar_zenith, dni_extra):
    """Light at every step of the grid from an hourly weather file (``weather``, a
    :class:`foldopt.inputs.weather_section.Weather`) drawn along the clear sky
    (:func:`foldopt.inputs.weather.downscale.hourly_light`), the air temperature and wind at every
    step (:func:`foldopt.inputs.weather.downscale.interpolate_points`), and how much of the file's
    irradiation the steps keep."""
    # The file's readers (and pandas) load with a weather file: a clear sky needs neither.
    import pandas as pd

    from foldopt.inputs.weather.reader import FORMATS, read_weather, weather_days, weather_format

    columns = ("dni", "ghi", "dhi", "temp_air", "wind_speed", "cloud_cover")
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
    if interval % step_ns or not np.array_equal(
        starts, day_start + np.arange(starts.shape[1]) * interval
    ):
        raise ValueError(
            f"weather: the study's step ({grid.step_hours * 60:g} min) must divide the file's "
            f"intervals ({interval / 6e10:g} min), which must start at the day's midnight"
        )
    cos_zenith = np.cos(np.radians(solar_zenith))
    light, placed = hourly_light(
        hourly["dni"],
        hourly["dhi"],
        clear["ghi"],
        clear["dni"],
        cos_zenith,
        per_interval,
        dni_extra,
    )
    balance = {
        key: (float(hourly[key].sum()), float(placed[key].sum())) for key in ("dni", "ghi", "dhi")
    }
    # Air temperature and wind stand at the file's own stamps (its meteorological fields are
    # instantaneous), linear between them.
    entry = FORMATS[weather_format(weather.path, weather.format)]
    offset = {"end": 0.5, "start": -0.5, "centre": 0.0}[
        weather.label or entry.interval_label
    ] + entry.stamp_lag
    temp_air = interpolate_points(hourly["temp_air"], offset, per_interval)
    wind_speed = interpolate_points(hourly["wind_speed"], offset, per_interval)
    return light, temp_air, wind_speed, balance, (hourly, per_interval)


def measured_light(options: SkyOptions, grid: ClockGrid, dates):
    """Light, air temperature and wind at every step of the grid from the options' measured
    weather file, at its own step (:func:`foldopt.inputs.weather.reader.study_weather`)."""
    import pandas as pd

    from foldopt.inputs.weather.reader import study_weather, weather_days

    weather = options.weather
    measured = study_weather(weather, options.weather_site)
    frame = measured.frame
    flagged = sorted(set(dates) & set(measured.flagged_days))
    if flagged:
        gaps = [
            f"{start:%H:%M}-{stop:%H:%M}"
            for start, stop, minutes in measured.gaps
            if start.date() in flagged and minutes > weather.max_gap_min
        ]
        raise WeatherError(
            f"weather {frame.attrs['weather']}: {flagged[0]} has a daylight gap too long to fill "
            f"({', '.join(gaps[:3])}; weather.max_gap_min {weather.max_gap_min:g} min)"
            + (f", and {len(flagged) - 1} more dates" if len(flagged) > 1 else "")
            + "; leave those dates out"
        )
    rows = weather_days(frame, dates)
    centres = pd.DatetimeIndex(frame.index).tz_localize(None).as_unit("ns").asi8[rows]
    if centres.shape != grid.local_ns.shape or not np.array_equal(centres, grid.local_ns):
        raise ValueError(
            f"weather: the study's step ({grid.step_hours * 60:g} min) must be the measured file's "
            f"({measured.step.total_seconds() / 60:g} min)"
        )
    columns = {
        key: frame[key].to_numpy(dtype=float)[rows]
        for key in ("ghi", "dni", "dhi", "temp_air", "wind_speed")
    }
    return columns, measured


def member_light(
    options: SkyOptions, hourly: dict, per_interval: int, clear: dict, solar_zenith, dates, share
):
    """Each block's light drawn as its member of the cloud ensemble of its day
    (:func:`foldopt.inputs.weather.ensemble.cloud_members`), and how much of the file's light the
    members keep on average. A day's members are drawn from the seed and the day alone, so that a
    member is the same whatever else a study runs with it."""
    inverse, member = share
    cos_zenith = np.cos(np.radians(solar_zenith))
    count = int(member.max()) + 1
    drawn = {
        key: np.empty((count, len(dates), solar_zenith.shape[1])) for key in ("ghi", "dni", "dhi")
    }
    for day, date in enumerate(dates):
        one = cloud_members(
            hourly["ghi"][day : day + 1],
            hourly["dhi"][day : day + 1],
            clear["ghi"][day : day + 1],
            cos_zenith[day : day + 1],
            per_interval,
            options.step_min,
            count,
            [options.weather.seed, date.toordinal()],
            hourly["cloud_cover"][day : day + 1],
        )
        for key in drawn:
            drawn[key][:, day] = one[key][:, 0]
    light = {key: values[member, inverse] for key, values in drawn.items()}
    # a day's members: all of them in every chunk (Blocks.chunks)
    per_day = len(inverse) / len(dates)
    balance = {
        key: (float(hourly[key].sum()), float(light[key].sum()) / per_interval / per_day)
        for key in ("dni", "ghi", "dhi")
    }
    return light, balance
