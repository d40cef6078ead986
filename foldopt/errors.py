"""The errors foldopt raises on purpose: a leaf module that imports nothing of foldopt.

Every stage raises these, so they live below all of them: a bad study (:class:`ConfigError`), a
weather file that cannot be used (:class:`WeatherError`) and a results folder that cannot be
written (:class:`OutputError`, :class:`OutputExistsError`). The command line turns each into one
line per fault and exit code 2.
"""

from __future__ import annotations


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
