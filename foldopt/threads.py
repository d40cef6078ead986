"""The process's threads for compiled passes that release the GIL (the kernel's chunks, the sun's
parts): one pool, started at its first use and kept, so that a pass does not start and join its
threads again at every call (some 50-100 us a call against passes of a few ms). A leaf: it imports
nothing of foldopt.

Each thread also keeps one workspace (:func:`workspace`): the bytes a compiled pass works in and
returns nothing of (the kernel's per-chunk scratch), reused by the thread's next call, so that a
repeated pass neither maps nor zeroes its scratch again (a page faulted in afresh costs a virtual
machine several times what it costs bare metal: ``docs/performance.rst``).

A forked child (a Dask worker, a test's forked command) inherits the pool's object but not its
threads: the pool is forgotten in the child, which starts its own at its first use; so are the
workspaces (the child's copies of its parent's are no one's to reuse).
"""

from __future__ import annotations

import os
import threading
from typing import TYPE_CHECKING, Callable

if TYPE_CHECKING:  # concurrent.futures is imported at the first pass that needs threads
    from concurrent.futures import Future, ThreadPoolExecutor

_pool: ThreadPoolExecutor | None = None
_size = 0
_lock = threading.Lock()
_local = threading.local()  # each thread's workspace
ALIGN = 64  # [bytes] a cache line: a workspace's parts start on their own lines


def _forget_in_child() -> None:
    global _pool, _size, _lock, _local
    _pool, _size, _lock, _local = None, 0, threading.Lock(), threading.local()


os.register_at_fork(after_in_child=_forget_in_child)


def submit(workers: int, tasks: list[Callable[[], None]]) -> list[Future]:
    """Run ``tasks`` on the process's pool, which holds ``workers`` threads or more; their futures,
    in order (``future.result()`` raises a task's error).

    Parameters
    ----------
    workers : int
        The threads the caller means to keep busy (numba's number of threads, or fewer).
    tasks : list of callables
        Each called with no argument.
    """
    from concurrent.futures import ThreadPoolExecutor

    global _pool, _size
    with _lock:
        if _pool is None or _size < workers:
            # A larger pool replaces a smaller one: the old one's threads end with its queue.
            if _pool is not None:
                _pool.shutdown(wait=False)
            _pool, _size = ThreadPoolExecutor(workers, thread_name_prefix="foldopt"), workers
        pool = _pool
    return [pool.submit(task) for task in tasks]


def workspace(nbytes: int):
    """This thread's workspace: a writable uint8 array of ``nbytes`` that starts on a cache line
    (:data:`ALIGN`), its contents whatever the thread's last use left. The same memory at every
    call that fits in it; a larger call replaces it (one workspace a thread, the largest asked).

    The caller owns it until its next call of this function in the same thread: it must not
    return it or a view of it, and may hand it to other threads only for work it waits for.

    Parameters
    ----------
    nbytes : int
        Bytes asked.
    """
    import numpy as np

    buffer = getattr(_local, "buffer", None)
    if buffer is None or buffer.size < nbytes + ALIGN:
        buffer = _local.buffer = np.empty(nbytes + ALIGN, dtype=np.uint8)
    start = -buffer.ctypes.data % ALIGN
    return buffer[start : start + nbytes]
