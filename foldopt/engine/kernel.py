"""Compiled loops of the engine (numba): sun to t_solar per row, with no (rows x steps) arrays.

A *row* is one block (a day at a site, see :class:`foldopt.engine.sky.Sky`) seen by one orientation of
the two sub-panels (a fold angle). :func:`fold_rows` takes each row in three tight loops over its
time steps. In the first, both sub-panel normals against the sun vector give the beam's incidence
(or Shin et al.'s Eq. 5 in paper mode), and the beam with the optional incidence-angle modifier
and the diffuse terms give each sub-panel's plane-of-array irradiance; free of table look-ups, it
vectorises. The second looks up the electrical tables and writes every asked connection's power
to a buffer of one day, reused by the next row. The third reduces each power curve to the daily
metrics of every load at once (:func:`_metrics`). :func:`curve_rows` takes power curves that
already exist (a tracker's) through the same reduction.

The metrics are those of :mod:`foldopt.engine.metrics`, which is their reference: power is sampled at
step centres and linear between them (held for half a step at both ends of the day), and a
segment from ``lo`` to ``hi`` of length ``dt`` is above a load ``L`` for
``dt * clip((hi - L) / (hi - lo), 0, 1)``. For many loads sorted ascending, the loads at or below
``lo`` take the whole segment: one entry of a difference array, summed from the top at the end;
only the loads inside the segment's range take a share. The position of the power among the loads
moves by a few loads a step, so it is walked from the previous step instead of searched. A day's
cost is then O(steps + loads x crossings), not O(steps x loads).

Rows are split into chunks, a few per thread, and each chunk has its own scratch, allocated by the
caller outside the parallel loop (:func:`scratch`; arrays zero-filled inside a numba prange body
have given wrong sums) and cleared per row.

Every function here is checked against the NumPy reference path of :mod:`foldopt.engine.rows` by
``tests/test_engine.py`` (hypothesis: random sites, days, loads, angles and models).
"""

from __future__ import annotations

import math

import numpy as np
from numba import get_num_threads, njit, prange

# Connection codes; the order of foldopt.physics.connections.CONNECTIONS, plus the whole (unfolded) panel.
EAST, WEST, PARALLEL, SERIES, INDEPENDENT, SWITCHING, PANEL = range(7)
IAM_NONE, IAM_ASHRAE, IAM_PHYSICAL = range(3)
IRRADIANCE_MAX = 1500.0  # [W/m^2], top of the electrical tables (foldopt.engine.electrical)
CHUNKS_PER_THREAD = 8  # rows are handed out in chunks: enough for balance, few scratch buffers


@njit(cache=True, inline="always")
def _linear(values, position):
    index = min(int(position), values.shape[0] - 2)
    weight = position - index
    return values[index] * (1.0 - weight) + values[index + 1] * weight


@njit(cache=True, inline="always")
def _bilinear(values, first, second):
    i = min(int(first), values.shape[0] - 2)
    j = min(int(second), values.shape[1] - 2)
    fi, fj = first - i, second - j
    return ((values[i, j] * (1.0 - fj) + values[i, j + 1] * fj) * (1.0 - fi)
            + (values[i + 1, j] * (1.0 - fj) + values[i + 1, j + 1] * fj) * fi)


@njit(cache=True, inline="always")
def _pair_powers(root_east, root_west, table_1d, table_parallel, table_series, need_series, bypass):
    """East, west, parallel and series power [W] from one table set at both sub-panels'
    irradiance (as sqrt(E / E_max))."""
    n1 = table_1d.shape[0] - 1
    n2, nr = table_parallel.shape[0] - 1, table_parallel.shape[1] - 1
    p_east = _linear(table_1d, root_east * n1)
    p_west = _linear(table_1d, root_west * n1)
    bound = p_east + p_west
    # The pair tables: stronger irradiance (as its root) x weaker/stronger ratio (parallel: as its
    # root; series: the ratio itself).
    strong, weak = max(root_east, root_west), min(root_east, root_west)
    root_ratio = weak / strong if strong > 0.0 else 1.0
    p_parallel = min(max(_bilinear(table_parallel, strong * n2, root_ratio * nr), 0.0), 1.0) * bound
    p_series = bound
    if need_series:
        fraction = _bilinear(table_series, strong * n2, root_ratio**2 * nr)
        p_series = min(max(fraction, 0.0), 1.0) * bound
    if bypass:
        p_series = max(p_series, max(p_east, p_west))
    return p_east, p_west, p_parallel, p_series


@njit(cache=True)
def iam_factor(cos_aoi, model, params):
    """Incidence-angle modifier of the beam, the arithmetic of pvlib's ``iam.ashrae`` and
    ``iam.physical`` (without coating) for one angle.

    Parameters
    ----------
    cos_aoi : float
        Cosine of the angle of incidence [-].
    model : int
        ``IAM_NONE``, ``IAM_ASHRAE`` or ``IAM_PHYSICAL``.
    params : (3,) float
        ASHRAE: ``b`` [-] (then unused); physical: ``n`` [-], ``K`` [1/m], ``L`` [m].

    Returns
    -------
    float
        Modifier [-]; 0 for light from behind, 1 for ``IAM_NONE``.

    References
    ----------
    .. [1] A. F. Souka, H. H. Safwat, "Determination of the optimum orientations for the double
       exposure flat-plate collector and its reflections", Solar Energy 10, 170-174, 1966; ASHRAE
       standard 93-77 (``1 - b (1 / cos(AOI) - 1)``).
    .. [2] W. De Soto, S. A. Klein, W. A. Beckman, "Improvement and validation of a model for
       photovoltaic array performance", Solar Energy 80(1), 78-88, 2006 (physical).
    """
    if model == IAM_NONE:
        return 1.0
    if cos_aoi <= 0.0:
        return 0.0
    if model == IAM_ASHRAE:
        return max(1.0 - params[0] * (1.0 / cos_aoi - 1.0), 0.0)
    n, k, thickness = params[0], params[1], params[2]
    sin_1 = math.sqrt(max(1.0 - cos_aoi * cos_aoi, 0.0))
    sin_2 = sin_1 / n
    cos_2 = math.sqrt(1.0 - sin_2 * sin_2)
    rho_s = ((cos_aoi - n * cos_2) / (cos_aoi + n * cos_2)) ** 2
    rho_p = ((cos_2 - n * cos_aoi) / (cos_2 + n * cos_aoi)) ** 2
    rho_0 = ((1.0 - n) / (1.0 + n)) ** 2
    absorbed = math.exp(-k * thickness / cos_2)
    return ((1.0 - rho_s) * absorbed + (1.0 - rho_p) * absorbed) / 2.0 / ((1.0 - rho_0) * math.exp(-k * thickness))


@njit(cache=True, inline="always")
def _walk(loads, position, power):
    """Number of loads at or below ``power``, walked from the previous step's ``position``."""
    count = loads.shape[0]
    while position < count and loads[position] <= power:
        position += 1
    while position > 0 and loads[position - 1] > power:
        position -= 1
    return position


@njit(cache=True, inline="always")
def _shares(loads, lo, hi, lo_at, hi_at, length, above, run, contiguous):
    """Shares of a segment from ``lo`` to ``hi`` for the loads strictly inside its range."""
    for j in range(lo_at, hi_at):
        share = length * (hi - loads[j]) / (hi - lo)
        above[j] += share
        if contiguous:
            run[j, 0] += share


@njit(cache=True, inline="always")
def _runs(start_at, lo_at, length, run):
    """Longest runs: a sample below a load ends that load's run (the segment starts a new one);
    loads below the segment's low end run on through it."""
    for j in range(start_at, run.shape[0]):
        run[j, 1] = max(run[j, 1], run[j, 0])
        run[j, 0] = 0.0
    for j in range(lo_at):
        run[j, 0] += length


@njit(cache=True, inline="always")
def _gather(whole, pending_at, pending, lo_at, length):
    """Add ``length`` to the pending sum for ``whole[lo_at]``, writing the previous sum out when
    the index changes."""
    if lo_at == pending_at:
        return pending_at, pending + length
    whole[pending_at] += pending
    return lo_at, length


@njit(cache=True, inline="always")
def _per_load(p, shape, s, use_shape):
    """The power against which the loads are compared at step ``s``: the power itself for constant
    loads, or for a load profile P_load(t) = scale x shape(t) the ratio P_pv / shape, so that
    P_pv >= scale x shape is ratio >= scale; a step without load (shape 0) is -inf, which no scale
    reaches, and neither do the segments next to it (:func:`foldopt.engine.metrics.per_load`)."""
    if not use_shape:
        return p
    g = shape[s]
    return p / g if g > 0.0 else -math.inf


@njit(cache=True)
def _metrics(power, first, last, step_hours, loads, contiguous, above, whole, run, t_out, cont_out, shape,
             use_shape):
    """Daily metrics of one power curve [W] sampled at step centres, of which only steps
    ``first..last`` need walking: the power before and after them is that of the first and the
    last (zero, or the day's end). Writes t_solar (and its longest run) per load; returns the
    energy [Wh] and the peak [W]. With ``use_shape`` the loads are scales of the load profile
    ``shape`` (n_steps) [W] (:func:`_per_load`); steps outside ``first..last`` hold the power of
    the first and last, and the shape there is taken as the first's and the last's.

    A segment adds its length to ``whole[k]`` when the k lowest loads lie at or below its low end
    (summed from the top at the end), and shares to the loads inside its range. Consecutive
    segments mostly share k, so their lengths gather in a local sum first."""
    n_steps, n_loads = power.shape[0], loads.shape[0]
    above[:] = 0.0
    whole[:] = 0.0
    if contiguous:
        run[:] = 0.0
    # The half-step held at the start of the day, and the steps before ``first``.
    harvested = peak = power[first]
    previous = _per_load(power[first], shape, first, use_shape)
    position = _walk(loads, 0, previous)
    pending_at, pending = position, (first + 0.5) * step_hours
    if contiguous:
        _runs(position, position, pending, run)
    for s in range(first + 1, last + 1):
        harvested += power[s]
        peak = max(peak, power[s])
        p = _per_load(power[s], shape, s, use_shape)
        at = _walk(loads, position, p)
        lo_at, hi_at = min(position, at), max(position, at)
        if contiguous:
            _runs(position, lo_at, step_hours, run)
        pending_at, pending = _gather(whole, pending_at, pending, lo_at, step_hours)
        if hi_at > lo_at:
            _shares(loads, min(previous, p), max(previous, p), lo_at, hi_at, step_hours, above, run, contiguous)
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
def _connection_power(code, p_east, p_west, p_parallel, p_series, p_panel, converter_efficiency, switch_series):
    if code == SWITCHING:
        best = max(max(p_east, p_west), p_parallel)
        return max(best, p_series) if switch_series else best
    if code == EAST:
        return p_east
    if code == WEST:
        return p_west
    if code == PARALLEL:
        return p_parallel
    if code == SERIES:
        return p_series
    if code == INDEPENDENT:
        return converter_efficiency * (p_east + p_west)
    return p_panel


@njit(cache=True)
def _fold_powers(r, b, first, last, sun, paper_sun, beam, terms, row_normal, row_paper, paper_incidence, iam_model,
                 iam_params, step_table, step_weight, table_1d, table_parallel, table_series, linear_power,
                 panel_scale, bypass, switch_series, converter_efficiency, connections, irradiance, buffer):
    """Every asked connection's power [W] of row ``r`` (over block ``b``) at steps
    ``first..last``, into ``buffer[c, step]``; returns the sum over those steps of the two
    sub-panels' mean incident plane-of-array irradiance [W/m^2] (before the incidence-angle
    modifier).

    Two loops: the first, free of table look-ups so that it vectorises, gives both sub-panels'
    irradiance (as sqrt(E / E_max), the tables' coordinate, with tables) into ``irradiance``; the
    second looks up the powers, from table set ``step_table[b, s]`` and, with weight
    ``step_weight[b, s]``, the next (both (n_blocks, n_steps), or (n_blocks, 1) for one set a
    block). Sun, beam and terms are laid out (n_blocks, component, n_steps)."""
    n_conn = connections.shape[0]
    has_terms = terms.shape[1] == 4
    tables = linear_power == 0.0
    need_series = switch_series
    for c in range(n_conn):
        need_series = need_series or connections[c] == SERIES
    ex, ey, ez = row_normal[r, 0, 0], row_normal[r, 0, 1], row_normal[r, 0, 2]
    wx, wy, wz = row_normal[r, 1, 0], row_normal[r, 1, 1], row_normal[r, 1, 2]
    e_sin_tilt = math.sqrt(max(1.0 - ez * ez, 0.0))
    w_sin_tilt = math.sqrt(max(1.0 - wz * wz, 0.0))
    to_root = 1.0 / IRRADIANCE_MAX
    sx, sy, sz, dni = sun[b, 0], sun[b, 1], sun[b, 2], beam[b]
    irradiation = 0.0
    for s in range(first, last + 1):
        cos_east = ex * sx[s] + ey * sy[s] + ez * sz[s]
        cos_west = wx * sx[s] + wy * sy[s] + wz * sz[s]
        if paper_incidence:
            cz, szen, sa, ca = paper_sun[b, 0, s], paper_sun[b, 1, s], paper_sun[b, 2, s], paper_sun[b, 3, s]
            f_east = (max(cz * row_paper[r, 0, 0] + szen * row_paper[r, 0, 1], 0.0)
                      * max(ca * row_paper[r, 0, 2] + sa * row_paper[r, 0, 3], 0.0))
            f_west = (max(cz * row_paper[r, 1, 0] + szen * row_paper[r, 1, 1], 0.0)
                      * max(ca * row_paper[r, 1, 2] + sa * row_paper[r, 1, 3], 0.0))
        else:
            f_east, f_west = max(cos_east, 0.0), max(cos_west, 0.0)
        g_east, g_west = dni[s] * f_east, dni[s] * f_west
        d_east = d_west = 0.0
        if has_terms:
            iso, circ, hor, ground = terms[b, 0, s], terms[b, 1, s], terms[b, 2, s], terms[b, 3, s]
            d_east = (max(iso * (1.0 + ez) * 0.5 + circ * max(cos_east, 0.0) + hor * e_sin_tilt, 0.0)
                      + ground * (1.0 - ez) * 0.5)
            d_west = (max(iso * (1.0 + wz) * 0.5 + circ * max(cos_west, 0.0) + hor * w_sin_tilt, 0.0)
                      + ground * (1.0 - wz) * 0.5)
        irradiation += 0.5 * (g_east + d_east + g_west + d_west)
        if iam_model != IAM_NONE:
            g_east *= iam_factor(cos_east, iam_model, iam_params)
            g_west *= iam_factor(cos_west, iam_model, iam_params)
        g_east, g_west = g_east + d_east, g_west + d_west
        if tables:
            g_east = math.sqrt(min(max(g_east, 0.0), IRRADIANCE_MAX) * to_root)
            g_west = math.sqrt(min(max(g_west, 0.0), IRRADIANCE_MAX) * to_root)
        irradiance[0, s], irradiance[1, s] = g_east, g_west
    per_step = step_table.shape[1] > 1
    # One table set a block (no weather file): its tables are taken once a row.
    row_1d, row_parallel, row_series = (table_1d[step_table[b, 0]], table_parallel[step_table[b, 0]],
                                        table_series[step_table[b, 0]])
    for s in range(first, last + 1):
        root_east, root_west = irradiance[0, s], irradiance[1, s]
        if not tables:
            p_east, p_west = linear_power * root_east, linear_power * root_west
            p_parallel = p_series = p_east + p_west
        elif not per_step:
            p_east, p_west, p_parallel, p_series = _pair_powers(root_east, root_west, row_1d, row_parallel,
                                                                row_series, need_series, bypass)
        else:
            t, w = step_table[b, s], step_weight[b, s]
            p_east, p_west, p_parallel, p_series = _pair_powers(root_east, root_west, table_1d[t], table_parallel[t],
                                                                table_series[t], need_series, bypass)
            if w > 0.0:
                # The step's cells lie between two tables' air temperatures: linear between them.
                q_east, q_west, q_parallel, q_series = _pair_powers(root_east, root_west, table_1d[t + 1],
                                                                    table_parallel[t + 1], table_series[t + 1],
                                                                    need_series, bypass)
                p_east += w * (q_east - p_east)
                p_west += w * (q_west - p_west)
                p_parallel += w * (q_parallel - p_parallel)
                p_series += w * (q_series - p_series)
        p_panel = panel_scale * p_east
        for c in range(n_conn):
            buffer[c, s] = _connection_power(connections[c], p_east, p_west, p_parallel, p_series, p_panel,
                                             converter_efficiency, switch_series)
    return irradiation


@njit(cache=True, parallel=True)
def fold_rows(sun, paper_sun, beam, terms, span, step_table, step_weight, row_block, row_normal, row_paper, row_loadset,
              paper_incidence, iam_model, iam_params, table_1d, table_parallel, table_series, linear_power,
              panel_scale, bypass, switch_series, converter_efficiency, connections, loads, step_hours,
              contiguous, load_shape, use_shape, t_out, cont_out, energy_out, peak_out, irradiation_out, irradiance,
              buffer, above, whole, run):
    """Daily metrics of every row and connection, computing the power on the fly.

    Parameters
    ----------
    sun : (n_blocks, 3, n_steps) float
        Unit sun vectors (east, north, up).
    paper_sun : (n_blocks, 4, n_steps) float
        cos(zenith), sin(zenith), sin(azimuth), cos(azimuth) for Eq. 5 (used in paper mode).
    beam : (n_blocks, n_steps) float
        Direct normal irradiance [W/m^2].
    terms : (n_blocks, 4, n_steps) float
        Diffuse terms (isotropic, circumsolar, horizon, ground) of
        :func:`foldopt.physics.irradiance.sky_diffuse_terms`; shape (n_blocks, 0, n_steps) for beam only.
    span : (n_blocks, 2) int
        First and last step to walk: the steps with any light and one dark step either side. The
        dark steps before and after hold zero power, so they join the half-steps held at the ends
        of the day.
    step_table, step_weight : (n_blocks, n_steps) or (n_blocks, 1) int and float
        The electrical table set of each step (or of each block): its cells' air temperature lies
        between set ``t`` and ``t + 1``, at ``weight`` of the way (0: set ``t``).
    row_block, row_loadset : (n_rows,) int
    row_normal : (n_rows, 2, 3) float
        East and west sub-panel normals.
    row_paper : (n_rows, 2, 4) float
        cos(tilt), sin(tilt), cos(azimuth), sin(azimuth) per sub-panel (paper mode).
    table_1d, table_parallel, table_series : float arrays
        Stacked over table sets (air temperatures), per set: sub-panel power [W] on sqrt-spaced
        irradiance nodes, and the parallel and series pairs as fractions of the two maxima over
        the stronger irradiance and the weaker/stronger ratio (:class:`foldopt.engine.electrical.Electrical`).
    linear_power : float
        ``efficiency * sub-panel area`` [m^2] for the ideal model (no tables); 0 with tables.
    panel_scale : float
        Panel area / sub-panel area.
    connections : (n_conn,) int
        Connection codes to evaluate.
    loads : (n_loadsets, n_loads) float
        Loads [W], ascending in each set.
    contiguous : bool
        Whether to track the longest contiguous interval too.
    load_shape : (n_blocks, n_steps) float
        With ``use_shape``, each block's load profile [W]: the loads are then its scales (one row
        (1, 1) without).
    use_shape : bool
    t_out, cont_out : (n_rows, n_conn, n_loads) float
        t_solar and its longest contiguous interval [h] (out).
    energy_out, peak_out : (n_rows, n_conn) float
        Energy [Wh] and peak power [W] (out).
    irradiation_out : (n_rows,) float
        Incident plane-of-array irradiation [Wh/m^2] (before the incidence-angle modifier), the
        mean of the two (equal) sub-panels (out).
    irradiance, buffer, above, whole, run : per-chunk scratch from :func:`scratch`.
    """
    n_rows = row_block.shape[0]
    n_chunks = buffer.shape[0]
    per_chunk = (n_rows + n_chunks - 1) // n_chunks
    for k in prange(n_chunks):
        for r in range(k * per_chunk, min((k + 1) * per_chunk, n_rows)):
            b = row_block[r]
            first, last = span[b, 0], span[b, 1]
            irradiation = _fold_powers(
                r, b, first, last, sun, paper_sun, beam, terms, row_normal, row_paper, paper_incidence, iam_model,
                iam_params, step_table, step_weight, table_1d, table_parallel, table_series, linear_power,
                panel_scale, bypass, switch_series, converter_efficiency, connections, irradiance[k], buffer[k])
            irradiation_out[r] = irradiation * step_hours
            for c in range(connections.shape[0]):
                energy_out[r, c], peak_out[r, c] = _metrics(
                    buffer[k, c], first, last, step_hours, loads[row_loadset[r]], contiguous, above[k], whole[k],
                    run[k], t_out[r, c], cont_out[r if contiguous else 0, c], load_shape[b if use_shape else 0],
                    use_shape)


@njit(cache=True, parallel=True)
def curve_rows(power, row_loadset, loads, step_hours, contiguous, load_shape, use_shape, t_out, cont_out, energy_out,
               peak_out, above, whole, run):
    """Daily metrics of given power curves (a tracker's), as :func:`fold_rows` with one connection.

    Parameters
    ----------
    power : (n_rows, n_steps) float
        Power at step centres [W].
    row_loadset : (n_rows,) int
        Set of loads of each row.
    loads : (n_loadsets, n_loads) float
        Loads [W], ascending in each set.
    step_hours : float
        Step length [h].
    contiguous : bool
        Whether to track the longest contiguous interval too.
    load_shape : (n_rows, n_steps) float
        With ``use_shape``, each row's load profile [W] (one row (1, 1) without).
    use_shape : bool
    t_out, cont_out, energy_out, peak_out : outputs as :func:`fold_rows`'s, with one connection.
    above, whole, run : per-chunk scratch from :func:`scratch`.
    """
    n_rows = power.shape[0]
    n_chunks = above.shape[0]
    per_chunk = (n_rows + n_chunks - 1) // n_chunks
    for k in prange(n_chunks):
        for r in range(k * per_chunk, min((k + 1) * per_chunk, n_rows)):
            energy_out[r, 0], peak_out[r, 0] = _metrics(
                power[r], 0, power.shape[1] - 1, step_hours, loads[row_loadset[r]], contiguous, above[k], whole[k],
                run[k], t_out[r, 0], cont_out[r if contiguous else 0, 0], load_shape[r if use_shape else 0],
                use_shape)


def scratch(n_rows, n_conn, n_loads, n_steps, contiguous):
    """Outputs and per-chunk scratch of :func:`fold_rows` or :func:`curve_rows`, allocated here,
    outside the parallel loop.

    Parameters
    ----------
    n_rows, n_conn, n_loads : int
        Rows, connections and loads per set.
    n_steps : int
        Steps per day for :func:`fold_rows`; 0 for :func:`curve_rows`.
    contiguous : bool
        Whether the longest contiguous interval is tracked.

    Returns
    -------
    dict of numpy.ndarray
        The keyword arguments ``t_out`` ... ``run`` of the kernel.
    """
    chunks = max(1, min(n_rows, get_num_threads() * CHUNKS_PER_THREAD))
    shape = (n_rows, n_conn)
    work = {
        "t_out": np.empty(shape + (n_loads,)),
        "cont_out": np.zeros(shape + (n_loads,)) if contiguous else np.zeros((1, n_conn, n_loads)),
        "energy_out": np.empty(shape),
        "peak_out": np.empty(shape),
        "above": np.zeros((chunks, n_loads)),
        "whole": np.zeros((chunks, n_loads + 1)),
        "run": np.zeros((chunks, n_loads if contiguous else 1, 2)),
    }
    if n_steps:
        work["irradiation_out"] = np.empty(n_rows)
        work["irradiance"] = np.zeros((chunks, 2, n_steps))
        work["buffer"] = np.zeros((chunks, n_conn, n_steps))
    return work
