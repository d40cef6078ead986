"""Brent's root finder on a bracket, as SciPy's :func:`scipy.optimize.brentq` runs it [1]_ [2]_.

The day's study finds two roots (the load a design carries for a given ``t_solar``, and the
paper's heuristic fold angle) and nothing else of :mod:`scipy.optimize`, whose import (with
scipy.linalg, scipy.sparse and scipy.special) would take longer than the day's whole computation.
:func:`brentq` is SciPy's C routine (``scipy/optimize/Zeros/brentq.c``, by Charles Harris) step
for step in Python floats, so that it returns the same root to the bit after the same calls of
``f``: ``tests/test_roots.py`` holds it to SciPy on random functions and brackets.

References
----------
.. [1] R. P. Brent, "Algorithms for Minimization Without Derivatives", Prentice-Hall, 1973, Ch. 4.
.. [2] SciPy, ``scipy/optimize/Zeros/brentq.c`` and ``scipy.optimize.brentq`` (BSD-3-Clause).
"""

from __future__ import annotations

import math
from collections.abc import Callable

#: SciPy's default tolerances and iteration limit: ``xtol`` [x's unit], ``rtol`` (4 machine
#: epsilons, the smallest SciPy accepts), iterations.
XTOL, RTOL, MAXITER = 2e-12, 4 * 2.220446049250313e-16, 100


def _divide(a: float, b: float) -> float:
    """``a / b`` as C divides doubles (IEEE 754): by zero an infinity or NaN, where Python
    raises."""
    if b != 0:
        return a / b
    if a == 0 or math.isnan(a):
        return math.nan
    return math.copysign(math.inf, a) * math.copysign(1.0, b)


def brentq(
    f: Callable[[float], float],
    a: float,
    b: float,
    xtol: float = XTOL,
    rtol: float = RTOL,
    maxiter: int = MAXITER,
) -> float:
    """A root of ``f`` in ``[a, b]`` by Brent's method, as :func:`scipy.optimize.brentq`.

    Parameters
    ----------
    f : callable
        A continuous function of a float returning a float, of opposite signs at ``a`` and ``b``.
    a, b : float
        The bracket's ends.
    xtol, rtol : float, default 2e-12 and 8.9e-16
        The root is within ``xtol + rtol * |root|`` of a sign change of ``f``; ``xtol`` above 0,
        ``rtol`` at least :data:`RTOL`.
    maxiter : int, default 100
        Iterations before it gives up.

    Returns
    -------
    float
        The root.

    Raises
    ------
    ValueError
        If ``f(a)`` and ``f(b)`` have the same sign, ``f`` returns NaN, or a tolerance is too small.
    RuntimeError
        If it has not converged after ``maxiter`` iterations.

    Examples
    --------
    >>> round(brentq(lambda x: x * x - 2.0, 0.0, 2.0), 12)
    1.414213562373
    """
    if xtol <= 0:
        raise ValueError(f"xtol too small ({xtol:g} <= 0)")
    if rtol < RTOL:
        raise ValueError(f"rtol too small ({rtol:g} < {RTOL:g})")

    def value(x: float) -> float:
        fx = float(f(x))
        if math.isnan(fx):
            raise ValueError(f"The function value at x={x} is NaN; solver cannot continue.")
        return fx

    xpre, xcur = float(a), float(b)
    xblk = fblk = spre = scur = 0.0
    fpre, fcur = value(xpre), value(xcur)
    if fpre * fcur > 0:
        raise ValueError("f(a) and f(b) must have different signs")
    if fpre == 0:
        return xpre
    if fcur == 0:
        return xcur
    for _ in range(maxiter):
        if fpre != 0 and fcur != 0 and (math.copysign(1.0, fpre) != math.copysign(1.0, fcur)):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + rtol * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # interpolate (secant)
                stry = _divide(-fcur * (xcur - xpre), fcur - fpre)
            else:  # extrapolate (inverse quadratic)
                dpre = _divide(fpre - fcur, xpre - xcur)
                dblk = _divide(fblk - fcur, xblk - xcur)
                stry = _divide(-fcur * (fblk * dblk - fpre * dpre), dblk * dpre * (fblk - fpre))
            limit = 3 * abs(sbis) - delta
            if 2 * abs(stry) < (abs(spre) if abs(spre) < limit else limit):  # a good short step
                spre, scur = scur, stry
            else:  # bisect
                spre = scur = sbis
        else:  # bisect
            spre = scur = sbis
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > delta else (delta if sbis > 0 else -delta)
        fcur = value(xcur)
    raise RuntimeError(f"Failed to converge after {maxiter} iterations, value is {xcur}")
