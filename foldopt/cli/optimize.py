"""``foldopt optimize``: the fold angle, base tilt and base azimuth together
(:func:`foldopt.studies.joint.optimize_plan`). It takes the search's own options and every option
of ``foldopt sweep`` for the site, days, loads and models (its days and loads several values,
:mod:`foldopt.cli.options`); the request is :func:`foldopt.studies.request.make_request`'s, the
search's options making its ``optimize`` section (:func:`foldopt.studies.request.optimize_section`).
"""

from pathlib import Path
from typing import Annotated

import typer

from foldopt import names
from foldopt.cli.options import (
    Albedo,
    Altitude,
    AngleStep,
    Area,
    Azimuth,
    BlockingDiode,
    BypassDiode,
    Climate,
    Config,
    Connection,
    Converter,
    ConverterEfficiency,
    Days,
    Efficiency,
    Engine,
    ExactElectrical,
    FoldAngle,
    ForceSite,
    Geometry,
    Horizon,
    Iam,
    Latitude,
    LoadProfile,
    Loads,
    LoadScales,
    LoadVoltage,
    Longitude,
    Members,
    MinSoc,
    Mode,
    Module,
    NoBypass,
    Objective,
    Offline,
    OutputFormat,
    Overwrite,
    Planes,
    PvModel,
    Quiet,
    Seed,
    Settings,
    Sky,
    StepMin,
    StorageWh,
    SwitchResistance,
    SwitchSeries,
    Table,
    TempAir,
    Tilt,
    Timezone,
    Tracker,
    TrackerStandby,
    Transposition,
    Visits,
    WeatherFileOrSource,
    WeatherFormat,
    WeatherYears,
    Year,
    out_option,
)
from foldopt.cli.run import run_options
from foldopt.names import DEFAULT_ENGINE

#: The optimize section's fields by the parameters of :func:`optimize` that set them.
_PARAMETER_OF_FIELD = {
    "vary": "vary",
    "fold_angle": "fold_range",
    "tilt": "tilt_range",
    "azimuth": "azimuth_range",
    "tolerance_h": "tolerance",
}


def optimize(
    vary: Annotated[
        str | None,
        typer.Option(
            "--vary",
            help="What to optimise: any of "
            + ", ".join(names.OPTIMIZE_VARIABLES)
            + ", joined by commas [default: all three, or the study's optimize.vary].",
        ),
    ] = None,
    fold_range: Annotated[
        str | None,
        typer.Option(
            "--fold-range",
            help="Fold angles min:max:step [deg] [default: the study's fold_angles].",
        ),
    ] = None,
    tilt_range: Annotated[
        str | None,
        typer.Option("--tilt-range", help="Base tilts min:max:step [deg] [default: 0:90:1]."),
    ] = None,
    azimuth_range: Annotated[
        str | None,
        typer.Option(
            "--azimuth-range",
            help="Base azimuths min:max:step [deg from north; may cross north, -90:90:2] "
            "[default: the equator-facing one +-90 by 2].",
        ),
    ] = None,
    tolerance: Annotated[
        float | None,
        typer.Option(
            "--tolerance",
            help="What the search may miss of the best objective [h]; no finer than the "
            "objective counts (one day: the time step) [default: 0.01].",
        ),
    ] = None,
    config: Config = None,
    lat: Latitude = None,
    lon: Longitude = None,
    altitude: Altitude = None,
    timezone: Timezone = None,
    days: Days = None,
    year: Year = None,
    p_load: Loads = None,
    load_profile: LoadProfile = None,
    p_load_scale: LoadScales = None,
    area: Area = None,
    efficiency: Efficiency = None,
    tilt: Tilt = None,
    azimuth: Azimuth = None,
    planes: Planes = None,
    mode: Mode = None,
    geometry: Geometry = None,
    sky: Sky = None,
    climate: Climate = None,
    weather: WeatherFileOrSource = None,
    years: WeatherYears = None,
    offline: Offline = False,
    weather_format: WeatherFormat = None,
    members: Members = None,
    seed: Seed = None,
    force_site: ForceSite = False,
    transposition: Transposition = None,
    albedo: Albedo = None,
    iam: Iam = None,
    objective: Objective = None,
    visits: Visits = None,
    tracker: Tracker = None,
    tracker_standby: TrackerStandby = None,
    pv_model: PvModel = None,
    module: Module = None,
    connection: Connection = None,
    switch_series: SwitchSeries = False,
    no_bypass: NoBypass = False,
    converter_efficiency: ConverterEfficiency = None,
    horizon: Horizon = None,
    blocking_diode: BlockingDiode = None,
    bypass_diode: BypassDiode = None,
    converter: Converter = None,
    load_voltage: LoadVoltage = None,
    switch_resistance: SwitchResistance = None,
    temp_air: TempAir = None,
    exact_electrical: ExactElectrical = False,
    step_min: StepMin = None,
    angle_step: AngleStep = None,
    fold_angle: FoldAngle = None,
    storage_wh: StorageWh = None,
    min_soc: MinSoc = None,
    settings: Settings = None,
    out: Annotated[Path | None, out_option(shown="results/optimize")] = None,
    overwrite: Overwrite = False,
    quiet: Quiet = False,
    output_format: OutputFormat = "table",
    engine: Engine = DEFAULT_ENGINE,
    table: Table = False,
):
    """The best fold angle, base tilt and base azimuth together (any of them), maximising the
    study's objective over its days: per load the optimum with its near-optimal region, the flat
    panel at its own best tilt and azimuth, the default mounting and the tracker, what each
    variable adds, and landscape.png (tilt x fold angle).

    \b
    Examples:
      foldopt optimize --mode exact
      foldopt optimize --days year --objective worst-month --vary fold_angle,tilt --step-min 10
      foldopt optimize --lat -33.87 --lon 151.21 --timezone Australia/Sydney --days 1:365:7 --p-load 1,3
    """
    options = dict(locals())
    search = {field: options.pop(parameter) for field, parameter in _PARAMETER_OF_FIELD.items()}
    # The study's modules (yaml, pydantic, numpy) once a command runs: --help stays quick.
    from foldopt.studies.request import OPTIMIZE_OPTIONS

    search = {field: value for field, value in search.items() if value is not None}
    # The search's own limits (loads x designs) are checked as it starts, before any work.
    run_options("optimize", options, "optimize", optimize={**search, "labels": OPTIMIZE_OPTIONS})


#: The commands of this module: name, function, and the line the command list shows.
COMMANDS = [
    (
        "optimize",
        optimize,
        "The best fold angle, tilt and azimuth together, and the flat panel's own best.",
    )
]
