"""The process's thread pool (foldopt.threads): its tasks' results and errors reach the caller, it
grows to what a caller asks, and a forked child, which inherits no thread, runs its own."""

from __future__ import annotations

import os
import threading

import pytest

from foldopt import threads


def test_the_results_and_errors_reach_the_caller_in_order():
    def fail():
        raise ValueError("a part's error")

    done = threads.submit(2, [lambda: 1, fail, lambda: 3])
    assert done[0].result() == 1 and done[2].result() == 3
    with pytest.raises(ValueError, match="a part's error"):
        done[1].result()


def test_the_pool_runs_as_many_tasks_at_once_as_it_is_asked():
    # Three tasks that each wait for the other two: they finish only on three threads at once.
    meet = threading.Barrier(3, timeout=10)
    done = threads.submit(3, [meet.wait] * 3)
    assert sorted(d.result(timeout=10) for d in done) == [0, 1, 2]


def _in_a_forked_child(what) -> bytes:
    """What ``what()`` gives in a forked child of this process, as it wrote it."""
    read, write = os.pipe()
    child = os.fork()
    if child == 0:  # the child: a hang here would leave the pipe silent, caught below
        try:
            os.write(write, str(what()).encode())
        finally:
            os._exit(0)
    os.close(write)
    try:
        with os.fdopen(read, "rb") as pipe:
            return pipe.read()
    finally:
        os.waitpid(child, 0)


def test_a_forked_child_runs_its_tasks_on_threads_of_its_own():
    assert threads.submit(2, [lambda: 0])[0].result() == 0  # the parent's pool started
    assert _in_a_forked_child(lambda: threads.submit(2, [lambda: 42])[0].result(timeout=10)) == b"42"


def test_a_thread_keeps_one_workspace_on_cache_lines():
    first = threads.workspace(1000)
    again = threads.workspace(800)  # fits: the same memory
    assert first.ctypes.data == again.ctypes.data and again.size == 800
    assert first.ctypes.data % threads.ALIGN == 0 and first.flags.writeable
    larger = threads.workspace(10**6)  # replaces it
    assert larger.size == 10**6 and larger.ctypes.data % threads.ALIGN == 0
    assert threads.workspace(1000).ctypes.data == larger.ctypes.data


def test_each_thread_has_a_workspace_of_its_own():
    meet, seen = threading.Barrier(2, timeout=10), {}

    def take(name):
        space = threads.workspace(4096)
        meet.wait()  # both held at once
        seen[name] = (space.ctypes.data, space.ctypes.data + space.size)

    workers = [threading.Thread(target=take, args=(k,)) for k in range(2)]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join(10)
    (a0, a1), (b0, b1) = seen[0], seen[1]
    assert a1 <= b0 or b1 <= a0  # apart


def test_a_forked_child_forgets_its_parents_workspaces():
    threads.workspace(4096)
    assert _in_a_forked_child(lambda: getattr(threads._local, "buffer", None) is None) == b"True"
