"""``foldopt sweep angle | latitude | day | load``: one design variable over a range, everything
else from the study. Each command is a function of its own, its options the shared types of
:mod:`foldopt.cli.options`: every option that sets a study field, those its axis varies taking
several values (``Latitudes``, ``Days``...) where ``sweep angle``'s take one. The request they make
is :func:`foldopt.studies.request.make_request`'s (:func:`foldopt.cli.run.run_options`).
"""

from pathlib import Path
from typing import Annotated

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
    Date,
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
    Latitudes,
    Load,
    LoadProfile,
    Loads,
    LoadScale,
    LoadScales,
    LoadVoltage,
    Longitude,
    Longitudes,
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
    Tilts,
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

#: The sweep group's help and its line in the command list.
HELP = "Sweep one design variable over a range, everything else from the study."
SHORT_HELP = "Sweep fold angle, latitude, day or load [default ranges]."


def angle(
    config: Config = None,
    lat: Latitude = None,
    lon: Longitude = None,
    altitude: Altitude = None,
    timezone: Timezone = None,
    days: Date = None,
    year: Year = None,
    p_load: Load = None,
    load_profile: LoadProfile = None,
    p_load_scale: LoadScale = None,
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
    out: Annotated[Path | None, out_option(shown="results/sweep-angle")] = None,
    overwrite: Overwrite = False,
    quiet: Quiet = False,
    output_format: OutputFormat = "table",
    engine: Engine = DEFAULT_ENGINE,
    table: Table = False,
):
    """Every fold angle at one site, day and load (sweep.csv, summary.csv, the paper's plots).
    With a weather file: one fold angle for the file's whole year (--objective, default mean).

    \b
    Examples:
      foldopt sweep angle
      foldopt sweep angle --lat -33.87 --lon 151.21 --timezone Australia/Sydney --date 2025-06-21
      foldopt sweep angle --weather configs/weather/723170TYA.CSV --p-load 2
    """
    run_options("sweep angle", locals(), "sweep-angle")


def latitude(
    config: Config = None,
    lat: Latitudes = None,
    lon: Longitudes = None,
    altitude: Altitude = None,
    timezone: Timezone = None,
    days: Days = None,
    year: Year = None,
    p_load: Loads = None,
    load_profile: LoadProfile = None,
    p_load_scale: LoadScales = None,
    area: Area = None,
    efficiency: Efficiency = None,
    tilt: Tilts = None,
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
    out: Annotated[Path | None, out_option(shown="results/sweep-latitude")] = None,
    overwrite: Overwrite = False,
    quiet: Quiet = False,
    output_format: OutputFormat = "table",
    engine: Engine = DEFAULT_ENGINE,
    table: Table = False,
):
    """The study at every latitude of a range [default: -60:60:5], the panel tilted at |latitude|
    toward the equator unless --tilt/--azimuth say otherwise: a row per case x design in
    results.csv, with maps and curves.

    \b
    Examples:
      foldopt sweep latitude
      foldopt sweep latitude --lat -40:40:10 --p-load 1:9:2
    """
    run_options("sweep latitude", locals(), "sweep-latitude")


def day(
    config: Config = None,
    lat: Latitudes = None,
    lon: Longitudes = None,
    altitude: Altitude = None,
    timezone: Timezone = None,
    days: Days = None,
    year: Year = None,
    p_load: Loads = None,
    load_profile: LoadProfile = None,
    p_load_scale: LoadScales = None,
    area: Area = None,
    efficiency: Efficiency = None,
    tilt: Tilts = None,
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
    out: Annotated[Path | None, out_option(shown="results/sweep-day")] = None,
    overwrite: Overwrite = False,
    quiet: Quiet = False,
    output_format: OutputFormat = "table",
    engine: Engine = DEFAULT_ENGINE,
    table: Table = False,
):
    """The study on every day of a range [default: 1:365:7 of the study's year].

    \b
    Examples:
      foldopt sweep day
      foldopt sweep day --days year --objective p10
    """
    run_options("sweep day", locals(), "sweep-day")


def load(
    config: Config = None,
    lat: Latitudes = None,
    lon: Longitudes = None,
    altitude: Altitude = None,
    timezone: Timezone = None,
    days: Days = None,
    year: Year = None,
    p_load: Loads = None,
    load_profile: LoadProfile = None,
    p_load_scale: LoadScales = None,
    area: Area = None,
    efficiency: Efficiency = None,
    tilt: Tilts = None,
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
    out: Annotated[Path | None, out_option(shown="results/sweep-load")] = None,
    overwrite: Overwrite = False,
    quiet: Quiet = False,
    output_format: OutputFormat = "table",
    engine: Engine = DEFAULT_ENGINE,
    table: Table = False,
):
    """The study at every load of a range [default: 20 loads from 5 % to 100 % of the panel's
    rating, area x 1000 W/m^2 x efficiency].

    \b
    Examples:
      foldopt sweep load
      foldopt sweep load --p-load 0.5:19:0.5 --pv-model single-diode
    """
    run_options("sweep load", locals(), "sweep-load")


#: The commands of this module: name, function, and the line the command list shows.
COMMANDS = [
    (
        "angle",
        angle,
        "Every fold angle at one site, day and load (or over a weather file's year).",
    ),
    ("latitude", latitude, "Every latitude of a range [default: -60:60:5]."),
    ("day", day, "Every day of a range [default: 1:365:7]."),
    ("load", load, "Every load of a range [default: 5 % to 100 % of the panel's rating]."),
]
