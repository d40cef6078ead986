"""Compiled reduction of power curves to daily metrics (numba), and of daily values to the means of
periods of days (:func:`period_means`).

:func:`day_metrics` reduces one power curve to the daily metrics of every load at once; the
kernel :func:`foldopt.engine.kernel.fold_rows` calls it per row and connection, and
:func:`curve_rows` takes power curves that already exist (a tracker's) through it.

The metrics are those of :mod:`foldopt.engine.metrics`, which is their reference: power is sampled at
step centres and linear between them (held for half a step at both ends of the day), and a
segment from ``lo`` to ``hi`` of length ``dt`` is above a load ``L`` for
``dt * clip((hi - L) / (hi - lo), 0, 1)``. For many loads sorted ascending, the loads at or below
``lo`` take the whole segment: one entry of a difference array, summed from the top at the end;
only the loads inside the segment's range take a share. The position of the power among the loads
moves by a few loads a step, so it is walked from the previous step instead of searched. A day's
cost is then O(steps + loads x crossings), not O(steps x loads). Given each block of steps' lowest
and highest power (the kernel's switching pass notes them), :func:`blocked_day` walks only the
blocks that cross a load.

Rows are split into chunks, a few per thread (:func:`foldopt.engine.records.in_chunks`), and each
chunk has its own scratch, in the calling thread's workspace
(:func:`foldopt.engine.records.allocate`), cleared per row. A chunk's loop allocates nothing and
is compiled without numba's reference counting, as the kernel's (:mod:`foldopt.engine.kernel`), and
the functions only compiled code calls without a wrapper for Python's calls, as the kernel's.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from foldopt.engine.records import WALK_BLOCK, in_chunks


@njit(cache=True, inline="always")
def _walk(loads, position, power):
    """Number of loads at or below ``power``, walked from the previous step's ``position``."""
    count = loads.shape[0]
    while position < count and loads[position] <= power:
        position += 1
    while position > 0 and loads[position - 1] > power:
        position -= 1
    return position


@njit(cache=True, _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _runs(start_at, lo_at, length, run):
    """Longest runs: a sample below a load ends that load's run (the segment starts a new one);
    loads below the segment's low end run on through it."""
    for j in range(start_at, run.shape[0]):
        run[j, 1] = max(run[j, 1], run[j, 0])
        run[j, 0] = 0.0
    for j in range(lo_at):
        run[j, 0] += length


@njit(cache=True, _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _gather(whole, pending_at, pending, lo_at, length):
    """Add ``length`` to the pending sum for ``whole[lo_at]``, writing the previous sum out when
    the index changes."""
    if lo_at == pending_at:
        return pending_at, pending + length
    whole[pending_at] += pending
    return lo_at, length


@njit(cache=True, _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _per_load(p, shape, s, use_shape):
    """The power against which the loads are compared at step ``s``: the power itself for constant
    loads, or for a load profile P_load(t) = scale x shape(t) the ratio P_pv / shape, so that
    P_pv >= scale x shape is ratio >= scale; a step without load (shape 0) is -inf, which no scale
    reaches, and neither do the segments next to it (:func:`foldopt.engine.metrics.per_load`)."""
    if not use_shape:
        return p
    g = shape[s]
    return p / g if g > 0.0 else -math.inf


@njit(cache=True, inline="always")
def day_metrics(power, span, p_load, profile, how, scratch, t_out, cont_out):
    """Daily metrics of one power curve [W] sampled at step centres, of which only steps
    ``first..last`` (``span``) need walking: the power before and after them is that of the first
    and the last (zero, or the day's end). Writes t_solar (and its longest run) per load of
    ``p_load`` (one set of :class:`foldopt.engine.records.Loads`, ascending) into ``t_out`` (and
    ``cont_out``); returns the energy [Wh] and the peak [W]. ``how``: the loads' ``step_hours``,
    ``contiguous`` and ``use_profile``; with ``use_profile`` the loads are scales of the load
    profile ``profile`` (n_steps) [W] (:func:`_per_load`); steps outside ``first..last`` hold the
    power of the first and last, and the profile there is taken as the first's and the last's.
    ``scratch`` is a chunk's ``above``, ``whole`` and ``run``
    (:class:`foldopt.engine.records.Scratch`).

    A segment adds its length to ``whole[k]`` when the k lowest loads lie at or below its low end
    (summed from the top at the end), and shares to the loads inside its range. Consecutive
    segments mostly share k, so their lengths gather in a local sum first."""
    # Constant loads without runs (every map's) with the flags as constants, so that no step tests
    # them; the other cases read them at run time.
    step_hours, contiguous, use_profile = how
    if not contiguous and not use_profile:
        held = (step_hours, False, False)
        return _day_steps(power, span, p_load, profile, held, scratch, t_out, cont_out)
    return _day_steps(power, span, p_load, profile, how, scratch, t_out, cont_out)


@njit(cache=True, inline="always")
def _day_steps(power, span, p_load, profile, held, scratch, t_out, cont_out):
    """:func:`day_metrics`' walk over the steps; ``held`` is how the curve is held against the
    loads: the step [h] and the flags ``contiguous`` and ``use_profile`` of
    :class:`foldopt.engine.records.Loads`."""
    first, last = span
    step_hours, contiguous, use_profile = held
    above, whole, run = scratch
    n_steps, n_loads = power.shape[0], p_load.shape[0]
    above[:] = 0.0
    whole[:] = 0.0
    if contiguous:
        run[:] = 0.0
    # The half-step held at the start of the day, and the steps before ``first``.
    harvested = peak = power[first]
    previous = _per_load(power[first], profile, first, use_profile)
    position = _walk(p_load, 0, previous)
    pending_at, pending = position, (first + 0.5) * step_hours
    if contiguous:
        _runs(position, position, pending, run)
    for s in range(first + 1, last + 1):
        harvested += power[s]
        peak = max(peak, power[s])
        p = _per_load(power[s], profile, s, use_profile)
        at = _walk(p_load, position, p)
        lo_at, hi_at = min(position, at), max(position, at)
        if contiguous:
            _runs(position, lo_at, step_hours, run)
        pending_at, pending = _gather(whole, pending_at, pending, lo_at, step_hours)
        if hi_at > lo_at:
            # The loads strictly inside the segment's range take a share of it.
            lo, hi = min(previous, p), max(previous, p)
            for j in range(lo_at, hi_at):
                share = step_hours * (hi - p_load[j]) / (hi - lo)
                above[j] += share
                if contiguous:
                    run[j, 0] += share
        previous, position = p, at
    # The last sample held to the end of the day.
    tail = (n_steps - last - 0.5) * step_hours
    if contiguous:
        _runs(position, position, tail, run)
    pending_at, pending = _gather(whole, pending_at, pending, position, tail)
    whole[pending_at] += pending
    total = 0.0
    for j in range(n_loads - 1, -1, -1):
        total += whole[j + 1]
        t_out[j] = above[j] + total
        if contiguous:
            cont_out[j] = max(run[j, 0], run[j, 1])
    return harvested * step_hours, peak


@njit(cache=True, inline="always")
def _bounds(loads, position):
    """The loads either side of ``position`` (:func:`_walk`'s): the power stays at it while
    ``lower <= power < upper``."""
    lower = loads[position - 1] if position > 0 else -math.inf
    upper = loads[position] if position < loads.shape[0] else math.inf
    return lower, upper


@njit(cache=True, inline="always")
def _run_length(start, count, step_hours, held):
    """A run's length [h]: ``count`` steps added one by one to its first length ``start``, or
    (``start`` < 0) to one step, which ``held`` has summed already (:attr:`Scratch.held`)."""
    if start < 0.0:
        return held[count]
    for _ in range(count):
        start += step_hours
    return start


@njit(cache=True, nogil=True, _nrt=False, no_cfunc_wrapper=True)
def blocked_day(power, span, p_load, step_hours, held, extremes, scratch, t_out):
    """t_solar of every load of ``p_load`` (ascending) of one power curve [W] into ``t_out``, as
    :func:`day_metrics` for constant loads without their longest runs, walking steps
    ``first..last`` (its ``span``), given the lowest and the highest power (``extremes``: low,
    high) of each block of :data:`foldopt.engine.records.WALK_BLOCK` steps from ``first`` and
    the lengths of runs of steps (``held``); ``scratch`` (above, whole) is the chunk's, as the
    rest of its :class:`foldopt.engine.records.Scratch`.

    A block whose power stays between the same two loads adds whole steps to the run at its
    place among them and is not walked: a clear day's curve spends most of its steps above
    every load, below them all, or between two, and only the blocks where it crosses a load are
    walked step by step. A run's steps are counted and its length taken from ``held``: the same
    additions of the step in the same order as :func:`_day_steps`' pending sum, so that every
    value is the same bits. It is called, not inlined: the kernel compiles faster, and the call
    costs less than the machine's noise. Like the kernel's chunk loops that call it, it counts no
    references (``_nrt=False``, :mod:`foldopt.engine.kernel`): it allocates nothing, and a count
    of each array handed to it would be an atomic operation at every call."""
    first, last = span
    low, high = extremes
    above, whole = scratch
    n_steps, n_loads, size = power.shape[0], p_load.shape[0], low.shape[0]
    above[:] = 0.0
    whole[:] = 0.0
    previous = power[first]
    position = _walk(p_load, 0, previous)
    lower, upper = _bounds(p_load, position)
    # The run: where it is among the loads, its first length and the steps added to it since.
    run_at, run_start, count = position, (first + 0.5) * step_hours, 0
    begin = first + 1
    for k in range(size):
        end = min(first + (k + 1) * WALK_BLOCK, last + 1)
        if begin >= end:
            break
        if lower <= low[k] and high[k] < upper:
            # Each of the block's segments lies at ``position``, the first joining the run there.
            if run_at != position:
                whole[run_at] += _run_length(run_start, count, step_hours, held)
                run_at, run_start, count = position, -1.0, end - begin - 1
            else:
                count += end - begin
            previous, begin = power[end - 1], end
            continue
        for s in range(begin, end):
            p = power[s]
            lo_at = position
            if not (lower <= p and p < upper):
                at = _walk(p_load, position, p)
                lo_at, hi_at = min(position, at), max(position, at)
                if hi_at > lo_at:
                    # The loads strictly inside the segment's range take a share of it.
                    lo, hi = min(previous, p), max(previous, p)
                    for j in range(lo_at, hi_at):
                        above[j] += step_hours * (hi - p_load[j]) / (hi - lo)
                position = at
                lower, upper = _bounds(p_load, position)
            if lo_at == run_at:
                count += 1
            else:
                whole[run_at] += _run_length(run_start, count, step_hours, held)
                run_at, run_start, count = lo_at, -1.0, 0
            previous = p
        begin = end
    # The last sample held to the end of the day.
    tail = (n_steps - last - 0.5) * step_hours
    length = _run_length(run_start, count, step_hours, held)
    if run_at == position:
        whole[run_at] += length + tail
    else:
        whole[run_at] += length
        whole[position] += tail
    total = 0.0
    for j in range(n_loads - 1, -1, -1):
        total += whole[j + 1]
        t_out[j] = above[j] + total


def curve_rows(power, span, row_loadset, loads, out, scratch):
    """Daily metrics of given power curves (a tracker's), as :func:`fold_rows` with one connection.

    Parameters
    ----------
    power : (n_rows, n_steps) float
        Power at step centres [W].
    span : (n_rows, 2) int
        First and last step to walk: the steps with power and one without either side (zero power
        before and after holds no load: the steps outside add to no load's time).
    row_loadset : (n_rows,) int
        Set of loads of each row.
    loads : foldopt.engine.records.Loads
        With each row's load profile (n_rows, n_steps) where it has one.
    out : foldopt.engine.records.Outputs
        As :func:`fold_rows`'s, with one connection (no irradiation).
    scratch : foldopt.engine.records.Scratch
        Per chunk (:func:`foldopt.engine.records.allocate`).
    """
    in_chunks(_chunk_curves, power.shape[0], scratch, power, span, row_loadset, loads, out)


@njit(cache=True, nogil=True, _nrt=False, no_cfunc_wrapper=True)
def _chunk_curves(start, stop, power, span, row_loadset, loads, out, work):
    """Rows ``start .. stop - 1`` of :func:`curve_rows` with one chunk's scratch ``work`` (a thread
    of :func:`foldopt.engine.records.in_chunks` calls it)."""
    how = (loads.step_hours, loads.contiguous, loads.use_profile)
    scratch = (work.above, work.whole, work.run)
    for r in range(start, stop):
        out.energy[r, 0], out.peak[r, 0] = day_metrics(
            power[r],
            (span[r, 0], span[r, 1]),
            loads.p_load[row_loadset[r]],
            loads.profile[r if loads.use_profile else 0],
            how,
            scratch,
            out.t_solar[r, 0],
            out.t_solar_contiguous[r if loads.contiguous else 0, 0],
        )


@njit(cache=True)
def period_means(hours, member):
    """The mean over each period's days of daily values, in one pass over the days.

    Parameters
    ----------
    hours : (n_days, n) float
        Daily values (t_solar [h]) of ``n`` designs and loads.
    member : (n_periods, n_days) bool
        Whether each day belongs to each period.

    Returns
    -------
    (n_periods, n) float
        Each period's mean, NaN for a period of no day. Each is summed over its days in their order,
        then divided by their count: for ``n`` of 2 or more the bits of NumPy's
        ``hours[member[p]].mean(axis=0)``, which adds the days in order (with ``n`` 1 it sums them
        pairwise), without the copy of the period's days that costs a map's search most of its
        objective's time (``tests/test_metrics.py``).
    """
    n_periods, n = member.shape[0], hours.shape[1]
    total = np.zeros((n_periods, n))
    count = np.zeros(n_periods)
    for d in range(hours.shape[0]):
        for p in range(n_periods):
            if member[p, d]:
                count[p] += 1.0
                for x in range(n):
                    total[p, x] += hours[d, x]
    for p in range(n_periods):
        for x in range(n):
            total[p, x] = total[p, x] / count[p] if count[p] > 0.0 else np.nan
    return total
