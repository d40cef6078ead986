"""A map is complete only when every file it promises is written (issue 38, items 1 and 2): a map
whose figures, ``map.nc`` or report fail never replaces the earlier map and is never marked
complete; every figure and writer copes with what a map's table can legally hold (no site able to
carry a load, every value equal, a single site, a single load); inputs given twice are refused in
one line, before any work. The cluster is a LocalCluster of this process on 127.0.0.1."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest
import xarray as xr
import yaml
from typer.testing import CliRunner

import foldopt
from foldopt.cli.app import app
from foldopt.errors import ConfigError
from foldopt.inputs.study_file import default_study_path
from foldopt.inputs.plan import make_plan

distributed = pytest.importorskip("distributed")
pytestmark = pytest.mark.xdist_group("map_finish")

runner = CliRunner()
#: The embedded study made cheap: hourly steps, fold angles 60, 120 and 180 deg.
STUDY = foldopt.map_study(yaml.safe_load(default_study_path().read_text()), step_min=60,
                          fold_angles={"start": 60, "stop": 180, "step": 60})
#: Every file a complete grid map promises beside its parts.
PROMISED = {"run.json", "sites.csv", "map.parquet", "map.csv", "map.nc", "report.html", "map_fold_angle.png",
            "map_gain_vs_flat.png", "map_pct_of_tracker.png", "map_near_optimal_width.png",
            "latitude_load_gain.png"}


def snapshot(folder: Path) -> dict[str, str]:
    return {str(path.relative_to(folder)): hashlib.sha256(path.read_bytes()).hexdigest()
            for path in sorted(folder.rglob("*")) if path.is_file()}


def world_map(scheduler, out, sites, loads, **keywords):
    """The map on the compiled kernel, a map's engine (what is tested is its folder)."""
    return foldopt.world_map(sites, loads, out, STUDY, scheduler=scheduler, engine="numba", **keywords)


#: Tables a map can legally hold, at their edges: the sites and loads of each.
LEGAL = {
    # No site carries 25 W on a 0.108 m^2 panel (its flat peak is about 21 W): every gain is NaN.
    "no-site-carries": ([{"latitude": 0.0, "longitude": 0.0}, {"latitude": 30.0, "longitude": 0.0}], [25.0]),
    # Two sites on the equator 90 deg apart under a clear sky: every value equal.
    "all-equal": ([{"latitude": 0.0, "longitude": 0.0}, {"latitude": 0.0, "longitude": 90.0}], [2.0]),
    # A single site and a single load; then a single site and two loads.
    "one-site-one-load": ([{"latitude": 45.0, "longitude": 8.0}], [2.0]),
    "one-site-two-loads": ([{"latitude": 45.0, "longitude": 8.0}], [1.0, 3.0]),
}


@pytest.fixture(scope="module")
def legal_maps(scheduler, tmp_path_factory):
    """``drawn(case)``: the map of a :data:`LEGAL` case, made once a module for every test that
    reads it, its figures drawn whole (where no test's fixture draws them without pixels: in a
    module fixture's setup, or a test marked ``figure_pixels``): its folder and what the map
    returned."""
    made = {}

    def drawn(case: str):
        if case not in made:
            out = tmp_path_factory.mktemp(case) / "map"
            made[case] = out, world_map(scheduler, out, *LEGAL[case])
        return made[case]

    return drawn


@pytest.fixture(scope="module")
def earlier(legal_maps) -> Path:
    """A complete map of two sites at 2 W (the legal table whose values are all equal)."""
    return legal_maps("all-equal")[0]


def _broken(*args, **kwargs):
    raise RuntimeError("a figure fails")


@pytest.mark.parametrize("writer", ["map_figures", "write_map_report"])
def test_a_map_whose_last_files_fail_leaves_the_earlier_map(earlier, scheduler, tmp_path, monkeypatch, writer,
                                                           figures_drawn_elsewhere):
    # The figures written before the report fails are PNGs of one pixel, not drawn: what is tested
    # is the folder (the figures of every legal table are drawn whole below).
    import shutil

    out = tmp_path / "map"
    shutil.copytree(earlier, out)
    before = snapshot(out)
    monkeypatch.setattr(f"foldopt.output.folders.{writer}", _broken)
    with pytest.raises(RuntimeError, match="a figure fails"), figures_drawn_elsewhere():
        world_map(scheduler, out, [{"latitude": 10.0, "longitude": 0.0}], [3.0], overwrite=True)
    assert snapshot(out) == before
    assert sorted(path.name for path in tmp_path.iterdir()) == ["map"]  # no staging folder left


def test_a_new_map_whose_last_files_fail_is_not_complete_and_resumes(scheduler, tmp_path, monkeypatch,
                                                                     figures_drawn_elsewhere):
    out = tmp_path / "map"
    sites = [{"latitude": 10.0, "longitude": 0.0}]
    with monkeypatch.context() as patch:
        patch.setattr("foldopt.output.folders.map_figures", _broken)
        with pytest.raises(RuntimeError):
            world_map(scheduler, out, sites, [3.0])
    assert json.loads((out / "run.json").read_text())["status"] == "running"
    assert not (out / "report.html").exists()
    with figures_drawn_elsewhere():  # PNGs of one pixel: what is tested is which files the folder holds
        run, _, _ = world_map(scheduler, out, sites, [3.0], resume=True)
    assert run.computed == () and json.loads((out / "run.json").read_text())["status"] == "complete"
    assert PROMISED <= {path.name for path in out.iterdir()}


@pytest.mark.parametrize("case", list(LEGAL))
@pytest.mark.figure_pixels  # the figures of tables at their edges, drawn whole
def test_every_figure_and_writer_copes_with_a_legal_table(legal_maps, case):
    sites, loads = LEGAL[case]
    out, (run, figures, answer) = legal_maps(case)
    assert PROMISED <= {path.name for path in out.iterdir()}
    assert json.loads((out / "run.json").read_text())["status"] == "complete"
    assert set(figures) <= PROMISED
    # No NaN in what the answer says: the JSON is strict, and its lines say "nan" nowhere.
    json.dumps(answer.result, allow_nan=False)
    assert not any("nan" in line.lower().split() for line in answer.lines())
    with xr.open_dataset(out / "map.nc") as data:
        assert data.sizes["latitude"] * data.sizes["longitude"] >= len(sites)
        assert data.sizes["load"] == len(loads)
    if loads == [25.0]:
        assert any("no fold angle carries the load; the tracker carries it at no site either" in line
                   for line in answer.lines())
        assert answer.designs["gain_vs_flat_pct"].isna().all()  # the table keeps its NaN; the lines do not




# --- inputs given twice -----------------------------------------------------------------------------------------


@pytest.mark.parametrize("args, words", [
    (["map", "--lat", "30,30", "--lon", "0"], ["--lat", "30 is given twice"]),
    (["map", "--lat", "30", "--lon", "0,10,0"], ["--lon", "0 is given twice (values 1 and 3)"]),
    (["map", "--lat", "30", "--lon", "0", "--p-load", "2,2"], ["--p-load", "2 is given twice"]),
    (["sweep", "load", "--p-load", "2,2.0"], ["--p-load", "2 is given twice"]),
    (["sweep", "day", "--days", "2025-06-21,2025-06-21"], ["--days", "2025-06-21 is given twice"]),
])
def test_a_value_given_twice_is_one_line(tmp_path, monkeypatch, args, words):
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, [*args, "--out", "out"])
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and all(word in lines[0] for word in words), result.output
    assert list(tmp_path.iterdir()) == []


def test_a_site_given_twice_in_a_sites_file_is_one_line(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    Path("sites.csv").write_text("latitude,longitude\n30,0\n10,5\n30.0,0\n")
    result = runner.invoke(app, ["map", "--sites", "sites.csv", "--out", "out"])
    assert result.exit_code == 2
    assert result.output.strip() == ("error: --sites sites.csv: the site at 30, 0 is given twice (sites 1 and 3); "
                                     "give each site once")
    assert sorted(path.name for path in tmp_path.iterdir()) == ["sites.csv"]


def test_the_same_place_under_two_names_or_two_weather_files_is_two_sites():
    sites = [{"latitude": 30.0, "longitude": 0.0, "name": "a"}, {"latitude": 30.0, "longitude": 0.0, "name": "b"}]
    from foldopt.studies.map_request import map_request

    assert len(map_request(STUDY, 2.0, sites=sites).sites) == 2


def test_a_study_files_axis_given_twice_is_one_line():
    with pytest.raises(ConfigError) as raised:
        make_plan({**yaml.safe_load(default_study_path().read_text()), "p_load": [2, 3, 2]})
    assert raised.value.errors == ["p_load = [2, 3, 2]: 2 is given twice (values 1 and 3); give each value once"]


def test_a_misspelt_objective_is_named_beside_the_missing_dates(tmp_path, monkeypatch):
    # The "several dates" fault once hid the objective's own: the newcomer saw no "did you mean".
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["sweep", "angle", "--objective", "worst-mnth", "--out", "out"])
    assert result.exit_code == 2
    assert "did you mean 'worst-month'?" in result.output and "needs several dates" in result.output
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args, words", [
    (["run", "--set", "fold_angles.step=1e-9"], ["fold_angles.step = '1e-9'", "180,000,000,000 fold angles"]),
    (["sweep", "angle", "--angle-step", "1e-9"], ["--angle-step = 1e-09", "fold angles"]),
])
def test_a_fold_angle_grid_too_fine_is_refused_at_once(tmp_path, monkeypatch, args, words):
    # The grid was listed before any limit looked at it: 1.8e11 angles, a hang.
    import time

    monkeypatch.chdir(tmp_path)
    started = time.perf_counter()
    result = runner.invoke(app, [*args, "--out", "out"])
    assert time.perf_counter() - started < 10
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and all(word in lines[0] for word in words) and "(line" not in lines[0], result.output
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("value", ["-1", "200", "abc", "0", "true"])
def test_a_fold_angle_step_out_of_range_is_one_line_naming_the_step(tmp_path, monkeypatch, value):
    # A step given alone starts the grid at the step; a bad one was refused twice, the second time
    # as a start the user never gave ("fold_angles.start = -1").
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["run", "--set", f"fold_angles.step={value}", "--out", "out"])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: fold_angles.step = "), result.output
    assert list(tmp_path.iterdir()) == []
