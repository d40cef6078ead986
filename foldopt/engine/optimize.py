"""Choosing the fold angle: an exhaustive sweep and the heuristic of Shin et al. Sec. VI, Eq. 8.

Both take the physics as callables of the fold angle, so they serve any site, sky, geometry and
PV model.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from foldopt.engine.metrics import t_solar
from foldopt.engine.roots import brentq
from foldopt.names import FLAT_FOLD_ANGLE

PowerOfAngles = Callable[[np.ndarray], np.ndarray]


def _last_argmax(values):
    return int(values.size - 1 - np.argmax(values[::-1]))


def optimal_fold_angle(
    combined_power: PowerOfAngles,
    fold_angles,
    sweep_t_solar,
    p_load: float,
    step_hours: float,
    refine_points: int = 41,
):
    """Fold angle with the longest ``t_solar``: best of a sweep, refined on a fine local grid.

    ``t_solar`` as a function of the fold angle has kinks (Shin et al. Fig. 12a), so the refinement
    is a second grid spanning one sweep step either side of the best sweep point, not a
    gradient method. Ties go to the largest (least folded) angle: folding that buys no time is not
    recommended, and a load no design can carry returns the flat panel.

    Parameters
    ----------
    combined_power : callable
        Maps fold angles, shape (k,), to the deliverable power, shape (k, n_time) [W].
    fold_angles : array_like
        Sweep grid [deg], ascending.
    sweep_t_solar : array_like
        ``t_solar`` [h] at ``fold_angles``, from the sweep the caller already ran.
    p_load : float
        Load power [W].
    step_hours : float
        Step length [h].
    refine_points : int, default 41
        Points of the refinement grid; 1 keeps the sweep's best point.

    Returns
    -------
    fold_angle : float
        [deg].
    t_solar_h : float
        [h].
    """
    fold_angles = np.asarray(fold_angles, dtype=float)
    hours = np.asarray(sweep_t_solar, dtype=float)
    best = _last_argmax(hours)
    if refine_points > 1 and fold_angles.size > 1:
        lo = fold_angles[max(best - 1, 0)]
        hi = fold_angles[min(best + 1, fold_angles.size - 1)]
        fine = np.linspace(lo, hi, refine_points)
        fine_hours = t_solar(combined_power(fine), p_load, step_hours)
        fine_best = _last_argmax(fine_hours)
        if fine_hours[fine_best] > hours[best]:
            return float(fine[fine_best]), float(fine_hours[fine_best])
    return float(fold_angles[best]), float(hours[best])


def noon_valley(p_east, p_west, p_parallel):
    """Minimum of the parallel curve between the peaks of the two sub-panels.

    Shin et al. Sec. VI, Fig. 10: folding shifts the east and west curves apart and digs a valley
    into their parallel sum around noon; Eq. 8 calls it ``Min(P_pv,parallel)``.

    Parameters
    ----------
    p_east, p_west : array_like
        Each sub-panel's power alone [W], time on the last axis.
    p_parallel : array_like
        The pair's power in parallel [W], of the same shape.

    Returns
    -------
    numpy.ndarray
        The valley [W], one per leading index (a float for 1-D curves).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0, 24, 241)
    >>> east, west = np.exp(-((t - 10) ** 2)), np.exp(-((t - 14) ** 2))
    >>> print(round(float(noon_valley(east, west, east + west)), 6))  # at noon: 2 exp(-4)
    0.036631
    """
    p_parallel = np.asarray(p_parallel, dtype=float)
    steps = np.arange(p_parallel.shape[-1])
    first = np.minimum(np.argmax(p_east, axis=-1), np.argmax(p_west, axis=-1))[..., None]
    last = np.maximum(np.argmax(p_east, axis=-1), np.argmax(p_west, axis=-1))[..., None]
    between = (steps >= first) & (steps <= last)
    return np.where(between, p_parallel, np.inf).min(axis=-1)


def heuristic_fold_angle(
    subpanel_power: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]],
    p_load: float,
    lo: float = 1.0,
    hi: float = FLAT_FOLD_ANGLE,
    tol: float = 0.01,
) -> tuple[float, str]:
    """The paper's optimum: the smallest fold angle whose noon valley still reaches the load.

    Shin et al. [1]_ Sec. VI, Eq. 8: ``Min(P_pv,parallel) = P_load``. The valley deepens as the
    panel folds (it rises with the fold angle), so the angle is the root of
    ``noon_valley(angle) - p_load`` in ``[lo, hi]``, found by Brent's method
    (:func:`foldopt.engine.roots.brentq`, SciPy's): on the paper's study it evaluates the day 9
    or 10 times where bisection to the same tolerance takes 17. Where the valley reaches the load already at ``lo``
    the rule's angle lies at or below ``lo``, which is no angle of ``[lo, hi]``: ``lo`` is only the
    search's bound, not returned as the rule's answer.

    Parameters
    ----------
    subpanel_power : callable
        Maps fold angles, shape (k,), to ``(p_east, p_west, p_parallel)``, each (k, n_time) [W].
    p_load : float
        Load power [W].
    lo, hi : float, default 1 and 180
        Search interval [deg]: a study's fold angles.
    tol : float, default 0.01
        Absolute tolerance on the angle [deg] (``xtol`` of :func:`foldopt.engine.roots.brentq`).

    Returns
    -------
    angle : float
        Fold angle [deg] in ``(lo, hi]`` whose valley reaches the load, at most ``tol`` above the
        threshold; NaN where the rule's angle is not in ``(lo, hi]``.
    outside : str
        Where the rule's angle lies when it is not in ``(lo, hi]``: ``"below"`` (even the most
        folded panel, at ``lo``, reaches the load), ``"above"`` (the valley falls short of the
        load even at ``hi``; at 180 deg the load exceeds the flat panel's noon power); ``""``
        where ``angle`` is the rule's.

    References
    ----------
    .. [1] D. Shin, N. Chang, Y. Wang, M. Pedram, "Reconfigurable three dimensional photovoltaic
       panel architecture for solar-powered time extension", Sec. VI, Eq. 8.

    Examples
    --------
    A valley that rises linearly with the fold angle reaches a 0.25 W load at 45 deg:

    >>> import numpy as np
    >>> def subpanels(angles):
    ...     level = np.asarray(angles)[:, None] / 180.0 * np.ones((1, 5))
    ...     return level, level, level
    >>> angle, outside = heuristic_fold_angle(subpanels, 0.25)
    >>> round(angle, 1), outside
    (45.0, '')
    >>> heuristic_fold_angle(subpanels, 0.25, lo=60.0)
    (nan, 'below')
    """

    def shortfall(angle):
        return float(noon_valley(*subpanel_power(np.array([angle])))[0]) - p_load

    if shortfall(hi) < 0.0:
        return float("nan"), "above"
    if shortfall(lo) >= 0.0:
        return float("nan"), "below"
    angle = float(brentq(shortfall, lo, hi, xtol=tol))
    # Brent's estimate may fall just short of the threshold; the answer must reach the load (the
    # valley rises with the fold angle, and the threshold lies within ``tol`` of the estimate).
    return (angle if shortfall(angle) >= 0.0 else min(angle + tol, hi)), ""
