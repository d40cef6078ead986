"""Brent's method (foldopt.engine.roots.brentq) against SciPy's brentq, whose C routine it follows
step for step: the same root to the bit after the same calls of the function, and the same
refusals."""

import numpy as np
import pytest
import scipy.optimize
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from foldopt.engine.roots import brentq

finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


def _traced(f, calls):
    def traced(x):
        calls.append(x)
        return f(x)

    return traced


@settings(max_examples=300, deadline=None)
@given(
    coefficients=st.lists(finite, min_size=2, max_size=7),
    ends=st.tuples(finite, finite),
    xtol_exponent=st.floats(-14.0, 0.0),
)
# A flat polynomial: the extrapolation divides by zero, which C answers with inf (not an error);
# x^3 about 0: no convergence in 100 iterations.
@example(coefficients=[2.0072992775582945e-135, 0.0], ends=(321.0, -1.0), xtol_exponent=0.0)
@example(coefficients=[1.0, 0.0, 0.0, 0.0], ends=(1.0, -2.0), xtol_exponent=-10.0)
def test_brentq_is_scipys_to_the_bit(coefficients, ends, xtol_exponent):
    """On random polynomials bracketed by random ends, each root (or the failure to converge)
    and each point evaluated is SciPy's."""
    a, b = ends

    def f(x):
        return float(np.polyval(coefficients, x))

    assume(f(a) * f(b) < 0)
    xtol = 10.0**xtol_exponent
    ours, theirs = [], []
    assert _outcome(brentq, f, a, b, xtol, ours) == _outcome(
        scipy.optimize.brentq, f, a, b, xtol, theirs
    )
    assert ours == theirs


def _outcome(solver, f, a, b, xtol, calls):
    """The root, or the kind of error (no convergence in 100 iterations, as x^3 near 0)."""
    try:
        return solver(_traced(f, calls), a, b, xtol=xtol)
    except RuntimeError:
        return RuntimeError


@pytest.mark.parametrize("a, b", [(0.0, 2.0), (2.0, 0.0), (-1.0, 3.0)])
def test_brentq_finds_a_known_root(a, b):
    """sqrt(2), to the default tolerance, whichever end comes first."""
    assert brentq(lambda x: x * x - 2.0, a, b) == pytest.approx(np.sqrt(2.0), abs=4e-12)


def test_brentq_returns_an_end_that_is_a_root():
    assert (
        brentq(lambda x: x - 1.0, 1.0, 3.0)
        == 1.0
        == scipy.optimize.brentq(lambda x: x - 1.0, 1.0, 3.0)
    )


@pytest.mark.parametrize(
    "f, a, b, kwargs, error",
    [
        (lambda x: x * x + 1.0, -1.0, 1.0, {}, ValueError),  # no sign change
        (lambda x: np.nan if x > 0.5 else x - 1.0, 0.0, 2.0, {}, ValueError),  # NaN
        (lambda x: x, -1.0, 1.0, {"xtol": 0.0}, ValueError),
        (lambda x: x, -1.0, 1.0, {"rtol": 1e-17}, ValueError),
        (lambda x: np.cbrt(x - 0.3), -1.0, 1.0, {"maxiter": 2}, RuntimeError),
    ],
)
def test_brentq_refuses_as_scipy_does(f, a, b, kwargs, error):
    with pytest.raises(error):
        scipy.optimize.brentq(f, a, b, **kwargs)
    with pytest.raises(error):
        brentq(f, a, b, **kwargs)
