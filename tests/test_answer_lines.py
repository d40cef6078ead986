"""Answers that hold against themselves where a design carries nothing: no NaN or 'nan' in any line or
JSON, a line that says why where there is no ratio to give (a gain over a flat panel that carries none of
the load, a share of a tracker that carries none), and one clear line where an objective has no day to
take."""

from __future__ import annotations

import json
import re

import pytest
from typer.testing import CliRunner

from foldopt.cli.app import app

#: A load of 4.3 W from 07:00 to 08:00 and none otherwise: in Los Angeles in September the flat panel,
#: facing south, never reaches it so early, where a folded panel's east half does.
MORNING = "time,watts\n00:00,0\n07:00,4.3\n08:00,0\n"


def _answer(tmp_path, *options):
    done = CliRunner().invoke(app, [*options, "--format", "json", "--out", str(tmp_path / "out")])
    assert done.exit_code == 0, done.output

    def refuse(constant):
        raise ValueError(f"{constant} in the JSON")

    answer = json.loads(done.stdout, parse_constant=refuse)["answer"]
    for line in answer["lines"]:
        assert re.search(r"\bnan\b", line, flags=re.IGNORECASE) is None, line
        assert " - over" not in line and " - of" not in line, line
    return answer


@pytest.mark.parametrize("days", [[], ["--days", "2014-09-01:2014-09-30:7", "--objective", "mean"]],
                         ids=["day", "days"])
def test_a_gain_over_a_flat_panel_that_carries_nothing_says_so(tmp_path, days):
    """The folded panel carries the morning load some 20 min a day, the flat one never: there is no
    gain to give (it printed '- over flat (0.00 h)'); the line says the flat panel carries none of the
    load, the JSON's gain is null."""
    profile = tmp_path / "morning.csv"
    profile.write_text(MORNING, encoding="utf-8")
    answer = _answer(tmp_path, "sweep", "angle", "--load-profile", str(profile), "--mode", "exact", *days)
    hours = {row["design"]: row.get("t_solar_h", row.get("t_solar_objective_h")) for row in answer["designs"]}
    assert hours["flat"] == 0.0 < hours["twofold"]
    best = answer["lines"][2]
    assert "where the flat panel carries none of the load (flat 0.00 h)" in best and "% over" not in best
    if not days:
        assert answer["result"]["gain_vs_flat_pct"] is None


def test_an_annual_objective_no_angle_carries_says_so_once(tmp_path):
    """At 80 N in November and December the sun never rises: no angle carries the load, said once (the
    near-optimal line said it again), with no gain and no range."""
    answer = _answer(tmp_path, "sweep", "angle", "--lat", "80", "--days", "2014-11-01:2014-12-31:10",
                     "--objective", "mean", "--p-load", "2", "--step-min", "15")
    said = [line for line in answer["lines"] if "carries the load" in line]
    assert len(said) == 1 and said[0].endswith("no fold angle carries the load: mean t_solar 0.00 h (flat 0.00 h);"
                                                " tracker 0.00 h")
    assert all(row["recommended_deg"] is None for row in answer["near_optimal"])


@pytest.mark.parametrize("statistic", ["p10", "worst-month", "mean", "min"])
def test_a_season_none_of_the_days_is_in_is_refused_by_a_sweep(tmp_path, statistic):
    """An objective over June of January's days has no day to take: it was an internal error (a
    percentile, a minimum of nothing); one line naming objective.months, as foldopt optimize says it,
    nothing written."""
    out = tmp_path / "out"
    done = CliRunner().invoke(app, ["sweep", "angle", "--days", "1:31:5", "--objective", statistic, "--set",
                                    "objective.months=[6]", "--out", str(out)])
    assert done.exit_code == 2, done.output
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: objective.months = [6]: none of the 7 days")
    assert not out.exists()
