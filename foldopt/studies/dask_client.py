"""A Dask client of the cluster a map runs on (:mod:`foldopt.studies.cluster`): an embedded
:class:`distributed.LocalCluster`, or the cluster of a scheduler named by its address or its
scheduler file. The scheduler is asked first, in bounded time, whether it is there and is Dask's,
so that a wrong address fails in seconds with a message saying what to start, rather than after
Dask's own retries or never.
"""

from __future__ import annotations

import json
import logging
import os
import socket
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from pathlib import Path

from foldopt.errors import ConfigError

#: Seconds to wait for a cluster's scheduler and its first worker.
CONNECT_TIMEOUT = 30
#: Seconds a scheduler has to answer foldopt's first message: Dask answers in milliseconds, while
#: a server of another kind may never answer.
HANDSHAKE_TIMEOUT = 5.0


@contextmanager
def connect(
    scheduler: str | None = None, workers: int | None = None, timeout: float = CONNECT_TIMEOUT
):
    """A Dask client: of the cluster at ``scheduler`` (``tcp://host:port`` or a scheduler file), or of an
    embedded :class:`distributed.LocalCluster` of ``workers`` single-threaded processes (default one per core).

    Parameters
    ----------
    scheduler : str, optional
        A scheduler's address or scheduler file (:func:`scheduler_address`); default an embedded cluster.
    workers : int, optional
        Worker processes of the embedded cluster; default one per core.
    timeout : float, default :data:`CONNECT_TIMEOUT`
        Seconds [s] to wait for ``scheduler`` and its first worker.

    Yields
    ------
    tuple of (distributed.Client, str)
        The client, closed (with the embedded cluster) when the block ends, and the cluster's description.

    Raises
    ------
    foldopt.ConfigError
        When no scheduler with a worker answers within ``timeout``, at once where the port refuses, and
        within :data:`HANDSHAKE_TIMEOUT` where what listens is not a Dask scheduler.
    """
    from distributed import Client, LocalCluster

    if scheduler is None:
        count = workers or os.cpu_count() or 1
        cluster = LocalCluster(
            n_workers=count,
            threads_per_worker=1,
            processes=True,
            dashboard_address="127.0.0.1:0",
            silence_logs=logging.ERROR,
        )
        try:
            with Client(cluster) as client:
                yield (
                    client,
                    f"embedded LocalCluster, {count} worker process{'es' if count > 1 else ''}",
                )
        finally:
            cluster.close()
        return
    address = scheduler_address(scheduler)
    check_scheduler(scheduler, address, timeout)
    try:
        client = Client(address, timeout=timeout)
    except (OSError, TimeoutError, ValueError) as error:
        raise ConfigError([_no_answer(scheduler, timeout, error.__class__.__name__)]) from None
    try:
        try:
            client.wait_for_workers(1, timeout=timeout)
        except TimeoutError:
            raise ConfigError(
                [
                    f"--scheduler = {scheduler!r}: the scheduler has no worker after {timeout:g} s; start "
                    "some with `dask worker ADDRESS`"
                ]
            ) from None
        yield client, f"Dask scheduler {client.scheduler.address}"
    finally:
        client.close()


def _no_answer(scheduler: str, timeout: float, reason: str) -> str:
    return (
        f"--scheduler = {scheduler!r}: no Dask scheduler answers there within {timeout:g} s ({reason}); start one "
        "with `dask scheduler`"
    )


def scheduler_address(scheduler: str) -> str:
    """The address ``scheduler`` gives: itself, or the ``address`` of the scheduler file it names
    (:class:`ConfigError` naming the file where it holds none).

    Parameters
    ----------
    scheduler : str
        ``tcp://host:port`` or the path of a scheduler file.
    """
    path = Path(scheduler)
    if not path.is_file():
        return scheduler
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


def _not_a_file(scheduler: str, reason: str) -> str:
    return (
        f"--scheduler = {scheduler!r}: not a Dask scheduler file ({reason}); `dask scheduler --scheduler-file "
        "FILE` writes one"
    )


def check_scheduler(scheduler: str, address: str, timeout: float) -> None:
    """Raise :class:`ConfigError` unless a Dask scheduler answers at ``address`` (from
    ``scheduler``): Dask's client retries a refused port until its timeout and waits without end
    for the greeting of a server that says nothing, so both are asked here first, in bounded time.

    Parameters
    ----------
    scheduler : str
        The scheduler as the user gave it, for the messages.
    address : str
        Its address (:func:`scheduler_address`).
    timeout : float
        Seconds [s] the caller waits; the scheduler has at most :data:`HANDSHAKE_TIMEOUT` of them
        to answer.

    Raises
    ------
    foldopt.ConfigError
        Where ``address`` is no address, its port refuses, or what listens there is not a Dask
        scheduler.
    """
    from distributed.comm import parse_address, parse_host_port

    try:
        scheme, location = parse_address(address)
        host, port = parse_host_port(location) if scheme in ("tcp", "tls") else (None, None)
    except ValueError as error:
        raise ConfigError(
            [
                f"--scheduler = {scheduler!r}: neither an existing scheduler file nor an "
                f"address like tcp://host:8786 ({error})"
            ]
        ) from None
    seconds = min(timeout, HANDSHAKE_TIMEOUT)
    if host is not None:
        try:
            socket.create_connection((host, port), timeout=seconds).close()
        except OSError as error:
            raise ConfigError(
                [_no_answer(scheduler, timeout, error.strerror or error.__class__.__name__)]
            ) from None
    identity = _identity(address, seconds)
    if not (isinstance(identity, dict) and identity.get("type") == "Scheduler"):
        raise ConfigError(
            [
                f"--scheduler = {scheduler!r}: what listens at {address} is not a Dask scheduler (no Dask "
                f"answer within {seconds:g} s); give the scheduler's address or its scheduler file"
            ]
        )


def _identity(address: str, seconds: float):
    """What the Dask server at ``address`` says it is, or None where no Dask answer comes within
    ``seconds``. Runs on a thread of its own, so that a caller's event loop (a notebook's) does
    not matter."""
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

    with ThreadPoolExecutor(1) as pool:
        try:
            return pool.submit(asyncio.run, asyncio.wait_for(ask(), seconds)).result()
        # whatever a server that is not Dask's sends (garbage can fail in many ways)
        except Exception:
            return None
