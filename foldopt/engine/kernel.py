"""Compiled loops of the engine (numba): sun to t_solar per row, with no (rows x steps) arrays.

A *row* is one block (a day at a site, see :class:`foldopt.engine.sky.Sky`) seen by one orientation of
the two sub-panels (a fold angle). :func:`fold_rows` takes each row in three loops over its lit
steps. In the first (:func:`foldopt.engine.incidence.incidence`), both sub-panel normals against the sun vector give the
beam's incidence (or Shin et al.'s Eq. 5 in paper mode), and the beam with the optional
incidence-angle modifier and the diffuse terms give each sub-panel's plane-of-array irradiance.
The second looks up the electrical tables (or, for the ideal model, scales the irradiance) and
writes every asked connection's power to a buffer of one day, reused by the next row (with the
circuit as built, :func:`_built_row`). The third reduces each power curve to the daily metrics of
every load at once (:func:`foldopt.engine.reduce.day_metrics`, with the per-chunk scratch of
:func:`foldopt.engine.reduce.scratch`).

Where the time goes: a loop vectorises only if LLVM can see that no index wraps around (the steps
are indexed as unsigned integers) and that nothing in it depends on a setting known only at run
time. So the loops are written once and inlined once per case, each case's settings passed as
constants (the incidence per mode, diffuse terms and modifier; the ideal model's power per
connection; the metrics per flag); the parallel loop hands each thread a chunk of rows
(:func:`_chunk_rows`) whose scratch is taken once, and a row's work is inlined into that chunk's
loop, not called. On a map's year (the ideal model, 10 loads) a row step cost about 5 ns on one
core on a fast day, against 21 ns before (the kernel's share of ``bench/map.py --w5 --phases``);
8.8 ns on the slower machine of 2026-12-03, of which some 5.9 ns the walk over the loads.

Every function here is checked against the NumPy reference path of :mod:`foldopt.engine.rows` by
``tests/test_engine.py`` (hypothesis: random sites, days, loads, angles and models).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange, uint64

from foldopt.engine.incidence import incidence, steps_sum
from foldopt.engine.reduce import day_metrics

# Connection codes; the order of foldopt.physics.connections.CONNECTIONS, plus the whole (unfolded) panel.
EAST, WEST, PARALLEL, SERIES, INDEPENDENT, SWITCHING, PANEL = range(7)
ZETA_MAX = 4.0  # top of a converter's table in input / rating (foldopt.physics.converter)


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


@njit(cache=True, inline="always")
def _built_parts(root_east, root_west, table_1d, table_alone, table_panel, table_parallel, table_series,
                 table_switching, need_series, direct, switch_table):
    """The parts of the circuit as built from one table set at both sub-panels' irradiance (as
    sqrt(E / E_max)): each sub-panel's maximum power, what it delivers alone, the pair in parallel,
    in series and switched (each as built, before the converter) and the whole panel's power [W].
    The pair tables are fractions of the two maximum powers; without a switch resistance
    (``switch_table`` False) switching is the best of its states."""
    n1 = table_1d.shape[0] - 1
    n2, nr = table_parallel.shape[0] - 1, table_parallel.shape[1] - 1
    m_east = _linear(table_1d, root_east * n1)
    m_west = _linear(table_1d, root_west * n1)
    bound = m_east + m_west
    a_east, a_west, p_panel = m_east, m_west, 0.0
    if direct:
        a_east = _linear(table_alone, root_east * n1)
        a_west = _linear(table_alone, root_west * n1)
        p_panel = _linear(table_panel, root_east * n1)
    strong, weak = max(root_east, root_west), min(root_east, root_west)
    root_ratio = weak / strong if strong > 0.0 else 1.0
    p_parallel = min(max(_bilinear(table_parallel, strong * n2, root_ratio * nr), 0.0), 1.0) * bound
    p_series = 0.0
    if need_series:
        p_series = min(max(_bilinear(table_series, strong * n2, root_ratio**2 * nr), 0.0), 1.0) * bound
    if switch_table:
        p_switching = min(max(_bilinear(table_switching, strong * n2, root_ratio * nr), 0.0), 1.0) * bound
    else:
        p_switching = max(max(a_east, a_west), p_parallel)
    return m_east, m_west, a_east, a_west, p_parallel, p_series, p_switching, p_panel


@njit(cache=True, inline="always")
def _delivered(power, conv_table, conv_rated):
    """What a converter of rating ``conv_rated`` [W] delivers of ``power`` [W], from its table of
    delivered power / rating on nodes uniform in sqrt(input / rating / ZETA_MAX)
    (:func:`foldopt.physics.converter.table_delivered`); ``conv_rated`` 0: an ideal converter."""
    if conv_rated <= 0.0:
        return power
    zeta = min(max(power / conv_rated, 0.0), ZETA_MAX)
    return conv_rated * _linear(conv_table, math.sqrt(zeta / ZETA_MAX) * (conv_table.shape[0] - 1))


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


@njit(cache=True, inline="always")
def _linear_steps(c, code, start, count, linear_power, panel_scale, converter_efficiency, irradiance, buffer):
    """:func:`_linear_connections`' loop, inlined once per connection with its code a constant."""
    for i in range(count):
        s = start + i
        p_east, p_west = linear_power * irradiance[0, s], linear_power * irradiance[1, s]
        if code == SWITCHING:
            # The pairs lose nothing: the parallel (and series) pair's power is the sum.
            buffer[c, s] = max(max(p_east, p_west), p_east + p_west)
        elif code == EAST:
            buffer[c, s] = p_east
        elif code == WEST:
            buffer[c, s] = p_west
        elif code == INDEPENDENT:
            buffer[c, s] = converter_efficiency * (p_east + p_west)
        elif code == PANEL:
            buffer[c, s] = panel_scale * p_east
        else:
            buffer[c, s] = p_east + p_west


@njit(cache=True, inline="always")
def _linear_connections(first, n, linear_power, panel_scale, converter_efficiency, connections, irradiance, buffer):
    """Every asked connection's power [W] of the ideal PV model (power proportional to
    irradiance, so that the pairs lose nothing) into ``buffer[c]`` at steps ``first ..
    first + n - 1``: one loop a connection, free of branches, so that each vectorises (the values
    are :func:`_connection_power`'s)."""
    start, count = uint64(first), uint64(n)
    for c in range(connections.shape[0]):
        # Switching (every map's) with its code a constant; the others read it at run time.
        if connections[c] == SWITCHING:
            _linear_steps(c, SWITCHING, start, count, linear_power, panel_scale, converter_efficiency, irradiance,
                          buffer)
        else:
            _linear_steps(c, connections[c], start, count, linear_power, panel_scale, converter_efficiency,
                          irradiance, buffer)


@njit(cache=True, inline="always")
def _table_row(b, first, last, step_table, step_weight, table_1d, table_parallel, table_series, need_series, bypass,
               panel_scale, converter_efficiency, switch_series, connections, irradiance, buffer):
    """Every asked connection's power [W] at steps ``first..last`` from the electrical tables at both
    sub-panels' irradiance (as sqrt(E / E_max), ``irradiance[0]`` and ``[1]``): table set
    ``step_table[b, s]`` and, with weight ``step_weight[b, s]``, the next (both (n_blocks, n_steps)),
    or one set a block ((n_blocks, 1))."""
    per_step = step_table.shape[1] > 1
    # One table set a block (no weather file): its tables are taken once a row.
    row_1d, row_parallel, row_series = (table_1d[step_table[b, 0]], table_parallel[step_table[b, 0]],
                                        table_series[step_table[b, 0]])
    for s in range(first, last + 1):
        root_east, root_west = irradiance[0, s], irradiance[1, s]
        if not per_step:
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
        for c in range(connections.shape[0]):
            buffer[c, s] = _connection_power(connections[c], p_east, p_west, p_parallel, p_series, p_panel,
                                             converter_efficiency, switch_series)


@njit(cache=True, inline="always")
def _built_power(code, m_east, m_west, a_east, a_west, p_parallel, p_series, p_switching, p_panel, switch_series,
                 switch_table, converter_efficiency, conv_table, conv_rated):
    """The power a connection delivers to the load [W] from the parts of :func:`_built_parts`:
    through the converter, or the independent connection's two converters each rated for its
    sub-panel (half the rating)."""
    if code == INDEPENDENT:
        return converter_efficiency * (_delivered(m_east, conv_table, 0.5 * conv_rated)
                                       + _delivered(m_west, conv_table, 0.5 * conv_rated))
    if code == SWITCHING:
        power = max(p_switching, p_series) if switch_series and not switch_table else p_switching
    elif code == EAST:
        power = a_east
    elif code == WEST:
        power = a_west
    elif code == PARALLEL:
        power = p_parallel
    elif code == SERIES:
        power = p_series
    else:
        power = p_panel
    return _delivered(power, conv_table, conv_rated)


@njit(cache=True)
def _built_row(b, first, last, step_table, step_weight, table_1d, table_alone, table_panel, table_parallel,
               table_series, table_switching, need_series, direct, switch_table, linear_power, panel_scale,
               switch_series, converter_efficiency, connections, conv_table, conv_rated, irradiance, buffer):
    """:func:`_chunk_rows`' second loop for the circuit as built: the parts at each step (linear
    between two table sets where the step's air temperature lies between them), then what each
    connection delivers. With the ideal PV model (``linear_power`` > 0, no tables), only the
    converter is as built: ``irradiance`` holds the irradiance itself."""
    per_step = step_table.shape[1] > 1
    parts = np.empty(8)
    for s in range(first, last + 1):
        root_east, root_west = irradiance[0, s], irradiance[1, s]
        t = step_table[b, s] if per_step else step_table[b, 0]
        w = step_weight[b, s] if per_step else 0.0
        if linear_power > 0.0:
            m_east, m_west = linear_power * root_east, linear_power * root_west
            a_east, a_west, p_panel = m_east, m_west, panel_scale * m_east
            p_parallel = p_series = m_east + m_west
            p_switching = max(max(m_east, m_west), p_parallel)
            w = 0.0
        else:
            m_east, m_west, a_east, a_west, p_parallel, p_series, p_switching, p_panel = _built_parts(
                root_east, root_west, table_1d[t], table_alone[t], table_panel[t], table_parallel[t],
                table_series[t], table_switching[t], need_series, direct, switch_table)
        if w > 0.0:
            parts[:] = _built_parts(root_east, root_west, table_1d[t + 1], table_alone[t + 1], table_panel[t + 1],
                                    table_parallel[t + 1], table_series[t + 1], table_switching[t + 1], need_series,
                                    direct, switch_table)
            m_east += w * (parts[0] - m_east)
            m_west += w * (parts[1] - m_west)
            a_east += w * (parts[2] - a_east)
            a_west += w * (parts[3] - a_west)
            p_parallel += w * (parts[4] - p_parallel)
            p_series += w * (parts[5] - p_series)
            p_switching += w * (parts[6] - p_switching)
            p_panel += w * (parts[7] - p_panel)
        if not direct:
            p_panel = panel_scale * m_east
        for c in range(connections.shape[0]):
            buffer[c, s] = _built_power(connections[c], m_east, m_west, a_east, a_west, p_parallel, p_series,
                                        p_switching, p_panel, switch_series, switch_table, converter_efficiency,
                                        conv_table, conv_rated)


@njit(cache=True, parallel=True)
def fold_rows(sun, paper_sun, beam, terms, span, step_table, step_weight, row_block, row_normal, row_paper, row_view,
              row_loadset, paper_incidence, iam_model, iam_params, table_1d, table_parallel, table_series,
              linear_power, panel_scale, bypass, switch_series, converter_efficiency, connections, built, table_alone,
              table_panel, table_switching, conv_table, conv_rated, loads, step_hours, contiguous, load_shape,
              use_shape, t_out, cont_out, energy_out, peak_out, irradiation_out, irradiance, buffer, above, whole,
              run):
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
    row_view : (n_rows, 2, 2) float
        Per sub-panel, the factors of the isotropic and the horizon-band diffuse terms:
        (1 + cos tilt) / 2 and sin tilt, less what the site's horizon hides
        (:func:`foldopt.physics.horizon.sky_view_factors`).
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
    built : (3,) int
        The circuit as built: whether it is (1) or Shin et al.'s ideal parts (0), direct coupling,
        and whether switching has its own table (a switch resistance).
    table_alone, table_panel, table_switching : float arrays
        As built, stacked as the other tables: a sub-panel's and the whole panel's power delivered
        at the load's voltage (direct coupling), and switching as a fraction of the two maxima
        (placeholders where unused).
    conv_table : (n,) float
        The converter's delivered power / rating (:func:`foldopt.physics.converter.delivered_table`).
    conv_rated : float
        The converter's rating [W]; 0 for an ideal converter.
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
        _chunk_rows(k * per_chunk, min((k + 1) * per_chunk, n_rows), sun, paper_sun, beam, terms, span, step_table,
                    step_weight, row_block, row_normal, row_paper, row_view, row_loadset, paper_incidence, iam_model,
                    iam_params, table_1d, table_parallel, table_series, linear_power, panel_scale, bypass,
                    switch_series, converter_efficiency, connections, built, table_alone, table_panel,
                    table_switching, conv_table, conv_rated, loads, step_hours, contiguous, load_shape, use_shape,
                    t_out, cont_out, energy_out, peak_out, irradiation_out, irradiance[k], buffer[k], above[k],
                    whole[k], run[k])


@njit(cache=True)
def _chunk_rows(start, stop, sun, paper_sun, beam, terms, span, step_table, step_weight, row_block, row_normal,
                row_paper, row_view, row_loadset, paper_incidence, iam_model, iam_params, table_1d, table_parallel,
                table_series, linear_power, panel_scale, bypass, switch_series, converter_efficiency, connections,
                built, table_alone, table_panel, table_switching, conv_table, conv_rated, loads, step_hours,
                contiguous, load_shape, use_shape, t_out, cont_out, energy_out, peak_out, irradiation_out, irradiance,
                buffer, above, whole, run):
    """Rows ``start .. stop - 1`` of :func:`fold_rows` with one chunk's scratch: a function of its own
    (the parallel loop's body calls it) so that the row's functions are inlined into it.

    Each row takes three loops over its lit steps. The first (:func:`foldopt.engine.incidence.incidence`)
    gives both sub-panels' irradiance (as sqrt(E / E_max), the tables' coordinate, with tables) and
    their mean incident irradiance before the incidence-angle modifier. The second writes every asked
    connection's power to ``buffer[c, step]``: from the tables (:func:`_table_row`), for the ideal
    model from :func:`_linear_connections`, or with the circuit as built from :func:`_built_row`,
    through :func:`_built_power`. The third reduces each power curve to the daily metrics. The row's
    work is inlined here rather than called: a call with the kernel's some thirty arrays cost about
    190 ns a row, a quarter of a map row's time at 30-min steps (some 12 % at 5-min steps)."""
    n_conn = connections.shape[0]
    tables = linear_power == 0.0
    need_series = switch_series
    for c in range(n_conn):
        need_series = need_series or connections[c] == SERIES
    for r in range(start, stop):
        b = row_block[r]
        first, last = span[b, 0], span[b, 1]
        n = last + 1 - first
        incidence(r, b, first, n, sun, paper_sun, beam, terms, row_normal, row_paper, row_view, paper_incidence,
                  terms.shape[1] == 4, iam_model, iam_params, tables, irradiance)
        irradiation_out[r] = steps_sum(irradiance[2], first, n) * step_hours
        if built[0]:
            _built_row(b, first, last, step_table, step_weight, table_1d, table_alone, table_panel, table_parallel,
                       table_series, table_switching, need_series, built[1] == 1, built[2] == 1, linear_power,
                       panel_scale, switch_series, converter_efficiency, connections, conv_table, conv_rated,
                       irradiance, buffer)
        elif not tables:
            _linear_connections(first, n, linear_power, panel_scale, converter_efficiency, connections, irradiance,
                                buffer)
        else:
            _table_row(b, first, last, step_table, step_weight, table_1d, table_parallel, table_series, need_series,
                       bypass, panel_scale, converter_efficiency, switch_series, connections, irradiance, buffer)
        for c in range(n_conn):
            energy_out[r, c], peak_out[r, c] = day_metrics(
                buffer[c], first, last, step_hours, loads[row_loadset[r]], contiguous, above, whole, run, t_out[r, c],
                cont_out[r if contiguous else 0, c], load_shape[b if use_shape else 0], use_shape)
