"""Named NumPy columns: a result's table until it is written or handed to a user.

A day's study reaches its answer from a handful of small tables (the sweep, the summary, the time
series, the tracker's standby). Held as :class:`Columns` they need NumPy alone, so that the
answer is printed before pandas is imported (some 0.2 s of a warm ``foldopt run``, see
docs/performance.rst); :meth:`Columns.to_frame` makes the :class:`pandas.DataFrame` where a table
is written or where the API hands it to a user. A leaf: it imports nothing of foldopt.
"""

from __future__ import annotations

import numpy as np


class TimeIndex:
    """Tz-aware instants as UTC nanoseconds and a time zone, what a time series is indexed by.

    Parameters
    ----------
    utc_ns : numpy.ndarray of int64
        UTC epoch of each instant [ns].
    timezone : datetime.tzinfo or str
        The zone the times are shown in.
    name : str, optional
        The index's name.
    """

    def __init__(self, utc_ns, timezone, name=None):
        self.utc_ns = np.asarray(utc_ns, dtype=np.int64)
        self.timezone = timezone
        self.name = name

    def __len__(self) -> int:
        return self.utc_ns.size

    def to_index(self):
        """The :class:`pandas.DatetimeIndex` of these instants in their time zone."""
        import pandas as pd

        utc = pd.DatetimeIndex(self.utc_ns.astype("datetime64[ns]"), tz="UTC")
        return utc.tz_convert(self.timezone).rename(self.name)


class Columns:
    """A table as named 1-D NumPy columns of one length, in order, with an optional index.

    Parameters
    ----------
    columns : dict
        Name -> values (array_like, one value per row; a scalar is repeated over the rows).
    index : TimeIndex, optional
        The rows' times; None for a table indexed by row number.
    """

    def __init__(self, columns: dict, index: TimeIndex | None = None):
        arrays = {name: np.asarray(values) for name, values in columns.items()}
        length = next((a.size for a in arrays.values() if a.ndim), 0)
        if index is not None:
            length = len(index)
        self._columns = {
            name: np.full(length, a) if a.ndim == 0 else a for name, a in arrays.items()
        }
        if any(a.shape != (length,) for a in self._columns.values()):
            raise ValueError("columns of a table need one length")
        self.index = index

    @property
    def columns(self) -> list[str]:
        """The columns' names, in order."""
        return list(self._columns)

    def __len__(self) -> int:
        return len(self.index) if self.index is not None else self._length()

    def _length(self) -> int:
        return next((a.size for a in self._columns.values()), 0)

    def __contains__(self, name) -> bool:
        return name in self._columns

    def __getitem__(self, key):
        """A column's values by name, or a table of the columns named in a list."""
        if isinstance(key, list):
            return Columns({name: self._columns[name] for name in key}, self.index)
        return self._columns[key]

    def assign(self, **columns) -> Columns:
        """This table with columns added or replaced (appended in the order given)."""
        return Columns({**self._columns, **columns}, self.index)

    def join(self, other: Columns) -> Columns:
        """This table's columns and then another's, row by row (``pandas.concat(axis=1)``)."""
        return Columns({**self._columns, **other._columns}, self.index)

    def row(self, column: str, value) -> dict:
        """The first row whose ``column`` holds ``value``: name -> value.

        Raises
        ------
        KeyError
            If no row holds it.
        """
        at = np.flatnonzero(self._columns[column] == value)
        if not at.size:
            raise KeyError(value)
        return {name: values[at[0]] for name, values in self._columns.items()}

    def to_frame(self):
        """The table as a :class:`pandas.DataFrame`, columns in order, its index the times'."""
        import pandas as pd

        index = None if self.index is None else self.index.to_index()
        return pd.DataFrame(dict(self._columns), index=index)


def as_frame(table):
    """A table as a :class:`pandas.DataFrame`: a :class:`Columns` converted, a DataFrame (or None)
    as it is.

    Parameters
    ----------
    table : Columns, pandas.DataFrame or None
    """
    return table.to_frame() if isinstance(table, Columns) else table
