"""``foldopt sweep angle | latitude | day | load``: one design variable over a range, everything
else from the study. The commands share their options (:func:`sweep_options`' signature); the
request they make is :func:`foldopt.studies.request.sweep_request`'s.
"""

from __future__ import annotations

import copy
import inspect
from pathlib import Path
from typing import Annotated, get_args

import typer

from foldopt import names
from foldopt.cli.options import (
    EMBEDDED,
    RESULTS,
    AngleStep,
    Area,
    Efficiency,
    Engine,
    OutputFormat,
    Overwrite,
    Quiet,
    MinSoc,
    Settings,
    StorageWh,
    Table,
    check_choices,
    out_option,
    StepMin,
)
from foldopt.cli.output import Output, fail
from foldopt.cli.run import run_request
from foldopt.errors import ConfigError
from foldopt.names import DEFAULT_ENGINE

#: The sweep group's help and its line in the command list.
HELP = "Sweep one design variable over a range, everything else from the study."
SHORT_HELP = "Sweep fold angle, latitude, day or load [default ranges]."


def _choices(registry) -> str:
    return " | ".join(registry)


def sweep_options(
    config: Annotated[
        Path | None, typer.Option("--config", help=f"Study to start from [default: {EMBEDDED}].")
    ] = None,
    lat: Annotated[str | None, typer.Option("--lat", help="Latitude [deg north].")] = None,
    lon: Annotated[str | None, typer.Option("--lon", help="Longitude [deg east].")] = None,
    altitude: Annotated[float | None, typer.Option("--altitude", help="Site altitude [m].")] = None,
    timezone: Annotated[
        str | None,
        typer.Option(
            "--timezone",
            help="IANA name or UTC offset, e.g. UTC-08:00 "
            "[default: the longitude's standard offset].",
        ),
    ] = None,
    days: Annotated[str | None, typer.Option("--days", "--date", help="A date YYYY-MM-DD.")] = None,
    year: Annotated[
        int | None,
        typer.Option("--year", help="Year of day-of-year ranges [default: the study's]."),
    ] = None,
    p_load: Annotated[str | None, typer.Option("--p-load", help="Load [W].")] = None,
    load_profile: Annotated[
        Path | None,
        typer.Option(
            "--load-profile",
            help="A day's load instead of a constant: "
            "a CSV of time,watts rows (HH:MM, held until the next "
            "time).",
        ),
    ] = None,
    p_load_scale: Annotated[
        str | None,
        typer.Option("--p-load-scale", help="Scale of the load profile [-] [default: 1]."),
    ] = None,
    area: Area = None,
    efficiency: Efficiency = None,
    tilt: Annotated[
        str | None,
        typer.Option(
            "--tilt",
            help="Panel tilt [deg] [default: the study's, or |latitude| "
            "where the latitude changes].",
        ),
    ] = None,
    azimuth: Annotated[
        float | None,
        typer.Option(
            "--azimuth",
            help="Panel azimuth [deg from north] [default: the "
            "study's, or facing the equator where the latitude "
            "changes].",
        ),
    ] = None,
    mode: Annotated[
        str | None,
        typer.Option(
            "--mode",
            help=_choices(names.MODES) + " [default: the study's; exact "
            "where the site or day leaves the embedded study's].",
        ),
    ] = None,
    geometry: Annotated[
        str | None,
        typer.Option(
            "--geometry",
            help=_choices(names.GEOMETRIES) + " [default: "
            "azimuth-split in paper mode, hinge in exact].",
        ),
    ] = None,
    sky: Annotated[str | None, typer.Option("--sky", help=_choices(names.SKIES) + ".")] = None,
    climate: Annotated[
        str | None,
        typer.Option(
            "--climate", help="Hottel's climate: " + _choices(names.HOTTEL_CLIMATES) + "."
        ),
    ] = None,
    weather: Annotated[
        Path | None,
        typer.Option(
            "--weather",
            help="Weather file: an hourly TMY3 / EPW / PVGIS TMY "
            "(its site and whole year) or a measured file (its days, at its "
            "step); or a source fetched for the site and cached: "
            + _choices(names.WEATHER_SOURCES)
            + ".",
        ),
    ] = None,
    years: Annotated[
        str | None,
        typer.Option(
            "--years",
            help="A weather source's years START:END, e.g. 2005:2020 (PVGIS TMY: its months "
            "chosen from them, at least 10; PVGIS hourly: the series' years, each day a block) "
            "[default: the service's record].",
        ),
    ] = None,
    offline: Annotated[
        bool,
        typer.Option(
            "--offline",
            help="Fetch nothing: a weather source from foldopt's cache only (FOLDOPT_OFFLINE=1).",
        ),
    ] = False,
    weather_format: Annotated[
        str | None,
        typer.Option(
            "--weather-format",
            help=_choices(names.WEATHER_FORMATS)
            + " [default: from the extension, hourly formats].",
        ),
    ] = None,
    members: Annotated[
        int | None,
        typer.Option(
            "--members",
            help="An hourly file's cloud ensemble: this many synthetic minute series (2 to 200).",
        ),
    ] = None,
    seed: Annotated[
        int | None, typer.Option("--seed", help="The ensemble's seed [default: 0].")
    ] = None,
    force_site: Annotated[
        bool,
        typer.Option(
            "--force-site", help="Keep --lat/--lon though far from the weather file's site."
        ),
    ] = False,
    transposition: Annotated[
        str | None, typer.Option("--transposition", help=_choices(names.TRANSPOSITIONS) + ".")
    ] = None,
    albedo: Annotated[
        float | None, typer.Option("--albedo", help="Ground reflectance [-] (with diffuse light).")
    ] = None,
    iam: Annotated[
        str | None,
        typer.Option("--iam", help="Incidence-angle modifier: " + _choices(names.IAMS) + "."),
    ] = None,
    objective: Annotated[
        str | None,
        typer.Option(
            "--objective",
            help="One fold angle for all days, maximising: "
            "mean | min | worst-month | pNN (a percentile).",
        ),
    ] = None,
    visits: Annotated[
        int | None,
        typer.Option(
            "--visits",
            help="With --objective mean or worst-month: also the "
            "best re-fold schedule of 1 to this many fold settings a year (at "
            "most 12).",
        ),
    ] = None,
    tracker: Annotated[
        str | None, typer.Option("--tracker", help=_choices(names.TRACKERS) + ".")
    ] = None,
    tracker_standby: Annotated[
        float | None, typer.Option("--tracker-standby", help="Tracker standby draw [W].")
    ] = None,
    pv_model: Annotated[
        str | None, typer.Option("--pv-model", help=_choices(names.PV_MODELS) + ".")
    ] = None,
    module: Annotated[
        str | None,
        typer.Option(
            "--module",
            help="single-diode: a module of pvlib's CEC database, "
            "any part of its name, e.g. CS5P-220M [default: the A-300 "
            "cell].",
        ),
    ] = None,
    connection: Annotated[
        str | None, typer.Option("--connection", help=_choices(names.CONNECTIONS) + ".")
    ] = None,
    switch_series: Annotated[
        bool, typer.Option("--switch-series", help="Switching may also choose series.")
    ] = False,
    no_bypass: Annotated[
        bool, typer.Option("--no-bypass", help="Series without bypass diodes.")
    ] = False,
    converter_efficiency: Annotated[
        float | None,
        typer.Option(
            "--converter-efficiency",
            help="Efficiency [-] of each converter of connection independent.",
        ),
    ] = None,
    horizon: Annotated[
        Path | None,
        typer.Option(
            "--horizon",
            help="The site's horizon: a PVGIS horizon file (JSON "
            "or CSV), a CSV azimuth,elevation [deg], or pvgis (fetched from PVGIS for --lat/--lon).",
        ),
    ] = None,
    blocking_diode: Annotated[
        str | None,
        typer.Option(
            "--blocking-diode",
            help="Blocking diodes in parallel: " + _choices(names.DIODE_MODELS) + " (I-V models).",
        ),
    ] = None,
    bypass_diode: Annotated[
        str | None,
        typer.Option(
            "--bypass-diode",
            help="Bypass diodes in series: " + _choices(names.DIODE_MODELS) + " (I-V models).",
        ),
    ] = None,
    converter: Annotated[
        str | None,
        typer.Option(
            "--converter",
            help="The MPPT converter's efficiency: " + _choices(names.CONVERTER_MODELS) + ".",
        ),
    ] = None,
    load_voltage: Annotated[
        float | None,
        typer.Option(
            "--load-voltage",
            help="Couple the load directly at this voltage [V], no converter (I-V models).",
        ),
    ] = None,
    switch_resistance: Annotated[
        float | None,
        typer.Option(
            "--switch-resistance",
            help="On-resistance [ohm] of the "
            "switch in each sub-panel's path (connection "
            "switching).",
        ),
    ] = None,
    temp_air: Annotated[
        float | None, typer.Option("--temp-air", help="Air temperature [C] (I-V models).")
    ] = None,
    exact_electrical: Annotated[
        bool,
        typer.Option(
            "--exact-electrical", help="Solve every step's I-V curves instead of the tables (slow)."
        ),
    ] = False,
    step_min: StepMin = None,
    angle_step: AngleStep = None,
    storage_wh: StorageWh = None,
    min_soc: MinSoc = None,
    settings: Settings = None,
    out: Annotated[Path | None, out_option()] = None,
    overwrite: Overwrite = False,
    quiet: Quiet = False,
    output_format: OutputFormat = "table",
    engine: Engine = DEFAULT_ENGINE,
    table: Table = False,
):
    """The options of every sweep (its signature is theirs, through :func:`signature`)."""


#: What each option that can set a field to several values says of them, where the command lets
#: that field vary (:func:`signature`).
_SEVERAL = {
    "lat": "a range start:stop:step or a list a,b,c",
    "lon": "a range start:stop:step or a list a,b,c",
    "days": "a range of days 1:365:7 or of dates, 'year', 'equinoxes-solstices' or a list of dates a,b",
    "p_load": "a range start:stop:step or a list a,b,c",
    "p_load_scale": "a range such as 0.5:2:0.1 or a list a,b,c",
    "tilt": "a range start:stop:step or a list a,b,c",
}
#: The options each command lets take several values, and on what condition (the rules are the
#: library's: :func:`foldopt.studies.request.plan_request` for ``sweep angle``,
#: :func:`foldopt.studies.joint.optimize_plan` for ``optimize``; every other sweep varies any).
_VARYING = {
    "angle": {"days": "with --objective or --weather"},
    "latitude": dict.fromkeys(_SEVERAL, ""),
    "day": dict.fromkeys(_SEVERAL, ""),
    "load": dict.fromkeys(_SEVERAL, ""),
    "optimize": {"days": "", "p_load": "", "p_load_scale": ""},
}


def signature(command: str, out: str) -> inspect.Signature:
    """:func:`sweep_options`' signature as one command takes it: the options that command lets take
    several values say so (:data:`_VARYING`), the others take one, and ``--out`` names its default.

    Parameters
    ----------
    command : str
        A sweep axis or ``optimize``.
    out : str
        The results folder's default, as the help gives it.

    Returns
    -------
    inspect.Signature
    """
    parameters = []
    for parameter in inspect.signature(sweep_options, eval_str=True).parameters.values():
        kind, option = get_args(parameter.annotation)
        if parameter.name in _VARYING[command]:
            condition, values = _VARYING[command][parameter.name], _SEVERAL[parameter.name]
            several = f"; {condition}, also {values}" if condition else f", or {values}"
            head, bracket, tail = option.help.partition(" [default")
            option = copy.copy(option)
            option.help = head.rstrip(".") + several + (bracket + tail if bracket else ".")
        elif parameter.name == "out":
            option = out_option(shown=out)
        parameters.append(parameter.replace(annotation=Annotated[kind, option]))
    return inspect.Signature(parameters)


#: Each sweep's help: what it does, and examples.
_SWEEP_HELP = {
    "angle": (
        "Every fold angle at one site, day and load (sweep.csv, summary.csv, the paper's plots). With a "
        "weather file: one fold angle for the file's whole year (--objective, default mean).",
        [
            "foldopt sweep angle",
            "foldopt sweep angle --lat -33.87 --lon 151.21 --timezone Australia/Sydney "
            "--date 2025-06-21",
            "foldopt sweep angle --weather configs/weather/723170TYA.CSV --p-load 2",
        ],
    ),
    "latitude": (
        "The study at every latitude of a range [default: -60:60:5], the panel tilted at |latitude| toward "
        "the equator unless --tilt/--azimuth say otherwise: a row per case x design in results.csv, with "
        "maps and curves.",
        ["foldopt sweep latitude", "foldopt sweep latitude --lat -40:40:10 --p-load 1:9:2"],
    ),
    "day": (
        "The study on every day of a range [default: 1:365:7 of the study's year].",
        ["foldopt sweep day", "foldopt sweep day --days year --objective p10"],
    ),
    "load": (
        "The study at every load of a range [default: 20 loads from 5 % to 100 % of the panel's rating, area x "
        "1000 W/m^2 x efficiency].",
        ["foldopt sweep load", "foldopt sweep load --p-load 0.5:19:0.5 --pv-model single-diode"],
    ),
}
#: Each sweep's line in the command list.
_SWEEP_SHORT = {
    "angle": "Every fold angle at one site, day and load (or over a weather file's year).",
    "latitude": "Every latitude of a range [default: -60:60:5].",
    "day": "Every day of a range [default: 1:365:7].",
    "load": "Every load of a range [default: 5 % to 100 % of the panel's rating].",
}


def _sweep(axis: str, options: dict) -> None:
    output_format, engine = check_choices(options.pop("output_format"), options.pop("engine"))
    output = Output(options.pop("quiet"), output_format, options.pop("table"))
    out, overwrite = options.pop("out"), options.pop("overwrite")
    config, settings = options.pop("config"), options.pop("settings") or ()
    from foldopt.studies.request import make_request  # the study's modules once a command runs

    try:
        request = make_request(f"sweep {axis}", config, options=options, settings=settings)
    except ConfigError as error:
        fail(list(dict.fromkeys(error.errors)))
    run_request(
        request, out or RESULTS / f"sweep-{axis}", overwrite, output, engine, f"sweep {axis}"
    )


def _command(axis: str):
    """The command of one sweep axis: the options of every sweep, the axis's own help."""
    summary, examples = _SWEEP_HELP[axis]

    def command(**options):
        _sweep(axis, options)

    command.__signature__ = signature(axis, f"results/sweep-{axis}")
    command.__doc__ = (
        summary + "\n\n\b\nExamples:\n" + "\n".join(f"  {example}" for example in examples)
    )
    return command


#: The commands of this module: name, function, and the line the command list shows.
COMMANDS = [(axis, _command(axis), _SWEEP_SHORT[axis]) for axis in _SWEEP_HELP]
