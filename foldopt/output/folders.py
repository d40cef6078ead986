"""Results folders: what each kind of result writes, a view of its answer
(:mod:`foldopt.studies.answer`) deciding nothing. A folder is built in a staging folder and
renamed into place whole (:func:`foldopt.files.staged_folder`); a map's folder, which its cluster
run fills part by part, gets its figures and ``report.html`` one atomic file at a time."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from foldopt.files import staged_folder
from foldopt.output.figures import day, storage, world, write_figure
from foldopt.output.html import write_html
from foldopt.output.provenance import input_hash, run_metadata, write_run_json
from foldopt.tables import write_csv
from foldopt.studies.annual import annual_cases, annual_summary
from foldopt.studies.day import StudyResult
from foldopt.studies.horizon_paths import sun_paths
from foldopt.studies.series import parquet_options, series_file


def _finite_or_none(value: float) -> float | None:
    # NaN (e.g. no heuristic angle: the load exceeds the flat panel's noon power) is not JSON.
    return value if np.isfinite(value) else None


def _horizon_figure(study, dates, folder: Path, name: str) -> list[str]:
    """``horizon_sun_paths.png`` where the study's site has a horizon."""
    paths = sun_paths(study, dates)
    return [] if paths is None else [write_figure(folder, "horizon_sun_paths.png", paths, name)]


def write_study(result: StudyResult, out: Path, overwrite: bool = False, command=None) -> Path:
    """Write a day's results folder: ``summary.csv``, ``sweep.csv``, ``timeseries.csv``,
    ``tracker_standby.csv``, the day's figures (:data:`foldopt.output.figures.day.FIGURES`),
    ``run.json`` and ``report.html``; with a buffer also ``storage_capacity.csv``,
    ``storage_sizing.csv`` (with a target) and :data:`foldopt.output.figures.storage.FIGURES`;
    with costs, ``design_space.csv`` and ``design_space.png``.

    Parameters
    ----------
    result : foldopt.StudyResult
    out : pathlib.Path
        The folder; one that exists is replaced only with ``overwrite`` (and only if foldopt wrote it).
    overwrite : bool, default False
    command : list of str, optional
        What ``run.json`` records as the command; default ``sys.argv``.

    Returns
    -------
    pathlib.Path
        ``out``.
    """
    with staged_folder(out, overwrite) as folder:
        write_csv(result.summary, folder / "summary.csv")
        write_csv(result.sweep, folder / "sweep.csv")
        write_csv(result.timeseries, folder / "timeseries.csv", index=True)
        figures = [write_figure(folder, file, result) for file in day.FIGURES]
        if result.storage is not None:
            write_csv(result.storage.sizing.curve, folder / "storage_capacity.csv")
            if len(result.storage.sizing.table):
                write_csv(result.storage.sizing.table, folder / "storage_sizing.csv")
            figures += [write_figure(folder, file, result) for file in storage.FIGURES]
            figures += _design_space(result.storage.design_space, folder, result.study)[1:]
        figures += _horizon_figure(result.study, [result.study.date], folder, result.study.name)
        write_csv(result.standby[0], folder / "tracker_standby.csv")
        metadata = run_metadata(
            result.study,
            command,
            input_sha256=input_hash(result.study.data()),
            engine=result.engine,
            fold_angle_twofold_deg=result.optimal_fold_angle,
            near_optimal={
                key: _finite_or_none(value) for key, value in result.near_optimal.items()
            },
            break_even_standby_tracker_w=_finite_or_none(result.standby[1]),
            fold_angle_twofold_heuristic_deg=_finite_or_none(result.heuristic_fold_angle),
        )
        write_run_json(folder, metadata)
        write_html(
            folder,
            result.answer,
            figures,
            result.summary,
            "Designs compared (summary.csv)",
            metadata,
        )
    return out


def write_reproduction(result, out: Path, overwrite: bool = False, command=None) -> Path:
    """Write the reproduction's folder: one ``<name>.csv`` per table, ``run.json`` and ``report.html``.

    Parameters
    ----------
    result : foldopt.Reproduction
        Its ``tables``: name -> the published values beside foldopt's, in paper and exact modes.
    out : pathlib.Path
    overwrite : bool, default False
    command : list of str, optional
        What ``run.json`` records as the command; default ``sys.argv``.

    Returns
    -------
    pathlib.Path
        ``out``.
    """
    with staged_folder(out, overwrite) as folder:
        for name, table in result.tables.items():
            write_csv(table, folder / f"{name}.csv")
        metadata = run_metadata(
            result.study,
            command,
            modes=["paper", "exact"],
            tables=list(result.tables),
            engine=result.engine,
        )
        write_run_json(folder, metadata)
        write_html(
            folder,
            result.answer,
            [],
            result.answer.designs,
            "Published and reproduced values (paper: Shin "
            "et al.; paper mode: their formulas; exact mode: pvlib's physics)",
            metadata,
        )
    return out


def _others(used: tuple[str, ...], varied: list[str]) -> str:
    """A title's note of the varied fields a figure averages over."""
    rest = [name for name in varied if name not in used and name != "date"]
    return f" (mean over {', '.join(rest)})" if rest else ""


def _sweep_plots(table: pd.DataFrame, varied: list[str], folder: Path, name: str) -> list[str]:
    """Write the figures the varied fields call for (:data:`foldopt.output.figures.sweep.FIGURES`);
    return their file names."""
    twofold = table[table["design"] == "twofold"]
    written = []
    for x, y, stem in (
        ("latitude", "p_load_w", "latitude_load"),
        ("dayofyear", "latitude", "day_latitude"),
    ):
        if x in varied and y in varied:
            other = _others((x, y, "dayofyear"), varied)
            written += [
                write_figure(
                    folder,
                    f"gain_map_{stem}.png",
                    twofold,
                    x,
                    y,
                    "gain_vs_flat_pct",
                    f"{name}: t_solar gain of the optimal twofold panel over flat{other}",
                    "gain over flat [%] (grey: flat never runs)",
                    diverging=True,
                ),
                write_figure(
                    folder,
                    f"fold_angle_map_{stem}.png",
                    twofold,
                    x,
                    y,
                    "fold_angle_deg",
                    f"{name}: optimal fold angle{other}",
                    "fold angle Θ [deg] (180 = flat)",
                    diverging=False,
                ),
            ]
    for x, stem in (
        ("dayofyear", "annual_t_solar"),
        ("p_load_w", "t_solar_vs_load"),
        ("latitude", "t_solar_vs_latitude"),
    ):
        if x in varied:
            rest = [v for v in varied if v not in (x, "date", "dayofyear")]
            split = next((v for v in rest if table[v].nunique() <= 4), None)
            used = (x, "dayofyear") + ((split,) if split else ())
            written.append(
                write_figure(
                    folder,
                    f"{stem}.png",
                    table,
                    x,
                    f"{name}: t_solar of flat, optimal twofold and tracker{_others(used, varied)}",
                    split,
                )
            )
    return written


def _annual_outputs(result, folder: Path, name: str) -> list[str]:
    """Write ``annual_summary.csv``, the annual group's tables and the annual figures
    (:data:`foldopt.output.figures.annual.FIGURES`) of a sweep that varies the date; return the
    file names."""
    table, study = result.table, result.plan.base
    write_csv(annual_summary(table, annual_cases(result)), folder / "annual_summary.csv")
    written = [
        "annual_summary.csv",
        write_figure(
            folder,
            "daily_t_solar_distribution.png",
            table,
            f"{name}: daily t_solar per design",
            study=study,
        ),
        write_figure(
            folder,
            "monthly_energy_t_solar.png",
            table,
            f"{name}: every design month by month",
            study=study,
        ),
    ]
    if result.timeseries is not None:
        written.append(write_series(result.timeseries, folder))
    extras = result.extras
    if extras:
        write_csv(extras["by_angle"], folder / "annual_fold_angles.csv")
        angle = extras["fold_angle"]
        written += [
            "annual_fold_angles.csv",
            write_figure(
                folder,
                "annual_t_solar_vs_fold_angle.png",
                extras["by_angle"],
                f"{name}: the year at each fold angle ({study.objective.statistic})",
                study,
            ),
            write_figure(
                folder,
                "day_hour_power.png",
                extras,
                "p_twofold_w",
                f"{name}: twofold power at {angle:g}° (first load)",
                "P_pv [W]",
            ),
            write_figure(
                folder,
                "day_hour_switch_state.png",
                extras,
                "switch_state",
                f"{name}: connection the switch chooses at {angle:g}°",
                "",
            ),
        ]
    if "annual_objective" in extras:
        write_csv(extras["annual_objective"], folder / "annual_objective.csv")
        written.append("annual_objective.csv")
    for file in ("storage_annual.csv", "storage_years.csv", "storage_monthly.csv"):
        if file.removesuffix(".csv") in extras:
            write_csv(extras[file.removesuffix(".csv")], folder / file)
            written.append(file)
    written += _design_space(extras.get("design_space"), folder, study)
    if "storage_years" in extras and extras["storage_years"]["year"].nunique() > 1:
        written.append(
            write_figure(
                folder,
                "storage_years.png",
                extras["storage_years"],
                f"{name}: powered time with the buffer, year by year",
                study=study,
            )
        )
    if "weather_sample" in extras:
        kind = {
            "measured": "measured minutes",
            "smooth": "the file's hours on the study's steps",
            "members": "a cloud ensemble's members",
        }[extras["weather_sample"]["kind"]]
        written.append(
            write_figure(
                folder,
                "weather_minutes.png",
                extras["weather_sample"],
                f"{name}: {kind}, the day most variable within its hours",
            )
        )
    if "t_solar_members_p10_h" in table:
        written.append(
            write_figure(
                folder,
                "ensemble_t_solar.png",
                table,
                f"{name}: daily t_solar over the cloud ensemble's members",
                study=study,
            )
        )
    if "refold_value" in extras:
        write_csv(extras["refold_value"], folder / "refold_value.csv")
        write_csv(extras["refold_schedule"], folder / "refold_schedule.csv")
        written += [
            "refold_value.csv",
            "refold_schedule.csv",
            write_figure(
                folder,
                "refold_value.png",
                extras["refold_value"],
                f"{name}: what each re-fold visit is worth",
                study,
            ),
        ]
    return written


def _design_space(space, folder: Path, study) -> list[str]:
    """The least-cost search's ``design_space.csv`` and ``design_space.png``, where the study has
    costs; the files written, the table first."""
    if space is None:
        return []
    write_csv(space, folder / "design_space.csv")
    title = f"{study.name}: the smallest buffer meeting the target against the panel's area"
    return ["design_space.csv", write_figure(folder, "design_space.png", space, title, study.costs)]


def write_series(series: pd.DataFrame, folder: Path) -> str:
    """Write a study's series over many days as ``timeseries.csv``, or ``timeseries.parquet``
    (pyarrow) above :data:`foldopt.studies.series.PARQUET_ROWS` rows; return the file's name."""
    name = series_file(series)
    if name.endswith(".parquet"):
        series.to_parquet(folder / name, engine="pyarrow", **parquet_options(series))
    else:
        write_csv(series, folder / name, index=True)
    return name


def write_sweep(result, out: Path, overwrite: bool = False, command=None) -> Path:
    """Write a sweep's folder: ``results.csv`` (a row per case and design), the figures its varied
    fields call for, an annual study's tables and figures, ``run.json`` and ``report.html``.

    Parameters
    ----------
    result : foldopt.SweepResult
    out : pathlib.Path
    overwrite : bool, default False
    command : list of str, optional
        What ``run.json`` records as the command; default ``sys.argv``.

    Returns
    -------
    pathlib.Path
        ``out``.
    """
    plan = result.plan
    with staged_folder(out, overwrite) as folder:
        write_csv(result.table, folder / "results.csv")
        plots = _sweep_plots(result.table, result.varied, folder, plan.base.name)
        # An annual objective's group (a weather file's days, one of them or many) writes its
        # tables, as a sweep of dates does: what the answer says of it, its buffer's too.
        annual = "date" in result.varied or "dayofyear" in result.varied
        if annual or result.answer.kind == "annual":
            plots += _annual_outputs(result, folder, plan.base.name)
        plots += _horizon_figure(
            plan.base, dict(plan.axes).get("date", (plan.base.date,)), folder, plan.base.name
        )
        metadata = run_metadata(
            plan.base,
            command,
            axes={
                path: [str(v) if hasattr(v, "isoformat") else v for v in values]
                for path, values in plan.axes
            },
            cases=plan.n_cases,
            plots=plots,
            input_sha256=input_hash({"study": plan.data, "axes": plan.axes}),
            engine=result.engine,
            **({"weather_light": result.weather_light} if result.weather_light else {}),
        )
        write_run_json(folder, metadata)
        answer = result.answer
        if answer.kind == "annual":
            # The year's summary per case and design, not every day's rows (results.csv has them).
            table = annual_summary(result.table, annual_cases(result))
            title = "The year per case and design (annual_summary.csv)"
        else:
            table, title = (
                result.table,
                "Every case and design (results.csv; click a header to sort)",
            )
        write_html(
            folder,
            answer,
            [name for name in plots if name.endswith(".png")],
            table,
            title,
            metadata,
            designs=answer.kind == "annual",
        )
    return out


def write_sizing(result, out: Path, overwrite: bool = False, command=None) -> Path:
    """Write a sizing's folder: ``sizing.csv``, ``sizing_best.csv``, ``net_benefit_vs_area.png``,
    ``run.json`` (with the sizing's costs, price and lifetime) and ``report.html``.

    Parameters
    ----------
    result : foldopt.SizingResult
    out : pathlib.Path
    overwrite : bool, default False
    command : list of str, optional
        What ``run.json`` records as the command; default ``sys.argv``.

    Returns
    -------
    pathlib.Path
        ``out``.
    """
    study, table, best = result.study, result.table, result.best
    with staged_folder(out, overwrite) as folder:
        write_csv(table, folder / "sizing.csv")
        write_csv(best, folder / "sizing_best.csv")
        figure = write_figure(
            folder,
            "net_benefit_vs_area.png",
            table,
            best,
            f"{study.name}: panel sizing (Shin et al. Sec. IV-A)",
        )
        metadata = run_metadata(
            study, command, sizing=result.parameters, input_sha256=input_hash(study.data())
        )
        write_run_json(folder, metadata)
        write_html(folder, result.answer, [figure], table, "Every area (sizing.csv)", metadata)
    return out


def write_optimize(result, out: Path, overwrite: bool = False, command=None) -> Path:
    """Write a joint optimisation's folder: ``optimum.csv`` (per load and design), ``near_optimal.csv``,
    ``added.csv`` (what each variable adds), ``evaluated.csv`` (every design the search
    evaluated, per load), ``landscape.csv`` and ``landscape.png``, ``run.json`` (with the search's
    levels) and ``report.html``.

    Parameters
    ----------
    result : foldopt.studies.joint.OptimizeResult
    out : pathlib.Path
    overwrite : bool, default False
    command : list of str, optional
        What ``run.json`` records as the command; default ``sys.argv``.

    Returns
    -------
    pathlib.Path
        ``out``.
    """
    study, search = result.study, result.twofold
    points = pd.DataFrame(
        search.points, columns=["fold_angle_deg", "surface_tilt", "surface_azimuth"]
    )
    points["surface_azimuth"] %= 360.0
    evaluated = pd.concat(
        [
            points.assign(p_load_w=load, t_solar_objective_h=search.values[:, index])
            for index, load in enumerate(result.loads)
        ],
        ignore_index=True,
    )
    with staged_folder(out, overwrite) as folder:
        write_csv(result.table, folder / "optimum.csv")
        write_csv(result.near_optimal, folder / "near_optimal.csv")
        write_csv(result.added, folder / "added.csv")
        write_csv(evaluated, folder / "evaluated.csv")
        write_csv(result.landscape, folder / "landscape.csv")
        figures = [
            write_figure(
                folder,
                "landscape.png",
                result.landscape,
                result.table,
                f"{study.name}: objective over tilt x fold angle (azimuth "
                f"{result.landscape['surface_azimuth'].iloc[0]:g} deg)",
            )
        ]
        figures += _horizon_figure(study, list(result.dates), folder, study.name)
        metadata = run_metadata(
            study,
            command,
            days=len(result.dates),
            search=result.answer.result["search"],
            input_sha256=input_hash(study.data()),
            engine=result.engine,
        )
        write_run_json(folder, metadata)
        write_html(folder, result.answer, figures, result.table, "Designs (optimum.csv)", metadata)
    return out


def map_figures(
    table: pd.DataFrame,
    folder: Path,
    name: str,
    relative: bool,
    load_index: int = 0,
    period: str = "year",
    tilt: bool = False,
) -> list[str]:
    """Write the world maps of one load and period and the latitude x load chart
    (:data:`foldopt.output.figures.world.FIGURES`) in a map's folder, each file atomically.

    Parameters
    ----------
    table : pandas.DataFrame
        The map's table (:attr:`foldopt.MapRun.table`): a row per site, load and period.
    folder : pathlib.Path
        The map's folder.
    name : str
        Begins each title.
    relative : bool
        Whether the map's loads are fractions of each site's flat peak (``p_load_frac``) rather
        than watts (``p_load_w``).
    load_index : int, default 0
        The load the maps show, by its index among the map's loads (sorted).
    period : str, default 'year'
        The period the maps and the chart show (``year``, ``DJF``...).
    tilt : bool, default False
        Whether the map searched the base tilt: its map of the best tilts too.

    Returns
    -------
    list of str
        The file names written.
    """
    loads = table["p_load_frac"] if relative else table["p_load_w"]
    values = np.unique(loads.round(12))
    shown = table[(np.isclose(loads, values[load_index])) & (table["period"] == period)]
    shown = shown.assign(
        near_optimal_width_deg=shown["near_optimal_hi_deg"] - shown["near_optimal_lo_deg"]
    )
    unit = "of the flat peak" if relative else "W"
    what = f"P_load {values[load_index]:g} {unit}, {period}"
    written = [
        write_figure(
            folder, file, shown, column, f"{name}: {description} ({what})", label, diverging
        )
        for file, column, description, label, diverging in (
            *world.MAPS,
            *(world.TILT_MAPS if tilt else ()),
        )
    ]
    return written + [
        write_figure(
            folder,
            "latitude_load_gain.png",
            table,
            period,
            relative,
            f"{name}: where folding pays ({period}, median over longitudes)",
        )
    ]


def write_map_report(result, figures: list[str], answer, metadata: dict) -> Path:
    """Write ``report.html`` in a map's folder: the question, the answer, the maps and the year's
    rows.

    Parameters
    ----------
    result : foldopt.MapRun
    figures : list of str
        The figures' file names (:func:`map_figures`), in order.
    answer : foldopt.Answer
        The map's answer (:func:`foldopt.studies.result_answers.of_map`).
    metadata : dict
        The provenance: the ``run.json`` the complete map gets.

    Returns
    -------
    pathlib.Path
        The page written.
    """
    year = result.table[result.table["period"] == "year"]
    return write_html(
        result.out,
        answer,
        figures,
        year,
        "The year per site and load (map.csv has every season)",
        metadata,
    )
