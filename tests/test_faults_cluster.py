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
from foldopt.studies.map_request import MapSpec
from foldopt.studies.dask_client import connect
from foldopt.errors import ConfigError
from foldopt.errors import OutputError
from test_faults_files import HOLDS_THE_LOCK

distributed = pytest.importorskip("distributed")

STUDY = {"name": "x", "panel": {"area": 0.1}, "sky": "ineichen", "mode": "exact", "step_min": 60,
         "fold_angles": {"start": 90, "stop": 180, "step": 90}}
SITES = ({"latitude": 0.0, "longitude": 0.0}, {"latitude": 30.0, "longitude": 10.0})


def spec(loads=(1.0,), sites=SITES) -> MapSpec:
    """A map of a chunk a site, on a map's engine (``auto``: the compiled kernel, a site's year in
    some 0.1 s; the NumPy path took 0.3-0.6 s, and what a fault leaves does not hang on it)."""
    return MapSpec(STUDY, sites, loads, sites_per_chunk=1)


def snapshot(folder: Path) -> dict[str, tuple]:
    """Every file under ``folder``: its bytes' digest and the time it was last written [ns]."""
    return {str(path.relative_to(folder)): (hashlib.sha256(path.read_bytes()).hexdigest(), path.stat().st_mtime_ns)
            for path in sorted(folder.rglob("*")) if path.is_file()}


@pytest.fixture(scope="module")
def finished(scheduler, tmp_path_factory, without_pixels) -> Path:
    """A complete map of :func:`spec`, two chunks."""
    out = tmp_path_factory.mktemp("finished") / "map"
    with without_pixels():
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


def _connect_error(address: str, **budget) -> tuple[list[str], float]:
    started = time.monotonic()
    with pytest.raises(ConfigError) as raised:
        with connect(address, **budget):
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
    """Within the connect budget: a silent server is waited for to its end, which is the default's
    5 s (CONNECT_TIMEOUT, at most 10 s: test_the_connect_budget_is_stated_in_the_help) on the
    command line, and a budget of 0.5 s here: the same code, a tenth of the wait (the silent
    server's whole budget is waited for, which the check does not need long)."""
    errors, seconds = _connect_error(not_dask, timeout=0.5)
    assert len(errors) == 1 and f"what listens at {not_dask} is not a Dask scheduler" in errors[0]
    assert seconds < 2, seconds


@pytest.mark.parametrize("content,reason", [("", "it is empty"), ("{garbage", "not JSON"),
                                            ('{"id": "x"}', 'it has no "address"'), ("[1, 2]", 'no "address"'),
                                            ("\x00\xff\xfe", "not JSON")])
def test_a_scheduler_file_without_an_address_is_one_line_naming_it(tmp_path, content, reason):
    path = tmp_path / "scheduler.json"
    path.write_bytes(content.encode("latin-1"))
    errors, seconds = _connect_error(str(path))
    assert len(errors) == 1 and str(path) in errors[0] and reason in errors[0] and "\n" not in errors[0]
    assert seconds < 2, seconds


# --- a failed run changes nothing that was there ------------------------------------------------------------


def interrupted(finished: Path, folder: Path) -> dict[str, tuple]:
    """A copy of :func:`finished` as a run killed after its first chunk leaves it: part 0, no tables,
    ``running``."""
    shutil.copytree(finished, folder)
    for name in ("parts/part-00001.parquet", "map.parquet", "map.csv"):
        (folder / name).unlink()
    run_json = json.loads((folder / "run.json").read_text())
    (folder / "run.json").write_text(json.dumps({**run_json, "status": "running"}))
    return snapshot(folder)


def assert_unchanged(out: Path, before: dict[str, tuple], new_parts: tuple[int, ...] = ()) -> None:
    """Every earlier file of ``out`` byte for byte and untouched; the only new files are whole parts
    of the map (``new_parts``) and nothing is staged beside it."""
    after = snapshot(out)
    assert {name: after.get(name) for name in before} == before
    assert sorted(set(after) - set(before)) == [f"parts/part-{index:05d}.parquet" for index in new_parts]
    for index in new_parts:
        assert len(pd.read_parquet(out / "parts" / f"part-{index:05d}.parquet")) > 0
    assert sorted(path.name for path in out.parent.iterdir()) == [out.name]


def _broken_finish(run, metadata):
    (run.out / "map_fold_angle.png").write_bytes(b"half a figure")
    raise RuntimeError("a figure fails")


@pytest.mark.parametrize("fault", ["unreachable", "malformed-address", "another-map", "figures-fail"])
@pytest.mark.parametrize("state", ["interrupted", "complete"])
def test_a_resume_that_fails_changes_nothing_that_was_there(finished, scheduler, tmp_path, fault, state):
    out = tmp_path / "results" / "map"
    out.parent.mkdir()
    if state == "interrupted":
        before = interrupted(finished, out)
    else:  # complete, but a part was damaged: it is computed again
        before = earlier_map(finished, out)
        if fault != "figures-fail":
            (out / "parts" / "part-00001.parquet").write_bytes(b"damaged")
            before = snapshot(out)
    keywords, error = {
        "unreachable": ({"scheduler": _refused_address()}, ConfigError),
        "malformed-address": ({"scheduler": "tcp://"}, ConfigError),
        "another-map": ({"scheduler": scheduler, "spec": spec(loads=(2.0,))}, OutputError),
        "figures-fail": ({"scheduler": scheduler, "finish": _broken_finish}, RuntimeError),
    }[fault]
    with pytest.raises(error):
        run_map(keywords.pop("spec", spec()), out, resume=True, **keywords)
    assert_unchanged(out, before, (1,) if fault == "figures-fail" and state == "interrupted" else ())


@pytest.mark.parametrize("fault", ["unreachable", "figures-fail", "broken-weather"])
def test_an_overwrite_that_fails_changes_nothing_that_was_there(finished, scheduler, tmp_path, fault):
    out = tmp_path / "results" / "map"
    out.parent.mkdir()
    before = earlier_map(finished, out)
    broken = tmp_path / "broken.epw"
    broken.write_text("LOCATION,x\nnot a weather file\n")
    sites = (SITES[0], {**SITES[1], "weather": str(broken)}) if fault == "broken-weather" else SITES
    with pytest.raises((ConfigError, RuntimeError)):
        run_map(spec(loads=(2.0,), sites=sites), out, overwrite=True,
                scheduler=_refused_address() if fault == "unreachable" else scheduler,
                finish=_broken_finish if fault == "figures-fail" else None)
    assert_unchanged(out, before)


def test_a_scheduler_lost_mid_resume_keeps_the_earlier_folder_and_the_new_parts(scheduler, tmp_path):
    """The cluster's scheduler is closed once the resumed run has written a part of its own: one
    line saying so, the earlier files as they were, the new part whole; a resume then finishes.
    The cluster closed is one of this test's own; the whole map and the resume that finishes run
    on the module's (conftest.scheduler)."""
    sites = tuple({"latitude": float(latitude), "longitude": 10.0} for latitude in (-40, -20, 0, 20, 40))
    whole, out = tmp_path / "whole" / "map", tmp_path / "resumed" / "map"
    first = run_map(spec(sites=sites), whole, scheduler=scheduler)
    shutil.copytree(whole, out)
    for name in ("map.parquet", "map.csv", *(f"parts/part-{index:05d}.parquet" for index in range(1, 5))):
        (out / name).unlink()
    before = snapshot(out)
    # Its HTTP server on a free port (8787 may be another's), without the dashboard: nothing looks at it.
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp://",
                                  host="127.0.0.1", dashboard_address="127.0.0.1:0",
                                  scheduler_kwargs={"dashboard": False}) as doomed:
        done = []

        def progress(sites_done, total):
            done.append(sites_done)
            if len(done) == 2:  # the first part of this run is written
                doomed.close()

        with pytest.raises(ConfigError) as raised:
            run_map(spec(sites=sites), out, resume=True, scheduler=doomed.scheduler_address, progress=progress)
    (line,) = raised.value.errors
    assert "the scheduler was lost mid-run" in line and "finish the map with --resume" in line
    assert re.search(r"the \d of 5 chunks done are kept", line)
    new_parts = tuple(sorted(int(path.name[5:10]) for path in (out / "parts").glob("part-*")))[1:]
    assert 1 <= len(new_parts) < 4
    assert_unchanged(out, before, new_parts)
    resumed = run_map(spec(sites=sites), out, resume=True, scheduler=scheduler)
    assert resumed.from_disk == (0, *new_parts)
    pd.testing.assert_frame_equal(resumed.table, first.table, check_exact=True)


def test_a_new_map_that_cannot_connect_leaves_nothing_not_even_its_parent_folders(tmp_path):
    with pytest.raises(ConfigError, match="no Dask scheduler answers there"):
        run_map(spec(), tmp_path / "new" / "deeper" / "map", scheduler=_refused_address())
    assert list(tmp_path.iterdir()) == []


# --- scheduler addresses on the command line ----------------------------------------------------------------


@pytest.mark.parametrize("address, reason", [
    ("foo", "neither an existing scheduler file nor an address"),
    ("tcp://", "no host and port"),
    ("tcp://127.0.0.1", "not a HOST:PORT"),
    ("tcp://127.0.0.1:", "not a HOST:PORT"),
    ("tcp://:8786", "not a HOST:PORT"),
    ("tcp://127.0.0.1:8786/status", "not a HOST:PORT"),
    ("tcp://127.0.0.1:99999", "port 99999 is not in [1, 65535]"),
    ("http://127.0.0.1:8787", "http:// is not a protocol"),
    ("inproc://x", "inproc:// is not a protocol"),
    ("missing/scheduler.json", "no such scheduler file"),
    ("scheduler.json", "no such scheduler file"),
    ("a-folder", "a folder, not a scheduler file"),
    ("", "empty"),
])
def test_a_malformed_scheduler_is_one_line_before_anything_is_touched(tmp_path, monkeypatch, address, reason):
    from typer.testing import CliRunner

    from foldopt.cli.app import app

    monkeypatch.chdir(tmp_path)
    (tmp_path / "a-folder").mkdir()
    started = time.monotonic()
    result = CliRunner().invoke(app, ["map", "--lat", "0", "--lon", "0", "--scheduler", address, "--out", "out/map"])
    assert time.monotonic() - started < 10
    assert result.exit_code == 2, result.output
    (line,) = result.output.strip().splitlines()
    assert line.startswith(f"error: --scheduler = {address!r}: {reason}") and "tcp://HOST:PORT" in line, line
    assert [path.name for path in tmp_path.iterdir()] == ["a-folder"]


def test_workers_with_a_scheduler_is_refused(tmp_path):
    with pytest.raises(ConfigError, match="--workers: the embedded cluster's"):
        run_map(spec(), tmp_path / "map", scheduler=_refused_address(), workers=2)
    assert list(tmp_path.iterdir()) == []


def test_the_connect_budget_is_stated_in_the_help():
    from typer.testing import CliRunner

    from foldopt.cli.app import app
    from foldopt.studies.dask_client import CONNECT_TIMEOUT, WORKER_TIMEOUT

    help_text = " ".join(CliRunner().invoke(app, ["map", "--help"]).output.split())
    assert CONNECT_TIMEOUT <= 10
    assert f"A scheduler that does not answer is given up after {CONNECT_TIMEOUT:g} s" in help_text
    assert f"one without a worker after {WORKER_TIMEOUT:g} s more" in help_text


def test_a_scheduler_file_holding_a_malformed_address_names_the_file(tmp_path):
    path = tmp_path / "scheduler.json"
    path.write_text(json.dumps({"address": "tcp://127.0.0.1"}))
    errors, seconds = _connect_error(str(path))
    assert len(errors) == 1 and "not a Dask scheduler file" in errors[0] and "'tcp://127.0.0.1'" in errors[0]
    assert seconds < 2
