"""Figures of a sweep (a :class:`foldopt.SweepResult`'s table): heat maps of the optimal twofold
panel over two varied fields, and t_solar of each design against one."""

from __future__ import annotations

import numpy as np
import pandas as pd

from foldopt.output.figures.canvas import FigureFile, colour_scale, new_axes

#: Axis labels of the varied fields that have a unit; any other field is labelled by its name.
AXIS_LABELS = {
    "latitude": "latitude [deg]",
    "p_load_w": "P_load [W]",
    "dayofyear": "day of year",
}


#: The widest gap [d] between sampled days that a curve over the days of the year bridges with a
#: line, and the widest cell of a heat map along them: a fortnight's weekly samples are joined,
#: while days further apart (months, solstices) are points or narrow cells, not a course through
#: the days between that nothing evaluated.
DAY_GAP = 16.0


def broken_at_gaps(x, y, gap: float):
    """A curve's points with a NaN between neighbours more than ``gap`` apart, where a line
    through them stops, and which points have no neighbour within ``gap`` (to draw as markers).

    Parameters
    ----------
    x, y : array_like
        The points, ``x`` ascending, (n,).
    gap : float
        The widest step bridged (``numpy.inf``: every one).

    Returns
    -------
    x, y : numpy.ndarray
        (n + breaks,).
    alone : numpy.ndarray of bool
        (n + breaks,): a point with no line to either side.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    wide = np.diff(x) > gap
    joined = np.zeros(x.size, bool)
    joined[1:] |= ~wide
    joined[:-1] |= ~wide
    at = np.flatnonzero(wide) + 1
    return np.insert(x, at, np.nan), np.insert(y, at, np.nan), np.insert(~joined, at, False)


def cells(centres, gap: float = np.inf):
    """A heat map's cells along one axis: each value's cell reaches halfway to its neighbours (the
    ends as far out as the next step in), but no further than ``gap / 2`` from it; what lies
    between two cells so bounded is a blank cell.

    Parameters
    ----------
    centres : array_like
        The values along the axis, ascending, (n,).
    gap : float, default numpy.inf
        The widest cell (:data:`DAY_GAP` along the days of the year).

    Returns
    -------
    edges : numpy.ndarray
        (m + 1,) the cells' edges.
    index : numpy.ndarray of int
        (m,) each cell's value's index in ``centres``; -1 for a blank cell.
    """
    centres = np.asarray(centres, dtype=float)
    if centres.size == 1:
        return centres + np.array([-0.5, 0.5]) * min(1.0, gap), np.zeros(1, int)
    mids = (centres[1:] + centres[:-1]) / 2
    left = np.maximum(np.r_[2 * centres[0] - mids[0], mids], centres - gap / 2)
    right = np.minimum(np.r_[mids, 2 * centres[-1] - mids[-1]], centres + gap / 2)
    edges, index = [left[0]], []
    for i in range(centres.size):
        if left[i] > edges[-1]:  # nothing evaluated between the two cells
            edges.append(left[i])
            index.append(-1)
        edges.append(right[i])
        index.append(i)
    return np.array(edges), np.array(index)


def plot_map(
    table: pd.DataFrame,
    x: str,
    y: str,
    value: str,
    title: str,
    label: str,
    diverging: bool,
    ax=None,
):
    """A heat map of ``value`` over ``x`` and ``y``, averaged over any other varied field.

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep's rows (usually the twofold design's): columns ``x``, ``y`` and ``value``.
    x, y : str
        The columns along the horizontal and vertical axes (e.g. ``latitude``, ``p_load_w``).
    value : str
        The column shown in colour (e.g. ``gain_vs_flat_pct`` [%], ``fold_angle_deg`` [deg]);
        NaN cells are grey, as are days of the year further than :data:`DAY_GAP` / 2 from any
        evaluated (:func:`cells`).
    title, label : str
        The Axes' title and the colour bar's label.
    diverging : bool
        Red-blue colours symmetric around 0 (a gain), else viridis.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (8 x 5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    grid = table.pivot_table(index=y, columns=x, values=value, aggfunc="mean")
    fig, ax = new_axes(ax, (8, 5))
    (x_edges, x_cells), (y_edges, y_cells) = (
        cells(axis, DAY_GAP if name == "dayofyear" else np.inf)
        for axis, name in ((grid.columns, x), (grid.index, y))
    )
    values = grid.to_numpy(dtype=float)[np.ix_(y_cells, x_cells)]
    data = np.ma.masked_invalid(
        np.where((y_cells[:, None] >= 0) & (x_cells[None, :] >= 0), values, np.nan)
    )
    mesh = ax.pcolormesh(x_edges, y_edges, data, shading="flat", **colour_scale(data, diverging))
    ax.set_facecolor("0.85")
    ax.figure.colorbar(mesh, ax=ax, label=label)
    ax.set_xlabel(AXIS_LABELS.get(x, x))
    ax.set_ylabel(AXIS_LABELS.get(y, y))
    ax.set_title(title, fontsize=10)
    return ax


def plot_curves(table: pd.DataFrame, x: str, title: str, split: str | None = None, ax=None):
    """t_solar of the flat panel, the optimal twofold panel and the tracker against ``x``; over the
    days of the year, a line joins only days at most :data:`DAY_GAP` apart, and a day with none
    so near is a marker (:func:`broken_at_gaps`).

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep's tidy table: a row per case and design, with ``design`` and ``t_solar_h`` [h].
    x : str
        The varied field along the horizontal axis (e.g. ``p_load_w`` [W], ``latitude`` [deg]).
    title : str
    split : str, optional
        A varied field of at most four values: each gets its own line style. Anything else that
        varies is averaged.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (8 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    fig, ax = new_axes(ax, (8, 4.5))
    colours = {"flat": "k", "twofold": "tab:blue", "tracker": "0.55"}
    styles = ["-", "--", ":", "-."]
    groups = [(None, table)] if split is None else list(table.groupby(split, sort=True))
    for (value, rows), style in zip(groups, styles, strict=False):
        for design, colour in colours.items():
            curve = rows[rows["design"] == design].groupby(x)["t_solar_h"].mean()
            name = "optimal twofold" if design == "twofold" else design
            label = name if split is None else f"{name}, {split} {value}"
            xs, ys, alone = broken_at_gaps(
                curve.index, curve.to_numpy(), DAY_GAP if x == "dayofyear" else np.inf
            )
            ax.plot(
                xs,
                ys,
                color=colour,
                ls=style,
                lw=2 if design == "twofold" else 1.3,
                label=label,
                marker="o" if alone.any() else None,
                ms=4,
                markevery=alone.tolist(),
            )
    ax.set_xlabel(AXIS_LABELS.get(x, x))
    ax.set_ylabel("t_solar [h]")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=1 if split is None else 2)
    return ax


#: A sweep's folder holds those its varied fields call for (:mod:`foldopt.output.folders`).
FIGURES = {
    "gain_map_latitude_load.png": FigureFile(
        plot_map, "t_solar gain of the optimal twofold panel over flat, by latitude and load"
    ),
    "fold_angle_map_latitude_load.png": FigureFile(
        plot_map, "optimal fold angle by latitude and load"
    ),
    "gain_map_day_latitude.png": FigureFile(
        plot_map,
        "t_solar gain of the optimal twofold panel over flat, by day of the year and latitude",
    ),
    "fold_angle_map_day_latitude.png": FigureFile(
        plot_map, "optimal fold angle by day of the year and latitude"
    ),
    "annual_t_solar.png": FigureFile(
        plot_curves, "t_solar of flat, optimal twofold and tracker over the days of the year"
    ),
    "t_solar_vs_load.png": FigureFile(
        plot_curves, "t_solar of flat, optimal twofold and tracker against the load"
    ),
    "t_solar_vs_latitude.png": FigureFile(
        plot_curves, "t_solar of flat, optimal twofold and tracker against the latitude"
    ),
}
