"""Which engine evaluates a request or a call: the ``auto`` rule of :data:`foldopt.names.ENGINES`.

The compiled kernel (:mod:`foldopt.engine.kernel`) is the faster the more rows and steps it
walks, but its first compile after an install costs far more than a small request's work; the
NumPy reference path compiles nothing and is slower a row step than the warm kernel (the figures
are in ``docs/performance.rst``, from ``bench/startup.py``). ``auto`` takes the reference path up
to :data:`foldopt.names.AUTO_NUMPY_ROW_STEPS` rows x steps and the kernel above. A request
decides once where it enters the API (:func:`foldopt.studies.request.request_engine`), so that
every evaluation of one request takes one engine and the same request gives the same numbers
every time; a library call given ``auto`` decides by its own size (:func:`engine_for`).

A leaf: it imports only :mod:`foldopt.names`, so that the command line's requests decide without
numpy.
"""

from __future__ import annotations

from foldopt.names import AUTO_NUMPY_ROW_STEPS, ENGINES


def engine_for(engine: str, row_steps: float) -> str:
    """The engine that evaluates ``row_steps`` rows x time steps: ``engine`` itself, or for
    ``auto`` the NumPy reference up to :data:`foldopt.names.AUTO_NUMPY_ROW_STEPS` and the
    compiled kernel above.

    Parameters
    ----------
    engine : {'auto', 'numba', 'numpy'}
    row_steps : float
        The rows times the steps of each (``math.inf``: more than any bound).

    Returns
    -------
    str
        ``'numba'`` or ``'numpy'``; an unknown ``engine`` raises ValueError naming the valid ones.

    Examples
    --------
    >>> engine_for("auto", 182 * 1440), engine_for("auto", 365 * 182 * 1440)
    ('numpy', 'numba')
    """
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {', '.join(ENGINES)}; got {engine!r}")
    if engine != "auto":
        return engine
    return "numpy" if row_steps <= AUTO_NUMPY_ROW_STEPS else "numba"
