"""The errors foldopt raises on purpose: a leaf module that imports nothing of foldopt.

Every stage raises these, so they live below all of them: a bad study (:class:`ConfigError`), a
weather file that cannot be used (:class:`WeatherError`) and a results folder that cannot be
written (:class:`OutputError`, :class:`OutputExistsError`). The command line turns each into one
line per fault and exit code 2. Text a message takes from a file is made :func:`printable` first,
and an address it quotes is :func:`redacted`: a message never shows a secret.
"""

from __future__ import annotations

import re

#: Characters a terminal would act on rather than show: C0 and C1 controls, DEL; and the same but
#: line breaks and tabs.
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f]")
_CONTROL_BUT_BREAKS = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")
#: An address in a text (``scheme://...``), up to a space, a quote, a bracket or a semicolon.
_ADDRESS = re.compile(r"\b[A-Za-z][A-Za-z0-9+.\-]*://[^\s'\"<>(),;]*")
#: A query parameter whose name says it holds a secret (``token``, ``api_key``, ``password``...).
_SECRET_NAME = re.compile(r"pass|pwd|secret|token|key|auth|sig|credential|session|cookie", re.I)


def printable(text, limit: int | None = None, breaks: bool = False) -> str:
    """Text fit for a message: control characters (a binary file's bytes, a terminal's escapes,
    line breaks) as ``\\xNN`` escapes, cut to ``limit`` characters.

    Parameters
    ----------
    text : object
        Its ``str``.
    limit : int, optional
        The most characters kept (an ellipsis ends a cut text); default all.
    breaks : bool, default False
        Keep line breaks and tabs (a terminal's several lines).

    Returns
    -------
    str
    """
    control = _CONTROL_BUT_BREAKS if breaks else _CONTROL
    text = control.sub(lambda match: f"\\x{ord(match.group()):02x}", str(text))
    return text if limit is None or len(text) <= limit else text[: limit - 3] + "..."


def redacted(value):
    """``value`` with every address in it (``scheme://...``) stripped of what may be a secret:
    the user and password before its host (``http://user:secret@mirror/`` -> ``http://mirror/``)
    and the query parameters whose names say they hold one (``?token=...``, ``api_key``,
    ``password``). What foldopt writes (a message, the cache's provenance, ``run.json``) is
    redacted; the address is asked as given.

    Parameters
    ----------
    value : str or dict or list or object
        A text, or data holding texts (``run.json``'s: the strings in a dict's values and a
        list's items); anything else is returned as it is.

    Returns
    -------
    str or dict or list or object
    """
    if isinstance(value, str):
        return _ADDRESS.sub(lambda found: _redacted_address(found.group()), value)
    if isinstance(value, dict):
        return {key: redacted(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [redacted(item) for item in value]
    return value


def _redacted_address(address: str) -> str:
    scheme, _, rest = address.partition("://")
    authority, tail = re.match(r"([^/?#]*)(.*)", rest, re.S).groups()
    path, question, query = tail.partition("?")
    query, hash_, fragment = query.partition("#")
    kept = [
        pair
        for pair in query.split("&")
        if pair and not _SECRET_NAME.search(pair.partition("=")[0])
    ]
    query = ("?" + "&".join(kept)) if question and kept else ""
    return f"{scheme}://{authority.rpartition('@')[2]}{path}{query}{hash_}{fragment}"


class ConfigError(ValueError):
    """A study that cannot be run.

    Parameters
    ----------
    errors : list of str
        One ``field: problem`` line per fault, kept as :attr:`errors` (each :func:`redacted`);
        the message joins them with semicolons.
    """

    def __init__(self, errors: list[str]):
        errors = [redacted(line) for line in errors]
        super().__init__("; ".join(errors))
        self.errors = errors

    def __reduce__(self):
        # Raised on a Dask worker, the error travels pickled: keep its lines, whatever the subclass.
        return _config_error, (type(self), self.errors)


def _config_error(cls, errors: list[str]) -> ConfigError:
    error = cls.__new__(cls)
    ConfigError.__init__(error, errors)
    return error


class WeatherError(ConfigError):
    """A weather file that cannot be used.

    Parameters
    ----------
    message : str
        One line naming the file, where in it and why.
    """

    def __init__(self, message: str):
        super().__init__([message])


class OutputExistsError(FileExistsError):
    """The results folder exists and overwriting was not asked for."""


class OutputError(OSError):
    """The results folder cannot be written there, or must not be replaced."""
