"""foldopt's cache folder and its files: where the electrical tables, the land mask and matplotlib's
settings are kept between runs (:func:`cache_dir`), and cache files that carry a checksum
(:func:`store_cache`, :func:`load_cache`), so that a damaged one is built again rather than read;
and foldopt's two switches, offline (:func:`offline`) and quiet (:func:`quiet`): each on where its
yes-or-no environment variable says yes (:func:`env_flag`: ``FOLDOPT_OFFLINE``, ``FOLDOPT_QUIET``)
or for a block that turns it on (:func:`offline_mode`, :func:`quiet_mode`: the command line's
``--offline`` and ``--quiet``), in a context variable: foldopt writes no environment variable. A leaf:
it imports nothing of foldopt but the errors.
"""

from __future__ import annotations

import contextvars
import hashlib
import io
import os
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path

from foldopt.errors import ConfigError, printable

#: Ends every cache file, followed by the SHA-256 (hex) of the bytes before it.
_CHECKSUM = b"\nfoldopt-sha256:"
#: Offline in this context (the command line's ``--offline``): what is fetched comes from the
#: cache only (:func:`offline`).
_OFFLINE: contextvars.ContextVar[bool] = contextvars.ContextVar("foldopt_offline", default=False)
#: Quiet in this context (the command line's ``--quiet``): no notice (:func:`quiet`).
_QUIET: contextvars.ContextVar[bool] = contextvars.ContextVar("foldopt_quiet", default=False)
#: The spellings of a yes and of a no an environment variable of :func:`env_flag` takes, in any
#: case; unset or empty is a no.
_YES, _NO = ("1", "true", "yes", "on"), ("0", "false", "no", "off", "")
#: foldopt's yes-or-no environment variables, each read by :func:`env_flag`.
YES_OR_NO_VARIABLES = ("FOLDOPT_OFFLINE", "FOLDOPT_QUIET")


def env_flag(name: str) -> bool:
    """A yes-or-no environment variable of foldopt's (``FOLDOPT_OFFLINE``, ``FOLDOPT_QUIET``).

    Parameters
    ----------
    name : str
        The variable.

    Returns
    -------
    bool
        True for 1, true, yes or on; False for 0, false, no, off, empty or unset (any case, spaces
        around ignored).

    Raises
    ------
    foldopt.errors.ConfigError
        For any other value: one line naming the variable and what it takes.
    """
    value = os.environ.get(name, "")
    word = value.strip().lower()
    if word in _YES or word in _NO:
        return word in _YES
    raise ConfigError(
        [
            f"{name} = {printable(repr(value), 40)}: a yes or a no, one of {', '.join(_YES)} or "
            f"{', '.join(_NO[:-1])} (any case)"
        ]
    )


def offline() -> bool:
    """Whether foldopt fetches nothing and reads fetched data from its cache only:
    ``--offline`` (:func:`offline_mode`) or ``FOLDOPT_OFFLINE`` yes (:func:`env_flag`).

    Raises
    ------
    foldopt.errors.ConfigError
        For a ``FOLDOPT_OFFLINE`` that is no yes or no.
    """
    return env_flag("FOLDOPT_OFFLINE") or _OFFLINE.get()


def offline_mode(on: bool = True):
    """Offline (:func:`offline`) for the block where ``on``.

    Parameters
    ----------
    on : bool, default True
    """
    return _turned_on(_OFFLINE, on)


def quiet() -> bool:
    """Whether foldopt's notices (:func:`notice`) are silent: ``--quiet`` (:func:`quiet_mode`) or
    ``FOLDOPT_QUIET`` yes (:func:`env_flag`).

    Raises
    ------
    foldopt.errors.ConfigError
        For a ``FOLDOPT_QUIET`` that is no yes or no.
    """
    return env_flag("FOLDOPT_QUIET") or _QUIET.get()


def quiet_mode(on: bool = True):
    """Quiet (:func:`quiet`) for the block where ``on``: the command line's ``--quiet``, for the
    command's run.

    Parameters
    ----------
    on : bool, default True
    """
    return _turned_on(_QUIET, on)


@contextmanager
def _turned_on(switch: contextvars.ContextVar, on: bool):
    """``switch`` on for the block where ``on`` (an outer block's on stays on), as it was after."""
    token = switch.set(bool(on) or switch.get())
    try:
        yield
    finally:
        switch.reset(token)


def cache_dir() -> Path:
    """foldopt's cache folder (electrical tables, the land mask, matplotlib's settings where HOME
    cannot be written): ``$FOLDOPT_CACHE_DIR``, else the user's cache folder as platformdirs
    names it (``$XDG_CACHE_HOME/foldopt`` or ``~/.cache/foldopt`` on Linux)."""
    if os.environ.get("FOLDOPT_CACHE_DIR"):
        return Path(os.environ["FOLDOPT_CACHE_DIR"])
    import platformdirs

    return Path(platformdirs.user_cache_dir("foldopt", appauthor=False))


def load_cache(path: Path) -> dict | None:
    """The arrays of the cache file ``path`` (:func:`store_cache`), or None where it is absent or
    damaged: then the caller builds them again. The checksum is verified before anything is read,
    so that a truncated or bit-flipped file is caught whatever its bytes; a damaged file gets a
    one-line notice on stderr (:func:`notice`).

    Parameters
    ----------
    path : pathlib.Path
    """
    try:
        data = Path(path).read_bytes()
    except FileNotFoundError:
        return None
    except OSError as error:
        notice(f"the cache file {path} cannot be read ({error.strerror or error}); {_AGAIN}")
        return None
    payload, mark, digest = data.rpartition(_CHECKSUM)
    if not mark:
        notice(
            f"the cache file {path} has no checksum (written by an earlier foldopt, or "
            f"truncated); {_AGAIN}"
        )
        return None
    if digest != hashlib.sha256(payload).hexdigest().encode():
        notice(f"the cache file {path} is damaged (its checksum does not match); {_AGAIN}")
        return None
    import numpy as np

    with np.load(io.BytesIO(payload), allow_pickle=False) as arrays:
        return {name: arrays[name] for name in arrays.files}


def store_cache(path: Path, arrays: dict, compress: bool = False) -> None:
    """Write ``arrays`` to the cache file ``path``: a NumPy ``.npz`` followed by
    :data:`_CHECKSUM` and the SHA-256 of the ``.npz``, atomically. A cache that cannot be written
    is skipped.

    Parameters
    ----------
    path : pathlib.Path
    arrays : dict of numpy.ndarray
        By name.
    compress : bool, default False
        ``numpy.savez_compressed`` instead of ``numpy.savez``.
    """
    import numpy as np

    buffer = io.BytesIO()
    (np.savez_compressed if compress else np.savez)(buffer, **arrays)
    payload = buffer.getvalue()
    try:
        write_atomically(
            path,
            lambda temporary: temporary.write_bytes(
                payload + _CHECKSUM + hashlib.sha256(payload).hexdigest().encode()
            ),
        )
    except OSError:
        return  # no cache where none can be written


def write_atomically(path: Path, write) -> None:
    """``write(temporary)`` to a new file beside ``path``, then rename it into ``path``: a reader
    sees the old file or the whole new one, and a write that fails (or raises) leaves nothing.

    Parameters
    ----------
    path : pathlib.Path
        The file to write; its folder is made where missing.
    write : callable
        Writes the file whose path (a :class:`pathlib.Path`) it is given.

    Raises
    ------
    OSError
        Where the folder or the file cannot be written; whatever ``write`` raises.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(handle)
    try:
        write(Path(temporary))
        os.replace(temporary, path)  # atomic: readers see the old file or the whole new one
    finally:
        Path(temporary).unlink(missing_ok=True)


_AGAIN = "building it again"


def notice(message: str) -> None:
    """One line on stderr, ``foldopt: <message>``, of something foldopt mended on its way (a
    damaged cache file built or fetched again); none where foldopt is quiet (:func:`quiet`).

    Parameters
    ----------
    message : str
    """
    if not quiet():
        print(f"foldopt: {message}", file=sys.stderr)
