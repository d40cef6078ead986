"""The figure of a site's horizon: the sun's paths on the study's days over the horizon line."""

from __future__ import annotations

import numpy as np

from foldopt.output.figures.canvas import FigureFile, new_axes


def plot_sun_paths(paths: dict, title: str, ax=None):
    """The sun's paths (azimuth x apparent elevation) over the horizon line, the sky it hides shaded.

    Parameters
    ----------
    paths : dict
        :func:`foldopt.studies.horizon_paths.sun_paths`.
    title : str
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new 8 x 4 in figure.

    Returns
    -------
    matplotlib.axes.Axes
    """
    fig, ax = new_axes(ax, (8, 4))
    grid = np.linspace(0.0, 360.0, 721)
    line = np.interp(grid, paths["horizon_azimuth"], paths["horizon_elevation"], period=360.0)
    ax.fill_between(grid, 0.0, line, color="0.55", alpha=0.6, lw=0, label="horizon")
    many = len(paths["dates"]) > 3
    for index, (azimuth, elevation) in enumerate(
        zip(paths["azimuth"], paths["elevation"], strict=True)
    ):
        order = np.argsort(np.where(np.isfinite(azimuth), azimuth, np.inf))
        ax.plot(
            azimuth[order],
            elevation[order],
            color="tab:orange",
            lw=0.6 if many else 1.2,
            alpha=0.5 if many else 1.0,
            label="the sun's paths" if index == 0 else None,
        )
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, 45))
    ax.set_ylim(0, 90)
    ax.set_xlabel("azimuth [deg from north]")
    ax.set_ylabel("elevation [deg]")
    ax.set_title(
        f"{title}: the sun behind the horizon {paths['hidden_pct']:.1f} % of daylight", fontsize=10
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    return ax


#: A study at a site with a horizon writes it.
FIGURES = {
    "horizon_sun_paths.png": FigureFile(
        plot_sun_paths,
        "the sun's paths on the study's days over the site's "
        "horizon line (the hidden share of daylight)",
    ),
}
