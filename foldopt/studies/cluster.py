"""A map (:mod:`foldopt.studies.worldmap`) run on a Dask cluster, in chunks that survive faults.

The sites are cut into chunks of a few seconds of work each. A chunk ships only its site list and the map's
:class:`~foldopt.inputs.study.Study` (a few kilobytes pickled), never arrays: every worker builds its own
skies. Workers compute; the client alone writes, so a cluster needs no shared file system. Each finished chunk
is written at once, atomically, as a Parquet part (``parts/part-NNNNN.parquet``); the final tables are
assembled from the parts on disk, so an interrupted run resumed with ``resume=True`` computes only the missing
chunks and gives the same bytes as an uninterrupted one; a part carries the digest of its map, so that a part
of another map is computed again, never mixed in. A map that replaces another (``overwrite``) is built in a
staging folder beside it and swapped in once complete (:mod:`foldopt.files`); one process at a time writes a
folder. A worker that dies takes nothing with it: Dask runs its chunks elsewhere, and a part is written once
per chunk.

Without a scheduler address the work goes to an embedded :class:`distributed.LocalCluster`, one single-threaded
worker process per core; with one, to that cluster (``dask scheduler`` and ``dask worker`` by hand,
dask-jobqueue, Kubernetes...), reached through :mod:`foldopt.studies.dask_client`. Each task runs the compiled
kernel on one thread: the parallelism is Dask's.
"""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
import time
from contextlib import ExitStack
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from foldopt.errors import ConfigError, OutputError, redacted
from foldopt.inputs.study import Study
from foldopt.files import (
    DiskFullError,
    check_output,
    commit,
    discard,
    is_full,
    new_staging,
    tree_size,
    versions,
    write_atomically,
    writing,
)
from foldopt.studies.dask_client import (
    CONNECT_TIMEOUT,
    WORKER_MODULES,
    check_cluster,
    connect,
    start_worker_server,
)
from foldopt.studies.map_request import MapSpec
from foldopt.tables import write_csv

PARTS = "parts"
#: What a chunk's task imports (:func:`evaluate_chunk`, foldopt's engine on first use): the embedded
#: cluster's worker processes are forked with them imported (start_worker_server).
TASK_MODULES = (
    *WORKER_MODULES,
    __name__,
    "numba",
    # numba's implementations, which its first compilation imports (a cached kernel's load too)
    "numba.cpython.listobj",
    "numba.cpython.charseq",
    "numba.np.arraymath",
    "pvlib",
    "foldopt.studies.worldmap",
    "foldopt.engine.kernel",
    "foldopt.engine.incidence",
    "foldopt.engine.curve_reduction",
    "foldopt.physics.clearsky",
    "foldopt.physics.spa_site",
    "foldopt.physics.tracker_moves",
)
#: Key of the map's digest (:attr:`MapSpec.key`) in the metadata of its Parquet files.
MAP_KEY = b"foldopt.map_key"


@dataclass(frozen=True)
class MapRun:
    """A finished map: its table and how it was computed."""

    spec: MapSpec
    table: pd.DataFrame
    out: Path
    computed: tuple  # chunks computed by this run
    from_disk: tuple  # chunks a previous run had finished
    seconds: float
    cluster: str
    dashboard: str | None


def evaluate_chunk(
    study: Study, sites: list, loads: list, relative: bool, year: int, engine: str
) -> pd.DataFrame:
    """The task of one chunk, run on a worker: :func:`foldopt.studies.worldmap.evaluate_sites` on one thread.

    Parameters
    ----------
    study, sites, loads, relative, year, engine
        As :func:`~foldopt.studies.worldmap.evaluate_sites` takes them (:class:`MapSpec`'s fields;
        ``sites`` the chunk's).

    Returns
    -------
    pandas.DataFrame
        The chunk's rows, per site, load and period.
    """
    import numba

    from foldopt.studies.worldmap import evaluate_sites

    numba.set_num_threads(1)
    _keep_freed_memory()
    return evaluate_sites(study, sites, loads, relative, year, engine)


def _keep_freed_memory() -> None:
    """Let glibc reuse freed memory for the next arrays rather than hand it back to the system.

    A Dask nanny starts its worker with ``MALLOC_TRIM_THRESHOLD_=65536``, which also fixes glibc's mmap threshold
    at its default: every array above 128 KiB is then a fresh mmap whose pages fault in one by one. A map
    allocates many such arrays per site and ran at half speed, the difference all system time
    (``docs/performance.rst``). Thresholds of 32 MiB (mmap) and 128 MiB (trim) keep a site's
    arrays on the heap and bound what a worker holds back. Elsewhere than glibc, nothing is done."""
    import ctypes
    import ctypes.util

    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return
    m_trim_threshold, m_mmap_threshold = -1, -3  # glibc's malloc.h
    mallopt(m_mmap_threshold, 32 << 20)
    mallopt(m_trim_threshold, 128 << 20)


def _part_path(out: Path, index: int) -> Path:
    return out / PARTS / f"part-{index:05d}.parquet"


def _write_parquet(frame: pd.DataFrame, path: Path, key: str) -> None:
    """Write ``frame`` with the digest of its map (:attr:`MapSpec.key`) in the file's metadata."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_pandas(frame, preserve_index=False)
    table = table.replace_schema_metadata({**(table.schema.metadata or {}), MAP_KEY: key.encode()})

    def write(temporary: Path) -> None:
        # pyarrow keeps a file it opened itself open in the error of a failed write (a full
        # disk): a file of ours is closed as the write fails.
        with open(temporary, "wb") as file:
            pq.write_table(table, file)

    write_atomically(path, write)


def _read_part(path: Path, key: str) -> pd.DataFrame | None:
    """A part of the map ``key`` on disk, or None where it is missing, cannot be read (a disk
    fault) or belongs to another map: then it is computed again."""
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(path)
    except (OSError, ValueError):
        return None
    if (table.schema.metadata or {}).get(MAP_KEY) != key.encode():
        return None
    return table.to_pandas()


def map_folder(out: Path, resume: bool, overwrite: bool) -> bool:
    """Whether the map is built in ``out`` itself: to resume the map there, or where there is none,
    so that a killed run leaves a folder that a later ``resume`` recognises; otherwise it replaces
    ``out`` (``overwrite``) from a staging folder beside it, so that the earlier folder stays whole
    until the new one is complete (:func:`foldopt.files.commit`). Nothing is written.

    Parameters
    ----------
    out : pathlib.Path
        The map's results folder.
    resume : bool
        Finish the map in ``out`` where it has a ``run.json``.
    overwrite : bool
        Replace ``out`` (a folder foldopt wrote).

    Returns
    -------
    bool
        True to build the map in ``out``, False to replace it.

    Raises
    ------
    foldopt.errors.OutputError
        Where ``out`` exists and neither ``resume`` nor ``overwrite`` is given, or cannot take the
        map (:func:`foldopt.files.check_output`: a file, a folder of other files...).
    """
    out = Path(out)
    if resume and (out / "run.json").exists():
        return True
    # only a folder foldopt wrote is replaced
    check_output(
        out, overwrite or resume, "pass --resume to finish it or --overwrite to replace it"
    )
    return not out.exists()


def chunks_on_disk(out: Path, spec: MapSpec) -> list[int]:
    """The chunks of the map ``spec`` whose parts ``out`` holds, read without writing anything;
    a part that cannot be read (a disk fault) or is another map's is not one of them.

    Parameters
    ----------
    out : pathlib.Path
        A map's folder (one with a ``run.json``).
    spec : MapSpec

    Returns
    -------
    list of int
        The chunks' indices.

    Raises
    ------
    foldopt.errors.OutputError
        Where ``out`` holds another map (its :attr:`MapSpec.key` differs).
    """
    try:
        previous = json.loads((out / "run.json").read_text())
    except (OSError, ValueError):
        previous = {}
    if not isinstance(previous, dict) or previous.get("map_key") != spec.key:
        theirs = previous.get("spec", {}) if isinstance(previous, dict) else {}
        differ = [
            name
            for name in ("study", "sites", "loads", "relative", "year", "sites_per_chunk", "engine")
            if json.dumps(theirs.get(name), sort_keys=True, default=str)
            != json.dumps(spec.as_dict()[name], sort_keys=True, default=str)
        ]
        raise OutputError(
            f"--resume: {out} holds another map (its {', '.join(differ) or 'settings'} differ); "
            "run the same command to resume it, or choose another --out"
        )
    return [
        index
        for index in range(len(spec.chunks()))
        if _read_part(_part_path(out, index), spec.key) is not None
    ]


def _start_folder(folder: Path, spec: MapSpec, metadata: dict) -> None:
    """A new map's folder: ``parts/``, ``sites.csv`` and ``run.json`` (status ``running``)."""
    (folder / PARTS).mkdir(parents=True)
    pd.DataFrame(list(spec.sites)).to_csv(folder / "sites.csv", index=False)
    _write_json(folder / "run.json", {**metadata, "status": "running"})


def _clear_parts(folder: Path) -> None:
    """Make a resumed map's ``parts/`` ready: the parts a killed writer left half-written go (one
    writer at a time holds the folder: :func:`foldopt.files.writer_lock`)."""
    (folder / PARTS).mkdir(exist_ok=True)
    for leftover in (folder / PARTS).glob(".*.tmp-*"):
        leftover.unlink(missing_ok=True)


def _write_json(path: Path, data: dict) -> None:
    text = json.dumps(redacted(data), indent=2, default=str) + "\n"  # no password in run.json
    write_atomically(path, lambda temporary: temporary.write_text(text))


def run_map(
    spec: MapSpec,
    out: Path,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    resume: bool = False,
    overwrite: bool = False,
    progress: Callable[[int, int], None] | None = None,
    announce: Callable[[str, str | None], None] | None = None,
    metadata: dict | None = None,
    connect_timeout: float = CONNECT_TIMEOUT,
    finish: Callable[[MapRun, dict], None] | None = None,
) -> MapRun:
    """Compute a map on a Dask cluster into ``out`` and return its table.

    A run that fails changes nothing that was there: the cluster is reached before anything is
    written; a map replacing another is built beside it; a map finished in ``out`` (a new one, or
    one resumed) gets its parts there as they come, each whole, and its tables, figures and
    ``run.json`` (written last) from a staging folder once all are written. A resumed folder's
    earlier files are never rewritten but by a run that completes.

    Parameters
    ----------
    spec : MapSpec
    out : pathlib.Path
        The results folder: ``run.json``, ``sites.csv``, ``parts/`` and, when every chunk is
        done, ``map.parquet`` and ``map.csv``.
    scheduler : str, optional
        A scheduler's address or scheduler file; default an embedded cluster of ``workers``.
    workers : int, optional
        Worker processes of the embedded cluster; not with ``scheduler``.
    resume : bool
        Finish the map in ``out``, computing only the chunks it lacks.
    overwrite : bool
        Replace ``out`` (a folder foldopt wrote), once the new map is complete.
    progress : callable, optional
        ``progress(sites done, sites)``.
    announce : callable, optional
        ``announce(cluster description, dashboard address or None)`` once connected.
    metadata : dict, optional
        Written into ``run.json`` beside the spec.
    connect_timeout : float
        Seconds [s] to reach ``scheduler``
        (:data:`foldopt.studies.dask_client.CONNECT_TIMEOUT`).
    finish : callable, optional
        ``finish(run, metadata)`` writes the rest of what the map promises (its figures, ``map.nc``,
        ``report.html``) in ``run.out``, given the ``run.json`` it is about to get. It runs before
        the map is marked complete and before it replaces an earlier one: a map whose figures fail
        is no complete map, and leaves the earlier map as it was.

    Returns
    -------
    MapRun
        ``table`` (the rows of :func:`foldopt.studies.worldmap.evaluate_sites` for every site, in site
        order), the chunks computed and found on disk, seconds, the cluster and its dashboard.

    Raises
    ------
    foldopt.errors.ConfigError
        Where ``scheduler`` is no address or scheduler file (before any folder is touched), no Dask
        scheduler with a worker answers there, or it is lost mid-run (the parts done are kept).
    foldopt.errors.OutputError
        Where ``out`` cannot take the map, another run writes it, or the file system fills.
    """
    started = time.perf_counter()
    out = Path(out)
    check_cluster(scheduler, workers)
    chunks = spec.chunks()
    metadata = {
        **(metadata or {}),
        "versions": versions(("dask", "distributed", "pyarrow")),
        "map_key": spec.key,
        "spec": spec.as_dict(),
        "chunks": len(chunks),
    }
    with writing(out):
        in_place = map_folder(out, resume, overwrite)
        resuming = in_place and out.exists()
        done = chunks_on_disk(out, spec) if resuming else []
        missing = [index for index in range(len(chunks)) if index not in done]
        if missing and scheduler is None:
            start_worker_server(TASK_MODULES)  # its imports beside this process's work
        if progress is not None:
            progress(sum(len(chunks[index]) for index in done), len(spec.sites))
        folder = finals = None
        try:
            with ExitStack() as cluster:
                client, description, dashboard = None, NO_COMPUTATION, None
                if missing:
                    client, description = cluster.enter_context(
                        connect(scheduler, workers, connect_timeout)
                    )
                    dashboard = client.dashboard_link if _has_dashboard(client) else None
                    if announce is not None:
                        announce(description, dashboard)
                # Reached: only now is anything written.
                folder = out if in_place else new_staging(out)
                if resuming:
                    _clear_parts(folder)
                else:
                    _start_folder(folder, spec, metadata)
                if missing:
                    _compute_parts(client, spec, folder, missing, done, scheduler, progress)
            finals = new_staging(out) if in_place else folder
            run = _assemble(
                spec,
                folder,
                finals,
                metadata,
                computed=missing,
                done=done,
                started=started,
                description=description,
                dashboard=dashboard,
                finish=finish,
            )
            if in_place:
                _move_into(finals, out)
            else:
                commit(folder, out)
        except BaseException as error:
            raise _failed(error, out, folder, finals, fresh=not resuming) from None
        if in_place:
            discard(finals)
    return dataclasses.replace(run, out=out)


#: A map's cluster where every chunk was on disk.
NO_COMPUTATION = "no computation (every chunk was on disk)"


def _failed(
    error: BaseException, out: Path, folder: Path | None, finals: Path | None, fresh: bool
) -> BaseException:
    """Clear up after a failed map and return the error to raise: the staging folders go, and so
    does a new folder in ``out`` with no part done; a full file system is
    :class:`~foldopt.files.DiskFullError` naming ``out``."""
    written, kept = getattr(error, "written", 0), False
    if finals is not None and finals != folder:
        written += discard(finals)
    if folder is not None and folder != out:
        written += discard(folder)
    elif folder is not None:
        written += tree_size(out)
        kept = not fresh or any((out / PARTS).glob("part-*"))
        if not kept:
            shutil.rmtree(out, ignore_errors=True)  # nothing done: leave nothing behind
    if is_full(error):
        return DiskFullError(out, written, "finish the map with --resume" if kept else "run again")
    return error


def _compute_parts(client, spec, folder, missing, done, scheduler, progress) -> None:
    """Compute the chunks ``missing`` on ``client``'s cluster, writing each part in ``folder`` as
    it comes. A task's own error is raised as it is (a bad weather file's :class:`ConfigError`
    names it); a chunk that killed every worker that ran it, or a scheduler lost mid-run, is one
    error saying so."""
    from distributed import KilledWorker, as_completed

    chunks = spec.chunks()
    finished_sites = sum(len(chunks[index]) for index in done)
    futures = [
        client.submit(
            evaluate_chunk,
            spec.study,
            [spec.sites[i] for i in chunks[index]],
            list(spec.loads),
            spec.relative,
            spec.year,
            spec.engine,
            key=f"foldopt-map-{spec.key}-{index:05d}",
            pure=False,
        )
        for index in missing
    ]
    index_of = {future.key: index for future, index in zip(futures, missing, strict=True)}
    new_parts = 0
    for future in as_completed(futures):
        index = index_of[future.key]
        try:
            frame = future.result()
        except KilledWorker as error:
            sites = chunks[index]
            raise RuntimeError(
                f"the map's worker processes died while computing it (chunk {index}, sites "
                f"{sites[0]} to {sites[-1]}, was running each time): a crash, or too little memory"
            ) from error
        except Exception as error:
            if future.status == "error" or scheduler is None:
                raise  # the task's own error; or the embedded cluster's, an internal fault
            # Cancelled as the client lost its scheduler, or the connection reset as it gathered.
            kept = len(done) + new_parts
            then = (
                f"the {kept} of {len(chunks)} chunks done are kept: start it again and finish the "
                "map with --resume"
                if kept
                else "no chunk was done: start it again and run the map again"
            )
            raise ConfigError(
                [
                    f"--scheduler = {scheduler!r}: the scheduler was lost mid-run "
                    f"({getattr(error, 'reason', None) or type(error).__name__}); {then}"
                ]
            ) from None
        _write_parquet(frame, _part_path(folder, index), spec.key)
        future.release()
        new_parts += 1
        finished_sites += len(chunks[index])
        if progress is not None:
            progress(finished_sites, len(spec.sites))


def _assemble(
    spec, folder, finals, metadata, *, computed, done, started, description, dashboard, finish
) -> MapRun:
    """Assemble the map's tables from the parts in ``folder`` and write them, ``finish``'s files
    and lastly ``run.json`` (status ``complete``) in ``finals``."""
    chunks = spec.chunks()
    table = pd.concat(
        [_read_part(_part_path(folder, index), spec.key) for index in range(len(chunks))],
        ignore_index=True,
    )
    seconds = time.perf_counter() - started
    _write_parquet(table, finals / "map.parquet", spec.key)
    write_atomically(finals / "map.csv", lambda temporary: write_csv(table, temporary))
    computed = tuple(computed)
    complete = {
        **metadata,
        "status": "complete",
        "cluster": description,
        "dashboard": dashboard,
        "chunks_computed": list(computed),
        "chunks_from_disk": sorted(done),
        "seconds": round(seconds, 3),
        "sites_per_second": round(sum(len(chunks[i]) for i in computed) / seconds, 3)
        if computed
        else None,
    }
    run = MapRun(
        spec, table, finals, computed, tuple(sorted(done)), seconds, description, dashboard
    )
    if finish is not None:
        finish(run, complete)
    # last: only a folder holding every promised file is complete
    _write_json(finals / "run.json", complete)
    return run


def _move_into(finals: Path, out: Path) -> None:
    """Move the files of ``finals`` into ``out``, each by one atomic rename, ``run.json`` last."""
    names = sorted(path.name for path in finals.iterdir() if path.name != "run.json")
    for name in [*names, "run.json"]:
        os.replace(finals / name, out / name)


def _has_dashboard(client) -> bool:
    """Whether the scheduler serves the dashboard (it needs bokeh)."""
    try:
        return bool(client.scheduler_info().get("services", {}).get("dashboard"))
    except (OSError, TimeoutError, AttributeError):
        return False
