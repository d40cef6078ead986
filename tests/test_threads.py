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


def test_a_forked_child_runs_its_tasks_on_threads_of_its_own():
    assert threads.submit(2, [lambda: 0])[0].result() == 0  # the parent's pool started
    read, write = os.pipe()
    child = os.fork()
    if child == 0:  # the child: a hang here would leave the pipe silent, caught below
        try:
            value = threads.submit(2, [lambda: 42])[0].result(timeout=10)
            os.write(write, str(value).encode())
        finally:
            os._exit(0)
    os.close(write)
    try:
        with os.fdopen(read, "rb") as pipe:
            assert pipe.read() == b"42"
    finally:
        os.waitpid(child, 0)
