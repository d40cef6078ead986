"""The CSV tables foldopt writes, all written one way: numbers to ten significant digits and times in
ISO 8601 with their UTC offset (a time series keeps its time zone, as pvlib's tz-aware indexes hold
it). A leaf, so that a map's table (:mod:`foldopt.studies.cluster`) and a results folder's
(:mod:`foldopt.output.folders`) are written alike.

pandas' ``DataFrame.to_csv`` is the reference. A table of plain columns (NumPy floats, integers and
booleans, and strings) is written by :func:`write_csv` itself, to the same bytes, in about half
the time (pandas formats each float through its own machinery; figures in
``docs/performance.rst``), the rows formatted :data:`ROWS_AT_ONCE` at a time. Here each
column is formatted by one ``%`` per value and the rows go to Python's ``csv`` writer, which pandas
uses too. ``tests/test_tables.py`` holds the bytes to pandas'.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pandas as pd

#: How floats are written: ten significant digits.
FLOAT_FORMAT = "%.10g"
#: How a time index is written: ISO 8601 with the UTC offset (``2014-09-23T12:00:30-0700``).
TIME_FORMAT = "%Y-%m-%dT%H:%M:%S%z"
#: Rows formatted at a time: their strings, not the whole table's, are held at once, so that a map
#: of a million rows is written in bounded memory (docs/performance.rst, "Memory").
ROWS_AT_ONCE = 50_000


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
        return path
    if not _plain(table):
        table.to_csv(path, index=False, float_format=FLOAT_FORMAT)
        return path
    # As pandas writes it: UTF-8, "\n" after every row, fields quoted only where they must be.
    with open(path, "w", encoding="utf-8", newline="") as stream:
        writer = csv.writer(stream, lineterminator="\n")
        writer.writerow([str(name) for name in table.columns])
        for start in range(0, len(table), ROWS_AT_ONCE):
            writer.writerows(zip(*_fields(table.iloc[start : start + ROWS_AT_ONCE])))
    return path


def _plain(table: pd.DataFrame) -> bool:
    """Whether every column is plain: NumPy floats, integers or booleans, or strings (missing
    ones allowed). Dates, categories, nullable types, objects other than strings and a multi-level
    header are not: pandas writes those tables."""
    if isinstance(table.columns, pd.MultiIndex) or not len(table.columns):
        return False
    for _, values in table.items():
        dtype = values.dtype
        if isinstance(dtype, np.dtype) and dtype.kind in "fiub":
            continue
        if not pd.api.types.is_string_dtype(dtype) or isinstance(dtype, pd.CategoricalDtype):
            return False
        if not all(isinstance(item, str) or _missing(item) for item in values.tolist()):
            return False
    return True


def _fields(table: pd.DataFrame) -> list[list[str]]:
    """Each column's fields as pandas writes them, of a plain table (:func:`_plain`)."""
    columns = []
    for _, values in table.items():
        kind = values.dtype.kind if isinstance(values.dtype, np.dtype) else "U"
        if kind == "f":
            array = values.to_numpy()
            fields = list(map(FLOAT_FORMAT.__mod__, array.tolist()))
            for at in np.flatnonzero(np.isnan(array)).tolist():
                fields[at] = ""  # pandas' na_rep
        elif kind in "iub":
            fields = list(map(str, values.tolist()))
        else:
            fields = [item if isinstance(item, str) else "" for item in values.tolist()]
        columns.append(fields)
    return columns


def _missing(item) -> bool:
    """None, NaN or pandas' NA: an empty field."""
    return item is None or item is pd.NA or (isinstance(item, float) and math.isnan(item))
