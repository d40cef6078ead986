"""Maps under faults (issue 21): a replacement that fails leaves the earlier map as it was, a part
of another map is never mixed in, one process writes a folder, a full file system is one line and
never a "complete" map that is not, and a scheduler address that is wrong fails fast. The cluster
is a LocalCluster of this process on 127.0.0.1; servers that are not Dask are sockets of this
process; the full file system is a tmpfs, unmounted in a finally."""

from __future__ import annotations

import hashlib
import json
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pandas as pd
import pytest

from foldopt.studies.cluster import run_map
from foldopt.studies.worldmap import MapSpec
from foldopt.studies.dask_client import connect
from foldopt.errors import ConfigError
from foldopt.errors import OutputError
from test_faults_files import HOLDS_THE_LOCK

distributed = pytest.importorskip("distributed")

STUDY = {"name": "x", "panel": {"area": 0.1}, "sky": "ineichen", "mode": "exact", "step_min": 60,
         "fold_angles": {"start": 90, "stop": 180, "step": 90}}
SITES = ({"latitude": 0.0, "longitude": 0.0}, {"latitude": 30.0, "longitude": 10.0})


def spec(loads=(1.0,), sites=SITES) -> MapSpec:
    return MapSpec(STUDY, sites, loads, sites_per_chunk=1, engine="numpy")


def snapshot(folder: Path) -> dict[str, str]:
    return {str(path.relative_to(folder)): hashlib.sha256(path.read_bytes()).hexdigest()
            for path in sorted(folder.rglob("*")) if path.is_file()}


@pytest.fixture(scope="module")
def finished(scheduler, tmp_path_factory) -> Path:
    """A complete map of :func:`spec`, two chunks."""
    out = tmp_path_factory.mktemp("finished") / "map"
    run_map(spec(), out, scheduler=scheduler)
    return out


def earlier_map(finished: Path, folder: Path) -> dict[str, str]:
    shutil.copytree(finished, folder)
    return snapshot(folder)


def _refused_address() -> str:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return f"tcp://127.0.0.1:{probe.getsockname()[1]}"  # closed at once: nothing listens there


def test_an_overwrite_that_cannot_connect_leaves_the_earlier_map(finished, tmp_path):
    out = tmp_path / "map"
    before = earlier_map(finished, out)
    with pytest.raises(ConfigError, match="no Dask scheduler answers there"):
        run_map(spec(loads=(2.0,)), out, scheduler=_refused_address(), overwrite=True)
    assert snapshot(out) == before and sorted(path.name for path in tmp_path.iterdir()) == ["map"]


def test_an_overwrite_that_meets_a_broken_weather_file_leaves_the_earlier_map(finished, scheduler, tmp_path):
    broken = tmp_path / "broken.epw"
    broken.write_text("LOCATION,x\nnot a weather file\n")
    out = tmp_path / "map"
    before = earlier_map(finished, out)
    with pytest.raises(ConfigError, match="broken.epw"):
        run_map(spec(sites=(SITES[0], {**SITES[1], "weather": str(broken)})), out, scheduler=scheduler,
                overwrite=True)
    assert snapshot(out) == before and sorted(path.name for path in tmp_path.iterdir()) == ["broken.epw", "map"]


def test_resume_recomputes_a_part_of_another_map(finished, scheduler, tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    out = tmp_path / "map"
    shutil.copytree(finished, out)
    # Chunk 1 as another map (other loads) wrote it, with that map's digest.
    part = out / "parts" / "part-00001.parquet"
    foreign = pd.read_parquet(part).assign(p_load_w=2.0)
    table = pa.Table.from_pandas(foreign, preserve_index=False)
    pq.write_table(table.replace_schema_metadata({b"foldopt.map_key": spec(loads=(2.0,)).key.encode()}), part)
    resumed = run_map(spec(), out, scheduler=scheduler, resume=True)
    assert resumed.computed == (1,) and resumed.from_disk == (0,)
    assert (out / "map.csv").read_bytes() == (finished / "map.csv").read_bytes()
    assert (resumed.table["p_load_w"] == 1.0).all()


def test_a_second_map_of_one_folder_is_refused_naming_the_first(tmp_path):
    out = tmp_path / "map"
    holder = subprocess.Popen([sys.executable, "-c", HOLDS_THE_LOCK, str(out)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline() == "locked\n"
        with pytest.raises(OutputError, match=f"another foldopt run \\(pid {holder.pid} on "):
            run_map(spec(), out, scheduler=_refused_address())
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.communicate(timeout=30)
    assert not out.exists()


# --- full file systems ------------------------------------------------------------------------------


# small_disk: a 2 MB tmpfs (tests/conftest.py).


def _fill(disk: Path, leave: int) -> None:
    """Fill ``disk`` but for about ``leave`` bytes."""
    free = shutil.disk_usage(disk).free
    (disk / "filler").write_bytes(b"\0" * max(0, free - leave))


def test_a_full_disk_never_leaves_a_complete_map_that_is_not(finished, small_disk):
    # A run killed after its last part: every part on disk, no table yet; the disk then fills.
    out = small_disk / "map"
    shutil.copytree(finished, out)
    (out / "map.parquet").unlink()
    (out / "map.csv").unlink()
    run_json = json.loads((out / "run.json").read_text())
    (out / "run.json").write_text(json.dumps({**run_json, "status": "running"}))
    _fill(small_disk, 12_000)
    with pytest.raises(OutputError) as raised:
        run_map(spec(), out, resume=True)  # nothing to compute: no cluster
    message = str(raised.value)
    assert "\n" not in message and message.startswith(f"--out {out}: the file system is full")
    assert re.search(r"need more than [\d.]+ [kM]B free there", message) and message.endswith("with --resume")
    assert json.loads((out / "run.json").read_text())["status"] == "running"
    assert not list(out.rglob(".*tmp*"))


def test_a_full_disk_keeps_the_earlier_map_of_an_overwrite(finished, scheduler, small_disk):
    out = small_disk / "map"
    before = earlier_map(finished, out)
    _fill(small_disk, 0)
    with pytest.raises(OutputError, match=f"^--out {out}: the file system is full"):
        run_map(spec(loads=(2.0,)), out, scheduler=scheduler, overwrite=True)
    assert snapshot(out) == before
    assert sorted(path.name for path in small_disk.iterdir()) == ["filler", "map"]


# --- scheduler addresses ----------------------------------------------------------------------------


def _connect_error(address: str) -> tuple[list[str], float]:
    started = time.monotonic()
    with pytest.raises(ConfigError) as raised:
        with connect(address):
            pytest.fail(f"connected to {address}")
    return raised.value.errors, time.monotonic() - started


@pytest.fixture(params=["silent", "garbage"])
def not_dask(request):
    """A TCP server on 127.0.0.1 that accepts and says nothing, or sends garbage; yields its address."""
    server = socket.create_server(("127.0.0.1", 0))
    server.settimeout(0.05)  # so that the thread sees the stop soon: closing a socket does not end accept()
    stop, accepted = threading.Event(), []

    def serve():
        while not stop.is_set():
            try:
                connection, _ = server.accept()
            except TimeoutError:
                continue
            accepted.append(connection)
            if request.param == "garbage":
                connection.sendall(b"HTTP/1.1 400 Bad Request\r\n\r\n" * 50)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        yield f"tcp://127.0.0.1:{server.getsockname()[1]}"
    finally:
        stop.set()
        thread.join(timeout=5)
        server.close()
        for connection in accepted:
            connection.close()


def test_a_refused_port_fails_within_2_s():
    errors, seconds = _connect_error(_refused_address())
    assert len(errors) == 1 and "no Dask scheduler answers there" in errors[0] and "refused" in errors[0]
    assert seconds < 2, seconds


def test_a_server_that_is_not_dask_fails_within_10_s(not_dask):
    errors, seconds = _connect_error(not_dask)
    assert len(errors) == 1 and f"what listens at {not_dask} is not a Dask scheduler" in errors[0]
    assert seconds < 10, seconds


@pytest.mark.parametrize("content,reason", [("", "it is empty"), ("{garbage", "not JSON"),
                                            ('{"id": "x"}', 'it has no "address"'), ("[1, 2]", 'no "address"'),
                                            ("\x00\xff\xfe", "not JSON")])
def test_a_scheduler_file_without_an_address_is_one_line_naming_it(tmp_path, content, reason):
    path = tmp_path / "scheduler.json"
    path.write_bytes(content.encode("latin-1"))
    errors, seconds = _connect_error(str(path))
    assert len(errors) == 1 and str(path) in errors[0] and reason in errors[0] and "\n" not in errors[0]
    assert seconds < 2, seconds
