"""The options the commands share, each declared once, and the words of their errors.

A command takes a shared option by annotating a parameter with it, the default after it
(``overwrite: Overwrite = False``). An option that sets a study field several values where the
command sweeps it (``--lat``, ``--days``, ``--p-load``...) has two types, one value and several
(``Latitude``, ``Latitudes``), whose help says which it takes; every sweep and ``optimize`` take
every option that sets a study field (:data:`foldopt.names.FIELD_OPTIONS`). An option whose help
names a command's own default (``--out``, the study argument) is made by one function here, which the
command annotates with (``out: Annotated[Path | None, out_option(shown="results/<study name>")] =
None``). Errors from the library name study fields; :func:`rename_fields` says them as the options
that set them.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated

import typer

from foldopt import names
from foldopt.cli.output import fail
from foldopt.names import OPTION_OF_FIELD

#: Where results folders go unless ``--out`` says otherwise.
RESULTS = Path("results")
#: The embedded study, as help texts and answers name it.
EMBEDDED = "configs/shin2015.yaml"

Overwrite = Annotated[bool, typer.Option("--overwrite", help="Replace an existing results folder.")]
Quiet = Annotated[
    bool,
    typer.Option(
        "--quiet", "-q", help="Print nothing but errors (with --format json: the JSON only)."
    ),
]
OutputFormat = Annotated[
    str,
    typer.Option(
        "--format",
        help=f"{' | '.join(names.OUTPUT_FORMATS)}: a short answer, or "
        "one JSON document on stdout for scripts.",
    ),
]
Engine = Annotated[
    str,
    typer.Option(
        "--engine",
        help=" | ".join(f"{name} ({names.ENGINES.describe(name)})" for name in names.ENGINES) + ".",
    ),
]
Table = Annotated[
    bool, typer.Option("--table", help="Also print the full table (it is always in the CSV files).")
]
Area = Annotated[float | None, typer.Option("--area", help="Flat panel area [m^2].")]
Efficiency = Annotated[
    float | None,
    typer.Option(
        "--efficiency", help="PV efficiency [-] (ideal model; sets the b-model panel's area)."
    ),
]
AngleStep = Annotated[
    float | None,
    typer.Option("--angle-step", help="Fold-angle grid step [deg] [default: the study's]."),
]
StepMin = Annotated[
    float | None,
    typer.Option("--step-min", help="Time step [min], a divisor of 1440 [default: the study's]."),
]
StorageWh = Annotated[
    float | None,
    typer.Option(
        "--storage-wh",
        help="A buffer behind a charge controller: its usable energy [Wh] (0: storage-less); "
        "--set storage.<field> for the rest [default: none].",
    ),
]
TargetH = Annotated[
    float | None,
    typer.Option(
        "--target-h",
        help="Hours a day the buffer must run the load, (0, 24] (storage.target.powered_h).",
    ),
]
MinSoc = Annotated[
    float | None,
    typer.Option(
        "--min-soc",
        help="The charge controller's cut-off: the state of charge [-] at which it disconnects "
        "the load [default: the storage preset's, else 0].",
    ),
]
Settings = Annotated[
    list[str] | None,
    typer.Option(
        "--set",
        metavar="KEY=VALUE",
        help="Any study field (a dotted "
        "key, a YAML value), e.g. --set pv_model=single-diode; "
        "repeatable.",
    ),
]


# --- The options of every sweep and of optimize: the study they start from and its fields ------

#: What an option that takes several values says of them.
_RANGE_OR_LIST = "a range start:stop:step or a list a,b,c"
#: ... and ``--days``, of days.
_DAYS = "a range of days 1:365:7 or of dates, 'year', 'equinoxes-solstices' or a list of dates a,b"


def _choices(registry) -> str:
    return " | ".join(registry)


def _several(text: str, values: str = _RANGE_OR_LIST, condition: str = "") -> str:
    """The help of an option that also takes several values, from its help for one.

    Parameters
    ----------
    text : str
        The help for one value, ending in a full stop or a ``[default: ...]``.
    values : str
        What the option takes for several values.
    condition : str
        Where it takes them (``with --objective or --weather``); empty where it always does.

    Returns
    -------
    str
        ``Latitude [deg north], or a range start:stop:step or a list a,b,c.``
    """
    several = f"; {condition}, also {values}" if condition else f", or {values}"
    head, bracket, tail = text.partition(" [default")
    return head.rstrip(".") + several + (bracket + tail if bracket else ".")


_LATITUDE = "Latitude [deg north]."
_LONGITUDE = "Longitude [deg east]."
_DATE = "A date YYYY-MM-DD."
_LOAD = "Load [W]."
_LOAD_SCALE = "Scale of the load profile [-] [default: 1]."
_TILT = "Panel tilt [deg] [default: the study's, or |latitude| where the latitude changes]."

Config = Annotated[
    Path | None, typer.Option("--config", help=f"Study to start from [default: {EMBEDDED}].")
]
#: ``--lat``: one latitude, or (``Latitudes``) where the command sweeps it, several.
Latitude = Annotated[str | None, typer.Option("--lat", help=_LATITUDE)]
Latitudes = Annotated[str | None, typer.Option("--lat", help=_several(_LATITUDE))]
Longitude = Annotated[str | None, typer.Option("--lon", help=_LONGITUDE)]
Longitudes = Annotated[str | None, typer.Option("--lon", help=_several(_LONGITUDE))]
Altitude = Annotated[float | None, typer.Option("--altitude", help="Site altitude [m].")]
Timezone = Annotated[
    str | None,
    typer.Option(
        "--timezone",
        help="IANA name or UTC offset, e.g. UTC-08:00 [default: the longitude's standard offset].",
    ),
]
#: ``--days``: one day, or several where the answer is one fold angle for them all
#: (:func:`foldopt.studies.request.make_request`'s ``sweep angle``).
Date = Annotated[
    str | None,
    typer.Option("--days", "--date", help=_several(_DATE, _DAYS, "with --objective or --weather")),
]
#: ``--days``: one day or several.
Days = Annotated[str | None, typer.Option("--days", "--date", help=_several(_DATE, _DAYS))]
Year = Annotated[
    int | None, typer.Option("--year", help="Year of day-of-year ranges [default: the study's].")
]
Load = Annotated[str | None, typer.Option("--p-load", help=_LOAD)]
Loads = Annotated[str | None, typer.Option("--p-load", help=_several(_LOAD))]
LoadProfile = Annotated[
    Path | None,
    typer.Option(
        "--load-profile",
        help="A day's load instead of a constant: a CSV of time,watts rows (HH:MM, held until "
        "the next time).",
    ),
]
LoadScale = Annotated[str | None, typer.Option("--p-load-scale", help=_LOAD_SCALE)]
LoadScales = Annotated[
    str | None,
    typer.Option(
        "--p-load-scale", help=_several(_LOAD_SCALE, "a range such as 0.5:2:0.1 or a list a,b,c")
    ),
]
Tilt = Annotated[str | None, typer.Option("--tilt", help=_TILT)]
Tilts = Annotated[str | None, typer.Option("--tilt", help=_several(_TILT))]
Azimuth = Annotated[
    float | None,
    typer.Option(
        "--azimuth",
        help="Panel azimuth [deg from north] [default: the study's, or facing the equator where "
        "the latitude changes].",
    ),
]
Planes = Annotated[
    str | None,
    typer.Option(
        "--planes",
        metavar="TILT/AZIMUTH,TILT/AZIMUTH",
        help="An existing array's two halves as they stand [deg], e.g. 9/14,9/194: the base "
        "tilt, azimuth and fold angle that make them (--geometry) are found and that design "
        "evaluated beside the best fold.",
    ),
]
FoldAngle = Annotated[
    float | None,
    typer.Option(
        "--fold-angle",
        help="Evaluate this one fold angle [deg] in (0, 180] (the grid "
        "fold_angles={start: X, stop: X, step: 1}) [default: the study's grid].",
    ),
]
Mode = Annotated[
    str | None,
    typer.Option(
        "--mode",
        help=_choices(names.MODES) + " [default: the study's; exact where the site or day leaves "
        "the embedded study's].",
    ),
]
Geometry = Annotated[
    str | None,
    typer.Option(
        "--geometry",
        help=_choices(names.GEOMETRIES)
        + " [default: azimuth-split in paper mode, hinge in exact].",
    ),
]
Sky = Annotated[str | None, typer.Option("--sky", help=_choices(names.SKIES) + ".")]
Climate = Annotated[
    str | None,
    typer.Option("--climate", help="Hottel's climate: " + _choices(names.HOTTEL_CLIMATES) + "."),
]
WeatherFileOrSource = Annotated[
    Path | None,
    typer.Option(
        "--weather",
        help="Weather file: an hourly TMY3 / EPW / PVGIS TMY (its site and whole year) or a "
        "measured file (its days, at its step); or a source fetched for the site and cached: "
        + _choices(names.WEATHER_SOURCES)
        + ".",
    ),
]
WeatherYears = Annotated[
    str | None,
    typer.Option(
        "--years",
        help="A weather source's years START:END, e.g. 2005:2020 (PVGIS TMY: its months chosen "
        "from them, at least 10; PVGIS hourly: the series' years, each day a block) [default: "
        "the service's record].",
    ),
]
Offline = Annotated[
    bool,
    typer.Option(
        "--offline",
        help="Fetch nothing: a weather source from foldopt's cache only (FOLDOPT_OFFLINE=1).",
    ),
]
WeatherFormat = Annotated[
    str | None,
    typer.Option(
        "--weather-format",
        help=_choices(names.WEATHER_FORMATS) + " [default: from the extension, hourly formats].",
    ),
]
Members = Annotated[
    int | None,
    typer.Option(
        "--members",
        help="An hourly file's cloud ensemble: this many synthetic minute series (2 to 200).",
    ),
]
Seed = Annotated[int | None, typer.Option("--seed", help="The ensemble's seed [default: 0].")]
ForceSite = Annotated[
    bool,
    typer.Option("--force-site", help="Keep --lat/--lon though far from the weather file's site."),
]
Transposition = Annotated[
    str | None, typer.Option("--transposition", help=_choices(names.TRANSPOSITIONS) + ".")
]
Albedo = Annotated[
    float | None, typer.Option("--albedo", help="Ground reflectance [-] (with diffuse light).")
]
Iam = Annotated[
    str | None,
    typer.Option("--iam", help="Incidence-angle modifier: " + _choices(names.IAMS) + "."),
]
Objective = Annotated[
    str | None,
    typer.Option(
        "--objective",
        help="One fold angle for all days, maximising: mean | min | worst-month | pNN (a "
        "percentile).",
    ),
]
Visits = Annotated[
    int | None,
    typer.Option(
        "--visits",
        help="With --objective mean or worst-month: also the best re-fold schedule of 1 to this "
        "many fold settings a year (at most 12).",
    ),
]
Tracker = Annotated[str | None, typer.Option("--tracker", help=_choices(names.TRACKERS) + ".")]
TrackerStandby = Annotated[
    float | None, typer.Option("--tracker-standby", help="Tracker standby draw [W].")
]
PvModel = Annotated[str | None, typer.Option("--pv-model", help=_choices(names.PV_MODELS) + ".")]
Module = Annotated[
    str | None,
    typer.Option(
        "--module",
        help="single-diode: a module of pvlib's CEC database, any part of its name, e.g. "
        "CS5P-220M [default: the A-300 cell].",
    ),
]
Connection = Annotated[
    str | None, typer.Option("--connection", help=_choices(names.CONNECTIONS) + ".")
]
SwitchSeries = Annotated[
    bool, typer.Option("--switch-series", help="Switching may also choose series.")
]
NoBypass = Annotated[bool, typer.Option("--no-bypass", help="Series without bypass diodes.")]
ConverterEfficiency = Annotated[
    float | None,
    typer.Option(
        "--converter-efficiency",
        help="Efficiency [-] of each converter of connection independent.",
    ),
]
Horizon = Annotated[
    Path | None,
    typer.Option(
        "--horizon",
        help="The site's horizon: a PVGIS horizon file (JSON or CSV), a CSV azimuth,elevation "
        "[deg], or pvgis (fetched from PVGIS for --lat/--lon).",
    ),
]
BlockingDiode = Annotated[
    str | None,
    typer.Option(
        "--blocking-diode",
        help="Blocking diodes in parallel: " + _choices(names.DIODE_MODELS) + " (I-V models).",
    ),
]
BypassDiode = Annotated[
    str | None,
    typer.Option(
        "--bypass-diode",
        help="Bypass diodes in series: " + _choices(names.DIODE_MODELS) + " (I-V models).",
    ),
]
Converter = Annotated[
    str | None,
    typer.Option(
        "--converter",
        help="The MPPT converter's efficiency: " + _choices(names.CONVERTER_MODELS) + ".",
    ),
]
LoadVoltage = Annotated[
    float | None,
    typer.Option(
        "--load-voltage",
        help="Couple the load directly at this voltage [V], no converter (I-V models).",
    ),
]
SwitchResistance = Annotated[
    float | None,
    typer.Option(
        "--switch-resistance",
        help="On-resistance [ohm] of the switch in each sub-panel's path (connection switching).",
    ),
]
TempAir = Annotated[
    float | None, typer.Option("--temp-air", help="Air temperature [C] (I-V models).")
]
ExactElectrical = Annotated[
    bool,
    typer.Option(
        "--exact-electrical", help="Solve every step's I-V curves instead of the tables (slow)."
    ),
]


def out_option(shown: str | None = None) -> typer.models.OptionInfo:
    """The ``--out`` option: the results folder.

    Parameters
    ----------
    shown : str, optional
        The default as the help text gives it where the command names the folder from the study
        (``results/<study name>``); without it the help shows the parameter's default.

    Returns
    -------
    typer.models.OptionInfo
    """
    return typer.Option("--out", help=f"Results folder{f' [default: {shown}]' if shown else ''}.")


def study_argument(kind: str = "") -> typer.models.ArgumentInfo:
    """The optional study argument of ``run`` and ``size``.

    Parameters
    ----------
    kind : str
        What study the command takes, after ``YAML study`` (e.g. `` (one case)``).

    Returns
    -------
    typer.models.ArgumentInfo
    """
    return typer.Argument(help=f"YAML study{kind} [default: the embedded {EMBEDDED}].")


def check_choices(output_format: str, engine: str) -> tuple[str, str]:
    """``--format`` and ``--engine`` as their registries name them; bad ones end the command.

    Parameters
    ----------
    output_format, engine : str
        As given, in any of the names :mod:`foldopt.names` knows.

    Returns
    -------
    tuple of str
        The canonical format and engine.
    """
    errors, chosen = [], []
    for option, value, choices in (
        ("--format", output_format, names.OUTPUT_FORMATS),
        ("--engine", engine, names.ENGINES),
    ):
        try:
            chosen.append(names.canonical(value, choices))
        except ValueError as error:
            errors.append(f"{option} = {value!r}: {error}")
    if errors:
        fail(errors)
    return tuple(chosen)


_FIELD = re.compile(r"^([A-Za-z_.]+)(\[\d+\])?")


def rename_fields(line: str, options: dict = OPTION_OF_FIELD) -> str:
    """A message's leading field path as the option that set it.

    Parameters
    ----------
    line : str
        ``field: problem`` or ``field = value: problem``.
    options : dict
        Field path -> option.

    Returns
    -------
    str
        The line with its field renamed, or as it was where ``options`` has no such field.
    """
    match = _FIELD.match(line)
    if match and match.group(1) in options:
        return options[match.group(1)] + line[match.end(1) :]
    return line
