"""Results folders: built under a temporary name beside their destination and renamed into place
only when complete, so a failed run never leaves a half-written folder, and an existing folder is
replaced only when the caller asks for it. Light on imports, so that the command line can check
its output folder before any work.
"""

from __future__ import annotations

import os
import shutil
from contextlib import contextmanager
from pathlib import Path


class OutputExistsError(FileExistsError):
    """The results folder exists and overwriting was not asked for."""


def check_output(out: Path, overwrite: bool) -> None:
    """Raise :class:`OutputExistsError` if ``out`` exists and ``overwrite`` is false."""
    if out.exists() and not overwrite:
        raise OutputExistsError(f"{out} already exists; pass --overwrite to replace it")


@contextmanager
def staged_folder(out: Path, overwrite: bool):
    """Yield a temporary folder that replaces ``out`` atomically when the block succeeds."""
    check_output(out, overwrite)
    out.parent.mkdir(parents=True, exist_ok=True)
    staging = out.parent / f".{out.name}.tmp-{os.getpid()}"
    shutil.rmtree(staging, ignore_errors=True)
    staging.mkdir()
    try:
        yield staging
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    if out.exists():
        retired = out.parent / f".{out.name}.old-{os.getpid()}"
        out.rename(retired)
        staging.rename(out)
        shutil.rmtree(retired)
    else:
        staging.rename(out)
