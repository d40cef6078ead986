"""Results folders and caches under faults (issue 21): a folder foldopt did not make is never
touched, two writers of one folder never both succeed, a damaged cache is built again, and a full
file system is one line naming the folder, leaving the earlier folder as it was. Processes started
here are killed by their id; the full file system is a 2 MB tmpfs, unmounted in a finally."""

from __future__ import annotations

import hashlib
import json
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from foldopt.files import clear_leftovers, staged_folder
from foldopt.errors import OutputError

#: A pid that no process has: above the default pid_max, below the largest one Linux allows.
DEAD_PID = 4000001


def snapshot(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` (and under its hidden neighbours) with its content's digest."""
    return {str(path.relative_to(folder)): hashlib.sha256(path.read_bytes()).hexdigest()
            for path in sorted(folder.rglob("*")) if path.is_file()}


def earlier_results(folder: Path) -> dict[str, str]:
    folder.mkdir(parents=True)
    (folder / "run.json").write_text(json.dumps({"versions": {"foldopt": "0"}}))
    (folder / "summary.csv").write_text("a,b\n1,2\n")
    return snapshot(folder)


def _python(code: str, *args) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", code, *map(str, args)], stdout=subprocess.PIPE, text=True)


def test_folders_foldopt_did_not_make_are_never_touched(tmp_path):
    assert not Path(f"/proc/{DEAD_PID}").exists()
    foreign = {name: tmp_path / name for name in (f".notes.tmp-{DEAD_PID}", f".notes.old-{DEAD_PID}",
                                                  ".notes.new-abc")}
    for folder in foreign.values():
        folder.mkdir()
        (folder / "draft.txt").write_text("another program's")
    (tmp_path / ".notes.lock").write_text("another program's lock")
    before = snapshot(tmp_path)
    with staged_folder(tmp_path / "results", overwrite=False) as folder:
        (folder / "run.json").write_text("{}")
    clear_leftovers(tmp_path)
    assert snapshot(tmp_path) == {**before, "results/run.json": hashlib.sha256(b"{}").hexdigest()}


_KILLED_WHILE_WRITING = """
import os, signal, sys
from pathlib import Path
from foldopt.files import staged_folder
with staged_folder(Path(sys.argv[1]), overwrite=True) as folder:
    (folder / "half.csv").write_text("1,2")
    os.kill(os.getpid(), signal.SIGKILL)
"""

_KILLED_BETWEEN_RENAMES = """
import os, signal, sys
from pathlib import Path
from foldopt.files import staged_folder
out = Path(sys.argv[1])
rename = Path.rename
def killed_at_the_second(self, target):
    if Path(target) == out:  # the earlier folder is retired; the new one is not yet in place
        os.kill(os.getpid(), signal.SIGKILL)
    return rename(self, target)
Path.rename = killed_at_the_second
with staged_folder(out, overwrite=True) as folder:
    (folder / "run.json").write_text("{}")
"""


@pytest.mark.parametrize("script", [_KILLED_WHILE_WRITING, _KILLED_BETWEEN_RENAMES], ids=["writing", "renaming"])
def test_what_a_killed_writer_left_is_cleared_and_the_earlier_folder_put_back(tmp_path, script):
    before = earlier_results(tmp_path / "out")
    killed = _python(script, tmp_path / "out")
    killed.communicate(timeout=60)
    assert killed.returncode == -signal.SIGKILL
    left = sorted(path.name for path in tmp_path.iterdir())
    assert f".out.tmp-{killed.pid}" in left and ".out.lock" in left
    with staged_folder(tmp_path / "other", overwrite=False) as folder:
        (folder / "run.json").write_text("{}")
    assert sorted(path.name for path in tmp_path.iterdir()) == ["other", "out"]
    assert snapshot(tmp_path / "out") == before


def test_a_second_writer_of_one_folder_is_refused(tmp_path):
    out = tmp_path / "out"
    with staged_folder(out, overwrite=False) as first:
        with pytest.raises(OutputError, match=f"another foldopt run \\(pid {os.getpid()} on .*\\) is writing it"):
            with staged_folder(out, overwrite=True):
                pytest.fail("two writers of one folder")
        (first / "run.json").write_text("{}")
    assert sorted(path.name for path in tmp_path.iterdir()) == ["out"]


#: A process that holds a folder's writer lock for a minute (test_faults_cluster uses it too).
HOLDS_THE_LOCK = """
import sys, time
from pathlib import Path
from foldopt.files import writer_lock
with writer_lock(Path(sys.argv[1])):
    print("locked", flush=True)
    time.sleep(60)
"""


def test_a_lock_names_its_holder_and_goes_with_it_even_by_sigkill(tmp_path):
    out = tmp_path / "out"
    holder = _python(HOLDS_THE_LOCK, out)
    try:
        assert holder.stdout.readline() == "locked\n"
        with pytest.raises(OutputError, match=f"pid {holder.pid} on "):
            with staged_folder(out, overwrite=False):
                pytest.fail("written while another process holds the lock")
    finally:
        holder.kill()
        holder.communicate(timeout=30)
    with staged_folder(out, overwrite=False) as folder:
        (folder / "run.json").write_text("{}")
    assert sorted(path.name for path in tmp_path.iterdir()) == ["out"]


# --- caches ---------------------------------------------------------------------------------------


def _truncate(path: Path) -> None:
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])


def _flip_a_bit(path: Path) -> None:
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0x10
    path.write_bytes(bytes(data))


@pytest.mark.parametrize("damage", [_truncate, _flip_a_bit], ids=["truncated", "bit-flipped"])
def test_a_damaged_electrical_table_is_built_again_once(tmp_path, monkeypatch, capsys, damage):
    from foldopt.engine.electrical import Electrical
    from foldopt.physics.pvmodel import PVModel

    monkeypatch.setenv("FOLDOPT_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("FOLDOPT_QUIET", raising=False)
    poa = np.linspace(0.0, 1200.0, 50)

    def power():
        return Electrical(PVModel("single-diode"), subpanel_area=0.05).subpanel_power(poa)

    expected = power()
    (table,) = (tmp_path / "tables").glob("subpanel-*.npz")
    damage(table)
    np.testing.assert_array_equal(power(), expected)
    notice = capsys.readouterr().err
    assert notice.count("\n") == 1 and str(table) in notice and "building it again" in notice
    np.testing.assert_array_equal(power(), expected)  # healed: loaded, silently
    assert capsys.readouterr().err == ""
    damage(table)
    monkeypatch.setenv("FOLDOPT_QUIET", "1")
    np.testing.assert_array_equal(power(), expected)
    assert capsys.readouterr().err == ""


def test_a_truncated_land_mask_cache_is_built_again(tmp_path, monkeypatch, capsys):
    from foldopt.inputs import land

    # A small stand-in for the 5-arc-minute fraction: the full mask takes seconds to load.
    small = (np.array([-45.0, 45.0]), np.array([-90.0, 90.0]), np.array([[0.0, 1.0], [1.0, 0.0]], np.float32))
    monkeypatch.setenv("FOLDOPT_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("FOLDOPT_QUIET", raising=False)
    monkeypatch.setattr(land, "_build", lambda: small, raising=False)
    land.land_fraction.cache_clear()
    try:
        land.land_fraction()
        (cached,) = tmp_path.glob("land-fraction-*.npz")
        _truncate(cached)
        land.land_fraction.cache_clear()
        for got, want in zip(land.land_fraction(), small, strict=True):
            np.testing.assert_array_equal(got, want)
        assert "building it again" in capsys.readouterr().err
        monkeypatch.setattr(land, "_build", lambda: pytest.fail("a sound cache is built again"))
        land.land_fraction.cache_clear()
        land.land_fraction()  # the rebuilt cache is sound
    finally:
        land.land_fraction.cache_clear()


# --- full file systems ------------------------------------------------------------------------------


# small_disk: a 2 MB tmpfs (tests/conftest.py).


def test_a_full_disk_is_one_line_naming_the_folder_and_keeps_the_earlier_one(small_disk):
    out = small_disk / "out"
    before = earlier_results(out)
    with pytest.raises(OutputError) as raised:
        with staged_folder(out, overwrite=True) as folder:
            (folder / "summary.csv").write_text("x" * 1_000_000)
            (folder / "timeseries.csv").write_text("x" * 2_000_000)
    message = str(raised.value)
    assert "\n" not in message and message.startswith(f"--out {out}: the file system is full")
    assert re.search(r"need more than [12]\.\d MB free there", message)  # what fitted before it filled
    assert snapshot(out) == before
    assert sorted(path.name for path in small_disk.iterdir()) == ["out"]


# --- an --out that is a file ------------------------------------------------------------------------


#: Every command that writes a results folder, with what it needs beside --out.
WRITERS = [["run"], ["sweep", "angle"], ["sweep", "day"], ["sweep", "load"], ["sweep", "latitude"], ["size"],
           ["optimize"], ["reproduce"], ["map", "--lat", "0", "--lon", "0"]]


@pytest.mark.parametrize("args", [[*command, *flag] for command in WRITERS for flag in ([], ["--overwrite"])]
                         + [["map", "--lat", "0", "--lon", "0", "--resume"]], ids=" ".join)
def test_an_out_that_is_a_file_is_refused_by_every_command_and_left_alone(tmp_path, monkeypatch, args):
    from typer.testing import CliRunner

    from foldopt.cli.app import app

    monkeypatch.chdir(tmp_path)
    notes = tmp_path / "notes"
    notes.write_text("the user's own notes\n")
    os.utime(notes, ns=(1_000_000_000, 1_000_000_000))
    result = CliRunner().invoke(app, [*args, "--out", "notes"])
    assert result.exit_code == 2, result.output
    assert result.output.strip().splitlines() == [
        "error: --out notes: is a file, not a results folder; foldopt will not replace it, so move it or choose "
        "another --out"]
    assert notes.read_text() == "the user's own notes\n" and notes.stat().st_mtime_ns == 1_000_000_000
    assert [path.name for path in tmp_path.iterdir()] == ["notes"]


def test_a_folder_of_other_files_is_not_offered_overwrite(tmp_path):
    """--overwrite replaces only results folders: a folder of other files is refused with or without it,
    never offered an option that would be refused in turn."""
    from foldopt.files import check_output

    (tmp_path / "thesis").mkdir()
    (tmp_path / "thesis" / "thesis.tex").write_text("x")
    for overwrite in (False, True):
        with pytest.raises(OutputError, match="holds files foldopt did not write") as raised:
            check_output(tmp_path / "thesis", overwrite)
        assert "--overwrite" not in str(raised.value)
