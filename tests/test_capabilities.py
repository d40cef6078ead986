"""The capability matrix walked (issue 47): every command with every section of
:data:`foldopt.capabilities.CAPABILITIES` either changes the answer's numbers or is refused in
one line that names the section. No command ignores a section silently (a buffer under
``optimize`` and ``map`` was, as a site's altitude given to a map was).

Each request is a tiny study (hourly steps, a 30-degree grid of fold angles) so that the walk,
some 70 requests, stays a few seconds; what is compared is every number of the answer.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

import foldopt
from foldopt.capabilities import CAPABILITIES, CAPABILITY, COMMANDS, RUNS, matrix_rows
from foldopt.cli.app import app
from foldopt.studies.request import make_request
from foldopt.studies.worldmap import evaluate_sites

WEATHER = str(Path(__file__).resolve().parent.parent / "configs" / "weather" / "723170TYA.CSV")
#: Greensboro's site (the weather file's), one summer day, a small grid: each run well under a second.
TINY = {
    "name": "tiny",
    "mode": "exact",
    "site": {"latitude": 36.1, "longitude": -79.95},
    "date": "2025-06-21",
    "panel": {"area": 0.1, "efficiency": 0.2},
    "p_load": 2.0,
    "step_min": 60,
    "fold_angles": {"start": 30, "stop": 180, "step": 30},
}
#: Each capability as the fields that give it: chosen so that it moves every run's numbers.
GIVEN = {
    "storage": {"storage": {"capacity_wh": 20.0}},
    "costs": {"storage": {"capacity_wh": 20.0, "target": {"powered_h": 12.0}},
              "costs": {"panel_usd_per_m2": 150.0, "buffer_usd_per_wh": 0.5}},
    "weather": {"weather": WEATHER},
    "weather.members": {"weather": {"path": WEATHER, "members": 2}, "objective": "mean"},
    "site.horizon": {"site": {"latitude": 36.1, "longitude": -79.95,
                              "horizon": [[0, 35], [120, 35], [240, 35]]}},
    "load_profile": {"load_profile": {"daily": {"00:00": 0.5, "12:00": 6.0}}},
    "optimize": {"optimize": {"vary": ["fold_angle", "tilt"], "tilt": {"min": 0, "max": 60,
                                                                       "step": 30}}},
    "panel.planes": {"panel": {"area": 0.1, "efficiency": 0.2, "planes": [[9, 14], [9, 194]]}},
    # not a capability of the registry (every run but the sizing has a tracker): its own draw
    "tracker": {"tracker": {"standby_w": 0.5}},
}
#: Each command's request, as the API makes it: its command, its own fields and parameters.
REQUESTS = {
    "run": ("run", {}, {}),
    "sweep angle": ("sweep angle", {}, {}),
    "sweep latitude": ("sweep latitude", {"latitude": [30.0, 36.1]}, {}),
    "sweep day": ("sweep day", {"date": "2025-06-01:2025-06-30:15"}, {}),
    "sweep day, an objective": ("sweep day", {"date": "2025-06-01:2025-06-30:15",
                                              "objective": "mean"}, {}),
    "sweep load": ("sweep load", {"p_load": [1.0, 3.0]}, {}),
    "optimize": ("optimize", {}, {"optimize": {"vary": ["fold_angle"]}}),
    "size": ("size", {}, {"costs": {}}),
    "size --storage": ("size --storage", {}, {"target_h": 12.0}),
    "map": ("map", {}, {"where": {"latitudes": [36.1], "longitudes": [-79.95]}}),
}


def _numbers(result) -> object:
    """Every number of an answer (and a map's rows), rounded to 9 digits: what a section changes."""
    if isinstance(result, tuple):  # a map's request: its rows
        spec = result[0]
        rows = evaluate_sites(spec.study, spec.sites, spec.loads, spec.relative, spec.year)
        return _rounded(json.loads(rows.to_json(orient="records")))
    answer = result.answer.to_dict()
    return _rounded([answer.get(key) for key in ("result", "designs", "near_optimal", "schedule")])


def _rounded(value):
    if isinstance(value, float):
        return None if math.isnan(value) else float(f"{value:.9g}")
    if isinstance(value, dict):
        return {key: _rounded(item) for key, item in value.items()}
    if isinstance(value, list):
        return [_rounded(item) for item in value]
    return value


def _answer(name: str, study: dict, given: dict | None = None):
    """The request ``name`` of :data:`REQUESTS` on ``study``, with the fields ``given``, run: its
    result (a map: its spec)."""
    command, fields, parameters = REQUESTS[name]
    request = make_request(command, study, fields={**fields, **(given or {})}, **parameters)
    if command == "map":
        return (request.plan,)
    if command == "size":
        return foldopt.size(request=request, areas=[0.05, 0.1])
    return foldopt.run(request=request)


def _with(study: dict, fields: dict) -> dict:
    return {**study, **fields}


@pytest.fixture(scope="module")
def bases():
    return {name: _numbers(_answer(name, TINY)) for name in REQUESTS}


@pytest.mark.parametrize("capability", list(GIVEN))
@pytest.mark.parametrize("name", list(REQUESTS))
def test_every_command_honours_a_section_or_refuses_it_in_one_line(bases, name, capability):
    study = _with(TINY, GIVEN[capability])
    if name == "map" and capability == "weather":
        study.pop("site")  # a map's weather is each site's (the file's own site is refused: below)
    try:
        # the tracker's draw given by the request, as --tracker-standby gives it
        result = (_answer(name, TINY, {"tracker.standby_w": 0.5}) if capability == "tracker"
                  else _answer(name, study))
    except foldopt.ConfigError as error:
        assert len(error.errors) == 1, error.errors
        # the section is named: refused for this run, or for what it is (a weather file is one site's)
        assert capability.split(".")[0] in error.errors[0], error.errors
        return
    assert _numbers(result) != bases[name], f"{name} ignored {capability}"


@pytest.mark.parametrize("capability", [c for c in CAPABILITIES if c.instead])
def test_a_refusal_names_the_section_the_command_and_where_it_is_honoured(capability):
    """The refusal's words come from the registry: the command, what its run is, and where the
    section is honoured instead."""
    run = next(run for run in RUNS if run not in capability.honoured)
    command = next(command for command in COMMANDS if run in foldopt.capabilities.COMMAND_RUNS[command])
    line = foldopt.capabilities.refusal(capability.name, command, run)
    assert line.startswith(f"{capability.name}: foldopt {command} ({RUNS.describe(run)})")
    assert line.endswith(capability.instead)


def test_a_buffer_under_optimize_and_map_is_refused_not_ignored(tmp_path, monkeypatch):
    """The issue's examples: optimize --storage-wh 20 and map --set storage.capacity_wh=20
    answered storage-less without a word."""
    monkeypatch.chdir(tmp_path)
    runner = CliRunner()
    for args in (["optimize", "--vary", "fold_angle", "--storage-wh", "20"],
                 ["map", "--lat", "0", "--lon", "0", "--set", "storage.capacity_wh=20"]):
        result = runner.invoke(app, [*args, "--out", "out"])
        assert result.exit_code == 2, result.output
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: storage: foldopt "), lines
        assert not (tmp_path / "out").exists()


def test_a_field_a_run_sets_itself_is_refused_not_overridden():
    """A map's sites set each site's altitude, the sizing has no tracker: a request that gives
    them is told, not overridden silently."""
    with pytest.raises(foldopt.ConfigError, match=r"^site.altitude: a map's sites are"):
        make_request("map", fields={"site.altitude": 3000.0},
                     where={"latitudes": [0.0], "longitudes": [0.0]})
    with pytest.raises(foldopt.ConfigError, match=r"^tracker.standby_w: Shin et al.'s panel sizing"):
        make_request("size", fields={"tracker.standby_w": 1.0}, costs={})


def test_the_docs_matrix_is_the_registry():
    """The docs' table is drawn from the registry: a row per capability, a column per run."""
    header, *rows = matrix_rows()
    assert header == ["capability", "what it is", *RUNS]
    assert [row[0] for row in rows] == list(CAPABILITY)
    for row in rows:
        honoured = CAPABILITY[row[0]].honoured
        assert row[2:] == ["yes" if run in honoured else "refused" for run in RUNS]
