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
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from foldopt.errors import ConfigError, OutputError, redacted
from foldopt.inputs.study import Study
from foldopt.files import (
    DiskFullError,
    check_output,
    clear_leftovers,
    commit,
    discard,
    is_full,
    new_staging,
    tree_size,
    versions,
    write_atomically,
    writer_lock,
)
from foldopt.studies.dask_client import CONNECT_TIMEOUT, connect
from foldopt.studies.worldmap import MapSpec
from foldopt.tables import write_csv

PARTS = "parts"
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
    allocates many such arrays per site and ran at half speed (0.49 against 0.25 s a site, the difference all
    system time). Thresholds of 32 MiB (mmap) and 128 MiB (trim) keep a site's arrays on the heap and bound
    what a worker holds back. Elsewhere than glibc, nothing is done."""
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
    write_atomically(path, lambda temporary: pq.write_table(table, temporary))


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


def map_folder(out: Path, resume: bool, overwrite: bool) -> Path:
    """The folder to build the map in: ``out`` itself to resume the map there or where there is none, so that a
    killed run leaves a folder that a later ``resume`` recognises; a staging folder beside ``out`` where the map
    replaces one (``overwrite``), so that the earlier folder stays whole until the new one is complete
    (:func:`foldopt.files.commit`).

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
    pathlib.Path
        ``out``, or a staging folder beside it.

    Raises
    ------
    foldopt.errors.OutputError
        Where ``out`` exists and neither ``resume`` nor ``overwrite`` is given, or cannot take the
        map (:func:`foldopt.files.check_output`).
    """
    out = Path(out)
    if resume and (out / "run.json").exists():
        return out
    if out.exists() and not overwrite and not resume:
        raise OutputError(
            f"{out} already exists; pass --resume to finish it or --overwrite to replace it"
        )
    check_output(out, overwrite=True)  # only a folder foldopt wrote is replaced
    return new_staging(out) if out.exists() else out


def prepare_folder(folder: Path, spec: MapSpec, metadata: dict) -> list[int]:
    """Make ``folder`` (:func:`map_folder`) ready for the map and return the chunks already done
    there. A new map starts with ``run.json`` (status ``running``) and ``sites.csv``; a folder
    with a ``run.json`` is resumed, and refused if it holds another map.

    Parameters
    ----------
    folder : pathlib.Path
    spec : MapSpec
    metadata : dict
        What ``run.json`` holds beside its status.

    Returns
    -------
    list of int
        The indices of the chunks whose parts are on disk (none for a new map).

    Raises
    ------
    foldopt.errors.OutputError
        Where ``folder`` holds another map (its :attr:`MapSpec.key` differs).
    """
    if (folder / "run.json").exists():
        return _resumable(folder, spec, metadata)
    (folder / PARTS).mkdir(parents=True)
    pd.DataFrame(list(spec.sites)).to_csv(folder / "sites.csv", index=False)
    _write_json(folder / "run.json", {**metadata, "status": "running"})
    return []


def _resumable(out: Path, spec: MapSpec, metadata: dict) -> list[int]:
    """The chunks on disk in ``out`` if it holds the map ``spec`` (:func:`_compute` marks it
    ``running`` again where it is not complete)."""
    try:
        previous = json.loads((out / "run.json").read_text())
    except ValueError:
        previous = {}
    if previous.get("map_key") != spec.key:
        theirs = previous.get("spec", {})
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
    (out / PARTS).mkdir(exist_ok=True)
    for leftover in (out / PARTS).glob(".*.tmp-*"):
        leftover.unlink(missing_ok=True)
    return [index for index in range(len(spec.chunks())) if _part_path(out, index).exists()]


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

    Parameters
    ----------
    spec : MapSpec
    out : pathlib.Path
        The results folder: ``run.json``, ``sites.csv``, ``parts/`` and, when every chunk is
        done, ``map.parquet`` and ``map.csv``.
    scheduler : str, optional
        A scheduler's address or scheduler file; default an embedded cluster of ``workers``.
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
        Seconds to wait for ``scheduler`` and its first worker.
    finish : callable, optional
        ``finish(run, metadata)`` writes the rest of what the map promises (its figures, ``map.nc``,
        ``report.html``) in ``run.out``, given the ``run.json`` it is about to get. It runs before
        the map is marked complete and before it replaces an earlier one: a map whose figures fail
        is no complete map, and an ``overwrite`` then leaves the earlier map as it was.

    Returns
    -------
    MapRun
        ``table`` (the rows of :func:`foldopt.studies.worldmap.evaluate_sites` for every site, in site
        order), the chunks computed and found on disk, seconds, the cluster and its dashboard.

    Raises
    ------
    foldopt.errors.OutputError
        Where ``out`` cannot take the map, another run writes it, or the file system fills.
    """
    started = time.perf_counter()
    out = Path(out)
    chunks = spec.chunks()
    metadata = {
        **(metadata or {}),
        "versions": versions(("dask", "distributed", "pyarrow")),
        "map_key": spec.key,
        "spec": spec.as_dict(),
        "chunks": len(chunks),
    }
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputError(f"--out {out}: cannot create it ({error.strerror or error})") from None
    with writer_lock(out):
        clear_leftovers(out.parent)
        fresh, folder = not out.exists(), None
        try:
            folder = map_folder(out, resume, overwrite)
            done = prepare_folder(folder, spec, metadata)
            run = _compute(
                spec,
                folder,
                done,
                chunks,
                metadata,
                started,
                scheduler,
                workers,
                progress,
                announce,
                connect_timeout,
                finish,
            )
            if folder != out:
                commit(folder, out)
        except BaseException as error:
            raise _failed(error, out, folder, fresh) from None
    return dataclasses.replace(run, out=out)


def _failed(error: BaseException, out: Path, folder: Path | None, fresh: bool) -> BaseException:
    """Clear up after a failed map and return the error to raise: a staging folder goes, and so does
    a new folder in ``out`` with no part done; a full file system is
    :class:`~foldopt.files.DiskFullError` naming ``out``."""
    written, kept = getattr(error, "written", 0), False
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


def _compute(
    spec,
    out,
    done,
    chunks,
    metadata,
    started,
    scheduler,
    workers,
    progress,
    announce,
    connect_timeout,
    finish,
) -> MapRun:
    # A part that cannot be read (a disk fault) or is another map's is computed again.
    done = [index for index in done if _read_part(_part_path(out, index), spec.key) is not None]
    missing = [index for index in range(len(chunks)) if index not in done]
    if missing or json.loads((out / "run.json").read_text()).get("status") != "complete":
        # Until every file is written again the folder is no complete map; a complete map resumed with
        # nothing to compute stays marked complete, its files replaced one atomic file at a time by the
        # same map's (the same digest: the same numbers).
        _write_json(out / "run.json", {**metadata, "status": "running"})
    finished_sites = sum(len(chunks[index]) for index in done)
    if progress is not None:
        progress(finished_sites, len(spec.sites))
    description, dashboard = "no computation (every chunk was on disk)", None
    if missing:
        from distributed import as_completed

        with connect(scheduler, workers, connect_timeout) as (client, description):
            dashboard = client.dashboard_link if _has_dashboard(client) else None
            if announce is not None:
                announce(description, dashboard)
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
            for future in as_completed(futures):
                index = index_of[future.key]
                try:
                    frame = future.result()
                except ConfigError:
                    client.cancel(futures)
                    raise
                _write_parquet(frame, _part_path(out, index), spec.key)
                future.release()
                finished_sites += len(chunks[index])
                if progress is not None:
                    progress(finished_sites, len(spec.sites))
    table = pd.concat(
        [_read_part(_part_path(out, index), spec.key) for index in range(len(chunks))],
        ignore_index=True,
    )
    seconds = time.perf_counter() - started
    _write_parquet(table, out / "map.parquet", spec.key)
    write_atomically(out / "map.csv", lambda temporary: write_csv(table, temporary))
    computed = tuple(missing)
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
    run = MapRun(spec, table, out, computed, tuple(sorted(done)), seconds, description, dashboard)
    if finish is not None:
        finish(run, complete)
    # last: only a folder holding every promised file is complete
    _write_json(out / "run.json", complete)
    return run


def _has_dashboard(client) -> bool:
    """Whether the scheduler serves the dashboard (it needs bokeh)."""
    try:
        return bool(client.scheduler_info().get("services", {}).get("dashboard"))
    except (OSError, TimeoutError, AttributeError):
        return False
