"""The CSV tables of a results folder, all written one way: numbers to ten significant digits and
times in ISO 8601 with their UTC offset (a time series keeps its time zone, as pvlib's tz-aware
indexes hold it)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

#: How floats are written: ten significant digits.
FLOAT_FORMAT = "%.10g"
#: How a time index is written: ISO 8601 with the UTC offset (``2014-09-23T12:00:30-0700``).
TIME_FORMAT = "%Y-%m-%dT%H:%M:%S%z"


def write_csv(table: pd.DataFrame, path: Path, index: bool = False) -> Path:
    """Write ``table`` as the CSV file ``path``, floats as :data:`FLOAT_FORMAT`.

    Parameters
    ----------
    table : pandas.DataFrame
    path : pathlib.Path
    index : bool, default False
        Write the index too, its times as :data:`TIME_FORMAT` (a time series' index is its time).

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    if index:
        table.to_csv(path, float_format=FLOAT_FORMAT, date_format=TIME_FORMAT)
    else:
        table.to_csv(path, index=False, float_format=FLOAT_FORMAT)
    return path
