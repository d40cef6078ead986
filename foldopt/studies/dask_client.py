"""A Dask client of the cluster a map runs on (:mod:`foldopt.studies.cluster`): an embedded
:class:`distributed.LocalCluster`, or the cluster of a scheduler named by its address or its
scheduler file.

The address is checked in form before anything else, and the scheduler is asked, within one
deadline, whether it is there and is Dask's, so that a wrong address fails in seconds with a message
saying what ``--scheduler`` accepts or what to start, rather than after Dask's own retries or never.

Dask's own log records (its scheduler, nannies and client in this process, the embedded cluster's
workers in theirs) go nowhere: a map's terminal holds foldopt's lines only, and a task that fails is
the one error the map raises (the worker's traceback travels with it, shown by ``foldopt --debug``).
"""

from __future__ import annotations

import atexit
import gc
import json
import logging
import multiprocessing
import os
import re
import signal
import socket
import threading
import time
import warnings
from contextlib import contextmanager
from pathlib import Path

from foldopt.cache import quiet
from foldopt.errors import ConfigError
from foldopt.names import CONNECT_TIMEOUT, WORKER_TIMEOUT

#: Dask's protocols whose addresses are ``host:port`` and can be asked in bounded time.
SCHEMES = ("tcp", "tls", "ws", "wss")
#: ``host:port``: a name or IPv4 address, or an IPv6 one in brackets, and a port number.
_HOST_PORT = re.compile(r"^(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+):([0-9]{1,5})$")
#: The loggers Dask writes through: its own, and tornado's and bokeh's, whose servers it runs.
DASK_LOGGERS = ("distributed", "tornado", "bokeh")
#: The modules whose warnings are Dask's.
DASK_WARNINGS = r"distributed(\.|$)"
#: A level above every record's: a logger set to it passes nothing on.
SILENT = logging.CRITICAL + 1
#: What ``--scheduler`` accepts, as the messages say it.
ACCEPTED = (
    "give a scheduler's address, tcp://HOST:PORT (or tls://, ws://, wss://), or the scheduler "
    "file `dask scheduler --scheduler-file FILE` writes"
)


@contextmanager
def connect(
    scheduler: str | None = None,
    workers: int | None = None,
    timeout: float = CONNECT_TIMEOUT,
    worker_timeout: float = WORKER_TIMEOUT,
):
    """A Dask client: of the cluster at ``scheduler`` (:func:`scheduler_address`), or of an embedded
    :class:`distributed.LocalCluster` of ``workers`` single-threaded processes (default one per
    core). Dask logs nothing while the block runs (:func:`quiet_dask`), nor do the embedded
    cluster's workers ever (:func:`dask_setup`).

    Parameters
    ----------
    scheduler : str, optional
        A scheduler's address or scheduler file; default an embedded cluster.
    workers : int, optional
        Worker processes of the embedded cluster; default one per core.
    timeout : float, default :data:`CONNECT_TIMEOUT`
        Seconds [s] to reach ``scheduler``, every step counted.
    worker_timeout : float, default :data:`WORKER_TIMEOUT`
        Seconds [s] to then wait for its first worker.

    Yields
    ------
    tuple of (distributed.Client, str)
        The client, closed (with the embedded cluster) when the block ends, and the cluster's
        description.

    Raises
    ------
    foldopt.ConfigError
        Where ``scheduler`` is no address or scheduler file, no Dask scheduler answers there
        within ``timeout`` (at once where the port refuses), or it has no worker within
        ``worker_timeout``.
    """
    address = None if scheduler is None else scheduler_address(scheduler)
    with quiet_dask():
        from distributed import Client, LocalCluster

        if address is None:
            count = workers or os.cpu_count() or 1
            with _forked_workers():
                cluster = LocalCluster(
                    n_workers=count,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address="127.0.0.1:0",
                    silence_logs=SILENT,
                    preload=[__name__],  # dask_setup: the workers' processes log nothing either
                    # --quiet reaches the worker processes' notices (a cache built again) too
                    env={"FOLDOPT_QUIET": "1"} if quiet() else {},
                )
                try:
                    with Client(cluster) as client:
                        yield (
                            client,
                            f"embedded LocalCluster, {count} worker process"
                            f"{'es' if count > 1 else ''}",
                        )
                finally:
                    cluster.close()
            return
        deadline = time.monotonic() + timeout
        check_scheduler(scheduler, address, timeout)
        try:
            # The scheduler has just answered: what is left of the deadline, a second at least.
            client = Client(address, timeout=max(deadline - time.monotonic(), 1.0))
        except (OSError, TimeoutError, ValueError) as error:
            raise ConfigError([_no_answer(scheduler, timeout, type(error).__name__)]) from None
        try:
            try:
                client.wait_for_workers(1, timeout=worker_timeout)
            except TimeoutError:
                raise ConfigError(
                    [
                        f"--scheduler = {scheduler!r}: the scheduler has no worker after "
                        f"{worker_timeout:g} s; start some with `dask worker ADDRESS`"
                    ]
                ) from None
            yield client, f"Dask scheduler {client.scheduler.address}"
        finally:
            client.close()


#: The modules the embedded cluster's worker processes import before their first task where no
#: caller names its own (:func:`start_worker_server`): Dask's worker and its preload, this module.
WORKER_MODULES = ("distributed", __name__)


def start_worker_server(modules: tuple[str, ...] = WORKER_MODULES) -> bool:
    """Start this process's server of worker processes, once, where the platform has one
    (multiprocessing's ``forkserver``: Linux and macOS, not Windows): a fresh Python process that
    imports ``modules`` and then forks each worker process of an embedded cluster
    (:func:`connect`) whole, its imports done. Started before the cluster is asked for, it imports
    while this process goes on (its own imports, the scheduler's start) rather than after, as each
    spawned worker did; a worker the nanny starts again is a fork too.

    The server is started with the environment Dask's nanny gives a worker it spawns
    (``distributed.nanny.pre-spawn-environ``: one BLAS thread, malloc's trim threshold; a fixed hash
    seed), set in this process's environment only while the server starts (the nanny, too, sets it
    only while it spawns), so that a forked worker computes as a spawned one did. A fork copies only
    the thread that forks, so the server runs nothing but imports: it holds no thread of Python's
    and no BLAS thread, and the only other thread of its libraries, jemalloc's (pyarrow's
    allocator), is jemalloc's to handle across a fork (its fork handlers hold its locks). Numba's
    compiled code is loaded by each worker at its first task: a kernel run in the server could start
    numba's threads before the forks.

    Parameters
    ----------
    modules : tuple of str
        Modules the server imports (one it cannot import is passed over): those the workers' first
        task needs (:data:`foldopt.studies.cluster.TASK_MODULES`). Only the first call that starts
        the server chooses them.

    Returns
    -------
    bool
        Whether the server runs: the embedded cluster's workers are then forked from it.
    """
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return False
    from multiprocessing import forkserver

    # The script this process runs (the command line's), imported once there rather than by each
    # worker as it starts.
    multiprocessing.get_context("forkserver").set_forkserver_preload(["__main__", *modules])
    environment = _nanny_environment()
    before = {name: os.environ.get(name) for name in environment}
    os.environ.update(environment)  # the server's, from its start; not left to this process's
    try:
        forkserver.ensure_running()
    finally:
        for name, value in before.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value
    return True


def _nanny_environment() -> dict[str, str]:
    """The variables Dask's nanny sets in this process's environment before it starts a worker
    process: ``distributed.nanny.pre-spawn-environ`` as configured, over Dask's defaults, and a
    fixed hash seed. Read without importing distributed, 0.4-1 s that would delay the server."""
    from importlib.util import find_spec

    import dask
    import yaml

    defaults = Path(find_spec("distributed").origin).with_name("distributed.yaml")
    environment = {
        **yaml.safe_load(defaults.read_text())["distributed"]["nanny"]["pre-spawn-environ"],
        **dask.config.get("distributed.nanny.pre-spawn-environ", default={}),
    }
    environment = {
        name: os.environ.get(name, str(value))
        for name, value in environment.items()
        if value is not None
    }
    if environment.get("PYTHONHASHSEED") in (None, "0"):
        environment["PYTHONHASHSEED"] = "6640"  # the nanny's, for hashes equal on every worker
    return environment


@contextmanager
def _forked_workers():
    """While the block runs, the embedded cluster's worker processes are forks of
    :func:`start_worker_server`'s server where it runs (Dask spawns them otherwise): a worker the
    nanny starts again is forked too."""
    if not start_worker_server():
        yield
        return
    import dask

    with dask.config.set({"distributed.worker.multiprocessing-method": "forkserver"}):
        yield


@contextmanager
def quiet_dask():
    """No log record of Dask's (:data:`DASK_LOGGERS`) reaches a handler of this process while the
    block runs, nor does a warning of Dask's: the embedded cluster's scheduler and nannies run
    here, and the client, whose records of a lost scheduler or a slow event loop would otherwise
    reach the terminal. The loggers' levels and the warnings' filters are put back afterwards, for
    a caller's own use of Dask."""
    import distributed  # noqa: F401 - sets its loggers' levels as it is first imported: before they are kept

    loggers = _dask_loggers()
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(SILENT)
    try:
        with warnings.catch_warnings():
            # and its warnings (a port in use, a large graph): the map works regardless
            warnings.filterwarnings("ignore", module=DASK_WARNINGS)
            yield
    finally:
        for logger, level in zip(loggers, levels, strict=True):
            logger.setLevel(level)


def _dask_loggers() -> list[logging.Logger]:
    """The loggers of :data:`DASK_LOGGERS` and those below them that have a level of their own
    (the others take their parent's)."""
    below = [
        logging.getLogger(name)
        for name, logger in list(logging.Logger.manager.loggerDict.items())
        if name.split(".")[0] in DASK_LOGGERS
        and name not in DASK_LOGGERS
        and isinstance(logger, logging.Logger)
        and logger.level != logging.NOTSET
    ]
    return [logging.getLogger(name) for name in DASK_LOGGERS] + below


def dask_setup(worker) -> None:
    """Dask's preload hook, run in each worker process of the embedded cluster as it starts
    (:func:`connect`): the process's Dask loggers log nothing and Dask warns of nothing, for its
    whole life (a heartbeat that
    fails as the cluster shuts down, a task that raises: its error reaches the client). As the
    process exits, every object is frozen (:func:`gc.freeze`), so that the exit's passes of the
    collector walk none, as the command line's own process does
    (:func:`foldopt.cli.process.ending`): over the objects of numba, pandas and pvlib a worker has
    loaded they took 1-3 s, which the map waits for as it closes its cluster. A terminal's Ctrl-C,
    which reaches the worker processes too (the command's process group), is the client's to
    answer (one line; it closes the cluster): a worker interrupted printed its traceback.

    Parameters
    ----------
    worker : distributed.Worker
    """
    for logger in _dask_loggers():
        logger.setLevel(SILENT)
    warnings.filterwarnings("ignore", module=DASK_WARNINGS)
    atexit.register(gc.freeze)
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


def check_cluster(scheduler: str | None, workers: int | None) -> None:
    """Raise :class:`ConfigError` where the cluster is asked for wrongly: ``scheduler`` is no
    address or scheduler file (:func:`foldopt.studies.dask_client.scheduler_address`), or
    ``workers``, which sizes the embedded cluster, is given with it. Nothing is asked of the network.

    Parameters
    ----------
    scheduler : str, optional
    workers : int, optional
    """
    if scheduler is not None and workers is not None:
        raise ConfigError(
            [
                "--workers: the embedded cluster's worker processes; a --scheduler's cluster has "
                "its own, so give one or the other"
            ]
        )
    if scheduler is not None:
        scheduler_address(scheduler)


def scheduler_address(scheduler: str) -> str:
    """The address ``scheduler`` gives, checked in form without asking the network: itself, or the
    ``address`` of the scheduler file it names.

    Parameters
    ----------
    scheduler : str
        ``tcp://host:port`` (or ``tls://``, ``ws://``, ``wss://``; ``host:port`` is ``tcp://``), or
        the path of a scheduler file.

    Returns
    -------
    str
        The scheduler's address.

    Raises
    ------
    foldopt.ConfigError
        One line naming ``--scheduler`` and what it accepts: where ``scheduler`` is neither such an
        address nor an existing scheduler file, or the file holds no such address.
    """
    if not scheduler.strip():
        raise ConfigError([_refused(scheduler, "empty")])
    path = Path(scheduler).expanduser()
    if "://" not in scheduler and path.is_dir():
        raise ConfigError([_refused(scheduler, "a folder, not a scheduler file")])
    if "://" not in scheduler and path.is_file():
        address = _file_address(scheduler, path)
        reason = _address_fault(address)
        if reason is not None:
            raise ConfigError([_not_a_file(scheduler, f"its address {address!r}: {reason}")])
        return address
    if "://" not in scheduler and not _HOST_PORT.match(scheduler):
        looks_like_a_file = "/" in scheduler or os.sep in scheduler or path.suffix == ".json"
        raise ConfigError(
            [
                _refused(
                    scheduler,
                    "no such scheduler file"
                    if looks_like_a_file
                    else "neither an existing scheduler file nor an address",
                )
            ]
        )
    reason = _address_fault(scheduler)
    if reason is not None:
        raise ConfigError([_refused(scheduler, reason)])
    return scheduler


def _address_fault(address: str) -> str | None:
    """Why ``address`` is no address foldopt can reach, or None."""
    scheme, _, location = address.rpartition("://")
    scheme = scheme or "tcp"
    if scheme.lower() not in SCHEMES:
        return f"{scheme}:// is not a protocol foldopt reaches a scheduler by"
    if not location:
        return "no host and port"
    match = _HOST_PORT.match(location)
    if match is None:
        return "not a HOST:PORT (such as 127.0.0.1:8786)"
    if not 1 <= int(match.group(2)) <= 65535:
        return f"port {int(match.group(2))} is not in [1, 65535]"
    return None


def _host_port(address: str) -> tuple[str, int]:
    """The host and port of an address :func:`_address_fault` accepts."""
    match = _HOST_PORT.match(address.rpartition("://")[2])
    return match.group(1).strip("[]"), int(match.group(2))


def _refused(scheduler: str, reason: str) -> str:
    return f"--scheduler = {scheduler!r}: {reason}; {ACCEPTED}"


def _file_address(scheduler: str, path: Path) -> str:
    """The ``address`` of the scheduler file ``path`` (:class:`ConfigError` naming it where it
    holds none)."""
    try:
        text = path.read_text()
        data = json.loads(text) if text.strip() else {}
    except OSError as error:
        raise ConfigError([_not_a_file(scheduler, error.strerror or str(error))]) from None
    except ValueError as error:  # UnicodeDecodeError too
        raise ConfigError([_not_a_file(scheduler, f"not JSON: {error}")]) from None
    address = data.get("address") if isinstance(data, dict) else None
    if not isinstance(address, str) or not address:
        raise ConfigError(
            [_not_a_file(scheduler, 'it has no "address"' if text.strip() else "it is empty")]
        )
    return address


def _no_answer(scheduler: str, timeout: float, reason: str) -> str:
    return (
        f"--scheduler = {scheduler!r}: no Dask scheduler answers there within {timeout:g} s "
        f"({reason}); start one with `dask scheduler`"
    )


def _not_a_file(scheduler: str, reason: str) -> str:
    return (
        f"--scheduler = {scheduler!r}: not a Dask scheduler file ({reason}); `dask scheduler "
        "--scheduler-file FILE` writes one"
    )


def check_scheduler(scheduler: str, address: str, timeout: float = CONNECT_TIMEOUT) -> None:
    """Raise :class:`ConfigError` unless a Dask scheduler answers at ``address`` (from
    ``scheduler``) within ``timeout``: Dask's client retries a refused port until its timeout and
    waits without end for the greeting of a server that says nothing, and a name lookup has no
    timeout of its own, so all are asked here first, on a thread given up at the deadline.

    Parameters
    ----------
    scheduler : str
        The scheduler as the user gave it, for the messages.
    address : str
        Its address (:func:`scheduler_address`).
    timeout : float, default :data:`CONNECT_TIMEOUT`
        Seconds [s] for every step: the name looked up, the port connected, Dask's greeting.

    Raises
    ------
    foldopt.ConfigError
        Where ``address`` is no address, no server answers there, or what answers is not a Dask
        scheduler.
    """
    reason = _address_fault(address)
    if reason is not None:
        raise ConfigError([_refused(scheduler, reason)])
    host, port = _host_port(address)
    deadline = time.monotonic() + timeout
    reached = threading.Event()

    def ask():
        socket.create_connection((host, port), timeout=timeout).close()
        reached.set()
        return _identity(address, max(deadline - time.monotonic(), 0.1))

    try:
        identity = _on_a_thread(ask, timeout)
    except OSError as error:  # socket.timeout and TimeoutError too
        if not reached.is_set():
            why = "timed out" if isinstance(error, TimeoutError) else error.strerror
            raise ConfigError(
                [_no_answer(scheduler, timeout, why or type(error).__name__)]
            ) from None
        identity = None
    if not (isinstance(identity, dict) and identity.get("type") == "Scheduler"):
        raise ConfigError(
            [
                f"--scheduler = {scheduler!r}: what listens at {address} is not a Dask scheduler "
                "(it gave no Dask answer); give the scheduler's address or its scheduler file"
            ]
        )


def _on_a_thread(function, seconds: float):
    """``function()`` on a daemon thread: its result, or its exception raised here, or
    :class:`TimeoutError` after ``seconds`` (the thread, stuck in a name lookup say, is left to end
    by itself: as a daemon it does not keep the process alive)."""
    outcome = {}

    def run():
        try:
            outcome["result"] = function()
        except BaseException as error:  # raised again in the caller's thread
            outcome["error"] = error

    thread = threading.Thread(target=run, name="foldopt: ask the scheduler", daemon=True)
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        raise TimeoutError
    if "error" in outcome:
        raise outcome["error"]
    return outcome["result"]


def _identity(address: str, seconds: float):
    """What the Dask server at ``address`` says it is, or None where no Dask answer comes within
    ``seconds``. Runs an event loop of its own (on :func:`_on_a_thread`'s thread), so that a
    caller's event loop (a notebook's) does not matter."""
    import asyncio

    from distributed.comm import connect as open_comm
    from distributed.security import Security

    async def ask():
        comm = await open_comm(address, timeout=seconds, **Security().get_connection_args("client"))
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    try:
        return asyncio.run(asyncio.wait_for(ask(), seconds))
    # whatever a server that is not Dask's sends (garbage can fail in many ways)
    except Exception:
        return None
