"""Figures of a day's study with a buffer (a :class:`foldopt.StudyResult` whose study has a
``storage`` section): the state of charge over the day, and powered time against the buffer's
capacity with the capacity at which folding stops paying."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from foldopt.output.figures.canvas import ONE_AXES, FigureFile, new_axes
from foldopt.studies.day import StudyResult

#: Each design's colour, as the day's comparison draws them.
COLOURS = {"flat": "0.3", "twofold": "tab:blue", "tracker": "tab:orange"}


def plot_state_of_charge(result: StudyResult, ax=None):
    """The buffer's state of charge over the day for flat, the optimal twofold panel and the
    tracker, in the periodic steady state (or from ``initial_soc``), with the controller's
    cut-off and reconnect levels.

    Parameters
    ----------
    result : foldopt.StudyResult
        With a buffer: its time series' ``soc_flat_frac``, ``soc_twofold_frac``,
        ``soc_tracker_frac`` [0-1].
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (8 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    storage, series = result.study.storage, result.timeseries
    times = series.index.tz_localize(None)
    hours = np.asarray((times - times.normalize()) / pd.Timedelta(hours=1))
    fig, ax = new_axes(ax, (8, 4.5))
    summary = result.summary.set_index("design")
    for design, colour in COLOURS.items():
        label = (
            f"twofold {summary.loc['twofold', 'fold_angle_deg']:.1f}°"
            if design == "twofold"
            else design
        )
        powered = summary.loc[design, "powered_h"]
        ax.plot(
            hours,
            100.0 * series[f"soc_{design}_frac"],
            color=colour,
            label=f"{label}: powered {powered:.2f} h",
        )
    ax.axhline(100 * storage.min_soc, color="tab:red", lw=0.8, ls="--", label="cut-off")
    if storage.restart_soc > storage.min_soc:
        ax.axhline(100 * storage.restart_soc, color="tab:red", lw=0.8, ls=":", label="reconnect")
    ax.set_xlim(0, 24)
    ax.set_ylim(0, 102)
    ax.set_xlabel("local time [h]")
    ax.set_ylabel("state of charge [%]")
    ax.set_title(
        f"{result.study.name}: state of charge of a {storage.capacity_wh:g} Wh buffer, "
        f"{result.study.date}",
        fontsize=10,
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return ax


def plot_powered_vs_capacity(result: StudyResult, ax=None):
    """Powered time against the buffer's capacity for flat, the best twofold angle at each
    capacity and the tracker; the capacity from which folding stops paying, the study's own
    buffer and each design's buffer for the target where one is stated are marked.

    Parameters
    ----------
    result : foldopt.StudyResult
        With a buffer: its ``storage.sizing`` (``storage_capacity.csv``, ``storage_sizing.csv``).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (8 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    sizing, storage = result.storage.sizing, result.study.storage
    curve = sizing.curve
    fig, ax = new_axes(ax, (8, 4.5))
    for design, colour in COLOURS.items():
        label = "twofold (best angle at each capacity)" if design == "twofold" else design
        ax.plot(
            curve["capacity_wh"],
            curve[f"powered_{design}_h"],
            "o-",
            ms=3,
            color=colour,
            label=label,
        )
    stops = sizing.folding.stops_wh
    if not math.isnan(stops):
        ax.axvline(stops, color="tab:green", lw=1, label=f"folding stops paying: {stops:.3g} Wh")
    ax.axvline(storage.capacity_wh, color="0.6", lw=0.8, ls=":", label="the study's buffer")
    if len(sizing.table):
        ax.axhline(storage.target.powered_h, color="tab:red", lw=0.8, ls="--", label="target")
        for _, row in sizing.table.iterrows():
            if row["design"] in COLOURS and not math.isnan(row["capacity_wh"]):
                ax.plot(
                    row["capacity_wh"],
                    storage.target.powered_h,
                    "s",
                    color=COLOURS[row["design"]],
                )
    ax.set_xscale("symlog", linthresh=max(float(curve["capacity_wh"].iloc[1]), 1e-3))
    ax.set_xlabel("buffer capacity [Wh]")
    ax.set_ylabel("powered time [h a day]")
    ax.set_ylim(0, 24.5)
    ax.set_title(f"{result.study.name}: powered time against the buffer, {result.study.date}",
                 fontsize=10)  # fmt: skip
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    return ax


FIGURES = {
    "state_of_charge.png": FigureFile(
        plot_state_of_charge,
        "the buffer's state of charge over the day for flat, optimal twofold and tracker "
        "(a study with storage)",
        ONE_AXES,
    ),
    "powered_vs_capacity.png": FigureFile(
        plot_powered_vs_capacity,
        "powered time against the buffer's capacity for flat, best twofold and tracker, where "
        "folding stops paying and each design's buffer for the target (a study with storage)",
        ONE_AXES,
    ),
}
