"""The figures: one registry (foldopt.output.figures.FIGURES) names every figure file a results
folder holds, and drawing them changes nothing of a notebook's matplotlib: the plot functions draw
into the user's Axes with the user's backend, and writing a folder chooses no backend at all."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import foldopt
from foldopt.output.figures import (FIGURES, annual, day, horizon, landscape, least_cost, sizing, storage, sweep,
                                    weather, world)

ROOT = Path(__file__).resolve().parent.parent
# No test here reads a PNG's pixels: the figures' artists are read from their Axes, and the folders
# written in a process of their own (the notebook's) are drawn whole, pixels and all;
# tests/conftest.py draws the others' files without them.


def test_the_registry_is_the_figures_of_the_examples():
    # results/examples/ holds a folder of every kind: each figure it has is registered, and each
    # registered figure is one a folder has.
    written = {path.name for path in (ROOT / "results" / "examples").glob("*/*.png")}
    assert written == set(FIGURES)


def test_the_registry_is_every_kind_once_and_draws_with_public_functions():
    kinds = [day.FIGURES, storage.FIGURES, sweep.FIGURES, annual.FIGURES, weather.FIGURES, horizon.FIGURES,
             world.FIGURES, sizing.FIGURES, landscape.FIGURES, least_cost.FIGURES]
    assert sum(len(kind) for kind in kinds) == len(FIGURES)  # no file name in two kinds
    for file, figure in FIGURES.items():
        assert file.endswith(".png") and figure.description
        assert getattr(foldopt, figure.plot.__name__) is figure.plot, file


#: Draws every public plot function into Axes of its own and writes two folders, in a process whose
#: matplotlib backend is svg (as a notebook's is its own): prints what it saw.
NOTEBOOK = textwrap.dedent("""
    import json, sys
    import matplotlib
    import numpy as np
    import pandas as pd
    import foldopt

    backend = matplotlib.get_backend()
    study = foldopt.default_study().variant(step_min=30, fold_angles={"start": 30, "stop": 180, "step": 30})
    result = foldopt.run(study)
    year = foldopt.sweep(study, "day", date="1:365:91", objective="mean", p_load=[2.0, 4.0])
    sized = foldopt.size(study, areas="0.05:0.2:0.05")
    buffered = foldopt.run(study.variant(p_load=2.0, storage={"capacity_wh": 5, "target": {"powered_h": 24}}))
    foldopt.write(result, sys.argv[1] + "/day")
    foldopt.write(year, sys.argv[1] + "/year")
    after_writing = [matplotlib.get_backend(), "matplotlib.pyplot" in sys.modules]

    import matplotlib.pyplot as plt
    sites = pd.DataFrame({"site_name": ["a", "b"], "latitude": [0.0, 40.0], "longitude": [0.0, 10.0],
                          "gain_vs_flat_pct": [1.0, -2.0], "period": "year", "p_load_frac": [0.2, 0.3]})
    calls = {
        "plot_power_curves": (result,), "plot_switching": (result,), "plot_t_solar_vs_fold_angle": (result,),
        "plot_comparison": (result,), "plot_standby": (result,),
        "plot_state_of_charge": (buffered,), "plot_powered_vs_capacity": (buffered,),
        "plot_map": (year.table, "dayofyear", "p_load_w", "t_solar_h", "t", "t_solar [h]", False),
        "plot_curves": (year.table, "dayofyear", "t"),
        "plot_sizing": (sized.table, sized.best, "t"),
        "plot_annual_fold_angles": (year.extras["by_angle"], "t"),
        "plot_distribution": (year.table, "t"),
        "plot_day_hour": (year.extras, "switch_state", "t", ""),
        "plot_refold_value": (pd.DataFrame({"latitude": 0.0, "longitude": 0.0, "p_load_w": 2.0, "settings_n": [1, 2],
                                            "objective": "mean", "t_solar_objective_h": [5.0, 6.0],
                                            "t_solar_flat_objective_h": 4.0, "t_solar_tracker_objective_h": 7.0}), "t"),
        "plot_powered_by_year": (pd.DataFrame({"p_load_w": 2.0, "design": ["flat", "flat"],
                                               "fold_angle_deg": 180.0, "year": [2020, 2021],
                                               "powered_mean_h": [20.0, 19.0],
                                               "powered_worst_month_h": [15.0, 14.0],
                                               "worst_year": [False, True]}), "t"),
        "plot_weather_minutes": ({"date": "2025-06-01", "hours": np.arange(96) / 4 + 0.125, "kind": "members",
                                  "ghi": np.random.default_rng(0).uniform(0, 900, (5, 96)),
                                  "hourly_ghi": np.full(24, 300.0)}, "t"),
        "plot_member_t_solar": (year.table.assign(t_solar_members_p10_h=year.table.t_solar_h - 0.1,
                                                  t_solar_members_p50_h=year.table.t_solar_h,
                                                  t_solar_members_p90_h=year.table.t_solar_h + 0.1), "t"),
        "plot_world_map": (sites, "gain_vs_flat_pct", "t", "gain [%]", True),
        "plot_latitude_load": (sites, "year", True, "t"),
        "plot_sun_paths": ({"dates": ["2025-06-21"], "azimuth": np.array([[90.0, 180.0, 270.0]]),
                            "elevation": np.array([[10.0, 60.0, 10.0]]), "horizon_azimuth": np.array([0.0, 180.0]),
                            "horizon_elevation": np.array([20.0, 5.0]), "hidden_pct": 12.0}, "t"),
        "plot_design_space": (pd.DataFrame({"p_load_w": 2.0, "design": ["flat", "flat", "twofold", "twofold"],
                                            "fold_angle_deg": [180.0, 180.0, 90.0, 90.0],
                                            "area_m2": [0.1, 0.2, 0.1, 0.2], "capacity_wh": [40.0, 20.0, 35.0, 18.0],
                                            "cost_usd": [35.0, 40.0, 33.5, 39.0], "frontier": True,
                                            "least_cost": [True, False, True, False]}),
                              "t", foldopt.Costs(panel_usd_per_m2=150, buffer_usd_per_wh=0.5)),
        "plot_landscape": (pd.DataFrame({"fold_angle_deg": [90.0, 180.0, 90.0, 180.0],
                                         "surface_tilt": [0.0, 0.0, 30.0, 30.0],
                                         "t_solar_objective_h": [9.0, 8.0, 9.5, 8.2]}),
                           pd.DataFrame({"p_load_w": 2.0, "design": ["twofold", "twofold-default"],
                                         "fold_angle_deg": [90.0, 90.0], "surface_tilt": [30.0, 0.0],
                                         "t_solar_objective_h": [9.5, 9.0]}), "t"),
    }
    drawn = []
    for name, args in calls.items():
        fig, ax = plt.subplots()
        drawn.append(getattr(foldopt, name)(*args, ax=ax) is ax)
    fig, axes = plt.subplots(2, 2, squeeze=False)
    drawn.append(foldopt.plot_monthly(year.table, "t", loads_at_most=2, axes=axes) is axes)
    print(json.dumps({"before": backend, "after_writing": after_writing, "after_plots": matplotlib.get_backend(),
                      "rc": matplotlib.rcParams["backend"], "plotted": sorted([*calls, "plot_monthly"]),
                      "drawn": drawn, "open": plt.get_fignums()}))
""")


def test_plots_and_folders_leave_a_notebooks_backend_alone(tmp_path):
    env = {**os.environ, "MPLBACKEND": "svg"}
    done = subprocess.run([sys.executable, "-c", NOTEBOOK, str(tmp_path)], capture_output=True, text=True, env=env,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    seen = json.loads(done.stdout.splitlines()[-1])
    assert seen["before"] == "svg"
    assert seen["after_writing"] == ["svg", False]  # writing a folder does not even import pyplot
    assert seen["after_plots"] == seen["rc"] == "svg"
    assert seen["plotted"] == sorted(name for name in foldopt.__all__ if name.startswith("plot_"))
    assert all(seen["drawn"]) and len(seen["open"]) == len(seen["drawn"])  # the user's figures, still open
    assert {"power_curves.png", "daily_t_solar_distribution.png"} <= {p.name for p in tmp_path.glob("*/*.png")}


# What the annual figures draw, read back from their Axes against references computed here.

def _bars(ax) -> dict:
    """Each design's bars in an Axes: design -> {month: height}."""
    return {bars.get_label(): {round(bar.get_x() + bar.get_width() / 2): bar.get_height() for bar in bars}
            for bars in ax.containers}


def test_a_months_bars_are_its_mean_day_however_many_days_it_samples():
    """Every 7th day of 2025 samples five days of January, April... and four of February...: a day
    the same all year draws every month's bar the same (a month's sum was 25 % taller in those)."""
    from matplotlib.figure import Figure

    dates = pd.date_range("2025-01-01", "2025-12-31", freq="7D")
    designs = {"flat": (80.0, 7.0), "twofold": (70.0, 9.0), "tracker": (120.0, 11.0)}
    table = pd.DataFrame([{"date": date.date().isoformat(), "latitude": 40.0, "longitude": 0.0, "p_load_w": 2.0,
                           "design": design, "energy_harvested_wh": energy, "t_solar_h": hours}
                          for date in dates for design, (energy, hours) in designs.items()])
    assert set(pd.Series(dates.month).value_counts()) == {4, 5}
    axes = annual.plot_monthly(table, "t", axes=Figure().subplots(1, 2, squeeze=False))
    for ax, column in zip(axes[0], (0, 1), strict=True):
        for design, bars in _bars(ax).items():
            assert list(bars) == list(range(1, 13))
            assert set(bars.values()) == {designs[design][column]}, (design, column)


def test_the_monthly_figure_draws_each_months_mean_day_of_results_csv(tmp_path, figures_drawn_elsewhere):
    """A year of every 7th day, through the folder: the monthly figure's bars are, per design, the
    mean over the month's days in results.csv (a grid point: no site name) of energy and t_solar.
    The folder's figures are drawn here from its table and its results.csv (the others of a sweep of
    dates by the notebook's folder above and the reports' annual folder)."""
    from matplotlib.figure import Figure

    study = foldopt.default_study().variant(step_min=30, fold_angles={"start": 30, "stop": 180, "step": 30})
    result = foldopt.sweep(study, "day", date="1:365:7", p_load=[2.0])
    with figures_drawn_elsewhere():
        foldopt.write(result, tmp_path / "year")
    days = pd.read_csv(tmp_path / "year" / "results.csv")
    assert (tmp_path / "year" / "monthly_energy_t_solar.png").exists()
    days["month"] = pd.to_datetime(days["date"]).dt.month
    reference = days.groupby(["design", "month"])[["energy_harvested_wh", "t_solar_h"]].mean()
    for table in (result.table, days.drop(columns="month")):
        axes = annual.plot_monthly(table, "t", axes=Figure().subplots(1, 2, squeeze=False))
        for ax, column in zip(axes[0], ("energy_harvested_wh", "t_solar_h"), strict=True):
            drawn = _bars(ax)
            assert set(drawn) == {"flat", "twofold", "tracker", "tracker-net"}
            for design, bars in drawn.items():
                expected = reference.loc[design, column]
                assert list(bars) == list(expected.index)
                # results.csv keeps 10 significant digits.
                np.testing.assert_allclose(list(bars.values()), expected.to_numpy(), rtol=1e-9)


def _segments_and_points(line):
    """A drawn line's stretches joined by a line, and its points drawn as markers."""
    x = np.asarray(line.get_xdata(), dtype=float)
    parts = [part[np.isfinite(part)] for part in np.split(x, np.flatnonzero(np.isnan(x)))]
    stretches = [part for part in parts if part.size > 1]
    every = line.get_markevery()
    shown = every is not None and line.get_marker() not in ("", "None")
    marked = set(x[np.asarray(every, bool)]) if shown else set()
    return stretches, marked


@pytest.mark.parametrize("dates,joined", [(["2025-06-21", "2025-12-21"], False), ("1:365:7", True)],
                         ids=["solstices", "weekly"])
def test_a_curve_over_the_days_joins_only_near_days(dates, joined):
    """annual_t_solar.png: days more than a fortnight apart (the solstices) are markers, with no
    line across the half year between them that nothing evaluated; weekly days are a line. Every
    day evaluated is drawn, as a line's point or a marker."""
    from matplotlib.figure import Figure

    study = foldopt.default_study().variant(step_min=30, fold_angles={"start": 30, "stop": 180, "step": 30},
                                            site={"latitude": 52.52, "longitude": 13.40})
    table = foldopt.sweep(study, "day", date=dates, p_load=[2.0]).table
    ax = sweep.plot_curves(table, "dayofyear", "t", ax=Figure().subplots())
    evaluated = set(table["dayofyear"].astype(float))
    assert len(ax.lines) == 3  # flat, optimal twofold, tracker
    for line in ax.lines:
        stretches, marked = _segments_and_points(line)
        for stretch in stretches:
            assert np.diff(stretch).max() <= sweep.DAY_GAP
        on_lines = set(np.concatenate(stretches)) if stretches else set()
        assert on_lines | marked == evaluated and not on_lines & marked
        assert bool(stretches) == joined


@pytest.mark.parametrize("days,joined", [([172, 355], False), (list(range(1, 366, 7)), True),
                                         ([15, 22, 29, 196, 300], None)], ids=["solstices", "weekly", "mixed"])
def test_an_ensembles_line_and_band_join_only_near_days(days, joined):
    """ensemble_t_solar.png: the median line and the P10-P90 band span only days at most DAY_GAP
    apart (they crossed the half year between the solstices); a lone day is a marker on its median
    and a bar from its P10 to its P90. Every day is drawn, at its own values."""
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.colors import to_rgb
    from matplotlib.figure import Figure

    rng = np.random.default_rng(0)
    table = pd.DataFrame([{"dayofyear": day, "p_load_w": load, "design": design,
                           "t_solar_members_p10_h": low, "t_solar_members_p50_h": low + 1.0,
                           "t_solar_members_p90_h": low + 2.5}
                          for day in days for load in (2.0, 4.0) for design in ("flat", "twofold", "tracker")
                          for low in rng.uniform(3.0, 9.0, 1)])
    ax = weather.plot_member_t_solar(table, "t", ax=Figure().subplots())
    bands = [artist for artist in ax.collections if isinstance(artist, PolyCollection)]
    assert len(ax.lines) == len(bands) == 2  # flat and twofold
    for line, band in zip(ax.lines, bands, strict=True):
        design = line.get_label().split(":")[0]
        rows = table[(table["design"] == design) & (table["p_load_w"] == 2.0)].set_index("dayofyear")
        stretches, marked = _segments_and_points(line)
        on_lines = set(np.concatenate(stretches)) if stretches else set()
        assert on_lines | marked == set(days) and not on_lines & marked
        if joined is not None:
            assert bool(stretches) == joined and bool(marked) != joined
        for stretch in stretches:
            assert np.diff(stretch).max() <= sweep.DAY_GAP
        np.testing.assert_array_equal(line.get_ydata()[np.isfinite(line.get_xdata())], rows["t_solar_members_p50_h"])
        polygons = [path.vertices for path in band.get_paths()]
        assert [sorted(set(vertices[:, 0])) for vertices in polygons] == [list(part) for part in stretches]
        for vertices in polygons:
            for x, y in vertices:
                assert y in (rows.loc[x, "t_solar_members_p10_h"], rows.loc[x, "t_solar_members_p90_h"])
        drawn_bars = {segment[0, 0]: (segment[0, 1], segment[1, 1]) for bars in ax.collections
                      if isinstance(bars, LineCollection) and to_rgb(bars.get_color()[0]) == to_rgb(line.get_color())
                      for segment in bars.get_segments()}
        assert drawn_bars == {day: (rows.loc[day, "t_solar_members_p10_h"], rows.loc[day, "t_solar_members_p90_h"])
                              for day in marked}


@pytest.mark.parametrize("dates,blank", [(["2025-06-21", "2025-12-21"], True), ("1:365:7", False)],
                         ids=["solstices", "weekly"])
def test_a_heat_map_over_the_days_colours_only_near_days(dates, blank):
    """gain_map_day_latitude.png / fold_angle_map_day_latitude.png: a cell spans at most DAY_GAP
    of the days, centred on its evaluated day, with that day's value (pandas on the table); the
    half year between the solstices is blank, weekly days leave no blank."""
    from matplotlib.figure import Figure

    study = foldopt.default_study().variant(step_min=30, fold_angles={"start": 30, "stop": 180, "step": 30})
    table = foldopt.sweep(study, "day", date=dates, latitude=[0.0, 50.0], p_load=[2.0]).table
    twofold = table[table["design"] == "twofold"]
    ax = sweep.plot_map(twofold, "dayofyear", "latitude", "fold_angle_deg", "t", "deg", False,
                        ax=Figure().subplots())
    mesh = ax.collections[0]
    corners = mesh.get_coordinates()  # (rows + 1, columns + 1, 2)
    x_edges, y_edges = corners[0, :, 0], corners[:, 0, 1]
    values = np.ma.filled(mesh.get_array().reshape(len(y_edges) - 1, len(x_edges) - 1).astype(float), np.nan)
    coloured = np.isfinite(values).any(axis=0)
    assert (np.diff(x_edges)[coloured] <= sweep.DAY_GAP).all()
    assert (~coloured).any() == blank
    for _, row in twofold.iterrows():
        column = np.searchsorted(x_edges, row["dayofyear"]) - 1
        line = np.searchsorted(y_edges, row["latitude"]) - 1
        assert values[line, column] == row["fold_angle_deg"]
        assert x_edges[column] < row["dayofyear"] < x_edges[column + 1]


@pytest.mark.parametrize("step,blank", [(183, True), (7, False)], ids=["half-year-apart", "weekly"])
def test_a_day_hour_map_draws_each_day_in_its_own_column_and_no_day_between(step, blank):
    """day_hour_power.png: each evaluated day's column holds its own hours' values, spans at most
    DAY_GAP days around its day of the study, and days between sampled days further apart are
    blank (they were the nearer day's)."""
    import datetime

    from matplotlib.figure import Figure

    dates = [datetime.date(2025, 6, 21) + datetime.timedelta(days=step * i) for i in range(2 if blank else 10)]
    hours = np.arange(24) + 0.5
    power = np.random.default_rng(0).uniform(0, 10, (len(dates), hours.size))
    ax = annual.plot_day_hour({"dates": dates, "hours": hours, "p_twofold_w": power}, "p_twofold_w", "t", "W",
                              ax=Figure().subplots())
    mesh = ax.collections[0]
    corners = mesh.get_coordinates()
    x_edges, y_edges = corners[0, :, 0], corners[:, 0, 1]
    drawn = np.ma.filled(mesh.get_array().reshape(len(y_edges) - 1, len(x_edges) - 1).astype(float), np.nan)
    coloured = np.isfinite(drawn).all(axis=0)
    assert (np.diff(x_edges)[coloured] <= annual.DAY_GAP).all() and (~coloured).any() == blank
    for index, date in enumerate(dates):
        day = (date - dates[0]).days + 1
        column = np.searchsorted(x_edges, day) - 1
        assert x_edges[column] < day < x_edges[column + 1]
        np.testing.assert_array_equal(drawn[:, column], power[index])


@pytest.mark.parametrize("circuit,connection,wired", [
    ({"coupling": "direct", "load_voltage": 5.0}, "parallel", "not the load wired directly at 5 V"),
    ({}, "parallel", None), ({}, "independent", None)], ids=["direct", "mppt", "independent-study"])
def test_the_independent_curve_says_it_runs_through_a_converter_per_sub_panel(circuit, connection, wired):
    """t_solar_vs_fold_angle.png and power_curves.png: the independent connection's curve is named
    with its converter per sub-panel, and with a load wired directly says it is not so wired (as the
    answer's note on twofold-independent does); no other connection's is."""
    from matplotlib.figure import Figure

    study = foldopt.default_study().variant(mode="exact", pv_model="single-diode", sky="ineichen", p_load=3.0,
                                            fold_angles={"start": 30, "stop": 180, "step": 30},
                                            connection=connection, circuit=circuit)
    result = foldopt.run(study)
    labels = [text.get_text() for plot in (day.plot_t_solar_vs_fold_angle, day.plot_power_curves)
              for text in plot(result, ax=Figure().subplots()).get_legend().get_texts()]
    independent = [label for label in labels if "independent" in label]
    assert len(independent) == 1 + (connection == "independent")  # the sweep's curve, and the day's
    for label in independent:
        assert "with a converter per sub-panel" in label
        assert ("not the load wired directly" in label) == (wired is not None)
        assert wired is None or wired in label
    assert not any("converter" in label for label in labels if label not in independent)


@pytest.mark.parametrize("fixed", ["fold_angle_deg", "surface_tilt"])
def test_a_landscape_of_one_fold_angle_or_one_tilt_is_the_objectives_line(fixed):
    """optimize with one fold angle (or one tilt) searched: no surface to colour (pcolormesh and
    contour need 2 x 2; it was an internal error), the objective along the other variable."""
    import matplotlib.pyplot as plt

    other = "surface_tilt" if fixed == "fold_angle_deg" else "fold_angle_deg"
    along = np.array([0.0, 15.0, 30.0, 45.0])
    objective = np.array([9.0, 9.4, 9.5, 9.1])
    landscape_table = pd.DataFrame({fixed: 100.0, other: along, "t_solar_objective_h": objective})
    designs = pd.DataFrame({"p_load_w": 2.0, "design": ["twofold", "twofold-default"], fixed: 100.0,
                            other: [30.0, 15.0], "t_solar_objective_h": [9.5, 9.4]})
    fig, ax = plt.subplots()
    landscape.plot_landscape(landscape_table, designs, "t", ax=ax)
    line, optimum, default = ax.get_lines()
    assert np.array_equal(line.get_xdata(), along) and np.array_equal(line.get_ydata(), objective)
    assert (optimum.get_xdata()[0], optimum.get_ydata()[0]) == (30.0, 9.5)
    assert (default.get_xdata()[0], default.get_ydata()[0]) == (15.0, 9.4)
    assert ax.get_ylabel() == "objective [h]"
    plt.close(fig)


def _weather_minutes(seed: int) -> tuple:
    """weather_minutes.png's arguments: a day of five members' GHI (laid out by its labels)."""
    ghi = np.random.default_rng(seed).uniform(0, 900, (5, 96))
    return ({"date": "2025-06-01", "hours": np.arange(96) / 4 + 0.125, "kind": "members", "ghi": ghi,
             "hourly_ghi": np.full(24, 300.0)}, "t"), {}


@pytest.mark.figure_pixels  # the pixels are what is compared
def test_a_figure_file_is_drawn_once_and_its_pixels_are_its_own(monkeypatch):
    """A file's figure laid out by its labels is drawn once (savefig drew it twice), and figures of
    one size share their thread's renderer without sharing pixels: a figure's bytes are the same
    after another figure of its size as drawn first in a thread of its own."""
    import threading

    from matplotlib.figure import Figure

    from foldopt.output.figures import figure_bytes

    assert FIGURES["weather_minutes.png"].margins is None
    draws = []
    draw = Figure.draw
    monkeypatch.setattr(Figure, "draw", lambda figure, renderer: draws.append(figure) or draw(figure, renderer))
    first = figure_bytes("weather_minutes.png", *_weather_minutes(0))
    assert len(draws) == 1
    other = figure_bytes("weather_minutes.png", *_weather_minutes(1))
    assert other != first and figure_bytes("weather_minutes.png", *_weather_minutes(0)) == first
    alone = []
    thread = threading.Thread(target=lambda: alone.append(figure_bytes("weather_minutes.png", *_weather_minutes(0))))
    thread.start()
    thread.join()
    assert alone == [first]
