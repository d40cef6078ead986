"""foldopt command line: thin wrappers over the library.

Every bad input ends the same way: one ``error: <field> ...`` line per fault on stderr, exit code
2, no traceback and nothing written. Anything that runs longer than a second shows a status line
on stderr (``--quiet`` hides it); ``--format json`` prints the summary on stdout for scripts.
"""

from __future__ import annotations

import json
import re
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Optional

import numpy as np
import typer
import yaml
from typer.core import TyperGroup

from foldopt.config import ConfigError, default_study_path, load_plan, load_study, make_plan, parse_range, set_path
from foldopt.report import (
    OutputExistsError,
    check_output,
    write_reproduction,
    write_sizing,
    write_study,
    write_sweep,
)
from foldopt.reproduce import REPRODUCTIONS
from foldopt.reproduce import reproduce as reproduce_table
from foldopt.sizing import C_GRID, LIFETIME_YEARS, size_panel
from foldopt.study import Day, run_study
from foldopt.sweep import run_plan

RESULTS = Path("results")
# Typer >= 0.29 vendors click; its UsageError is reached through the public BadParameter.
_USAGE_ERROR = next(cls for cls in typer.BadParameter.__mro__ if cls.__name__ == "UsageError")
FORMATS = ("table", "json")
ENGINES = ("numba", "numpy")  # foldopt.engine.ENGINES, without importing the engine for --help


class _OneLineErrors(TyperGroup):
    """Report usage errors (unknown option, bad number...) as one line, exit code 2."""

    def main(self, *args, **kwargs):
        kwargs["standalone_mode"] = False
        try:
            code = super().main(*args, **kwargs)
        except _USAGE_ERROR as error:
            message = error.format_message()
            if message:  # empty after no_args_is_help has printed the help
                where = f"{error.ctx.command_path}: " if error.ctx is not None else ""
                typer.echo(f"error: {where}{message}", err=True)
            sys.exit(2)
        except typer.Abort:
            typer.echo("aborted", err=True)
            sys.exit(1)
        sys.exit(code if isinstance(code, int) else 0)


app = typer.Typer(
    cls=_OneLineErrors,
    add_completion=False,
    pretty_exceptions_enable=False,
    no_args_is_help=True,
    help="Design-space optimiser for twofold PV panels powering storage-less loads.",
)


def _fail(lines: list[str]):
    for line in lines:
        typer.echo(f"error: {line}", err=True)
    raise typer.Exit(2)


class _Status:
    """A status line on stderr that appears only once a task has run for a second."""

    def __init__(self, label: str, quiet: bool):
        self.label, self.quiet = label, quiet
        self.start = time.monotonic()
        self.detail = ""
        self.shown = False
        self._stop = threading.Event()

    def progress(self, done: int, total: int) -> None:
        width = 24
        filled = int(width * done / max(total, 1))
        self.detail = f"[{'#' * filled}{'.' * (width - filled)}] {done}/{total}"

    def _draw(self):
        while not self._stop.wait(0.25):
            if time.monotonic() - self.start >= 1.0:
                self.shown = True
                elapsed = time.monotonic() - self.start
                sys.stderr.write(f"\r{self.label} {self.detail} {elapsed:5.1f} s ")
                sys.stderr.flush()

    @contextmanager
    def running(self):
        thread = None
        if not self.quiet:
            thread = threading.Thread(target=self._draw, daemon=True)
            thread.start()
        try:
            yield self
        finally:
            self._stop.set()
            if thread is not None:
                thread.join()
            if self.shown:
                sys.stderr.write("\n")


def _check_format(output_format: str, engine: str = "numba") -> None:
    errors = []
    if output_format not in FORMATS:
        errors.append(f"--format = {output_format!r}: must be one of {', '.join(FORMATS)}")
    if engine not in ENGINES:
        errors.append(f"--engine = {engine!r}: must be one of {', '.join(ENGINES)}")
    if errors:
        _fail(errors)


def _emit(table, title: str, output_format: str, out: Path, columns=None) -> None:
    """The summary: a text table on stdout, or JSON records for scripts (messages then on stderr)."""
    if output_format == "json":
        records = json.loads(table.to_json(orient="records", double_precision=10))
        typer.echo(json.dumps({"title": title, "out": str(out), "rows": records}, indent=1))
        return
    shown = table[[c for c in columns if c in table]] if columns else table
    typer.echo(title)
    typer.echo(shown.to_string(index=False, float_format=lambda v: f"{v:.3f}", na_rep="-"))
    typer.echo(f"wrote {out}")


SUMMARY_COLUMNS = ["design", "fold_angle_deg", "t_solar_h", "t_solar_contiguous_h", "energy_wh",
                   "peak_power_w", "gain_vs_flat_pct", "pct_of_tracker_t_solar", "flat_area_multiple"]
SWEEP_COLUMNS = ["latitude", "date", "p_load_w", "design", "fold_angle_deg", "t_solar_h", "gain_vs_flat_pct", "note"]
QUIET = typer.Option(False, "--quiet", "-q", help="No status line")
FORMAT = typer.Option("table", "--format", help="table | json (summary on stdout for scripts)")
OVERWRITE = typer.Option(False, "--overwrite", help="Replace an existing results folder")
ENGINE = typer.Option("numba", "--engine", help="numba (compiled kernel) | numpy (the reference path, slower)")


def _run_plan(plan, out: Path, overwrite: bool, quiet: bool, output_format: str, engine: str) -> None:
    check_output(out, overwrite)
    base = plan.base
    if not plan.axes:
        with _Status(f"foldopt: {base.name}", quiet).running():
            result = run_study(base, engine)
            write_study(result, out, overwrite)
        study = result.study
        title = (f"{study.name} ({study.mode} mode, {study.geometry}, {study.pv_model} + {study.connection}, "
                 f"P_load {study.p_load:g} W)")
        _emit(result.summary, title, output_format, out, SUMMARY_COLUMNS)
        if output_format == "table" and np.isfinite(result.standby[1]):
            typer.echo(f"the optimal twofold panel outlasts the {study.tracker.model} tracker once the tracker's "
                       f"standby draw exceeds {result.standby[1]:.2f} W")
        return
    with _Status(f"foldopt: {base.name}, {plan.n_cases} cases", quiet).running() as status:
        result = run_plan(plan, status.progress, engine)
        write_sweep(result, out, overwrite)
    twofold = result.table[result.table["design"] == "twofold"]
    title = f"{base.name}: {plan.n_cases} cases over {', '.join(p for p, _ in plan.axes)} (twofold rows)"
    table = result.table if output_format == "json" else twofold
    _emit(table, title, output_format, out, SWEEP_COLUMNS)


@app.command()
def run(
    config: Optional[Path] = typer.Argument(None, help="YAML study; default: the embedded configs/shin2015.yaml"),
    out: Optional[Path] = typer.Option(None, "--out", help="Results folder; default results/<study name>"),
    overwrite: bool = OVERWRITE,
    quiet: bool = QUIET,
    output_format: str = FORMAT,
    engine: str = ENGINE,
):
    """Run a YAML study: one case (fold-angle sweep, heuristic, comparison) or a sweep of cases."""
    _check_format(output_format, engine)
    try:
        plan = load_plan(config if config is not None else default_study_path())
        _run_plan(plan, out or RESULTS / plan.base.name, overwrite, quiet, output_format, engine)
    except (ConfigError, OutputExistsError) as error:
        _fail(getattr(error, "errors", [str(error)]))


@app.command()
def reproduce(
    out: Path = typer.Option(RESULTS / "reproduction", "--out", help="Results folder"),
    overwrite: bool = OVERWRITE,
    quiet: bool = QUIET,
    output_format: str = FORMAT,
    engine: str = ENGINE,
):
    """Reproduce Shin et al.'s study in paper and exact modes.

    Writes reproduction.csv (the embedded study: ideal PV model) and reproduction_single_diode.csv
    (A-300 single-diode sub-panels with switching).
    """
    _check_format(output_format, engine)
    try:
        check_output(out, overwrite)
        study = load_study(default_study_path())
        with _Status("foldopt: reproducing Shin et al.", quiet).running():
            tables = {name: reproduce_table(study, engine, **changes) for name, changes in REPRODUCTIONS.items()}
            write_reproduction(tables, study, out, overwrite, engine=engine)
    except (ConfigError, OutputExistsError) as error:
        _fail(getattr(error, "errors", [str(error)]))
    for name, table in tables.items():
        title = f"Shin et al. twofold study ({name}): paper value, paper-mode and exact-mode reproduction"
        _emit(table, title, output_format, out / f"{name}.csv")


#: Study fields as the command-line options name them, so errors speak the user's words.
_OPTION_OF_FIELD = {
    "site.latitude": "--lat", "site.longitude": "--lon", "site.altitude": "--altitude",
    "site.timezone": "--timezone", "date": "--days/--date", "p_load": "--p-load", "panel.area": "--area",
    "panel.efficiency": "--efficiency", "panel.tilt": "--tilt", "panel.azimuth": "--azimuth",
    "mode": "--mode", "geometry": "--geometry", "sky": "--sky", "step_min": "--step-min",
    "connection": "--connection", "fold_angles.step": "--angle-step", "fold_angles.start": "--angle-step",
    "pv_model": "--pv-model", "module": "--module", "temp_air": "--temp-air",
    "converter_efficiency": "--converter-efficiency", "year": "--year", "climate": "--climate",
    "tracker.model": "--tracker", "tracker.standby_w": "--tracker-standby", "transposition": "--transposition",
    "objective.statistic": "--objective", "weather": "--weather", "albedo": "--albedo", "iam": "--iam",
}
_FIELD = re.compile(r"^([A-Za-z_.]+)(\[\d+\])?")


def _rename_fields(line: str) -> str:
    match = _FIELD.match(line)
    if match and match.group(1) in _OPTION_OF_FIELD:
        return _OPTION_OF_FIELD[match.group(1)] + line[match.end(1):]
    return line


AXES = ("angle", "latitude", "day", "load")
_DEFAULT_RANGES = {"latitude": "-60:60:5", "day": "1:365:7"}


@app.command()
def sweep(
    axis: str = typer.Argument(..., help="angle | latitude | day | load"),
    lat: Optional[str] = typer.Option(None, "--lat", help="Latitude [deg north] or a range -60:60:5"),
    lon: Optional[str] = typer.Option(None, "--lon", help="Longitude [deg east] (or a range)"),
    days: Optional[str] = typer.Option(
        None, "--days", "--date",
        help="A date YYYY-MM-DD, a range of days 1:365:7 or dates, 'year' or 'equinoxes-solstices'",
    ),
    year: int = typer.Option(2025, "--year", help="Year of day-of-year ranges"),
    p_load: Optional[str] = typer.Option(None, "--p-load", help="Load [W] or a range 1:20:0.5"),
    area: Optional[float] = typer.Option(None, "--area", help="Flat panel area [m^2], > 0"),
    efficiency: float = typer.Option(0.2, "--efficiency", help="PV efficiency (ideal model), 0..1"),
    tilt: Optional[str] = typer.Option(None, "--tilt", help="Tilt [deg]; default |latitude|"),
    azimuth: Optional[float] = typer.Option(None, "--azimuth", help="Azimuth [deg]; default facing the equator"),
    altitude: Optional[float] = typer.Option(None, "--altitude", help="Site altitude [m]; default 0"),
    timezone: Optional[str] = typer.Option(None, "--timezone", help="IANA name or UTC offset; default from longitude"),
    mode: str = typer.Option("exact", "--mode", help="paper | exact"),
    geometry: Optional[str] = typer.Option(None, "--geometry", help="azimuth-split | hinge; default by mode"),
    sky: str = typer.Option("meinel", "--sky", help="Clear-sky beam model: meinel | hottel"),
    climate: str = typer.Option("midlatitude-summer", "--climate", help="hottel: tropical | midlatitude-summer | "
                                "subarctic-summer | midlatitude-winter"),
    weather: Optional[Path] = typer.Option(
        None, "--weather", help="TMY3 / EPW / PVGIS TMY file: its site and its whole year unless given"),
    force_site: bool = typer.Option(False, "--force-site", help="Keep --lat/--lon far from the weather file's site"),
    albedo: Optional[float] = typer.Option(None, "--albedo", help="Ground reflectance 0..1; default 0.2"),
    iam: Optional[str] = typer.Option(None, "--iam", help="Incidence-angle modifier: none | ashrae | physical"),
    transposition: Optional[str] = typer.Option(None, "--transposition", help="none | isotropic | haydavies | perez"),
    objective: Optional[str] = typer.Option(None, "--objective", help="One fold angle for all days: mean | min | "
                                            "worst-month | pNN"),
    tracker: str = typer.Option("dual-axis", "--tracker", help="dual-axis | equatorial | dual-axis-steps | single-axis"),
    tracker_standby: float = typer.Option(0.0, "--tracker-standby", help="Tracker controller standby draw [W]"),
    pv_model: str = typer.Option("ideal", "--pv-model", help="ideal | single-diode | b-model"),
    module: Optional[str] = typer.Option(None, "--module", help="single-diode: CEC module name (default A-300 cell)"),
    connection: str = typer.Option(
        "switching", "--connection", help="east | west | parallel | series | independent | switching"
    ),
    switch_series: bool = typer.Option(False, "--switch-series", help="Switching may also select series"),
    no_bypass: bool = typer.Option(False, "--no-bypass", help="No bypass diodes in series"),
    converter_efficiency: float = typer.Option(1.0, "--converter-efficiency", help="Independent converters' efficiency"),
    temp_air: float = typer.Option(25.0, "--temp-air", help="Air temperature [C]"),
    exact_electrical: bool = typer.Option(False, "--exact-electrical", help="Solve I-V curves per step, not tables"),
    step_min: float = typer.Option(1.0, "--step-min", help="Time step [min], divides 1440"),
    angle_step: float = typer.Option(1.0, "--angle-step", help="Fold-angle sweep step [deg]"),
    settings: Optional[list[str]] = typer.Option(
        None, "--set", help="Any study field, KEY=VALUE (dotted keys, YAML values), e.g. --set tracker.gcr=0.4"),
    out: Optional[Path] = typer.Option(None, "--out", help="Results folder; default results/sweep-<axis>"),
    overwrite: bool = OVERWRITE,
    quiet: bool = QUIET,
    output_format: str = FORMAT,
    engine: str = ENGINE,
):
    """Sweep a design variable from the command line.

    angle: one site, day and load, every fold angle (sweep.csv, summary.csv); with a weather file,
    one fold angle for the file's whole year (--objective, default mean). latitude, day, load:
    every combination of the ranges given (--lat, --days, --p-load, --tilt, --lon accept
    start:stop:step), one row per case x design in results.csv, with heat maps and curves.
    """
    _check_format(output_format, engine)
    if axis not in AXES:
        _fail([f"sweep: axis {axis!r} must be one of {', '.join(AXES)}"])
    if weather is None:
        lat = lat if lat is not None else _DEFAULT_RANGES.get(axis)
        days = days if days is not None else _DEFAULT_RANGES.get(axis)
    if axis == "angle" and weather is not None and objective is None:
        objective = "mean"  # a year of weather at one fold angle
    if axis == "load" and (p_load is None or _single(p_load)):
        _fail(["--p-load: sweep load needs a range start:stop:step or a list"])
    site = {key: value for key, value in
            {"latitude": lat, "longitude": lon, "altitude": altitude, "timezone": timezone}.items() if value is not None}
    panel = {"area": area, "efficiency": efficiency, "tilt": tilt, "azimuth": azimuth}
    data = {
        "name": f"sweep-{axis}",
        "year": year,
        "mode": mode,
        "site": site or None,  # none given: the weather file's, or an error naming the field
        "date": days,
        "panel": {key: value for key, value in panel.items() if value is not None},
        "p_load": p_load,
        "geometry": geometry,
        "sky": sky,
        "climate": climate,
        "weather": str(weather) if weather is not None else None,
        "force_site": force_site,
        "albedo": albedo,
        "iam": iam,
        "transposition": transposition,
        "objective": {"statistic": objective} if objective is not None else None,
        "tracker": {"model": tracker, "standby_w": tracker_standby},
        "pv_model": pv_model,
        "module": module,
        "connection": connection,
        "switch_series": switch_series,
        "bypass_diodes": not no_bypass,
        "converter_efficiency": converter_efficiency,
        "temp_air": temp_air,
        "exact_electrical": exact_electrical,
        "step_min": step_min,
        "fold_angles": {"start": angle_step, "stop": 180.0, "step": angle_step},
    }
    data = {key: value for key, value in data.items() if value is not None}
    try:
        for setting in settings or ():
            data = _apply_setting(data, setting)
        plan = make_plan(data)
    except ConfigError as error:
        _fail(list(dict.fromkeys(_rename_fields(line) for line in error.errors)))
    varied = [p for p, _ in plan.axes if not (p == "date" and plan.base.objective is not None)]
    if axis == "angle" and varied:
        _fail([f"sweep angle: one site, day and load; {', '.join(varied)} vary (use sweep latitude/day/load)"])
    try:
        _run_plan(plan, out or RESULTS / f"sweep-{axis}", overwrite, quiet, output_format, engine)
    except OutputExistsError as error:
        _fail([str(error)])


def _apply_setting(data: dict, setting: str) -> dict:
    """``KEY=VALUE`` into the study's data: a dotted field path and a YAML value."""
    key, separator, text = setting.partition("=")
    if not separator or not key.strip():
        raise ConfigError([f"--set = {setting!r}: expected KEY=VALUE, e.g. tracker.gcr=0.4"])
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError:
        raise ConfigError([f"--set {key} = {text!r}: not a YAML value"]) from None
    return set_path(data, key.strip(), value)


def _single(text: str) -> bool:
    return ":" not in text and "," not in text


@app.command()
def size(
    config: Optional[Path] = typer.Argument(None, help="YAML study (one case); default the embedded paper study"),
    areas: str = typer.Option("0.01:0.5:0.005", "--areas", help="Panel areas [m^2], start:stop:step"),
    cost_per_m2: Optional[float] = typer.Option(None, "--cost-per-m2", help="Panel cost [$/m^2]"),
    cost_per_w: Optional[float] = typer.Option(None, "--cost-per-w", help="Panel cost [$/W at STC]"),
    c_grid: float = typer.Option(C_GRID, "--c-grid", help="Grid energy price [$/kWh] (Shin et al.: 0.22)"),
    years: float = typer.Option(LIFETIME_YEARS, "--years", help="Lifetime [years] (Shin et al.: 20)"),
    days_per_year: float = typer.Option(365.0, "--days-per-year", help="Days a year like the study's day"),
    out: Optional[Path] = typer.Option(None, "--out", help="Results folder; default results/<study>-sizing"),
    overwrite: bool = OVERWRITE,
    quiet: bool = QUIET,
    output_format: str = FORMAT,
):
    """Shin et al. Sec. IV-A sizing: lifetime benefit C_grid * t_solar * P_load against panel cost."""
    _check_format(output_format)
    errors = []
    if (cost_per_m2 is None) == (cost_per_w is None):
        errors.append("--cost-per-m2 / --cost-per-w: give exactly one panel cost")
    for name, value, low in (("--cost-per-m2", cost_per_m2, 0.0), ("--cost-per-w", cost_per_w, 0.0),
                             ("--c-grid", c_grid, 0.0), ("--years", years, 0.0), ("--days-per-year", days_per_year, 0.0)):
        if value is not None and not (np.isfinite(value) and value > low):
            errors.append(f"{name} = {value}: must be > {low:g}")
    try:
        grid = parse_range(areas)
        if grid[0] <= 0 or grid[-1] > 1000:
            errors.append(f"--areas = {areas!r}: areas must be in (0, 1000] m^2")
    except ValueError as error:
        errors.append(f"--areas: {error}")
    if errors:
        _fail(errors)
    try:
        study = load_study(config if config is not None else default_study_path())
        out = out or RESULTS / f"{study.name}-sizing"
        check_output(out, overwrite)
        with _Status(f"foldopt: sizing {study.name}", quiet).running():
            table = size_panel(Day(study), grid, cost_per_m2, cost_per_w, c_grid, years, days_per_year)
            best = write_sizing(table, study, out, overwrite)
    except (ConfigError, OutputExistsError) as error:
        _fail(getattr(error, "errors", [str(error)]))
    _emit(best, f"{study.name}: area with the largest lifetime net benefit", output_format, out)


def main():  # pragma: no cover - console-script entry point
    app()


if __name__ == "__main__":  # pragma: no cover
    main()
