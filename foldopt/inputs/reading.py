"""Reading an input file's text, and the size limits of inputs: a leaf module of
:mod:`foldopt.inputs` that every reader (study files, tables of sites, load profiles, horizon
files, weather files) shares. A file that is missing, a folder, a device, a FIFO or over its
limit is refused by name before anything reads it (:func:`check_input`, :func:`read_input`)."""

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
#: Bytes of a weather file: a TMY3 or EPW year is under 2 MB, a year of 1-min steps in the generic
#: CSV about 40 MB, a BSRN station-to-archive month 10 MB.
MAX_WEATHER_BYTES = size_limit("MAX_WEATHER_BYTES", 100_000_000)
#: Values of one sweep axis (a range or a list), or of one searched range of foldopt optimize.
MAX_AXIS_VALUES = size_limit("MAX_AXIS_VALUES", 10_000)
#: Steps a measured weather file's days may lay out: two years of 1-min steps. Stamps years apart
#: at a short step (a slip in a year) would otherwise mean a grid of millions of steps.
MAX_MEASURED_STEPS = size_limit("MAX_MEASURED_STEPS", 2 * 366 * 1440)


#: What :func:`check_input` calls a file that is no regular file, by its type.
_SPECIAL_FILES = (
    (stat.S_ISCHR, "character device"),
    (stat.S_ISBLK, "block device"),
    (stat.S_ISFIFO, "FIFO"),
    (stat.S_ISSOCK, "socket"),
)


def _size_text(size: int) -> str:
    """``2.0 GB``, ``25 MB``, ``3 kB``."""
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if size >= scale:
            value = size / scale
            return f"{value:.1f} {unit}" if value < 10 else f"{value:.0f} {unit}"
    return f"{size} bytes"


def _refuse(
    info: os.stat_result, path: Path, field: str, limit: int, limit_name: str, what: str
) -> None:
    """Raise :class:`ConfigError` unless ``info`` is a regular file of at most ``limit`` bytes."""
    if stat.S_ISDIR(info.st_mode):
        raise ConfigError([f"{field}: {path} is a folder, not a file; give a file"])
    kind = next((name for test, name in _SPECIAL_FILES if test(info.st_mode)), None)
    if kind is not None:
        raise ConfigError([f"{field}: {path} is a {kind}, not a regular file; give a file"])
    if info.st_size > limit:
        raise ConfigError(
            [
                f"{field}: {path} is {info.st_size:,} bytes ({_size_text(info.st_size)}): larger than "
                f"any {what} foldopt reads, at most {limit:,} bytes (FOLDOPT_{limit_name} raises it)"
            ]
        )


def _not_found(path: Path, field: str) -> str:
    """``file not found``, or the missing target of a symbolic link that exists."""
    if path.is_symlink():
        return f"{field}: {path} is a symbolic link to {os.readlink(path)}, which does not exist"
    return f"{field}: file not found: {path}"


def check_input(
    path: Path | str, field: str, limit: int, limit_name: str, what: str = "input file"
) -> None:
    """Refuse, before anything reads it, an input file that is missing, no regular file (a folder,
    a device or a FIFO: a device never ends, a FIFO may never start) or larger than ``limit``: for
    readers that open the file themselves (pvlib's), as :func:`read_input` does for its own.

    Parameters
    ----------
    path : str or pathlib.Path
    field : str
        What messages name the file by (``weather``, ``--sites``...).
    limit : int
        Its largest size [bytes].
    limit_name : str
        The limit's name: ``FOLDOPT_<limit_name>`` raises it.
    what : str, default 'input file'
        What kind of file it is, for the message on its size (``weather file``).

    Raises
    ------
    ConfigError
        One line naming ``field`` and the file, and what it is.
    """
    path = Path(path)
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise ConfigError([_not_found(path, field)]) from None
    except OSError as error:
        raise ConfigError(
            [f"{field}: cannot read {path}: {error.strerror or error.__class__.__name__}"]
        ) from None
    _refuse(info, path, field, limit, limit_name, what)


def read_input(
    path: Path | str, field: str, limit: int, limit_name: str, what: str = "input file"
) -> str:
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
    what : str, default 'input file'
        What kind of file it is, for the message on its size.

    Returns
    -------
    str

    Raises
    ------
    ConfigError
        One line naming ``field`` and the file: missing, a folder, no regular file (a device or a
        FIFO never ends, or never starts), larger than ``limit``, unreadable or not UTF-8 text
        (:func:`check_input`'s refusals, made on the open file).
    """
    path = Path(path)
    try:
        # Opened without blocking and checked by the open descriptor, so that a FIFO cannot hold
        # the command and no file swapped in after a check is read.
        descriptor = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(descriptor, "rb") as handle:
            info = os.fstat(handle.fileno())
            _refuse(info, path, field, limit, limit_name, what)
            # One that grows while it is read is cut.
            data = handle.read(limit + 1)
    except FileNotFoundError:
        raise ConfigError([_not_found(path, field)]) from None
    except IsADirectoryError:  # Python's file object refuses a folder's descriptor itself
        raise ConfigError([f"{field}: {path} is a folder, not a file; give a file"]) from None
    except OSError as error:
        raise ConfigError([f"{field}: cannot read {path}: {error.__class__.__name__}"]) from None
    if len(data) > limit:
        raise ConfigError(
            [
                f"{field}: {path} is over {limit:,} bytes: larger than any {what} foldopt reads "
                f"(FOLDOPT_{limit_name} raises it)"
            ]
        )
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise ConfigError(
            [f"{field}: cannot read {path}: not UTF-8 text (byte {error.start + 1:,})"]
        ) from None
