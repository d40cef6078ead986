"""Measured minutes against their hourly means (issue 24): the committed measured days
(tests/data/measured) through foldopt.studies.validation, as bench/weather_validation.py runs them
for the manual's table (docs/weather.rst).

What the hourly means lose is measured here against the minutes themselves, the independent
reference: the smooth path runs long on broken-cloud days, where an hour whose mean clears the
load counts whole; the cloud ensemble widens exactly there. The ensemble does not contain every
broken day's measured t_solar: an hour's means cannot tell thin, steady overcast from broken cloud
(MIDC NWTC M2 2018-10-14, hours 10-12), and the published cover climatology the ensemble draws its
overcast hours from makes such hours broken more often than not."""

import importlib.util
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "bench" / "weather_validation.py"
#: One worker runs this module (pytest-xdist --dist loadgroup): its three tests share one table of 20-member
#: ensembles (15-30 s), which each worker built again when both ran a test of it.
pytestmark = pytest.mark.xdist_group("weather_minutes")


@pytest.fixture(scope="session")
def table():
    spec = importlib.util.spec_from_file_location("weather_validation", BENCH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    with pytest.MonkeyPatch.context() as patch:
        # Most of the table's engine calls (a day's 36 fold angles, one sky or 20 members, at 288
        # to 1440 steps) are under the bound up to which ``auto`` takes the NumPy reference though
        # the kernel is compiled: here ``auto`` takes the kernel where numba's cache holds it (the
        # suite's warm-up compiled it), the reference where it does not (never a compile). What
        # is checked is the minutes against their hourly means, which the two paths give alike
        # (here to 1.3e-13 h; test_engine.py holds the kernel to the reference): half the CPU.
        patch.setattr("foldopt.engine.choice.AUTO_CACHED_NUMPY_ROW_STEPS", 0)
        frame = module.validation(members=20)
    frame["bias_min"] = 60 * (frame["smooth_h"] - frame["measured_h"])
    frame["inside"] = (frame["ensemble_p5_h"] - 1e-9 <= frame["measured_h"]) & (
        frame["measured_h"] <= frame["ensemble_p95_h"] + 1e-9)
    frame["width_min"] = 60 * (frame["ensemble_p95_h"] - frame["ensemble_p5_h"])
    return frame


def test_the_days_are_the_files_whole_days(table):
    # Ten days in all; the RMIS days with a daylight gap longer than an hour are left out.
    days = table.groupby("file")["date"].nunique().to_dict()
    assert days == {"SURFRAD Alamosa": 1, "MIDC NWTC M2": 1, "MIDC UA OASIS": 1, "SRML Eugene": 1,
                    "RMIS Golden 2019": 3, "RMIS Golden 2022": 3}
    broken = sorted(set(zip(table.file[table.sky == "broken"], table.date[table.sky == "broken"], strict=True)))
    assert broken == [("MIDC NWTC M2", "2018-10-14"), ("RMIS Golden 2019", "2019-02-02"),
                      ("RMIS Golden 2022", "2022-01-03")]


def test_the_smooth_path_runs_long_where_clouds_break(table):
    # Issue 24: on broken-cloud days the hourly means bias daily t_solar upward (an hour whose mean
    # clears the load counts whole); on steady days the smooth minutes are close to the measured.
    # Measured: broken +15.6 min on average (up to +42 min: MIDC, 2 W, tracker), steady +1.0 min
    # (5.3 min absolute).
    broken, steady = table[table.sky == "broken"], table[table.sky == "steady"]
    assert broken["bias_min"].mean() > 5.0
    assert broken["bias_min"].max() > 25.0
    assert abs(steady["bias_min"].mean()) < 5.0 and steady["bias_min"].abs().mean() < 10.0


def test_the_ensemble_spreads_where_clouds_break(table):
    # The members' P5-P95 is several times wider on broken days than on steady ones (measured:
    # 24 min against 4 min), and holds the measured t_solar in more than a third of the broken
    # days' cases (measured 39 %: RMIS 2019-02-02 8 of 12, MIDC 4 of 12, RMIS 2022-01-03 2 of 12;
    # the module docstring says why thin overcast escapes it).
    broken, steady = table[table.sky == "broken"], table[table.sky == "steady"]
    assert broken["width_min"].mean() > 3.0 * steady["width_min"].mean()
    assert broken["inside"].mean() > 1 / 3
    rmis = broken[broken.date == "2019-02-02"]
    assert rmis["inside"].mean() >= 0.5
    # Steady days' members barely differ: the band is minutes wide.
    assert steady["width_min"].median() < 5.0
