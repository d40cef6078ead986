"""A day's tables as named NumPy columns (:mod:`foldopt.columnar`): the DataFrame each makes is
the one pandas makes of the same columns, its JSON records are the DataFrame's, and the notes an
answer reads of it are what pandas' explode and groupby read of the DataFrame."""

from __future__ import annotations

import zoneinfo

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from foldopt.columnar import Columns, TimeIndex, as_frame
from foldopt.studies.answer import records
from foldopt.studies.result_answers import design_notes


def _table():
    return {
        "design": np.array(["flat", "twofold", "tracker"], dtype=object),
        "fold_angle_deg": np.array([180.0, 28.5, np.nan]),
        "t_solar_h": np.array([7.73, 9.44, 11.19]),
        "switch_state": np.array(["off", "parallel", "series"]),
        "count": np.array([1, 2, 3]),
        "lit": np.array([True, False, True]),
        "p_load_w": 4.398,
    }


def test_a_tables_frame_is_pandas_frame_of_its_columns():
    frame = Columns(_table()).to_frame()
    pd.testing.assert_frame_equal(frame, pd.DataFrame(_table()))
    assert list(frame["p_load_w"]) == [4.398] * 3


def test_a_time_series_frame_is_indexed_by_its_zones_times():
    zone = zoneinfo.ZoneInfo("America/Los_Angeles")
    utc = pd.date_range("2014-11-02 07:30", periods=4, freq="h", tz="UTC").as_unit("ns")
    frame = Columns({"dni": np.arange(4.0)}, TimeIndex(utc.asi8, zone, name="time")).to_frame()
    index = pd.DatetimeIndex(utc.tz_convert(zone).rename("time"), freq=None)
    expected = pd.DataFrame({"dni": np.arange(4.0)}, index=index)
    pd.testing.assert_frame_equal(frame, expected)
    # The clocks went back in the middle: the index holds both 01:30s, as the instants say.
    assert [t.strftime("%H:%M%z") for t in frame.index] == [
        "00:30-0700",
        "01:30-0700",
        "01:30-0800",
        "02:30-0800",
    ]


def test_a_tables_records_are_its_frames():
    table = Columns(_table())
    assert records(table) == records(table.to_frame())
    assert records(Columns({})) == records(pd.DataFrame()) == []


def test_selected_joined_and_assigned_columns_keep_their_order():
    table = Columns(_table())
    assert table[["t_solar_h", "design"]].columns == ["t_solar_h", "design"]
    joined = table.join(Columns({"extra": [1.0, 2.0, 3.0]})).assign(design=np.array(["a"] * 3))
    assert joined.columns == [*_table(), "extra"] and list(joined["design"]) == ["a"] * 3
    assert table.row("design", "tracker")["t_solar_h"] == 11.19
    with pytest.raises(KeyError):
        table.row("design", "flat-panel")
    with pytest.raises(ValueError, match="one length"):
        Columns({"a": [1.0, 2.0], "b": [1.0]})
    assert as_frame(None) is None and isinstance(as_frame(table), pd.DataFrame)


def _pandas_notes(table: pd.DataFrame, case_count=None) -> list[dict]:
    """The notes as pandas reads them: each note's rows by explode and groupby (the reference)."""
    if "note" not in table or not len(table):
        return []
    exploded = table.assign(note=table["note"].astype(str).str.split("; ")).explode("note")
    exploded = exploded[exploded["note"] != ""]
    every = set(table["design"])
    notes = []
    for note, rows in exploded.groupby("note", sort=True):
        designs = list(dict.fromkeys(rows["design"]))
        entry = {"note": note, "designs": [] if set(designs) == every else designs}
        if case_count is not None:
            keys = [c for c in rows.columns if c in ("latitude", "p_load_w")]
            entry.update(
                cases=int(len(rows.drop_duplicates(keys))) if keys else len(rows), of=case_count
            )
        notes.append(entry)
    return notes


NOTES = st.sampled_from(["", "load above peak", "overcast", "drive exceeds harvest", "a; b"])


@settings(max_examples=150, deadline=None)
@given(
    rows=st.lists(
        st.tuples(
            st.sampled_from(["flat", "twofold", "tracker", "tracker-net"]),
            st.lists(NOTES, max_size=3),
            st.sampled_from([10.0, 20.0, np.nan]),
            st.sampled_from([1.0, 2.0]),
        ),
        max_size=12,
    ),
    keys=st.sampled_from([(), ("latitude",), ("latitude", "p_load_w")]),
    cases=st.sampled_from([None, 7]),
)
def test_the_notes_of_a_table_are_pandas_explode_and_groupby(rows, keys, cases):
    """design_notes reads a day's Columns and a sweep's DataFrame alike, as pandas' explode and
    groupby read the DataFrame: each note once, sorted, with the designs it concerns (none where
    it concerns every design) and the cases it is found in (a NaN key one value)."""
    columns = {
        "design": np.array([r[0] for r in rows], dtype=object),
        "note": np.array(["; ".join(r[1]) for r in rows], dtype=object),
        "latitude": np.array([r[2] for r in rows], dtype=float),
        "p_load_w": np.array([r[3] for r in rows], dtype=float),
    }
    columns = {name: columns[name] for name in ("design", "note", *keys)}
    frame = pd.DataFrame(columns)
    expected = _pandas_notes(frame, cases)
    assert design_notes(frame, cases) == expected
    assert design_notes(Columns(columns), cases) == expected
