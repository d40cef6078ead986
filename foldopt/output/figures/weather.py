"""Figures of a weather study's light: a sample day's minutes beside its hourly means (measured
minutes, the smooth minutes of an hourly file, or a cloud ensemble's members), and each day's
t_solar over an ensemble's members."""

from __future__ import annotations

import numpy as np
import pandas as pd

from foldopt.output.figures.canvas import FigureFile, load_label, new_axes
from foldopt.output.figures.sweep import DAY_GAP, broken_at_gaps

#: Members drawn one by one in the sample day's figure (the rest make the band).
SHOWN_MEMBERS = 3


def plot_weather_minutes(sample: dict, title: str, ax=None):
    """A sample day's GHI at every step of the study, beside the hourly means it keeps.

    Parameters
    ----------
    sample : dict
        ``date``, ``hours`` (n_steps,) clock hours of the steps, ``ghi`` (k, n_steps) [W/m^2] the
        study's GHI (k members, or 1), ``hourly_ghi`` (24,) [W/m^2] the hours' means, ``kind``
        (``measured``, ``smooth`` or ``members``).
    title : str
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new 8 x 4 in figure.

    Returns
    -------
    matplotlib.axes.Axes
    """
    fig, ax = new_axes(ax, (8, 4))
    hours, ghi = np.asarray(sample["hours"]), np.atleast_2d(sample["ghi"])
    if len(ghi) > 1:
        ax.fill_between(
            hours,
            np.percentile(ghi, 10, axis=0),
            np.percentile(ghi, 90, axis=0),
            color="tab:blue",
            alpha=0.2,
            lw=0,
            label=f"P10-P90 of {len(ghi)} members",
        )
    for index, member in enumerate(ghi[:SHOWN_MEMBERS]):
        label = {"measured": "measured minutes", "smooth": "smooth minutes"}.get(
            sample["kind"], "a member"
        )
        ax.plot(
            hours,
            member,
            lw=0.8,
            color="tab:blue",
            alpha=1.0 if index == 0 else 0.5,
            label=label if index == 0 else None,
        )
    ax.step(
        np.arange(25),
        np.r_[sample["hourly_ghi"], sample["hourly_ghi"][-1]],
        where="post",
        color="k",
        lw=1.2,
        label="hourly means",
    )
    ax.set_xlim(0, 24)
    ax.set_xticks(range(0, 25, 3))
    ax.set_xlabel("local standard time [h]")
    ax.set_ylabel("GHI [W/m^2]")
    ax.set_title(f"{title} ({sample['date']})", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    return ax


def plot_member_t_solar(table: pd.DataFrame, title: str, ax=None, study=None):
    """Each day's t_solar over a cloud ensemble's members: P10 to P90 and the median, for the
    flat and the twofold panel, at the first load; line and band join only days at most
    :data:`~foldopt.output.figures.sweep.DAY_GAP` apart, and a day with none so near is a marker
    and a bar (:func:`~foldopt.output.figures.sweep.broken_at_gaps`).

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep's tidy table with ``t_solar_members_p10_h``, ``t_solar_members_p50_h`` and
        ``t_solar_members_p90_h``.
    title : str
    ax : matplotlib.axes.Axes, optional
    study : foldopt.Study, optional
        Names a load profile's loads.

    Returns
    -------
    matplotlib.axes.Axes
    """
    fig, ax = new_axes(ax, (8, 4))
    load = sorted(table["p_load_w"].unique())[0]
    for design, colour in (("flat", "0.35"), ("twofold", "tab:blue")):
        rows = table[(table["design"] == design) & (table["p_load_w"] == load)].sort_values(
            "dayofyear"
        )
        # Line and band stop where nothing was evaluated between two days (solstices, months).
        (days, p10, alone), (_, p50, _), (_, p90, _) = (
            broken_at_gaps(rows["dayofyear"], rows[column], DAY_GAP)
            for column in (
                "t_solar_members_p10_h",
                "t_solar_members_p50_h",
                "t_solar_members_p90_h",
            )
        )
        ax.fill_between(days, p10, p90, where=~alone, color=colour, alpha=0.25, lw=0)
        # a lone day's band
        ax.vlines(days[alone], p10[alone], p90[alone], color=colour, alpha=0.25, lw=4)
        ax.plot(
            days,
            p50,
            color=colour,
            lw=1,
            marker="o" if alone.any() else None,
            ms=4,
            markevery=alone.tolist(),
            label=f"{design}: median, P10-P90 band",
        )
    ax.set_xlabel("day of year")
    ax.set_ylabel(f"daily t_solar [h]\n{load_label(study, load)}", fontsize=8)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return ax


#: A weather study's folder holds the first; a cloud ensemble's the second too.
FIGURES = {
    "weather_minutes.png": FigureFile(
        plot_weather_minutes,
        "a sample day's GHI at every step (measured, smooth or "
        "a cloud ensemble's members) beside its hourly means",
    ),
    "ensemble_t_solar.png": FigureFile(
        plot_member_t_solar,
        "each day's t_solar over a cloud ensemble's members "
        "(P10-P90 and the median), flat and twofold",
    ),
}
