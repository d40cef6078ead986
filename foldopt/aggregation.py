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

from foldopt.pvmodel import IVCurve

CONNECTIONS = ("east", "west", "parallel", "series", "independent", "switching")
SWITCH_STATES = ("east", "west", "parallel", "series")  # ties go to the earlier, simpler state
_GRID_POINTS = 48
_GOLDEN_STEPS = 40
_INVPHI = (np.sqrt(5.0) - 1.0) / 2.0


def _maximise(power_of, upper):
    """Maximum over ``x`` in [0, upper] of ``power_of(x)``, curve by curve.

    ``power_of`` maps operating points shaped ``upper.shape + (k,)`` to power. A grid locates the
    best bracket (the parallel and series curves can have two local maxima); golden-section search
    inside it refines the maximum to ~1e-8 of the bracket.
    """
    upper = np.asarray(upper, dtype=float)
    fractions = np.linspace(0.0, 1.0, _GRID_POINTS)
    grid = upper[..., None] * fractions
    values = np.nan_to_num(power_of(grid), nan=-np.inf)
    best = np.argmax(values, axis=-1)
    step = upper / (_GRID_POINTS - 1)
    lo = np.clip(best - 1, 0, None) * step
    hi = np.clip(best + 1, None, _GRID_POINTS - 1) * step
    def evaluate(x):
        return np.nan_to_num(power_of(x[..., None])[..., 0], nan=-np.inf)

    a, b = hi - _INVPHI * (hi - lo), lo + _INVPHI * (hi - lo)
    fa, fb = evaluate(a), evaluate(b)
    for _ in range(_GOLDEN_STEPS):
        left = fa > fb  # the maximum lies in [lo, b]: b's bracket shrinks from above
        lo, hi = np.where(left, lo, a), np.where(left, b, hi)
        kept, f_kept = np.where(left, a, b), np.where(left, fa, fb)
        probe = np.where(left, hi - _INVPHI * (hi - lo), lo + _INVPHI * (hi - lo))
        f_probe = evaluate(probe)
        a, fa = np.where(left, probe, kept), np.where(left, f_probe, f_kept)
        b, fb = np.where(left, kept, probe), np.where(left, f_kept, f_probe)
    refined = np.maximum(fa, fb)
    return np.clip(np.maximum(refined, values.max(axis=-1)), 0.0, None)


def parallel_power(east: IVCurve, west: IVCurve):
    """Maximum power [W] of two sub-panels in parallel behind blocking diodes."""

    def power(voltage):
        # Blocking diodes: a sub-panel adds its current only while it sources it (NaN: dark).
        current = sum(np.nan_to_num(np.clip(side.current(voltage), 0.0, None)) for side in (east, west))
        return voltage * current

    # Running at the stronger sub-panel's own MPP is always a valid operating point (the other adds
    # current or is blocked), so it bounds the result from below where a kink near it (the weak
    # sub-panel's Voc) misleads the search (seen: 1.2e-4 short).
    best_alone = np.maximum(east.max_power(), west.max_power())
    return np.maximum(_maximise(power, np.maximum(east.v_oc, west.v_oc)), best_alone)


def series_power(east: IVCurve, west: IVCurve, bypass: bool = True):
    """Maximum power [W] of two sub-panels in series, with or without ideal bypass diodes.

    Without bypass diodes the string current cannot exceed the weaker sub-panel's short-circuit
    current. With ideal ones (0 V forward drop) the optimum is either that, both sub-panels
    conducting, or the stronger sub-panel alone at its own MPP with the weaker one bypassed: above
    the weaker Isc only the stronger sub-panel contributes voltage, at most its MPP power, and
    below it the no-bypass string already includes that operating point. Taking the larger of the
    two is exact, and avoids searching across the cliff where the weaker voltage collapses (a
    search there once settled 0.7 % low).
    """
    isc_e, isc_w = east.i_sc, west.i_sc
    voc_e, voc_w = east.v_oc, west.v_oc

    def side_voltage(curve, voc, current):
        # Between 0 and Isc a sub-panel's voltage lies in [0, Voc]; clipping to it also removes
        # the absurd voltages pvlib returns for a practically dark cell (Voc is 0 there).
        return np.clip(np.nan_to_num(curve.voltage(current)), 0.0, voc[..., None])

    def power(current):
        return current * (side_voltage(east, voc_e, current) + side_voltage(west, voc_w, current))

    string = _maximise(power, np.minimum(isc_e, isc_w))
    if not bypass:
        return string
    return np.maximum(string, np.maximum(east.max_power(), west.max_power()))


def pair_powers(east: IVCurve, west: IVCurve, bypass: bool = True):
    """Parallel and series power [W] of a pair of sub-panels from their I-V curves."""
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


def connection_power(p_east, p_west, connection="switching", p_parallel=None, p_series=None, **options):
    """Deliverable power [W] of one connection; see :func:`connection_powers`."""
    if connection not in CONNECTIONS:
        raise ValueError(f"connection must be one of {', '.join(CONNECTIONS)}; got {connection!r}")
    return connection_powers(p_east, p_west, p_parallel, p_series, **options)[0][connection]
