"""Compiled state-of-charge simulation of a small buffer (numba): the loop over time that
:func:`foldopt.engine.storage.simulate` runs with ``engine='numba'``; the model, its conventions and
the layout of the arrays are documented there, and :func:`foldopt.engine.storage._simulate_numpy`
is the reference it is tested against.

One plain loop per series, the series spread over threads (:func:`simulate_series`). The arguments
are named records, module-level named tuples numba takes (:class:`Curves`, :class:`Parameters`,
:class:`Days`, of :mod:`foldopt.engine.storage_records`), each field with the same type at every
call (arrays of float64 laid out C-contiguous, a float, a bool), so that numba compiles one
specialisation once and caches it. The functions only compiled code calls have no wrapper for
Python's calls (as :mod:`foldopt.engine.kernel`'s).
NumPy's error model spares every division Python's check for a zero divisor (the model divides
by efficiencies, lengths and the capacity only where they are above zero). Dark
steps and steps with the buffer full, most of a day, take short cuts through the same
operations as the general part (:func:`_run`), so the two paths agree to the bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from foldopt.engine.storage_records import (
    CHARGE_LOSS,
    COLD_CHARGE,
    COLD_CUT,
    COLD_DISCHARGE,
    COLD_KEEP,
    DISCHARGE_LOSS,
    DRAWN,
    EMPTY,
    FULL,
    HARVESTED,
    HISTOGRAM,
    LOST,
    MISSING,
    PLAIN_ITERATIONS,
    POWERED,
    SELF_DISCHARGE,
    SERVED,
    Curves,
    Days,
    Parameters,
)


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _ramp(x, cap):
    """Antiderivative of ``clip(x, 0, cap)`` in ``x``, zero at ``x = 0``."""
    if x <= 0.0:
        return 0.0
    if x <= cap:
        return 0.5 * x * x
    return cap * (0.5 * cap + (x - cap))


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def clipped_energy(a, b, tau, cap):
    """Energy [Wh] of a power running linearly from ``a`` to ``b`` [W] over ``tau`` [h], each
    instant's power clipped to ``[0, cap]``."""
    lo, hi = min(a, b), max(a, b)
    if hi <= 0.0 or tau <= 0.0:
        return 0.0
    if lo >= cap:
        return tau * cap
    if lo >= 0.0 and hi <= cap:
        return 0.5 * tau * (a + b)
    return tau * (_ramp(hi, cap) - _ramp(lo, cap)) / (hi - lo)


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _charge(stored, spare, limit, capacity, eta):
    """Charge ``spare`` [Wh] offered at the bus, at most ``limit``, into the buffer holding
    ``stored`` [Wh]. Returns the new content, the charge loss and the energy lost [Wh], and
    whether the buffer is full."""
    room = max(capacity - stored, 0.0) / eta
    take = min(spare, limit)
    full = take >= room
    if full:  # set exactly, so that a full buffer is recognised as such
        take = room
        stored = capacity
    else:
        stored += take * eta
    return stored, take * (1.0 - eta), spare - take, full and capacity > 0.0


@njit(cache=True, error_model="numpy")
def time_to_draw(da, db, tau, energy):
    """Hours until a deficit running linearly from ``da`` to ``db`` [W] over ``tau`` [h] has
    drawn ``energy`` [Wh] (less than the whole part's): the root in ``[0, tau]`` of
    ``da t + (db - da) t^2 / (2 tau) = energy``, in the form that does not cancel. The rates are
    taken as at least 0 (at the crossing that bounds a part, rounding can leave one below)."""
    da, db = max(da, 0.0), max(db, 0.0)
    slope = 0.5 * (db - da) / tau
    if slope == 0.0:
        return min(energy / da, tau)
    root = math.sqrt(max(da * da + 4.0 * slope * energy, 0.0))
    if da + root == 0.0:
        # From a crossing (da 0) with an energy so small that 4 slope energy underflows: the
        # root of slope t^2 = energy, which does not (2 energy / 0 would run the whole part).
        return min(math.sqrt(energy / slope), tau)
    return min(2.0 * energy / (da + root), tau)


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _part(ends, tau, surplus, stored, on, par, cold):
    """One part of a segment over ``tau`` [h] (``tau`` > 0), in which the power left after the
    design's own draw runs from ``pa`` to ``pb``, the load from ``la`` to ``lb`` and that draw
    from ``da`` to ``db`` [W] (``ends``, the six in that order), the power at or above the load
    throughout (``surplus``) or below it; ``stored`` [Wh] and ``on`` the buffer's content and
    the load's state at its start, ``par`` the series' :class:`Parameters`, ``cold`` the
    segment's cut-off and reconnection [Wh] and whether the buffer may charge and discharge
    (the series' cold array's, the levels as contents).

    Returns the buffer's content [Wh], whether the load is on, the part's energies [Wh] served,
    missing, lost, lost in charging and in discharging, the hours the load ran, whether the
    buffer was full, whether it ran down to its cut-off, and the design's own draw served [Wh].
    Scalars only, so that the call moves no array (numba counts references to arrays passed to
    a function)."""
    pa, pb, la, lb, da, db = ends
    floor, restart, charge, discharge = cold
    capacity = par.capacity
    pv = 0.5 * tau * (pa + pb)
    need = 0.5 * tau * (la + lb)
    own = 0.5 * tau * (da + db)
    if not on and stored >= restart:
        on = True
    if on and surplus:
        # A blocked charger takes nothing: the surplus is lost as over a full buffer.
        limit = clipped_energy(pa - la, pb - lb, tau, par.max_charge) if charge else 0.0
        stored, loss, lost, full = _charge(
            stored, max(pv - need, 0.0), limit, capacity, par.eta_charge
        )
        return stored, on, need, 0.0, lost, loss, 0.0, tau, full, False, own
    served = ran = discharge_loss = drawn = 0.0
    empty = False
    if on:
        usable = stored - floor
        eta = par.eta_discharge
        if discharge and usable > 0.0 and max(la - pa, lb - pb) <= par.max_discharge:
            short = max(need - pv, 0.0)
            if short <= eta * usable:
                taken = short / eta
                left = stored - taken
                return left, on, need, 0.0, 0.0, 0.0, taken - short, tau, False, False, own
            # The buffer carries the load part of the way, to its cut-off; the rest is off.
            ran = time_to_draw(la - pa, lb - pb, tau, eta * usable)
            x = ran / tau
            pm, lm, dm = pa + x * (pb - pa), la + x * (lb - la), da + x * (db - da)
            served = 0.5 * ran * (la + lm)
            drawn = 0.5 * ran * (da + dm)
            discharge_loss = usable - eta * usable
            stored = floor
            pa, la, da, tau = pm, lm, dm, tau - ran
            need = 0.5 * tau * (la + lb)
        on = False
        # not when only max_discharge_w or the cold turned the load off
        empty = stored <= floor
    # The controller has the load and the design's own draw off: the whole power charges.
    spare = clipped_energy(pa + da, pb + db, tau, math.inf)
    limit = clipped_energy(pa + da, pb + db, tau, par.max_charge) if charge else 0.0
    stored, loss, lost, full = _charge(stored, spare, limit, capacity, par.eta_charge)
    return stored, on, served, need, lost, loss, discharge_loss, ran, full, empty, drawn


@njit(cache=True, inline="always")
def _at(cold, d, j, column):
    """Day ``d``'s segment ``j`` of one series' cold array, its ``COLD_*`` ``column`` (a size 1
    serves every day or segment)."""
    return cold[d if cold.shape[0] > 1 else 0, j if cold.shape[1] > 1 else 0, column]


#: Day or segment 0 as an int64, not a literal: numba compiles a function once more for each
#: literal argument's type (:func:`_levels` thrice).
FIRST = np.int64(0)
#: The fewest steps (series x days x steps a day) a chunk of :func:`simulate_series` takes: a
#: thread woken for less costs more than it takes off.
STEPS_PER_CHUNK = 2_000


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _levels(par, cold, d, j):
    """Day ``d``'s segment ``j``: the cut-off and the reconnection [Wh] the cold raises
    (:func:`foldopt.physics.buffer_temperature.cold_cut_off`; the buffer's own without it)."""
    cut = _at(cold, d, j, COLD_CUT)
    floor = (par.min_soc + cut * (1.0 - par.min_soc)) * par.capacity
    restart = (par.restart_soc + cut * (1.0 - par.restart_soc)) * par.capacity
    return floor, restart


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _run(curves, par, cold, stored, on, merge, days):
    """One pass over a series' days (its :class:`Curves`, :class:`Parameters`, cold array and
    :class:`Days`) from the content ``stored`` [Wh] and load state ``on``.

    With ``merge``, a day that starts in the state the previous pass started it in
    (``days.state``) ends the pass: from there on, the previous pass's outputs are this one's. The
    load's state is kept as on wherever the content allows it to reconnect (the same state: the
    first part would reconnect it; after the last day, as the first day's first part would).
    Returns the state at the end of the last day.
    """
    power, load, draw, step_hours = curves
    out, state, soc, keep_soc = days
    n_days, n_steps = power.shape
    profile_days, profile_steps = load.shape[0] > 1, load.shape[1] > 1
    draw_days, draw_steps = draw.shape[0] > 1, draw.shape[1] > 1
    capacity = par.capacity
    n_bins = out.shape[1] - HISTOGRAM
    keep_half, keep_step = par.keep_half, par.keep_step
    eta_discharge = par.eta_discharge
    max_discharge = par.max_discharge
    for d in range(n_days):
        floor, restart = _levels(par, cold, d, FIRST)
        on = on or stored >= restart
        flag = 1.0 if on else 0.0
        if merge and state[d, 0] == stored and state[d, 1] == flag:
            return state[n_days, 0], state[n_days, 1] > 0.5
        state[d, 0], state[d, 1] = stored, flag
        row = out[d]
        row[:] = 0.0
        full = capacity > 0.0 and stored >= capacity
        empty = stored <= floor
        powered = served = missing = lost = charge_loss = discharge_loss = leak = 0.0
        harvested = drawn = 0.0
        day_load = load[d if profile_days else 0]
        day_draw = draw[d if draw_days else 0]
        for j in range(n_steps + 1):
            # Segment j runs from the centre of step j - 1 to that of step j; the first and the
            # last are the half steps held at the day's ends (foldopt.engine.metrics).
            first, last = max(j - 1, 0), min(j, n_steps - 1)
            p0, p1 = power[d, first], power[d, last]
            l0 = day_load[first if profile_steps else 0]
            l1 = day_load[last if profile_steps else 0]
            d0 = day_draw[first if draw_steps else 0]
            d1 = day_draw[last if draw_steps else 0]
            half = j == 0 or j == n_steps
            tau = 0.5 * step_hours if half else step_hours
            floor, restart = _levels(par, cold, d, j)
            charge = _at(cold, d, j, COLD_CHARGE) > 0.0
            discharge = _at(cold, d, j, COLD_DISCHARGE) > 0.0
            if j < n_steps:
                harvested += p1 + d1
            e0, e1 = p0 - l0, p1 - l1
            demand = l0 > 0.0 and l1 > 0.0  # time counts where the load runs at both ends
            # Three common segments take a short cut, by the very operations _part would do (the
            # results are the same to the bit): a dark one the buffer carries, a dark one with the
            # load off (neither with a draw of the design's own), and one above the load with the
            # buffer full.
            need = 0.5 * tau * (l0 + l1)
            usable = stored - floor
            dark = p0 == 0.0 and p1 == 0.0 and d0 == 0.0 and d1 == 0.0
            if (
                on
                and discharge
                and dark
                and l0 == l1
                and l0 > 0.0
                and usable > 0.0
                and l0 <= max_discharge
                and need <= eta_discharge * usable
            ):
                taken = need / eta_discharge
                stored = stored - taken
                served += need
                discharge_loss += taken - need
                if demand:
                    powered += tau
            elif not on and dark and l0 == l1 and stored < restart:
                missing += need  # dark and off: nothing to charge
            elif on and e0 >= 0.0 and e1 >= 0.0 and stored >= capacity:
                # _part's one part above the load runs to p0 + 1.0 * (p1 - p0), and so the load
                # and the draw.
                ls = l0 + (l1 - l0)
                need = 0.5 * tau * (l0 + ls)
                served += need
                drawn += 0.5 * tau * (d0 + (d0 + (d1 - d0)))
                lost += max(0.5 * tau * (p0 + (p0 + (p1 - p0))) - need, 0.0)
                if demand:
                    powered += tau
                stored = capacity
                full = full or capacity > 0.0
            else:
                if e0 >= 0.0 and e1 >= 0.0:
                    above = 1.0
                elif e0 < 0.0 and e1 < 0.0:
                    above = 0.0
                else:
                    above = max(e0, e1) / abs(e0 - e1)
                rising = e0 < 0.0  # below the load first
                split = 1.0 - above if rising else above
                ps, ls = p0 + split * (p1 - p0), l0 + split * (l1 - l0)
                ds = d0 + split * (d1 - d0)
                t_above, t_below = tau * above, tau * (1.0 - above)
                for second in (False, True):
                    length = (
                        (t_above if rising else t_below)
                        if second
                        else (t_below if rising else t_above)
                    )
                    if length <= 0.0:
                        continue
                    ends = (ps, p1, ls, l1, ds, d1) if second else (p0, ps, l0, ls, d0, ds)
                    (
                        stored,
                        on,
                        s_wh,
                        m_wh,
                        l_wh,
                        c_wh,
                        d_wh,
                        ran_h,
                        was_full,
                        ran_out,
                        own_wh,
                    ) = _part(
                        ends,
                        length,
                        rising == second,
                        stored,
                        on,
                        par,
                        (floor, restart, charge, discharge),
                    )
                    served += s_wh
                    missing += m_wh
                    lost += l_wh
                    charge_loss += c_wh
                    discharge_loss += d_wh
                    drawn += own_wh
                    if demand:
                        powered += ran_h
                    full = full or was_full
                    empty = empty or ran_out
            keep = _at(cold, d, j, COLD_KEEP)
            if math.isnan(keep):
                keep = keep_half if half else keep_step
            if keep < 1.0:  # without a leak the product is the content itself: spared
                kept = stored * keep
                leak += stored - kept
                stored = kept
            level = stored / capacity if capacity > 0.0 else 0.0
            row[HISTOGRAM + min(max(int(level * n_bins), 0), n_bins - 1)] += tau
            if keep_soc and j < n_steps:
                soc[d, j] = level
        row[POWERED], row[SERVED], row[MISSING], row[LOST] = powered, served, missing, lost
        row[HARVESTED] = harvested * step_hours
        row[CHARGE_LOSS], row[DISCHARGE_LOSS], row[SELF_DISCHARGE] = (
            charge_loss,
            discharge_loss,
            leak,
        )
        row[FULL], row[EMPTY] = 1.0 if full else 0.0, 1.0 if empty else 0.0
        row[DRAWN] = drawn
    on = on or stored >= _levels(par, cold, FIRST, FIRST)[1]
    state[n_days, 0], state[n_days, 1] = stored, 1.0 if on else 0.0
    return stored, on


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _series(curves, par, cold, days, max_iterations, tolerance):
    """A series (its :class:`Curves`, :class:`Parameters`, cold array and :class:`Days`) from
    its initial
    state of charge, or in its periodic state: passes until the state at the end of the series is
    that at its start (content within ``tolerance`` x the capacity, the load on or off alike),
    first plainly from a full buffer, then by bisection on the start's content, until the start is
    known to the tolerance (then periodic if the end is within one step's load energy of it).
    Returns the passes run, negative when none was periodic."""
    capacity = par.capacity
    if not math.isnan(par.initial_soc):
        stored = par.initial_soc * capacity
        on = stored >= _levels(par, cold, FIRST, FIRST)[1]
        # np.bool_, not a literal: numba compiles a function again for a literal argument's type.
        _run(curves, par, cold, stored, on, np.bool_(False), days)
        return 1
    resolution = 0.0  # one step's load energy [Wh], the largest of the series
    for row in curves.load:
        for value in row:
            resolution = max(resolution, value * curves.step_hours)
    low, high = 0.0, capacity
    # np.bool_, not a literal: numba would compile ``_run`` once more for the first pass's types.
    stored, on = capacity, np.bool_(True)
    passes = 0
    while passes < max_iterations:
        passes += 1
        end, end_on = _run(curves, par, cold, stored, on, passes > 1, days)
        if abs(end - stored) <= tolerance * capacity and end_on == on:
            return passes
        if end > stored:
            low = stored
        elif end < stored:
            high = stored
        if high - low <= tolerance * capacity:
            # The start is known to the tolerance and the end jumps over it (a cut-off or a
            # reconnection a part earlier or later): periodic to the model's resolution if the
            # jump is within one step's load energy.
            return passes if abs(end - stored) <= resolution else -passes
        on = end_on
        if passes < PLAIN_ITERATIONS and low <= end <= high:
            stored = end
        else:
            stored = 0.5 * (low + high)
    return -passes


@njit(cache=True, inline="always")
def _one(values, s):
    """Series ``s`` of per-series ``values`` (the only one where there is one)."""
    return values[s if values.shape[0] > 1 else 0]


@njit(cache=True, nogil=True, error_model="numpy", no_cfunc_wrapper=True)
def _series_range(start, stop, curves, params, cold, days, passes, limits):
    """Series ``start .. stop - 1`` of :func:`simulate_series` (a thread of
    :func:`foldopt.engine.records.in_chunks` calls it); ``limits``: its ``(max_iterations,
    tolerance)``."""
    max_iterations, tolerance = limits
    power, load, draw, step_hours = curves
    out, state, soc, keep_soc = days
    for s in range(start, stop):
        passes[s] = _series(
            Curves(_one(power, s), _one(load, s), _one(draw, s), step_hours),
            Parameters(
                params.capacity[s],
                params.min_soc[s],
                params.restart_soc[s],
                params.eta_charge[s],
                params.eta_discharge[s],
                params.keep_step[s],
                params.keep_half[s],
                params.max_charge[s],
                params.max_discharge[s],
                params.initial_soc[s],
            ),
            _one(cold, s),
            Days(out[s], state[s], soc[s if keep_soc else 0], keep_soc),
            max_iterations,
            tolerance,
        )


def simulate_series(curves, params, cold, days, passes, max_iterations, tolerance):
    """Every series, spread over the engine's threads (:func:`foldopt.engine.storage.simulate`).

    The series run in chunks of :func:`_series_range`, compiled with ``nogil``, on the threads of
    :func:`foldopt.engine.records.in_chunks`, as the fold kernel's rows do: a numba ``prange`` loop
    compiled several times slower, and its OpenMP threads, woken at every call, cost a call of
    one series milliseconds under load against a tenth of one on the calling thread, which a call
    of fewer steps than two chunks' (:data:`STEPS_PER_CHUNK`) keeps to.

    Parameters
    ----------
    curves : Curves
        Of every series (or one that serves all).
    params : Parameters
        The buffer of each series.
    cold : (n_series or 1, n_days or 1, n_steps + 1 or 1, 4) float
        The buffer's temperature's effects per segment (``COLD_*`` columns), of every series (or
        one that serves all).
    days : Days
        Of every series, written.
    passes : (n_series,) int
        Passes run, negative where no periodic state was found; written.
    max_iterations : int
    tolerance : float
    """
    from numba import get_num_threads

    from foldopt.engine.records import in_chunks

    n_series = passes.shape[0]
    steps = n_series * curves.power.shape[1] * curves.power.shape[2]
    # Chunks of STEPS_PER_CHUNK steps or more, one a thread: each chunk is a call of the compiled
    # loop, whose records' arrays numba takes again at every call (a sizing search calls this
    # hundreds of times).
    n_chunks = max(1, min(n_series, steps // STEPS_PER_CHUNK, get_num_threads()))
    records = (curves, params, cold, days, passes, (int(max_iterations), float(tolerance)))
    in_chunks(_series_range, n_series, None, *records, n_chunks=n_chunks)
