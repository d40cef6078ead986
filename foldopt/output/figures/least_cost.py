"""The figure of the least-cost search (:mod:`foldopt.studies.least_cost`): each kind's frontier of
panel area against the smallest buffer meeting the target, with lines of equal cost through the
least-cost design."""

from __future__ import annotations

import numpy as np
import pandas as pd

from foldopt.output.figures.canvas import ONE_AXES, FigureFile, new_axes

#: Each kind's colour, as the day's comparison draws flat, twofold and the tracker.
COLOURS = {"flat": "0.3", "twofold": "tab:blue", "tracker-net": "tab:orange"}


def plot_design_space(space: pd.DataFrame, title: str, costs, ax=None):
    """Each kind's frontier (the smallest buffer meeting the target at each panel area; a twofold
    panel's at its best angle there, the first load's), its least-cost design marked and the
    line of equal cost through it (``area x panel + capacity x buffer`` constant).

    Parameters
    ----------
    space : pandas.DataFrame
        As ``design_space.csv`` (:func:`foldopt.studies.least_cost.design_space`).
    title : str
    costs : foldopt.inputs.costs_section.Costs
        The prices the lines of equal cost are drawn at.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (7 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    fig, ax = new_axes(ax, (7, 4.5))
    first = space[space["p_load_w"] == space["p_load_w"].iloc[0]]
    for design, colour in COLOURS.items():
        rows = first[(first["design"] == design) & first["frontier"]]
        rows = rows.drop_duplicates("area_m2").sort_values("area_m2")
        if not len(rows):
            continue
        ax.plot(rows["area_m2"], rows["capacity_wh"], "o-", ms=3, color=colour, label=design)
        best = first[(first["design"] == design) & first["least_cost"]].iloc[0]
        angle = "" if design != "twofold" else f" at {best['fold_angle_deg']:g}°"
        ax.plot(best["area_m2"], best["capacity_wh"], "*", ms=12, color=colour,
                label=f"{design}{angle}: ${best['cost_usd']:.4g}")  # fmt: skip
        if costs.buffer_usd_per_wh > 0:
            # The line of equal cost through it: what a m^2 of panel is worth in Wh of buffer.
            area = np.linspace(rows["area_m2"].min(), rows["area_m2"].max(), 50)
            slope = costs.panel_usd_per_m2 / costs.buffer_usd_per_wh
            ax.plot(area, best["capacity_wh"] - slope * (area - best["area_m2"]), ":",
                    color=colour, lw=0.8)  # fmt: skip
    ax.set_ylim(bottom=0, top=1.05 * max(first["capacity_wh"].max(), 1e-3))
    ax.set_xlabel("panel area [m²]")
    ax.set_ylabel("smallest buffer meeting the target [Wh]")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return ax


FIGURES = {
    "design_space.png": FigureFile(
        plot_design_space,
        "each kind's smallest buffer meeting the target against the panel's area, its "
        "least-cost design and the line of equal cost through it (a study with costs)",
        ONE_AXES,
    ),
}
