"""Compiled loops of the engine (numba): sun to t_solar in one pass per row, no temporaries.

A *row* is one block (a day at a site, see :class:`foldopt.sky.Sky`) seen by one orientation of
the two sub-panels (a fold angle). :func:`fold_rows` walks the row's time steps once: both
sub-panel normals against the sun vector give the beam's incidence (or Shin et al.'s Eq. 5 in
paper mode), the beam with the optional incidence-angle modifier and the diffuse terms give the
plane-of-array irradiance, the electrical tables give every connection's power, and the power
feeds the daily metrics of every load at once. No (rows x steps) array is ever made.
:func:`curve_rows` takes power curves that already exist (a tracker's) through the same metrics.

The metrics are those of :mod:`foldopt.metrics`, which is their reference: power is sampled at
step centres and linear between them (held for half a step at both ends of the day), and a
segment from ``lo`` to ``hi`` of length ``dt`` is above a load ``L`` for
``dt * clip((hi - L) / (hi - lo), 0, 1)``. For many loads sorted ascending, the loads at or below
``lo`` take the whole segment: one entry of a difference array, summed from the top at the end;
only the loads inside the segment's range take a share. The position of the power among the loads
moves by a few loads a step, so it is walked from the previous step instead of searched. A day's
cost is then O(steps + loads x crossings), not O(steps x loads).

Every function here is checked against the NumPy reference path of :mod:`foldopt.engine` by
``tests/test_engine.py`` (hypothesis: random sites, days, loads, angles and models).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

# Connection codes; the order of foldopt.aggregation.CONNECTIONS, plus the whole (unfolded) panel.
EAST, WEST, PARALLEL, SERIES, INDEPENDENT, SWITCHING, PANEL = range(7)
IAM_NONE, IAM_ASHRAE, IAM_PHYSICAL = range(3)
IRRADIANCE_MAX = 1500.0  # [W/m^2], top of the electrical tables (foldopt.electrical)


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


@njit(cache=True)
def iam_factor(cos_aoi, model, params):
    """Incidence-angle modifier of the beam at ``cos(AOI)``: pvlib's ``iam.ashrae`` (``params[0]``
    = b) or ``iam.physical`` without coating (n, K, L), the same arithmetic; 1 for ``IAM_NONE``."""
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
def _segment(loads, start, end, start_at, end_at, length, above, whole, run, contiguous):
    """Add one linear segment of the power curve to every load's time above it.

    ``start_at``/``end_at`` are the loads at or below each end; ``whole[k]`` collects time that
    every load below index k takes whole; ``above`` the shares of loads inside the segment."""
    lo_at, hi_at = min(start_at, end_at), max(start_at, end_at)
    lo, hi = min(start, end), max(start, end)
    if contiguous:
        # A sample below a load ends that load's run: the segment starts a new one.
        for j in range(start_at, loads.shape[0]):
            if run[j, 1] < run[j, 0]:
                run[j, 1] = run[j, 0]
            run[j, 0] = 0.0
        for j in range(lo_at):
            run[j, 0] += length
    whole[lo_at] += length
    for j in range(lo_at, hi_at):
        share = length * (hi - loads[j]) / (hi - lo)
        above[j] += share
        if contiguous:
            run[j, 0] += share


@njit(cache=True, inline="always")
def _finish(loads, last, last_at, half, above, whole, run, contiguous, t_out, cont_out):
    """The held half-step after the last sample, then the loads' totals."""
    _segment(loads, last, last, last_at, last_at, half, above, whole, run, contiguous)
    total = 0.0
    for j in range(loads.shape[0] - 1, -1, -1):
        total += whole[j + 1]
        t_out[j] = above[j] + total
        if contiguous:
            cont_out[j] = max(run[j, 0], run[j, 1])


@njit(cache=True, inline="always")
def _connection_power(code, p_east, p_west, p_parallel, p_series, p_panel, converter_efficiency, switch_series):
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
    if code == PANEL:
        return p_panel
    best = max(max(p_east, p_west), p_parallel)
    if switch_series:
        best = max(best, p_series)
    return best


@njit(cache=True, parallel=True)
def fold_rows(sun, paper_sun, beam, terms, lit, block_table, row_block, row_normal, row_paper, row_loadset,
              paper_incidence, iam_model, iam_params, table_1d, table_parallel, table_series, linear_power,
              panel_scale, bypass, switch_series, converter_efficiency, connections, loads, step_hours,
              contiguous, t_out, cont_out, energy_out, peak_out, whole, above, run, previous, position):
    """Daily metrics of every row and connection, computing the power on the fly.

    Parameters
    ----------
    sun : (n_blocks, n_steps, 3) float
        Unit sun vectors (east, north, up).
    paper_sun : (n_blocks, n_steps, 4) float
        cos(zenith), sin(zenith), sin(azimuth), cos(azimuth) for Eq. 5 (used in paper mode).
    beam : (n_blocks, n_steps) float
        Direct normal irradiance [W/m^2].
    terms : (n_blocks, n_steps, 4) float
        Diffuse terms (isotropic, circumsolar, horizon, ground) of
        :func:`foldopt.irradiance.sky_diffuse_terms`; shape (n_blocks, n_steps, 0) for beam only.
    lit : (n_blocks, n_steps) bool
        Steps with any light (power is zero elsewhere).
    block_table : (n_blocks,) int
        Electrical table of each block (its cells' air temperature).
    row_block, row_loadset : (n_rows,) int
    row_normal : (n_rows, 2, 3) float
        East and west sub-panel normals.
    row_paper : (n_rows, 2, 4) float
        cos(tilt), sin(tilt), cos(azimuth), sin(azimuth) per sub-panel (paper mode).
    table_1d, table_parallel, table_series : float arrays
        Per table: sub-panel power [W] on sqrt-spaced irradiance nodes, and the parallel and
        series pairs as fractions of the two maxima (:class:`foldopt.electrical.Electrical`).
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
    t_out, cont_out : (n_rows, n_conn, n_loads) float
        t_solar and its longest contiguous interval [h] (out).
    energy_out, peak_out : (n_rows, n_conn) float
        Energy [Wh] and peak power [W] (out).
    whole, above, run, previous, position : scratch, zero, allocated outside the parallel loop
        (n_rows, n_conn) + ``(n_loads + 1,)``, ``(n_loads,)``, ``(n_loads, 2)``, ``()``, ``()``
        (int); see :func:`scratch`.
    """
    n_steps = sun.shape[1]
    n_conn = connections.shape[0]
    has_terms = terms.shape[2] == 4
    need_series = switch_series
    for c in range(n_conn):
        if connections[c] == SERIES:
            need_series = True
    n1 = table_1d.shape[1] - 1
    n2 = table_parallel.shape[1] - 1
    nr = table_series.shape[2] - 1
    half = 0.5 * step_hours
    for r in prange(row_block.shape[0]):
        b = row_block[r]
        tab = block_table[b]
        ld = loads[row_loadset[r]]
        ex, ey, ez = row_normal[r, 0, 0], row_normal[r, 0, 1], row_normal[r, 0, 2]
        wx, wy, wz = row_normal[r, 1, 0], row_normal[r, 1, 1], row_normal[r, 1, 2]
        e_sin_tilt = math.sqrt(max(1.0 - ez * ez, 0.0))
        w_sin_tilt = math.sqrt(max(1.0 - wz * wz, 0.0))
        for s in range(n_steps):
            p_east = p_west = p_parallel = p_series = p_panel = 0.0
            if lit[b, s]:
                sx, sy, sz = sun[b, s, 0], sun[b, s, 1], sun[b, s, 2]
                cos_east = ex * sx + ey * sy + ez * sz
                cos_west = wx * sx + wy * sy + wz * sz
                if paper_incidence:
                    cz, sz_, sa, ca = paper_sun[b, s, 0], paper_sun[b, s, 1], paper_sun[b, s, 2], paper_sun[b, s, 3]
                    f_east = (max(cz * row_paper[r, 0, 0] + sz_ * row_paper[r, 0, 1], 0.0)
                              * max(ca * row_paper[r, 0, 2] + sa * row_paper[r, 0, 3], 0.0))
                    f_west = (max(cz * row_paper[r, 1, 0] + sz_ * row_paper[r, 1, 1], 0.0)
                              * max(ca * row_paper[r, 1, 2] + sa * row_paper[r, 1, 3], 0.0))
                else:
                    f_east, f_west = max(cos_east, 0.0), max(cos_west, 0.0)
                g_east = beam[b, s] * f_east * iam_factor(cos_east, iam_model, iam_params)
                g_west = beam[b, s] * f_west * iam_factor(cos_west, iam_model, iam_params)
                if has_terms:
                    iso, circ, hor, ground = terms[b, s, 0], terms[b, s, 1], terms[b, s, 2], terms[b, s, 3]
                    g_east += (max(iso * (1.0 + ez) * 0.5 + circ * max(cos_east, 0.0) + hor * e_sin_tilt, 0.0)
                               + ground * (1.0 - ez) * 0.5)
                    g_west += (max(iso * (1.0 + wz) * 0.5 + circ * max(cos_west, 0.0) + hor * w_sin_tilt, 0.0)
                               + ground * (1.0 - wz) * 0.5)
                if linear_power > 0.0:
                    p_east, p_west = linear_power * g_east, linear_power * g_west
                    p_parallel = p_series = p_east + p_west
                    p_panel = panel_scale * p_east
                else:
                    e_east = min(max(g_east, 0.0), IRRADIANCE_MAX)
                    e_west = min(max(g_west, 0.0), IRRADIANCE_MAX)
                    root_east = math.sqrt(e_east / IRRADIANCE_MAX)
                    root_west = math.sqrt(e_west / IRRADIANCE_MAX)
                    p_east = _linear(table_1d[tab], root_east * n1)
                    p_west = _linear(table_1d[tab], root_west * n1)
                    p_panel = panel_scale * p_east
                    bound = p_east + p_west
                    if e_east == e_west:
                        # Identical sub-panels at equal irradiance deliver exactly their sum.
                        p_parallel = p_series = bound
                    else:
                        fraction = _bilinear(table_parallel[tab], root_east * n2, root_west * n2)
                        p_parallel = min(max(fraction, 0.0), 1.0) * bound
                        if need_series:
                            strong = max(e_east, e_west)
                            ratio = min(e_east, e_west) / strong
                            fraction = _bilinear(table_series[tab], max(root_east, root_west) * n2, ratio * nr)
                            p_series = min(max(fraction, 0.0), 1.0) * bound
                    if bypass:
                        p_series = max(p_series, max(p_east, p_west))
            for c in range(n_conn):
                power = _connection_power(connections[c], p_east, p_west, p_parallel, p_series, p_panel,
                                          converter_efficiency, switch_series)
                energy_out[r, c] += power
                if power > peak_out[r, c]:
                    peak_out[r, c] = power
                at = _walk(ld, position[r, c], power)
                if s == 0:
                    _segment(ld, power, power, at, at, half, above[r, c], whole[r, c], run[r, c], contiguous)
                else:
                    _segment(ld, previous[r, c], power, position[r, c], at, step_hours, above[r, c], whole[r, c],
                             run[r, c], contiguous)
                previous[r, c], position[r, c] = power, at
        for c in range(n_conn):
            energy_out[r, c] *= step_hours
            _finish(ld, previous[r, c], position[r, c], half, above[r, c], whole[r, c], run[r, c], contiguous,
                    t_out[r, c], cont_out[r, c])


@njit(cache=True, parallel=True)
def curve_rows(power, row_loadset, loads, step_hours, contiguous, t_out, cont_out, energy_out, peak_out,
               whole, above, run, previous, position):
    """Daily metrics of given power curves, ``power`` (n_rows, n_steps) [W]; outputs and scratch as
    :func:`fold_rows` with one connection."""
    n_steps = power.shape[1]
    half = 0.5 * step_hours
    for r in prange(power.shape[0]):
        ld = loads[row_loadset[r]]
        for s in range(n_steps):
            p = power[r, s]
            energy_out[r, 0] += p
            if p > peak_out[r, 0]:
                peak_out[r, 0] = p
            at = _walk(ld, position[r, 0], p)
            if s == 0:
                _segment(ld, p, p, at, at, half, above[r, 0], whole[r, 0], run[r, 0], contiguous)
            else:
                _segment(ld, previous[r, 0], p, position[r, 0], at, step_hours, above[r, 0], whole[r, 0], run[r, 0],
                         contiguous)
            previous[r, 0], position[r, 0] = p, at
        energy_out[r, 0] *= step_hours
        _finish(ld, previous[r, 0], position[r, 0], half, above[r, 0], whole[r, 0], run[r, 0], contiguous, t_out[r, 0],
                cont_out[r, 0])


def scratch(n_rows, n_conn, n_loads, contiguous):
    """Zeroed outputs and scratch of :func:`fold_rows` / :func:`curve_rows`, made outside the
    parallel loop (arrays zero-filled inside a numba prange body have given wrong sums)."""
    shape = (n_rows, n_conn)
    runs = shape + (n_loads, 2) if contiguous else (n_rows, n_conn, 1, 2)
    return {
        "t_out": np.zeros(shape + (n_loads,)),
        "cont_out": np.zeros(shape + (n_loads,)),
        "energy_out": np.zeros(shape),
        "peak_out": np.full(shape, -np.inf),
        "whole": np.zeros(shape + (n_loads + 1,)),
        "above": np.zeros(shape + (n_loads,)),
        "run": np.zeros(runs),
        "previous": np.zeros(shape),
        "position": np.zeros(shape, dtype=np.int64),
    }
