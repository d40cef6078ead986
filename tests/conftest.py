"""Shared fixtures: the paper's study as shipped, a cheap variant for fast tests, and a small tmpfs for full disks."""

import contextlib
import os
import subprocess
import sys

import pytest

from foldopt.inputs.study_file import default_study_path
from foldopt.api import load_study


@pytest.fixture(scope="session")
def shin_study():
    """configs/shin2015.yaml, resolved (paper mode, azimuth-split, 1-min steps)."""
    return load_study(default_study_path())


def pytest_configure(config):
    # Electrical tables are cached on disk; tests keep theirs in pytest's own cache folder (kept
    # between runs, ignored by git) rather than in the user's ~/.cache.
    if getattr(config, "cache", None) is not None:  # None under -p no:cacheprovider
        os.environ.setdefault("FOLDOPT_CACHE_DIR", str(config.cache.mkdir("foldopt")))
    if sys.dont_write_bytecode or os.environ.get("PYTHONDONTWRITEBYTECODE"):
        # Where the environment asks Python not to write bytecode (this machine's does), each pytest
        # process would rewrite every test module for its assertions again (some 7 s), and each command
        # line a test starts would compile foldopt's modules again (some 0.5 s). The suite keeps the
        # bytecode of its own runs, in the __pycache__ folders git ignores, as Python does by default.
        sys.dont_write_bytecode = False
        os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
    if hasattr(config, "workerinput") and "numba" not in sys.modules:
        # Each pytest-xdist worker has a core of its own: numba's threads (OpenMP, which spins while
        # it waits) and OpenBLAS's would fight the other worker for it. One thread each, here and in
        # the processes the tests start (the command line, Dask's workers): the suite's CPU time
        # fell from 460 s to 394 s, its wall time from 260 s to 224 s. Set before numba is imported,
        # which reads it once (changed later, it refuses to compile). The kernel's threads are
        # tested by tests/test_engine.py::test_the_kernel_on_two_threads.
        for name in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
            os.environ.setdefault(name, "1")


#: Modules whose tests take longest (Dask clusters, the docs build, whole years): run first, so that
#: the two workers do not end on one long test while the other idles.
LONG_FIRST = ("test_cluster.py", "test_docs.py", "test_one_answer.py", "test_report_html.py", "test_faults_cluster.py")


def pytest_collection_modifyitems(items):
    items.sort(key=lambda item: item.path.name not in LONG_FIRST)  # stable: the order within each part is kept


@pytest.fixture
def small_disk(tmp_path):
    """A 2 MB tmpfs at ``tmp_path / "disk"``, unmounted afterwards; skipped where it cannot be mounted."""
    disk = tmp_path / "disk"
    disk.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(disk)], capture_output=True,
                             text=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.strip() or mounted.returncode}")
    try:
        yield disk
    finally:
        subprocess.run(["umount", str(disk)], check=True)


@contextlib.contextmanager
def _in_process_cluster():
    """A Dask scheduler and one single-threaded worker in this process, on 127.0.0.1; yields its
    address. Skipped without distributed."""
    import logging

    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp://",
                                       host="127.0.0.1", dashboard_address=None, silence_logs=logging.ERROR)
    try:
        yield cluster.scheduler_address
    finally:
        cluster.close()


@pytest.fixture(scope="module")
def scheduler():
    """The address of a Dask cluster in this process (no process to start: a map's embedded
    cluster, ``--workers 1``, starts one that imports foldopt and loads its compiled code again,
    5-18 s on the 2-core machine). Tests whose point is the embedded cluster or a process of its
    own are tests/test_cluster.py's."""
    with _in_process_cluster() as address:
        yield address


@pytest.fixture(scope="session")
def in_process_scheduler():
    """For session-scoped fixtures that run a map: the context manager :func:`scheduler` enters,
    to enter for as long as the map runs."""
    return _in_process_cluster
