"""Loads that vary over the day: P_load(t) = scale x profile(t).

A profile (:class:`foldopt.inputs.config.LoadProfile`) gives loads [W] at clock times of the local day,
held until the next time or interpolated linearly, the last carried over midnight to the first; a
weekend day and days per month may replace it. :func:`load_shape` evaluates it at every step of
every block (a day at a site, :class:`foldopt.engine.sky.Sky`), so that the engine compares the power
with ``scale x shape(t)``: for many scales in one pass it compares P_pv(t) / shape(t) with each
scale (:func:`foldopt.engine.metrics.per_load`), the method of many constant loads.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np


def read_profile(path: str | Path) -> dict:
    """A day's profile from a CSV file with a header ``time,watts`` (``HH:MM`` and watts), UTF-8 with
    or without a byte-order mark, each time at most once."""
    from foldopt.inputs.config import MAX_CSV_BYTES, _profile_steps, read_input
    from foldopt.errors import ConfigError

    path = Path(path)
    text = read_input(path, "load_profile.file", MAX_CSV_BYTES, "MAX_CSV_BYTES")
    try:
        reader = csv.DictReader(io.StringIO(text, newline=""))
        rows = [(reader.line_num, row) for row in reader]
    except csv.Error as error:
        raise ConfigError([f"load_profile.file: cannot read {path}: {error}"]) from None
    steps, lines = {}, {}
    for line, row in rows:
        try:
            time, watts = row["time"].strip(), float(row["watts"])
        except (KeyError, TypeError, ValueError, AttributeError):
            raise ConfigError([f"load_profile.file {path}, line {line}: expected time,watts (HH:MM, a number)"
                               ]) from None
        if time in steps:  # the second load would replace the first unseen
            raise ConfigError([f"load_profile.file {path}, line {line}: time {time} is also on line {lines[time]}; "
                               "give each time once"])
        steps[time], lines[time] = watts, line
    try:
        return _profile_steps(steps)
    except ValueError as error:
        raise ConfigError([f"load_profile.file {path}: {error}"]) from None


def _day(steps: dict, clock_hours: np.ndarray, linear: bool) -> np.ndarray:
    """One day's profile at local clock hours [h]."""
    times = np.array([int(t[:2]) + int(t[3:]) / 60.0 for t in steps])
    watts = np.array(list(steps.values()))
    if linear:
        # Periodic: the last point joins the first across midnight.
        return np.interp(clock_hours, np.r_[times - 24.0, times, times + 24.0], np.r_[watts, watts, watts])
    index = np.searchsorted(times, clock_hours, side="right") - 1  # -1: before the first time, the last's load
    return watts[index]


def load_shape(profile, clock_hours: np.ndarray, dates) -> np.ndarray:
    """P_load(t) for a scale of 1 [W] at every step of every block.

    Parameters
    ----------
    profile : foldopt.inputs.config.LoadProfile
    clock_hours : numpy.ndarray
        (n_blocks, n_steps) local clock time of each step [h].
    dates : sequence of datetime.date
        Each block's local date (weekday and month choose its day).

    Returns
    -------
    numpy.ndarray
        (n_blocks, n_steps) [W].
    """
    linear = profile.interpolation == "linear"
    shape = np.empty(clock_hours.shape)
    for block, date in enumerate(dates):
        steps = profile.daily
        if profile.months and date.month in profile.months:
            steps = profile.months[date.month]
        if profile.weekend and date.weekday() >= 5:
            steps = profile.weekend
        shape[block] = _day(steps, clock_hours[block], linear)
    return shape


def describe_load(study, p_load: float | None = None) -> dict:
    """The load of a study as a user knows it: a constant ``p_load_w`` [W], or a profile's
    ``name`` (its file's stem, or ``daily``), ``scale`` [-] and the ``mean_w`` and ``peak_w`` [W]
    of P_load(t) = scale x profile(t) over its daily day (weekend and monthly days aside).
    ``p_load`` replaces the study's load (a sweep's value)."""
    profile = study.load_profile
    scale = float(study.p_load if p_load is None else p_load)
    if profile is None:
        return {"p_load_w": scale}
    minutes = (np.arange(1440) + 0.5) / 60.0
    day = _day(profile.daily, minutes, profile.interpolation == "linear") * scale
    name = Path(profile.file).stem if profile.file else "daily"
    return {"profile": name, "scale": scale, "mean_w": float(day.mean()), "peak_w": float(day.max())}


def load_text(study, p_load: float | None = None) -> str:
    """``P_load 2 W``, or for a profile ``load profile camera (mean 2.88 W, peak 6 W)`` (with its
    scale where it is not 1)."""
    load = describe_load(study, p_load)
    if "p_load_w" in load:
        return f"P_load {load['p_load_w']:g} W"
    scale = f" x{load['scale']:g}" if load["scale"] != 1 else ""
    return f"load profile {load['profile']}{scale} (mean {load['mean_w']:.3g} W, peak {load['peak_w']:.3g} W)"
