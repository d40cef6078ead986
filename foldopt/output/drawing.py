"""Where a results folder's figures are drawn: in the process that writes the folder, or by a small
pool of worker processes beside it.

A figure is some 0.1 s of matplotlib's work on one core, and matplotlib's import 0.4 s more. The
command line's own process (:mod:`foldopt.cli.process`) on Linux with more than one core starts
the pool (:func:`start`) before it computes its answer: the workers are forked then, before the
command starts a thread of its own (a progress bar, numba's), and import matplotlib and the figure
modules while the command computes; the command itself never imports matplotlib. Elsewhere (an
in-process caller such as a notebook or a test's ``CliRunner``, one core, no ``fork``) nothing
starts and every figure is drawn in the caller's process as it is asked for.

Wherever it runs, a figure is drawn by the one function the writer gives (:func:`draw`): it
returns the file's bytes, and the writing process writes them into the folder
(:func:`foldopt.files.write_atomically`). The workers touch no file: a folder that fails is
discarded whole by its writer, as ever. A worker's error comes back as it was raised (its type and
message), when the writer collects the figures (:func:`written`), before ``report.html`` embeds
them and the folder is committed. The workers ignore Ctrl-C (the command ends them) and die with
the command's process, however it ends (``PR_SET_PDEATHSIG``).
"""

from __future__ import annotations

import os
import signal
import sys
from pathlib import Path

#: The most workers a command starts: a folder holds a handful of figures, and each worker's
#: imports cost 0.4 s of CPU.
MAX_WORKERS = 2

#: The pool, where one runs, and the figures handed to it and not yet written: (path, future).
_POOL: dict = {"executor": None, "pending": []}

#: Linux's prctl option: the signal a process gets when its parent ends.
_PR_SET_PDEATHSIG = 1


def workers() -> int:
    """The workers a command may start: the cores this process may run on, up to
    :data:`MAX_WORKERS`; 0 with one core (a worker would only share it) or where processes are
    not forked (not Linux).

    Returns
    -------
    int
    """
    if sys.platform != "linux":
        return 0
    cores = len(os.sched_getaffinity(0))
    return min(cores, MAX_WORKERS) if cores > 1 else 0


def start(count: int) -> None:
    """Fork ``count`` workers that draw the figures of this process from now on (none where
    ``count`` is 0 or a pool runs already). Called where no other thread runs: a forked child holds
    only the forking thread, and any lock another thread held stays locked in it.

    Parameters
    ----------
    count : int
        From :func:`workers`.
    """
    if count < 1 or _POOL["executor"] is not None:
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    executor = ProcessPoolExecutor(
        count,
        mp_context=multiprocessing.get_context("fork"),
        initializer=_worker,
        initargs=(os.getpid(),),
    )
    executor.submit(os.getpid)  # forks the workers now, before the command's work
    _POOL["executor"] = executor


def _worker(parent: int) -> None:
    """A worker's start: Ctrl-C and SIGTERM left to the command, death with it, then matplotlib and
    the figure modules imported."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    import ctypes

    ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    if os.getppid() != parent:  # the command ended before the line above
        os._exit(1)
    from foldopt.output.figures import canvas

    canvas.load_matplotlib()


def draw(path: Path, function, *args) -> None:
    """Have the file ``path`` drawn: ``function(*args)`` returns its bytes. Without a pool it runs
    here and the file is written now; with one, in a worker, and the file is written by
    :func:`written`.

    Parameters
    ----------
    path : pathlib.Path
        The file.
    function : callable
        A module's function (a worker finds it by name), returning bytes.
    *args
        Its arguments (pickled to a worker).
    """
    executor = _POOL["executor"]
    if executor is None:
        _write(path, function(*args))
    else:
        _POOL["pending"].append((Path(path), executor.submit(function, *args)))


def _write(path: Path, data: bytes) -> None:
    from foldopt.files import write_atomically

    write_atomically(path, lambda temporary: Path(temporary).write_bytes(data))


def written() -> None:
    """Write every file handed to the pool and not yet written, as each worker returns it; the
    first error a worker raised is raised here (the files not yet drawn are dropped). Without a
    pool, or with nothing handed to it, nothing to do."""
    pending, _POOL["pending"] = _POOL["pending"], []
    try:
        for path, future in pending:
            _write(path, future.result())
    except BaseException:
        for _, future in pending:
            future.cancel()
        raise


def stop() -> None:
    """End the pool, where one runs: the figures not yet drawn dropped, the workers ended and
    waited for (none outlives the command)."""
    executor, _POOL["executor"] = _POOL["executor"], None
    _POOL["pending"] = []
    if executor is not None:
        executor.shutdown(wait=True, cancel_futures=True)
