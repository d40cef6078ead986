"""Where a results folder's figures are drawn: in the process that writes the folder, or by a small
pool of worker processes beside it.

A figure is some 0.1 s of matplotlib's work on one core, and matplotlib's import 0.3-0.4 s more.
The command line's own process (:mod:`foldopt.cli.process`) on Linux with a core to spare
(:func:`workers`) starts the pool (:func:`start`) before it computes its answer, before it starts
a thread of its own (a progress bar, numba's): its first worker, forked then, imports matplotlib
and the figure modules at the lowest priority while the command computes, then forks the others,
which find them imported. The command itself never imports matplotlib. Elsewhere (an in-process
caller such as a notebook or a test's ``CliRunner``, one core, a busy machine, no ``fork``)
nothing starts and every figure is drawn in the caller's process as it is asked for.

Wherever it runs, a figure is drawn by the one function the writer gives (:func:`draw`): it
returns the file's bytes, and the writing process writes them into the folder
(:func:`foldopt.files.write_atomically`). The workers touch no file: a folder that fails is
discarded whole by its writer, as ever. A worker's error comes back as it was raised (its type and
message, its traceback as the cause), when the writer collects the figures (:func:`written`),
before ``report.html`` embeds them and the folder is committed. The workers ignore Ctrl-C (the
command ends them) and die with their parent, however it ends (``PR_SET_PDEATHSIG``).
"""

from __future__ import annotations

import contextlib
import gc
import os
import pickle
import signal
import sys
import traceback
from pathlib import Path

#: The most workers a command starts: a folder holds a handful of figures.
MAX_WORKERS = 2

#: The pool where one runs: its queues, its first worker (a child of the command's process), the
#: others (its children, forked once it has imported matplotlib) and the figures handed to it and
#: not yet written (task number -> path).
_POOL: dict = {"leader": None, "pending": {}}

#: Linux's prctl option: the signal a process gets when its parent ends.
_PR_SET_PDEATHSIG = 1


class WorkerTraceback(Exception):
    """Where a figure worker's error was raised: its traceback, the cause of the error raised in
    the command (``foldopt --debug`` prints it)."""


def workers() -> int:
    """The workers a command may start: the cores this process may run on, up to
    :data:`MAX_WORKERS`; none with one core, where the machine's load (the last minute's
    average of runnable processes) exceeds its cores by more than one, the command's own (a
    worker would only share a busy core and add its own work), or where processes are not forked
    (not Linux).

    Returns
    -------
    int
    """
    if sys.platform != "linux" or not _pidfd_works():
        return 0
    cores = len(os.sched_getaffinity(0))
    if cores < 2 or os.getloadavg()[0] > os.cpu_count() + 1:
        return 0
    return min(cores, MAX_WORKERS)


def _pidfd_works() -> bool:
    """Whether the kernel gives process file descriptors (Linux 5.3 and later), by which the
    command sees a worker end (:func:`written`)."""
    try:
        os.close(os.pidfd_open(os.getpid()))
    except (AttributeError, OSError):
        return False
    return True


def start(count: int) -> None:
    """Start ``count`` workers that draw this process's figures from now on (none where ``count``
    is 0 or a pool runs already). The first is forked now and imports matplotlib and the figure
    modules; it then forks the others, which find them imported. Called where no other thread
    runs: a forked child holds only the forking thread, and a lock another thread held stays
    locked in it.

    Parameters
    ----------
    count : int
        From :func:`workers`.
    """
    if count < 1 or _POOL["leader"] is not None:
        return
    import multiprocessing

    context = multiprocessing.get_context("fork")
    # Tasks go through a queue's feeder thread: a task larger than the pipe never blocks the
    # command while a worker waits for it to read a result.
    tasks, results = context.Queue(), context.SimpleQueue()
    leader = context.Process(
        target=_lead, args=(tasks, results, count, os.getpid()), name="foldopt-figures"
    )
    leader.start()
    _POOL.update(leader=leader, tasks=tasks, results=results, helpers=None, tasks_sent=0)


def prepare() -> None:
    """Load what drawing needs where the figures are drawn in this process (no pool): matplotlib
    (:func:`foldopt.output.figures.canvas.load_matplotlib`), which the first figure would load."""
    if _POOL["leader"] is None:
        from foldopt.output.figures import canvas

        canvas.load_matplotlib()


def _detach(parent: int) -> None:
    """A worker's signals: Ctrl-C and SIGTERM are the command's (which ends its workers), and the
    worker dies with its parent however that ends."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    import ctypes

    ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    if os.getppid() != parent:  # the parent ended before the line above
        os._exit(1)


def _lead(tasks, results, count: int, parent: int) -> None:
    """The first worker: matplotlib and the figure modules imported, the other workers forked
    (their ids sent to the command), then figures drawn as the others do."""
    _detach(parent)
    # Its modules (the figure modules, with pandas, and matplotlib) load at the lowest priority,
    # so that the command computing its answer beside it comes first where the cores are shared
    # (where one is free, it changes nothing), and with the collector paused, then frozen, as the
    # command's do (foldopt.cli.process): its passes would walk them again and again.
    priority = os.getpriority(os.PRIO_PROCESS, 0)
    os.setpriority(os.PRIO_PROCESS, 0, 19)
    gc.disable()
    with contextlib.suppress(Exception):  # else each figure raises it, as it would in the command
        from foldopt.output.figures import canvas

        canvas.load_matplotlib()
    gc.freeze()
    gc.enable()
    with contextlib.suppress(PermissionError):  # only a privileged process may raise it again
        os.setpriority(os.PRIO_PROCESS, 0, priority)
    helpers = []
    for _ in range(count - 1):
        pid = os.fork()
        if pid == 0:
            try:
                _detach(os.getppid())
                _serve(tasks, results)
            finally:
                os._exit(0)
        helpers.append(pid)
    results.put(("helpers", helpers, None))
    _serve(tasks, results)
    for pid in helpers:
        os.waitpid(pid, 0)


def _serve(tasks, results) -> None:
    """Draw figures until the command says there are no more: each result, or the error raised
    with its traceback, sent back under its task's number."""
    while (task := tasks.get()) is not None:
        number, function, args = pickle.loads(task)
        try:
            results.put((number, function(*args), None))
        except BaseException as error:  # sent back, raised in the command
            text = "".join(traceback.format_exception(error))
            try:
                pickle.loads(pickle.dumps(error))
            except Exception:  # an error that cannot travel: its type and first line do
                error = RuntimeError(f"{type(error).__name__}: {str(error).splitlines()[0]}")
            results.put((number, error, text))


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
        Its arguments (pickled to a worker; where they cannot be, the file is drawn here).
    """
    task = None
    if _POOL["leader"] is not None:
        with contextlib.suppress(Exception):  # what cannot travel to a worker is drawn here
            task = pickle.dumps((_POOL["tasks_sent"], function, args), pickle.HIGHEST_PROTOCOL)
    if task is None:
        _write(path, function(*args))
        return
    _POOL["pending"][_POOL["tasks_sent"]] = Path(path)
    _POOL["tasks_sent"] += 1
    _POOL["tasks"].put(task)


def _write(path: Path, data: bytes) -> None:
    from foldopt.files import write_atomically

    write_atomically(path, lambda temporary: Path(temporary).write_bytes(data))


def written() -> None:
    """Write every file handed to the pool and not yet written, as the workers return them; the
    first error a worker raised is raised here, and the pool is ended (the figures not yet drawn
    are dropped). Without a pool, or with nothing handed to it, nothing to do."""
    if not _POOL["pending"]:
        return
    from multiprocessing.connection import wait

    results, pending = _POOL["results"], _POOL["pending"]
    try:
        while pending:
            if results._reader not in wait([results._reader, *_ended()]):
                raise RuntimeError("a figure worker ended before drawing its figures")
            number, data, text = results.get()
            if number == "helpers":
                _POOL["helpers"] = {pid: os.pidfd_open(pid) for pid in data}
            elif text is not None:
                data.__cause__ = WorkerTraceback(text)
                raise data
            else:
                _write(pending.pop(number), data)
    except BaseException:
        stop()
        raise


def _ended() -> list:
    """What a worker's end makes ready: the first worker's sentinel, the others' pidfds."""
    return [_POOL["leader"].sentinel, *(_POOL["helpers"] or {}).values()]


def stop() -> None:
    """End the pool, where one runs, and wait for its workers to end (none outlives the
    command): a pool that drew all it was given is told to end, any other is killed (its first
    worker, and the others die with it)."""
    leader = _POOL["leader"]
    if leader is None:
        return
    helpers, tasks = _POOL["helpers"] or {}, _POOL["tasks"]
    if _POOL["pending"] or not helpers or not _POOL["tasks_sent"]:
        for pidfd in helpers.values():
            with contextlib.suppress(ProcessLookupError):  # one that has ended already
                signal.pidfd_send_signal(pidfd, signal.SIGKILL)
        leader.kill()
        tasks.cancel_join_thread()  # what the killed workers did not read is dropped
    else:
        for _ in range(1 + len(helpers)):
            tasks.put(None)
    tasks.close()
    leader.join()
    for pidfd in helpers.values():
        os.close(pidfd)
    _POOL.update(leader=None, pending={}, helpers=None)
