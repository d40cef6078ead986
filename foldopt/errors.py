"""The errors foldopt raises on purpose: a leaf module that imports nothing of foldopt.

Every stage raises these, so they live below all of them: a bad study (:class:`ConfigError`), a
weather file that cannot be used (:class:`WeatherError`) and a results folder that cannot be
written (:class:`OutputError`, :class:`OutputExistsError`). The command line turns each into one
line per fault and exit code 2. Text a message takes from a file is made :func:`printable` first.
"""

from __future__ import annotations

import re

#: Characters a terminal would act on rather than show: C0 and C1 controls, DEL; and the same but
#: line breaks and tabs.
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f]")
_CONTROL_BUT_BREAKS = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")


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


class ConfigError(ValueError):
    """A study that cannot be run.

    Parameters
    ----------
    errors : list of str
        One ``field: problem`` line per fault, kept as :attr:`errors`; the message joins them
        with semicolons.
    """

    def __init__(self, errors: list[str]):
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
