"""Daily metrics of a power curve against a constant load.

The power is sampled at the centres of ``n`` equal steps covering the day. Between samples it is
taken as linear, so the times where it crosses the load fall inside a step rather than on its
edges; before the first and after the last centre it is held constant (so a polar day counts the
full 24 h). ``t_solar`` is the time with ``P_pv >= P_load`` (Shin et al. Sec. I, Fig. 1a).

All functions reduce the last axis (time) and broadcast ``p_load`` against the leading axes, so
one call serves many fold angles and loads.
"""

from __future__ import annotations

import numpy as np

from foldopt.engine.roots import brentq


def _time_above_per_segment(p_pv, p_load, step_hours):
    """Hours above the load in each of the ``n + 1`` segments of the piecewise-linear curve."""
    excess = np.asarray(p_pv, dtype=float) - np.asarray(p_load, dtype=float)[..., None]
    start, end = excess[..., :-1], excess[..., 1:]
    with np.errstate(divide="ignore", invalid="ignore"):  # -inf: a step without load (per_load)
        crossing = np.maximum(start, end) / np.abs(start - end)
    fraction = np.where(
        (start >= 0) & (end >= 0), 1.0, np.where((start < 0) & (end < 0), 0.0, crossing)
    )
    head = (excess[..., :1] >= 0) * 0.5
    tail = (excess[..., -1:] >= 0) * 0.5
    return np.concatenate([head, fraction, tail], axis=-1) * step_hours, excess


def t_solar(p_pv, p_load, step_hours):
    """Total solar-powered time [h]: time with ``p_pv >= p_load``.

    Parameters
    ----------
    p_pv : array_like
        Power at step centres [W], time on the last axis.
    p_load : float or array_like
        Load [W], broadcast against ``p_pv``'s leading axes.
    step_hours : float
        Step length [h].

    Returns
    -------
    numpy.ndarray
        ``t_solar`` [h], one per leading index (a float for a 1-D curve).

    References
    ----------
    .. [1] D. Shin, N. Chang, Y. Wang, M. Pedram, "Reconfigurable three dimensional photovoltaic
       panel architecture for solar-powered time extension", Sec. I and Fig. 1a.

    Examples
    --------
    A half-sine day from 06:00 to 18:00 runs a load of half its peak from 08:00 to 16:00; sampled
    hourly and taken as linear between samples, 7.96 h:

    >>> import numpy as np
    >>> hours = np.arange(24) + 0.5
    >>> power = np.clip(np.sin(np.pi * (hours - 6) / 12), 0, None)
    >>> print(round(float(t_solar(power, 0.5, 1.0)), 3))
    7.962
    """
    above, _ = _time_above_per_segment(p_pv, p_load, step_hours)
    return above.sum(axis=-1)


def t_solar_contiguous(p_pv, p_load, step_hours):
    """Longest contiguous solar-powered interval: the longest run with ``p_pv >= p_load``.

    Parameters
    ----------
    p_pv : array_like
        Power at step centres [W], time on the last axis.
    p_load : float or array_like
        Load [W], broadcast against ``p_pv``'s leading axes.
    step_hours : float
        Step length [h].

    Returns
    -------
    numpy.ndarray
        Longest interval [h], shaped as :func:`t_solar`'s result.
    """
    above, excess = _time_above_per_segment(p_pv, p_load, step_hours)
    # Segment k joins segment k-1 when the sample between them is above the load; a sample below
    # it starts a new run. Label runs row by row and add up each run's hours with one bincount.
    below = np.concatenate([excess[..., :1] < 0, excess < 0], axis=-1)
    run = np.cumsum(below, axis=-1)
    flat_above = above.reshape(-1, above.shape[-1])
    n_labels = above.shape[-1] + 1
    labels = run.reshape(-1, above.shape[-1]) + n_labels * np.arange(flat_above.shape[0])[:, None]
    per_run = np.bincount(
        labels.ravel(), weights=flat_above.ravel(), minlength=flat_above.shape[0] * n_labels
    ).reshape(flat_above.shape[0], n_labels)
    return per_run.max(axis=-1).reshape(above.shape[:-1])


def energy(p_pv, step_hours):
    """Energy over the day by the midpoint rule (steps are interval-centred).

    Parameters
    ----------
    p_pv : array_like
        Power at step centres [W], time on the last axis.
    step_hours : float
        Step length [h].

    Returns
    -------
    numpy.ndarray
        Energy [Wh], one per leading index.
    """
    return np.asarray(p_pv, dtype=float).sum(axis=-1) * step_hours


def daily_metrics(p_pv, p_load, step_hours):
    """All daily metrics of a power curve against a load.

    Parameters
    ----------
    p_pv : array_like
        Power at step centres [W], time on the last axis.
    p_load : float or array_like
        Load [W], broadcast against ``p_pv``'s leading axes.
    step_hours : float
        Step length [h].

    Returns
    -------
    dict of numpy.ndarray
        :func:`metric_columns` of the curve.
    """
    p_pv = np.asarray(p_pv, dtype=float)
    p_load = np.asarray(p_load, dtype=float)
    return metric_columns(
        t_solar(p_pv, p_load, step_hours),
        t_solar_contiguous(p_pv, p_load, step_hours),
        energy(p_pv, step_hours),
        p_pv.max(axis=-1),
        p_load,
    )


def metric_columns(
    t_solar_h, t_solar_contiguous_h, energy_harvested_wh, peak_power_w, p_load, served_wh=None
) -> dict:
    """The daily metrics by their report names, from t_solar, its longest run, the energy and the peak.

    Parameters
    ----------
    t_solar_h, t_solar_contiguous_h : array_like
        :func:`t_solar` and :func:`t_solar_contiguous` [h].
    energy_harvested_wh : array_like
        :func:`energy` [Wh].
    peak_power_w : array_like
        [W].
    p_load : float or array_like
        Load [W] (the scale of a load profile).
    served_wh : array_like, optional
        Energy served to a load profile [Wh] (:func:`energy_served`).

    Returns
    -------
    dict of numpy.ndarray
        ``t_solar_h``, ``t_solar_contiguous_h`` [h]; ``energy_harvested_wh`` harvested (at the maximum power
        point), ``energy_served_wh`` = P_load * t_solar, ``energy_wasted_wh`` the rest (without
        storage, power above the load and power too low to run it are both lost) [Wh];
        ``peak_power_w`` [W]. ``served_wh`` replaces ``P_load * t_solar`` for a load profile
        (:func:`energy_served`). A tracker net of its drive can harvest less than nothing (its
        drive costs more than it harvests, :data:`DRIVE_NOTE`): it then serves and wastes nothing,
        so that served energy never exceeds what is harvested and nothing wasted is negative.
    """
    served = np.asarray(p_load, dtype=float) * t_solar_h if served_wh is None else served_wh
    harvested = np.maximum(energy_harvested_wh, 0.0)
    served = np.minimum(served, harvested)
    return {
        "t_solar_h": t_solar_h,
        "t_solar_contiguous_h": t_solar_contiguous_h,
        "energy_harvested_wh": energy_harvested_wh,
        "energy_served_wh": served,
        "energy_wasted_wh": harvested - served,
        "peak_power_w": peak_power_w,
    }


def load_for_t_solar(p_pv, target_t_solar, step_hours):
    """The load [W] at which a power curve gives ``target_t_solar`` hours.

    ``t_solar`` falls continuously as the load rises, so the root is found by Brent's method
    between a vanishing load (the daylight length) and the peak power (zero hours).

    Parameters
    ----------
    p_pv : array_like
        One day's power [W], 1-D.
    target_t_solar : float
        Solar-powered time to reach [h].
    step_hours : float
        Step length [h].

    Returns
    -------
    float
        Load [W]; NaN when the curve never reaches ``target_t_solar`` (longer than daylight).
    """
    p_pv = np.asarray(p_pv, dtype=float)
    peak = p_pv.max()
    if peak <= 0:
        return float("nan")
    smallest = peak * 1e-9

    def shortfall(load):
        return float(t_solar(p_pv, load, step_hours)) - target_t_solar

    if shortfall(smallest) < 0:
        return float("nan")
    return brentq(shortfall, smallest, peak, xtol=peak * 1e-12)


def relative_to(t_solar_h, reference_h):
    """``t_solar_h / reference_h``, NaN where the reference never reaches the load (a gain over
    nothing has no value).

    Parameters
    ----------
    t_solar_h, reference_h : array_like
        [h], broadcast.

    Returns
    -------
    numpy.ndarray
        Ratio [-].

    Examples
    --------
    >>> print(relative_to([9.49, 3.0], [7.73, 0.0]).round(3))
    [1.228   nan]
    """
    t_solar_h, reference_h = np.broadcast_arrays(
        np.asarray(t_solar_h, dtype=float), np.asarray(reference_h, dtype=float)
    )
    ratio = np.full(t_solar_h.shape, np.nan)
    np.divide(t_solar_h, reference_h, out=ratio, where=reference_h > 0)
    return ratio


#: The note of a tracker whose own draw exceeds its harvest: its net energy is below zero.
DRIVE_NOTE = "drive costs more than it harvests"


def design_condition(condition, energy_harvested_wh):
    """Each design's condition on its day, for the notes of reports.

    Parameters
    ----------
    condition : array_like of str
        The day's (:meth:`foldopt.engine.sky.Sky.conditions`).
    energy_harvested_wh : array_like
        Each design's harvest [Wh], broadcast against ``condition``.

    Returns
    -------
    numpy.ndarray of str
        The day's condition and, where the design harvests less than nothing (a tracker net of
        its drive), :data:`DRIVE_NOTE`, joined by ``"; "``.
    """
    condition, harvested = np.broadcast_arrays(
        np.asarray(condition, dtype=object), np.asarray(energy_harvested_wh, dtype=float)
    )
    return np.array(
        [
            "; ".join(p for p in (c, DRIVE_NOTE if h < 0 else "") if p)
            for c, h in zip(condition.ravel(), harvested.ravel(), strict=True)
        ],
        dtype=object,
    ).reshape(condition.shape)


def notes(condition, t_solar_h):
    """A report's note per design.

    Parameters
    ----------
    condition : array_like of str
        :func:`design_condition`, or the day's condition.
    t_solar_h : array_like
        Each design's ``t_solar`` [h], broadcast against ``condition``.

    Returns
    -------
    numpy.ndarray of str
        The condition and, where direct light arrives but the design never reaches the load,
        ``load above peak``, joined by ``"; "``.

    Examples
    --------
    >>> print(list(notes(["", "polar night", ""], [0.0, 0.0, 5.0])))
    ['load above peak', 'polar night', '']
    """
    condition, hours = np.broadcast_arrays(
        np.asarray(condition, dtype=object), np.asarray(t_solar_h)
    )
    # On a polar night or an overcast day the condition is the reason already.
    dark = np.array([("polar night" in c) or ("overcast" in c) for c in condition.ravel()]).reshape(
        hours.shape
    )
    above = (hours == 0) & ~dark
    return np.array(
        [
            "; ".join(p for p in (c, "load above peak" if a else "") if p)
            for c, a in zip(condition.ravel(), above.ravel(), strict=True)
        ],
        dtype=object,
    ).reshape(hours.shape)


def per_load(power, load_shape):
    """What loads are compared with: the power itself, or its ratio to a load profile.

    With a profile, ``P_pv >= scale x shape`` is ``ratio >= scale``; where the shape is 0 (no load)
    the ratio is -inf, which no scale reaches. The segments between a step without load and one
    with it then count nothing: a profile that is zero outside a window never counts time outside
    it, and loses at most half a step at each edge of the window.

    Parameters
    ----------
    power : array_like
        Power at step centres [W], time on the last axis.
    load_shape : array_like or None
        P_load(t) for a scale of 1 [W], broadcast against ``power``; None for a constant load.

    Returns
    -------
    numpy.ndarray
        ``power`` [W], or ``power / load_shape`` [-] (-inf without load).
    """
    if load_shape is None:
        return power
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(load_shape > 0, power / np.where(load_shape > 0, load_shape, 1.0), -np.inf)


def energy_served(p_pv, scale, load_shape, step_hours, t_solar_h=None):
    """Energy a time-varying load draws while solar-powered [Wh]: the integral of
    P_load(t) = ``scale`` x ``load_shape``(t) over the time with P_pv >= P_load.

    The time above the load is :func:`t_solar`'s, segment by segment, and the load over a segment
    is the mean of its two samples; for a constant shape of 1 this is ``scale x t_solar``.

    Parameters
    ----------
    p_pv : array_like
        Power at step centres [W], time on the last axis.
    scale : float or array_like
        Scales of the profile, broadcast against ``p_pv``'s leading axes.
    load_shape : array_like
        P_load(t) for a scale of 1 [W], broadcast against ``p_pv``.
    step_hours : float
        Step length [h].
    t_solar_h : array_like, optional
        The curves' t_solar at these scales [h], as computed elsewhere: where the shape is the same
        at every step, the served energy is then ``scale x shape x t_solar_h`` exactly, as for a
        constant load.

    Returns
    -------
    numpy.ndarray
        Energy served [Wh], one per leading index of ``p_pv`` (and per scale).
    """
    shape = np.broadcast_to(np.asarray(load_shape, dtype=float), np.shape(p_pv))
    scale = np.asarray(scale, dtype=float)
    if t_solar_h is not None and np.all(shape == shape[..., :1]):
        level = shape[..., 0][..., None] if scale.ndim else shape[..., 0]
        return scale * level * t_solar_h
    above, _ = _time_above_per_segment(
        per_load(p_pv, shape)[..., None, :] if scale.ndim else per_load(p_pv, shape),
        scale,
        step_hours,
    )
    segment_load = np.concatenate(
        [shape[..., :1], 0.5 * (shape[..., :-1] + shape[..., 1:]), shape[..., -1:]], axis=-1
    )
    if scale.ndim:
        segment_load = segment_load[..., None, :]
    return scale * (above * segment_load).sum(axis=-1)
