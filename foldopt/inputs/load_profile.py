"""Loads that vary over the day: P_load(t) = scale x profile(t).

A profile (:class:`foldopt.inputs.sections.LoadProfile`) gives loads [W] at clock times of the local
day, held until the next time or interpolated linearly, the last carried over midnight to the first;
a weekend day and days per month may replace it. :func:`load_shape` evaluates it at every step of
every block (a day at a site, :class:`foldopt.engine.sky.Sky`), so that the engine compares the power
with ``scale x shape(t)``: for many scales in one pass it compares P_pv(t) / shape(t) with each
scale (:func:`foldopt.engine.metrics.per_load`), the method of many constant loads.

The module opens no files (a profile's CSV is read by :func:`foldopt.inputs.study_file.read_profile`)
and imports nothing of the study models, which import :func:`profile_steps` from it; numpy loads
with the first profile evaluated, not with the models (the command line checks its input and
prints its help before numpy loads).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

_CLOCK = re.compile(r"^([01]?\d|2[0-3]):([0-5]\d)$")


def profile_steps(value: dict) -> dict:
    """A day's loads checked and put in order: clock times ``HH:MM`` of the day to loads [W].

    Parameters
    ----------
    value : dict
        Clock times (``"7:00"`` or ``"07:00"``, in [00:00, 23:59]) to loads [W], each at least 0.

    Returns
    -------
    dict
        ``{"HH:MM": watts}`` with two-digit hours, in time order, loads as floats [W].

    Raises
    ------
    ValueError
        For an empty or non-mapping value, a time that is no clock time, a load that is not a
        finite number >= 0, or one time given twice (``7:00`` beside ``07:00``).
    """
    if not isinstance(value, dict) or not value:
        raise ValueError(
            "expected a mapping of clock times HH:MM to watts, e.g. {'07:00': 6, '19:00': 1.5}"
        )
    steps, given = {}, {}
    for time, watts in value.items():
        match = _CLOCK.match(str(time).strip())
        if not match:
            raise ValueError(f"{time!r} is not a clock time HH:MM in [00:00, 23:59]")
        if (
            isinstance(watts, bool)
            or not isinstance(watts, (int, float))
            or not math.isfinite(watts)
            or watts < 0
        ):
            raise ValueError(f"{time}: {watts!r} is not a load in watts >= 0")
        clock = f"{int(match.group(1)):02d}:{match.group(2)}"
        if clock in given:  # 7:00 beside 07:00: one of the two loads would be dropped unseen
            raise ValueError(f"{time!r} is the time {given[clock]!r} again; give each time once")
        given[clock] = time
        steps[clock] = float(watts)
    return dict(sorted(steps.items()))


#: How far PVGIS's 24 fractions of a day's energy may sum from 1 (values rounded to 3 decimals
#: each may add up to 0.012 away); they are scaled to sum 1 exactly.
HOURCONSUMPTION_TOLERANCE = 0.02


def hourly_steps(fractions: list, consumptionday: float) -> dict:
    """PVGIS's off-grid load as a day's loads: 24 fractions of a day's energy, hour by hour.

    PVGIS's off-grid tool (SHScalc) takes the load as a daily energy, ``consumptionday`` [Wh],
    and its ``hourconsumption``: the fraction of that energy used in each hour of the day, 24
    values that sum to 1 [1]_. Hour ``h``'s energy ``consumptionday x fraction_h`` spread over
    its hour is a load of that many watts from ``h:00`` to ``h+1:00`` of the study's local day,
    so the day's energy is ``consumptionday`` exactly.

    Parameters
    ----------
    fractions : list of float
        24 fractions [-], each finite and >= 0, summing to 1 within
        :data:`HOURCONSUMPTION_TOLERANCE` (scaled to sum 1).
    consumptionday : float
        The day's energy [Wh].

    Returns
    -------
    dict
        ``{"HH:00": watts}`` for the 24 hours, in time order (:func:`profile_steps`' form), held
        over each hour.

    Raises
    ------
    ValueError
        For other than 24 values, a value that is not a finite number >= 0, or a sum away from 1.

    References
    ----------
    .. [1] European Commission JRC, "PVGIS non-interactive service" (API): the SHScalc tool's
       ``consumptionday`` and ``hourconsumption``; "Performance of off-grid PV systems".
    """
    if not isinstance(fractions, list) or len(fractions) != 24:
        count = len(fractions) if isinstance(fractions, list) else "no list of"
        raise ValueError(
            f"hourconsumption: {count} values; PVGIS's form is 24 fractions of consumptionday, "
            "one an hour from 00:00, summing to 1"
        )
    for hour, fraction in enumerate(fractions):
        if (
            isinstance(fraction, bool)
            or not isinstance(fraction, (int, float))
            or not math.isfinite(fraction)
            or fraction < 0
        ):
            raise ValueError(
                f"hourconsumption[{hour}] = {fraction!r}: is not a fraction of the day's energy >= 0"
            )
    total = math.fsum(fractions)
    if abs(total - 1.0) > HOURCONSUMPTION_TOLERANCE:
        raise ValueError(
            f"hourconsumption: the 24 fractions sum to {total:g}; they are shares of "
            f"consumptionday and must sum to 1 (within {HOURCONSUMPTION_TOLERANCE:g})"
        )
    return {
        f"{hour:02d}:00": consumptionday * fraction / total
        for hour, fraction in enumerate(fractions)
    }


def _day(steps: dict, clock_hours, linear: bool):
    """One day's profile at local clock hours [h]."""
    import numpy as np

    times = np.array([int(t[:2]) + int(t[3:]) / 60.0 for t in steps])
    watts = np.array(list(steps.values()))
    if linear:
        # Periodic: the last point joins the first across midnight.
        return np.interp(
            clock_hours, np.r_[times - 24.0, times, times + 24.0], np.r_[watts, watts, watts]
        )
    # -1: before the first time, the last's load
    index = np.searchsorted(times, clock_hours, side="right") - 1
    return watts[index]


def load_shape(profile, clock_hours, dates):
    """P_load(t) for a scale of 1 [W] at every step of every block.

    Parameters
    ----------
    profile : foldopt.inputs.sections.LoadProfile
    clock_hours : numpy.ndarray
        (n_blocks, n_steps) local clock time of each step [h].
    dates : sequence of datetime.date
        Each block's local date (weekday and month choose its day).

    Returns
    -------
    numpy.ndarray
        (n_blocks, n_steps) [W].
    """
    import numpy as np

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
    """The load of a study as a user knows it.

    Parameters
    ----------
    study : foldopt.inputs.study.Study
    p_load : float, optional
        Replaces the study's load (a sweep's value): [W], or a profile's scale [-].

    Returns
    -------
    dict
        ``{"p_load_w": W}`` for a constant load; for a profile its ``name`` (its file's stem, or
        ``daily``), ``scale`` [-] and the ``mean_w`` and ``peak_w`` [W] of P_load(t) = scale x
        profile(t) over its daily day (weekend and monthly days aside).
    """
    profile = study.load_profile
    scale = float(study.p_load if p_load is None else p_load)
    if profile is None:
        return {"p_load_w": scale}
    import numpy as np

    minutes = (np.arange(1440) + 0.5) / 60.0
    day = _day(profile.daily, minutes, profile.interpolation == "linear") * scale
    name = (
        Path(profile.file).stem
        if profile.file
        else "hourconsumption"
        if profile.hourconsumption is not None
        else "daily"
    )
    return {
        "profile": name,
        "scale": scale,
        "mean_w": float(day.mean()),
        "peak_w": float(day.max()),
    }


def load_text(study, p_load: float | None = None) -> str:
    """The load of a study in words, for the answer's lines.

    Parameters
    ----------
    study : foldopt.inputs.study.Study
    p_load : float, optional
        Replaces the study's load (a sweep's value): [W], or a profile's scale [-].

    Returns
    -------
    str
        ``P_load 2 W``, or for a profile ``load profile camera (mean 2.88 W, peak 6 W)`` (with its
        scale where it is not 1).
    """
    load = describe_load(study, p_load)
    if "p_load_w" in load:
        return f"P_load {load['p_load_w']:g} W"
    scale = f" x{load['scale']:g}" if load["scale"] != 1 else ""
    return f"load profile {load['profile']}{scale} (mean {load['mean_w']:.3g} W, peak {load['peak_w']:.3g} W)"
