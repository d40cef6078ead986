"""Compiled loops of the engine (numba): sun to t_solar per row, with no (rows x steps) arrays.

A *row* is one block (a day at a site, see :class:`foldopt.engine.sky.Sky`) seen by one orientation of
the two sub-panels (a fold angle). :func:`fold_rows` takes each row in three loops over its lit
steps. In the first (:func:`foldopt.engine.incidence.incidence`), both sub-panel normals against the sun vector give the
beam's incidence (or Shin et al.'s Eq. 5 in paper mode), and the beam with the optional
incidence-angle modifier and the diffuse terms give each sub-panel's plane-of-array irradiance.
The second looks up the electrical tables (or, for a model without I-V curve, takes its power
as a polynomial of the irradiance, :func:`_powers_of_irradiance`) and
writes every asked connection's power to a buffer of one day, reused by the next row (with the
circuit as built, :func:`_built_row`; switching alone from one table set a block, the common case,
in two loops of its own, :func:`_switching_row`). The third reduces each power curve to the daily
metrics of every load at once (:func:`foldopt.engine.curve_reduction.day_metrics`; after
:func:`_switching_row`, :func:`foldopt.engine.curve_reduction.blocked_day`, which skips the blocks
of steps that cross no load). The inputs come as the named records of
:mod:`foldopt.engine.records` (the sky, the rows, the tables, the loads, the outputs and the
per-chunk scratch of :func:`foldopt.engine.records.allocate`).

Where the time goes: a loop vectorises only if LLVM can see that no index wraps around (the steps
are indexed as unsigned integers) and that nothing in it depends on a setting known only at run
time. So the loops are written once and inlined once per case, each case's settings passed as
constants (the incidence per mode, diffuse terms and modifier; the power of a model without
I-V curve per connection; the metrics per flag); the parallel loop hands each thread a chunk of
rows whose scratch is taken once, and a row's work is inlined into that chunk's loop, not called
(a call costs some 6 ns an array it is handed: a map's row 10-25 % more), but for the power of the
cases that are neither the common one (:func:`_chunk_switching`) nor a map's: the tables' rows
(:func:`_table_row`, a weather year's), switching's off the common case (:func:`_switching_call`)
and the circuit as built (:func:`_built_row`) are each called, compiled apart, so that numba does
not type, lower and LLVM does not optimise them as one function several times their size (the
compile grows faster than the code). The small functions of a step (a table's look-up, a
connection's power, a converter's) are called, not inlined by numba: numba compiles each once
and LLVM inlines it where it is used, the same code at a fraction of the compile; the few that
LLVM would leave as calls in a loop over the steps (:func:`_pair_powers`, :func:`_built_parts`)
numba inlines. The chunk's loops, and the functions they call rather than inline, are compiled
without numba's reference counting (``_nrt=False``): they allocate nothing, every array they see is
the caller's and lives through the call, and numba would otherwise count each array handed to an
inlined function, or each view taken (``power[0]``, ``t_solar[r, 0]``), and release it at every
row, an atomic operation each, which its pruning of the counts does not remove from loops this
large. The functions only compiled code calls are compiled without the wrappers that would make
them callable from Python and as first-class functions (``no_cpython_wrapper``,
``no_cfunc_wrapper``; the chunk loops, which Python calls, without the latter): numba lowers each
wrapper and LLVM optimises it at every compile, and again in each caller that links the function
in, for code the kernel never runs (a wrapper that takes records unpacks each of their arrays).
The chunk's loop takes the records' arrays once, into tuples of the arrays each function
reads (:func:`foldopt.engine.incidence.row_arrays`). The common case (switching alone from one table
set a block, the exact incidence without the modifier, constant loads) has a chunk's loop of its
own, :func:`_chunk_switching`, chosen before numba sees the call, so that a request compiles only
the loop it runs. (What each choice was worth: ``docs/performance.rst``.)

Every function here is checked against the NumPy reference path of :mod:`foldopt.engine.evaluation` by
``tests/test_engine.py`` (hypothesis: random sites, days, loads, angles and models).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from numba import njit, uint64

from foldopt.engine.incidence import IAM_NONE, incidence, incidence_steps, row_arrays, steps_sum
from foldopt.engine.curve_reduction import blocked_day, day_metrics
from foldopt.engine.records import WALK_BLOCK, in_chunks

# Connection codes; the order of foldopt.physics.connections.CONNECTIONS, plus the whole (unfolded) panel.
EAST, WEST, PARALLEL, SERIES, INDEPENDENT, SWITCHING, PANEL = range(7)
ZETA_MAX = 4.0  # top of a converter's table in input / rating (foldopt.physics.converter)


@njit(cache=True, _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _linear(values, position):
    """``values`` linear between nodes at ``position`` >= 0 [nodes]. The index is unsigned: no
    index can wrap around, so the compiled look-up tests no sign."""
    index = min(uint64(position), uint64(values.shape[0] - 2))
    weight = position - index
    return values[index] * (1.0 - weight) + values[index + uint64(1)] * weight


@njit(cache=True, _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _bilinear(values, first, second):
    """``values`` bilinear between nodes at ``first``, ``second`` >= 0 [nodes] (unsigned indices,
    as :func:`_linear`'s)."""
    i = min(uint64(first), uint64(values.shape[0] - 2))
    j = min(uint64(second), uint64(values.shape[1] - 2))
    fi, fj = first - i, second - j
    one = uint64(1)
    return (values[i, j] * (1.0 - fj) + values[i, j + one] * fj) * (1.0 - fi) + (
        values[i + one, j] * (1.0 - fj) + values[i + one, j + one] * fj
    ) * fi


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


class Parts(NamedTuple):
    """The parts of the circuit as built at one step [W] (:func:`_built_parts`)."""

    m_east: float  # each sub-panel's maximum power
    m_west: float
    a_east: float  # what each delivers alone
    a_west: float
    parallel: float  # the pairs and switching as built, before the converter
    series: float
    switching: float
    panel: float  # the whole panel


@njit(cache=True, inline="always")
def _built_parts(root_east, root_west, tables, t, need_series):
    """The :class:`Parts` of the circuit as built from table set ``t`` of ``tables`` at both
    sub-panels' irradiance (as sqrt(E / E_max)). The pair tables are fractions of the two maximum
    powers; without a switch resistance (``tables.switch_table`` False) switching is the best of
    its states."""
    table_1d, table_parallel = tables.subpanel[t], tables.parallel[t]
    n1 = table_1d.shape[0] - 1
    n2, nr = table_parallel.shape[0] - 1, table_parallel.shape[1] - 1
    m_east = _linear(table_1d, root_east * n1)
    m_west = _linear(table_1d, root_west * n1)
    bound = m_east + m_west
    a_east, a_west, p_panel = m_east, m_west, 0.0
    if tables.direct:
        a_east = _linear(tables.alone[t], root_east * n1)
        a_west = _linear(tables.alone[t], root_west * n1)
        p_panel = _linear(tables.panel[t], root_east * n1)
    strong, weak = max(root_east, root_west), min(root_east, root_west)
    root_ratio = weak / strong if strong > 0.0 else 1.0
    p_parallel = min(max(_bilinear(table_parallel, strong * n2, root_ratio * nr), 0.0), 1.0) * bound
    p_series = 0.0
    if need_series:
        p_series = (
            min(max(_bilinear(tables.series[t], strong * n2, root_ratio**2 * nr), 0.0), 1.0) * bound
        )
    if tables.switch_table:
        p_switching = (
            min(max(_bilinear(tables.switching[t], strong * n2, root_ratio * nr), 0.0), 1.0) * bound
        )
    else:
        p_switching = max(max(a_east, a_west), p_parallel)
    return Parts(m_east, m_west, a_east, a_west, p_parallel, p_series, p_switching, p_panel)


@njit(cache=True, _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _between(lo, hi, w):
    """:class:`Parts` at ``w`` of the way from ``lo`` to ``hi``."""
    return Parts(
        lo.m_east + w * (hi.m_east - lo.m_east),
        lo.m_west + w * (hi.m_west - lo.m_west),
        lo.a_east + w * (hi.a_east - lo.a_east),
        lo.a_west + w * (hi.a_west - lo.a_west),
        lo.parallel + w * (hi.parallel - lo.parallel),
        lo.series + w * (hi.series - lo.series),
        lo.switching + w * (hi.switching - lo.switching),
        lo.panel + w * (hi.panel - lo.panel),
    )


@njit(cache=True, _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _delivered(power, conv_table, conv_rated):
    """What a converter of rating ``conv_rated`` [W] delivers of ``power`` [W], from its table of
    delivered power / rating on nodes uniform in sqrt(input / rating / ZETA_MAX)
    (:func:`foldopt.physics.converter.table_delivered`); ``conv_rated`` 0: an ideal converter."""
    if conv_rated <= 0.0:
        return power
    zeta = min(max(power / conv_rated, 0.0), ZETA_MAX)
    return conv_rated * _linear(conv_table, math.sqrt(zeta / ZETA_MAX) * (conv_table.shape[0] - 1))


@njit(cache=True, _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _connection_power(
    code, p_east, p_west, p_parallel, p_series, p_panel, converter_efficiency, switch_series
):
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
def _powers_of_irradiance(b, start, count, sets, terms, east, west):
    """Each sub-panel's power [W] in place of its irradiance in ``east`` and ``west`` at steps
    ``start .. start + count - 1`` of block ``b``, for a model without I-V curve: ``(a + q E) E``
    of the table set's terms ``power_terms[t] = (a, q)``
    (:meth:`foldopt.physics.pvmodel.PVModel.power_terms`), linear between two sets where a step's
    air temperature lies between them (the power is linear in the air temperature). ``sets``:
    the sky's ``step_table`` and ``step_weight``; ``terms``: the tables' ``power_terms``."""
    step_table, step_weight = sets
    if step_table.shape[1] == 1:
        t = step_table[b, 0]
        a, q = terms[t, 0], terms[t, 1]
        for i in range(count):
            s = start + i
            east[s] = (a + q * east[s]) * east[s]
            west[s] = (a + q * west[s]) * west[s]
        return
    for i in range(count):
        s = start + i
        t, w = step_table[b, s], step_weight[b, s]
        a = terms[t, 0] + w * (terms[t + 1, 0] - terms[t, 0])
        q = terms[t, 1] + w * (terms[t + 1, 1] - terms[t, 1])
        east[s] = (a + q * east[s]) * east[s]
        west[s] = (a + q * west[s]) * west[s]


@njit(cache=True, inline="always")
def _linear_steps(c, code, start, count, scales, east, west, buffer):
    """:func:`_linear_connections`' loop, inlined once per connection with its code a constant
    (``scales``: the tables' ``panel_scale`` and ``converter_efficiency``)."""
    panel_scale, converter_efficiency = scales
    for i in range(count):
        s = start + i
        p_east, p_west = east[s], west[s]
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
def _linear_connections(b, first, n, sets, terms, connections, scales, curves):
    """Every asked connection's power [W] of a PV model without I-V curve (the ideal model's and
    PVWatts': the pairs lose nothing) into ``power[c]`` at steps ``first .. first + n - 1`` of
    block ``b`` from each sub-panel's irradiance (``curves``: east, west, power): each
    sub-panel's power (:func:`_powers_of_irradiance`, ``sets`` and ``terms``), then one loop a
    connection (``connections``; ``scales``: :func:`_linear_steps`'), free of branches, so that
    each vectorises (the values are :func:`_connection_power`'s)."""
    east, west, buffer = curves
    start, count = uint64(first), uint64(n)
    _powers_of_irradiance(b, start, count, sets, terms, east, west)
    for c in range(connections.shape[0]):
        # Switching (every map's) with its code a constant; the others read it at run time.
        if connections[c] == SWITCHING:
            _linear_steps(c, SWITCHING, start, count, scales, east, west, buffer)
        else:
            _linear_steps(c, connections[c], start, count, scales, east, west, buffer)


@njit(cache=True, _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _table_row(b, first, last, sets, pair_tables, connections, settings, curves):
    """Every asked connection's power [W] at steps ``first..last`` into ``power`` from the
    electrical tables (``pair_tables``: the tables' subpanel, parallel and series) at both
    sub-panels' irradiance (as sqrt(E / E_max), ``east`` and ``west``; ``curves``: east, west,
    power): table set ``step_table[b, s]`` and, with weight ``step_weight[b, s]``, the next (both
    (n_blocks, n_steps)), or one set a block ((n_blocks, 1)) (``sets``: the sky's step_table and
    step_weight). ``settings``: the tables' bypass, panel_scale, switch_series and
    converter_efficiency, and whether the series pair is asked."""
    step_table, step_weight = sets
    table_1d, table_parallel, table_series = pair_tables
    bypass, panel_scale, switch_series, converter_efficiency, need_series = settings
    east, west, buffer = curves
    per_step = step_table.shape[1] > 1
    # One table set a block (no weather file): its tables are taken once a row.
    row_1d, row_parallel, row_series = (
        table_1d[step_table[b, 0]],
        table_parallel[step_table[b, 0]],
        table_series[step_table[b, 0]],
    )
    for s in range(first, last + 1):
        root_east, root_west = east[s], west[s]
        if not per_step:
            p_east, p_west, p_parallel, p_series = _pair_powers(
                root_east, root_west, row_1d, row_parallel, row_series, need_series, bypass
            )
        else:
            t, w = step_table[b, s], step_weight[b, s]
            p_east, p_west, p_parallel, p_series = _pair_powers(
                root_east,
                root_west,
                table_1d[t],
                table_parallel[t],
                table_series[t],
                need_series,
                bypass,
            )
            if w > 0.0:
                # The step's cells lie between two tables' air temperatures: linear between them.
                q_east, q_west, q_parallel, q_series = _pair_powers(
                    root_east,
                    root_west,
                    table_1d[t + 1],
                    table_parallel[t + 1],
                    table_series[t + 1],
                    need_series,
                    bypass,
                )
                p_east += w * (q_east - p_east)
                p_west += w * (q_west - p_west)
                p_parallel += w * (q_parallel - p_parallel)
                p_series += w * (q_series - p_series)
        p_panel = panel_scale * p_east
        for c in range(connections.shape[0]):
            buffer[c, s] = _connection_power(
                connections[c],
                p_east,
                p_west,
                p_parallel,
                p_series,
                p_panel,
                converter_efficiency,
                switch_series,
            )


@njit(cache=True, inline="always")
def _switching_power(i, table_1d, pair, stride, nodes, weights):
    """Switching's power [W] at the ``i``-th step of a block of :func:`_switching_row`, from its
    coordinates in the tables (``nodes`` and ``weights``)."""
    one = uint64(1)
    node_east, node_west, node_pair = nodes[0, i], nodes[1, i], nodes[2, i]
    w_east, w_west, fi, fj = weights[0, i], weights[1, i], weights[2, i], weights[3, i]
    p_east = table_1d[node_east] * (1.0 - w_east) + table_1d[node_east + one] * w_east
    p_west = table_1d[node_west] * (1.0 - w_west) + table_1d[node_west + one] * w_west
    best = max(p_east, p_west)
    if min(p_east, p_west) == 0.0 and best >= 0.0:
        # One sub-panel gives nothing (the sun behind it): the pair's sum is then ``best``, a
        # fraction of it in [0, 1] rounds to no more than ``best``, and the maximum below keeps
        # ``best`` on a tie (or a NaN), whatever the pair table holds: its look-up is skipped.
        return best
    fraction = (pair[node_pair] * (1.0 - fj) + pair[node_pair + one] * fj) * (1.0 - fi) + (
        pair[node_pair + stride] * (1.0 - fj) + pair[node_pair + stride + one] * fj
    ) * fi
    p_parallel = min(max(fraction, 0.0), 1.0) * (p_east + p_west)
    return max(best, p_parallel)


@njit(cache=True, inline="always")
def _switching_row(b, first, n, step_table, pair_tables, curves, coordinates):
    """Switching's power [W] at steps ``first .. first + n - 1`` into ``power[0]`` from one table
    set a block (``step_table[b, 0]`` of ``pair_tables``, the tables' subpanel and parallel
    first), without the series pair (every clear-sky study's and map's): the values
    of :func:`_pair_powers` and :func:`_connection_power` by the same operations, so the same
    bits (where one sub-panel gives nothing, without the pair's look-up, which cannot change
    them: :func:`_switching_power`). Returns the sum of the steps' power [W] and its peak [W],
    the bits of :func:`day_metrics`' (the same operations in the same order), and writes each
    walking block's lowest and highest power to ``low`` and ``high``
    (:func:`foldopt.engine.curve_reduction.blocked_day`). ``curves``: a chunk's east, west and
    power; ``coordinates``: its nodes, weights, low and high
    (:class:`foldopt.engine.records.Scratch`).

    :data:`foldopt.engine.records.TABLE_BLOCK` steps at a time, in two loops: the first works out
    each step's coordinates in the tables (its nodes and the weights between them, the pair's
    ratio a division) and vectorises; the second looks them up a value at a time (LLVM prices a
    gather on this CPU above the loads it replaces) with the sums that wait on each addition
    beside them, where they cost nothing more."""
    table = step_table[b, 0]
    table_1d, table_pair = pair_tables[0][table], pair_tables[1][table]
    pair = table_pair.reshape(table_pair.size)
    n1 = table_1d.shape[0] - 1
    n2, nr = table_pair.shape[0] - 1, table_pair.shape[1] - 1
    top_1d, top_strong, top_ratio = uint64(n1 - 1), uint64(n2 - 1), uint64(nr - 1)
    stride = uint64(nr + 1)
    east, west, buffer = curves
    nodes, weights, low, high = coordinates
    block, end, walk = uint64(nodes.shape[1]), uint64(first + n), uint64(WALK_BLOCK)
    start = uint64(first)
    # -0.0 adds nothing to any value, so the sum is the first step's power plus the others'.
    harvested, peak = -0.0, 0.0
    for begin in range(start, end, block):
        count = min(block, end - begin)
        for i in range(count):
            root_east, root_west = east[begin + i], west[begin + i]
            at_east, at_west = root_east * n1, root_west * n1
            node_east, node_west = min(uint64(at_east), top_1d), min(uint64(at_west), top_1d)
            strong, weak = max(root_east, root_west), min(root_east, root_west)
            root_ratio = weak / strong if strong > 0.0 else 1.0
            at_strong, at_ratio = strong * n2, root_ratio * nr
            node_strong = min(uint64(at_strong), top_strong)
            node_ratio = min(uint64(at_ratio), top_ratio)
            nodes[0, i], nodes[1, i] = node_east, node_west
            nodes[2, i] = node_strong * stride + node_ratio
            weights[0, i], weights[1, i] = at_east - node_east, at_west - node_west
            weights[2, i], weights[3, i] = at_strong - node_strong, at_ratio - node_ratio
        if begin == start:
            peak = _switching_power(0, table_1d, pair, stride, nodes, weights)
        for part in range(uint64(0), count, walk):
            lowest, highest = math.inf, -math.inf
            for i in range(part, min(part + walk, count)):
                power = _switching_power(i, table_1d, pair, stride, nodes, weights)
                buffer[0, begin + i] = power
                lowest, highest = min(lowest, power), max(highest, power)
                harvested += power
            # The day's peak from each walking block's highest: the same maximum.
            peak = max(peak, highest)
            low[(begin - start + part) // walk] = lowest
            high[(begin - start + part) // walk] = highest
    return harvested, peak


@njit(cache=True, _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _switching_call(b, first, n, step_table, pair_tables, curves, coordinates):
    """:func:`_switching_row` called rather than inlined, for :func:`_chunk_rows`, whose rows
    take it only off the common case (:func:`_chunk_switching` inlines it)."""
    return _switching_row(b, first, n, step_table, pair_tables, curves, coordinates)


@njit(cache=True, _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _built_power(code, parts, p_panel, tables):
    """The power a connection delivers to the load [W] from the :class:`Parts` of
    :func:`_built_parts` (and the whole panel's ``p_panel``): through the converter, or the
    independent connection's two converters each rated for its sub-panel (half the rating)."""
    conv_table, conv_rated = tables.converter, tables.converter_rating
    if code == INDEPENDENT:
        return tables.converter_efficiency * (
            _delivered(parts.m_east, conv_table, 0.5 * conv_rated)
            + _delivered(parts.m_west, conv_table, 0.5 * conv_rated)
        )
    if code == SWITCHING:
        power = (
            max(parts.switching, parts.series)
            if tables.switch_series and not tables.switch_table
            else parts.switching
        )
    elif code == EAST:
        power = parts.a_east
    elif code == WEST:
        power = parts.a_west
    elif code == PARALLEL:
        power = parts.parallel
    elif code == SERIES:
        power = parts.series
    else:
        power = p_panel
    return _delivered(power, conv_table, conv_rated)


@njit(cache=True, _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _built_row(b, first, last, sky, tables, need_series, work):
    """:func:`_chunk_rows`' second loop for the circuit as built: the parts at each step (linear
    between two table sets where the step's air temperature lies between them), then what each
    connection delivers. With a PV model without I-V curve (no tables), only the converter is
    as built: ``work.east`` and ``work.west`` hold the irradiance, turned into each sub-panel's
    power first (:func:`_powers_of_irradiance`)."""
    step_table, step_weight = sky.step_table, sky.step_weight
    panel_scale, connections = tables.panel_scale, tables.connections
    east, west, buffer = work.east, work.west, work.power
    per_step = step_table.shape[1] > 1
    with_tables = tables.power_terms.shape[0] == 0
    if not with_tables:
        count = uint64(last + 1 - first)
        sets = (step_table, step_weight)
        _powers_of_irradiance(b, uint64(first), count, sets, tables.power_terms, east, west)
    for s in range(first, last + 1):
        root_east, root_west = east[s], west[s]
        t = step_table[b, s] if per_step else step_table[b, 0]
        w = step_weight[b, s] if per_step else 0.0
        if not with_tables:
            m_east, m_west = root_east, root_west
            pair = m_east + m_west
            parts = Parts(
                m_east,
                m_west,
                m_east,
                m_west,
                pair,
                pair,
                max(max(m_east, m_west), pair),
                panel_scale * m_east,
            )
            w = 0.0
        else:
            parts = _built_parts(root_east, root_west, tables, t, need_series)
        if w > 0.0:
            parts = _between(
                parts, _built_parts(root_east, root_west, tables, t + 1, need_series), w
            )
        p_panel = parts.panel if tables.direct else panel_scale * parts.m_east
        for c in range(connections.shape[0]):
            buffer[c, s] = _built_power(connections[c], parts, p_panel, tables)


@njit(cache=True, _nrt=False, no_cfunc_wrapper=True)
def _keep_curves(kept, power, first, last):
    """Every connection's power [W] at steps ``first..last`` of a row (``power``, (n_conn,
    n_steps)) into ``kept``, the row's curves of :attr:`foldopt.engine.records.Outputs.power`.
    A loop, not a slice assignment: numba compiles the message of a slice's mismatched shapes
    (its string formatting) into every function that assigns one, seconds of the kernel's
    compile."""
    for c in range(power.shape[0]):
        for s in range(first, last + 1):
            kept[c, s] = power[c, s]


def fold_rows(sky, rows, tables, loads, out, scratch):
    """Daily metrics of every row and connection, computing the power on the fly.

    Parameters
    ----------
    sky : foldopt.engine.records.SkyArrays
        The light of every block along its steps, and how the beam is taken.
    rows : foldopt.engine.records.Rows
        Each row's block, sub-panel normals, Eq. 5 factors, sky-view factors and set of loads.
    tables : foldopt.engine.records.Tables
        The electrical tables (or the power terms of a model without I-V curve), the circuit as
        built and the connections to evaluate.
    loads : foldopt.engine.records.Loads
        The loads (and load profiles) and the step length.
    out : foldopt.engine.records.Outputs
        t_solar (and its longest contiguous interval), energy, peak power and irradiation, and the
        power curves of the rows that keep them (out).
    scratch : foldopt.engine.records.Scratch
        Per-chunk scratch (:func:`foldopt.engine.records.allocate`).
    """
    # Decided here, in Python: numba compiles a chunk's loop at its first call, so a request
    # whose rows are all of the common case never compiles the general one, and the reverse.
    common = (
        tables.power_terms.shape[0] == 0
        and not tables.as_built
        and not tables.switch_series
        and list(tables.connections) == [SWITCHING]
        and sky.step_table.shape[1] == 1
        and not sky.paper
        and sky.iam_model == IAM_NONE
        and not loads.contiguous
        and not loads.use_profile
    )
    body = _chunk_switching if common else _chunk_rows
    in_chunks(body, rows.block.shape[0], scratch, sky, rows, tables, loads, out)


@njit(cache=True, inline="always")
def _held(held, step_hours):
    """``held[k]``, the length of ``k + 1`` steps [h], as ``k`` additions of the step
    (:attr:`foldopt.engine.records.Scratch.held`)."""
    held[0] = step_hours
    for k in range(1, held.shape[0]):
        held[k] = held[k - 1] + step_hours
    return held


@njit(cache=True, nogil=True, _nrt=False, no_cfunc_wrapper=True)
def _chunk_switching(start, stop, sky, rows, tables, loads, out, work):
    """:func:`_chunk_rows` for the common case, apart: switching alone from one table set a block,
    the exact incidence without the modifier, constant loads without their longest runs (W1-W3,
    a single-diode study's clear days). Its incidence takes the tables' coordinate in its main
    loop (a pass over the steps less), and the row's other cases are not compiled into it: the
    two make its row step cheaper than :func:`_chunk_rows`' (``docs/performance.rst``). The same
    operations in the same order as :func:`_chunk_rows`', so the same bits
    (``tests/test_engine.py``)."""
    has_terms = sky.terms.shape[1] == 4
    held = _held(work.held, loads.step_hours)
    # The records' arrays taken once: see foldopt.engine.incidence.row_arrays.
    light, panels, lit = row_arrays(sky, rows, work)
    block, span, step_hours = rows.block, sky.span, loads.step_hours
    step_table, power = sky.step_table, work.power
    pair_tables, curves = (tables.subpanel, tables.parallel), (work.east, work.west, power)
    coordinates = (work.nodes, work.weights, work.low, work.high)
    extremes, reduction = (work.low, work.high), (work.above, work.whole)
    curve, loadset, p_load, kept = rows.curve, rows.loadset, loads.p_load, out.power
    irradiation, energy, peaks, t_solar = out.irradiation, out.energy, out.peak, out.t_solar
    for r in range(start, stop):
        b = block[r]
        first, last = span[b, 0], span[b, 1]
        n = last + 1 - first
        at, count = uint64(first), uint64(n)
        if has_terms:
            incidence_steps(r, b, at, count, light, panels, (False, True, False, True), lit)
        else:
            incidence_steps(r, b, at, count, light, panels, (False, False, False, True), lit)
        irradiation[r] = steps_sum(lit[2], first, n) * step_hours
        harvested, peak = _switching_row(b, first, n, step_table, pair_tables, curves, coordinates)
        if curve[r] >= 0:
            _keep_curves(kept[curve[r]], power, first, last)
        energy[r, 0], peaks[r, 0] = harvested * step_hours, peak
        blocked_day(
            power[0],
            (first, last),
            p_load[loadset[r]],
            step_hours,
            held,
            extremes,
            reduction,
            t_solar[r, 0],
        )


@njit(cache=True, nogil=True, _nrt=False, no_cfunc_wrapper=True)
def _chunk_rows(start, stop, sky, rows, tables, loads, out, work):
    """Rows ``start .. stop - 1`` of :func:`fold_rows` with one chunk's scratch ``work`` (a thread
    of :func:`foldopt.engine.records.in_chunks` calls it).

    Each row takes three loops over its lit steps. The first (:func:`foldopt.engine.incidence.incidence`)
    gives both sub-panels' irradiance (as sqrt(E / E_max), the tables' coordinate, with tables) and
    their mean incident irradiance before the incidence-angle modifier. The second writes every asked
    connection's power to ``work.power[c, step]``: from the tables (:func:`_table_row`), for a model
    without I-V curve from :func:`_linear_connections`, or with the circuit as built from
    :func:`_built_row`, through :func:`_built_power`, and a row that keeps its curves copies them to ``out.power``. The
    third reduces each power curve to the daily metrics. The row's work is inlined here rather than
    called: a call that passes the kernel's some thirty arrays is a large share of a short row's
    time (``docs/performance.rst``); but for the power of the tables' rows, of switching and of the
    circuit as built, loops longer than a call, each compiled apart (the module's docstring)."""
    connections = tables.connections
    n_conn = connections.shape[0]
    with_tables = tables.power_terms.shape[0] == 0
    need_series = tables.switch_series
    for c in range(n_conn):
        need_series = need_series or connections[c] == SERIES
    # Switching alone from one table set a block (every clear-sky study's and map's).
    switching_alone = (
        with_tables
        and not tables.as_built
        and not need_series
        and n_conn == 1
        and connections[0] == SWITCHING
        and sky.step_table.shape[1] == 1
    )
    # ... and its walk over the loads by blocks, for constant loads without their longest runs.
    blocked = switching_alone and not loads.contiguous and not loads.use_profile
    held = _held(work.held, loads.step_hours)
    # The records' arrays taken once: see foldopt.engine.incidence.row_arrays.
    arrays = row_arrays(sky, rows, work)
    how = (sky.paper, sky.iam_model, sky.iam_params)
    block, span, step_hours = rows.block, sky.span, loads.step_hours
    sets, curves = (sky.step_table, sky.step_weight), (work.east, work.west, work.power)
    pair_tables = (tables.subpanel, tables.parallel, tables.series)
    terms, scales = tables.power_terms, (tables.panel_scale, tables.converter_efficiency)
    settings = (tables.bypass, scales[0], tables.switch_series, scales[1], need_series)
    coordinates = (work.nodes, work.weights, work.low, work.high)
    load_how = (step_hours, loads.contiguous, loads.use_profile)
    reduction = (work.above, work.whole, work.run)
    extremes, power, incident = (work.low, work.high), work.power, work.incident
    curve, loadset, p_load, profiles, kept = (
        rows.curve,
        rows.loadset,
        loads.p_load,
        loads.profile,
        out.power,
    )
    irradiation, energy, peaks = out.irradiation, out.energy, out.peak
    t_solar, t_solar_contiguous = out.t_solar, out.t_solar_contiguous
    as_built, contiguous, use_profile = tables.as_built, loads.contiguous, loads.use_profile
    harvested = peak = 0.0  # the day's sum and peak of switching's pass, when it is taken
    for r in range(start, stop):
        b = block[r]
        first, last = span[b, 0], span[b, 1]
        n = last + 1 - first
        incidence(r, b, first, n, arrays, how, with_tables)
        irradiation[r] = steps_sum(incident, first, n) * step_hours
        if as_built:
            _built_row(b, first, last, sky, tables, need_series, work)
        elif not with_tables:
            _linear_connections(b, first, n, sets, terms, connections, scales, curves)
        elif switching_alone:
            harvested, peak = _switching_call(
                b, first, n, sets[0], pair_tables, curves, coordinates
            )
        else:
            _table_row(b, first, last, sets, pair_tables, connections, settings, curves)
        if curve[r] >= 0:
            _keep_curves(kept[curve[r]], power, first, last)
        row_loads, profile = p_load[loadset[r]], profiles[b if use_profile else 0]
        if blocked:
            energy[r, 0], peaks[r, 0] = harvested * step_hours, peak
            blocked_day(
                power[0],
                (first, last),
                row_loads,
                step_hours,
                held,
                extremes,
                reduction[:2],
                t_solar[r, 0],
            )
            continue
        for c in range(n_conn):
            energy[r, c], peaks[r, c] = day_metrics(
                power[c],
                (first, last),
                row_loads,
                profile,
                load_how,
                reduction,
                t_solar[r, c],
                t_solar_contiguous[r if contiguous else 0, c],
            )
