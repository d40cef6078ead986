"""Deliverable power of the two sub-panels under each way of connecting them.

Shin et al. Sec. V describe the architectures, and the foldopt SPEC ("Aggregating the two
sub-panels") defines them. All powers are at the best operating point of the connection.

- ``east``, ``west``: one sub-panel alone at its maximum power point.
- ``parallel``: one converter sets a common voltage and the currents add. A blocking diode per
  sub-panel stops it sinking current above its open-circuit voltage.
- ``series``: one converter sets a common current and the voltages add. Without bypass diodes the
  current cannot exceed the weaker sub-panel's short-circuit current. With ideal bypass diodes
  (no forward drop), a sub-panel driven past its short-circuit current is bypassed at 0 V.
- ``independent``: each sub-panel on its own converter. It delivers the sum of the two maxima
  times ``converter_efficiency``; at efficiency 1 this bounds every single-converter connection.
- ``switching``: per step the best of east / parallel / west, plus series where enabled (Shin et
  al. Sec. V-C, Fig. 8b and 9).

With the ``ideal`` PV model the sub-panels have no I-V curve, so ``parallel`` and ``series`` are
the sum of the two maxima.
"""

from __future__ import annotations

import numpy as np

from foldopt.names import CONNECTIONS
from foldopt.physics.pvmodel import IVCurve

SWITCH_STATES = ("east", "west", "parallel", "series")  # ties go to the earlier, simpler state
_GOLDEN_STEPS = 40
_INVPHI = (np.sqrt(5.0) - 1.0) / 2.0
#: Curves a pair's search takes at once: its some 40 temporaries of this many values stay in the
#: processor's cache and below the size the C library maps afresh from the system (page faults),
#: which a whole electrical table (51,681 pairs) is not.
_BLOCK = 8192
_LARGEST = np.finfo(float).max


def golden_section(evaluate, lo, hi, steps=_GOLDEN_STEPS):
    """Maximum of unimodal functions on [lo, hi], curve by curve, by golden-section search (the
    bracket shrinks by 0.618 a step; 40 steps leave 4e-9 of its width).

    Parameters
    ----------
    evaluate : callable
        Values at an array of points shaped as ``lo``.
    lo, hi : array_like
        The brackets.
    steps : int, default 40

    Returns
    -------
    maximum, argument : numpy.ndarray
        The largest value found and where, shaped as ``lo``.
    """
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    a, b = hi - _INVPHI * (hi - lo), lo + _INVPHI * (hi - lo)
    fa, fb = evaluate(a), evaluate(b)
    for _ in range(steps):
        left = fa > fb  # the maximum lies in [lo, b]: b's bracket shrinks from above
        lo, hi = np.where(left, lo, a), np.where(left, b, hi)
        inset = _INVPHI * (hi - lo)
        probe = np.where(left, hi - inset, lo + inset)
        f_probe = evaluate(probe)
        # The inner point kept: a (becoming b) where left, b (becoming a) elsewhere.
        a, fa, b, fb = (
            np.where(left, probe, b),
            np.where(left, f_probe, fb),
            np.where(left, a, probe),
            np.where(left, fa, f_probe),
        )
    better = fa >= fb
    return np.where(better, fa, fb), np.where(better, a, b)


def parallel_power(east: IVCurve, west: IVCurve):
    """Maximum power [W] of two sub-panels in parallel behind blocking diodes.

    Each sub-panel's power ``P_i(V) = V max(I_i(V), 0)`` is concave up to its open-circuit voltage
    (``I_i`` is decreasing and concave) and zero beyond, so it rises up to its maximum-power
    voltage and falls after. The sum therefore peaks between the two maximum-power voltages
    ``V_a <= V_b``; there the lower one's power is concave up to its ``V_oc``, so the sum is
    concave on ``[V_a, min(V_b, V_oc,a)]`` (golden-section search, exact to ~1e-8 of the bracket)
    and equals the other sub-panel alone beyond it, which peaks at ``V_b``. The result is the
    larger of that search and each sub-panel alone, with no grid search.

    Parameters
    ----------
    east, west : IVCurve
        The two sub-panels' I-V curves, of one shape (one curve per time step, say).

    Returns
    -------
    numpy.ndarray
        Maximum power of the pair [W], shaped as the curves; 0 where both are dark.

    References
    ----------
    .. [1] D. Shin, N. Chang, Y. Wang, M. Pedram, "Reconfigurable three dimensional photovoltaic
       panel architecture for solar-powered time extension", Sec. V-C and Fig. 9 (parallel
       connection of the sub-panels around noon).
    .. [2] J. Kiefer, "Sequential minimax search for a maximum", Proc. Amer. Math. Soc. 4(3),
       502-506, 1953 (golden-section search).
    """
    if _size(east) > _BLOCK:
        return _in_blocks(parallel_power, east, west)
    (p_east, v_east), (p_west, v_west) = east.mpp(), west.mpp()

    def power(voltage):
        return _finite(
            voltage * (_sourced(east.current(voltage)) + _sourced(west.current(voltage)))
        )

    lower = np.minimum(v_east, v_west)
    # The sub-panel whose maximum-power voltage is the lower one stops sourcing at its own Voc.
    voc_lower = np.where(v_east <= v_west, east.v_oc, west.v_oc)
    upper = np.maximum(lower, np.minimum(np.maximum(v_east, v_west), voc_lower))
    searched = golden_section(power, lower, upper)[0]
    return np.maximum(searched, np.maximum(p_east, p_west))


def _sourced(current):
    """``numpy.nan_to_num(numpy.clip(current, 0, None))`` in three passes rather than some ten:
    behind a blocking diode a sub-panel adds its current only while it sources it, NaN (a dark
    curve) adds none and an overflow the largest float."""
    return np.minimum(np.fmax(np.maximum(current, 0.0), 0.0), _LARGEST)


def _inside(voltage, voc):
    """``numpy.clip(numpy.nan_to_num(voltage), 0, voc)`` for finite ``voc``, in two passes: up to its
    Isc a sub-panel's voltage lies in [0, Voc], and NaN is 0 V."""
    return np.clip(np.fmax(voltage, 0.0), 0.0, voc)


def _finite(power):
    """``numpy.nan_to_num(power, nan=-inf)`` for powers that are not -inf, in two passes: a search's
    value where the curves give none (NaN) is below every other."""
    return np.fmax(np.clip(power, -_LARGEST, _LARGEST), -np.inf)


def _size(curve: IVCurve) -> int:
    return int(np.prod(np.broadcast_shapes(*(np.shape(p) for p in curve.params))))


def _in_blocks(pair, east: IVCurve, west: IVCurve, *args):
    """``pair(east, west, *args)`` over consecutive blocks of at most :data:`_BLOCK` curves, the
    same values as at once: each curve's search is its own, and the curves' maximum-power points
    and end points are worked out once on all of them (:meth:`IVCurve.taken`)."""
    shape = np.broadcast_shapes(*(np.shape(p) for p in (*east.params, *west.params)))
    size = _size(east)
    blocks = np.array_split(np.arange(size), -(-size // _BLOCK))
    return np.concatenate(
        [pair(east.taken(block), west.taken(block), *args) for block in blocks]
    ).reshape(shape)


def series_power(east: IVCurve, west: IVCurve, bypass: bool = True):
    """Maximum power [W] of two sub-panels in series, with or without ideal bypass diodes.

    Without bypass diodes the string current cannot exceed the weaker sub-panel's short-circuit
    current. With ideal ones (0 V forward drop) the optimum is either that, both sub-panels
    conducting, or the stronger sub-panel alone at its own MPP with the weaker one bypassed: above
    the weaker Isc only the stronger sub-panel contributes voltage, at most its MPP power, and
    below it the no-bypass string already includes that operating point. Taking the larger of the
    two is exact, and avoids searching across the cliff where the weaker voltage collapses (a
    search there once settled 0.7 % low).

    Parameters
    ----------
    east, west : IVCurve
        The two sub-panels' I-V curves, of one shape.
    bypass : bool, default True
        Ideal bypass diodes across each sub-panel.

    Returns
    -------
    numpy.ndarray
        Maximum power of the string [W], shaped as the curves.
    """
    if _size(east) > _BLOCK:
        return _in_blocks(series_power, east, west, bypass)
    isc_e, isc_w = east.i_sc, west.i_sc
    voc_e, voc_w = east.v_oc, west.v_oc

    def power(current):
        # Clipping to [0, Voc] also removes the absurd voltages pvlib returns for a practically
        # dark cell (Voc is 0 there).
        return _finite(
            current
            * (_inside(east.voltage(current), voc_e) + _inside(west.voltage(current), voc_w))
        )

    # Each sub-panel's voltage is concave and decreasing in the current, so the string's power is
    # concave on [0, the weaker Isc]: golden-section search finds its maximum.
    upper = np.minimum(isc_e, isc_w)
    string = np.clip(golden_section(power, np.zeros_like(upper), upper)[0], 0.0, None)
    if not bypass:
        return string
    return np.maximum(string, np.maximum(east.max_power(), west.max_power()))


def pair_powers(east: IVCurve, west: IVCurve, bypass: bool = True):
    """Parallel and series power of a pair of sub-panels from their I-V curves.

    Parameters
    ----------
    east, west : IVCurve
        The two sub-panels' I-V curves, of one shape.
    bypass : bool, default True
        Ideal bypass diodes across each sub-panel in series.

    Returns
    -------
    p_parallel, p_series : numpy.ndarray
        :func:`parallel_power` and :func:`series_power` [W], the arguments ``p_parallel`` and
        ``p_series`` of :func:`connection_powers`.
    """
    return parallel_power(east, west), series_power(east, west, bypass)


def connection_powers(
    p_east,
    p_west,
    p_parallel=None,
    p_series=None,
    *,
    switch_series: bool = False,
    converter_efficiency: float = 1.0,
    with_state: bool = True,
):
    """Deliverable power of every connection [W], and the state switching chooses.

    Parameters
    ----------
    p_east, p_west : array_like
        Maximum power of each sub-panel [W].
    p_parallel, p_series : array_like, optional
        Power of the pair in parallel and in series (:func:`pair_powers`); without them (the
        ``ideal`` model, no I-V curves) both are the sum of the two maxima.
    switch_series : bool, default False
        Whether the switch may also select series.
    converter_efficiency : float, default 1
        Efficiency of each converter of ``independent`` [-].
    with_state : bool, default True
        Whether to work out the switch state (None otherwise; it costs a pass over the arrays).

    Returns
    -------
    powers : dict of numpy.ndarray
        One entry per name of :data:`CONNECTIONS`.
    state : numpy.ndarray of int or None
        Index into :data:`SWITCH_STATES` of the state switching chose per step.
    """
    p_east, p_west = np.asarray(p_east, dtype=float), np.asarray(p_west, dtype=float)
    independent = p_east + p_west
    p_parallel = independent if p_parallel is None else np.asarray(p_parallel, dtype=float)
    p_series = independent if p_series is None else np.asarray(p_series, dtype=float)
    stacked = np.stack([p_east, p_west, p_parallel] + ([p_series] if switch_series else []))
    powers = {
        "east": p_east,
        "west": p_west,
        "parallel": p_parallel,
        "series": p_series,
        "independent": converter_efficiency * independent,
        "switching": stacked.max(axis=0),
    }
    if not with_state:
        return powers, None
    # The state is the first (simplest) one within solver precision of the best: with a dark
    # sub-panel, parallel equals the lit one alone and must not win on rounding.
    best = powers["switching"]
    return powers, np.argmax(stacked >= best * (1 - 1e-6) - 1e-12, axis=0)


def connection_power(
    p_east, p_west, connection="switching", p_parallel=None, p_series=None, **options
):
    """Deliverable power of one connection; see :func:`connection_powers`.

    Parameters
    ----------
    p_east, p_west : array_like
        Maximum power of each sub-panel [W].
    connection : str, default 'switching'
        One of :data:`foldopt.names.CONNECTIONS`.
    p_parallel, p_series : array_like, optional
        Power of the pair in parallel and in series [W] (:func:`pair_powers`); default the sum
        of the two maxima (the ``ideal`` model).
    **options
        ``switch_series``, ``converter_efficiency``, ``with_state`` of :func:`connection_powers`.

    Returns
    -------
    numpy.ndarray
        Power [W], shaped as ``p_east``.

    Raises
    ------
    ValueError
        If ``connection`` is unknown.

    Examples
    --------
    With the ``ideal`` model (no I-V curves), switching takes the better of the two sub-panels
    alone and both together:

    >>> print(connection_power([3.0, 4.0], [1.0, 0.0], "switching"))
    [4. 4.]
    """
    if connection not in CONNECTIONS:
        raise ValueError(f"connection must be one of {', '.join(CONNECTIONS)}; got {connection!r}")
    return connection_powers(p_east, p_west, p_parallel, p_series, **options)[0][connection]
