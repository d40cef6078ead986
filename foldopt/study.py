"""One day's study: flat, twofold and tracked panels at one site, compared.

:class:`Day` holds everything that does not depend on orientation (times, sun, beam) and gives
the power of each design as arrays over fold angles x time; :func:`run_study` sweeps the fold
angle, applies the paper's heuristic and tabulates the comparison.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from foldopt.aggregation import connection_power
from foldopt.atmosphere import clear_sky_dni
from foldopt.config import Study, parse_timezone
from foldopt.geometry import subpanel_orientation
from foldopt.irradiance import beam_incidence_factor
from foldopt.metrics import daily_metrics
from foldopt.optimize import heuristic_fold_angle, noon_valley, optimal_fold_angle
from foldopt.pvmodel import max_power
from foldopt.sizing import flat_area_multiple
from foldopt.solarposition import day_times, get_solar_position
from foldopt.tracker import tracker_incidence_factor


class Day:
    """Sun and beam over one day for a resolved study, and the power of each design on it.

    Paper mode uses the paper's sun, air mass at sea level and Eq. 5 incidence; exact mode pvlib's
    sun (apparent zenith), Laue's altitude term and the true angle of incidence.
    """

    def __init__(self, study: Study):
        self.study = study
        site = study.site
        self.times = day_times(study.date, parse_timezone(site.timezone), study.step_min)
        self.step_hours = study.step_min / 60.0
        sun = get_solar_position(self.times, site.latitude, site.longitude, site.altitude, study.mode)
        self.solar_zenith = sun["solar_zenith"].to_numpy()
        self.solar_azimuth = sun["solar_azimuth"].to_numpy()
        altitude = site.altitude if study.mode == "exact" else 0.0
        self.dni = clear_sky_dni(self.solar_zenith, altitude, study.sky)

    def _power(self, surface_tilt, surface_azimuth, area):
        factor = beam_incidence_factor(
            np.asarray(surface_tilt)[..., None],
            np.asarray(surface_azimuth)[..., None],
            self.solar_zenith,
            self.solar_azimuth,
            model=self.study.mode,
        )
        panel = self.study.panel
        return max_power(self.dni * factor, area, panel.efficiency, self.study.pv_model)

    def flat_power(self):
        """Power of the flat panel over the day [W], shape (n_time,)."""
        panel = self.study.panel
        return self._power(panel.tilt, panel.azimuth, panel.area)

    def tracker_power(self):
        """Power of the same panel on the tracker [W], shape (n_time,)."""
        panel = self.study.panel
        poa = self.dni * tracker_incidence_factor(self.solar_zenith, self.study.tracker)
        return max_power(poa, panel.area, panel.efficiency, self.study.pv_model)

    def subpanel_power(self, fold_angles):
        """East and west sub-panel powers and their parallel sum [W], each (k, n_time)."""
        panel = self.study.panel
        sides = subpanel_orientation(fold_angles, panel.tilt, panel.azimuth, self.study.geometry)
        p_east = self._power(sides["tilt_east"], sides["azimuth_east"], panel.area / 2)
        p_west = self._power(sides["tilt_west"], sides["azimuth_west"], panel.area / 2)
        return p_east, p_west, connection_power(p_east, p_west, "parallel")

    def combined_power(self, fold_angles):
        """Deliverable twofold power under the study's connection [W], (k, n_time)."""
        p_east, p_west, _ = self.subpanel_power(fold_angles)
        return connection_power(p_east, p_west, self.study.connection)


@dataclass(frozen=True)
class StudyResult:
    """Everything a report needs from one study."""

    study: Study
    day: Day
    sweep: pd.DataFrame
    summary: pd.DataFrame
    timeseries: pd.DataFrame
    optimal_fold_angle: float
    heuristic_fold_angle: float


def run_study(study: Study) -> StudyResult:
    """Sweep the fold angle of a resolved study and compare flat, twofold and tracker.

    Returns
    -------
    StudyResult
        ``sweep``: metrics per fold angle (and the noon valley of the parallel curve);
        ``summary``: one row per design (``flat``, ``twofold`` at the sweep's optimum,
        ``twofold-heuristic`` at the paper's angle, ``tracker``); ``timeseries``: the power curves of
        the day at the optimum.
    """
    day = Day(study)
    p_load, step = study.p_load, day.step_hours
    angles = np.asarray(study.fold_angles.grid())
    p_east, p_west, p_parallel = day.subpanel_power(angles)
    combined = connection_power(p_east, p_west, study.connection)
    sweep = pd.DataFrame({"fold_angle_deg": angles, **daily_metrics(combined, p_load, step)})
    sweep["noon_valley_w"] = noon_valley(p_east, p_west, p_parallel)

    best_angle, _ = optimal_fold_angle(
        day.combined_power, angles, sweep["t_solar_h"].to_numpy(), p_load, step
    )
    paper_angle = heuristic_fold_angle(day.subpanel_power, p_load)

    p_flat, p_tracker = day.flat_power(), day.tracker_power()
    p_best = day.combined_power(np.array([best_angle]))[0]
    designs = {"flat": (180.0, p_flat), "twofold": (best_angle, p_best)}
    if np.isfinite(paper_angle):
        designs["twofold-heuristic"] = (paper_angle, day.combined_power(np.array([paper_angle]))[0])
    designs["tracker"] = (np.nan, p_tracker)

    rows = []
    for design, (angle, power) in designs.items():
        metrics = {key: float(value) for key, value in daily_metrics(power, p_load, step).items()}
        rows.append({"design": design, "fold_angle_deg": angle, **metrics})
    summary = pd.DataFrame(rows)
    flat_hours = summary.loc[0, "t_solar_h"]
    tracker_hours = summary["t_solar_h"].iloc[-1]
    with np.errstate(divide="ignore", invalid="ignore"):
        summary["gain_vs_flat_pct"] = (summary["t_solar_h"] / flat_hours - 1.0) * 100.0
        summary["pct_of_tracker_t_solar"] = summary["t_solar_h"] / tracker_hours * 100.0
    summary["flat_area_multiple"] = [
        flat_area_multiple(p_flat, p_load, hours, step) if hours > 0 else np.nan
        for hours in summary["t_solar_h"]
    ]

    p_best_east, p_best_west, _ = day.subpanel_power(np.array([best_angle]))
    timeseries = pd.DataFrame(
        {
            "time": day.times.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "solar_zenith": day.solar_zenith,
            "solar_azimuth": day.solar_azimuth,
            "dni": day.dni,
            "p_flat_w": p_flat,
            "p_east_w": p_best_east[0],
            "p_west_w": p_best_west[0],
            "p_twofold_w": p_best,
            "p_tracker_w": p_tracker,
            "p_load_w": p_load,
        }
    )
    return StudyResult(study, day, sweep, summary, timeseries, best_angle, paper_angle)

