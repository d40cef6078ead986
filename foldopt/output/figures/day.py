"""Figures of one day (a :class:`foldopt.StudyResult`): the power curves, the connection switching
chooses, t_solar against the fold angle, the designs compared and the tracker's standby draw."""

from __future__ import annotations

import numpy as np
import pandas as pd

from foldopt.inputs.study import Study
from foldopt.names import FLAT_FOLD_ANGLE, IV_MODELS
from foldopt.output.figures.canvas import ONE_AXES, FigureFile, new_axes
from foldopt.studies.day import StudyResult

#: The colour of each connection of the sub-panels (and of a switching state).
STATE_COLOURS = {
    "east": "tab:orange",
    "parallel": "tab:green",
    "west": "tab:purple",
    "series": "tab:brown",
}


def _clock_hours(result: StudyResult):
    times = result.day.times.tz_localize(None)
    return np.asarray((times - times.normalize()) / pd.Timedelta(hours=1))


def _mode_label(study: Study) -> str:
    return f"{study.mode} mode, {study.geometry} geometry, {study.date}"


def _connection_label(study: Study, connection: str) -> str:
    """A connection's name in a legend; independent's says it runs through a converter per
    sub-panel (and, with a load wired directly, that it is not wired so: Circuit.ignored_by)."""
    if connection != "independent":
        return connection
    return (
        f"{connection}, {study.circuit.ignored_by(connection) or 'with a converter per sub-panel'}"
    )


def _draw_load(ax, hours, series, study) -> None:
    """The load: a line at P_load, or a load profile's P_load(t) as its curve, labelled as a load."""
    from foldopt.inputs.load_profile import load_text

    if study.load_profile is None:
        ax.axhline(study.p_load, color="tab:red", lw=1, label=f"P_load = {study.p_load:.3g} W")
    else:
        ax.step(
            hours, series["p_load_w"], where="mid", color="tab:red", lw=1, label=load_text(study)
        )


def plot_power_curves(result: StudyResult, ax=None):
    """Flat, east, west and combined twofold power over the day with the load (Shin et al. Fig. 6).

    Parameters
    ----------
    result : foldopt.StudyResult
        Its time series gives the powers P_pv [W] against local clock time [h].
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (8 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    series, hours, study = result.timeseries, _clock_hours(result), result.study
    daylight = series["p_tracker_w"].to_numpy() > 0
    fig, ax = new_axes(ax, (8, 4.5))
    ax.plot(hours, series["p_tracker_w"], color="0.6", ls=":", label="ideal dual-axis tracker")
    ax.plot(hours, series["p_flat_w"], color="k", label="flat")
    ax.plot(hours, series["p_east_w"], color="tab:orange", ls="--", label="east sub-panel")
    ax.plot(hours, series["p_west_w"], color="tab:purple", ls="--", label="west sub-panel")
    ax.plot(
        hours,
        series["p_twofold_w"],
        color="tab:blue",
        lw=2,
        label=f"twofold {result.optimal_fold_angle:.1f}° ({_connection_label(study, study.connection)})",
    )
    _draw_load(ax, hours, series, study)
    if daylight.any():
        ax.set_xlim(hours[daylight].min() - 0.5, hours[daylight].max() + 0.5)
    ax.set_xlabel(f"local clock time [h] ({study.site.timezone})")
    ax.set_ylabel("P_pv [W]")
    ax.set_title(f"{study.name}: power over the day ({_mode_label(study)})")
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3)
    return ax


def plot_switching(result: StudyResult, ax=None):
    """The sub-panels' power in each connection and the one switching chooses over the day,
    shaded (Shin et al. Fig. 9).

    Parameters
    ----------
    result : foldopt.StudyResult
        At its optimal fold angle; its time series gives the powers P_pv [W] and ``switch_state``.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (8 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    series, hours, study = result.timeseries, _clock_hours(result), result.study
    fig, ax = new_axes(ax, (8, 4.5))
    state = series["switch_state"].to_numpy()
    step = hours[1] - hours[0]
    starts = np.flatnonzero(np.r_[True, state[1:] != state[:-1]])
    for start, stop in zip(starts, np.r_[starts[1:], state.size], strict=True):
        if state[start] != "off":
            ax.axvspan(
                hours[start] - step / 2,
                hours[stop - 1] + step / 2,
                color=STATE_COLOURS[state[start]],
                alpha=0.12,
                lw=0,
            )
    for name in ("east", "west", "parallel") + (("series",) if study.switch_series else ()):
        ax.plot(hours, series[f"p_{name}_w"], color=STATE_COLOURS[name], ls="--", label=name)
    ax.plot(
        hours, series["p_switching_w"], color="k", lw=2, label="switching (shaded: state chosen)"
    )
    _draw_load(ax, hours, series, study)
    daylight = series["p_switching_w"].to_numpy() > 0
    if daylight.any():
        ax.set_xlim(hours[daylight].min() - 0.5, hours[daylight].max() + 0.5)
    ax.set_xlabel(f"local clock time [h] ({study.site.timezone})")
    ax.set_ylabel("P_pv [W]")
    ax.set_title(
        f"{study.name}: sub-panel switching at {result.optimal_fold_angle:.1f}° ({study.pv_model}, {study.mode} mode)",
        fontsize=10,
    )
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3)
    return ax


def plot_t_solar_vs_fold_angle(result: StudyResult, ax=None):
    """t_solar against the fold angle, with the flat and tracker levels, the sweep's optimum and
    the paper's heuristic angle (Shin et al. Fig. 12a).

    Parameters
    ----------
    result : foldopt.StudyResult
        Its sweep gives t_solar [h] at each fold angle [deg] (every connection, for a PV model
        other than ``ideal``).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (7 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    summary = result.summary.set_index("design")
    fig, ax = new_axes(ax, (7, 4.5))
    ax.plot(
        result.sweep["fold_angle_deg"],
        result.sweep["t_solar_h"],
        color="tab:blue",
        label=f"twofold ({_connection_label(result.study, result.study.connection)})",
    )
    if result.study.pv_model in IV_MODELS:  # without I-V curve, every pair delivers the sum
        for name in ("parallel", "series", "independent"):
            if name != result.study.connection:
                ax.plot(
                    result.sweep["fold_angle_deg"],
                    result.sweep[f"t_solar_{name}_h"],
                    lw=1,
                    ls="--",
                    color=STATE_COLOURS.get(name, "tab:gray"),
                    label=f"twofold ({_connection_label(result.study, name)})",
                )
    ax.axhline(summary.loc["flat", "t_solar_h"], color="k", ls="--", label="flat")
    ax.axhline(summary.loc["tracker", "t_solar_h"], color="0.5", ls=":", label="ideal tracker")
    ax.axvline(
        result.optimal_fold_angle,
        color="tab:green",
        lw=1,
        label=f"sweep optimum {result.optimal_fold_angle:.2f}°",
    )
    if np.isfinite(result.heuristic_fold_angle):
        ax.axvline(
            result.heuristic_fold_angle,
            color="tab:red",
            lw=1,
            ls="-.",
            label=f"paper heuristic {result.heuristic_fold_angle:.2f}°",
        )
    ax.set_xlabel("fold angle Θ [deg] (180 = flat)")
    ax.set_ylabel("t_solar [h]")
    ax.set_xlim(0, FLAT_FOLD_ANGLE)
    ax.set_title(
        f"{result.study.name}: t_solar vs fold angle ({_mode_label(result.study)})", fontsize=10
    )
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return ax


def plot_comparison(result: StudyResult, ax=None):
    """t_solar of the flat panel, the optimal twofold panel and every tracker, gross and net of
    the tracker's own draw, as bars (Shin et al. Fig. 12b).

    Parameters
    ----------
    result : foldopt.StudyResult
        Its summary gives each design's t_solar [h].
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure, 4.5 in high and wide enough for the designs.

    Returns
    -------
    matplotlib.axes.Axes
    """
    summary = result.summary.set_index("design")
    names = ["flat", "twofold"] + [
        d for d in summary.index if d.startswith("tracker") and not d.endswith("-net")
    ]
    labels = ["flat", f"twofold\n{summary.loc['twofold', 'fold_angle_deg']:.1f}°"] + [
        (result.study.tracker.model if d == "tracker" else d.split(":", 1)[1]).replace(
            "-", "-\n", 1
        )
        for d in names[2:]
    ]
    x = np.arange(len(names))
    gross = summary.loc[names, "t_solar_h"].to_numpy()
    net = np.array(
        [
            summary.loc[f"{d}-net", "t_solar_h"] if f"{d}-net" in summary.index else np.nan
            for d in names
        ]
    )
    fig, ax = new_axes(ax, (max(6, 1.1 * len(names) + 2), 4.5))
    colours = ["0.3", "tab:blue"] + ["0.7"] * (len(names) - 2)
    ax.bar(x, gross, color=colours, label="gross")
    ax.bar(x[2:], net[2:], width=0.45, color="tab:orange", label="net of the tracker's own draw")
    for xi, hours in zip(x, gross, strict=True):
        ax.annotate(f"{hours:.2f} h", (xi, hours), ha="center", va="bottom", fontsize=8)
    ax.set_xticks(x, labels, fontsize=8)
    ax.set_ylabel("t_solar [h]")
    ax.set_ylim(0, max(gross.max() * 1.2, 1))
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title(f"{result.study.name}: {_mode_label(result.study)}", fontsize=10)
    return ax


def plot_standby(result: StudyResult, ax=None):
    """The tracker's net t_solar against its standby draw, beside the optimal twofold panel's, and
    the break-even draw where the twofold panel overtakes it.

    Parameters
    ----------
    result : foldopt.StudyResult
        Its ``standby``: the table of t_solar [h] per standby draw [W] and the break-even draw [W]
        (NaN where there is none).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (7 x 4.5 in).

    Returns
    -------
    matplotlib.axes.Axes
    """
    table, break_even = result.standby
    study = result.study
    fig, ax = new_axes(ax, (7, 4.5))
    ax.plot(
        table["standby_w"],
        table["t_solar_tracker_net_h"],
        color="0.4",
        label=f"{study.tracker.model} tracker, net",
    )
    ax.axhline(
        table["t_solar_twofold_h"].iloc[0],
        color="tab:blue",
        label="optimal twofold (draws nothing)",
    )
    if np.isfinite(break_even):
        ax.axvline(
            break_even, color="tab:red", ls="--", lw=1, label=f"break-even {break_even:.2f} W"
        )
    ax.set_xlabel("tracker standby draw [W]")
    ax.set_ylabel("t_solar [h]")
    ax.set_title(
        f"{study.name}: when does the tracker's own draw hand the day to the twofold panel?",
        fontsize=9,
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return ax


#: A day's results folder holds every one, in this order (each drawn from the StudyResult alone, one
#: Axes laid out by fixed margins).
FIGURES = {
    "power_curves.png": FigureFile(
        plot_power_curves,
        "flat, east, west and twofold power over the day, with the load (Shin et al. Fig. 6)",
        ONE_AXES,
    ),
    "t_solar_vs_fold_angle.png": FigureFile(
        plot_t_solar_vs_fold_angle,
        "t_solar against the fold angle, with flat, tracker and the paper's heuristic (Fig. 12a)",
        ONE_AXES,
    ),
    "comparison.png": FigureFile(
        plot_comparison,
        "t_solar of flat, optimal twofold and every tracker, gross and net (Fig. 12b)",
        ONE_AXES,
    ),
    "switching.png": FigureFile(
        plot_switching,
        "the sub-panels' connections and the one switching chooses over the day (Fig. 9)",
        ONE_AXES,
    ),
    "tracker_standby.png": FigureFile(
        plot_standby,
        "the tracker's net t_solar against its standby draw, and the break-even draw",
        ONE_AXES,
    ),
}
