"""Results folders that cannot hurt: built under a temporary name beside their destination and
renamed into place only when complete; an existing folder is replaced only when the caller asks
for it and only if foldopt wrote it. Light on imports, so that the command line can check its
output folder before any work.

A process killed while it writes leaves its staging folder (``.<name>.tmp-<pid>``) or, between
the two renames of a replacement, the retired folder (``.<name>.old-<pid>``). The next results
folder written into the same parent clears the first and puts the second back where it was, so
that nothing stays behind and no earlier results are lost. SIGTERM and SIGINT are turned into exceptions by the
command line, so that the staging folder goes at once.
"""

from __future__ import annotations

import json
import os
import re
import shutil
from contextlib import contextmanager
from pathlib import Path


class OutputExistsError(FileExistsError):
    """The results folder exists and overwriting was not asked for."""


class OutputError(OSError):
    """The results folder cannot be written there, or must not be replaced."""


def written_by_foldopt(folder: Path) -> bool:
    """Whether ``folder`` holds foldopt's ``run.json`` (one that names foldopt's version)."""
    try:
        meta = json.loads((folder / "run.json").read_text())
    except (OSError, ValueError):
        return False
    return isinstance(meta, dict) and isinstance(meta.get("versions"), dict) and "foldopt" in meta["versions"]


def check_output(out: Path, overwrite: bool) -> None:
    """Raise if ``out`` cannot take a results folder: :class:`OutputExistsError` if it exists and
    ``overwrite`` is false, :class:`OutputError` if it is a file, the working folder or one of its
    parents, a folder foldopt did not write, or in a place that cannot be written."""
    out = Path(out)
    resolved = out.resolve()
    if resolved == Path.cwd().resolve() or resolved in Path.cwd().resolve().parents:
        raise OutputError(f"--out {out}: is the working folder or one of its parents; name a folder for the results")
    if out.is_symlink():
        raise OutputError(f"--out {out}: is a symbolic link; name the folder itself")
    if out.exists() and not out.is_dir():
        raise OutputError(f"--out {out}: is a file, not a folder")
    if out.exists() and not overwrite:
        raise OutputExistsError(f"{out} already exists; pass --overwrite to replace it")
    if out.exists() and any(out.iterdir()) and not written_by_foldopt(out):
        raise OutputError(f"--out {out}: holds files foldopt did not write (no foldopt run.json); --overwrite "
                          "replaces only results folders, so move them or choose another folder")
    ancestor = resolved.parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise OutputError(f"--out {out}: {ancestor} is a file, not a folder")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise OutputError(f"--out {out}: cannot write in {ancestor} (permission denied)")


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (another user's process is alive too: PermissionError)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    return True


_LEFTOVER = re.compile(r"^\.(.+)\.(tmp|old)-(\d+)$")


def clear_leftovers(parent: Path) -> None:
    """Remove the staging folders that dead processes left in ``parent`` and put the folders they
    retired back in place (see the module docstring)."""
    if not parent.is_dir():
        return
    for path in sorted(parent.iterdir()):
        match = _LEFTOVER.match(path.name)
        if not match or not path.is_dir() or int(match.group(3)) == os.getpid() or _alive(int(match.group(3))):
            continue
        home = parent / match.group(1)
        if match.group(2) == "old" and not home.exists():
            path.rename(home)
        else:
            shutil.rmtree(path, ignore_errors=True)


def write_atomically(path: Path, write) -> Path:
    """``write(temporary)`` to a file beside ``path`` (same suffix, so that writers that read it
    know the format), then rename it into ``path``: a reader sees the old file or the whole new one,
    and a failed write leaves nothing."""
    path = Path(path)
    temporary = path.with_name(f".{path.stem}.tmp-{os.getpid()}{path.suffix}")
    try:
        write(temporary)
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)
    return path


@contextmanager
def staged_folder(out: Path, overwrite: bool):
    """Yield a temporary folder that replaces ``out`` atomically when the block succeeds."""
    out = Path(out)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        clear_leftovers(out.parent)
        check_output(out, overwrite)
        staging = out.parent / f".{out.name}.tmp-{os.getpid()}"
        shutil.rmtree(staging, ignore_errors=True)
        staging.mkdir()
    except (OutputError, OutputExistsError):
        raise
    except OSError as error:
        raise OutputError(f"--out {out}: cannot create it ({error.strerror or error})") from None
    try:
        yield staging
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    if not out.exists():
        staging.rename(out)
        return
    retired = out.parent / f".{out.name}.old-{os.getpid()}"
    out.rename(retired)
    try:
        staging.rename(out)
    except BaseException:
        retired.rename(out)
        shutil.rmtree(staging, ignore_errors=True)
        raise
    shutil.rmtree(retired)
