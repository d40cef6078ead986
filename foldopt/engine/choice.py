"""Which engine evaluates a request or a call: the ``auto`` rule of :data:`foldopt.names.ENGINES`.

The compiled kernel (:mod:`foldopt.engine.kernel`) is the faster the more rows and steps it
walks, but its first compile after an install costs far more than a small request's work, and
even loading it from numba's cache costs more than a day's study on the NumPy reference path,
which compiles nothing and is slower a row step than the kernel (the figures are in
``docs/performance.rst``). ``auto`` takes the reference path up to
:data:`foldopt.names.AUTO_CACHED_NUMPY_ROW_STEPS` rows x steps where the kernel is compiled
already (:func:`kernel_cached`: in this process, or in numba's cache on disk), up to
:data:`foldopt.names.AUTO_NUMPY_ROW_STEPS` where it is not, and the kernel above. A request
decides once where it enters the API (:func:`foldopt.studies.request.request_engine`), so that
every evaluation of one request takes one engine, the one its answer records; a library call
given ``auto`` decides by its own size (:func:`engine_for`).

A leaf: it imports only :mod:`foldopt.names` and the standard library, and reads numba's cache
files without importing numba, so that the command line's requests decide without numpy.
"""

from __future__ import annotations

import hashlib
import os
import pickletools
import sys
from pathlib import Path

from foldopt.names import AUTO_CACHED_NUMPY_ROW_STEPS, AUTO_NUMPY_ROW_STEPS, ENGINES

#: The kernel's compiled entry points, by module of :mod:`foldopt.engine` and function: the rows
#: (:func:`foldopt.engine.kernel.fold_rows`: its common case's loop and the general one, each
#: compiled at its first call) and the curves (a tracker's, a design's:
#: :func:`foldopt.engine.curve_reduction.curve_rows`) every evaluation on the kernel runs through;
#: their compile is the kernel's (the functions they call are compiled and cached with them).
KERNEL_FUNCTIONS = (
    ("kernel", "_chunk_rows"),
    ("kernel", "_chunk_switching"),
    ("curve_reduction", "_chunk_curves"),
)


def engine_for(engine: str, row_steps: float) -> str:
    """The engine that evaluates ``row_steps`` rows x time steps: ``engine`` itself, or for
    ``auto`` the NumPy reference up to a bound and the compiled kernel above: the bound is
    :data:`foldopt.names.AUTO_CACHED_NUMPY_ROW_STEPS` where the kernel is compiled already
    (:func:`kernel_cached`), :data:`foldopt.names.AUTO_NUMPY_ROW_STEPS` where it is not.

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
    >>> engine_for("auto", 181 * 1440), engine_for("auto", 365 * 181 * 1440)
    ('numpy', 'numba')
    """
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {', '.join(ENGINES)}; got {engine!r}")
    if engine != "auto":
        return engine
    if row_steps <= AUTO_CACHED_NUMPY_ROW_STEPS:
        return "numpy"
    if row_steps <= AUTO_NUMPY_ROW_STEPS and not kernel_cached():
        return "numpy"
    return "numba"


def kernel_cached() -> bool:
    """Whether the compiled kernel runs without a compile: each of :data:`KERNEL_FUNCTIONS` is
    compiled in this process already, or numba's cache on disk holds it for this numba, this
    Python and the function's source as it is now.

    Returns
    -------
    bool
        False where numba is not installed, where the cache folder numba would use is not the
        sources' own ``__pycache__`` or ``NUMBA_CACHE_DIR`` (a read-only install caches in the
        user's folder, not looked for here), or where an index is unreadable. An index holds a
        compile for some CPU and argument types: one of another CPU (a cache folder shared
        between machines) counts as held, and numba then compiles.
    """
    version = None
    for module, function in KERNEL_FUNCTIONS:
        if _compiled_here(module, function):
            continue
        version = version or _numba_version()
        if version is None or not in_cache(
            Path(__file__).with_name(f"{module}.py"), function, version
        ):
            return False
    return True


def _compiled_here(module: str, function: str) -> bool:
    """Whether this process holds a compile of ``foldopt.engine.<module>.<function>``."""
    dispatcher = getattr(sys.modules.get(f"foldopt.engine.{module}"), function, None)
    return bool(getattr(dispatcher, "signatures", ()))


def _numba_version() -> str | None:
    """numba's version, from its installed metadata (not importing it)."""
    from importlib import metadata

    try:
        return metadata.version("numba")
    except metadata.PackageNotFoundError:
        return None


def _cache_folder(source: Path) -> Path | None:
    """The folder where numba caches the functions of ``source``, as its locators choose it:
    ``NUMBA_CACHE_DIR``'s subfolder for the source's folder, else the source's ``__pycache__``
    where it can be written; None otherwise."""
    folder = os.path.dirname(os.path.abspath(source))
    configured = os.environ.get("NUMBA_CACHE_DIR")
    if configured:
        hashed = hashlib.sha1(folder.encode()).hexdigest()
        return Path(configured) / f"{os.path.basename(folder)}_{hashed}"
    in_tree = Path(folder) / "__pycache__"
    return in_tree if os.access(in_tree if in_tree.is_dir() else folder, os.W_OK) else None


def in_cache(source: Path, function: str, version: str) -> bool:
    """Whether numba's cache holds a compile of a function for a numba version and the source's
    present content: an index ``<module>.<function>-<line>.py<XY>.nbi`` written by that numba (its
    first pickle) for the source's SHA-256 (the first bytes of its second pickle, before the
    compiles it lists), listing at least one compile. The index is read opcode by opcode
    (:func:`pickletools.genops`): nothing in it is unpickled, imported or run. A numba that
    stamps its indexes otherwise (older ones: the source's time and size) finds none here.

    Parameters
    ----------
    source : pathlib.Path
        The module's file.
    function : str
        The function's qualified name in it.
    version : str
        numba's version.

    Returns
    -------
    bool
    """
    folder = _cache_folder(source)
    if folder is None or not folder.is_dir():
        return False
    python = f"py{sys.version_info[0]}{sys.version_info[1]}{getattr(sys, 'abiflags', '')}"
    try:
        stamp = hashlib.sha256(source.read_bytes()).digest()
        for index in folder.glob(f"{source.stem}.{function}-*.{python}.nbi"):
            with open(index, "rb") as file:
                written_by = [arg for _, arg, _ in pickletools.genops(file) if isinstance(arg, str)]
                entries = pickletools.genops(file)
                written_for = next((arg for _, arg, _ in entries if isinstance(arg, bytes)), None)
                listed = any(op.name in ("SETITEM", "SETITEMS") for op, _, _ in entries)
            if written_by[:1] == [version] and written_for == stamp and listed:
                return True
    except (OSError, ValueError):
        return False  # unreadable or not a pickle: numba would compile
    return False
