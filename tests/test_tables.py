"""CSV tables (foldopt.tables): the same bytes as pandas' DataFrame.to_csv with the same float
format, the reference, on random tables of every plain column type and on the special values
(NaN, infinities, -0, subnormals, strings that must be quoted), and pandas' own writing of any
other column."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from foldopt.tables import FLOAT_FORMAT, TIME_FORMAT, write_csv

TEXT = st.one_of(st.text(alphabet=st.sampled_from(list('ab ,"\'\n\r\té€;')), max_size=6),
                 st.sampled_from(["Zürich", "São"]))
FLOATS = st.floats(allow_nan=True, allow_infinity=True, width=64)


def _not_pandas(*args, **kwargs):
    raise AssertionError("a plain table went to pandas")


def _pandas(table, path, **kwargs) -> bytes:
    table.to_csv(path, float_format=FLOAT_FORMAT, **kwargs)
    return path.read_bytes()


@settings(max_examples=60, deadline=None)
@given(rows=st.integers(0, 6), data=st.data())
def test_plain_tables_are_pandas_bytes(tmp_path_factory, rows, data):
    folder = tmp_path_factory.mktemp("csv")
    columns = {
        "x": pd.Series(data.draw(st.lists(FLOATS, min_size=rows, max_size=rows)), dtype=float),
        "n": pd.Series(data.draw(st.lists(st.integers(-2**62, 2**62), min_size=rows, max_size=rows)), dtype="int64"),
        "ok": pd.Series(data.draw(st.lists(st.booleans(), min_size=rows, max_size=rows)), dtype=bool),
        "name, with comma": pd.Series(data.draw(st.lists(st.one_of(TEXT, st.none()), min_size=rows, max_size=rows)),
                                      dtype="str"),
    }
    table = pd.DataFrame(columns)
    with pytest.MonkeyPatch.context() as patch:  # written by foldopt, not handed to pandas
        patch.setattr(pd.DataFrame, "to_csv", _not_pandas)
        mine = write_csv(table, folder / "mine.csv").read_bytes()
    assert mine == _pandas(table, folder / "pandas.csv", index=False)


def test_special_values_are_pandas_bytes(tmp_path):
    table = pd.DataFrame({
        "x": [np.nan, np.inf, -np.inf, -0.0, 5e-324, 1e-5, 123456789012.0, 0.1 + 0.2, 4.398, 1e300],
        "u": np.arange(10, dtype=np.uint8),
        "s": ["", "a,b", 'say "hi"', "line\nbreak", None, np.nan, "é", " ", "x", "y"],
    })
    assert write_csv(table, tmp_path / "mine.csv").read_bytes() == _pandas(table, tmp_path / "pandas.csv", index=False)
    assert (tmp_path / "mine.csv").read_text(encoding="utf-8").splitlines()[1] == ",0,"  # NaN and "": empty fields


@pytest.mark.parametrize("other", [
    pd.Series(pd.date_range("2025-06-21", periods=3, freq="h", tz="Europe/Madrid")),
    pd.Series(["a", "b", "a"], dtype="category"),
    pd.Series([1.5, None, 2.0], dtype="Float64"),
    pd.Series([1, "b", 2.5], dtype=object),
])
def test_other_columns_are_written_by_pandas(tmp_path, other):
    table = pd.DataFrame({"x": [0.1, 0.2, 0.3], "other": other})
    assert write_csv(table, tmp_path / "mine.csv").read_bytes() == _pandas(table, tmp_path / "pandas.csv", index=False)


def test_a_time_series_keeps_its_offset(tmp_path):
    table = pd.DataFrame({"poa_global": [0.0, 812.5]},
                         index=pd.date_range("2014-09-23 12:00:30", periods=2, freq="min", tz="Etc/GMT+7"))
    text = write_csv(table, tmp_path / "ts.csv", index=True).read_text()
    assert text == _pandas(table, tmp_path / "pandas.csv", date_format=TIME_FORMAT).decode()
    assert "2014-09-23T12:00:30-0700,0" in text


def test_a_table_longer_than_a_slice_is_pandas_bytes(tmp_path, monkeypatch):
    # Rows are formatted a slice at a time (foldopt.tables.ROWS_AT_ONCE): slices of 2 over 7 rows.
    import foldopt.tables

    monkeypatch.setattr(foldopt.tables, "ROWS_AT_ONCE", 2)
    table = pd.DataFrame({"x": np.linspace(-1.0, 1.0, 7), "n": np.arange(7), "s": list("abcdefg")})
    table.loc[3, "x"] = np.nan
    assert write_csv(table, tmp_path / "mine.csv").read_bytes() == _pandas(table, tmp_path / "pandas.csv", index=False)
