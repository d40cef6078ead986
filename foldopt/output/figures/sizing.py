"""The figure of a panel sizing (a :class:`foldopt.SizingResult`): the lifetime net benefit of
flat and twofold panels against their area (Shin et al. Sec. IV-A)."""

from __future__ import annotations

import pandas as pd

from foldopt.output.figures.canvas import FigureFile, new_axes


def plot_sizing(table: pd.DataFrame, best: pd.DataFrame, title: str, ax=None):
    """Lifetime net benefit against panel area for flat and twofold, each design's best area
    marked with its t_solar (Shin et al. Fig. 3a).

    Parameters
    ----------
    table : pandas.DataFrame
        A row per design and area: ``design``, ``area_m2`` [m^2] and ``net_benefit_usd`` [$]
        (``sizing.csv``).
    best : pandas.DataFrame
        Each design's best area, with its ``t_solar_h`` [h] (``sizing_best.csv``).
    title : str
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (8 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    fig, ax = new_axes(ax, (8, 4.5))
    for design, colour in (("flat", "k"), ("twofold", "tab:blue")):
        rows = table[table["design"] == design]
        ax.plot(rows["area_m2"], rows["net_benefit_usd"], color=colour, label=design)
        top = best[best["design"] == design].iloc[0]
        ax.plot(top["area_m2"], top["net_benefit_usd"], "o", color=colour)
        ax.annotate(
            f"{top['area_m2']:.3f} m², {top['t_solar_h']:.2f} h",
            (top["area_m2"], top["net_benefit_usd"]),
            textcoords="offset points",
            xytext=(5, 5),
            fontsize=8,
        )
    ax.axhline(0, color="0.6", lw=0.8)
    ax.set_xlabel("panel area [m²]")
    ax.set_ylabel("lifetime net benefit [$]")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return ax


FIGURES = {
    "net_benefit_vs_area.png": FigureFile(
        plot_sizing,
        "lifetime net benefit of flat and twofold panels against their area (Shin et al. Fig. 3a)",
    ),
}
