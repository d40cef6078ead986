"""Reading an input file's text, and the size limits of inputs: a leaf module of
:mod:`foldopt.inputs` that every reader (study files, tables of sites, load profiles, horizon
files) shares."""

from __future__ import annotations

import os
import stat
from pathlib import Path

from foldopt.errors import ConfigError


def size_limit(name: str, default: int) -> int:
    """A size limit, raised by the environment variable ``FOLDOPT_<NAME>``.

    Parameters
    ----------
    name : str
        The limit's name (``MAX_CASES``).
    default : int
        Its value where the variable is unset or not a number.

    Returns
    -------
    int
    """
    text = os.environ.get(f"FOLDOPT_{name}")
    try:
        return int(float(text)) if text else default
    except ValueError:
        return default


#: Bytes of a study file.
MAX_STUDY_BYTES = size_limit("MAX_STUDY_BYTES", 1_000_000)
#: Bytes of a CSV input (a table of sites, a load profile): MAX_CASES sites at 100 bytes a row.
MAX_CSV_BYTES = size_limit("MAX_CSV_BYTES", 20_000_000)


#: What :func:`read_input` calls a file that is no regular file, by its type.
_SPECIAL_FILES = ((stat.S_ISCHR, "character device"), (stat.S_ISBLK, "block device"), (stat.S_ISFIFO, "FIFO"),
                  (stat.S_ISSOCK, "socket"))


def read_input(path: Path | str, field: str, limit: int, limit_name: str) -> str:
    """The text of an input file (a study, a table of sites, a load profile), read as UTF-8
    whatever the locale, a byte-order mark (a spreadsheet's "CSV UTF-8") dropped.

    Parameters
    ----------
    path : str or pathlib.Path
    field : str
        What messages name the file by (``config``, ``--sites``...).
    limit : int
        Its largest size [bytes].
    limit_name : str
        The limit's name: ``FOLDOPT_<limit_name>`` raises it.

    Returns
    -------
    str

    Raises
    ------
    ConfigError
        One line naming ``field`` and the file: missing, a folder, no regular file (a device or a
        FIFO never ends, or never starts), larger than ``limit``, unreadable or not UTF-8 text.
    """
    path = Path(path)
    try:
        # Opened without blocking and checked by the open descriptor, so that a FIFO cannot hold
        # the command and no file swapped in after a check is read.
        descriptor = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(descriptor, "rb") as handle:
            info = os.fstat(handle.fileno())
            mode = info.st_mode
            if stat.S_ISDIR(mode):
                raise ConfigError([f"{field}: {path} is a folder; give a file"])
            kind = next((name for test, name in _SPECIAL_FILES if test(mode)), None)
            if kind is not None:
                raise ConfigError([f"{field}: {path} is a {kind}, not a regular file; give a file"])
            # A file that says it is too large is not read; one that grows while it is read is cut.
            data = b"" if info.st_size > limit else handle.read(limit + 1)
    except FileNotFoundError:
        raise ConfigError([f"{field}: file not found: {path}"]) from None
    except IsADirectoryError:  # Python's file object refuses a folder's descriptor itself
        raise ConfigError([f"{field}: {path} is a folder; give a file"]) from None
    except OSError as error:
        raise ConfigError([f"{field}: cannot read {path}: {error.__class__.__name__}"]) from None
    if info.st_size > limit or len(data) > limit:
        size = f"{info.st_size:,} bytes" if info.st_size > limit else f"over {limit:,} bytes"
        raise ConfigError([f"{field}: {path} is {size}; at most {limit:,} (FOLDOPT_{limit_name} raises it)"])
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise ConfigError([f"{field}: cannot read {path}: not UTF-8 text (byte {error.start + 1:,})"]) from None
