"""A measured file's edges (foldopt.inputs.weather.measured): whichever end of its periods its stamps
mark, a file holds the days of its light and no others, and what its edges leave to fill is said.

The files are built here from pvlib's clear sky at each period's centre, so that the days they hold
are known: ``DAYS`` whole local days from ``FIRST``."""

from __future__ import annotations

import json
import re

import numpy as np
import pandas as pd
import pvlib
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from foldopt.inputs.weather.measured import read_measured
from test_cli import assert_one_line_error, invoke

SITE = {"latitude": 39.74, "longitude": -105.18, "altitude": 1829.0, "timezone": "UTC-07:00"}
ZONE = "Etc/GMT+7"  # UTC-07:00
FIRST, DAYS = pd.Timestamp("2022-10-01"), 3


def _file(path, first_stamp, step_min: int, label: str, rows: int, site=SITE, sky=None) -> None:
    """A generic CSV of ``rows`` stamps from ``first_stamp`` (local), each the clear sky of the
    period it starts or ends (``label``); ``sky``: :func:`_clear_sky` of those periods, where the
    caller has it."""
    step = pd.Timedelta(minutes=step_min)
    stamps = pd.date_range(first_stamp, periods=rows, freq=step, tz=ZONE)
    centres = stamps + (step / 2 if label == "start" else -step / 2)
    sky = _clear_sky(centres, site) if sky is None else sky
    pd.DataFrame({"timestamp": [stamp.isoformat() for stamp in stamps], "ghi": sky["ghi"].to_numpy(),
                  "dni": sky["dni"].to_numpy(), "dhi": sky["dhi"].to_numpy()}).to_csv(path, index=False)


def _clear_sky(centres, site) -> pd.DataFrame:
    """pvlib's Ineichen clear sky at ``site`` at the periods' ``centres``."""
    location = pvlib.location.Location(site["latitude"], site["longitude"], altitude=site["altitude"])
    return location.get_clearsky(centres, model="ineichen")


def _filled_minutes(report: list[str]) -> float:
    """Minutes the report says the file's edges left and were filled."""
    return sum(float(m.group(1)) for line in report
               if (m := re.match(r"([\d.]+) min (?:before|after) the file's (?:first|last) period filled", line)))


@pytest.mark.parametrize("step_min", [10, 60])
@pytest.mark.parametrize("label", ["start", "end"])
@pytest.mark.parametrize("begins", ["00:00", "00:10"])
def test_a_file_holds_its_days_and_says_what_its_edges_filled(tmp_path, step_min, label, begins):
    """A day's worth of stamps a day from ``begins``: whichever end of its period a stamp marks, the
    file's days are the three it was made for (a period that reaches over midnight into a day the
    file holds nothing else of, at night, makes no day of it), no daylight gap, and the minutes the
    file leaves of its first and last days are reported filled: as many as its periods reach over
    midnight into the day before or after."""
    per_day = 24 * 60 // step_min
    path = tmp_path / f"{label}_{step_min}_{begins.replace(':', '')}.csv"
    _file(path, f"{FIRST:%Y-%m-%d} {begins}", step_min, label, DAYS * per_day)
    weather = read_measured(path, "csv", label=label, site=SITE)
    index = weather.frame.index
    days = index.tz_localize(None).normalize().unique()
    assert list(days) == list(pd.date_range(FIRST, periods=DAYS)), weather.report()
    assert weather.report()[0].split(": ", 1)[1].startswith(
        f"{step_min}-min steps, {DAYS} days ({FIRST.date()} to ")
    assert weather.gaps == () and weather.flagged_days == () and "no daylight gaps" in weather.report()
    # The periods the file holds start at first_start; those before FIRST or after the last day are
    # no day's: the kept days' steps the file does not hold are filled, and as many.
    step = pd.Timedelta(minutes=step_min)
    first_start = pd.Timestamp(f"{FIRST:%Y-%m-%d} {begins}") - (step if label == "end" else 0 * step)
    starts = first_start + step * np.arange(DAYS * per_day)
    outside = (starts < FIRST) | (starts >= FIRST + pd.Timedelta(days=DAYS))
    expected = outside.sum() * step_min
    assert _filled_minutes(weather.report()) == expected, weather.report()
    if expected:
        assert any("not counted: the file holds only" in line for line in weather.report())
    # No air in the file: its default throughout (said so), nothing taken from a nearest step.
    assert not any("nearest step" in line for line in weather.report())
    assert not weather.frame.isna().any().any()


@settings(max_examples=25, deadline=None)
@given(
    step_min=st.sampled_from([1, 5, 10, 15, 30, 60]),
    offset=st.integers(0, 5),
    days=st.integers(1, 3),
    latitude=st.floats(-50.0, 60.0),
)
def test_start_or_end_labels_of_the_same_light_give_the_same_days_and_energy(
    tmp_path_factory, step_min, offset, days, latitude
):
    """The same periods' light, stamped at their starts or (one period later) at their ends: the
    same days, the same light at every step, so the same daily energy."""
    folder = tmp_path_factory.mktemp("labels")
    step = pd.Timedelta(minutes=step_min)
    per_day = 24 * 60 // step_min
    first = FIRST + offset * step
    site = {**SITE, "latitude": latitude}
    # The same periods either way: one clear sky (pvlib's, the example's costly part) for both files.
    sky = _clear_sky(pd.date_range(first + step / 2, periods=days * per_day, freq=step, tz=ZONE), site)
    read = {}
    for label, first_stamp in (("start", first), ("end", first + step)):
        path = folder / f"{label}.csv"
        _file(path, first_stamp, step_min, label, days * per_day, site, sky)
        read[label] = read_measured(path, "csv", label=label, site=site)
    start, end = read["start"].frame, read["end"].frame
    pd.testing.assert_index_equal(start.index, end.index)
    pd.testing.assert_frame_equal(start, end)
    daily = {label: weather.frame["ghi"].groupby(weather.frame.index.date).sum() * step_min / 60
             for label, weather in read.items()}
    pd.testing.assert_series_equal(daily["start"], daily["end"])
    assert _filled_minutes(read["start"].report()) == _filled_minutes(read["end"].report())


def test_the_answer_counts_the_files_days_and_says_what_was_filled(tmp_path, figures_drawn_elsewhere):
    """Through the command line: an end-labelled 10-min file beginning at 00:00 is a study of its
    three days from the first, and the answer says the day before is not counted and the last
    period's 10 min were filled; its series holds those days' steps."""
    path = tmp_path / "end.csv"
    _file(path, f"{FIRST:%Y-%m-%d} 00:00", 10, "end", DAYS * 144)
    out = tmp_path / "s"
    with figures_drawn_elsewhere():  # a measured file's days: test_weather_fetch's fetched series
        result = invoke("sweep", "angle", "--weather", path, "--weather-format", "csv", "--lat", SITE["latitude"],
                        "--lon", SITE["longitude"], "--altitude", SITE["altitude"], "--timezone", SITE["timezone"],
                        "--p-load", "2", "--angle-step", "30", "--out", out, "--format", "json")
    assert result.exit_code == 0, result.output
    answer = json.loads(result.stdout)["answer"]
    notes = [note["note"] for note in answer["notes"]]
    assert notes[0].split(": ", 1)[1].startswith("10-min steps, 3 days (2022-10-01 to 2022-10-03)")
    assert "2022-09-30 not counted: the file holds only 10 min of it, all at night" in notes
    assert any(note.startswith("10 min after the file's last period filled (2022-10-03 23:50 to 00:00; night")
               for note in notes)
    assert not any("daylight gap" in note and "no daylight gaps" not in note for note in notes)
    series = pd.read_csv(out / "timeseries.csv")
    assert sorted({stamp[:10] for stamp in series["time"]}) == ["2022-10-01", "2022-10-02", "2022-10-03"]


def test_a_day_with_a_long_daylight_gap_asked_for_is_one_line(tmp_path):
    """A gap inside the file is no edge: 150 daylight minutes missing on its second day leave that
    day in the file, flagged, and a study of it is refused in one line."""
    path = tmp_path / "gap.csv"
    _file(path, f"{FIRST:%Y-%m-%d} 00:10", 10, "end", DAYS * 144)
    lines = path.read_text().splitlines(keepends=True)
    gap = {f"2022-10-02T{hour:02d}:{minute:02d}" for hour in (10, 11, 12) for minute in range(0, 60, 10)}
    path.write_text("".join(line for line in lines if line[:16] not in gap))
    weather = read_measured(path, "csv", label="end", site=SITE)
    assert [str(day) for day in weather.flagged_days] == ["2022-10-02"] and len(weather.frame) == DAYS * 144
    assert_one_line_error(
        invoke("sweep", "angle", "--weather", path, "--weather-format", "csv", "--lat", SITE["latitude"], "--lon",
               SITE["longitude"], "--altitude", SITE["altitude"], "--timezone", SITE["timezone"], "--days",
               "2022-10-02", "--out", tmp_path / "b"),
        "2022-10-02", "daylight gap too long to fill")
