"""The figure of a joint optimisation (a :class:`foldopt.studies.joint.OptimizeResult`): the
objective over base tilt x fold angle at the optimum's azimuth, the optimum and the flat panel's
own best marked."""

from __future__ import annotations

import numpy as np
import pandas as pd

from foldopt.output.figures.canvas import FigureFile, new_axes


def plot_landscape(landscape: pd.DataFrame, designs: pd.DataFrame, title: str, ax=None):
    """The objective [h] over tilt x fold angle, with contours, the twofold optimum (a star) and
    the default mounting's best fold angle (a circle).

    Parameters
    ----------
    landscape : pandas.DataFrame
        ``fold_angle_deg``, ``surface_tilt``, ``t_solar_objective_h`` on a grid (``landscape.csv``).
    designs : pandas.DataFrame
        The optimum's designs of the first load: ``design`` (``twofold``, ``twofold-default``...),
        ``fold_angle_deg``, ``surface_tilt``, ``t_solar_objective_h`` (``optimum.csv``).
    title : str
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (7 x 5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    fig, ax = new_axes(ax, (7, 5))
    grid = landscape.pivot_table(
        index="surface_tilt", columns="fold_angle_deg", values="t_solar_objective_h"
    )
    values = grid.to_numpy(dtype=float)
    # One fold angle (or one tilt) searched leaves a line, not a surface: the objective along the
    # other variable, the markers where they stand on it.
    single = None if min(values.shape) > 1 else ("tilt" if values.shape[1] == 1 else "fold")
    if single is None:
        _draw_surface(fig, ax, grid, values)
    elif single == "tilt":
        ax.plot(grid.index, values[:, 0], color="tab:blue", label="objective [h]")
    elif single == "fold":
        ax.plot(grid.columns, values[0], color="tab:blue", label="objective [h]")
    first = designs[designs["p_load_w"] == designs["p_load_w"].iloc[0]]
    for design, marker, label in (
        ("twofold", "*", "optimum"),
        ("twofold-default", "o", "default mounting"),
    ):
        row = first[first["design"] == design].iloc[0]
        x, y = row["fold_angle_deg"], row["surface_tilt"]
        if single is not None:
            x, y = (y if single == "tilt" else x), row["t_solar_objective_h"]
        ax.plot(
            x,
            y,
            marker,
            color="red" if marker == "*" else "orange",
            markersize=12 if marker == "*" else 7,
            markeredgecolor="black",
            label=f"{label}: {row['t_solar_objective_h']:.2f} h",
        )
    ax.set_xlabel("base tilt [deg]" if single == "tilt" else "fold angle [deg]")
    ax.set_ylabel("objective [h]" if single is not None else "base tilt [deg]")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8, loc="lower right")
    return ax


def _draw_surface(fig, ax, grid: pd.DataFrame, values: np.ndarray):
    """The objective's colours over tilt x fold angle, contours a few minutes below its top."""
    mesh = ax.pcolormesh(grid.columns, grid.index, values, shading="nearest", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="objective [h]")
    top = np.nanmax(values)
    levels = [top - 0.5, top - 0.2, top - 0.1, top - 0.05]
    levels = [level for level in levels if np.nanmin(values) < level < top]
    if levels:
        lines = ax.contour(
            grid.columns, grid.index, values, levels=levels, colors="white", linewidths=0.7
        )
        ax.clabel(lines, fmt=lambda level: f"-{(top - level) * 60:.0f} min", fontsize=7)


FIGURES = {
    "landscape.png": FigureFile(
        plot_landscape,
        "the objective over base tilt x fold angle at the optimum's azimuth, "
        "the optimum and the default mounting marked",
    ),
}
