"""Results folders: CSV tables, PNG plots and ``run.json``.

A folder is built under a temporary name beside its destination and renamed into place only when
complete, so a failed run never leaves a half-written folder, and an existing folder is replaced
only when the caller asks for it.
"""

from __future__ import annotations

import json
import os
import platform
import shutil
import sys
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from foldopt.config import Study  # noqa: E402
from foldopt.study import StudyResult  # noqa: E402

FLOAT_FORMAT = "%.10g"
VERSIONED = ("foldopt", "numpy", "scipy", "pandas", "pvlib", "matplotlib", "pydantic", "typer")


class OutputExistsError(FileExistsError):
    """The results folder exists and overwriting was not asked for."""


def check_output(out: Path, overwrite: bool) -> None:
    """Raise :class:`OutputExistsError` if ``out`` exists and ``overwrite`` is false."""
    if out.exists() and not overwrite:
        raise OutputExistsError(f"{out} already exists; pass --overwrite to replace it")


@contextmanager
def staged_folder(out: Path, overwrite: bool):
    """Yield a temporary folder that replaces ``out`` atomically when the block succeeds."""
    check_output(out, overwrite)
    out.parent.mkdir(parents=True, exist_ok=True)
    staging = out.parent / f".{out.name}.tmp-{os.getpid()}"
    shutil.rmtree(staging, ignore_errors=True)
    staging.mkdir()
    try:
        yield staging
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    if out.exists():
        retired = out.parent / f".{out.name}.old-{os.getpid()}"
        out.rename(retired)
        staging.rename(out)
        shutil.rmtree(retired)
    else:
        staging.rename(out)


def versions() -> dict[str, str]:
    """Versions of Python and of foldopt and its main dependencies."""
    found = {"python": platform.python_version()}
    for name in VERSIONED:
        try:
            found[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            found[name] = "not installed"
    return found


def run_metadata(study: Study, command: list[str] | None = None, **extra) -> dict:
    """The content of ``run.json``: resolved study, mode, command line and versions."""
    return {
        "study": study.model_dump(mode="json"),
        "mode": study.mode,
        "command": command if command is not None else sys.argv,
        "versions": versions(),
        **extra,
    }


def _write_json(path: Path, data: dict) -> None:
    path.write_text(json.dumps(data, indent=2, sort_keys=False, default=float) + "\n")


def _clock_hours(result: StudyResult):
    times = result.day.times.tz_localize(None)
    return np.asarray((times - times.normalize()) / pd.Timedelta(hours=1))


def _mode_label(study: Study) -> str:
    return f"{study.mode} mode, {study.geometry} geometry, {study.date}"


def plot_power_curves(result: StudyResult, path: Path) -> None:
    """Flat, east, west and combined twofold power with the load (Shin et al. Fig. 6)."""
    series, hours, study = result.timeseries, _clock_hours(result), result.study
    daylight = series["p_tracker_w"].to_numpy() > 0
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.plot(hours, series["p_tracker_w"], color="0.6", ls=":", label="ideal dual-axis tracker")
    ax.plot(hours, series["p_flat_w"], color="k", label="flat")
    ax.plot(hours, series["p_east_w"], color="tab:orange", ls="--", label="east sub-panel")
    ax.plot(hours, series["p_west_w"], color="tab:purple", ls="--", label="west sub-panel")
    ax.plot(
        hours,
        series["p_twofold_w"],
        color="tab:blue",
        lw=2,
        label=f"twofold {result.optimal_fold_angle:.1f}° ({study.connection})",
    )
    ax.axhline(study.p_load, color="tab:red", lw=1, label=f"P_load = {study.p_load:.3g} W")
    if daylight.any():
        ax.set_xlim(hours[daylight].min() - 0.5, hours[daylight].max() + 0.5)
    ax.set_xlabel(f"local clock time [h] ({study.site.timezone})")
    ax.set_ylabel("P_pv [W]")
    ax.set_title(f"{study.name}: power over the day ({_mode_label(study)})")
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


STATE_COLOURS = {"east": "tab:orange", "parallel": "tab:green", "west": "tab:purple", "series": "tab:brown"}


def plot_switching(result: StudyResult, path: Path) -> None:
    """Sub-panel curves and the connection switching chooses over the day (Shin et al. Fig. 9)."""
    series, hours, study = result.timeseries, _clock_hours(result), result.study
    fig, ax = plt.subplots(figsize=(8, 4.5))
    state = series["switch_state"].to_numpy()
    step = hours[1] - hours[0]
    starts = np.flatnonzero(np.r_[True, state[1:] != state[:-1]])
    for start, stop in zip(starts, np.r_[starts[1:], state.size], strict=True):
        if state[start] != "off":
            ax.axvspan(hours[start] - step / 2, hours[stop - 1] + step / 2, color=STATE_COLOURS[state[start]], alpha=0.12, lw=0)
    for name in ("east", "west", "parallel") + (("series",) if study.switch_series else ()):
        ax.plot(hours, series[f"p_{name}_w"], color=STATE_COLOURS[name], ls="--", label=name)
    ax.plot(hours, series["p_switching_w"], color="k", lw=2, label="switching (shaded: state chosen)")
    ax.axhline(study.p_load, color="tab:red", lw=1, label=f"P_load = {study.p_load:.3g} W")
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
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_t_solar_vs_fold_angle(result: StudyResult, path: Path) -> None:
    """t_solar versus fold angle, with flat and tracker levels (Shin et al. Fig. 12a)."""
    summary = result.summary.set_index("design")
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot(
        result.sweep["fold_angle_deg"], result.sweep["t_solar_h"], color="tab:blue", label=f"twofold ({result.study.connection})"
    )
    if result.study.pv_model != "ideal":
        for name in ("parallel", "series", "independent"):
            if name != result.study.connection:
                ax.plot(result.sweep["fold_angle_deg"], result.sweep[f"t_solar_{name}_h"], lw=1, ls="--",
                        color=STATE_COLOURS.get(name, "tab:gray"), label=f"twofold ({name})")
    ax.axhline(summary.loc["flat", "t_solar_h"], color="k", ls="--", label="flat")
    ax.axhline(summary.loc["tracker", "t_solar_h"], color="0.5", ls=":", label="ideal tracker")
    ax.axvline(
        result.optimal_fold_angle, color="tab:green", lw=1, label=f"sweep optimum {result.optimal_fold_angle:.2f}°"
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
    ax.set_xlim(0, 180)
    ax.set_title(f"{result.study.name}: t_solar vs fold angle ({_mode_label(result.study)})", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_comparison(result: StudyResult, path: Path) -> None:
    """t_solar of flat, optimal twofold and tracker (Shin et al. Fig. 12b)."""
    summary = result.summary.set_index("design").loc[["flat", "twofold", "tracker"]]
    labels = ["flat", f"twofold {summary.loc['twofold', 'fold_angle_deg']:.1f}°", "ideal tracker"]
    fig, ax = plt.subplots(figsize=(6, 4.5))
    bars = ax.bar(labels, summary["t_solar_h"], color=["0.3", "tab:blue", "0.7"])
    for bar, hours, share in zip(bars, summary["t_solar_h"], summary["pct_of_tracker_t_solar"], strict=True):
        ax.annotate(
            f"{hours:.2f} h\n{share:.1f} % of tracker",
            (bar.get_x() + bar.get_width() / 2, bar.get_height()),
            ha="center",
            va="bottom",
            fontsize=8,
        )
    ax.set_ylabel("t_solar [h]")
    ax.set_ylim(0, max(summary["t_solar_h"].max() * 1.2, 1))
    ax.set_title(f"{result.study.name}: {_mode_label(result.study)}", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_study(result: StudyResult, out: Path, overwrite: bool = False, command=None) -> Path:
    """Write a study's results folder: summary, sweep and time-series CSVs, plots, ``run.json``."""
    with staged_folder(out, overwrite) as folder:
        result.summary.to_csv(folder / "summary.csv", index=False, float_format=FLOAT_FORMAT)
        result.sweep.to_csv(folder / "sweep.csv", index=False, float_format=FLOAT_FORMAT)
        result.timeseries.to_csv(folder / "timeseries.csv", index=False, float_format=FLOAT_FORMAT)
        plot_power_curves(result, folder / "power_curves.png")
        plot_t_solar_vs_fold_angle(result, folder / "t_solar_vs_fold_angle.png")
        plot_comparison(result, folder / "comparison.png")
        plot_switching(result, folder / "switching.png")
        _write_json(
            folder / "run.json",
            run_metadata(
                result.study,
                command,
                optimal_fold_angle_deg=result.optimal_fold_angle,
                # NaN (the load exceeds the flat panel's noon power) is not JSON: null instead.
                heuristic_fold_angle_deg=(
                    result.heuristic_fold_angle if np.isfinite(result.heuristic_fold_angle) else None
                ),
            ),
        )
    return out


def write_reproduction(tables: dict[str, pd.DataFrame], study: Study, out: Path, overwrite=False, command=None) -> Path:
    """Write one ``<name>.csv`` per reproduction table and ``run.json``."""
    with staged_folder(out, overwrite) as folder:
        for name, table in tables.items():
            table.to_csv(folder / f"{name}.csv", index=False, float_format=FLOAT_FORMAT)
        _write_json(folder / "run.json", run_metadata(study, command, modes=["paper", "exact"], tables=list(tables)))
    return out
