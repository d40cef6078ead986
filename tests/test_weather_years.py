"""A measured series of years (issue 49): planned in one pass over its days, not a study per day,
and its answer, day by day, that of the same days run one at a time.

The series is PVGIS's recorded hourly answer for 45 N, 8 E, 2020-2021 (tests/data/pvgis/README.md),
and its year 2021 alone.
"""

from __future__ import annotations

import datetime as dt
import json
from pathlib import Path

import numpy as np
import pytest

from foldopt.api import run
from foldopt.inputs.study import Study
from foldopt.studies.request import make_request

HOURLY = Path(__file__).parent / "data" / "pvgis" / "seriescalc_45.000_8.000_2020_2021.json"


def _series(path) -> dict:
    return {"weather": str(path), "weather_format": "pvgis-hourly"}


@pytest.fixture(scope="module")
def one_year(tmp_path_factory) -> Path:
    """The recorded answer's year 2021 alone, as PVGIS answers for one year."""
    answer = json.loads(HOURLY.read_text())
    hourly = [record for record in answer["outputs"]["hourly"] if record["time"].startswith("2021")]
    path = tmp_path_factory.mktemp("series") / "seriescalc_2021.json"
    path.write_text(json.dumps({**answer, "outputs": {"hourly": hourly}}))
    return path


def test_a_series_is_planned_with_as_many_studies_whatever_its_days(one_year, monkeypatch):
    """Planning validates a study per value of each other axis, not per day: a year and two years
    of the same file's kind validate the same number of studies (it was one per day)."""
    validated = []
    original = Study.model_validate.__func__

    def counted(cls, *args, **kwargs):
        validated.append(1)
        return original(cls, *args, **kwargs)

    monkeypatch.setattr(Study, "model_validate", classmethod(counted))
    counts = {}
    for path in (one_year, HOURLY):
        validated.clear()
        plan = make_request("sweep angle", options=_series(path)).plan
        counts[len(dict(plan.axes)["date"])] = len(validated)
    assert sorted(counts) == [365, 731]
    assert counts[365] == counts[731] < 10, counts


def test_each_day_of_a_planned_series_is_its_base_study_on_that_day():
    """A day's study, made from the plan as the run makes it, is the plan's first day's study with
    that date: nothing else of a study depends on its day, which is why the days are not
    validated a study each."""
    plan = make_request("sweep angle", options=_series(HOURLY)).plan
    days = dict(plan.axes)["date"]
    assert days[0] == dt.date(2020, 1, 1) and days[-1] == dt.date(2021, 12, 31)
    for day in days[::9] + days[-1:]:
        study = plan.study({"date": day})
        assert study == plan.base.model_copy(update={"date": day})
        assert study.data() == {**plan.base.data(), "date": day.isoformat()}


def test_a_two_year_series_answer_is_its_days_run_one_at_a_time():
    """The series' one fold angle for both years, then each day's metrics in one pass over the
    days: on every design, each day's t_solar, energy and light are those of that day's own study
    (the day alone from the same file) at the same fold angle, to the last bit."""
    series = run(request=make_request("sweep angle", options=_series(HOURLY)))
    table = series.table.set_index(["date", "design"])
    angle = float(table.xs("twofold", level="design")["fold_angle_deg"].iloc[0])
    weather = {"path": str(HOURLY), "format": "pvgis-hourly"}
    columns = ["t_solar_h", "energy_harvested_wh", "energy_served_wh", "peak_power_w"]
    for day in ("2020-01-01", "2020-02-29", "2020-06-21", "2021-03-28", "2021-12-31"):
        alone = run(request=make_request("run", fields={"weather": weather, "date": day}))
        assert alone.engine == series.engine
        rows = table.xs(day, level="date")
        summary = alone.summary.set_index("design")
        for design in ("flat", "tracker", "tracker-net"):
            np.testing.assert_array_equal(
                rows.loc[design, columns].to_numpy(float),
                summary.loc[design, columns].to_numpy(float),
                err_msg=f"{day} {design}",
            )
        at_angle = alone.sweep.set_index("fold_angle_deg").loc[angle]
        np.testing.assert_array_equal(
            rows.loc["twofold", columns].to_numpy(float),
            at_angle[columns].to_numpy(float),
            err_msg=f"{day} twofold at {angle:g} deg",
        )
        assert rows.loc["twofold", "poa_global_wh_m2"] > 0
