"""Figures of a map of many sites (:mod:`foldopt.studies.worldmap`): one value per site on a world
map with coastlines, and where folding pays by latitude and load."""

from __future__ import annotations

import numpy as np
import pandas as pd

from foldopt.inputs.sites import lattice
from foldopt.output.figures.canvas import FigureFile, colour_scale, new_axes


def _grid_axes(sites: pd.DataFrame):
    """The latitude and longitude lattices of a grid of sites, or None for named sites (or a
    single row or column, drawn as dots)."""
    if (sites["site_name"].astype(str) != "").any() or len(sites) < 4:
        return None
    lats, lons = lattice(sites["latitude"]), lattice(sites["longitude"])
    return None if lats is None or lons is None or min(lats.size, lons.size) < 2 else (lats, lons)


def plot_world_map(
    rows: pd.DataFrame, value: str, title: str, label: str, diverging: bool, ax=None
):
    """One value per site on a longitude x latitude map with coastlines
    (:func:`foldopt.inputs.land.draw_coastlines`): cells for a grid of sites, dots for named sites.

    Parameters
    ----------
    rows : pandas.DataFrame
        A row per site: ``site_name``, ``latitude``, ``longitude`` [deg] and ``value``.
    value : str
        The column shown in colour (e.g. ``recommended_deg`` [deg],
        ``gain_vs_flat_pct`` [%]).
    title, label : str
        The Axes' title and the colour bar's label.
    diverging : bool
        Red-blue colours symmetric around 0 (a gain), else viridis.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (10 x 5.2 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    from foldopt.inputs.land import draw_coastlines

    fig, ax = new_axes(ax, (10, 5.2))
    values = rows[value].to_numpy(dtype=float)
    colours = colour_scale(values, diverging)
    axes = _grid_axes(rows)
    if axes is not None:
        lats, lons = axes
        grid = rows.pivot_table(index="latitude", columns="longitude", values=value, aggfunc="mean")
        grid = grid.reindex(index=lats, columns=lons, method="nearest", tolerance=1e-6)
        mesh = ax.pcolormesh(
            lons,
            lats,
            np.ma.masked_invalid(grid.to_numpy(dtype=float)),
            shading="nearest",
            **colours,
        )
    else:
        mesh = ax.scatter(
            rows["longitude"],
            rows["latitude"],
            c=values,
            s=40,
            edgecolors="k",
            linewidths=0.4,
            **colours,
        )
    coast = draw_coastlines(ax)
    ax.set_xlim(-180, 180)
    ax.set_ylim(-90, 90)
    ax.set_aspect("equal")
    ax.set_facecolor("0.9")
    ax.figure.colorbar(mesh, ax=ax, label=label, shrink=0.8)
    ax.set_xlabel("longitude [deg]")
    ax.set_ylabel("latitude [deg]")
    ax.set_title(
        title
        + _no_value(values)
        + ("" if coast else " (no coastlines: pip install global-land-mask)"),
        fontsize=10,
    )
    return ax


def _edges(centres, width: float) -> np.ndarray:
    """Cell edges around sorted centres: midpoints between them, ``width`` for a lone centre."""
    centres = np.asarray(centres, dtype=float)
    if centres.size == 1:
        return np.array([centres[0] - width / 2, centres[0] + width / 2])
    middle = (centres[1:] + centres[:-1]) / 2
    return np.concatenate([[2 * centres[0] - middle[0]], middle, [2 * centres[-1] - middle[-1]]])


def plot_latitude_load(table: pd.DataFrame, period: str, relative: bool, title: str, ax=None):
    """Where folding pays: the median gain over flat at each latitude and load as a share of the
    site's flat peak, with the +1 % contour.

    Parameters
    ----------
    table : pandas.DataFrame
        A map's table: ``period``, ``latitude`` [deg], ``p_load_frac`` [-] and
        ``gain_vs_flat_pct`` [%].
    period : str
        The period shown (``year``, ``DJF``...).
    relative : bool
        Whether the map's loads were given as fractions of the flat peak; loads given in watts are
        a different share at each site and are binned to 0.05.
    title : str
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (8 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    rows = table[table["period"] == period]
    share = (
        rows["p_load_frac"].round(9) if relative else (rows["p_load_frac"] / 0.05).round() * 0.05
    )
    # dropna=False: a latitude where no site carries a load (every gain NaN) keeps its grey cell.
    grid = rows.assign(share=share).pivot_table(
        index="share", columns="latitude", values="gain_vs_flat_pct", aggfunc="median", dropna=False
    )
    fig, ax = new_axes(ax, (8, 4.5))
    data = np.ma.masked_invalid(grid.to_numpy(dtype=float))
    mesh = ax.pcolormesh(
        _edges(grid.columns, 5.0), _edges(grid.index, 0.05), data, **colour_scale(data, True)
    )
    if data.count() > 3 and grid.shape[0] > 1 and grid.shape[1] > 1:
        ax.contour(
            grid.columns, grid.index, data.filled(np.nan), levels=[1.0], colors="k", linewidths=0.8
        )
    ax.set_facecolor("0.85")
    ax.figure.colorbar(
        mesh,
        ax=ax,
        label="median gain over flat [%]" + (" (contour: +1 %)" if grid.shape[0] > 1 else ""),
    )
    ax.set_xlabel("latitude [deg]")
    ax.set_ylabel("P_load / flat peak [-]" + ("" if relative else " (bins of 0.05)"))
    ax.set_title(title + _no_value(data), fontsize=10)
    return ax


def _no_value(values) -> str:
    """A title's note where no value is finite (no site carries the load), else nothing."""
    return (
        ""
        if np.isfinite(np.ma.filled(np.ma.masked_invalid(values), np.nan)).any()
        else " (no value: no site carries the load)"
    )


#: The world maps of one load and period: file, the column shown, what it shows, the colour bar's
#: label and whether its colours diverge around 0.
MAPS = (
    (
        "map_fold_angle.png",
        "recommended_deg",
        "recommended fold angle (the near-optimal range's centre; 180 where flat is best)",
        "fold angle Θ [deg] (180 = flat)",
        False,
    ),
    (
        "map_gain_vs_flat.png",
        "gain_vs_flat_pct",
        "t_solar gain of the twofold panel over flat",
        "gain over flat [%]",
        True,
    ),
    (
        "map_pct_of_tracker.png",
        "share_of_tracker_pct",
        "twofold panel's t_solar as a share of the tracker's",
        "share of the tracker [%]",
        False,
    ),
    (
        "map_near_optimal_width.png",
        "near_optimal_width_deg",
        "near-optimal fold-angle range's width",
        "near-optimal range, hi - lo [deg]",
        False,
    ),
)

#: The world maps a map that searches the base tilt adds (``foldopt map --optimize tilt``).
TILT_MAPS = (
    (
        "map_surface_tilt.png",
        "surface_tilt",
        "twofold panel's best base tilt",
        "base tilt [deg]",
        False,
    ),
)

#: A map's folder holds every one (the tilt's where the map searched it).
FIGURES = {
    **{
        file: FigureFile(plot_world_map, f"world map of the {description}")
        for file, _, description, _, _ in MAPS
    },
    **{
        file: FigureFile(plot_world_map, f"world map of the {description} (map --optimize tilt)")
        for file, _, description, _, _ in TILT_MAPS
    },
    "latitude_load_gain.png": FigureFile(
        plot_latitude_load, "median gain over flat by latitude and load (share of the flat peak)"
    ),
}
