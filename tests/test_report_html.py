"""report.html in every results folder, opened in a real headless Chromium: every image decodes,
the page logs nothing to the console, it fetches nothing, and it renders at a phone's width. The
commands run in this process, as a notebook's would: each draws its figures here, with no worker.

One Chromium opens every report, each in a tab of its own at a phone's width, driven through the
DevTools protocol on a pipe (``--remote-debugging-pipe``): a browser's start is most of what
opening a page costs, and each report was opened by two (its DOM, its screenshot)."""

from __future__ import annotations

import base64
import contextlib
import json
import os
import re
import select
import shutil
import subprocess
import time
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


class _Browser:
    """A headless Chromium driven through the DevTools protocol on fds 3 (to it) and 4 (from it):
    each message is JSON ended by a NUL."""

    def __init__(self, timeout: float = 120):
        to_browser, from_browser = os.pipe(), os.pipe()
        ends = (to_browser[0], from_browser[1])

        def pipes():
            for fd, end in zip((3, 4), [os.dup(end) for end in ends], strict=True):
                os.dup2(end, fd)

        self.process = subprocess.Popen(
            [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
             "--disable-extensions", "--hide-scrollbars", "--remote-debugging-pipe", "about:blank"],
            preexec_fn=pipes, close_fds=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        for fd in ends:
            os.close(fd)
        self.to, self.read_fd = os.fdopen(to_browser[1], "wb"), from_browser[0]
        self.deadline, self.buffer, self.events, self.sent = time.monotonic() + timeout, b"", [], 0

    def _message(self) -> dict:
        while b"\0" not in self.buffer:
            remaining = self.deadline - time.monotonic()
            assert remaining > 0 and select.select([self.read_fd], [], [], remaining)[0], "Chromium hung"
            chunk = os.read(self.read_fd, 1 << 16)
            assert chunk, "Chromium ended"
            self.buffer += chunk
        message, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(message)

    def send(self, method: str, session: str | None = None, **params) -> dict:
        """Call ``method`` (in the tab of ``session``) and return its result; the events that come
        meanwhile are kept."""
        self.sent += 1
        self.to.write(json.dumps({"id": self.sent, "method": method, "params": params,
                                  **({"sessionId": session} if session else {})}).encode() + b"\0")
        self.to.flush()
        while (message := self._message()).get("id") != self.sent:
            self.events.append(message)
        assert "error" not in message, (method, message["error"])
        return message["result"]

    def wait(self, event: str, session: str) -> None:
        """Until the tab of ``session`` has sent ``event``."""
        while not any(e.get("method") == event and e.get("sessionId") == session for e in self.events):
            self.events.append(self._message())

    def open(self, url: str) -> tuple[str | None, list[str], bytes]:
        """Open ``url`` in a tab at a phone's width (412 x 900), let its load handler and 10 s of
        its timers run: (its ``data-images`` marker, what it logged to the console, its
        screenshot's PNG)."""
        target = self.send("Target.createTarget", url="about:blank")["targetId"]
        session = self.send("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
        for domain in ("Page", "Runtime", "Log"):  # console calls, uncaught errors, the browser's
            self.send(f"{domain}.enable", session)
        self.send("Emulation.setDeviceMetricsOverride", session, width=412, height=900,
                  deviceScaleFactor=1, mobile=False)
        self.send("Page.navigate", session, url=url)
        self.wait("Page.loadEventFired", session)
        self.send("Emulation.setVirtualTimePolicy", session, policy="advance", budget=10_000)
        self.wait("Emulation.virtualTimeBudgetExpired", session)
        marker = self.send("Runtime.evaluate", session, expression="document.body.dataset.images")
        shot = base64.b64decode(self.send("Page.captureScreenshot", session)["data"])
        self.send("Target.closeTarget", targetId=target)
        logged = [json.dumps(e["params"])[:500] for e in self.events if e.get("sessionId") == session
                  and e["method"] in ("Runtime.consoleAPICalled", "Runtime.exceptionThrown", "Log.entryAdded")]
        return marker["result"].get("value"), logged, shot

    def close(self) -> int:
        with contextlib.suppress(AssertionError):  # the browser ends as it answers
            self.send("Browser.close")
        self.to.close()
        os.close(self.read_fd)
        return self.process.wait(timeout=60)


@pytest.fixture(scope="session")
def written(tmp_path_factory, in_process_scheduler) -> dict[str, tuple[Path, list, bool]]:
    """Each command run in this process (a test's CliRunner, as a notebook would call it), by its
    name: (its results folder, each figure it drew and the id of the process that drew it, whether
    it left a figure pool's worker)."""
    import foldopt.output.figures as figures
    from foldopt.output import drawing

    root = tmp_path_factory.mktemp("reports")
    out = {}
    draw = figures.figure_bytes
    for name, args in COMMANDS.items():
        drawn = []

        def recorded(file, args, kwargs, drawn=drawn):
            drawn.append((file, os.getpid()))
            return draw(file, args, kwargs)

        # The map on a cluster in this process: an embedded one (--workers 1) started a process that
        # imported foldopt and loaded its compiled code again.
        with (in_process_scheduler() if name == "map" else contextlib.nullcontext() as address,
              pytest.MonkeyPatch.context() as patch):
            patch.setattr(figures, "figure_bytes", recorded)
            cluster = ["--scheduler", address] if address else []
            result = runner.invoke(app, [*args, *cluster, "--out", str(root / name), "-q"])
        assert result.exit_code == 0, (name, result.output)
        out[name] = (root / name, drawn, drawing._POOL["leader"] is not None)
    return out


@pytest.fixture(scope="session")
def folders(written) -> dict[str, Path]:
    """Each command's results folder (:func:`written`), by its name."""
    return {name: folder for name, (folder, _, _) in written.items()}


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


@pytest.mark.parametrize("name", list(COMMANDS))
def test_an_in_process_caller_draws_in_its_own_process(written, name):
    """A command run in the caller's process starts no figure worker: every figure of its folder
    is drawn in the caller's process (tests/test_figure_pool.py runs the command line's own)."""
    from foldopt.output.figures import day

    folder, drawn, pool = written[name]
    assert not pool
    assert {pid for _, pid in drawn} <= {os.getpid()}
    assert sorted(file for file, _ in drawn) == sorted(path.name for path in folder.glob("*.png"))
    if name == "run":
        assert sorted(file for file, _ in drawn) == sorted(day.FIGURES)


@pytest.fixture(scope="session")
def opened(folders) -> dict[str, tuple[str | None, list[str], bytes]]:
    """Every report opened by one Chromium (:meth:`_Browser.open`), by its command's name."""
    browser = _Browser()
    try:
        pages = {name: browser.open((folder / "report.html").resolve().as_uri()) for name, folder in folders.items()}
    finally:
        ended = browser.close()
    assert ended == 0
    return pages


@pytest.mark.skipif(CHROMIUM is None, reason="no Chromium here: `apt-get install chromium` (.ci/run installs it)")
@pytest.mark.parametrize("name", list(COMMANDS))
def test_report_opens_in_a_real_browser(opened, folders, name):
    marker, console, shot = opened[name]
    assert marker, "the page's load handler did not run"
    assert marker == "{0}/{0}".format(len(list(folders[name].glob("*.png"))))
    assert console == []
    assert shot.startswith(b"\x89PNG") and len(shot) > 10_000
