"""foldopt command line: thin wrappers over the library.

Every bad input ends the same way: one ``error: <field> ...`` line per fault on stderr, exit code
2, no traceback and nothing written. Input is checked before numpy, pandas, pvlib or matplotlib
load, so that help and errors come at once. Work shows a progress bar on stderr that is removed when
done; the terminal then gets a short answer (``--table`` adds the full table, always in the CSV
files), ``--format json`` one JSON document, and ``--quiet`` nothing but errors.
"""

from __future__ import annotations

import codecs
import inspect
import os
import json
import re
import signal
import sys
import threading
import traceback
from contextlib import contextmanager
from pathlib import Path
from typing import Optional

import typer
from typer.core import TyperCommand, TyperGroup

from foldopt import names
from foldopt.inputs.config import (default_study_path, load_plan, parse_study_text, parse_values, read_study,
    year_problem)
from foldopt.errors import ConfigError
from foldopt.inputs.policy import set_path
from foldopt.studies.request import Request, plan_request, size_request
from foldopt.inputs.costs import C_GRID, DAYS_PER_YEAR, LIFETIME_YEARS, PAPER_COST_PER_M2
from foldopt.files import check_output
from foldopt.errors import OutputError, OutputExistsError

RESULTS = Path("results")
# Typer >= 0.29 vendors click; its UsageError is reached through the public BadParameter.
_USAGE_ERROR = next(cls for cls in typer.BadParameter.__mro__ if cls.__name__ == "UsageError")
EMBEDDED = "configs/shin2015.yaml"

HELP = """Design-space optimiser for twofold PV panels powering storage-less loads.

Every command runs from its defaults: the embedded study (configs/shin2015.yaml, Shin et al.'s
pole camera in Los Angeles on the 2014 autumn equinox) or the one --config names.

\b
Examples:
  foldopt run                                  the embedded study: best fold angle, flat, tracker
  foldopt run configs/design-map.yaml          a YAML study, one case or a sweep
  foldopt reproduce                            Shin et al.'s numbers beside foldopt's
  foldopt sweep latitude                       the embedded study from 60 S to 60 N
  foldopt sweep angle --weather FILE.csv       a real year from a TMY3 / EPW / PVGIS file
  foldopt size --cost-per-w 0.9                panel sizing (Shin et al. Sec. IV-A)
  foldopt map --p-load 2 --area 0.108          many sites on Dask: where folding pays, worldwide

Shell completion: foldopt --install-completion.
"""


#: The command line as typed, for run.json (``sys.argv`` holds the script's path, or pytest's).
_INVOCATION: list[str] = []


#: Set by ``foldopt --debug``: an internal error shows its traceback.
_DEBUG = {"on": False}


def _terminate(signum, frame):
    raise SystemExit(128 + signum)  # unwinds like an error: a staging folder is removed


class _Interrupted(Exception):
    """Ctrl-C, carried past typer, which would end the command with code 130 and not a word."""


def _as_text(text: str) -> str:
    """Text from the command line (an argument, a path in a message) as it was typed: under a C
    locale without Python's UTF-8 mode its bytes arrive as surrogates (PEP 383), which no UTF-8
    file can hold and a terminal shows as ``?``; they are read as the UTF-8 they are, and bytes
    that are no UTF-8 as backslash escapes."""
    return text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")


def _echo(text: str, err: bool = False) -> None:
    typer.echo(_as_text(text), err=err)


class _OneLineErrors(TyperGroup):
    """The one error path of the command line. Bad input (usage, study, weather file, results
    folder) is one line per fault and exit code 2; anything else is an internal error: one line
    naming it, exit code 1, and the traceback only with ``--debug``; Ctrl-C is ``interrupted``,
    exit code 130."""

    def main(self, *args, **kwargs):
        quiet = os.environ.get("FOLDOPT_QUIET")
        try:
            self._main(*args, **kwargs)
        finally:
            # --quiet silences the caches' notices for this command only (an in-process caller's
            # environment is left as it was).
            if quiet is None:
                os.environ.pop("FOLDOPT_QUIET", None)
            else:
                os.environ["FOLDOPT_QUIET"] = quiet

    def _main(self, *args, **kwargs):
        kwargs["standalone_mode"] = False
        given = kwargs.get("args", args[0] if args else None)
        _INVOCATION[:] = ["foldopt", *map(_as_text, sys.argv[1:] if given is None else given)]
        for stream in (sys.stdout, sys.stderr):
            # A terminal that cannot show a character (a site's name under LANG=C) gets an escape, not an error.
            if codecs.lookup(getattr(stream, "encoding", None) or "utf-8").name != "utf-8" and hasattr(
                    stream, "reconfigure"):
                stream.reconfigure(errors="backslashreplace")
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGTERM, _terminate)
        try:
            code = super().main(*args, **kwargs)
        except ConfigError as error:
            for line in dict.fromkeys(error.errors):
                _echo(f"error: {line}", err=True)
            sys.exit(2)
        except (OutputError, OutputExistsError) as error:
            _echo(f"error: {error}", err=True)
            sys.exit(2)
        except _USAGE_ERROR as error:
            message = error.format_message()
            if type(error).__name__ == "NoArgsIsHelpError":  # a bare `foldopt` or `foldopt sweep`
                typer.echo(message)
                sys.exit(0)
            if message:
                where = f"{error.ctx.command_path}: " if error.ctx is not None else ""
                if message.startswith("No such command") and error.ctx is not None:
                    message += f" Choose one of {', '.join(error.ctx.command.list_commands(error.ctx))}."
                _echo(f"error: {where}{message}", err=True)
            sys.exit(2)
        except (_Interrupted, typer.Abort):  # Ctrl-C; typer's Abort: end of input at a prompt
            typer.echo("interrupted", err=True)
            sys.exit(130)
        except Exception as error:
            if _DEBUG["on"]:
                traceback.print_exc()
            else:
                reason = str(error).splitlines()[0][:300] if str(error) else ""
                _echo(f"error: internal error ({type(error).__name__}{': ' + reason if reason else ''}); "
                      "run again as foldopt --debug ... for the traceback, and please report it", err=True)
            sys.exit(1)
        sys.exit(code if isinstance(code, int) else 0)

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            raise _Interrupted() from None


class _OnceEach(TyperCommand):
    """A command whose options are each given at most once: a repeated option (``--days a --days
    b``) is an error, not a silent last-wins. Options that collect values (``--set``) repeat."""

    def parse_args(self, ctx, args):
        seen: dict[str, str] = {}
        for arg in args:
            if arg == "--":
                break
            flag = arg.split("=", 1)[0]
            for param in self.params:
                if getattr(param, "multiple", False) or flag not in tuple(getattr(param, "opts", ())) + tuple(
                        getattr(param, "secondary_opts", ())):
                    continue
                if param.name in seen:
                    raise _USAGE_ERROR(f"{flag}: given twice (first as {seen[param.name]}); give each option once",
                                       ctx=ctx)
                seen[param.name] = flag
        return super().parse_args(ctx, args)


app = typer.Typer(cls=_OneLineErrors, add_completion=True, pretty_exceptions_enable=False, no_args_is_help=True,
                  rich_markup_mode=None, help=HELP)
sweep_app = typer.Typer(rich_markup_mode=None, no_args_is_help=True,
                        help="Sweep one design variable over a range, everything else from the study.")


def _print_version(value: bool) -> None:
    if value:
        from foldopt import __version__

        typer.echo(f"foldopt {__version__}")
        raise typer.Exit()


@app.callback()
def _options(debug: bool = typer.Option(False, "--debug", help="Show the traceback of an internal error."),
             version: bool = typer.Option(False, "--version", callback=_print_version, is_eager=True,
                                          help="Print foldopt's version and exit.")):
    _DEBUG["on"] = debug


app.add_typer(sweep_app, name="sweep", short_help="Sweep fold angle, latitude, day or load [default ranges].")


def _fail(lines: list[str]):
    for line in lines:
        _echo(f"error: {line}", err=True)
    raise typer.Exit(2)


# --- Options every command shares ---------------------------------------------------------------

OVERWRITE = typer.Option(False, "--overwrite", help="Replace an existing results folder.")
QUIET = typer.Option(False, "--quiet", "-q", help="Print nothing but errors (with --format json: the JSON only).")
FORMAT = typer.Option("table", "--format", help=f"{' | '.join(names.OUTPUT_FORMATS)}: a short answer, or one JSON "
                                                 "document on stdout for scripts.")
ENGINE = typer.Option("numba", "--engine", help="numba (the compiled kernel) | numpy (the reference path it is "
                                                "tested against, slower).")
TABLE = typer.Option(False, "--table", help="Also print the full table (it is always in the CSV files).")


def _check_choices(output_format: str, engine: str) -> tuple[str, str]:
    errors, chosen = [], []
    for option, value, choices in (("--format", output_format, names.OUTPUT_FORMATS),
                                   ("--engine", engine, names.ENGINES)):
        try:
            chosen.append(names.canonical(value, choices))
        except ValueError as error:
            errors.append(f"{option} = {value!r}: {error}")
    if errors:
        _fail(errors)
    return tuple(chosen)


class _Output:
    """What a command prints: progress on stderr while it works, then the answer."""

    def __init__(self, quiet: bool, output_format: str, table: bool = False):
        self.quiet, self.json, self.table = quiet, output_format == "json", table
        if quiet:
            os.environ["FOLDOPT_QUIET"] = "1"  # the caches' rebuild notices too; embedded workers inherit it

    @contextmanager
    def progress(self, label: str, total: float | None = None, unit: str = "days"):
        """A rich progress bar from the first moment of the work, removed when done; yields a
        ``progress(done, total)`` callback counting ``unit``."""
        from rich.console import Console

        console = Console(stderr=True)
        if self.quiet or not console.is_terminal:  # a bar in a log or a pipe is noise
            yield lambda done, total: None
            return
        from rich.progress import (BarColumn, Progress, ProgressColumn, SpinnerColumn, TaskProgressColumn,
                                   TextColumn, TimeElapsedColumn, TimeRemainingColumn)
        from rich.text import Text

        class Rate(ProgressColumn):
            def render(self, task):
                return Text(f"{task.speed:,.0f} {unit}/s" if task.speed else "")

        columns = [SpinnerColumn(), TextColumn("{task.description}")]
        if total is not None:
            columns += [BarColumn(), TaskProgressColumn(), Rate(), TimeRemainingColumn()]
        with Progress(*columns, TimeElapsedColumn(), console=console, transient=True) as bar:
            task = bar.add_task(label, total=total)
            yield lambda done, total: bar.update(task, completed=done, total=total)

    def answer(self, command: str, out: Path, answer, rows=None, lines_after=(), table=None) -> None:
        """Render an :class:`foldopt.studies.answer.Answer`: its lines (``--table`` adds ``table``), or one
        JSON document holding it and the rows."""
        if self.json:
            document = {"command": command, "out": _as_text(str(out)), "answer": answer.to_dict(),
                        "rows": _records(rows)}
            typer.echo(json.dumps(document, indent=1))
            return
        if self.quiet:
            return
        for line in [*answer.lines(), *lines_after]:
            _echo(line)
        if table is not None and self.table:
            typer.echo(table.to_string(index=False, float_format=lambda v: f"{v:.3f}", na_rep="-"))
        elif table is not None:
            typer.echo("(--table prints the full table)")


def _records(table) -> list[dict]:
    """A table's rows as JSON-ready records, every number exact (JSON reads back the same float)."""
    from foldopt.studies.answer import records

    return records(table)


def _run_request(request, out: Path, overwrite: bool, output: _Output, engine: str, command: str) -> None:
    """Evaluate a request's plan (one case or many) through the API, write its folder, print its answer."""
    check_output(out, overwrite)
    plan, base = request.plan, request.plan.base
    if not plan.axes:
        label, total, unit = f"{base.name}: one day, {len(base.fold_angles.grid())} fold angles", None, "days"
    else:
        days = plan.n_cases // max(len(dict(plan.axes).get("p_load", (1,))), 1)
        unit = "site-days" if any(path.startswith("site") for path, _ in plan.axes) else "days"
        label, total = f"{base.name}: {days} {unit}", days
    with output.progress(label, total=total, unit=unit) as progress:
        from foldopt.api import run, write

        result = run(plan, engine, progress, request=request)
        write(result, out, overwrite, _INVOCATION)
    rows = result.summary if not plan.axes else result.table
    output.answer(command, out, result.answer, rows, [f"wrote {out}"], rows)


# --- run, reproduce -----------------------------------------------------------------------------


@app.command(cls=_OnceEach, short_help="Run a YAML study, one case or a sweep [default: the embedded study].")
def run(
    config: Optional[Path] = typer.Argument(None, help=f"YAML study [default: the embedded {EMBEDDED}]."),
    out: Optional[Path] = typer.Option(None, "--out", help="Results folder [default: results/<study name>]."),
    overwrite: bool = OVERWRITE,
    quiet: bool = QUIET,
    output_format: str = FORMAT,
    engine: str = ENGINE,
    table: bool = TABLE,
):
    """Run a YAML study: one case (fold-angle sweep, the paper's heuristic, flat and trackers
    compared) or a sweep of cases (a row per case x design).

    \b
    Examples:
      foldopt run
      foldopt run configs/annual-weather.yaml --out results/greensboro
    """
    output_format, engine = _check_choices(output_format, engine)
    source = EMBEDDED if config is None else str(config)
    request = Request(load_plan(config if config is not None else default_study_path()), source, ())
    _run_request(request, out or RESULTS / request.plan.base.name, overwrite, _Output(quiet, output_format, table),
                 engine, "run")


@app.command(cls=_OnceEach, short_help="Shin et al.'s published values beside foldopt's, paper and exact modes.")
def reproduce(
    out: Path = typer.Option(RESULTS / "reproduction", "--out", help="Results folder."),
    overwrite: bool = OVERWRITE,
    quiet: bool = QUIET,
    output_format: str = FORMAT,
    engine: str = ENGINE,
):
    """Reproduce Shin et al.'s study in paper and exact modes: their published values beside foldopt's.

    Writes reproduction.csv (the embedded study: ideal PV model) and reproduction_single_diode.csv
    (A-300 single-diode sub-panels with switching).
    """
    output_format, engine = _check_choices(output_format, engine)
    output = _Output(quiet, output_format)
    check_output(out, overwrite)
    with output.progress("reproducing Shin et al. (two PV models x two modes)"):
        from foldopt.api import reproduce as reproduce_paper
        from foldopt.output.report import write_reproduction

        result = reproduce_paper(engine)
        write_reproduction(result, out, overwrite, _INVOCATION)
    output.answer("reproduce", out, result.answer, None, [f"wrote {out}"])


# --- sweep angle | latitude | day | load ---------------------------------------------------------

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
    "objective.statistic": "--objective", "objective.visits": "--visits", "weather": "--weather", "albedo": "--albedo", "iam": "--iam",
    "switch_series": "--switch-series", "bypass_diodes": "--no-bypass", "exact_electrical": "--exact-electrical",
    "force_site": "--force-site", "load_profile": "--load-profile",
}
_FIELD = re.compile(r"^([A-Za-z_.]+)(\[\d+\])?")


def _rename_fields(line: str, options: dict = _OPTION_OF_FIELD) -> str:
    """A message's leading field path as the option that set it (``options``: field -> option)."""
    match = _FIELD.match(line)
    if match and match.group(1) in options:
        return options[match.group(1)] + line[match.end(1):]
    return line


def _choices(registry) -> str:
    return " | ".join(registry)


def _sweep_options(
    config: Optional[Path] = typer.Option(None, "--config", help=f"Study to start from [default: {EMBEDDED}]."),
    lat: Optional[str] = typer.Option(None, "--lat", help="Latitude [deg north], or a range start:stop:step."),
    lon: Optional[str] = typer.Option(None, "--lon", help="Longitude [deg east], or a range."),
    altitude: Optional[float] = typer.Option(None, "--altitude", help="Site altitude [m]."),
    timezone: Optional[str] = typer.Option(None, "--timezone", help="IANA name or UTC offset, e.g. UTC-08:00 "
                                           "[default: the longitude's standard offset]."),
    days: Optional[str] = typer.Option(None, "--days", "--date", help="A date YYYY-MM-DD, a range of days 1:365:7 "
                                       "or of dates, 'year' or 'equinoxes-solstices'."),
    year: Optional[int] = typer.Option(None, "--year", help="Year of day-of-year ranges [default: the study's]."),
    p_load: Optional[str] = typer.Option(None, "--p-load", help="Load [W], or a range start:stop:step."),
    load_profile: Optional[Path] = typer.Option(None, "--load-profile", help="A day's load instead of a constant: a "
                                                "CSV of time,watts rows (HH:MM, held until the next time)."),
    p_load_scale: Optional[str] = typer.Option(None, "--p-load-scale", help="Scale of the load profile [-], or a range "
                                               "such as 0.5:2:0.1 [default: 1]."),
    area: Optional[float] = typer.Option(None, "--area", help="Flat panel area [m^2]."),
    efficiency: Optional[float] = typer.Option(None, "--efficiency", help="PV efficiency [-] (ideal model; sets the "
                                               "b-model panel's area)."),
    tilt: Optional[str] = typer.Option(None, "--tilt", help="Panel tilt [deg], or a range [default: the study's, "
                                       "or |latitude| where the latitude changes]."),
    azimuth: Optional[float] = typer.Option(None, "--azimuth", help="Panel azimuth [deg from north] [default: the "
                                            "study's, or facing the equator where the latitude changes]."),
    mode: Optional[str] = typer.Option(None, "--mode", help=_choices(names.MODES) + " [default: the study's; exact "
                                       "where the site or day leaves the embedded study's]."),
    geometry: Optional[str] = typer.Option(None, "--geometry", help=_choices(names.GEOMETRIES)
                                           + " [default: azimuth-split in paper mode, hinge in exact]."),
    sky: Optional[str] = typer.Option(None, "--sky", help=_choices(names.SKIES) + "."),
    climate: Optional[str] = typer.Option(None, "--climate", help="Hottel's climate: "
                                          + _choices(names.HOTTEL_CLIMATES) + "."),
    weather: Optional[Path] = typer.Option(None, "--weather", help="TMY3 / EPW / PVGIS TMY file: its site and its "
                                           "whole year unless given."),
    force_site: bool = typer.Option(False, "--force-site", help="Keep --lat/--lon though far from the weather "
                                    "file's site."),
    transposition: Optional[str] = typer.Option(None, "--transposition", help=_choices(names.TRANSPOSITIONS) + "."),
    albedo: Optional[float] = typer.Option(None, "--albedo", help="Ground reflectance [-] (with diffuse light)."),
    iam: Optional[str] = typer.Option(None, "--iam", help="Incidence-angle modifier: " + _choices(names.IAMS) + "."),
    objective: Optional[str] = typer.Option(None, "--objective", help="One fold angle for all days, maximising: "
                                            "mean | min | worst-month | pNN (a percentile)."),
    visits: Optional[int] = typer.Option(None, "--visits", help="With --objective mean or worst-month: also the best "
                                         "re-fold schedule of 1 to this many fold settings a year (at most 12)."),
    tracker: Optional[str] = typer.Option(None, "--tracker", help=_choices(names.TRACKERS) + "."),
    tracker_standby: Optional[float] = typer.Option(None, "--tracker-standby", help="Tracker standby draw [W]."),
    pv_model: Optional[str] = typer.Option(None, "--pv-model", help=_choices(names.PV_MODELS) + "."),
    module: Optional[str] = typer.Option(None, "--module", help="single-diode: a module of pvlib's CEC database, any "
                                         "part of its name, e.g. CS5P-220M [default: the A-300 cell]."),
    connection: Optional[str] = typer.Option(None, "--connection", help=_choices(names.CONNECTIONS) + "."),
    switch_series: bool = typer.Option(False, "--switch-series", help="Switching may also choose series."),
    no_bypass: bool = typer.Option(False, "--no-bypass", help="Series without bypass diodes."),
    converter_efficiency: Optional[float] = typer.Option(None, "--converter-efficiency", help="Efficiency [-] of "
                                                         "each converter of connection independent."),
    temp_air: Optional[float] = typer.Option(None, "--temp-air", help="Air temperature [C] (I-V models)."),
    exact_electrical: bool = typer.Option(False, "--exact-electrical", help="Solve every step's I-V curves instead "
                                          "of the tables (slow)."),
    step_min: Optional[float] = typer.Option(None, "--step-min", help="Time step [min], a divisor of 1440."),
    angle_step: Optional[float] = typer.Option(None, "--angle-step", help="Fold-angle grid step [deg]."),
    settings: Optional[list[str]] = typer.Option(None, "--set", metavar="KEY=VALUE", help="Any study field (a dotted "
                                                 "key, a YAML value), e.g. --set tracker.gcr=0.4; repeatable."),
    out: Optional[Path] = typer.Option(None, "--out", help="Results folder [default: results/sweep-<axis>]."),
    overwrite: bool = OVERWRITE,
    quiet: bool = QUIET,
    output_format: str = FORMAT,
    engine: str = ENGINE,
    table: bool = TABLE,
):
    """The options of every sweep (its signature is theirs)."""


_SWEEP_HELP = {
    "angle": ("Every fold angle at one site, day and load (sweep.csv, summary.csv, the paper's plots). With a "
              "weather file: one fold angle for the file's whole year (--objective, default mean).",
              ["foldopt sweep angle", "foldopt sweep angle --lat -33.87 --lon 151.21 --timezone Australia/Sydney "
               "--date 2025-06-21", "foldopt sweep angle --weather configs/weather/723170TYA.CSV --p-load 2"]),
    "latitude": ("The study at every latitude of a range [default: -60:60:5], the panel tilted at |latitude| toward "
                 "the equator unless --tilt/--azimuth say otherwise: a row per case x design in results.csv, with "
                 "maps and curves.",
                 ["foldopt sweep latitude", "foldopt sweep latitude --lat -40:40:10 --p-load 1:9:2"]),
    "day": ("The study on every day of a range [default: 1:365:7 of the study's year].",
            ["foldopt sweep day", "foldopt sweep day --days year --objective p10"]),
    "load": ("The study at every load of a range [default: 20 loads from 5 % to 100 % of the panel's rating, area x "
             "1000 W/m^2 x efficiency].",
             ["foldopt sweep load", "foldopt sweep load --p-load 0.5:19:0.5 --pv-model single-diode"]),
}


_SWEEP_SHORT = {
    "angle": "Every fold angle at one site, day and load (or over a weather file's year).",
    "latitude": "Every latitude of a range [default: -60:60:5].",
    "day": "Every day of a range [default: 1:365:7].",
    "load": "Every load of a range [default: 5 % to 100 % of the panel's rating].",
}


def _register_sweep(axis: str) -> None:
    summary, examples = _SWEEP_HELP[axis]

    def command(**options):
        _sweep(axis, options)

    command.__signature__ = inspect.signature(_sweep_options)
    command.__annotations__ = dict(_sweep_options.__annotations__)
    command.__doc__ = summary + "\n\n\b\nExamples:\n" + "\n".join(f"  {example}" for example in examples)
    sweep_app.command(axis, cls=_OnceEach, short_help=_SWEEP_SHORT[axis])(command)


def _sweep(axis: str, options: dict) -> None:
    output_format, engine = _check_choices(options.pop("output_format"), options.pop("engine"))
    output = _Output(options.pop("quiet"), output_format, options.pop("table"))
    out, overwrite = options.pop("out"), options.pop("overwrite")
    config = options.pop("config")
    source = EMBEDDED if config is None else str(config)
    data, _ = read_study(config if config is not None else default_study_path())
    # --p-load and --p-load-scale both set p_load: a message names the one given.
    options_of = _OPTION_OF_FIELD if options["p_load_scale"] is None else {**_OPTION_OF_FIELD,
                                                                            "p_load": "--p-load-scale"}
    try:
        changes = _sweep_changes(options, data)
        changes["description"] = f"foldopt sweep {axis} from {source} (see command)"
        request = plan_request(data, changes, axis=axis, source=source, name=f"sweep-{axis}")
    except ConfigError as error:
        _fail(list(dict.fromkeys(_rename_fields(line, options_of) for line in error.errors)))
    _run_request(request, out or RESULTS / f"sweep-{axis}", overwrite, output, engine, f"sweep {axis}")


#: Sweep options -> the study field each sets (the request's changes; foldopt.studies.request does the rest).
_FIELD_OF_OPTION = {
    "lat": "site.latitude", "lon": "site.longitude", "altitude": "site.altitude", "timezone": "site.timezone",
    "days": "date", "year": "year", "p_load": "p_load", "p_load_scale": "p_load", "area": "panel.area",
    "efficiency": "panel.efficiency", "tilt": "panel.tilt", "azimuth": "panel.azimuth", "mode": "mode",
    "geometry": "geometry", "sky": "sky", "climate": "climate", "weather": "weather", "force_site": "force_site",
    "transposition": "transposition", "albedo": "albedo", "iam": "iam", "objective": "objective.statistic",
    "visits": "objective.visits", "tracker": "tracker.model", "tracker_standby": "tracker.standby_w",
    "pv_model": "pv_model", "module": "module", "connection": "connection", "switch_series": "switch_series",
    "no_bypass": "bypass_diodes", "converter_efficiency": "converter_efficiency", "temp_air": "temp_air",
    "exact_electrical": "exact_electrical", "step_min": "step_min", "angle_step": "fold_angles.step",
    "load_profile": "load_profile",
}
#: Options that take a value, a range or a list (:func:`foldopt.inputs.config.parse_values`).
_LISTED = ("lat", "lon", "p_load", "p_load_scale", "tilt", "days")
#: Flags and what each sets its field to.
_FLAGS = {"switch_series": True, "exact_electrical": True, "force_site": True, "no_bypass": False}


def _sweep_changes(options: dict, data: dict) -> dict:
    """The fields a sweep's options change, by field path; ``--set`` last."""
    changes, errors = {}, []
    if options["p_load_scale"] is not None:
        if options["p_load"] is not None:
            errors.append("--p-load / --p-load-scale: a constant load or a profile's scale, not both")
        elif data.get("load_profile") is None and options["load_profile"] is None:
            errors.append("--p-load-scale: scales a load profile; give one with --load-profile (or load_profile in "
                          "the study)")
    for option, value in options.items():
        if option == "settings" or value is None or value is False:
            continue
        if option in _FLAGS:
            value = _FLAGS[option]
        elif option in _LISTED:
            try:
                value = parse_values(value, numeric=option != "days")
            except ValueError as error:
                flag = "--" + option.replace("_", "-")
                errors.append(f"{flag} = {options[option]!r}: {error}")
                continue
        elif option == "weather":
            value = str(value)
        elif option == "load_profile":
            value = {"file": str(value)}
        changes[_FIELD_OF_OPTION[option]] = value
    if errors:
        raise ConfigError(errors)
    for setting in options["settings"] or ():
        changes.update([_setting(setting)])
    return changes


def _setting(setting: str) -> tuple[str, object]:
    """``KEY=VALUE``: a dotted field path and a YAML value."""
    key, separator, text = setting.partition("=")
    if not separator or not key.strip():
        raise ConfigError([f"--set = {setting!r}: expected KEY=VALUE, e.g. tracker.gcr=0.4"])
    source = f"--set {key}"
    try:
        value, _ = parse_study_text(text, source)
    except ConfigError as error:
        # parse_study_text's line is "config: <source> at line <n>: <problem>"; the problem is kept.
        problem = re.sub(rf"^config: {re.escape(source)}(?: at line \d+)?: ", "", error.errors[0])
        raise ConfigError([f"--set {key} = {text!r}: not a YAML value ({problem})"]) from None
    return key.strip(), value


for _axis in _SWEEP_HELP:
    _register_sweep(_axis)


# --- map ----------------------------------------------------------------------------------------


def _values(option: str, text: str) -> list[float]:
    """A value, a range start:stop:step or a comma list for ``option``, as a list
    (:func:`foldopt.inputs.config.parse_values`, the parser of every sweep axis too)."""
    try:
        values = parse_values(text)
    except ValueError as error:
        _fail([f"{option} = {text!r}: {error}"])
    return values if isinstance(values, list) else [values]


@app.command("map", cls=_OnceEach, short_help="Many sites on Dask: best fold angle, gains and tracker share worldwide.")
def map_(
    lat: Optional[str] = typer.Option(None, "--lat", help="Latitudes [deg north]: a range start:stop:step or a "
                                      "list [default: -60:60:10]."),
    lon: Optional[str] = typer.Option(None, "--lon", help="Longitudes [deg east] [default: -180:180:30]."),
    land_only: bool = typer.Option(False, "--land-only", help="Keep only the grid points on land."),
    sites: Optional[Path] = typer.Option(None, "--sites", help="CSV of named sites: name, latitude, longitude "
                                         "[, altitude, timezone], instead of a grid."),
    weather_dir: Optional[Path] = typer.Option(None, "--weather-dir", help="Folder of TMY3 / EPW / PVGIS files, each "
                                               "file a site (its site read from the file), instead of a grid."),
    p_load: Optional[str] = typer.Option(None, "--p-load", help="Loads [W]: a value, a range or a list [default: the "
                                         "study's]."),
    p_load_fraction: Optional[str] = typer.Option(None, "--p-load-fraction", help="Loads as fractions of each "
                                                  "site's flat peak, e.g. 0.1:0.9:0.1, instead of --p-load."),
    area: Optional[float] = typer.Option(None, "--area", help="Flat panel area [m^2]."),
    efficiency: Optional[float] = typer.Option(None, "--efficiency", help="PV efficiency [-]."),
    objective: str = typer.Option("mean", "--objective", help="What each period's fold angle maximises: mean | min | "
                                  "worst-month | pNN."),
    year: int = typer.Option(2025, "--year", help="Year of the clear-sky days (or that a typical year stands for)."),
    step_min: Optional[float] = typer.Option(None, "--step-min", help="Time step [min] [default: 5]."),
    angle_step: Optional[float] = typer.Option(None, "--angle-step", help="Fold-angle grid step [deg] [default: 1]."),
    config: Optional[Path] = typer.Option(None, "--config", help=f"Study to take the panel and models from [default: "
                                          f"{EMBEDDED}, in exact mode with the Ineichen clear sky]."),
    settings: Optional[list[str]] = typer.Option(None, "--set", metavar="KEY=VALUE", help="Any study field, e.g. "
                                                 "--set pv_model=single-diode; repeatable."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", help="A Dask scheduler's address (tcp://host:8786) "
                                            "or scheduler file [default: an embedded cluster]."),
    workers: Optional[int] = typer.Option(None, "--workers", help="Worker processes of the embedded cluster "
                                          "[default: one per core]."),
    chunk_sites: Optional[int] = typer.Option(None, "--chunk-sites", help="Sites per task [default: about 5 s of "
                                              "work]."),
    show_load: int = typer.Option(1, "--show-load", help="Which load (1 = the first) the world maps show."),
    show_period: str = typer.Option("year", "--show-period", help="Period the world maps show: year | DJF | MAM | "
                                    "JJA | SON."),
    resume: bool = typer.Option(False, "--resume", help="Finish an interrupted map in --out: only missing chunks "
                                "are computed."),
    out: Path = typer.Option(RESULTS / "map", "--out", help="Results folder."),
    overwrite: bool = OVERWRITE,
    quiet: bool = QUIET,
    output_format: str = FORMAT,
    engine: str = ENGINE,
):
    """Where folding pays: the best fold angle for the year and per season at every site of a grid,
    a CSV of sites or a folder of weather files, with flat, twofold and tracker t_solar and energy,
    gains and the tracker's break-even standby draw. Runs on Dask: an embedded cluster by default,
    any cluster with --scheduler. Writes map.parquet, map.csv, world maps and run.json; --resume
    finishes a killed run. With --format json the rows are the year's (map.parquet has every
    period).

    \b
    Examples:
      foldopt map --lat -60:60:10 --lon -180:180:30 --p-load 2 --area 0.108
      foldopt map --lat -60:70:1 --lon -180:179:1 --land-only --p-load-fraction 0.1:0.9:0.1
      foldopt map --sites sites.csv --scheduler tcp://127.0.0.1:8786
    """
    from foldopt.studies.worldmap import PERIODS

    output_format, engine = _check_choices(output_format, engine)
    output = _Output(quiet, output_format)
    errors = []
    if sum(source is not None for source in (sites, weather_dir)) + (lat is not None or lon is not None) > 1:
        errors.append("--lat/--lon, --sites, --weather-dir: give one source of sites")
    if land_only and (sites is not None or weather_dir is not None):
        errors.append("--land-only: only for a --lat/--lon grid")
    if p_load is not None and p_load_fraction is not None:
        errors.append("--p-load / --p-load-fraction: give loads one way")
    if show_period not in PERIODS:
        errors.append(f"--show-period = {show_period!r}: must be one of {', '.join(PERIODS)}")
    for option, value in (("--workers", workers), ("--chunk-sites", chunk_sites)):
        if value is not None and value < 1:
            errors.append(f"{option} = {value}: must be at least 1")
    if year_problem(year):
        errors.append(f"--year = {year}: {year_problem(year)}")
    if errors:
        _fail(errors)
    grid = sites is None and weather_dir is None
    # An empty --lat is no value (an error), not the default grid.
    latitudes = _values("--lat", "-60:60:10" if lat is None else lat) if grid else []
    longitudes = _values("--lon", "-180:180:30" if lon is None else lon) if grid else []
    for option, values, bound in (("--lat", latitudes, 90), ("--lon", longitudes, 180)):
        if any(not -bound <= value <= bound for value in values):
            errors.append(f"{option}: must be in [-{bound}, {bound}] deg")
    relative = p_load_fraction is not None
    loads = _values("--p-load-fraction", p_load_fraction) if relative else None
    if relative and any(not 0 < value <= 2 for value in loads):
        errors.append(f"--p-load-fraction = {p_load_fraction!r}: fractions must be in (0, 2]")
    if p_load is not None:
        loads = _values("--p-load", p_load)
        if any(not 0 < value <= 1e6 for value in loads):
            errors.append(f"--p-load = {p_load!r}: loads must be in (0, 1e+06] W")
    if errors:
        _fail(errors)
    from pydantic import ValidationError

    from foldopt.inputs.config import MAX_CASES, Objective
    from foldopt.studies.worldmap import grid_sites, map_study, read_sites, weather_sites

    try:
        Objective(statistic=objective)
    except ValidationError:
        _fail([f"--objective = {objective!r}: must be mean, min, worst-month or a percentile pNN (e.g. p10)"])
    data, _ = read_study(config if config is not None else default_study_path())
    if loads is None:
        loads = [float(data.get("p_load") or 1.0)]
    changes = {"objective": {"statistic": objective}}
    for key, field in (("area", "panel.area"), ("efficiency", "panel.efficiency"), ("step_min", "step_min")):
        value = {"area": area, "efficiency": efficiency, "step_min": step_min}[key]
        if value is not None:
            changes[field] = value
    if angle_step is not None:
        changes["fold_angles"] = {"start": angle_step, "stop": 180.0, "step": angle_step}
    study = map_study(data, embedded=config is None, **changes)
    for setting in settings or ():
        study = set_path(study, *_setting(setting))
    if sites is not None:
        site_list = read_sites(sites)
    elif weather_dir is not None:
        site_list = weather_sites(weather_dir)
    else:
        site_list = grid_sites(latitudes, longitudes, land_only)
        if not site_list:
            _fail(["--land-only: no grid point is on land"])
    if len(site_list) > MAX_CASES:
        _fail([f"sites: {len(site_list):,}; the limit is {MAX_CASES:,} (FOLDOPT_MAX_CASES raises it)"])
    if not 1 <= show_load <= len(loads):
        _fail([f"--show-load = {show_load}: must be in [1, {len(loads)}] (the map has "
               f"{len(loads)} load{'s' if len(loads) > 1 else ''})"])

    def announce(cluster: str, dashboard: str | None):
        if not quiet and not output.json:
            typer.echo(f"{cluster}; dashboard: {dashboard or 'none (pip install bokeh)'}", err=True)

    taken = [f"panel {study['panel']['area']:g} m^2" if area is None else None,
             f"P_load {loads[0]:g} W" if p_load is None and not relative else None,
             f"{study.get('pv_model', 'ideal')} PV model", f"{study.get('mode')} mode",
             f"{study.get('step_min'):g}-min steps" if step_min is None else None]
    defaults = {"study": EMBEDDED if config is None else str(config), "taken": [item for item in taken if item]}
    with output.progress(f"map: {len(site_list)} sites", total=len(site_list), unit="sites") as progress:
        from foldopt.api import world_map

        try:
            result, figures, answer = world_map(
                site_list, loads, out, study, relative, year, scheduler=scheduler, workers=workers,
                sites_per_chunk=chunk_sites or 0, resume=resume, overwrite=overwrite, engine=engine,
                show_load=show_load - 1, show_period=show_period, progress=progress, announce=announce,
                command=_INVOCATION, defaults=defaults)
        except ConfigError as error:
            _fail(list(dict.fromkeys(_rename_fields(line) for line in error.errors)))
    output.answer("map", out, answer, result.table[result.table["period"] == "year"].reset_index(drop=True),
                  [f"wrote {out} (map.parquet, map.csv, report.html, {', '.join(figures)})"])


# --- size ---------------------------------------------------------------------------------------


@app.command(cls=_OnceEach, short_help="Panel sizing: lifetime net benefit against area, flat and twofold.")
def size(
    config: Optional[Path] = typer.Argument(None, help=f"YAML study (one case) [default: the embedded {EMBEDDED}]."),
    areas: str = typer.Option("0.01:0.5:0.005", "--areas", help="Panel areas [m^2], start:stop:step."),
    cost_per_m2: Optional[float] = typer.Option(None, "--cost-per-m2", help=f"Panel cost [$/m^2] [default: "
                                                f"{PAPER_COST_PER_M2:g}, the cost Shin et al.'s 0.108 m^2 optimum implies]."),
    cost_per_w: Optional[float] = typer.Option(None, "--cost-per-w", help="Panel cost [$/W at STC], instead."),
    c_grid: float = typer.Option(C_GRID, "--c-grid", help="Grid energy price [$/kWh] (Shin et al.: 0.22)."),
    years: float = typer.Option(LIFETIME_YEARS, "--years", help="Lifetime [years] (Shin et al.: 20)."),
    days_per_year: float = typer.Option(DAYS_PER_YEAR, "--days-per-year", help="Days a year like the study's day."),
    out: Optional[Path] = typer.Option(None, "--out", help="Results folder [default: results/<study>-sizing]."),
    overwrite: bool = OVERWRITE,
    quiet: bool = QUIET,
    output_format: str = FORMAT,
    table: bool = TABLE,
):
    """Shin et al. Sec. IV-A panel sizing: the lifetime benefit C_grid x t_solar x P_load against the
    panel's cost, for flat and twofold panels of every area.

    \b
    Examples:
      foldopt size
      foldopt size --cost-per-w 0.9 --areas 0.02:0.3:0.002
    """
    output_format, _ = _check_choices(output_format, "numba")
    output = _Output(quiet, output_format, table)
    errors = _beyond_sizing_bounds({"--cost-per-m2": cost_per_m2, "--cost-per-w": cost_per_w, "--c-grid": c_grid,
                                    "--years": years, "--days-per-year": days_per_year})
    if errors:
        _fail(errors)
    plan = load_plan(config if config is not None else default_study_path())
    if plan.axes:
        _fail([f"config: {config} sweeps {', '.join(p for p, _ in plan.axes)}; size takes one case"])
    request = size_request(plan, EMBEDDED if config is None else str(config),
                           cost_per_m2 is not None or cost_per_w is not None)
    study = plan.base
    out = out or RESULTS / f"{study.name}-sizing"
    check_output(out, overwrite)
    from foldopt.api import size as size_panel

    try:
        with output.progress(f"sizing {study.name}"):
            from foldopt.output.report import write_sizing

            result = size_panel(study, areas, cost_per_m2, cost_per_w, c_grid, years, days_per_year, request=request)
            write_sizing(result, out, overwrite, _INVOCATION)
    except ConfigError as error:
        _fail([_sizing_option(line) for line in error.errors])
    output.answer("size", out, result.answer, result.table, [f"wrote {out}"], result.table)


#: The sizing's largest values and their units. Within them every benefit, cost and net benefit
#: over areas up to 1000 m^2 stays far below float overflow (the largest is some 1e13 $); beyond
#: them a value is a slip, and 1e308 $/m^2 would print as a 309-digit net benefit, or as -inf.
_SIZING_MAX = {"--cost-per-m2": (1e9, " $/m^2"), "--cost-per-w": (1e6, " $/W"), "--c-grid": (1e3, " $/kWh"),
               "--years": (1e3, " years"), "--days-per-year": (366, " days")}


def _beyond_sizing_bounds(values: dict) -> list[str]:
    """One line per sizing option (``values``: option -> value or None) that is no number in
    (0, :data:`_SIZING_MAX`]."""
    return [f"{option} = {values[option]:g}: must be a finite number > 0 and at most {largest:g}{unit}"
            for option, (largest, unit) in _SIZING_MAX.items()
            if values[option] is not None and not 0 < values[option] <= largest]


#: The sizing's parameters as the command line names them, longest first.
_OPTION_OF_SIZING = {"cost_per_m2 / cost_per_w": "--cost-per-m2 / --cost-per-w", "c_grid_usd_per_kwh": "--c-grid",
                     "days_per_year": "--days-per-year", "cost_per_m2": "--cost-per-m2", "cost_per_w": "--cost-per-w",
                     "years": "--years", "areas": "--areas"}


def _sizing_option(line: str) -> str:
    for field, option in _OPTION_OF_SIZING.items():
        if line.startswith(field):
            return option + line[len(field):]
    return line


def main():  # pragma: no cover - console-script entry point
    app()


if __name__ == "__main__":  # pragma: no cover
    main()
