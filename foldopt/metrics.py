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
from scipy.optimize import brentq


def _time_above_per_segment(p_pv, p_load, step_hours):
    """Hours above the load in each of the ``n + 1`` segments of the piecewise-linear curve."""
    excess = np.asarray(p_pv, dtype=float) - np.asarray(p_load, dtype=float)[..., None]
    start, end = excess[..., :-1], excess[..., 1:]
    with np.errstate(divide="ignore", invalid="ignore"):
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
    """
    above, _ = _time_above_per_segment(p_pv, p_load, step_hours)
    return above.sum(axis=-1)


def t_solar_many_loads(p_pv, loads, step_hours):
    """``t_solar`` [h] of each curve for many loads in one pass: shape ``p_pv.shape[:-1] + (n_loads,)``.

    Each segment of the piecewise-linear curve, with end values lo <= hi and length dt, is above a
    load L for ``dt * clip((hi - L) / (hi - lo), 0, 1)``: all of it below lo, none above hi, a
    linear share between. Summed over segments that is piecewise linear in L, so sorting the
    segments' lo and hi once and taking prefix sums evaluates every load by binary search, instead
    of one pass over the power per load. Equals :func:`t_solar` to 1e-6 h (tested).
    """
    p_pv = np.asarray(p_pv, dtype=float)
    loads = np.asarray(loads, dtype=float)
    flat = p_pv.reshape(-1, p_pv.shape[-1])
    # Segments: the held half-steps at both ends (lo = hi) and the n - 1 linear ones between.
    start = np.concatenate([flat[:, :1], flat[:, :-1], flat[:, -1:]], axis=1)
    end = np.concatenate([flat[:, :1], flat[:, 1:], flat[:, -1:]], axis=1)
    length = np.r_[0.5, np.ones(flat.shape[1] - 1), 0.5] * step_hours
    lo, hi = np.minimum(start, end), np.maximum(start, end)
    width = hi - lo
    # Segments narrower than 1e-6 of the curve's peak would carry huge slopes, whose terms cancel
    # only approximately in the prefix sums; they (rare: night and plateaus are exactly flat) get
    # their exact share directly below. The rest keep the prefix-sum rounding below
    # n * eps * 1e6 * dt ~ 2e-7 h.
    scale = np.maximum(1.0, np.abs(flat).max(axis=1, keepdims=True))
    sloped = width > 1e-6 * scale
    narrow = (width > 0) & ~sloped
    # Flat segments count fully while L <= hi (>= keeps P == L as served, like t_solar).
    slope = np.where(sloped, length / np.where(sloped, width, 1.0), 0.0)
    rows = flat.shape[0]
    length = np.broadcast_to(length, lo.shape)
    full = np.where(width == 0, length, 0.0)
    sloped_length = np.where(sloped, length, 0.0)
    order_hi, order_lo = np.argsort(hi, axis=1), np.argsort(lo, axis=1)
    hi_sorted, lo_sorted = np.take_along_axis(hi, order_hi, 1), np.take_along_axis(lo, order_lo, 1)

    def prefix(values, order):  # row-wise prefix sums with a leading 0
        return np.concatenate([np.zeros((rows, 1)), np.cumsum(np.take_along_axis(values, order, 1), axis=1)], axis=1)

    def counts(keys, side):  # per row, how many keys lie below (left) / at or below (right) each load
        # Row by row: shifting rows apart to search them at once would round keys next to a load.
        return np.array([np.searchsorted(row, loads, side=side) for row in keys]).reshape(rows, loads.size)

    lo_below, hi_upto, hi_below = counts(lo_sorted, "left"), counts(hi_sorted, "right"), counts(hi_sorted, "left")
    total = lambda cumulative, index: np.take_along_axis(cumulative, index, 1)  # noqa: E731
    # Flat segments count while hi >= L; sloped ones fully while lo >= L, partly while lo < L < hi.
    full_sums, sloped_sums = prefix(full, order_hi), prefix(sloped_length, order_lo)
    flat_full = full_sums[:, -1:] - total(full_sums, hi_below)
    above_lo = sloped_sums[:, -1:] - total(sloped_sums, lo_below)
    slope_hi = slope * hi
    partial = (total(prefix(slope_hi, order_lo), lo_below) - total(prefix(slope_hi, order_hi), hi_upto)) - loads * (
        total(prefix(slope, order_lo), lo_below) - total(prefix(slope, order_hi), hi_upto))
    out = flat_full + above_lo + partial
    row, seg = np.nonzero(narrow)
    if row.size:
        with np.errstate(over="ignore"):  # denormal widths: the share saturates at 0 or 1
            share = np.clip((hi[row, seg, None] - loads) / width[row, seg, None], 0.0, 1.0) * length[row, seg, None]
        np.add.at(out, row, share)
    return out.reshape(p_pv.shape[:-1] + (loads.size,))


def t_solar_contiguous(p_pv, p_load, step_hours):
    """Longest contiguous solar-powered interval [h]."""
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
    """Energy over the day [Wh] by the midpoint rule (steps are interval-centred)."""
    return np.asarray(p_pv, dtype=float).sum(axis=-1) * step_hours


def daily_metrics(p_pv, p_load, step_hours):
    """All daily metrics of a power curve against a load.

    Returns
    -------
    dict of numpy.ndarray
        ``t_solar_h``, ``t_solar_contiguous_h`` [h]; ``energy_wh`` harvested (at the maximum power
        point), ``energy_served_wh`` = P_load * t_solar, ``energy_wasted_wh`` the rest (without
        storage, power above the load and power too low to run it are both lost) [Wh];
        ``peak_power_w`` [W].
    """
    p_pv = np.asarray(p_pv, dtype=float)
    p_load = np.asarray(p_load, dtype=float)
    hours = t_solar(p_pv, p_load, step_hours)
    harvested = energy(p_pv, step_hours)
    served = p_load * hours
    return {
        "t_solar_h": hours,
        "t_solar_contiguous_h": t_solar_contiguous(p_pv, p_load, step_hours),
        "energy_wh": harvested,
        "energy_served_wh": served,
        "energy_wasted_wh": harvested - served,
        "peak_power_w": p_pv.max(axis=-1),
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
        [h].
    step_hours : float
        [h].

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
