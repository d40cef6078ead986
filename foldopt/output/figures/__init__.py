"""Figures: one module per kind of result (:mod:`~foldopt.output.figures.day`,
:mod:`~foldopt.output.figures.storage`, :mod:`~foldopt.output.figures.sweep`, :mod:`~foldopt.output.figures.annual`,
:mod:`~foldopt.output.figures.weather`, :mod:`~foldopt.output.figures.horizon`,
:mod:`~foldopt.output.figures.world`, :mod:`~foldopt.output.figures.sizing`,
:mod:`~foldopt.output.figures.landscape`, :mod:`~foldopt.output.figures.least_cost`), each with the public
``plot_*`` functions that draw on an ``ax`` (a notebook's, with its own backend) and its
``FIGURES``: file name -> the plot function and what it shows. :data:`FIGURES` gathers them: every
figure file a results folder can hold, the one list the folder writers draw through
(:func:`write_figure`) and the manual's table (:func:`rst_table`, ``python -m
foldopt.output.figures``). Importing this package chooses no backend: files are drawn on bare
:class:`matplotlib.figure.Figure` objects (:func:`~foldopt.output.figures.canvas.for_files`). It
may import :mod:`foldopt.studies` and everything below it.
"""

from __future__ import annotations

import atexit
import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

from foldopt.cache import cache_dir
from foldopt.files import write_atomically


def _writable(folder: Path) -> bool:
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return False
    return folder.is_dir() and os.access(folder, os.W_OK)


def _matplotlib_folder() -> Path | None:
    """A writable folder for matplotlib's configuration and font cache where its own under HOME
    is not (HOME read-only, missing or no folder), or None where it is or ``MPLCONFIGDIR`` names
    one: matplotlib would warn on stderr, which ``--quiet`` keeps empty. foldopt's cache folder
    where it is writable (the font cache is then kept), else a temporary folder removed at exit."""
    if os.environ.get("MPLCONFIGDIR"):
        return None
    try:
        own = [
            Path(os.environ.get("XDG_CONFIG_HOME") or Path.home() / ".config") / "matplotlib",
            Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "matplotlib",
        ]
    except RuntimeError:  # no home folder at all
        own = []
    if own and all(_writable(folder) for folder in own):
        return None
    try:
        folder = cache_dir() / "matplotlib"
    except RuntimeError:
        folder = None
    if folder is None or not _writable(folder):
        folder = Path(tempfile.mkdtemp(prefix="foldopt-matplotlib-"))
        atexit.register(shutil.rmtree, folder, ignore_errors=True)
    return folder


@contextmanager
def _matplotlib_imported():
    """matplotlib imported and its folders chosen (:func:`_matplotlib_folder`), which it does once,
    reading ``MPLCONFIGDIR``: the variable is set for that moment only, and the environment is the
    caller's again after (the one write of foldopt's to the environment, undone at once)."""
    folder = _matplotlib_folder()
    if folder is not None:
        os.environ["MPLCONFIGDIR"] = str(folder)
    try:
        import matplotlib

        matplotlib.get_configdir(), matplotlib.get_cachedir()  # each read once, then kept
        yield
    finally:
        if folder is not None:
            del os.environ["MPLCONFIGDIR"]


# Every figure module imports matplotlib, and Python runs this package's __init__ before any of
# them: its folders are chosen before anything draws.
with _matplotlib_imported():
    from foldopt.output.figures import (
        annual,
        day,
        horizon,
        landscape,
        least_cost,
        sizing,
        storage,
        sweep,
        weather,
        world,
    )
    from foldopt.output.figures.canvas import for_files, save_plot

#: Every figure file a results folder can hold -> :class:`~foldopt.output.figures.canvas.FigureFile`
#: (its plot function and what it shows), by kind of result.
FIGURES = {
    **day.FIGURES,
    **storage.FIGURES,
    **sweep.FIGURES,
    **annual.FIGURES,
    **weather.FIGURES,
    **horizon.FIGURES,
    **world.FIGURES,
    **sizing.FIGURES,
    **landscape.FIGURES,
    **least_cost.FIGURES,
}


def write_figure(folder: Path, file: str, *args, **kwargs) -> str:
    """Draw the figure ``file`` with its plot function (:data:`FIGURES`) and write it in ``folder``.

    The figure is a bare :class:`matplotlib.figure.Figure` (no pyplot, no backend), laid out by
    its entry's margins and saved by :func:`~foldopt.output.figures.canvas.save_plot` under a
    temporary name, then renamed into place (:func:`foldopt.files.write_atomically`).

    Parameters
    ----------
    folder : pathlib.Path
        The results folder.
    file : str
        A file name of :data:`FIGURES` (``power_curves.png``...).
    *args, **kwargs
        The plot function's arguments, but ``ax``.

    Returns
    -------
    str
        ``file``.
    """
    figure = FIGURES[file]
    with for_files():
        ax = figure.plot(*args, **kwargs)
    write_atomically(
        Path(folder) / file, lambda temporary: save_plot(ax, temporary, figure.margins)
    )
    return file


def rst_table() -> str:
    """The manual's table of figures: every file a results folder can hold, the function that
    draws it and what it shows.

    Returns
    -------
    str
        reStructuredText: a title, a paragraph and a list table.
    """
    kinds = (
        (day, "one case"),
        (storage, "one case with storage"),
        (sweep, "a sweep"),
        (annual, "a sweep of dates"),
        (weather, "a weather file's dates"),
        (horizon, "a site with a horizon"),
        (world, "a map"),
        (sizing, "a sizing"),
        (least_cost, "a weather file's dates with costs"),
    )
    lines = [
        "Figures",
        "=======",
        "",
        "Every figure a results folder can hold, the results that write it and the function that draws it",
        "(each takes ``ax=`` to draw into yours). Generated by ``python -m foldopt.output.figures`` from",
        ":data:`foldopt.output.figures.FIGURES`.",
        "",
        ".. list-table::",
        "   :header-rows: 1",
        "   :widths: 28 14 22 36",
        "",
        "   * - file",
        "     - written by",
        "     - drawn by",
        "     - what it shows",
    ]
    for module, kind in kinds:
        for file, figure in module.FIGURES.items():
            lines += [
                f"   * - ``{file}``",
                f"     - {kind}",
                f"     - :func:`foldopt.{figure.plot.__name__}`",
                f"     - {figure.description}",
            ]
    return "\n".join(lines) + "\n"
