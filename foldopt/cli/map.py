"""``foldopt map``: many sites on Dask. The request is
:func:`foldopt.studies.request.make_request`'s (which checks how the sites, loads and weather
combine, naming the options by :data:`_OPTION_OF_PARAMETER`), the run :func:`foldopt.world_map`'s;
the command checks how it asks for its cluster, and prints.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

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
    Settings,
    check_choices,
    out_option,
    StepMin,
)
from foldopt import names
from foldopt.cli.output import INVOCATION, Output, fail
from foldopt.cli.process import loading
from foldopt.errors import ConfigError
from foldopt.names import CONNECT_TIMEOUT, DEFAULT_ENGINE, WORKER_TIMEOUT

#: The map request's parameters as the options name them, beside the study's fields.
_OPTION_OF_PARAMETER = {
    "latitudes": "--lat",
    "longitudes": "--lon",
    "sites": "--sites",
    "weather_dir": "--weather-dir",
    "land_only": "--land-only",
    "show_period": "--show-period",
    "optimize": "--optimize",
    "weather.source": "--weather",
    "weather.years": "--years",
}


def map_(
    lat: Annotated[
        str | None,
        typer.Option(
            "--lat",
            help="Latitudes [deg north]: a range start:stop:step or a list [default: -60:60:10].",
        ),
    ] = None,
    lon: Annotated[
        str | None,
        typer.Option(
            "--lon", help="Longitudes [deg east]: a range or a list [default: -180:180:30]."
        ),
    ] = None,
    land_only: Annotated[
        bool, typer.Option("--land-only", help="Keep only the grid points on land.")
    ] = False,
    sites: Annotated[
        Path | None,
        typer.Option(
            "--sites",
            help="CSV of named sites: name, latitude, longitude "
            "[, altitude, timezone], instead of a grid.",
        ),
    ] = None,
    weather_dir: Annotated[
        Path | None,
        typer.Option(
            "--weather-dir",
            help="Folder of TMY3 / EPW / PVGIS files, "
            "each file a site (its site read from the file), instead of "
            "a grid.",
        ),
    ] = None,
    weather: Annotated[
        str | None,
        typer.Option(
            "--weather",
            help="Each site's weather from a source, "
            + ", ".join(names.WEATHER_SOURCES)
            + ": fetched once a site before the map starts, and cached (a stopped fetch resumes "
            "from the cache).",
        ),
    ] = None,
    years: Annotated[
        str | None,
        typer.Option("--years", help="The weather source's years START:END, e.g. 2005:2020."),
    ] = None,
    offline: Annotated[
        bool,
        typer.Option("--offline", help="Fetch nothing: the weather source from the cache only."),
    ] = False,
    p_load: Annotated[
        str | None,
        typer.Option(
            "--p-load", help="Loads [W]: a value, a range or a list [default: the study's]."
        ),
    ] = None,
    p_load_fraction: Annotated[
        str | None,
        typer.Option(
            "--p-load-fraction",
            help="Loads as fractions of each "
            "site's flat peak: a value, a range such as 0.1:0.9:0.1 or "
            "a list, instead of --p-load.",
        ),
    ] = None,
    area: Area = None,
    efficiency: Efficiency = None,
    objective: Annotated[
        str | None,
        typer.Option(
            "--objective",
            help="What each period's fold angle maximises: mean | min | worst-month | pNN "
            "[default: the study's, else mean].",
        ),
    ] = None,
    year: Annotated[
        int | None,
        typer.Option(
            "--year",
            help="Year of the clear-sky days (or that a typical year stands for) [default: 2025].",
        ),
    ] = None,
    step_min: StepMin = None,
    angle_step: AngleStep = None,
    fold_search: Annotated[
        bool,
        typer.Option(
            "--fold-search",
            help="Search the fold angles (foldopt.engine.search) "
            "instead of evaluating every one: the same objectives within 0.01 h "
            "from some 60 of 180 angles.",
        ),
    ] = False,
    optimize: Annotated[
        str | None,
        typer.Option(
            "--optimize",
            help="What the search varies with the fold angle: "
            "tilt (each site's best tilt, and the flat panel's own); implies "
            "--fold-search.",
        ),
    ] = None,
    config: Annotated[
        Path | None,
        typer.Option(
            "--config",
            help=f"Study to take the panel and models from "
            f"[default: {EMBEDDED}, in exact mode with the Ineichen clear "
            "sky].",
        ),
    ] = None,
    settings: Settings = None,
    scheduler: Annotated[
        str | None,
        typer.Option(
            "--scheduler",
            help="A Dask scheduler's address (tcp://host:8786; or tls://, ws://, wss://) or "
            "scheduler file [default: an embedded cluster]. A scheduler that does not answer is "
            f"given up after {CONNECT_TIMEOUT:g} s, one without a worker after "
            f"{WORKER_TIMEOUT:g} s more.",
        ),
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option(
            "--workers", help="Worker processes of the embedded cluster [default: one per core]."
        ),
    ] = None,
    chunk_sites: Annotated[
        int | None,
        typer.Option("--chunk-sites", help="Sites per task [default: about 5 s of work]."),
    ] = None,
    show_load: Annotated[
        int, typer.Option("--show-load", help="Which load (1 = the first) the world maps show.")
    ] = 1,
    show_period: Annotated[
        str,
        typer.Option(
            "--show-period", help="Period the world maps show: year | DJF | MAM | JJA | SON."
        ),
    ] = "year",
    resume: Annotated[
        bool,
        typer.Option(
            "--resume", help="Finish an interrupted map in --out: only missing chunks are computed."
        ),
    ] = False,
    out: Annotated[Path, out_option()] = RESULTS / "map",
    overwrite: Overwrite = False,
    quiet: Quiet = False,
    output_format: OutputFormat = "table",
    engine: Engine = DEFAULT_ENGINE,
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
    # How the run asks for its cluster, before any site or weather is read (the request's own
    # checks are make_request's).
    errors = [
        f"{option} = {value}: must be at least 1"
        for option, value in (("--workers", workers), ("--chunk-sites", chunk_sites))
        if value is not None and value < 1
    ]
    # The cluster's client (logging, sockets) loads with a map: other commands need none of it.
    with loading():
        from foldopt.studies.dask_client import check_cluster

    try:
        check_cluster(scheduler, workers)
    except ConfigError as error:
        errors += error.errors
    if errors:
        fail(errors)
    with loading():
        from foldopt.studies.request import make_request

    options = {
        "area": area,
        "efficiency": efficiency,
        "step_min": step_min,
        "objective": objective,
        "year": year,
        "p_load": p_load,
        "p_load_fraction": p_load_fraction,
        "angle_step": angle_step,
        "fold_search": fold_search,
        "optimize": optimize,
        "offline": offline,
    }
    where = {
        "sites": sites,
        "weather_dir": weather_dir,
        "latitudes": lat,
        "longitudes": lon,
        "land_only": land_only,
        "show_period": show_period,
        "weather": {
            key: value
            for key, value in (("source", weather), ("years", years))
            if value is not None
        }
        or None,
        "labels": {
            **_OPTION_OF_PARAMETER,
            "loads": "--p-load-fraction" if p_load_fraction is not None else "--p-load",
        },
    }
    try:
        request = make_request("map", config, options=options, settings=settings or (), where=where)
    except ConfigError as error:
        fail(list(dict.fromkeys(error.errors)))
    spec = request.plan
    if not 1 <= show_load <= len(spec.loads):
        fail(
            [
                f"--show-load = {show_load}: must be in [1, {len(spec.loads)}] (the map has "
                f"{len(spec.loads)} load{'s' if len(spec.loads) > 1 else ''})"
            ]
        )

    def announce(cluster: str, dashboard: str | None):
        if not quiet and not output.json:
            typer.echo(f"{cluster}; dashboard: {dashboard or 'none (pip install bokeh)'}", err=True)

    with output.progress(
        f"map: {len(spec.sites)} sites", total=len(spec.sites), unit="sites"
    ) as progress:
        with loading():
            from foldopt.api import world_map

        try:
            result, figures, answer = world_map(
                request=request,
                out=out,
                scheduler=scheduler,
                workers=workers,
                sites_per_chunk=chunk_sites or 0,
                resume=resume,
                overwrite=overwrite,
                engine=engine,
                show_load=show_load - 1,
                show_period=show_period,
                progress=progress,
                announce=announce,
                command=INVOCATION,
            )
        except ConfigError as error:
            fail(list(dict.fromkeys(request.rename(line) for line in error.errors)))
    output.answer(
        "map",
        out,
        answer,
        result.table[result.table["period"] == "year"].reset_index(drop=True),
        [
            f"wrote {out} (map.parquet, map.csv{', map.nc' if (out / 'map.nc').exists() else ''}, report.html, "
            f"{', '.join(figures)})"
        ],
    )


#: The commands of this module: name, function, and the line the command list shows.
COMMANDS = [
    ("map", map_, "Many sites on Dask: best fold angle, gains and tracker share worldwide.")
]
