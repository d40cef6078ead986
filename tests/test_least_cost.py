"""The cheapest panel and buffer that meet the target (foldopt.studies.least_cost, issue 50 part 3):
the search against a brute-force grid of area x capacity x fold computed here with the engine's
simulate alone, its limits (a free buffer, a target out of reach, prices scaled), the costs
section's refusals, and the command line against the API."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import foldopt
from foldopt.cli.app import app
from foldopt.engine.storage import Buffer, simulate
from foldopt.inputs.costs_section import Costs
from foldopt.inputs.storage_section import Storage, StorageTarget
from foldopt.studies.answer import plain
from foldopt.studies.request import make_request
from foldopt.studies.least_cost import AREA_FACTORS, design_space, least_cost_answer

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()

#: Ten hourly days of a sunny, dull and dark mix [-], each a day's sine scaled.
WEATHER = np.array([1.0, 0.3, 0.8, 0.1, 1.0, 0.6, 0.2, 0.9, 0.5, 1.0])
HOURS = np.arange(24) + 0.5
AREA = 0.4  # [m^2]
LOAD = 1.0  # [W]


def _day(width: float, peak: float) -> np.ndarray:
    """A clear day's power [W]: a sine ``width`` hours wide around noon, ``peak`` at its top."""
    return peak * np.clip(np.sin((HOURS - 12 + width / 2) / width * np.pi), 0, None)


def _curves():
    """Flat, twofold at three angles (flatter and wider as they fold) and a tracker, at AREA."""
    days = WEATHER[:, None]
    twofold = np.stack([days * _day(w, p) for w, p in ((13, 9.0), (14, 8.0), (12, 9.5))])
    return {
        "flat": days * _day(12, 10.0),
        "twofold": twofold,
        "tracker-net": days * _day(15, 10.0),
    }


ANGLES = np.array([60.0, 100.0, 140.0])
DRAW = np.where((HOURS > 6) & (HOURS < 18), 0.05, 0.0)[None].repeat(WEATHER.size, 0)
#: A buffer whose powered time does not fall as it grows (no hysteresis, no leak): the search's
#: premise, so that the brute force's least capacity is the search's.
STORAGE = Storage(
    capacity_wh=5.0,
    min_soc=0.2,
    charge_efficiency=0.95,
    discharge_efficiency=0.9,
    target=StorageTarget(powered_h=24, days_pct=70),
)
#: A LiFePO4 behind its controller: a reconnect band and a leak, where a larger buffer may run
#: the load less (the premise holds here at the grids' resolution).
LIFEPO4 = Storage(capacity_wh=5.0, preset="lifepo4", target=StorageTarget(powered_h=24, days_pct=70))
COSTS = Costs(
    panel_usd_per_m2=150, buffer_usd_per_wh=0.6, hinge_usd=2, drive_dual_axis_usd=10, fixed_usd=5
)


def _search(costs=COSTS, storage=STORAGE, load=LOAD):
    """The design space of :func:`_curves`, each search run once for the module (four tests read
    the default one, two the LiFePO4's); a copy."""
    key = (costs.model_dump_json(), storage.model_dump_json(), load)
    if key not in _SEARCHED:
        _SEARCHED[key] = design_space(
            _curves(),
            ANGLES,
            area_m2=AREA,
            load=load,
            storage=storage,
            costs=costs,
            tracker_model="dual-axis",
            step_hours=1.0,
            engine="numba",
            in_sequence=True,
            draw=DRAW,
        )
    return _SEARCHED[key].copy()


#: The searches run so far, by their costs, storage and load.
_SEARCHED = {}


def _meets(curve, capacities, draw=None, load=LOAD, storage=STORAGE):
    """Whether each capacity [Wh] runs the load the target's hours on its share of the days, by
    the engine's simulate alone (the days in sequence, from the periodic state)."""
    buffer = Buffer(
        capacity_wh=np.asarray(capacities, dtype=float),
        min_soc=storage.min_soc,
        restart_soc=storage.restart_soc,
        charge_efficiency=storage.charge_efficiency,
        discharge_efficiency=storage.discharge_efficiency,
        self_discharge=storage.self_discharge,
    )
    result = simulate(
        curve[None], load, buffer, 1.0, "numba", draw=None if draw is None else draw[None]
    )
    target = storage.target
    days = result.powered_h >= target.powered_h - 1e-9
    return (100 * days.mean(axis=1) >= target.days_pct - 1e-9) & result.converged


def _top(storage) -> float:
    """The sizing grid's top [Wh]: four days' load energy over the usable fraction (the search's
    stated bound, foldopt.studies.storage_sizing.capacity_grid)."""
    return 4 * LOAD * 24 / ((1 - storage.min_soc) * storage.discharge_efficiency)


def _brute_force(costs=COSTS, storage=STORAGE):
    """Each kind's cheapest (cost, area, capacity, angle) on a grid of area x capacity x fold."""
    capacities = np.geomspace(_top(storage) / 3000, _top(storage), 700)
    curves = _curves()
    kinds = {
        "flat": [(180.0, curves["flat"], 0.0, None)],
        "twofold": [(a, c, costs.hinge_usd, None) for a, c in zip(ANGLES, curves["twofold"])],
        "tracker-net": [(np.nan, curves["tracker-net"], costs.drive_dual_axis_usd, DRAW)],
    }
    best = {}
    for kind, designs in kinds.items():
        found = []
        for angle, curve, extra, draw in designs:
            for factor in AREA_FACTORS:
                ok = _meets(curve * factor, capacities, draw, storage=storage)
                if ok.any():
                    capacity = capacities[np.argmax(ok)]
                    cost = (
                        factor * AREA * costs.panel_usd_per_m2
                        + capacity * costs.buffer_usd_per_wh
                        + extra
                        + costs.fixed_usd
                    )
                    found.append((cost, factor * AREA, capacity, angle))
        best[kind] = min(found, key=lambda f: f[0]) if found else None
    return best


@pytest.mark.parametrize("storage", [STORAGE, LIFEPO4], ids=["no-hysteresis", "lifepo4"])
def test_the_least_cost_design_is_the_brute_force_grid_s_of_each_kind(storage):
    # The search's least cost of each kind is the brute force's to within the capacities'
    # resolutions (its own 1e-3, the grid's 1.2 %), and its design meets the target.
    space = _search(storage=storage)
    brute = _brute_force(storage=storage)
    curves = _curves()
    for kind, (cost, area, capacity, angle) in brute.items():
        row = space[(space["design"] == kind) & space["least_cost"]].iloc[0]
        assert row["cost_usd"] == pytest.approx(cost, abs=0.013 * capacity * 0.6), kind
        assert row["area_m2"] not in (space["area_m2"].min(), space["area_m2"].max()), kind
        curve = {
            "flat": curves["flat"],
            "tracker-net": curves["tracker-net"],
            "twofold": curves["twofold"][list(ANGLES).index(row["fold_angle_deg"])]
            if kind == "twofold"
            else None,
        }[kind]
        scaled = curve * row["area_m2"] / AREA
        draw = DRAW if kind == "tracker-net" else None
        assert _meets(scaled, [row["capacity_wh"]], draw, storage=storage)[0], kind
        # A buffer 0.5 % smaller falls short: the capacity is the area's least.
        assert not _meets(scaled, [row["capacity_wh"] * 0.995], draw, storage=storage)[0], kind


@pytest.mark.parametrize("storage", [STORAGE, LIFEPO4], ids=["no-hysteresis", "lifepo4"])
def test_every_row_s_capacity_meets_the_target_and_its_bracket_s_bottom_does_not(storage):
    # The frontier's rows not refined are the sizing grid's capacities: each meets the target
    # at its area, and the grid's capacity below it does not.
    space, curves = _search(storage=storage), _curves()
    rows = {"flat": [curves["flat"]], "tracker-net": [curves["tracker-net"]],
            "twofold": list(curves["twofold"])}  # fmt: skip
    for row in space[space["meets"]].itertuples():
        index = 0 if row.design != "twofold" else list(ANGLES).index(row.fold_angle_deg)
        scaled = rows[row.design][index] * row.area_m2 / AREA
        draw = DRAW if row.design == "tracker-net" else None
        below = row.capacity_wh * (1 - row.capacity_bracket_frac) * (1 - 1e-9)
        said = [True, row.capacity_wh == 0]  # no buffer at all: nothing below it
        assert _meets(scaled, [row.capacity_wh, below], draw, storage=storage).tolist() == said


@pytest.mark.parametrize("load", [LOAD, 0.4, 3.0], ids=["1W", "0.4W", "3W"])
def test_the_walk_s_grid_bounds_are_every_area_and_capacity_evaluated(load):
    # The frontier on the grids (least_cost._grid_bounds) against the whole grid of area x
    # capacity evaluated by the engine's simulate alone: at each area the least capacity of the
    # sizing's grid that meets the target and the one below it; each kind's walk evaluates at
    # most n_areas + the grid's size of them.
    from foldopt.studies.least_cost import _grid_bounds, _Known, _Run
    from foldopt.studies.storage_sizing import capacity_grid

    curves = _curves()
    power = np.concatenate([curves["flat"][None], curves["twofold"]])
    m = AREA_FACTORS.size
    grid = capacity_grid(load, STORAGE, 1.0, power.shape[-1])

    def scaled(rows):
        return power[rows // m] * AREA_FACTORS[rows % m, None, None]

    known = _Known(scaled, None, _Run((load, STORAGE, 1.0, "numba", True), {}))
    upper, lower = _grid_bounds(known, grid, (len(power), m))
    assert len(known.found) <= len(power) * (m + grid.size)
    for row in range(len(power) * m):
        ok = _meets(scaled(np.array([row]))[0], grid, load=load)
        if not ok.any():
            assert np.isnan(upper[row]) and np.isnan(lower[row])
            continue
        first = int(np.argmax(ok))
        assert ok[first:].all()  # the premise, here
        assert upper[row] == grid[first]
        assert lower[row] == (grid[first - 1] if first else 0.0)


def test_a_free_buffer_makes_the_least_cost_the_smallest_area_that_meets_with_any_buffer():
    free = Costs(panel_usd_per_m2=150, buffer_usd_per_wh=0, drive_dual_axis_usd=10)
    space = _search(free)
    curves = _curves()
    for kind, curve, draw in (
        ("flat", curves["flat"], None),
        ("tracker-net", curves["tracker-net"], DRAW),
    ):
        # The smallest area of the grid at which the grid's largest buffer meets the target.
        meets = [_meets(curve * factor, [_top(STORAGE)], draw)[0] for factor in AREA_FACTORS]
        row = space[(space["design"] == kind) & space["least_cost"]].iloc[0]
        assert row["area_m2"] == pytest.approx(AREA * AREA_FACTORS[np.argmax(meets)], rel=1e-12)
        assert not meets[0] and any(meets)  # the grid holds areas that meet and one that does not


def test_a_design_that_meets_the_target_at_no_area_says_so():
    # A 50 W load on a 10 W panel: four times the panel does not carry it with any buffer.
    space = _search(load=50.0)
    assert not space["meets"].any() and space["capacity_wh"].isna().all()
    assert not space["least_cost"].any()
    lines, part = least_cost_answer(
        space.assign(p_load_w=50.0), COSTS, STORAGE.target, "dual-axis"
    )
    assert "no kind meets the target at any area of the grid" in lines[1]
    assert all(not row["meets"] for row in part["least_cost"])
    assert "nan" not in " ".join(lines).lower()


def test_doubling_every_price_picks_the_same_design_at_twice_the_cost():
    doubled = Costs(**{name: 2 * value for name, value in COSTS.model_dump().items()
                       if value is not None})  # fmt: skip
    space, twice = _search(), _search(doubled)
    assert (space["least_cost"] == twice["least_cost"]).all()
    np.testing.assert_array_equal(twice["cost_usd"], 2 * space["cost_usd"])


def test_the_answer_s_line_names_the_cheapest_kind_against_flat():
    space = _search().assign(p_load_w=LOAD)
    lines, part = least_cost_answer(space, COSTS, STORAGE.target, "dual-axis")
    best = {row["design"]: row for row in part["least_cost"]}
    cheapest = min(best.values(), key=lambda row: row["cost_usd"])
    line = lines[1]
    assert line.startswith("  P_load 1: ")
    flat = best["flat"]
    if cheapest["design"] != "flat":
        pct = (cheapest["cost_usd"] / flat["cost_usd"] - 1) * 100
        assert f"{abs(pct):.0f} % {'cheaper' if pct < 0 else 'dearer'} than flat's" in line
        assert f"{flat['area_m2']:.3g} m^2 and {flat['capacity_wh']:.3g} Wh" in line
    assert f"for ${cheapest['cost_usd']:.4g}" in line


#: A short annual study: three measured days, a pvwatts panel, a buffer with a target, costs.
SETTINGS = {
    "pv_model": "pvwatts",
    "p_load": "2",
    "fold_angles.step": "45",
    "storage.capacity_wh": "5",
    "storage.target.powered_h": "24",
    "storage.target.days_pct": "60",
    "costs.panel_usd_per_m2": "150",
    "costs.buffer_usd_per_wh": "0.5",
}


def _study(*args, **changes):
    """The short study's ``foldopt run`` arguments, with ``changes`` to its settings (a value of
    None leaves the setting out) and more arguments."""
    settings = {**SETTINGS, **changes}
    pairs = [["--set", f"{k}={v}"] for k, v in settings.items() if v is not None]
    return ["run", str(ROOT / "configs" / "measured-minutes.yaml"), *sum(pairs, []), *args]


def test_the_command_line_s_least_cost_is_the_api_s_to_the_bit(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, _study("--format", "json", "--out", "out", "-q"))
    assert result.exit_code == 0, result.output
    printed = json.loads(result.output)["answer"]
    settings = [f"{k}={v}" for k, v in SETTINGS.items()]
    study = ROOT / "configs" / "measured-minutes.yaml"
    api = foldopt.run(request=make_request("run", study, settings=settings))
    assert printed["result"]["least_cost"] == json.loads(
        json.dumps(plain(api.answer.result["least_cost"]))
    )
    assert printed["lines"] == api.answer.lines()
    written = pd.read_csv(tmp_path / "out" / "design_space.csv")
    mine = api.extras["design_space"]
    assert list(written.columns) == list(mine.columns)
    # The file's numbers are the answer's, to the CSV's digits.
    np.testing.assert_allclose(written["capacity_wh"], mine["capacity_wh"], rtol=1e-9)
    assert (tmp_path / "out" / "design_space.png").exists()
    html = (tmp_path / "out" / "report.html").read_text()
    assert "the cheapest panel and buffer" in html and "design_space.png" in html


@pytest.mark.parametrize(
    "setting, said",
    [
        ({"costs.panel_usd_per_m2": "-1"}, ["costs.panel_usd_per_m2", "[0, 1e+09] USD/m^2"]),
        ({"costs.buffer_usd_per_wh": "-0.5"}, ["costs.buffer_usd_per_wh", "USD/Wh"]),
        ({"costs.hinge_usd": "-2"}, ["costs.hinge_usd"]),
        ({"costs.drive_single_axis_usd": "-2"}, ["costs.drive_single_axis_usd"]),
        ({"costs.panel_cost": "3"}, ["costs.panel_cost"]),
        ({"costs.buffer_usd_per_wh": None}, ["costs.buffer_usd_per_wh"]),
    ],
)
def test_bad_costs_are_one_line_and_exit_2(tmp_path, monkeypatch, setting, said):
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, _study("--out", "out", "-q", **setting))
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.output, result.output
    assert all(part in lines[0] for part in said), lines[0]
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "changes, said",
    [
        # a plan of clear days, each its own best angle: no buffer over days, said in one line
        ({"objective": "null", "weather": "null", "date": "'2019-02-10:2019-02-12:1'"},
         "and costs, which goes with it"),
        ({"storage.target.powered_h": None, "storage.target.days_pct": None},
         "costs: the least-cost search sizes the buffer for"),
        ({"pv_model": "single-diode"}, "pv_model single-diode's I-V curve"),
    ],
)  # fmt: skip
def test_costs_where_they_cannot_be_searched_are_refused_in_one_line(
    tmp_path, monkeypatch, changes, said
):
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, _study("--out", "out", "-q", **changes))
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and said in lines[0], result.output
    assert not (tmp_path / "out").exists()


def test_target_h_is_the_storage_target_s_hours_and_says_so_when_out_of_range(
    tmp_path, monkeypatch
):
    study = ROOT / "configs" / "measured-minutes.yaml"
    given = [f"{k}={v}" for k, v in SETTINGS.items()]
    without = [f"{k}={v}" for k, v in SETTINGS.items() if k != "storage.target.powered_h"]
    by_option = make_request("run", study, settings=without, target_h=24.0)
    assert by_option.plan.base == make_request("run", study, settings=given).plan.base
    monkeypatch.chdir(tmp_path)
    args = _study("--target-h", "25", "--out", "out", "-q", **{"storage.target.powered_h": None})
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "--target-h" in lines[0] and "(0, 24] h" in lines[0], lines
    assert not (tmp_path / "out").exists()


def test_a_day_s_study_searches_its_clear_day_and_writes_the_table(tmp_path, monkeypatch):
    # camera-buffer's clear day repeated to its periodic state: the least-cost line, the table
    # and the figure, the JSON's part the API's to the bit.
    monkeypatch.chdir(tmp_path)
    args = ["run", str(ROOT / "configs" / "camera-buffer.yaml"), "--set", "step_min=10",
            "--set", "fold_angles.step=20", "--set", "costs.panel_usd_per_m2=150",
            "--set", "costs.buffer_usd_per_wh=0.5", "--set", "costs.hinge_usd=1"]  # fmt: skip
    result = runner.invoke(app, [*args, "--format", "json", "--out", "out", "-q"])
    assert result.exit_code == 0, result.output
    printed = json.loads(result.output)["answer"]
    api = foldopt.run(request=make_request("run", args[1], settings=args[3::2]))
    assert printed["result"]["least_cost"] == json.loads(
        json.dumps(plain(api.answer.result["least_cost"]))
    )
    assert any(line.startswith("the cheapest panel and buffer for 24 h") for line in printed["lines"])
    written = pd.read_csv(tmp_path / "out" / "design_space.csv")
    assert written["least_cost"].sum() == 2  # flat and twofold: the tracker's drive has no price
    assert (tmp_path / "out" / "design_space.png").exists()
