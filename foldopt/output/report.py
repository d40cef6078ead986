"""Results folders: CSV tables, PNG plots and ``run.json`` (built atomically, see
:mod:`foldopt.files`), each a view of its result's answer (:mod:`foldopt.studies.answer`)."""

from __future__ import annotations

import atexit
import hashlib
import json
import os
import shutil
import sys
import tempfile
from pathlib import Path


def _writable(folder: Path) -> bool:
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return False
    return folder.is_dir() and os.access(folder, os.W_OK)


def _matplotlib_folder() -> None:
    """Give matplotlib a writable folder for its configuration and font cache (``MPLCONFIGDIR``)
    where its own under HOME is not (HOME read-only, missing or no folder): matplotlib would warn
    on stderr, which ``--quiet`` keeps empty. foldopt's cache folder is taken where it is
    writable (the font cache is then kept), else a temporary folder removed at exit. Run before
    matplotlib is imported, which reads the variable once."""
    if os.environ.get("MPLCONFIGDIR"):
        return
    try:
        own = [Path(os.environ.get("XDG_CONFIG_HOME") or Path.home() / ".config") / "matplotlib",
               Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "matplotlib"]
    except RuntimeError:  # no home folder at all
        own = []
    if own and all(_writable(folder) for folder in own):
        return
    from foldopt.files import cache_dir

    try:
        folder = cache_dir() / "matplotlib"
    except RuntimeError:
        folder = None
    if folder is None or not _writable(folder):
        folder = Path(tempfile.mkdtemp(prefix="foldopt-matplotlib-"))
        atexit.register(shutil.rmtree, folder, ignore_errors=True)
    os.environ["MPLCONFIGDIR"] = str(folder)


_matplotlib_folder()
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from foldopt.physics.connections import SWITCH_STATES  # noqa: E402
from foldopt.files import staged_folder, versions, write_atomically  # noqa: E402
from foldopt.inputs.config import Study  # noqa: E402
from foldopt.engine.metrics import relative_to  # noqa: E402
from foldopt.studies.day import StudyResult  # noqa: E402
from foldopt.output.html import write_html  # noqa: E402

FLOAT_FORMAT = "%.10g"
TIME_FORMAT = "%Y-%m-%dT%H:%M:%S%z"
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


def _save(fig, path: Path) -> None:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _axes(ax, figsize):
    """The figure and axes to draw on: ``ax`` and its figure, or a new figure of ``figsize`` [in]."""
    if ax is not None:
        return ax.figure, ax
    return plt.subplots(figsize=figsize)


def save_plot(ax, path: Path) -> Path:
    """Save the figure that holds ``ax`` (an Axes or an array of them) as ``path`` and close it."""
    first = np.ravel(ax)[0]
    _save(first.figure, path)
    return path


def _clock_hours(result: StudyResult):
    times = result.day.times.tz_localize(None)
    return np.asarray((times - times.normalize()) / pd.Timedelta(hours=1))


def _mode_label(study: Study) -> str:
    return f"{study.mode} mode, {study.geometry} geometry, {study.date}"


def plot_power_curves(result: StudyResult, ax=None):
    """Flat, east, west and combined twofold power with the load (Shin et al. Fig. 6)."""
    series, hours, study = result.timeseries, _clock_hours(result), result.study
    daylight = series["p_tracker_w"].to_numpy() > 0
    fig, ax = _axes(ax, (8, 4.5))
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
    _draw_load(ax, hours, series, study)
    if daylight.any():
        ax.set_xlim(hours[daylight].min() - 0.5, hours[daylight].max() + 0.5)
    ax.set_xlabel(f"local clock time [h] ({study.site.timezone})")
    ax.set_ylabel("P_pv [W]")
    ax.set_title(f"{study.name}: power over the day ({_mode_label(study)})")
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3)
    return ax


def _load_label(study, load: float) -> str:
    """A sweep's load as a load: ``P_load 2 W``, or a profile with its mean and peak watts."""
    if study is None:
        return f"P_load {load:g} W"
    from foldopt.inputs.loads import load_text

    return load_text(study, load)


def _draw_load(ax, hours, series, study) -> None:
    """The load: a line at P_load, or a load profile's P_load(t) as its curve, labelled as a load."""
    from foldopt.inputs.loads import load_text

    if study.load_profile is None:
        ax.axhline(study.p_load, color="tab:red", lw=1, label=f"P_load = {study.p_load:.3g} W")
    else:
        ax.step(hours, series["p_load_w"], where="mid", color="tab:red", lw=1, label=load_text(study))


STATE_COLOURS = {"east": "tab:orange", "parallel": "tab:green", "west": "tab:purple", "series": "tab:brown"}


def plot_switching(result: StudyResult, ax=None):
    """Sub-panel curves and the connection switching chooses over the day (Shin et al. Fig. 9)."""
    series, hours, study = result.timeseries, _clock_hours(result), result.study
    fig, ax = _axes(ax, (8, 4.5))
    state = series["switch_state"].to_numpy()
    step = hours[1] - hours[0]
    starts = np.flatnonzero(np.r_[True, state[1:] != state[:-1]])
    for start, stop in zip(starts, np.r_[starts[1:], state.size], strict=True):
        if state[start] != "off":
            ax.axvspan(hours[start] - step / 2, hours[stop - 1] + step / 2, color=STATE_COLOURS[state[start]], alpha=0.12, lw=0)
    for name in ("east", "west", "parallel") + (("series",) if study.switch_series else ()):
        ax.plot(hours, series[f"p_{name}_w"], color=STATE_COLOURS[name], ls="--", label=name)
    ax.plot(hours, series["p_switching_w"], color="k", lw=2, label="switching (shaded: state chosen)")
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
    """t_solar versus fold angle, with flat and tracker levels (Shin et al. Fig. 12a)."""
    summary = result.summary.set_index("design")
    fig, ax = _axes(ax, (7, 4.5))
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
    return ax


def plot_comparison(result: StudyResult, ax=None):
    """t_solar of flat, optimal twofold and every tracker, gross and net (Shin et al. Fig. 12b)."""
    summary = result.summary.set_index("design")
    names = ["flat", "twofold"] + [d for d in summary.index if d.startswith("tracker") and not d.endswith("-net")]
    labels = ["flat", f"twofold\n{summary.loc['twofold', 'fold_angle_deg']:.1f}°"] + [
        (result.study.tracker.model if d == "tracker" else d.split(":", 1)[1]).replace("-", "-\n", 1)
        for d in names[2:]
    ]
    x = np.arange(len(names))
    gross = summary.loc[names, "t_solar_h"].to_numpy()
    net = np.array([summary.loc[f"{d}-net", "t_solar_h"] if f"{d}-net" in summary.index else np.nan for d in names])
    fig, ax = _axes(ax, (max(6, 1.1 * len(names) + 2), 4.5))
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
    """The tracker's net t_solar against its standby draw, and where twofold overtakes it."""
    table, break_even = result.standby
    study = result.study
    fig, ax = _axes(ax, (7, 4.5))
    ax.plot(table["standby_w"], table["t_solar_tracker_net_h"], color="0.4", label=f"{study.tracker.model} tracker, net")
    ax.axhline(table["t_solar_twofold_h"].iloc[0], color="tab:blue", label="optimal twofold (draws nothing)")
    if np.isfinite(break_even):
        ax.axvline(break_even, color="tab:red", ls="--", lw=1, label=f"break-even {break_even:.2f} W")
    ax.set_xlabel("tracker standby draw [W]")
    ax.set_ylabel("t_solar [h]")
    ax.set_title(f"{study.name}: when does the tracker's own draw hand the day to the twofold panel?", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return ax


def write_study(result: StudyResult, out: Path, overwrite: bool = False, command=None) -> Path:
    """Write a study's results folder: summary, sweep and time-series CSVs, plots, ``run.json``."""
    with staged_folder(out, overwrite) as folder:
        result.summary.to_csv(folder / "summary.csv", index=False, float_format=FLOAT_FORMAT)
        result.sweep.to_csv(folder / "sweep.csv", index=False, float_format=FLOAT_FORMAT)
        result.timeseries.to_csv(folder / "timeseries.csv", float_format=FLOAT_FORMAT, date_format=TIME_FORMAT)
        save_plot(plot_power_curves(result), folder / "power_curves.png")
        save_plot(plot_t_solar_vs_fold_angle(result), folder / "t_solar_vs_fold_angle.png")
        save_plot(plot_comparison(result), folder / "comparison.png")
        save_plot(plot_switching(result), folder / "switching.png")
        save_plot(plot_standby(result), folder / "tracker_standby.png")
        result.standby[0].to_csv(folder / "tracker_standby.csv", index=False, float_format=FLOAT_FORMAT)
        metadata = run_metadata(
                result.study,
                command,
                input_sha256=input_hash(result.study.model_dump(mode="json")),
                engine=result.engine,
                optimal_fold_angle_deg=result.optimal_fold_angle,
                near_optimal={key: value if np.isfinite(value) else None for key, value in result.near_optimal.items()},
                tracker_break_even_standby_w=result.standby[1] if np.isfinite(result.standby[1]) else None,
                # NaN (the load exceeds the flat panel's noon power) is not JSON: null instead.
                heuristic_fold_angle_deg=(
                    result.heuristic_fold_angle if np.isfinite(result.heuristic_fold_angle) else None
                ),
        )
        _write_json(folder / "run.json", metadata)
        write_html(folder, result.answer, STUDY_FIGURES, result.summary, "Designs compared (summary.csv)", metadata)
    return out


STUDY_FIGURES = ["power_curves.png", "t_solar_vs_fold_angle.png", "comparison.png", "switching.png",
                 "tracker_standby.png"]


def write_reproduction(result, out: Path, overwrite=False, command=None) -> Path:
    """Write one ``<name>.csv`` per reproduction table (:class:`foldopt.studies.reproduce.Reproduction`),
    ``report.html`` and ``run.json``."""
    with staged_folder(out, overwrite) as folder:
        for name, table in result.tables.items():
            table.to_csv(folder / f"{name}.csv", index=False, float_format=FLOAT_FORMAT)
        metadata = run_metadata(result.study, command, modes=["paper", "exact"], tables=list(result.tables),
                                engine=result.engine)
        _write_json(folder / "run.json", metadata)
        write_html(folder, result.answer, [], result.answer.designs, "Published and reproduced values (paper: Shin "
                   "et al.; paper mode: their formulas; exact mode: pvlib's physics)", metadata)
    return out


# --- Sweeps -------------------------------------------------------------------------------------


def _mean_pivot(table: pd.DataFrame, rows: str, columns: str, value: str) -> pd.DataFrame:
    return table.pivot_table(index=rows, columns=columns, values=value, aggfunc="mean")


def _others(table: pd.DataFrame, used: tuple[str, ...], varied: list[str]) -> str:
    rest = [name for name in varied if name not in used and name != "date"]
    return f" (mean over {', '.join(rest)})" if rest else ""


def _colours(values, diverging: bool) -> dict:
    """pcolormesh/scatter colours: red-blue around 0, symmetric over the finite ``values``, or viridis."""
    if not diverging:
        return {"cmap": "viridis"}
    finite = np.asarray(np.ma.filled(np.ma.masked_invalid(values), np.nan), dtype=float)
    finite = finite[np.isfinite(finite)]
    bound = max(float(np.abs(finite).max()) if finite.size else 1.0, 1e-9)
    return {"cmap": "RdBu", "vmin": -bound, "vmax": bound}


def plot_map(table: pd.DataFrame, x: str, y: str, value: str, title: str, label: str, diverging: bool,
             ax=None):
    """A heat map of ``value`` over ``x`` and ``y``, averaged over any other varied field."""
    grid = _mean_pivot(table, y, x, value)
    fig, ax = _axes(ax, (8, 5))
    data = np.ma.masked_invalid(grid.to_numpy(dtype=float))
    mesh = ax.pcolormesh(grid.columns, grid.index, data, shading="nearest", **_colours(data, diverging))
    ax.set_facecolor("0.85")
    ax.figure.colorbar(mesh, ax=ax, label=label)
    ax.set_xlabel(_AXIS_LABELS.get(x, x))
    ax.set_ylabel(_AXIS_LABELS.get(y, y))
    ax.set_title(title, fontsize=10)
    return ax


_AXIS_LABELS = {
    "latitude": "latitude [deg]",
    "p_load_w": "P_load [W]",
    "day_of_year": "day of year",
}


def plot_curves(table: pd.DataFrame, x: str, title: str, split: str | None = None, ax=None):
    """t_solar of flat, optimal twofold and tracker against ``x``.

    With ``split`` (a varied field of at most four values) each value gets its own line style;
    anything else that varies is averaged.
    """
    fig, ax = _axes(ax, (8, 4.5))
    colours = {"flat": "k", "twofold": "tab:blue", "tracker": "0.55"}
    styles = ["-", "--", ":", "-."]
    groups = [(None, table)] if split is None else list(table.groupby(split, sort=True))
    for (value, rows), style in zip(groups, styles, strict=False):
        for design, colour in colours.items():
            curve = rows[rows["design"] == design].groupby(x)["t_solar_h"].mean()
            name = "optimal twofold" if design == "twofold" else design
            label = name if split is None else f"{name}, {split} {value}"
            ax.plot(curve.index, curve.to_numpy(), color=colour, ls=style, lw=2 if design == "twofold" else 1.3,
                    label=label)
    ax.set_xlabel(_AXIS_LABELS.get(x, x))
    ax.set_ylabel("t_solar [h]")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=1 if split is None else 2)
    return ax


def sweep_plots(table: pd.DataFrame, varied: list[str], folder: Path, name: str) -> list[str]:
    """Write the plots that the varied fields call for; return their file names."""
    twofold = table[table["design"] == "twofold"]
    written = []
    maps = [("latitude", "p_load_w", "latitude_load"), ("day_of_year", "latitude", "day_latitude")]
    for x, y, stem in maps:
        if x in varied and y in varied:
            other = _others(table, (x, y, "day_of_year"), varied)
            save_plot(plot_map(twofold, x, y, "gain_vs_flat_pct",
                               f"{name}: t_solar gain of the optimal twofold panel over flat{other}",
                               "gain over flat [%] (grey: flat never runs)", diverging=True),
                      folder / f"gain_map_{stem}.png")
            save_plot(plot_map(twofold, x, y, "fold_angle_deg", f"{name}: optimal fold angle{other}",
                               "fold angle Θ [deg] (180 = flat)", diverging=False), folder / f"fold_angle_map_{stem}.png")
            written += [f"gain_map_{stem}.png", f"fold_angle_map_{stem}.png"]
    for x, stem in (("day_of_year", "annual_t_solar"), ("p_load_w", "t_solar_vs_load"), ("latitude", "t_solar_vs_latitude")):
        if x in varied:
            rest = [v for v in varied if v not in (x, "date", "day_of_year")]
            split = next((v for v in rest if table[v].nunique() <= 4), None)
            used = (x, "day_of_year") + ((split,) if split else ())
            save_plot(plot_curves(table, x, f"{name}: t_solar of flat, optimal twofold and tracker"
                                            f"{_others(table, used, varied)}", split), folder / f"{stem}.png")
            written.append(f"{stem}.png")
    return written


def input_hash(data) -> str:
    """SHA-256 of the canonical JSON of a study's inputs."""
    canonical = json.dumps(data, sort_keys=True, default=str, separators=(",", ":"))
    return hashlib.sha256(canonical.encode()).hexdigest()


def write_sweep(result, out: Path, overwrite: bool = False, command=None) -> Path:
    """Write a sweep's folder: ``results.csv`` (a row per case x design), plots and ``run.json``."""
    plan = result.plan
    with staged_folder(out, overwrite) as folder:
        result.table.to_csv(folder / "results.csv", index=False, float_format=FLOAT_FORMAT)
        plots = sweep_plots(result.table, result.varied, folder, plan.base.name)
        if "date" in result.varied or "day_of_year" in result.varied:
            plots += annual_outputs(result, folder, plan.base.name)
        metadata = run_metadata(
            plan.base.resolved(),
            command,
            axes={path: [str(v) if hasattr(v, "isoformat") else v for v in values] for path, values in plan.axes},
            cases=plan.n_cases,
            plots=plots,
            input_sha256=input_hash({"study": plan.data, "axes": plan.axes}),
            engine=result.engine,
            **({"weather_light": result.weather_light} if result.weather_light else {}),
        )
        _write_json(folder / "run.json", metadata)
        answer = result.answer
        if answer.kind == "annual":
            # The year's summary per case and design, not every day's rows (results.csv has them).
            table = annual_summary(result.table, _annual_cases(result))
            title = "The year per case and design (annual_summary.csv)"
        else:
            table, title = result.table, "Every case and design (results.csv; click a header to sort)"
        write_html(folder, answer, [name for name in plots if name.endswith(".png")], table, title, metadata,
                   designs=answer.kind == "annual")
    return out


def plot_sizing(table: pd.DataFrame, best: pd.DataFrame, title: str, ax=None):
    """Lifetime net benefit against panel area for flat and twofold (Shin et al. Fig. 3a)."""
    fig, ax = _axes(ax, (8, 4.5))
    for design, colour in (("flat", "k"), ("twofold", "tab:blue")):
        rows = table[table["design"] == design]
        ax.plot(rows["area_m2"], rows["net_benefit_usd"], color=colour, label=design)
        top = best[best["design"] == design].iloc[0]
        ax.plot(top["area_m2"], top["net_benefit_usd"], "o", color=colour)
        ax.annotate(f"{top['area_m2']:.3f} m², {top['t_solar_h']:.2f} h", (top["area_m2"], top["net_benefit_usd"]),
                    textcoords="offset points", xytext=(5, 5), fontsize=8)
    ax.axhline(0, color="0.6", lw=0.8)
    ax.set_xlabel("panel area [m²]")
    ax.set_ylabel("lifetime net benefit [$]")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return ax


def write_sizing(result, out: Path, overwrite: bool = False, command=None) -> Path:
    """Write ``sizing.csv``, ``sizing_best.csv``, the net-benefit plot, ``report.html`` and
    ``run.json`` (with the sizing's parameters: costs, price, lifetime) of a
    :class:`foldopt.studies.sizing.SizingResult`."""
    study, table, best = result.study, result.table, result.best
    with staged_folder(out, overwrite) as folder:
        table.to_csv(folder / "sizing.csv", index=False, float_format=FLOAT_FORMAT)
        best.to_csv(folder / "sizing_best.csv", index=False, float_format=FLOAT_FORMAT)
        save_plot(plot_sizing(table, best, f"{study.name}: panel sizing (Shin et al. Sec. IV-A)"),
                  folder / "net_benefit_vs_area.png")
        metadata = run_metadata(study.resolved(), command, sizing=result.parameters,
                                input_sha256=input_hash(study.model_dump(mode="json")))
        _write_json(folder / "run.json", metadata)
        write_html(folder, result.answer, ["net_benefit_vs_area.png"], table, "Every area (sizing.csv)", metadata)
    return out


# --- Annual studies -----------------------------------------------------------------------------

THRESHOLDS_H = (2, 4, 6, 8, 10, 12)


def annual_summary(table: pd.DataFrame, cases=("site_name", "latitude", "longitude", "p_load_w")) -> pd.DataFrame:
    """Per case (``cases``: the columns that tell one case from another, but the date) and design:

    - daily t_solar: mean, p10, p50, p90 and minimum, the days reaching each of
      :data:`THRESHOLDS_H`, and monthly means [h];
    - the totals over the days: energy harvested, served and wasted [Wh] and plane-of-array
      irradiation [kWh/m^2];
    - each design's gain over the case's flat panel and share of its tracker, in energy
      harvested and in mean daily t_solar (served energy is the load times t_solar, so it moves
      with the time) [%].
    """
    table = table.assign(month=pd.to_datetime(table["date"]).dt.month)
    cases = [c for c in cases if c in table]
    keys = cases + ["design"]
    rows = []
    for key, group in table.groupby(keys, sort=False):
        hours = group["t_solar_h"]
        row = dict(zip(keys, key if isinstance(key, tuple) else (key,), strict=True))
        row.update(days=len(group), fold_angle_deg=group["fold_angle_deg"].iloc[0], mean_t_solar_h=hours.mean(),
                   energy_harvested_wh=group["energy_harvested_wh"].sum(), energy_served_wh=group["energy_served_wh"].sum(),
                   energy_wasted_wh=group["energy_wasted_wh"].sum())
        if "poa_kwh_m2" in group:
            row["poa_kwh_m2"] = group["poa_kwh_m2"].sum()
        row.update(p10_t_solar_h=hours.quantile(0.1), p50_t_solar_h=hours.median(), p90_t_solar_h=hours.quantile(0.9),
                   min_t_solar_h=hours.min())
        row.update({f"days_ge_{x}h": int((hours >= x).sum()) for x in THRESHOLDS_H})
        row.update({f"month_{m:02d}_mean_t_solar_h": v for m, v in group.groupby("month")["t_solar_h"].mean().items()})
        rows.append(row)
    summary = pd.DataFrame(rows)
    for reference, gain in (("flat", "gain_vs_flat_pct"), ("tracker", "pct_of_tracker")):
        base = summary[summary["design"] == reference].set_index(cases)[["energy_harvested_wh", "mean_t_solar_h"]]
        matched = base.reindex(pd.MultiIndex.from_frame(summary[cases]) if len(cases) > 1 else summary[cases[0]])
        energy = relative_to(summary["energy_harvested_wh"], matched["energy_harvested_wh"].to_numpy())
        time = relative_to(summary["mean_t_solar_h"], matched["mean_t_solar_h"].to_numpy())
        summary[f"energy_{gain}"] = (energy - 1.0) * 100.0 if reference == "flat" else energy * 100.0
        summary[gain] = (time - 1.0) * 100.0 if reference == "flat" else time * 100.0
    return summary


def plot_annual_fold_angles(by_angle: pd.DataFrame, title: str, study=None, ax=None):
    """The objective and the mean daily t_solar of one fold angle kept all year, per load."""
    fig, ax = _axes(ax, (7, 4.5))
    for (load, rows), colour in zip(by_angle.groupby("p_load_w"), plt.cm.viridis(np.linspace(0, 0.85, 8)),
                                    strict=False):
        ax.plot(rows["fold_angle_deg"], rows["mean_t_solar_h"], color=colour, label=f"mean, {_load_label(study, load)}")
        ax.plot(rows["fold_angle_deg"], rows["objective_h"], color=colour, ls="--", lw=1, label="objective")
        chosen = rows[rows["chosen"]]
        ax.plot(chosen["fold_angle_deg"], chosen["objective_h"], "o", color=colour)
    ax.set_xlabel("fold angle Θ kept all year [deg] (180 = flat)")
    ax.set_ylabel("daily t_solar [h]")
    ax.set_xlim(0, 180)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return ax


MONTH_NAMES = ("J", "F", "M", "A", "M", "J", "J", "A", "S", "O", "N", "D")


def plot_monthly(table: pd.DataFrame, title: str, loads_at_most: int = 4, axes=None, study=None):
    """Monthly energy harvested and mean daily t_solar of every design, side by side, a row per
    load (the first case's site). ``axes``: a (loads, 2) array of Axes to draw on; returns it."""
    table = table.assign(month=pd.to_datetime(table["date"]).dt.month)
    first = table.iloc[0]
    for column in ("site_name", "latitude", "longitude"):
        if column in table:
            table = table[table[column] == first[column]]
    loads = sorted(table["p_load_w"].unique())[:loads_at_most]
    designs = [d for d in ("flat", "twofold", "tracker", "tracker-net") if d in set(table["design"])]
    colours = {"flat": "0.35", "twofold": "tab:blue", "tracker": "0.7", "tracker-net": "tab:orange"}
    if axes is None:
        _, axes = plt.subplots(len(loads), 2, figsize=(11, 3.2 * len(loads)), squeeze=False)
    width = 0.8 / len(designs)
    for (energy_ax, time_ax), load in zip(axes, loads, strict=True):
        rows = table[table["p_load_w"] == load]
        for i, design in enumerate(designs):
            monthly = rows[rows["design"] == design].groupby("month")
            x = np.asarray(monthly.size().index) + (i - (len(designs) - 1) / 2) * width
            energy_ax.bar(x, monthly["energy_harvested_wh"].sum() / 1000.0, width, color=colours[design], label=design)
            time_ax.bar(x, monthly["t_solar_h"].mean(), width, color=colours[design], label=design)
        energy_ax.set_ylabel("energy harvested [kWh]")
        time_ax.set_ylabel(f"mean daily t_solar [h]\n{_load_label(study, load)}", fontsize=8)
        for ax in (energy_ax, time_ax):
            ax.set_xticks(range(1, 13), MONTH_NAMES)
            ax.grid(alpha=0.3, axis="y")
    axes[0, 0].legend(fontsize=8)
    axes[0, 0].set_title("energy harvested per month", fontsize=10)
    axes[0, 1].set_title("mean daily t_solar per month", fontsize=10)
    axes[0, 0].figure.suptitle(title, fontsize=10)
    return axes


def plot_distribution(table: pd.DataFrame, title: str, ax=None, study=None):
    """Daily t_solar of each design as box plots, one group per load."""
    designs = [d for d in ("flat", "twofold", "tracker", "tracker-net") if d in set(table["design"])]
    loads = sorted(table["p_load_w"].unique())
    fig, ax = _axes(ax, (max(6, 2.2 * len(loads) + 2), 4.5))
    width = 0.8 / len(designs)
    colours = {"flat": "0.35", "twofold": "tab:blue", "tracker": "0.7", "tracker-net": "tab:orange"}
    for i, design in enumerate(designs):
        data = [table[(table.design == design) & (table.p_load_w == load)]["t_solar_h"].to_numpy() for load in loads]
        positions = np.arange(len(loads)) + (i - (len(designs) - 1) / 2) * width
        box = ax.boxplot(data, positions=positions, widths=width * 0.9, patch_artist=True, showfliers=False)
        for patch in box["boxes"]:
            patch.set_facecolor(colours[design])
        ax.plot([], [], color=colours[design], lw=6, label=design)
    ax.set_xticks(np.arange(len(loads)), [_load_label(study, load) for load in loads], fontsize=7)
    ax.set_ylabel("daily t_solar [h]")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=8)
    return ax


def plot_day_hour(extras: dict, key: str, title: str, label: str, ax=None):
    """A day x hour heat map of one annual series (twofold power, or the switch state)."""
    values = np.asarray(extras[key], dtype=float)
    days = np.arange(1, values.shape[0] + 1)
    fig, ax = _axes(ax, (9, 4.5))
    if key == "switch_state":
        cmap = matplotlib.colors.ListedColormap(["0.15", "tab:orange", "tab:purple", "tab:green", "tab:brown"])
        mesh = ax.pcolormesh(days, extras["hours"], values.T, cmap=cmap, vmin=-1.5, vmax=3.5, shading="nearest")
        bar = ax.figure.colorbar(mesh, ax=ax, ticks=range(-1, 4))
        bar.ax.set_yticklabels(["off", *SWITCH_STATES])
    else:
        mesh = ax.pcolormesh(days, extras["hours"], values.T, cmap="magma", shading="nearest")
        ax.figure.colorbar(mesh, ax=ax, label=label)
    ax.set_xlabel("day of the study")
    ax.set_ylabel("local clock time [h]")
    ax.set_title(title, fontsize=10)
    return ax


def _annual_cases(result) -> list[str]:
    """A case of an annual study: its site and load, and any other field the plan varies but the date."""
    others = [c for c in result.varied if c not in ("date", "day_of_year", "site_name", "latitude", "p_load_w")]
    return ["site_name", "latitude", *others, "p_load_w"]


def annual_outputs(result, folder: Path, name: str) -> list[str]:
    """``annual_summary.csv`` and the annual plots of a study that varies the date."""
    table = result.table
    annual_summary(table, _annual_cases(result)).to_csv(folder / "annual_summary.csv", index=False,
                                                         float_format=FLOAT_FORMAT)
    study = result.plan.base
    save_plot(plot_distribution(table, f"{name}: daily t_solar per design", study=study),
              folder / "daily_t_solar_distribution.png")
    save_plot(plot_monthly(table, f"{name}: every design month by month", study=study),
              folder / "monthly_energy_t_solar.png")
    written = ["annual_summary.csv", "daily_t_solar_distribution.png", "monthly_energy_t_solar.png"]
    if result.extras:
        by_angle = result.extras["by_angle"]
        by_angle.to_csv(folder / "annual_fold_angles.csv", index=False, float_format=FLOAT_FORMAT)
        save_plot(plot_annual_fold_angles(by_angle, f"{name}: the year at each fold angle "
                                                    f"({result.plan.base.objective.statistic})", study),
                  folder / "annual_t_solar_vs_fold_angle.png")
        written += ["annual_fold_angles.csv", "annual_t_solar_vs_fold_angle.png"]
        angle = result.extras["fold_angle"]
        save_plot(plot_day_hour(result.extras, "p_twofold_w", f"{name}: twofold power at {angle:g}° (first load)",
                                "P_pv [W]"), folder / "day_hour_power.png")
        save_plot(plot_day_hour(result.extras, "switch_state", f"{name}: connection the switch chooses at {angle:g}°",
                                ""), folder / "day_hour_switch_state.png")
        written += ["day_hour_power.png", "day_hour_switch_state.png"]
    if "annual_objective" in result.extras:
        result.extras["annual_objective"].to_csv(folder / "annual_objective.csv", index=False,
                                                 float_format=FLOAT_FORMAT)
        written.append("annual_objective.csv")
    if "refold_value" in result.extras:
        result.extras["refold_value"].to_csv(folder / "refold_value.csv", index=False, float_format=FLOAT_FORMAT)
        result.extras["refold_schedule"].to_csv(folder / "refold_schedule.csv", index=False,
                                                float_format=FLOAT_FORMAT)
        save_plot(plot_refold_value(result.extras["refold_value"], f"{name}: what each re-fold visit is worth",
                                    result.plan.base), folder / "refold_value.png")
        written += ["refold_value.csv", "refold_schedule.csv", "refold_value.png"]
    return written


def plot_refold_value(values: pd.DataFrame, title: str, study=None, ax=None):
    """The objective of the best schedule of k fold settings a year against k, per load (the first
    site's; ``study`` names a load profile's loads), beside the flat panel and the tracker
    (:func:`foldopt.studies.sweeps.refold_tables`)."""
    fig, ax = _axes(ax, (7, 4.5))
    first = values[(values["latitude"] == values["latitude"].iloc[0])
                   & (values["longitude"] == values["longitude"].iloc[0])]
    for (load, rows), colour in zip(first.groupby("p_load_w"), plt.rcParams["axes.prop_cycle"].by_key()["color"],
                                    strict=False):
        ax.plot(rows["settings"], rows["objective_h"], "o-", color=colour, label=f"twofold, {_load_label(study, load)}")
        ax.axhline(rows["objective_flat_h"].iloc[0], color=colour, ls="--", lw=1)
        ax.axhline(rows["objective_tracker_h"].iloc[0], color=colour, ls=":", lw=1)
    ax.plot([], [], "k--", lw=1, label="flat panel")
    ax.plot([], [], "k:", lw=1, label="tracker")
    ax.set_xlabel("fold settings a year (1 = one fixed angle)")
    ax.set_ylabel(f"{values['objective'].iloc[0]} daily t_solar [h]")
    ax.set_xticks(sorted(first["settings"].unique()))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    return ax


# --- Maps: many sites (foldopt.studies.worldmap) --------------------------------------------------------

#: The map figures: column, file, what it shows, colour bar label, diverging colours.
MAP_FIGURES = (
    ("recommended_fold_angle_deg", "map_fold_angle.png", "recommended fold angle (centre of the near-optimal range)",
     "fold angle Θ [deg] (180 = flat)", False),
    ("gain_vs_flat_pct", "map_gain_vs_flat.png", "t_solar gain of the twofold panel over flat",
     "gain over flat [%]", True),
    ("pct_of_tracker", "map_pct_of_tracker.png", "twofold panel's t_solar as a share of the tracker's",
     "share of the tracker [%]", False),
)


def _lattice(values) -> np.ndarray | None:
    """The regular lattice that sorted ``values`` sit on (gaps allowed, e.g. land only), or None."""
    values = np.unique(values)
    if values.size < 2:
        return None
    step = np.diff(values).min()
    steps = (values - values[0]) / step
    if not np.allclose(steps, np.round(steps), atol=1e-6):
        return None
    return values[0] + step * np.arange(int(round(steps[-1])) + 1)


def _grid_axes(sites: pd.DataFrame):
    """The latitude and longitude lattices of a grid of sites, or None for named sites."""
    if (sites["site_name"].astype(str) != "").any() or len(sites) < 4:
        return None
    lats, lons = _lattice(sites["latitude"]), _lattice(sites["longitude"])
    return None if lats is None or lons is None else (lats, lons)


def plot_world_map(rows: pd.DataFrame, value: str, title: str, label: str, diverging: bool, ax=None):
    """One value per site on a longitude x latitude map with coastlines (:func:`foldopt.inputs.land.draw_coastlines`):
    cells for a grid of sites, dots for named sites."""
    from foldopt.inputs.land import draw_coastlines

    fig, ax = _axes(ax, (10, 5.2))
    values = rows[value].to_numpy(dtype=float)
    colours = _colours(values, diverging)
    axes = _grid_axes(rows)
    if axes is not None:
        lats, lons = axes
        grid = rows.pivot_table(index="latitude", columns="longitude", values=value, aggfunc="mean")
        grid = grid.reindex(index=lats, columns=lons, method="nearest", tolerance=1e-6)
        mesh = ax.pcolormesh(lons, lats, np.ma.masked_invalid(grid.to_numpy(dtype=float)), shading="nearest",
                             **colours)
    else:
        mesh = ax.scatter(rows["longitude"], rows["latitude"], c=values, s=40, edgecolors="k", linewidths=0.4,
                          **colours)
    coast = draw_coastlines(ax)
    ax.set_xlim(-180, 180)
    ax.set_ylim(-90, 90)
    ax.set_aspect("equal")
    ax.set_facecolor("0.9")
    ax.figure.colorbar(mesh, ax=ax, label=label, shrink=0.8)
    ax.set_xlabel("longitude [deg]")
    ax.set_ylabel("latitude [deg]")
    ax.set_title(title + ("" if coast else " (no coastlines: pip install global-land-mask)"), fontsize=10)
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
    site's flat peak (loads given in watts are a different share at each site: binned to 0.05)."""
    rows = table[table["period"] == period]
    share = rows["p_load_fraction"].round(9) if relative else (rows["p_load_fraction"] / 0.05).round() * 0.05
    grid = rows.assign(share=share).pivot_table(index="share", columns="latitude", values="gain_vs_flat_pct",
                                                aggfunc="median")
    fig, ax = _axes(ax, (8, 4.5))
    data = np.ma.masked_invalid(grid.to_numpy(dtype=float))
    mesh = ax.pcolormesh(_edges(grid.columns, 5.0), _edges(grid.index, 0.05), data, **_colours(data, True))
    if data.count() > 3 and grid.shape[0] > 1 and grid.shape[1] > 1:
        ax.contour(grid.columns, grid.index, data.filled(np.nan), levels=[1.0], colors="k", linewidths=0.8)
    ax.set_facecolor("0.85")
    ax.figure.colorbar(mesh, ax=ax, label="median gain over flat [%]" + (" (contour: +1 %)" if grid.shape[0] > 1 else ""))
    ax.set_xlabel("latitude [deg]")
    ax.set_ylabel("P_load / flat peak [-]" + ("" if relative else " (bins of 0.05)"))
    ax.set_title(title, fontsize=10)
    return ax


def map_figures(table: pd.DataFrame, folder: Path, name: str, relative: bool, load_index: int = 0,
                period: str = "year") -> list[str]:
    """Write the maps of one load (by its index among the map's loads, fractions of the flat peak
    where ``relative``) and period, and the latitude x load chart; return the file names. Each file
    is written atomically."""
    loads = table["p_load_fraction"] if relative else table["p_load_w"]
    values = np.unique(loads.round(12))
    shown = table[(np.isclose(loads, values[load_index])) & (table["period"] == period)]
    unit = "of the flat peak" if relative else "W"
    what = f"P_load {values[load_index]:g} {unit}, {period}"
    written = []
    for value, file, description, label, diverging in MAP_FIGURES:
        _atomic_figure(folder / file, plot_world_map(shown, value, f"{name}: {description} ({what})", label,
                                                     diverging))
        written.append(file)
    _atomic_figure(folder / "latitude_load_gain.png", plot_latitude_load(
        table, period, relative, f"{name}: where folding pays ({period}, median over longitudes)"))
    return written + ["latitude_load_gain.png"]


def _atomic_figure(path: Path, ax) -> None:
    """:func:`save_plot` under a temporary name, then renamed into ``path``."""
    write_atomically(path, lambda temporary: save_plot(ax, temporary))


def write_map_report(result, figures: list[str], answer) -> Path:
    """``report.html`` of a map's folder: the question, the answer, the maps and the year's rows."""
    metadata = json.loads((result.out / "run.json").read_text())
    year = result.table[result.table["period"] == "year"]
    return write_html(result.out, answer, figures, year, "The year per site and load (map.csv has every season)",
                      metadata)
