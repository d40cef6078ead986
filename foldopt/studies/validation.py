"""Measured minutes against their hourly means: what a study gains or loses when it sees only a
file's hours.

For each day of a measured file (:data:`foldopt.inputs.weather.reader.MEASURED_FORMATS`),
:func:`minute_validation` gives each design's t_solar (the flat panel, the twofold panel at its
own best fold angle, the tracker) for every load, from three skies of the same site and day:

- ``measured``: the file's own minutes (or 5 minutes), at its own step;
- ``smooth``: the day's hourly means (written as an EPW file,
  :func:`foldopt.inputs.weather.epw.write_epw`, and read back like any typical year) brought to
  the same step by :mod:`foldopt.inputs.weather.downscale`;
- ``ensemble``: the same hourly means through a cloud ensemble
  (:mod:`foldopt.inputs.weather.ensemble`): the members' P5, P50 and P95, the twofold panel at
  the ensemble's fold angle (the best of the members' mean t_solar).

Everything else is the study's: its PV model, connection, tracker, transposition. The manual's
validation table (docs/weather.rst) and the tests (tests/test_weather_validation_minutes.py) are
made from it.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from foldopt.inputs.study_file import with_files
from foldopt.inputs.study import Study
from foldopt.inputs.weather.reader import study_weather
from foldopt.inputs.weather.epw import write_epw
from foldopt.studies.designs import DESIGNS, Blocks, design_metrics, fold_hours
from foldopt.studies.objectives import best_angle_index
from foldopt.names import DEFAULT_ENGINE

#: The designs compared and the ensemble's percentiles.
COMPARED = ("flat", "twofold", "tracker")
PERCENTILES = (5, 50, 95)


def hourly_means(frame: pd.DataFrame) -> pd.DataFrame:
    """A measured frame's hourly means, indexed by the hours' centres.

    Parameters
    ----------
    frame : pandas.DataFrame
        :attr:`foldopt.inputs.weather.measured.MeasuredWeather.frame`: steps of whole days.

    Returns
    -------
    pandas.DataFrame
        The same columns, one row per hour.
    """
    hours = frame.groupby(frame.index.floor("h")).mean()
    hours.index = hours.index + pd.Timedelta(minutes=30)
    return hours


def _design_hours(blocks: Blocks, sky, loads):
    """(members, loads, designs) t_solar and (loads,) fold angles of one day's blocks and their sky:
    the twofold panel at each member's own best angle without an ensemble, at the ensemble's with
    one."""
    fold_angles, hours, _ = fold_hours(sky, blocks, loads)  # (members, angles, loads)
    hours = hours.transpose(0, 2, 1)
    chosen = best_angle_index(hours.mean(axis=0))  # (loads,)
    metrics = design_metrics(
        sky,
        blocks,
        loads,
        fold_angles,
        np.broadcast_to(chosen, (sky.n_blocks, loads.size)),
        DEFAULT_ENGINE,
    )
    return metrics["t_solar_h"], fold_angles[chosen]


def minute_validation(study: Study, loads, members: int = 20, seed: int = 0) -> pd.DataFrame:
    """Each day's t_solar from a measured file's minutes, from its hourly means through the smooth
    path, and through a cloud ensemble (module docstring).

    Parameters
    ----------
    study : Study
        With a measured ``weather`` file (its site where the file holds none); its ``date`` is
        not used: every day of the file that has no long gap is.
    loads : array_like
        (n_loads,) [W].
    members : int, default 20
        Members of the ensemble.
    seed : int, default 0
        The ensemble's seed.

    Returns
    -------
    pandas.DataFrame
        One row per day, load and design: ``date``, ``p_load_w``, ``design``, ``measured_h``,
        ``smooth_h``, ``ensemble_p5_h``, ``ensemble_p50_h``, ``ensemble_p95_h``, the twofold
        panel's fold angles ``fold_angle_measured_deg``, ``fold_angle_smooth_deg`` and
        ``fold_angle_ensemble_deg`` (NaN for the other designs), and the day's
        ``within_hour_sd_measured_w_m2`` and ``within_hour_sd_smooth_w_m2``: the mean over lit
        hours of the standard deviation of GHI within each hour [W/m^2].
    """
    loads = np.atleast_1d(np.asarray(loads, dtype=float))
    measured = study_weather(study.weather, study.site)
    frame = measured.frame
    days = [
        day
        for day in dict.fromkeys(frame.index.tz_localize(None).date)
        if day not in measured.flagged_days
    ]
    rows = []
    site = {
        key: measured.site[key] for key in ("name", "latitude", "longitude", "altitude", "timezone")
    }
    days_of = frame.index.tz_localize(None).date
    with tempfile.TemporaryDirectory() as folder:
        for day in days:
            # One file a day: an hourly file's rows run on without a gap, and a day left out has one.
            path = Path(folder) / f"{Path(study.weather.path).stem}-{day}.epw"
            write_epw(path, hourly_means(frame[days_of == day]), measured.site)
            hourly = with_files(
                study.variant(
                    weather={"path": str(path)},
                    step_min=study.step_min,
                    site=site,
                    date=day.isoformat(),
                )
            )
            ensemble = with_files(
                hourly.variant(
                    weather={"path": str(path), "members": members, "seed": seed},
                    objective={"statistic": "mean"},
                    date=day.isoformat(),
                )
            )
            # Each sky built once: the designs' hours and the spread of its GHI read the same.
            skies = {name: _day(of, day) for name, of in (("measured", study), ("smooth", hourly))}
            sources = {
                **{name: _design_hours(*blocks_sky, loads) for name, blocks_sky in skies.items()},
                "ensemble": _design_hours(*_day(ensemble, day), loads),
            }
            spread = {name: _spread(sky) for name, (_, sky) in skies.items()}
            for index, load in enumerate(loads):
                for design in COMPARED:
                    d = DESIGNS.index(design)
                    members_h = sources["ensemble"][0][:, index, d]
                    rows.append(
                        {
                            "date": day.isoformat(),
                            "p_load_w": float(load),
                            "design": design,
                            "measured_h": float(sources["measured"][0][0, index, d]),
                            "smooth_h": float(sources["smooth"][0][0, index, d]),
                            **{
                                f"ensemble_p{pct}_h": float(np.percentile(members_h, pct))
                                for pct in PERCENTILES
                            },
                            **{
                                f"fold_angle_{name}_deg": float(sources[name][1][index])
                                if design == "twofold"
                                else np.nan
                                for name in sources
                            },
                            **{
                                f"within_hour_sd_{name}_w_m2": value
                                for name, value in spread.items()
                            },
                        }
                    )
    return pd.DataFrame(rows)


def _day(study: Study, day):
    """One day's blocks of ``study`` and their sky."""
    blocks = Blocks.of_dates(study, [day])
    return blocks, blocks.sky()


def _spread(sky) -> float:
    """The mean over a day's lit hours of the standard deviation of GHI within each hour [W/m^2]."""
    per_hour = round(1.0 / sky.step_hours)
    ghi = sky.ghi[0].reshape(24, per_hour)
    lit = (ghi > 0).all(axis=1)
    return float(ghi[lit].std(axis=1).mean()) if lit.any() else float("nan")
