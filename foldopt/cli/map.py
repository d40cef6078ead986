"""``foldopt map``: many sites on Dask. The request is
:func:`foldopt.studies.request.map_request_from`'s, the run :func:`foldopt.world_map`'s; the command
checks how its options combine and prints.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from foldopt.cli.options import (ANGLE_STEP, AREA, EFFICIENCY, EMBEDDED, ENGINE, FORMAT, OPTION_OF_FIELD, OVERWRITE,
                                 QUIET, RESULTS, SETTINGS, check_choices, out_option, rename_fields,
                                 step_min_option)
from foldopt.cli.output import INVOCATION, Output, fail
from foldopt.errors import ConfigError, WeatherError

#: The map request's parameters as the options name them, beside the study's fields.
_OPTION_OF_PARAMETER = {"latitudes": "--lat", "longitudes": "--lon", "land_only": "--land-only",
                        "show_period": "--show-period", "optimize": "--optimize"}


def map_(
    lat: Optional[str] = typer.Option(None, "--lat", help="Latitudes [deg north]: a range start:stop:step or a "
                                      "list [default: -60:60:10]."),
    lon: Optional[str] = typer.Option(None, "--lon", help="Longitudes [deg east]: a range or a list "
                                      "[default: -180:180:30]."),
    land_only: bool = typer.Option(False, "--land-only", help="Keep only the grid points on land."),
    sites: Optional[Path] = typer.Option(None, "--sites", help="CSV of named sites: name, latitude, longitude "
                                         "[, altitude, timezone], instead of a grid."),
    weather_dir: Optional[Path] = typer.Option(None, "--weather-dir", help="Folder of TMY3 / EPW / PVGIS files, each "
                                               "file a site (its site read from the file), instead of a grid."),
    p_load: Optional[str] = typer.Option(None, "--p-load", help="Loads [W]: a value, a range or a list [default: the "
                                         "study's]."),
    p_load_fraction: Optional[str] = typer.Option(None, "--p-load-fraction", help="Loads as fractions of each "
                                                  "site's flat peak: a value, a range such as 0.1:0.9:0.1 or a list, "
                                                  "instead of --p-load."),
    area: Optional[float] = AREA,
    efficiency: Optional[float] = EFFICIENCY,
    objective: str = typer.Option("mean", "--objective", help="What each period's fold angle maximises: mean | min | "
                                  "worst-month | pNN."),
    year: int = typer.Option(2025, "--year", help="Year of the clear-sky days (or that a typical year stands for)."),
    step_min: Optional[float] = step_min_option("5"),
    angle_step: Optional[float] = ANGLE_STEP,
    fold_search: bool = typer.Option(False, "--fold-search", help="Search the fold angles (foldopt.engine.search) "
                                     "instead of evaluating every one: the same objectives within 0.01 h from some "
                                     "60 of 180 angles."),
    optimize: Optional[str] = typer.Option(None, "--optimize", help="What the search varies with the fold angle: "
                                           "tilt (each site's best tilt, and the flat panel's own); implies "
                                           "--fold-search."),
    config: Optional[Path] = typer.Option(None, "--config", help=f"Study to take the panel and models from [default: "
                                          f"{EMBEDDED}, in exact mode with the Ineichen clear sky]."),
    settings: Optional[list[str]] = SETTINGS,
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
    out: Path = out_option(RESULTS / "map"),
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
    output_format, engine = check_choices(output_format, engine)
    output = Output(quiet, output_format)
    errors = []
    if sum(source is not None for source in (sites, weather_dir)) + (lat is not None or lon is not None) > 1:
        errors.append("--lat/--lon, --sites, --weather-dir: give one source of sites")
    if land_only and (sites is not None or weather_dir is not None):
        errors.append("--land-only: only for a --lat/--lon grid")
    if p_load is not None and p_load_fraction is not None:
        errors.append("--p-load / --p-load-fraction: give loads one way")
    for option, value in (("--workers", workers), ("--chunk-sites", chunk_sites)):
        if value is not None and value < 1:
            errors.append(f"{option} = {value}: must be at least 1")
    if errors:
        fail(errors)
    relative = p_load_fraction is not None
    options_of = {**OPTION_OF_FIELD, **_OPTION_OF_PARAMETER, "loads": "--p-load-fraction" if relative else "--p-load"}
    from foldopt.studies.request import map_request_from

    try:
        request = map_request_from(
            config, source=EMBEDDED if config is None else str(config), objective=objective, area=area,
            efficiency=efficiency, step_min=step_min, angle_step=angle_step, fold_search=fold_search,
            optimize=optimize, settings=settings or (),
            loads=p_load_fraction if relative else p_load, relative=relative, year=year, show_period=show_period,
            sites=sites, weather_dir=weather_dir, latitudes=lat, longitudes=lon, land_only=land_only)
    except WeatherError:
        raise  # a file of --weather-dir: its line names the file, as the reader says it (map has no --weather)
    except ConfigError as error:
        fail(list(dict.fromkeys(rename_fields(line, options_of) for line in error.errors)))
    if not 1 <= show_load <= len(request.loads):
        fail([f"--show-load = {show_load}: must be in [1, {len(request.loads)}] (the map has "
              f"{len(request.loads)} load{'s' if len(request.loads) > 1 else ''})"])

    def announce(cluster: str, dashboard: str | None):
        if not quiet and not output.json:
            typer.echo(f"{cluster}; dashboard: {dashboard or 'none (pip install bokeh)'}", err=True)

    with output.progress(f"map: {len(request.sites)} sites", total=len(request.sites), unit="sites") as progress:
        from foldopt.api import world_map

        try:
            result, figures, answer = world_map(
                request.sites, request.loads, out, request.study, relative, year, scheduler=scheduler,
                workers=workers, sites_per_chunk=chunk_sites or 0, resume=resume, overwrite=overwrite, engine=engine,
                show_load=show_load - 1, show_period=show_period, progress=progress, announce=announce,
                command=INVOCATION, defaults=request.defaults)
        except ConfigError as error:
            fail(list(dict.fromkeys(rename_fields(line) for line in error.errors)))
    output.answer("map", out, answer, result.table[result.table["period"] == "year"].reset_index(drop=True),
                  [f"wrote {out} (map.parquet, map.csv{', map.nc' if (out / 'map.nc').exists() else ''}, report.html, "
                   f"{', '.join(figures)})"])


#: The commands of this module: name, function, and the line the command list shows.
COMMANDS = [("map", map_, "Many sites on Dask: best fold angle, gains and tracker share worldwide.")]
