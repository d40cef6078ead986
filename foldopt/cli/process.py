"""The command line's own process and Python's cyclic garbage collector.

A command loads some 100,000 objects that live as long as its process (the modules of typer,
pydantic, numpy, pandas, matplotlib... with their classes and functions). The collector walks
every object it tracks at each full pass, and starts a pass every few thousand new objects:
loading them set off passes over all that came before, and the interpreter's exit walks them all
again (what that cost a warm ``foldopt run`` is in docs/performance.rst).

In the command line's own process (the ``foldopt`` script, ``python -m foldopt``) a command's
modules load with the collector paused and are then frozen (:func:`gc.freeze`: its later passes
leave them out), and the process ends with every object frozen, so that its exit walks none. The
garbage of the command's work is collected as ever. A caller in its own process (a notebook
through the API, a test's ``CliRunner``) keeps its collector as it was.
"""

from __future__ import annotations

import gc
from contextlib import contextmanager

#: Whether this process is the command line's alone (:func:`own_process`).
_OWN = {"process": False}


def own_process() -> None:
    """Mark this process as the command line's alone: the console script's and ``python -m``'s
    entry calls it, never an in-process caller."""
    _OWN["process"] = True


@contextmanager
def loading():
    """Load modules within the block: in the command line's own process with the collector paused,
    and everything loaded frozen after it; elsewhere the block runs as it is.

    Yields
    ------
    None
    """
    if not _OWN["process"]:
        yield
        return
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if enabled:
            gc.enable()


def drawing_aside() -> None:
    """In the command line's own process, a command that will draw figures has them drawn by
    worker processes beside it (:func:`foldopt.output.drawing.start`, where a core is to spare:
    :func:`~foldopt.output.drawing.workers`); elsewhere they are drawn in the caller's process.
    Called before the command's work starts a thread (its progress bar)."""
    if _OWN["process"]:
        from foldopt.output import drawing

        drawing.start(drawing.workers())


def ending() -> None:
    """Before the command line's own process exits: its figure workers ended
    (:func:`foldopt.output.drawing.stop`) and every object frozen, so that the exit's passes of
    the collector walk none (the process's memory goes back whole); elsewhere nothing."""
    if _OWN["process"]:
        from foldopt.output import drawing

        drawing.stop()
        gc.freeze()
