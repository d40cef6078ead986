"""Figures of an annual study (a sweep that varies the date): the year at each fold angle kept all
year, every design month by month, the daily t_solar's distribution, day x hour maps and what each
re-fold visit is worth."""

from __future__ import annotations

import numpy as np
import pandas as pd

from foldopt.output.figures.canvas import FigureFile, load_label, new_axes
from foldopt.output.figures.sweep import DAY_GAP, cells
from foldopt.names import FLAT_FOLD_ANGLE
from foldopt.physics.connections import SWITCH_STATES

MONTH_NAMES = ("J", "F", "M", "A", "M", "J", "J", "A", "S", "O", "N", "D")
#: The colour of each design in the month-by-month bars and the distribution's boxes.
DESIGN_COLOURS = {
    "flat": "0.35",
    "twofold": "tab:blue",
    "tracker": "0.7",
    "tracker-net": "tab:orange",
}


def _designs(table: pd.DataFrame) -> list[str]:
    return [d for d in DESIGN_COLOURS if d in set(table["design"])]


def plot_annual_fold_angles(by_angle: pd.DataFrame, title: str, study=None, ax=None):
    """The objective and the mean daily t_solar of each fold angle kept all year, per load, with
    the angle chosen marked.

    Parameters
    ----------
    by_angle : pandas.DataFrame
        A row per load and fold angle: ``p_load_w`` [W], ``fold_angle_deg`` [deg],
        ``t_solar_mean_h`` and ``t_solar_objective_h`` [h] and ``chosen`` (bool), as
        ``annual_fold_angles.csv``.
    title : str
    study : foldopt.Study, optional
        Names a load profile's loads in the legend.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (7 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    fig, ax = new_axes(ax, (7, 4.5))
    import matplotlib  # loaded by new_axes

    colours = matplotlib.colormaps["viridis"](np.linspace(0, 0.85, 8))
    for (load, rows), colour in zip(by_angle.groupby("p_load_w"), colours, strict=False):
        ax.plot(
            rows["fold_angle_deg"],
            rows["t_solar_mean_h"],
            color=colour,
            label=f"mean, {load_label(study, load)}",
        )
        ax.plot(
            rows["fold_angle_deg"],
            rows["t_solar_objective_h"],
            color=colour,
            ls="--",
            lw=1,
            label="objective",
        )
        chosen = rows[rows["chosen"]]
        ax.plot(chosen["fold_angle_deg"], chosen["t_solar_objective_h"], "o", color=colour)
    ax.set_xlabel("fold angle Θ kept all year [deg] (180 = flat)")
    ax.set_ylabel("daily t_solar [h]")
    ax.set_xlim(0, FLAT_FOLD_ANGLE)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return ax


def monthly_means(table: pd.DataFrame, loads_at_most: int = 4) -> pd.DataFrame:
    """What :func:`plot_monthly` draws: per load, design and month, the mean day of the days the
    study has in that month (the first case's site), whatever their number.

    A month's sum over the days sampled would grow with their number (every 7th day: five days in
    some months, four in others); the mean day is comparable across months, and with every day
    it is the month's total over its days.

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep's tidy table with ``date``, ``design``, ``p_load_w`` [W],
        ``energy_harvested_wh`` [Wh] and ``t_solar_h`` [h].
    loads_at_most : int, default 4
        The lowest loads kept.

    Returns
    -------
    pandas.DataFrame
        ``p_load_w`` [W], ``design``, ``month`` [1-12], ``days`` (of the table in that month),
        ``energy_harvested_wh`` [Wh] and ``t_solar_h`` [h] of the mean day.
    """
    table = table.assign(month=pd.to_datetime(table["date"]).dt.month)
    first = table.iloc[0]
    for column in ("site_name", "latitude", "longitude"):
        if column in table:
            # A grid point's site has no name: NaN, read from results.csv, is its own site.
            same = (
                table[column].isna() if pd.isna(first[column]) else table[column] == first[column]
            )
            table = table[same]
    loads = sorted(table["p_load_w"].unique())[:loads_at_most]
    rows = table[table["p_load_w"].isin(loads) & table["design"].isin(_designs(table))]
    means = rows.groupby(["p_load_w", "design", "month"])[
        ["energy_harvested_wh", "t_solar_h"]
    ].mean()
    return means.assign(days=rows.groupby(["p_load_w", "design", "month"]).size()).reset_index()


def plot_monthly(table: pd.DataFrame, title: str, loads_at_most: int = 4, axes=None, study=None):
    """The mean day of each month, energy harvested and t_solar of every design side by side, a
    row per load (the first case's site): :func:`monthly_means`.

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep's tidy table with ``date``, ``design``, ``p_load_w`` [W],
        ``energy_harvested_wh`` [Wh] and ``t_solar_h`` [h].
    title : str
        The figure's title.
    loads_at_most : int, default 4
        The lowest loads shown, a row each.
    axes : numpy.ndarray of matplotlib.axes.Axes, optional
        A (loads, 2) array to draw on: mean daily energy [Wh] on the left, mean daily t_solar [h]
        on the right; default a new figure (11 in wide, 3.2 in per load).
    study : foldopt.Study, optional
        Names a load profile's loads.

    Returns
    -------
    numpy.ndarray of matplotlib.axes.Axes
        ``axes``.
    """
    means = monthly_means(table, loads_at_most)
    loads = sorted(means["p_load_w"].unique())
    designs = [d for d in DESIGN_COLOURS if d in set(means["design"])]
    if axes is None:
        _, axes = new_axes(None, (11, 3.2 * len(loads)), len(loads), 2, squeeze=False)
    width = 0.8 / len(designs)
    for (energy_ax, time_ax), load in zip(axes, loads, strict=True):
        for i, design in enumerate(designs):
            monthly = means[(means["p_load_w"] == load) & (means["design"] == design)]
            x = monthly["month"].to_numpy() + (i - (len(designs) - 1) / 2) * width
            energy_ax.bar(
                x, monthly["energy_harvested_wh"], width, color=DESIGN_COLOURS[design], label=design
            )
            time_ax.bar(x, monthly["t_solar_h"], width, color=DESIGN_COLOURS[design], label=design)
        energy_ax.set_ylabel("energy harvested [Wh/day]")
        time_ax.set_ylabel(f"t_solar [h/day]\n{load_label(study, load)}", fontsize=8)
        for ax in (energy_ax, time_ax):
            ax.set_xticks(range(1, 13), MONTH_NAMES)
            ax.grid(alpha=0.3, axis="y")
    axes[0, 0].legend(fontsize=8)
    axes[0, 0].set_title("mean daily energy harvested, per month", fontsize=10)
    axes[0, 1].set_title("mean daily t_solar, per month", fontsize=10)
    axes[0, 0].figure.suptitle(title, fontsize=10)
    return axes


def plot_distribution(table: pd.DataFrame, title: str, ax=None, study=None):
    """Daily t_solar of each design as box plots (whiskers at 1.5 IQR, no outliers), a group per
    load.

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep's tidy table with ``design``, ``p_load_w`` [W] and ``t_solar_h`` [h].
    title : str
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure, 4.5 in high and wide enough for the loads.
    study : foldopt.Study, optional
        Names a load profile's loads.

    Returns
    -------
    matplotlib.axes.Axes
    """
    designs = _designs(table)
    loads = sorted(table["p_load_w"].unique())
    fig, ax = new_axes(ax, (max(6, 2.2 * len(loads) + 2), 4.5))
    width = 0.8 / len(designs)
    for i, design in enumerate(designs):
        data = [
            table[(table.design == design) & (table.p_load_w == load)]["t_solar_h"].to_numpy()
            for load in loads
        ]
        positions = np.arange(len(loads)) + (i - (len(designs) - 1) / 2) * width
        box = ax.boxplot(
            data, positions=positions, widths=width * 0.9, patch_artist=True, showfliers=False
        )
        for patch in box["boxes"]:
            patch.set_facecolor(DESIGN_COLOURS[design])
        ax.plot([], [], color=DESIGN_COLOURS[design], lw=6, label=design)
    ax.set_xticks(np.arange(len(loads)), [load_label(study, load) for load in loads], fontsize=7)
    ax.set_ylabel("daily t_solar [h]")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=8)
    return ax


def plot_day_hour(extras: dict, key: str, title: str, label: str, ax=None):
    """A day x hour heat map of one annual series: the twofold panel's power, or the switch state.

    Parameters
    ----------
    extras : dict
        A :class:`foldopt.SweepResult`'s ``extras``: ``dates`` (the days, ascending), ``hours``
        (local clock time [h]) and ``key``, a (days, hours) array. A day's column spans at most
        :data:`foldopt.output.figures.sweep.DAY_GAP` around it: days between sampled days further
        apart are grey, not the nearer day's (:func:`foldopt.output.figures.sweep.cells`).
    key : {'p_twofold_w', 'switch_state'}
        The series: power P_pv [W] (magma colours), or the connection chosen (-1 off, then the
        index in :data:`foldopt.physics.connections.SWITCH_STATES`).
    title : str
    label : str
        The colour bar's label (unused for the switch state, whose bar names the states).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (9 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    values = np.asarray(extras[key], dtype=float)
    first = extras["dates"][0]
    day_edges, day_cells = cells([(date - first).days + 1 for date in extras["dates"]], DAY_GAP)
    hour_edges, _ = cells(extras["hours"])
    shown = np.ma.masked_invalid(np.where(day_cells[:, None] >= 0, values[day_cells], np.nan).T)
    fig, ax = new_axes(ax, (9, 4.5))
    ax.set_facecolor("0.85")
    if key == "switch_state":
        import matplotlib  # loaded by new_axes

        cmap = matplotlib.colors.ListedColormap(
            ["0.15", "tab:orange", "tab:purple", "tab:green", "tab:brown"]
        )
        mesh = ax.pcolormesh(
            day_edges, hour_edges, shown, cmap=cmap, vmin=-1.5, vmax=3.5, shading="flat"
        )
        bar = ax.figure.colorbar(mesh, ax=ax, ticks=range(-1, 4))
        bar.ax.set_yticklabels(["off", *SWITCH_STATES])
    else:
        mesh = ax.pcolormesh(day_edges, hour_edges, shown, cmap="magma", shading="flat")
        ax.figure.colorbar(mesh, ax=ax, label=label)
    ax.set_xlabel(f"day of the study (1 = {first:%Y-%m-%d})")
    ax.set_ylabel("local clock time [h]")
    ax.set_title(title, fontsize=10)
    return ax


def plot_refold_value(values: pd.DataFrame, title: str, study=None, ax=None):
    """The objective of the best schedule of k fold settings a year against k, per load (the first
    site's), beside the flat panel and the tracker (:func:`foldopt.studies.sweeps.refold_tables`).

    Parameters
    ----------
    values : pandas.DataFrame
        As ``refold_value.csv``: ``latitude``, ``longitude`` [deg], ``p_load_w`` [W],
        ``settings_n``, ``objective`` (its statistic), ``t_solar_objective_h``, ``t_solar_flat_objective_h`` and
        ``t_solar_tracker_objective_h`` [h].
    title : str
    study : foldopt.Study, optional
        Names a load profile's loads.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (7 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    fig, ax = new_axes(ax, (7, 4.5))
    import matplotlib  # loaded by new_axes

    first = values[
        (values["latitude"] == values["latitude"].iloc[0])
        & (values["longitude"] == values["longitude"].iloc[0])
    ]
    colours = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    for (load, rows), colour in zip(first.groupby("p_load_w"), colours, strict=False):
        ax.plot(
            rows["settings_n"],
            rows["t_solar_objective_h"],
            "o-",
            color=colour,
            label=f"twofold, {load_label(study, load)}",
        )
        ax.axhline(rows["t_solar_flat_objective_h"].iloc[0], color=colour, ls="--", lw=1)
        ax.axhline(rows["t_solar_tracker_objective_h"].iloc[0], color=colour, ls=":", lw=1)
    ax.plot([], [], "k--", lw=1, label="flat panel")
    ax.plot([], [], "k:", lw=1, label="tracker")
    ax.set_xlabel("fold settings a year (1 = one fixed angle)")
    ax.set_ylabel(f"{values['objective'].iloc[0]} daily t_solar [h]")
    ax.set_xticks(sorted(first["settings_n"].unique()))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    return ax


#: The colour of each design of a buffer's years (``storage_years.csv``).
YEAR_COLOURS = {**DESIGN_COLOURS, "twofold-buffer": "tab:green"}


def plot_powered_by_year(years: pd.DataFrame, title: str, study=None, ax=None):
    """Mean daily powered time with the buffer in each calendar year, per design (the first
    case's first load), each design's worst year ringed and its worst month's mean beneath.

    Parameters
    ----------
    years : pandas.DataFrame
        ``storage_years.csv``: ``p_load_w``, ``design``, ``fold_angle_deg``, ``year``,
        ``powered_mean_h``, ``powered_worst_month_h`` [h] and ``worst_year``.
    title : str
    study : foldopt.Study, optional
        Names a load profile's load.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (8 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    fig, ax = new_axes(ax, (8, 4.5))
    block = (years["design"] != years["design"].shift()).cumsum()
    first = years[block <= len(set(years["design"]))]
    for design, rows in first.groupby("design", sort=False):
        colour = YEAR_COLOURS.get(design, "k")
        angle = rows["fold_angle_deg"].iloc[0]
        label = design if angle != angle or design == "flat" else f"{design} {angle:g} deg"
        ax.plot(rows["year"], rows["powered_mean_h"], "o-", color=colour, label=label)
        ax.plot(rows["year"], rows["powered_worst_month_h"], ":", color=colour, lw=1)
        worst = rows[rows["worst_year"]]
        ax.plot(worst["year"], worst["powered_mean_h"], "o", ms=12, mfc="none", color=colour)
    ax.plot([], [], "k:", lw=1, label="worst month's mean")
    ax.set_xlabel("year")
    ax.set_ylabel(
        f"powered time [h a day], {load_label(study, first['p_load_w'].iloc[0])}", fontsize=9
    )
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    return ax


#: An annual study's folder holds the first two, the next three where one fold angle is kept all
#: year (an objective over the days), the next where re-folding is valued and the last where a
#: buffer runs over several calendar years.
FIGURES = {
    "daily_t_solar_distribution.png": FigureFile(
        plot_distribution, "daily t_solar of each design as box plots, per load"
    ),
    "monthly_energy_t_solar.png": FigureFile(
        plot_monthly, "mean daily energy harvested and t_solar of every design, month by month"
    ),
    "annual_t_solar_vs_fold_angle.png": FigureFile(
        plot_annual_fold_angles,
        "the year's objective and mean daily t_solar at each fold angle kept all year",
    ),
    "day_hour_power.png": FigureFile(plot_day_hour, "the twofold panel's power, day by hour"),
    "day_hour_switch_state.png": FigureFile(
        plot_day_hour, "the connection the switch chooses, day by hour"
    ),
    "refold_value.png": FigureFile(
        plot_refold_value, "the objective of the best schedule of k fold settings a year against k"
    ),
    "storage_years.png": FigureFile(
        plot_powered_by_year,
        "mean daily powered time with the buffer in each calendar year per design, the worst "
        "year ringed (a buffer over two years or more)",
    ),
}
