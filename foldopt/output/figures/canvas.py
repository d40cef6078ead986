"""What every figure shares: the Axes a plot draws on, how a figure is saved, a registry entry,
a load's label and the colour scale of a map.

A plot function draws on the ``ax`` it is given (a notebook's, with the user's backend), or makes
its own figure: a pyplot figure, which a notebook shows, or inside :func:`for_files` a bare
:class:`matplotlib.figure.Figure`, which needs no backend and no pyplot (a PNG is drawn by Agg
whatever backend the user chose), so that writing a results folder changes nothing of theirs.

A file's figure is made at the file's resolution (:data:`DPI`) on its own Agg canvas, whose
renderer is the one every figure of its size drawn in the thread shares
(:func:`_shared_renderer_canvas`), so that its layout and its draw, and the figures after it,
measure a label's text once. Its layout is the fixed :class:`Margins` its registry entry gives,
where they serve (one Axes whose labels' size is known: a figure of one day); otherwise the tight
layout, which measures every label once more before the draw.
"""

from __future__ import annotations

import atexit
import contextvars
import functools
import os
import shutil
import tempfile
import threading
from collections.abc import Callable
from contextlib import contextmanager
from pathlib import Path
from typing import NamedTuple

import numpy as np

from foldopt.cache import cache_dir


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


def load_matplotlib() -> None:
    """Import what a figure file is drawn with (matplotlib, its bare Figure and Agg canvas), its
    folders chosen (:func:`_matplotlib_imported`): the first figure made does, and a figure worker
    as it starts (:mod:`foldopt.output.drawing`). Importing the figure modules loads no
    matplotlib, so that a process that has its figures drawn elsewhere never does."""
    if _LOADED["matplotlib"]:  # its folders are chosen once, as matplotlib reads them
        return
    with _matplotlib_imported():
        import matplotlib.backends.backend_agg  # noqa: F401
        import matplotlib.figure  # noqa: F401
    _LOADED["matplotlib"] = True


#: Whether :func:`load_matplotlib` has loaded matplotlib in this process.
_LOADED = {"matplotlib": False}


#: Dots per inch of a figure file.
DPI = 110


class Margins(NamedTuple):
    """A fixed layout: the space [in] between the Axes and each edge of the figure, room for the
    tick labels, the axis labels and the title."""

    left: float
    right: float
    bottom: float
    top: float


#: The margins of a figure of one Axes with a title, an axis label each side and tick labels of
#: up to six characters (the widest a number takes before matplotlib writes an offset: 800000).
ONE_AXES = Margins(left=0.95, right=0.3, bottom=0.65, top=0.4)


class FigureFile(NamedTuple):
    """A figure a results folder may hold, by its file name in a module's ``FIGURES``."""

    #: The public ``plot_*`` function that draws it; it returns the Axes drawn on.
    plot: Callable
    #: What it shows, in one line.
    description: str
    #: Its fixed layout, where one serves; None lays it out by its labels (``tight_layout``).
    margins: Margins | None = None


#: Whether the figures made now are for files (:func:`for_files`); a context variable, so that a
#: thread or task writing a folder does not change what another's plots make.
_FOR_FILES = contextvars.ContextVar("foldopt_figures_for_files", default=False)


@contextmanager
def for_files():
    """Within the block, a plot function that is given no Axes draws on a bare
    :class:`matplotlib.figure.Figure` (no pyplot, no backend, nothing left open) instead of a
    pyplot figure.

    Yields
    ------
    None
    """
    token = _FOR_FILES.set(True)
    try:
        yield
    finally:
        _FOR_FILES.reset(token)


def new_axes(
    ax, figsize: tuple[float, float], nrows: int = 1, ncols: int = 1, squeeze: bool = True
):
    """The figure and Axes a plot draws on.

    Parameters
    ----------
    ax : matplotlib.axes.Axes or None
        The Axes to draw on; None makes a new figure: a pyplot one (shown by the user's backend),
        or within :func:`for_files` a bare :class:`matplotlib.figure.Figure`.
    figsize : tuple of float
        (width, height) of a new figure [in].
    nrows, ncols : int, default 1
        The grid of Axes of a new figure.
    squeeze : bool, default True
        As :meth:`matplotlib.figure.Figure.subplots`: False always gives a 2-D array of Axes.

    Returns
    -------
    fig : matplotlib.figure.Figure
    ax : matplotlib.axes.Axes or numpy.ndarray of them
        ``ax`` itself when given.
    """
    if ax is not None:
        return ax.figure, ax
    load_matplotlib()
    if _FOR_FILES.get():
        from matplotlib.figure import Figure

        fig = Figure(figsize=figsize, dpi=DPI)
        _shared_renderer_canvas()(fig)
        return fig, fig.subplots(nrows, ncols, squeeze=squeeze)
    import matplotlib.pyplot as plt

    return plt.subplots(nrows, ncols, figsize=figsize, squeeze=squeeze)


#: This thread's Agg renderers, by (width, height) [px] and dpi, the last used last: see
#: :func:`_shared_renderer_canvas`.
_RENDERERS = threading.local()

#: The most renderers a thread keeps (a figure's size follows its loads and sites: a process that
#: writes many folders meets many sizes; each keeps a pixel buffer of some 2-7 MB).
RENDERERS_KEPT = 8


@functools.cache
def _shared_renderer_canvas():
    """The Agg canvas class of a file's figure: every figure of one size drawn in a thread draws on
    that thread's one renderer of that size (the last :data:`RENDERERS_KEPT` sizes kept).
    matplotlib keeps the text metrics it measures per renderer, and laying out a label's glyphs
    with FreeType is the dearest part of a label: a new renderer a figure measured the same tick
    labels, titles and legends again in every figure. ``savefig`` clears and draws the whole
    figure before it reads the pixels, so that no figure's pixels are another's."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg, RendererAgg

    class SharedRendererCanvas(FigureCanvasAgg):
        def get_renderer(self):
            key = (*self.get_width_height(physical=True), self.figure.dpi)
            renderers = _RENDERERS.__dict__.setdefault("by_size", {})
            renderer = renderers.pop(key, None) or RendererAgg(*key)
            renderers[key] = renderer
            if len(renderers) > RENDERERS_KEPT:
                del renderers[next(iter(renderers))]
            self.renderer, self._lastKey = renderer, key
            return renderer

    return SharedRendererCanvas


def save_plot(ax, path, margins: Margins | None = None, file_format: str | None = None):
    """Save the figure that holds ``ax`` as the file ``path`` (:data:`DPI`) and close it.

    Parameters
    ----------
    ax : matplotlib.axes.Axes or array of Axes
        An Axes of the figure, as the ``plot_*`` functions return it.
    path : pathlib.Path or file object
        The file; a path's suffix gives the format (``.png``) where ``file_format`` does not.
    margins : Margins, optional
        A fixed layout; default a tight layout.
    file_format : str, optional
        The format (``png``...).

    Returns
    -------
    pathlib.Path or file object
        ``path``.
    """
    fig = np.ravel(ax)[0].figure
    if margins is None:
        from matplotlib.layout_engine import TightLayoutEngine

        # The engine run once, not set on the figure (as tight_layout() leaves a placeholder):
        # savefig lays out, and so draws, a figure that has an engine once more before its draw.
        TightLayoutEngine().execute(fig)
    else:
        width, height = fig.get_size_inches()
        fig.subplots_adjust(
            left=margins.left / width,
            right=1 - margins.right / width,
            bottom=margins.bottom / height,
            top=1 - margins.top / height,
        )
    fig.savefig(path, dpi=DPI, format=file_format)
    if fig.canvas.manager is not None:  # a pyplot figure: pyplot keeps it until it is closed
        import matplotlib.pyplot as plt

        plt.close(fig)
    return path


def load_label(study, load: float) -> str:
    """A sweep's load in a legend or on an axis.

    Parameters
    ----------
    study : foldopt.Study or None
        The study whose load profile (if any) the load scales; None for a constant load.
    load : float
        The sweep's ``p_load_w`` [W].

    Returns
    -------
    str
        ``P_load 2 W``, or a load profile's mean and peak watts
        (:func:`foldopt.inputs.load_profile.load_text`).
    """
    if study is None:
        return f"P_load {load:g} W"
    from foldopt.inputs.load_profile import load_text

    return load_text(study, load)


def colour_scale(values, diverging: bool) -> dict:
    """The colours of a map of ``values`` (``pcolormesh``/``scatter`` keywords).

    Parameters
    ----------
    values : array_like
        The values shown; NaN and masked values are left out of the scale.
    diverging : bool
        Red-blue around 0, symmetric over the finite values (a gain); else viridis.

    Returns
    -------
    dict
        ``cmap`` and, when diverging, ``vmin`` and ``vmax``.
    """
    if not diverging:
        return {"cmap": "viridis"}
    finite = np.asarray(np.ma.filled(np.ma.masked_invalid(values), np.nan), dtype=float)
    finite = finite[np.isfinite(finite)]
    bound = max(float(np.abs(finite).max()) if finite.size else 1.0, 1e-9)
    return {"cmap": "RdBu", "vmin": -bound, "vmax": bound}
