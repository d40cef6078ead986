"""``foldopt sweep angle | latitude | day | load``: one design variable over a range, everything
else from the study. The commands share their options (:func:`sweep_options`' signature); the
request they make is :func:`foldopt.studies.request.sweep_request`'s.
"""

from __future__ import annotations

import copy
import inspect
from pathlib import Path
from typing import Optional

import typer

from foldopt import names
from foldopt.cli.options import (ANGLE_STEP, AREA, EFFICIENCY, EMBEDDED, ENGINE, FORMAT, OVERWRITE,
                                 QUIET, RESULTS, SETTINGS, TABLE, check_choices, out_option, rename_fields,
                                 step_min_option)
from foldopt.cli.output import Output, fail
from foldopt.cli.run import run_request
from foldopt.errors import ConfigError
from foldopt.studies.request import sweep_request

#: The sweep group's help and its line in the command list.
HELP = "Sweep one design variable over a range, everything else from the study."
SHORT_HELP = "Sweep fold angle, latitude, day or load [default ranges]."


def _choices(registry) -> str:
    return " | ".join(registry)


def sweep_options(
    config: Optional[Path] = typer.Option(None, "--config", help=f"Study to start from [default: {EMBEDDED}]."),
    lat: Optional[str] = typer.Option(None, "--lat", help="Latitude [deg north]."),
    lon: Optional[str] = typer.Option(None, "--lon", help="Longitude [deg east]."),
    altitude: Optional[float] = typer.Option(None, "--altitude", help="Site altitude [m]."),
    timezone: Optional[str] = typer.Option(None, "--timezone", help="IANA name or UTC offset, e.g. UTC-08:00 "
                                           "[default: the longitude's standard offset]."),
    days: Optional[str] = typer.Option(None, "--days", "--date", help="A date YYYY-MM-DD."),
    year: Optional[int] = typer.Option(None, "--year", help="Year of day-of-year ranges [default: the study's]."),
    p_load: Optional[str] = typer.Option(None, "--p-load", help="Load [W]."),
    load_profile: Optional[Path] = typer.Option(None, "--load-profile", help="A day's load instead of a constant: a "
                                                "CSV of time,watts rows (HH:MM, held until the next time)."),
    p_load_scale: Optional[str] = typer.Option(None, "--p-load-scale", help="Scale of the load profile [-] "
                                               "[default: 1]."),
    area: Optional[float] = AREA,
    efficiency: Optional[float] = EFFICIENCY,
    tilt: Optional[str] = typer.Option(None, "--tilt", help="Panel tilt [deg] [default: the study's, or |latitude| "
                                       "where the latitude changes]."),
    azimuth: Optional[float] = typer.Option(None, "--azimuth", help="Panel azimuth [deg from north] [default: the "
                                            "study's, or facing the equator where the latitude changes]."),
    mode: Optional[str] = typer.Option(None, "--mode", help=_choices(names.MODES) + " [default: the study's; exact "
                                       "where the site or day leaves the embedded study's]."),
    geometry: Optional[str] = typer.Option(None, "--geometry", help=_choices(names.GEOMETRIES)
                                           + " [default: azimuth-split in paper mode, hinge in exact]."),
    sky: Optional[str] = typer.Option(None, "--sky", help=_choices(names.SKIES) + "."),
    climate: Optional[str] = typer.Option(None, "--climate", help="Hottel's climate: "
                                          + _choices(names.HOTTEL_CLIMATES) + "."),
    weather: Optional[Path] = typer.Option(None, "--weather", help="Weather file: an hourly TMY3 / EPW / PVGIS TMY "
                                           "(its site and whole year) or a measured file (its days, at its step)."),
    weather_format: Optional[str] = typer.Option(None, "--weather-format", help=_choices(names.WEATHER_FORMATS)
                                                  + " [default: from the extension, hourly formats]."),
    members: Optional[int] = typer.Option(None, "--members", help="An hourly file's cloud ensemble: this many "
                                          "synthetic minute series (2 to 200)."),
    seed: Optional[int] = typer.Option(None, "--seed", help="The ensemble's seed [default: 0]."),
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
    horizon: Optional[Path] = typer.Option(None, "--horizon", help="The site's horizon: a PVGIS horizon file (JSON "
                                           "or CSV) or a CSV azimuth,elevation [deg]."),
    blocking_diode: Optional[str] = typer.Option(None, "--blocking-diode", help="Blocking diodes in parallel: "
                                                 + _choices(names.DIODE_MODELS) + " (I-V models)."),
    bypass_diode: Optional[str] = typer.Option(None, "--bypass-diode", help="Bypass diodes in series: "
                                               + _choices(names.DIODE_MODELS) + " (I-V models)."),
    converter: Optional[str] = typer.Option(None, "--converter", help="The MPPT converter's efficiency: "
                                            + _choices(names.CONVERTER_MODELS) + "."),
    load_voltage: Optional[float] = typer.Option(None, "--load-voltage", help="Couple the load directly at this "
                                                 "voltage [V], no converter (I-V models)."),
    switch_resistance: Optional[float] = typer.Option(None, "--switch-resistance", help="On-resistance [ohm] of "
                                                      "the switch in each sub-panel's path (connection switching)."),
    temp_air: Optional[float] = typer.Option(None, "--temp-air", help="Air temperature [C] (I-V models)."),
    exact_electrical: bool = typer.Option(False, "--exact-electrical", help="Solve every step's I-V curves instead "
                                          "of the tables (slow)."),
    step_min: Optional[float] = step_min_option(),
    angle_step: Optional[float] = ANGLE_STEP,
    settings: Optional[list[str]] = SETTINGS,
    out: Optional[Path] = out_option(),
    overwrite: bool = OVERWRITE,
    quiet: bool = QUIET,
    output_format: str = FORMAT,
    engine: str = ENGINE,
    table: bool = TABLE,
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
    "latitude": dict.fromkeys(_SEVERAL, ""), "day": dict.fromkeys(_SEVERAL, ""), "load": dict.fromkeys(_SEVERAL, ""),
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
    for parameter in inspect.signature(sweep_options).parameters.values():
        option = copy.copy(parameter.default)
        if parameter.name in _VARYING[command]:
            condition, values = _VARYING[command][parameter.name], _SEVERAL[parameter.name]
            several = f"; {condition}, also {values}" if condition else f", or {values}"
            head, bracket, tail = option.help.partition(" [default")
            option.help = head.rstrip(".") + several + (bracket + tail if bracket else ".")
        elif parameter.name == "out":
            option = out_option(shown=out)
        parameters.append(parameter.replace(default=option))
    return inspect.Signature(parameters)


#: Each sweep's help: what it does, and examples.
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
    config = options.pop("config")
    # Of the options that set one field (--p-load, --p-load-scale), a message names the one given.
    options_of = names.option_labels({name for name, value in options.items() if value is not None})
    try:
        request = sweep_request(config, options, axis, EMBEDDED if config is None else str(config))
    except ConfigError as error:
        fail(list(dict.fromkeys(rename_fields(line, options_of) for line in error.errors)))
    run_request(request, out or RESULTS / f"sweep-{axis}", overwrite, output, engine, f"sweep {axis}")


def _command(axis: str):
    """The command of one sweep axis: the options of every sweep, the axis's own help."""
    summary, examples = _SWEEP_HELP[axis]

    def command(**options):
        _sweep(axis, options)

    command.__signature__ = signature(axis, f"results/sweep-{axis}")
    command.__annotations__ = dict(sweep_options.__annotations__)
    command.__doc__ = summary + "\n\n\b\nExamples:\n" + "\n".join(f"  {example}" for example in examples)
    return command


#: The commands of this module: name, function, and the line the command list shows.
COMMANDS = [(axis, _command(axis), _SWEEP_SHORT[axis]) for axis in _SWEEP_HELP]
