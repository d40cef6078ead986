"""Deliverable power of the two sub-panels connected as built: diodes with a forward drop, switches
with an on-resistance, and a converter or a directly coupled load.

:mod:`foldopt.physics.connections` connects the sub-panels through ideal diodes and switches. Here
each path carries what a reconfigurable panel is built from (Shin et al. Sec. V-C, Fig. 8b):

- ``alone``: one sub-panel through a switch of on-resistance ``R_sw``: ``V_out = V_pv(I) - I R_sw``.
- ``parallel``: both sub-panels on one bus, each behind a blocking diode and a switch. At bus
  voltage ``V`` sub-panel ``i`` sources ``I_i >= 0`` with ``V_pv,i(I_i) = V + V_d(I_i) + I_i R_sw``
  (none where ``V`` exceeds its open-circuit voltage less the diode's drop at zero current).
- ``series``: one string current ``I`` through one switch; a sub-panel adds ``V_pv,i(I)`` up to
  its short-circuit current; beyond it its bypass diode carries the excess and the sub-panel adds
  ``-V_bypass(I - I_sc,i)``. This takes the cells' current at the small reverse voltage across a
  conducting bypass diode as ``I_sc`` (their reverse characteristic is flat there). Without bypass
  diodes the string current stops at the weaker ``I_sc``.
- ``switching``: per element the best of east alone, west alone, parallel and (optionally) series.

A converter (``load_voltage=None``) holds each connection at its maximum-power point. A directly
coupled load fixes the output voltage instead: the connection delivers ``load_voltage`` times the
current it sources there (0 where it cannot reach that voltage).

Method. The I-V curves are handled through an explicit parameter ``x`` in which current and
voltage are closed forms: the diode voltage ``u = V + I R_s`` for the single-diode model (the
parametrisation of Bishop [1]_, pvlib's ``bishop88``) and the voltage for the b-model. The current
a sub-panel sources through a diode and a switch at a given output voltage ``V`` is the root of
``r(x) = V_pv(x) - V_d(I(x)) - I(x) R_sw - V``, increasing in ``x`` and convex (``I(x)`` is
concave and decreasing, ``V_d`` concave and increasing in ``I``). Newton's method is started at
open circuit, right of the root: the tangent of a convex function lies below it, so every step
lands right of the root again and the iterates decrease monotonically to it, quadratically at the
end; 10-12 steps reach 1e-12 V. Maxima are found by golden-section search [2]_ where the power is
concave or unimodal (argued per function), to ~4e-9 of the bracket (power to ~1e-15 relative);
where a Shockley diode breaks concavity the best of ``_GRID`` points brackets the search first.
``tests/test_circuit.py`` checks every connection against densely sampled pvlib curves (agreement
to 3e-8, the samples' resolution).

References
----------
.. [1] J. W. Bishop, "Computer simulation of the effects of electrical mismatches in photovoltaic
   cell interconnection circuits", Solar Cells 25, 73-89, 1988 (current and voltage of the
   single-diode model as functions of the diode voltage).
.. [2] J. Kiefer, "Sequential minimax search for a maximum", Proc. Amer. Math. Soc. 4(3),
   502-506, 1953.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from foldopt.physics import connections
from foldopt.physics.diodes import Diode
from foldopt.physics.pvmodel import IVCurve, trailing_axes

SWITCH_STATES = connections.SWITCH_STATES
IDEAL_DIODE = Diode("ideal")
_NEWTON_TOL = 1e-12  # [V]
_NEWTON_MAX = 100
_BISECTIONS = 60  # a 10 A bracket shrinks to 1e-17 A
_GRID = 12  # points bracketing a maximum where a Shockley diode breaks concavity


def _bracketed(evaluate, lo, hi, count=_GRID):
    """Maximum of functions on [lo, hi] that may not be unimodal: the best of ``count`` evenly
    spaced points, refined by golden-section search between its neighbours."""
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    nodes = lo[..., None] + (hi - lo)[..., None] * np.linspace(0.0, 1.0, count)
    values = evaluate(nodes)
    best = np.argmax(values, axis=-1)[..., None]
    left = np.take_along_axis(nodes, np.maximum(best - 1, 0), axis=-1)[..., 0]
    right = np.take_along_axis(nodes, np.minimum(best + 1, count - 1), axis=-1)[..., 0]
    return np.maximum(connections.golden_section(evaluate, left, right)[0], values.max(axis=-1))


@dataclass(frozen=True)
class _Explicit:
    """An I-V curve in an explicit parameter ``x`` in [0, ``x_oc``]; ``x_oc`` is open circuit."""

    curve: IVCurve

    @functools.cached_property
    def x_oc(self):
        return self.curve.v_oc  # u = V at I = 0; the b-model's parameter is V itself

    @functools.cached_property
    def _terms(self):
        """The parameters and the terms of :meth:`__call__` that depend on them alone, worked out
        once: a Newton solve calls it some ten times at each of some 50 operating points."""
        if self.curve.model == "single-diode":
            il, io, rs, rsh, a = self.curve.params
            return il, io, rs, rsh, a, -io / a, 1.0 / rsh
        if self.curve.model == "b-model":
            v_x, i_x, b = self.curve.params
            lit = v_x > 0
            v_x = np.where(lit, v_x, 1.0)  # a dark curve sources nothing; avoid 0/0
            scale = i_x / -np.expm1(-1.0 / b)
            return lit, v_x, b, scale, -scale, v_x * b
        raise ValueError(f"no I-V curve of model {self.curve.model!r}")

    @functools.cached_property
    def _by_rank(self):
        return {}

    def __call__(self, x):
        """Current, voltage and their derivatives in ``x``: ``I, V, dI/dx, dV/dx``."""
        rank = np.ndim(x)
        if rank not in self._by_rank:
            self._by_rank[rank] = tuple(trailing_axes(p, x) for p in self._terms)
        terms = self._by_rank[rank]
        if self.curve.model == "single-diode":
            # I = I_L - I_0 (exp(u / a) - 1) - u / R_sh and V = u - I R_s (Bishop [1]_).
            il, io, rs, rsh, a, slope_factor, conductance = terms
            scaled = x / a
            current = il - io * np.expm1(scaled) - x / rsh
            slope = slope_factor * np.exp(scaled) - conductance
            return current, x - current * rs, slope, 1.0 - rs * slope
        lit, v_x, b, scale, slope_factor, slope_scale = terms
        growth = np.exp((x / v_x - 1.0) / b)
        current = np.where(lit, scale * (1.0 - growth), 0.0)
        return (
            current,
            x,
            np.where(lit, slope_factor * growth / slope_scale, 0.0),
            np.ones_like(current),
        )


def _output_current(side: _Explicit, voltage, diode: Diode, switch_resistance):
    """Current [A] a sub-panel sources at output voltage ``voltage`` through a diode and a switch.

    Solves ``V_pv(x) - V_d(I(x)) - I(x) R_sw = voltage`` by Newton's method from open circuit (see
    the module's Method); 0 where the output voltage is above the branch's reach.
    """
    voltage = np.asarray(voltage, dtype=float)
    x_oc = trailing_axes(side.x_oc, voltage)
    x = np.broadcast_to(x_oc, np.broadcast_shapes(voltage.shape, x_oc.shape))

    def residual(x):
        current, pv_voltage, di, dv = side(x)
        current = np.maximum(current, 0.0)
        return (
            current,
            pv_voltage - diode.drop(current) - current * switch_resistance - voltage,
            di,
            dv,
        )

    current, r, di, dv = residual(x)
    sources = r > 0
    for _ in range(_NEWTON_MAX):
        step = np.where(
            sources, r / (dv - (diode.resistance(current) + switch_resistance) * di), 0.0
        )
        x = x - step
        current, r, di, dv = residual(x)
        if not np.any(np.abs(step) > _NEWTON_TOL):
            break
    return np.where(sources, current, 0.0)


def _branch_mpp(side: _Explicit, diode: Diode, switch_resistance):
    """Maximum power [W] of one sub-panel through a diode and a switch, and its output voltage [V].

    ``P(I) = I V_pv(I) - I V_d(I) - I^2 R_sw`` is concave in ``I``: ``I V_pv(I)`` is (``V_pv`` is
    concave and decreasing) and ``I V_d(I)`` is convex for every diode model (``I`` times a
    constant; for Shockley's, ``d^2/dI^2 [I ln(1 + I/I_s)] = (I + 2 I_s)/(I + I_s)^2 > 0``). ``I``
    is monotonic in ``x``, so the power is unimodal in ``x`` and golden-section search finds it,
    once per distinct curve (:meth:`foldopt.physics.pvmodel.IVCurve.per_curve`).
    """

    def search(curve):
        side = _Explicit(curve)

        def power(x):
            current, voltage, _, _ = side(x)
            current = np.maximum(current, 0.0)
            return current * (voltage - diode.drop(current) - current * switch_resistance)

        best, x = connections.golden_section(power, np.zeros_like(side.x_oc), side.x_oc)
        current, voltage, _, _ = side(x)
        current = np.maximum(current, 0.0)
        lit = best > 0
        return np.where(lit, best, 0.0), voltage - diode.drop(current) - current * switch_resistance

    return side.curve.per_curve(search)


def _load(load_voltage, like):
    return np.broadcast_to(np.asarray(load_voltage, dtype=float), np.shape(like))


def alone_power(curve: IVCurve, load_voltage=None, switch_resistance=0.0):
    """Power [W] of one sub-panel through a switch, at its maximum-power point or into a load.

    ``V_out = V_pv(I) - I R_sw``; the power ``I V_out`` is concave in ``I`` (``V_pv`` is concave
    and decreasing), so its maximum is found by golden-section search (:func:`_branch_mpp`).

    Parameters
    ----------
    curve : IVCurve
        The sub-panels' I-V curves.
    load_voltage : array_like or None, default None
        None: a converter at the maximum-power point. Otherwise the output voltage [V] a directly
        coupled load holds, broadcast against the curves.
    switch_resistance : float, default 0
        On-resistance of the switch in the path [ohm].

    Returns
    -------
    numpy.ndarray
        Power [W], shaped as the curves; 0 where dark or, coupled, above the curve's reach. With
        ``switch_resistance=0`` and a converter it is ``curve.max_power()``.
    """
    side = _Explicit(curve)
    if load_voltage is None:
        if switch_resistance == 0:
            return curve.max_power()
        return _branch_mpp(side, IDEAL_DIODE, switch_resistance)[0]
    voltage = _load(load_voltage, curve.params[0])
    if switch_resistance == 0:
        # A load above open circuit draws nothing. The current is read at most at V_oc: far beyond
        # it the diode's exponential overflows (pvlib's i_from_v at 900 V), a value never used.
        reach = curve.v_oc
        current = np.clip(np.nan_to_num(curve.current(np.minimum(voltage, reach))), 0.0, None)
        return np.where(voltage < reach, voltage * current, 0.0)
    return voltage * _output_current(side, voltage, IDEAL_DIODE, switch_resistance)


def parallel_power(
    east: IVCurve, west: IVCurve, blocking: Diode, load_voltage=None, switch_resistance=0.0
):
    """Power [W] of two sub-panels in parallel, each behind a blocking diode and a switch.

    At bus voltage ``V`` each sub-panel sources the current of :func:`_output_current`; the pair
    delivers ``V (I_e + I_w)``. With a converter the bus voltage maximising it is found as follows.
    Each sub-panel's power is unimodal in ``V`` (:func:`_branch_mpp`), so the maximum lies between
    the two maximum-power bus voltages ``V_a <= V_b``.

    - ``ideal`` and ``constant`` diodes: the output voltage ``V_pv(I) - V_F - I R_sw`` is concave
      and decreasing in ``I``, so the current is concave and decreasing in ``V`` and each
      sub-panel's power ``V I(V)`` is concave up to its bus open-circuit voltage ``V_oc - V_F``.
      The sum is concave on ``[V_a, min(V_b, V_oc,a - V_F)]`` and beyond equals the other
      sub-panel alone, which rises to ``V_b``: golden-section search on the first interval and the
      other sub-panel's maximum give the exact optimum (as
      :func:`foldopt.physics.connections.parallel_power`).
    - ``shockley``: the drop's logarithm makes ``I(V)`` convex at small currents (the diode's
      turn-on), so the sum need not be concave there: the best of ``_GRID`` voltages across
      ``[V_a, V_b]`` brackets the search. (Over the 161 x 321 irradiance pairs of the engine's
      tables, 2, 12 and 96 points give the same power to 1e-14: the grid is a guard.)

    Parameters
    ----------
    east, west : IVCurve
        The two sub-panels' I-V curves, of one shape.
    blocking : Diode
        The blocking diode of each sub-panel (:func:`foldopt.physics.diodes.diode`).
    load_voltage : array_like or None, default None
        None: a converter at the pair's maximum-power point. Otherwise the bus voltage [V] of a
        directly coupled load, broadcast against the curves.
    switch_resistance : float, default 0
        On-resistance of the switch in each sub-panel's path [ohm].

    Returns
    -------
    numpy.ndarray
        Power [W], shaped as the curves; 0 where both are dark. With an ideal diode, no switch
        resistance and a converter, :func:`foldopt.physics.connections.parallel_power`.
    """
    if load_voltage is None and blocking.model == "ideal" and switch_resistance == 0:
        return connections.parallel_power(east, west)
    sides = _Explicit(east), _Explicit(west)

    def power(voltage):
        return voltage * sum(
            _output_current(side, voltage, blocking, switch_resistance) for side in sides
        )

    if load_voltage is not None:
        return np.maximum(power(_load(load_voltage, east.params[0])), 0.0)
    (p_e, v_e), (p_w, v_w) = (_branch_mpp(side, blocking, switch_resistance) for side in sides)
    # A sub-panel that delivers nothing takes the other's voltage: the search is then that one alone.
    v_e, v_w = np.where(p_e > 0, v_e, v_w), np.where(p_w > 0, v_w, v_e)
    lower, upper = np.minimum(v_e, v_w), np.maximum(v_e, v_w)
    if blocking.model == "shockley":
        searched = _bracketed(power, lower, upper)
    else:
        # The sub-panel of the lower maximum-power voltage stops sourcing at V_oc - V_F.
        reach = np.where(v_e <= v_w, sides[0].x_oc, sides[1].x_oc) - blocking.drop(0.0)
        searched = connections.golden_section(
            power, lower, np.maximum(lower, np.minimum(upper, reach))
        )[0]
    return np.maximum(np.maximum(searched, 0.0), np.maximum(p_e, p_w))


def _string_voltage(east: IVCurve, west: IVCurve, bypass: Diode | None, current, switch_resistance):
    """Voltage [V] of the series string at ``current`` (a trailing axis allowed)."""
    total = -current * switch_resistance
    for curve in (east, west):
        isc, voc = (
            trailing_axes(np.maximum(curve.i_sc, 0.0), current),
            trailing_axes(curve.v_oc, current),
        )
        # Up to Isc a sub-panel's voltage lies in [0, Voc]; clipping also removes pvlib's absurd
        # voltages of practically dark cells (connections.series_power does the same).
        inside = np.clip(np.nan_to_num(curve.voltage(np.minimum(current, isc))), 0.0, voc)
        if bypass is None:
            total = total + inside
        else:
            total = total + np.where(
                current <= isc, inside, -bypass.drop(np.maximum(current - isc, 0.0))
            )
    return total


def series_power(
    east: IVCurve, west: IVCurve, bypass: Diode | None, load_voltage=None, switch_resistance=0.0
):
    """Power [W] of two sub-panels in series, with bypass diodes (or none) and one switch.

    The string voltage is ``V_e(I) + V_w(I) - I R_sw``, a bypassed sub-panel adding
    ``-V_bypass(I - I_sc)`` instead (see the module's description). With a converter:

    - up to the weaker short-circuit current both sub-panels conduct and the power
      ``I (V_e(I) + V_w(I) - I R_sw)`` is concave (each voltage is concave and decreasing):
      golden-section search, as :func:`foldopt.physics.connections.series_power`;
    - between the two short-circuit currents the weaker one is bypassed: the power
      ``I (V_s(I) - V_bypass(I - I_sc,w) - I R_sw)`` is concave for ``ideal`` and ``constant``
      bypass diodes (golden-section search); for ``shockley`` the logarithm's turn-on breaks
      concavity just above the weaker ``I_sc`` and the best of ``_GRID`` currents brackets the
      search (a guard again: 2 and 96 points agree to 1e-14 over the tables' pairs).

    A directly coupled load takes the current where the string voltage, decreasing in ``I``, meets
    ``load_voltage`` (bisection, exact to 1e-15 A). Without bypass diodes the weaker sub-panel at
    its ``I_sc`` takes any reverse voltage, so a load below the string's voltage there draws the
    weaker ``I_sc``.

    Parameters
    ----------
    east, west : IVCurve
        The two sub-panels' I-V curves, of one shape.
    bypass : Diode or None
        The bypass diode across each sub-panel; None for none.
    load_voltage : array_like or None, default None
        None: a converter at the string's maximum-power point. Otherwise the string voltage [V]
        of a directly coupled load, broadcast against the curves.
    switch_resistance : float, default 0
        On-resistance of the one switch in the string [ohm].

    Returns
    -------
    numpy.ndarray
        Power [W], shaped as the curves. With ideal (or no) bypass diodes, no switch resistance
        and a converter, :func:`foldopt.physics.connections.series_power`.
    """
    ideal = bypass is None or bypass.model == "ideal"
    if load_voltage is None and ideal and switch_resistance == 0:
        return connections.series_power(east, west, bypass is not None)
    # pvlib gives a practically dark cell an Isc of -1e-26 A or so.
    isc_e, isc_w = np.maximum(east.i_sc, 0.0), np.maximum(west.i_sc, 0.0)
    weaker, stronger = np.minimum(isc_e, isc_w), np.maximum(isc_e, isc_w)
    top = weaker if bypass is None else stronger

    def power(current):
        return np.nan_to_num(
            current * _string_voltage(east, west, bypass, current, switch_resistance), nan=-np.inf
        )

    if load_voltage is not None:
        target = _load(load_voltage, isc_e)
        # A target the string cannot reach gives 0, one it holds at its top current that current;
        # between them V_string(lo) >= target > V_string(hi) is kept, over those strings alone (a
        # load beyond the panel's reach bisects nothing).
        reaches = (
            _string_voltage(east, west, bypass, np.zeros_like(top), switch_resistance) >= target
        )
        saturated = _string_voltage(east, west, bypass, top, switch_resistance) >= target
        inside = reaches & ~saturated
        strings = [
            IVCurve(curve.model, tuple(np.asarray(p)[inside] for p in curve.params))
            for curve in (east, west)
        ]
        lo, hi, aim = np.zeros(np.count_nonzero(inside)), top[inside], target[inside]
        for _ in range(_BISECTIONS):
            middle = 0.5 * (lo + hi)
            above = _string_voltage(*strings, bypass, middle, switch_resistance) >= aim
            lo, hi = np.where(above, middle, lo), np.where(above, hi, middle)
        current = np.where(saturated, top, 0.0)
        current[inside] = lo
        return np.where(reaches, target * current, 0.0)
    both = connections.golden_section(power, np.zeros_like(weaker), weaker)[0]
    if bypass is None:
        return np.maximum(both, 0.0)
    if bypass.model == "shockley":
        bypassed = _bracketed(power, weaker, stronger)
    else:
        bypassed = connections.golden_section(power, weaker, stronger)[0]
    return np.maximum(np.maximum(both, bypassed), 0.0)


def switching_power(
    east: IVCurve,
    west: IVCurve,
    blocking: Diode,
    bypass: Diode | None,
    switch_series=False,
    load_voltage=None,
    switch_resistance=0.0,
):
    """Power [W] of a reconfigurable switch: the best state per element, and that state.

    The states are east alone, west alone (:func:`alone_power`, through a switch but no diode),
    parallel (:func:`parallel_power`) and, with ``switch_series``, series (:func:`series_power`),
    each through switches of ``switch_resistance``.

    Parameters
    ----------
    east, west : IVCurve
        The two sub-panels' I-V curves, of one shape.
    blocking : Diode
        Blocking diode of each sub-panel in parallel.
    bypass : Diode or None
        Bypass diode across each sub-panel in series.
    switch_series : bool, default False
        Whether series is a state.
    load_voltage : array_like or None, default None
        None: a converter; otherwise the output voltage [V] of a directly coupled load.
    switch_resistance : float, default 0
        On-resistance of each switch [ohm].

    Returns
    -------
    power : numpy.ndarray
        Power of the best state [W], shaped as the curves.
    state : numpy.ndarray of int
        Index into :data:`SWITCH_STATES`; of states within 1e-6 of the best, the first (simplest),
        as :func:`foldopt.physics.connections.connection_powers`.
    """
    options = {"load_voltage": load_voltage, "switch_resistance": switch_resistance}
    candidates = [
        alone_power(east, **options),
        alone_power(west, **options),
        parallel_power(east, west, blocking, **options),
    ]
    if switch_series:
        candidates.append(series_power(east, west, bypass, **options))
    stacked = np.stack(np.broadcast_arrays(*candidates))
    best = stacked.max(axis=0)
    return best, np.argmax(stacked >= best * (1 - 1e-6) - 1e-12, axis=0)
