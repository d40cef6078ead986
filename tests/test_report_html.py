"""report.html in every results folder, opened in a real headless Chromium: every image decodes,
the page logs nothing to the console, it fetches nothing, and it renders at a phone's width."""

from __future__ import annotations

import contextlib
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from typer.testing import CliRunner

from foldopt.cli.app import app

#: One worker runs this module (the results folders are written once, by one worker; pytest-xdist --dist loadgroup).
#: The folders are session-scoped: the worker may run other modules' tests between these, which
#: would tear a module-scoped fixture down and write them again.
#: Each report's images are the folder's PNGs, which a browser decodes: drawn whole (figure_pixels).
pytestmark = [pytest.mark.xdist_group("reports"), pytest.mark.figure_pixels]

runner = CliRunner()
QUICK = ["--step-min", "30", "--angle-step", "30"]
COMMANDS = {
    "run": ["run"],
    "sweep": ["sweep", "latitude", "--lat", "-40:40:40", "--p-load", "2:4:2", *QUICK],
    "annual": ["sweep", "day", "--days", "1:365:61", "--objective", "mean", *QUICK],
    "size": ["size", "--areas", "0.05:0.2:0.05"],
    "reproduce": ["reproduce"],
    "map": ["map", "--lat", "0,40", "--lon", "0", "--p-load", "2", *QUICK],  # its cluster: folders
}
CHROMIUM = next((shutil.which(name) for name in ("chromium", "chromium-browser", "google-chrome")
                 if shutil.which(name)),
                None)


def _browser(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                           "--disable-extensions", *args], capture_output=True, text=True, timeout=120)


@pytest.fixture(scope="session")
def folders(tmp_path_factory, in_process_scheduler) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("reports")
    out = {}
    for name, args in COMMANDS.items():
        # The map on a cluster in this process: an embedded one (--workers 1) started a process that
        # imported foldopt and loaded its compiled code again.
        with in_process_scheduler() if name == "map" else contextlib.nullcontext() as address:
            cluster = ["--scheduler", address] if address else []
            result = runner.invoke(app, [*args, *cluster, "--out", str(root / name), "-q"])
        assert result.exit_code == 0, (name, result.output)
        out[name] = root / name
    return out


@pytest.mark.parametrize("name", list(COMMANDS))
def test_every_results_folder_has_a_self_contained_report(folders, name):
    page = (folders[name] / "report.html").read_text()
    assert page.startswith("<!DOCTYPE html>") and '<meta name="viewport"' in page
    # Nothing is fetched: every image is inline and no URL leaves the page.
    assert not re.search(r'(src|href)="(?!data:)', page)
    assert "http://" not in page and "https://" not in page
    images = re.findall(r'<img src="data:image/png;base64,', page)
    figures = [p for p in folders[name].glob("*.png")]
    assert len(images) == len(figures)
    assert "<h2>Answer</h2>" in page and "<h2>Provenance</h2>" in page


@pytest.mark.skipif(CHROMIUM is None, reason="no Chromium here: `apt-get install chromium` (.ci/run installs it)")
@pytest.mark.parametrize("name", list(COMMANDS))
def test_report_opens_in_a_real_browser(folders, name, tmp_path):
    url = (folders[name] / "report.html").resolve().as_uri()
    loaded = _browser("--enable-logging=stderr", "--v=0", "--virtual-time-budget=10000", "--dump-dom", url)
    assert loaded.returncode == 0, loaded.stderr[-2000:]
    marker = re.search(r'data-images="(\d+)/(\d+)"', loaded.stdout)
    assert marker, "the page's load handler did not run"
    assert marker.group(1) == marker.group(2) == str(len(list(folders[name].glob("*.png"))))
    console = [line for line in loaded.stderr.splitlines() if ":CONSOLE" in line]
    assert console == []
    shot = tmp_path / f"{name}.png"
    taken = _browser("--hide-scrollbars", "--window-size=412,900", f"--screenshot={shot}", url)
    assert taken.returncode == 0 and shot.stat().st_size > 10_000
