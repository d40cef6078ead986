"""foldopt command line: thin wrappers over the library.

Every bad input ends the same way: one ``error: <field> ...`` line per fault on stderr, exit code
2, no traceback and nothing written.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Optional

import typer
from typer.core import TyperGroup

from foldopt.config import ConfigError, default_study_path, load_study, make_study
from foldopt.report import OutputExistsError, check_output, write_reproduction, write_study
from foldopt.reproduce import REPRODUCTIONS
from foldopt.reproduce import reproduce as reproduce_table
from foldopt.study import run_study

RESULTS = Path("results")
# Typer >= 0.29 vendors click; its UsageError is reached through the public BadParameter.
_USAGE_ERROR = next(cls for cls in typer.BadParameter.__mro__ if cls.__name__ == "UsageError")


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
sweep_app = typer.Typer(cls=_OneLineErrors, no_args_is_help=True, help="Sweep one design variable.")
app.add_typer(sweep_app, name="sweep")


def _fail(lines: list[str]):
    for line in lines:
        typer.echo(f"error: {line}", err=True)
    raise typer.Exit(2)


def _print_summary(summary) -> None:
    columns = ["design", "fold_angle_deg", "t_solar_h", "t_solar_contiguous_h", "energy_wh",
               "peak_power_w", "gain_vs_flat_pct", "pct_of_tracker_t_solar", "flat_area_multiple"]
    typer.echo(summary[columns].to_string(index=False, float_format=lambda v: f"{v:.3f}"))


def _run_and_write(study, out: Path, overwrite: bool) -> None:
    check_output(out, overwrite)
    result = run_study(study)
    write_study(result, out, overwrite)
    study = result.study
    typer.echo(
        f"{study.name} ({study.mode} mode, {study.geometry}, {study.pv_model} + {study.connection}, "
        f"P_load {study.p_load:g} W)"
    )
    _print_summary(result.summary)
    typer.echo(f"wrote {out}")


@app.command()
def run(
    config: Optional[Path] = typer.Argument(None, help="YAML study; default: the embedded configs/shin2015.yaml"),
    out: Optional[Path] = typer.Option(None, "--out", help="Results folder; default results/<study name>"),
    overwrite: bool = typer.Option(False, "--overwrite", help="Replace an existing results folder"),
):
    """Run a YAML study: fold-angle sweep, paper heuristic, flat / twofold / tracker comparison."""
    try:
        study = load_study(config if config is not None else default_study_path())
        _run_and_write(study, out or RESULTS / study.name, overwrite)
    except (ConfigError, OutputExistsError) as error:
        _fail(getattr(error, "errors", [str(error)]))


@app.command()
def reproduce(
    out: Path = typer.Option(RESULTS / "reproduction", "--out", help="Results folder"),
    overwrite: bool = typer.Option(False, "--overwrite", help="Replace an existing results folder"),
):
    """Reproduce Shin et al.'s study in paper and exact modes.

    Writes reproduction.csv (the embedded study: ideal PV model) and reproduction_single_diode.csv
    (A-300 single-diode sub-panels with switching).
    """
    try:
        check_output(out, overwrite)
        study = load_study(default_study_path())
        tables = {name: reproduce_table(study, **changes) for name, changes in REPRODUCTIONS.items()}
        write_reproduction(tables, study, out, overwrite)
    except (ConfigError, OutputExistsError) as error:
        _fail(getattr(error, "errors", [str(error)]))
    for name, table in tables.items():
        typer.echo(f"Shin et al. twofold study ({name}): paper value, paper-mode and exact-mode reproduction")
        typer.echo(table.to_string(index=False, float_format=lambda v: f"{v:.3f}", na_rep="-"))
        typer.echo(f"wrote {out / (name + '.csv')}")


#: Study fields as the sweep options name them, so errors speak the user's words.
_SWEEP_OPTIONS = {
    "site.latitude": "--lat", "site.longitude": "--lon", "site.altitude": "--altitude",
    "site.timezone": "--timezone", "date": "--date", "p_load": "--p-load", "panel.area": "--area",
    "panel.efficiency": "--efficiency", "panel.tilt": "--tilt", "panel.azimuth": "--azimuth",
    "mode": "--mode", "geometry": "--geometry", "sky": "--sky", "step_min": "--step-min",
    "connection": "--connection", "fold_angles.step": "--angle-step", "fold_angles.start": "--angle-step",
    "pv_model": "--pv-model", "module": "--module", "temp_air": "--temp-air",
    "converter_efficiency": "--converter-efficiency",
}


def _rename_fields(line: str) -> str:
    field, sep, rest = line.partition(" ")
    key = field.rstrip(":")
    return f"{_SWEEP_OPTIONS[key]}{field[len(key):]}{sep}{rest}" if key in _SWEEP_OPTIONS else line


@sweep_app.command("angle")
def sweep_angle(
    lat: Optional[float] = typer.Option(None, "--lat", help="Latitude [deg north], -90..90"),
    lon: Optional[float] = typer.Option(None, "--lon", help="Longitude [deg east], -180..180"),
    date: Optional[str] = typer.Option(None, "--date", help="Day, YYYY-MM-DD"),
    p_load: Optional[float] = typer.Option(None, "--p-load", help="Load [W], > 0"),
    area: Optional[float] = typer.Option(None, "--area", help="Flat panel area [m^2], > 0"),
    efficiency: float = typer.Option(0.2, "--efficiency", help="PV efficiency (ideal model), 0..1"),
    tilt: Optional[float] = typer.Option(None, "--tilt", help="Tilt [deg]; default |latitude|"),
    azimuth: Optional[float] = typer.Option(None, "--azimuth", help="Azimuth [deg]; default facing the equator"),
    altitude: float = typer.Option(0.0, "--altitude", help="Site altitude [m]"),
    timezone: Optional[str] = typer.Option(None, "--timezone", help="IANA name or UTC offset; default from longitude"),
    mode: str = typer.Option("exact", "--mode", help="paper | exact"),
    geometry: Optional[str] = typer.Option(None, "--geometry", help="azimuth-split | hinge; default by mode"),
    sky: str = typer.Option("meinel", "--sky", help="Clear-sky model: meinel"),
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
    out: Path = typer.Option(RESULTS / "sweep-angle", "--out", help="Results folder"),
    overwrite: bool = typer.Option(False, "--overwrite", help="Replace an existing results folder"),
):
    """t_solar and energy for every fold angle at one site, day and load (sweep.csv, summary.csv)."""
    site = {"latitude": lat, "longitude": lon, "altitude": altitude, "timezone": timezone}
    panel = {"area": area, "efficiency": efficiency, "tilt": tilt, "azimuth": azimuth}
    data = {
        "name": "sweep-angle",
        "mode": mode,
        "site": {key: value for key, value in site.items() if value is not None},
        "date": date,
        "panel": {key: value for key, value in panel.items() if value is not None},
        "p_load": p_load,
        "geometry": geometry,
        "sky": sky,
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
        study = make_study(data)
    except ConfigError as error:
        _fail([_rename_fields(line) for line in error.errors])
    try:
        _run_and_write(study, out, overwrite)
    except OutputExistsError as error:
        _fail([str(error)])


def main():  # pragma: no cover - console-script entry point
    app()


if __name__ == "__main__":  # pragma: no cover
    main()
