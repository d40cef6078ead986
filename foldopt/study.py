"""One day's study: flat, twofold and tracked panels at one site, compared.

:class:`Day` holds everything that does not depend on orientation (times, sun, beam, the
electrical tables) and gives the power of each design as arrays over fold angles x time;
:func:`run_study` sweeps the fold angle, applies the paper's heuristic and tabulates the
comparison, for the study's connection and for the others.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from foldopt.aggregation import CONNECTIONS, SWITCH_STATES
import pvlib

from foldopt.atmosphere import clear_sky_dni, relative_airmass
from foldopt.config import Study, parse_timezone
from foldopt.electrical import Electrical
from foldopt.geometry import normal_vector, subpanel_orientation
from foldopt.irradiance import beam_incidence_factor
from foldopt.metrics import daily_metrics, load_for_t_solar, t_solar
from foldopt.optimize import heuristic_fold_angle, noon_valley, optimal_fold_angle
from foldopt.pvmodel import PVModel
from foldopt.sizing import flat_area_multiple
from foldopt.solarposition import day_times, get_solar_position
from foldopt.weather import CLEAR_SKIES, clear_sky, read_weather, weather_day
from foldopt.tracker import TRACKERS, TrackerDrive, TrackerOptions, tracker_draw, tracker_orientation


class Day:
    """Sun, beam and electrical model over one day, and the power of each design on it.

    Paper mode uses the paper's sun, air mass at sea level and Eq. 5 incidence; exact mode pvlib's
    sun (apparent zenith), Laue's altitude term and the true angle of incidence. The study is
    resolved here, so its defaults follow its own site and mode.
    """

    def __init__(self, study: Study, cache: dict | None = None):
        study = study.resolved()
        self.study = study
        site, panel = study.site, study.panel
        temp_air = study.temp_air
        self.ghi = self.dhi = None
        if study.weather is not None:
            frame = weather_day(read_weather(study.weather.path, study.weather.format, study.date.year, study.weather.label), study.date)
            self.times = pd.DatetimeIndex(frame.index)
            self.step_hours = float(pd.Series(self.times).diff().median() / pd.Timedelta(hours=1))
            # Cells follow the day's mean air temperature (the electrical tables assume one per
            # day), rounded to 5 C so that days share their tables; wind stays the study's.
            temp_air = round(float(frame["temp_air"].mean()) / 5.0) * 5.0
        else:
            self.times = day_times(study.date, parse_timezone(site.timezone), study.step_min)
            self.step_hours = study.step_min / 60.0
        sun = get_solar_position(self.times, site.latitude, site.longitude, site.altitude, study.mode)
        self.solar_zenith = sun["solar_zenith"].to_numpy()
        self.solar_azimuth = sun["solar_azimuth"].to_numpy()
        self.hour_angle = sun["hour_angle"].to_numpy()
        self.declination = sun["declination"].to_numpy()
        self.sun_vector = normal_vector(self.solar_zenith, self.solar_azimuth)  # east-north-up, unit
        altitude = site.altitude if study.mode == "exact" else 0.0
        if study.weather is not None:
            self.dni, self.ghi, self.dhi = (frame[key].to_numpy(dtype=float) for key in ("dni", "ghi", "dhi"))
        elif study.sky in CLEAR_SKIES:
            sky = clear_sky(self.times, self.solar_zenith, site.latitude, site.longitude, site.altitude,
                            study.sky, study.linke_turbidity)
            self.dni, self.ghi, self.dhi = sky["dni"], sky["ghi"], sky["dhi"]
        else:
            self.dni = clear_sky_dni(
                self.solar_zenith, altitude, study.sky, dayofyear=self.times.day_of_year, climate=study.climate
            )
        self.transposition = study.sky_transposition()
        self._tracker_orientations: dict = {}
        # Orientation-independent inputs of the transposition, computed once for every fold angle.
        self.dni_extra = np.asarray(pvlib.irradiance.get_extra_radiation(self.times.day_of_year), dtype=float)
        self.airmass = np.nan_to_num(relative_airmass(np.minimum(self.solar_zenith, 90.0)), nan=0.0)
        settings = dict(
            pv=PVModel(study.pv_model, panel.efficiency, study.module),
            subpanel_area=panel.area / 2.0,
            temp_air=temp_air,
            wind_speed=study.wind_speed,
            temperature_model=study.temperature_model,
            bypass=study.bypass_diodes,
            switch_series=study.switch_series,
            converter_efficiency=study.converter_efficiency,
            exact=study.exact_electrical,
        )
        if cache is None:
            self.electrical = Electrical(**settings)
        else:
            # Days of one setup share their electrical tables.
            self.electrical = cache.setdefault(tuple(map(repr, settings.values())), Electrical(**settings))

    def _poa(self, surface_tilt, surface_azimuth, per_step=False):
        """Irradiance on surfaces [W/m^2]: one orientation per fold angle, (k, n_time), or, with
        ``per_step``, one per time step (a tracker), (n_time,).

        Beam only (``transposition: none``): the beam by the mode's incidence model. Trackers always
        take the exact angle of incidence: Eq. 5 is the paper's formula for its fixed panels (it
        reads an azimuth even for a level panel, which a single-axis tracker is at noon), and for
        the paper's only tracker, the ideal one, both give 1. With diffuse light: pvlib's
        ``get_total_irradiance`` (beam, sky diffuse by the transposition model, ground-reflected
        with ``albedo``), the beam optionally reduced by an incidence-angle modifier.
        """
        tilt, azimuth = np.asarray(surface_tilt, dtype=float), np.asarray(surface_azimuth, dtype=float)
        if not per_step:
            tilt, azimuth = tilt[..., None], azimuth[..., None]
        study = self.study
        if self.transposition == "none":
            if per_step or study.mode == "paper":
                model = "exact" if per_step else study.mode
                factor = beam_incidence_factor(tilt, azimuth, self.solar_zenith, self.solar_azimuth, model=model)
            else:
                # cos(AOI) of every fold angle at every step is one matrix product of the surface
                # normals with the sun vectors (equal to pvlib's aoi_projection; tested).
                factor = np.clip(normal_vector(tilt[..., 0], azimuth[..., 0]) @ self.sun_vector.T, 0.0, None)
            return self.dni * factor * self._iam(tilt, azimuth)
        dhi = self.dhi if self.dhi is not None else np.zeros_like(self.dni)
        ghi = self.ghi if self.ghi is not None else self.dni * np.clip(np.cos(np.radians(self.solar_zenith)), 0, None)
        poa = pvlib.irradiance.get_total_irradiance(
            tilt, azimuth, self.solar_zenith, self.solar_azimuth, self.dni, ghi, dhi,
            dni_extra=self.dni_extra, airmass=self.airmass, albedo=study.albedo, model=self.transposition,
        )
        direct = np.nan_to_num(np.asarray(poa["poa_direct"], dtype=float)) * self._iam(tilt, azimuth)
        return direct + np.nan_to_num(np.asarray(poa["poa_diffuse"], dtype=float))

    def _iam(self, tilt, azimuth):
        """Incidence-angle modifier of the beam (pvlib ``iam.ashrae`` / ``iam.physical``), or 1."""
        if self.study.iam == "none":
            return 1.0
        aoi = pvlib.irradiance.aoi(tilt, azimuth, self.solar_zenith, self.solar_azimuth)
        modifier = pvlib.iam.ashrae(aoi) if self.study.iam == "ashrae" else pvlib.iam.physical(aoi)
        return np.nan_to_num(np.asarray(modifier, dtype=float))

    def flat_power(self):
        """Power of the flat panel over the day [W], shape (n_time,)."""
        panel = self.study.panel
        return self.electrical.panel_power(self._poa(panel.tilt, panel.azimuth), panel.area)

    def tracker_orientation(self, model=None):
        """Surface tilt and azimuth of a tracker over the day [deg] (default: the study's).

        Kept per model: a tracker's power, its draw and the standby sweep all steer by it.
        """
        model = model or self.study.tracker.model
        if model not in self._tracker_orientations:
            self._tracker_orientations[model] = self._steer(model)
        return self._tracker_orientations[model]

    def _steer(self, model):
        tracker = self.study.tracker
        options = TrackerOptions(
            steps=tracker.steps, angular_field=tracker.angular_field,
            step_offsets_h=tuple(tracker.step_offsets_h or TrackerOptions().step_offsets_h),
            axis_tilt=tracker.axis_tilt, axis_azimuth=tracker.axis_azimuth, max_angle=tracker.max_angle,
            backtrack=tracker.backtrack, gcr=tracker.gcr,
        )
        return tracker_orientation(
            model, self.solar_zenith, self.solar_azimuth, self.hour_angle, self.declination,
            self.study.site.latitude, options,
        )

    def tracker_power(self, model=None):
        """Power of the same panel on a tracker [W], shape (n_time,) (default: the study's)."""
        return self.electrical.panel_power(self._poa(*self.tracker_orientation(model), per_step=True), self.study.panel.area)

    def tracker_draw(self, model=None):
        """The tracker's own draw [W] per step: standby while the sun is up, plus its moves."""
        tracker = self.study.tracker
        drive = TrackerDrive(standby_w=tracker.standby_w, drive=tracker.drive, wh_per_degree=tracker.wh_per_degree)
        return tracker_draw(*self.tracker_orientation(model), self.dni > 0, self.step_hours, drive)

    def connections(self, fold_angles, series: bool = True, with_state: bool = True):
        """Every connection's power [W], each (k, n_time), and the switching state per step.

        ``series=False`` skips the series connection (NaN) when nothing asks for it."""
        panel = self.study.panel
        sides = subpanel_orientation(fold_angles, panel.tilt, panel.azimuth, self.study.geometry)
        poa_east = self._poa(sides["tilt_east"], sides["azimuth_east"])
        poa_west = self._poa(sides["tilt_west"], sides["azimuth_west"])
        return self.electrical.connections(poa_east, poa_west, series, with_state)

    def subpanel_power(self, fold_angles):
        """East and west sub-panel powers and their parallel connection [W], each (k, n_time)."""
        powers, _ = self.connections(fold_angles, series=False, with_state=False)
        return powers["east"], powers["west"], powers["parallel"]

    def combined_power(self, fold_angles, connection=None):
        """Deliverable twofold power [W], (k, n_time), under ``connection`` (default: the study's)."""
        connection = connection or self.study.connection
        series = connection == "series" or self.study.switch_series
        return self.connections(fold_angles, series, with_state=False)[0][connection]


@dataclass(frozen=True)
class StudyResult:
    """Everything a report needs from one study; ``study`` is resolved."""

    study: Study
    day: Day
    sweep: pd.DataFrame
    summary: pd.DataFrame
    timeseries: pd.DataFrame
    optimal_fold_angle: float
    heuristic_fold_angle: float
    standby: tuple  # (table, break-even standby draw [W]) of :func:`standby_sweep`


def _best_angle(day: Day, angles, sweep_t_solar, connection):
    return optimal_fold_angle(
        lambda fold: day.combined_power(fold, connection), angles, sweep_t_solar, day.study.p_load, day.step_hours
    )[0]


def run_study(study: Study) -> StudyResult:
    """Sweep the fold angle and compare flat, twofold and tracker.

    Returns
    -------
    StudyResult
        ``sweep``: metrics per fold angle for the study's connection, ``t_solar`` and energy for
        every connection, and the noon valley of the parallel curve. ``summary``: one row per
        design: ``flat``; ``twofold`` at the sweep's optimum; ``twofold-heuristic`` at the paper's
        angle; with I-V models, ``twofold-<connection>`` for each other connection at its own
        optimum; ``tracker``. ``timeseries``: the day's curves at the optimum, with the state
        switching chose.
    """
    day = Day(study)
    study = day.study
    p_load, step = study.p_load, day.step_hours
    angles = np.asarray(study.fold_angles.grid())
    powers, _ = day.connections(angles)
    sweep = pd.DataFrame({"fold_angle_deg": angles, **daily_metrics(powers[study.connection], p_load, step)})
    sweep["noon_valley_w"] = noon_valley(powers["east"], powers["west"], powers["parallel"])
    for connection in CONNECTIONS:
        metrics = daily_metrics(powers[connection], p_load, step)
        sweep[f"t_solar_{connection}_h"] = metrics["t_solar_h"]
        sweep[f"energy_{connection}_wh"] = metrics["energy_wh"]

    best_angle = _best_angle(day, angles, sweep["t_solar_h"].to_numpy(), study.connection)
    paper_angle = heuristic_fold_angle(day.subpanel_power, p_load)

    p_flat, p_tracker = day.flat_power(), day.tracker_power()
    designs = {"flat": (180.0, p_flat), "twofold": (best_angle, day.combined_power(np.array([best_angle]))[0])}
    if np.isfinite(paper_angle):
        designs["twofold-heuristic"] = (paper_angle, day.combined_power(np.array([paper_angle]))[0])
    if day.electrical.pv.has_iv:
        for connection in ("parallel", "series", "independent", "switching"):
            if connection != study.connection:
                angle = _best_angle(day, angles, sweep[f"t_solar_{connection}_h"].to_numpy(), connection)
                designs[f"twofold-{connection}"] = (angle, day.combined_power(np.array([angle]), connection)[0])
    # The study's tracker is "tracker"; every other model follows as "tracker:<model>". Each net row
    # is what is left for the load after the tracker's own draw.
    for model in (study.tracker.model,) + tuple(m for m in TRACKERS if m != study.tracker.model):
        name = "tracker" if model == study.tracker.model else f"tracker:{model}"
        gross = p_tracker if model == study.tracker.model else day.tracker_power(model)
        designs[name] = (np.nan, gross)
        designs[f"{name}-net"] = (np.nan, gross - day.tracker_draw(model))

    rows = []
    for design, (angle, power) in designs.items():
        metrics = {key: float(value) for key, value in daily_metrics(power, p_load, step).items()}
        rows.append({"design": design, "fold_angle_deg": angle, **metrics})
    summary = pd.DataFrame(rows)
    by_design = summary.set_index("design")["t_solar_h"]
    flat_hours, tracker_hours = by_design["flat"], by_design["tracker"]
    with np.errstate(divide="ignore", invalid="ignore"):
        summary["gain_vs_flat_pct"] = (summary["t_solar_h"] / flat_hours - 1.0) * 100.0
        summary["pct_of_tracker_t_solar"] = summary["t_solar_h"] / tracker_hours * 100.0
    summary["flat_area_multiple"] = [
        flat_area_multiple(p_flat, p_load, hours, step) if hours > 0 else np.nan
        for hours in summary["t_solar_h"]
    ]
    standby = standby_sweep(day, p_tracker, by_design["twofold"])

    at_best, state = day.connections(np.array([best_angle]))
    timeseries = pd.DataFrame(
        {
            "time": day.times.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "solar_zenith": day.solar_zenith,
            "solar_azimuth": day.solar_azimuth,
            "dni": day.dni,
            "p_flat_w": p_flat,
            **{f"p_{connection}_w": at_best[connection][0] for connection in CONNECTIONS},
            "p_twofold_w": at_best[study.connection][0],
            "switch_state": np.where(at_best["switching"][0] > 0, np.array(SWITCH_STATES)[state[0]], "off"),
            "p_tracker_w": p_tracker,
            "p_load_w": p_load,
        }
    )
    return StudyResult(study, day, sweep, summary, timeseries, best_angle, paper_angle, standby)


def standby_sweep(day: Day, p_tracker, twofold_t_solar: float, points: int = 101):
    """The study's tracker's net ``t_solar`` as its standby draw grows, and the break-even draw.

    A standby draw ``s`` while the sun is up leaves the load ``P_pv - drive - s``; over daylight
    that is the gross curve less its drive against the load ``P_load + s``, so every draw is one
    load of a single ``t_solar`` pass, and the break-even draw, where the tracker's net time falls
    to the optimal twofold panel's, is one root search for the load.

    Returns
    -------
    table : pandas.DataFrame
        ``standby_w``, ``tracker_net_t_solar_h``, ``twofold_t_solar_h``.
    break_even_w : float
        Standby draw [W] above which the twofold panel runs longer; NaN if it never does.
    """
    study, step = day.study, day.step_hours
    drive_only = day.tracker_draw() - np.where(day.dni > 0, study.tracker.standby_w, 0.0)
    available = np.where(day.dni > 0, p_tracker - drive_only, 0.0)
    draws = np.linspace(0.0, max(2.0 * study.p_load, 1e-3), points)
    hours = t_solar(available, study.p_load + draws, step)
    load = load_for_t_solar(available, twofold_t_solar, step) if twofold_t_solar > 0 else np.nan
    break_even = max(load - study.p_load, 0.0) if np.isfinite(load) else float("nan")
    table = pd.DataFrame({"standby_w": draws, "tracker_net_t_solar_h": hours, "twofold_t_solar_h": twofold_t_solar})
    return table, break_even


def twofold_t_solar(day: Day, fold_angle: float, connection=None) -> float:
    """``t_solar`` [h] of the twofold panel at one fold angle."""
    power = day.combined_power(np.array([fold_angle]), connection)[0]
    return float(t_solar(power, day.study.p_load, day.step_hours))
