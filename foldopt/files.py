"""Results folders that cannot hurt: built under a temporary name beside their destination and renamed into place
only when complete; an existing folder is replaced only when the caller asks for it, only if foldopt wrote it,
and only once its replacement is whole. Light on imports, so that the command line can check its output folder
before any work.

One writer per folder: a writer holds an OS lock (``flock``) on ``.<name>.lock`` beside its destination, which
the kernel drops when the process ends, even by SIGKILL; a second writer is refused by name. The staging folder
``.<name>.tmp-<pid>`` and, between the two renames of a replacement, the retired folder ``.<name>.old-<pid>``
hold a marker, :data:`MARKER` (the writer's pid, host and a random token), and the results in a folder named
like the destination, so that the marker never reaches the results. A process killed while it writes leaves
them behind; the next results folder written into the same parent removes those whose writer is gone and puts
a retired folder back where it was. A folder without the marker, whatever its name, is never touched. SIGTERM
and SIGINT are turned into exceptions by the command line, so that the staging folder goes at once. A full file
system (``ENOSPC``, ``EDQUOT``) is :class:`OutputError` naming the folder and the space it needs.
"""

from __future__ import annotations

import errno
import fcntl
import json
import os
import platform
import re
import secrets
import shutil
import socket
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

from foldopt.errors import OutputError, OutputExistsError

#: The file that marks a staging or retired folder as foldopt's: JSON of its writer's pid, host and token.
MARKER = ".foldopt-staging"
_FULL = {errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC)}
_LEFTOVER = re.compile(r"^\.(.+)\.(tmp|old|new)-\w+$")
_LOCK = re.compile(r"^\.(.+)\.lock$")
#: Seconds a writer retries a held lock: a clean-up holds a dead writer's lock for an instant.
_LOCK_PATIENCE = 0.2


#: The packages whose versions every ``run.json`` names (:func:`versions`).
VERSIONED = ("foldopt", "numpy", "scipy", "pandas", "pvlib", "matplotlib", "pydantic", "typer")


def versions(extra: tuple[str, ...] = ()) -> dict[str, str]:
    """Versions of Python, foldopt and its main dependencies (and of the ``extra`` packages), as
    every ``run.json`` records them: a folder whose ``run.json`` names foldopt's version is one
    foldopt wrote (:func:`written_by_foldopt`).

    Parameters
    ----------
    extra : tuple of str, default ()
        More distribution names.
    """
    from importlib import metadata

    found = {"python": platform.python_version()}
    for name in VERSIONED + tuple(extra):
        try:
            found[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            found[name] = "not installed"
    return found


def written_by_foldopt(folder: Path) -> bool:
    """Whether ``folder`` holds foldopt's ``run.json`` (one that names foldopt's version).

    Parameters
    ----------
    folder : pathlib.Path

    Returns
    -------
    bool
        False where ``run.json`` is missing, cannot be read or is not foldopt's.
    """
    try:
        meta = json.loads((folder / "run.json").read_text())
    except (OSError, ValueError):
        return False
    return (
        isinstance(meta, dict)
        and isinstance(meta.get("versions"), dict)
        and "foldopt" in meta["versions"]
    )


def check_output(
    out: Path, overwrite: bool, remedy: str = "pass --overwrite to replace it"
) -> None:
    """Raise if ``out`` cannot take a results folder: :class:`OutputError` if it is a file, a
    symbolic link, the working folder or one of its parents, a folder foldopt did not write, or in
    a place that cannot be written (no option changes that, so none is offered);
    :class:`OutputExistsError` if it is an existing results folder and ``overwrite`` is false.

    Parameters
    ----------
    out : pathlib.Path
        The results folder to be.
    overwrite : bool
        Whether an existing results folder may be replaced.
    remedy : str, default 'pass --overwrite to replace it'
        What the message of an existing results folder offers.
    """
    out = Path(out)
    resolved = out.resolve()
    if resolved == Path.cwd().resolve() or resolved in Path.cwd().resolve().parents:
        raise OutputError(
            f"--out {out}: is the working folder or one of its parents; name a folder for the results"
        )
    if out.is_symlink():
        raise OutputError(f"--out {out}: is a symbolic link; name the folder itself")
    if out.exists() and not out.is_dir():
        raise OutputError(
            f"--out {out}: is a file, not a results folder; foldopt will not replace it, so move "
            "it or choose another --out"
        )
    if out.exists() and any(out.iterdir()) and not written_by_foldopt(out):
        raise OutputError(
            f"--out {out}: holds files foldopt did not write (no foldopt run.json); foldopt "
            "replaces only results folders, so move them or choose another --out"
        )
    if out.exists() and not overwrite:
        raise OutputExistsError(f"{out} already exists; {remedy}")
    ancestor = resolved.parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise OutputError(f"--out {out}: {ancestor} is a file, not a folder")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise OutputError(f"--out {out}: cannot write in {ancestor} (permission denied)")


# --- full file systems ------------------------------------------------------------------------------


class DiskFullError(OutputError):
    """The file system filled while results were written.

    Parameters
    ----------
    folder : pathlib.Path
        The results folder.
    written : int
        Bytes written before the file system filled.
    remedy : str, default 'run again'
        What the message tells the user to do once space is free.
    """

    def __init__(self, folder: Path, written: int, remedy: str = "run again"):
        self.folder, self.written = Path(folder), written
        super().__init__(
            f"--out {folder}: the file system is full; the results need more than "
            f"{_size_text(written)} free there (what was written before it filled); free space and "
            f"{remedy}"
        )


def is_full(error: BaseException) -> bool:
    """Whether ``error`` says that the file system (or the user's quota) is full.

    Parameters
    ----------
    error : BaseException

    Returns
    -------
    bool
        True for a :class:`DiskFullError` or an :class:`OSError` with ``ENOSPC`` or ``EDQUOT``.
    """
    return isinstance(error, DiskFullError) or isinstance(error, OSError) and error.errno in _FULL


def tree_size(path: Path) -> int:
    """Bytes of the files under ``path``, or of the file ``path`` (0 where it is gone).

    Parameters
    ----------
    path : pathlib.Path
        A folder or a file.

    Returns
    -------
    int
        Size [bytes].
    """
    if Path(path).is_file():
        return Path(path).stat().st_size
    return sum(
        (Path(root) / name).stat().st_size for root, _, names in os.walk(path) for name in names
    )


def _size_text(size: int) -> str:
    return f"{size / 1e6:.1f} MB" if size >= 100_000 else f"{max(size, 1) / 1e3:.0f} kB"


def write_atomically(path: Path, write) -> Path:
    """``write(temporary)`` to a file beside ``path`` (same suffix, so that writers that read it
    know the format), then rename it into ``path``: a reader sees the old file or the whole new one,
    and a failed write leaves nothing. A full file system is :class:`DiskFullError`.

    Parameters
    ----------
    path : pathlib.Path
        The file to write, returned.
    write : callable
        Writes the file whose path it is given.
    """
    path = Path(path)
    temporary = path.with_name(f".{path.stem}.tmp-{os.getpid()}{path.suffix}")
    try:
        write(temporary)
        os.replace(temporary, path)
    except OSError as error:
        if is_full(error):
            raise DiskFullError(
                path.parent, tree_size(temporary) if temporary.exists() else 0
            ) from None
        raise
    finally:
        temporary.unlink(missing_ok=True)
    return path


# --- one writer per folder ------------------------------------------------------------------------


def _record() -> dict:
    return {
        "writer": "foldopt",
        "pid": os.getpid(),
        "host": socket.gethostname(),
        "token": secrets.token_hex(8),
    }


def _read_record(path: Path) -> dict | None:
    """The writer a lock file or marker names, or None where it is not foldopt's."""
    try:
        record = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if (
        isinstance(record, dict)
        and record.get("writer") == "foldopt"
        and isinstance(record.get("pid"), int)
    ):
        return record
    return None


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (another user's process is alive too: PermissionError)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    return True


def _gone(record: dict) -> bool:
    """Whether the writer ``record`` names has ended: a process of this host that no longer runs
    (another host's writer cannot be asked, so its folders stay)."""
    return (
        record.get("host") == socket.gethostname()
        and record["pid"] != os.getpid()
        and not _alive(record["pid"])
    )


def _lock_path(out: Path) -> Path:
    return out.parent / f".{out.name}.lock"


def _try_lock(path: Path) -> int | None:
    """A descriptor of ``path`` locked by this process, or None while another process holds it."""
    descriptor = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        # The last holder removes the file as it leaves: a lock on a removed file guards nothing.
        if os.fstat(descriptor).st_ino == os.stat(path).st_ino:
            return descriptor
    except (BlockingIOError, FileNotFoundError):
        pass
    os.close(descriptor)
    return None


def _acquire(out: Path) -> int:
    path = _lock_path(out)
    deadline = time.monotonic() + _LOCK_PATIENCE
    while (descriptor := _locked(path, out)) is None:
        if time.monotonic() > deadline:
            holder = _read_record(path) or {}
            raise OutputError(
                f"--out {out}: another foldopt run (pid {holder.get('pid', '?')} on "
                f"{holder.get('host', '?')}) is writing it; wait for it to end or choose another --out"
            )
        time.sleep(0.01)
    if os.fstat(descriptor).st_size and _read_record(path) is None:
        os.close(descriptor)
        raise OutputError(
            f"--out {out}: {path.name} beside it is not foldopt's lock file; move it or choose "
            "another --out"
        )
    try:
        os.ftruncate(descriptor, 0)
        os.write(descriptor, json.dumps(_record()).encode())
    except OSError as error:
        os.unlink(path)
        os.close(descriptor)
        raise _lock_error(out, path, error) from None
    return descriptor


def _locked(path: Path, out: Path) -> int | None:
    """:func:`_try_lock`, its failures as :class:`OutputError`."""
    try:
        return _try_lock(path)
    except OSError as error:
        raise _lock_error(out, path, error) from None


def _lock_error(out: Path, path: Path, error: OSError) -> OutputError:
    if is_full(error):
        return DiskFullError(out, 0)
    return OutputError(
        f"--out {out}: cannot write its lock file {path.name} ({error.strerror or error})"
    )


@contextmanager
def writer_lock(out: Path):
    """Hold ``out``'s lock (``.<name>.lock`` beside it) for the block; :class:`OutputError` names
    the run that holds it.

    Parameters
    ----------
    out : pathlib.Path
        The results folder (it need not exist; its parent must).

    Raises
    ------
    foldopt.errors.OutputError
        Where another process holds the lock past :data:`_LOCK_PATIENCE` seconds, where the lock
        file is not foldopt's, or where it cannot be written (:class:`DiskFullError` on a full
        file system).
    """
    out = Path(out)
    descriptor = _acquire(out)
    try:
        yield
    finally:
        _lock_path(out).unlink(missing_ok=True)  # while still held: see _try_lock
        os.close(descriptor)


def _clear_lock(path: Path) -> None:
    """Remove a lock file foldopt left, once no process holds it."""
    if _read_record(path) is None:
        return
    descriptor = _try_lock(path)
    if descriptor is not None:
        path.unlink(missing_ok=True)
        os.close(descriptor)


# --- staging --------------------------------------------------------------------------------------


def clear_leftovers(parent: Path) -> None:
    """Remove the staging folders and lock files that ended writers left in ``parent`` and put the
    folders they retired back in place (see the module docstring).

    Parameters
    ----------
    parent : pathlib.Path
        The folder results folders are written into; nothing is done where it is not a folder.
    """
    if not parent.is_dir():
        return
    for path in sorted(parent.iterdir()):
        match = _LEFTOVER.match(path.name)
        try:
            if match and path.is_dir() and not path.is_symlink():
                _clear_folder(path, parent / match.group(1), match.group(2) == "old")
            elif _LOCK.match(path.name) and path.is_file() and not path.is_symlink():
                _clear_lock(path)
        except OSError:
            continue  # another process clears it at the same time, or it is not ours to clear


def _clear_folder(leftover: Path, home: Path, retired: bool) -> None:
    record = _read_record(leftover / MARKER)
    if record is None or not _gone(record):
        return
    kept = leftover / home.name
    if retired and kept.is_dir() and not home.exists():
        kept.rename(home)  # killed between the two renames of a replacement
    shutil.rmtree(leftover)


def _marked_folder(out: Path, kind: str) -> Path:
    """A new folder ``.<name>.<kind>-<pid>`` beside ``out`` holding :data:`MARKER`: made under a
    scratch name and renamed, so that it never exists unmarked under a name clean-up looks at."""
    scratch = Path(tempfile.mkdtemp(prefix=f".{out.name}.new-", dir=out.parent))
    try:
        (scratch / MARKER).write_text(json.dumps(_record()))
        if kind == "tmp":
            (scratch / out.name).mkdir()
        final = out.parent / f".{out.name}.{kind}-{os.getpid()}"
        scratch.rename(final)
    except BaseException:
        shutil.rmtree(scratch, ignore_errors=True)
        raise
    return final


def new_staging(out: Path) -> Path:
    """A marked staging folder beside ``out``; returns the folder to write the results into.

    Parameters
    ----------
    out : pathlib.Path
        The results folder to be.

    Returns
    -------
    pathlib.Path
        ``.<name>.tmp-<pid>/<name>`` beside ``out``, empty; :func:`commit` or :func:`discard`
        takes it.

    Raises
    ------
    OSError
        Where the folder cannot be made (the caller says why: :func:`staged_folder`).
    """
    return _marked_folder(Path(out), "tmp") / Path(out).name


def commit(staged: Path, out: Path) -> None:
    """Put the results folder ``staged`` (from :func:`new_staging`) in ``out``'s place; an earlier
    ``out`` is retired first and removed only once ``staged`` is in place.

    Parameters
    ----------
    staged, out : pathlib.Path
    """
    out = Path(out)
    if out.exists():
        retired = _marked_folder(out, "old")
        out.rename(retired / out.name)
        try:
            staged.rename(out)
        except BaseException:
            (retired / out.name).rename(out)
            shutil.rmtree(retired, ignore_errors=True)
            raise
        shutil.rmtree(retired)
    else:
        staged.rename(out)
    shutil.rmtree(staged.parent)


def discard(staged: Path) -> int:
    """Remove a staging folder; returns the bytes it held.

    Parameters
    ----------
    staged : pathlib.Path
        The results folder inside the staging folder (from :func:`new_staging`).

    Returns
    -------
    int
        The bytes the staging folder held [bytes], 0 where it is gone.
    """
    size = tree_size(staged.parent) if staged.parent.exists() else 0
    shutil.rmtree(staged.parent, ignore_errors=True)
    return size


@contextmanager
def writing(out: Path):
    """Hold ``out``'s lock (:func:`writer_lock`) for the block, its parent folders made and what
    ended writers left beside it cleared (:func:`clear_leftovers`). The parent folders it made
    are removed again, deepest first, where the block fails and they are empty: a failed run
    leaves nothing behind.

    Parameters
    ----------
    out : pathlib.Path
        The results folder to be.

    Raises
    ------
    foldopt.errors.OutputError
        Where the parent folders cannot be made, or from :func:`writer_lock`.
    """
    out = Path(out)
    made = [folder for folder in out.parents if not folder.exists() and not folder.is_symlink()]
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputError(f"--out {out}: cannot create it ({error.strerror or error})") from None
    try:
        with writer_lock(out):
            clear_leftovers(out.parent)
            yield
    except BaseException:
        for folder in made:
            try:
                folder.rmdir()
            except OSError:  # not empty, or not ours to remove any more
                break
        raise


@contextmanager
def staged_folder(out: Path, overwrite: bool):
    """Yield a temporary folder that replaces ``out`` atomically when the block succeeds; while
    the block runs, ``out``'s lock is held.

    Parameters
    ----------
    out : pathlib.Path
    overwrite : bool
        Whether an existing results folder may be replaced (:func:`check_output`).
    """
    out = Path(out)
    with writing(out):
        check_output(out, overwrite)
        try:
            staged = new_staging(out)
        except OSError as error:
            if is_full(error):
                raise DiskFullError(out, 0) from None
            raise OutputError(
                f"--out {out}: cannot create it ({error.strerror or error})"
            ) from None
        try:
            yield staged
            commit(staged, out)
        except BaseException as error:
            written = discard(staged)
            if is_full(error):
                raise DiskFullError(out, written + getattr(error, "written", 0)) from None
            raise
