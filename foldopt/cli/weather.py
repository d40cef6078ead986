"""``foldopt weather fetch | list | path``: the cache of weather fetched from public services
(:mod:`foldopt.inputs.weather.sources`). Fetch a site ahead of a field trip, list what is cached,
and give a cached answer's file (or a copy of it, a standard weather file to keep beside a study).
"""

from __future__ import annotations

import json
import os
import re
import shutil
from pathlib import Path
from typing import Annotated

import typer

from foldopt import names
from foldopt.cli.options import OutputFormat, Overwrite, Quiet
from foldopt.cli.output import echo, fail
from foldopt.errors import ConfigError

#: The weather group's help and its line in the command list.
HELP = (
    "Weather fetched from public services for a site, cached in foldopt's cache folder and "
    "replayed offline: fetch a site ahead of a trip, list the cache, give a cached file."
)
SHORT_HELP = "Fetch, list and export weather from public services (PVGIS) [cached]."

Source = Annotated[
    str,
    typer.Argument(help="The source: " + " | ".join(names.WEATHER_SOURCES) + "."),
]
Lat = Annotated[float, typer.Option("--lat", help="Latitude [deg north].")]
Lon = Annotated[float, typer.Option("--lon", help="Longitude [deg east].")]
Years = Annotated[
    str | None,
    typer.Option(
        "--years",
        help="The years START:END (PVGIS TMY: its months chosen from them, at least 10; "
        "PVGIS hourly: the series' years, 2005 to 2023) [default: the service's record].",
    ),
]
NoHorizon = Annotated[
    bool,
    typer.Option("--no-horizon", help="Light without the terrain's horizon (usehorizon=0)."),
]
Url = Annotated[
    str | None,
    typer.Option(
        "--url",
        help="The service's base address (a mirror) [default: FOLDOPT_PVGIS_URL, else the "
        "pinned versioned address].",
    ),
]
Timeout = Annotated[
    float | None,
    typer.Option("--timeout", help="Seconds to wait for the service [default: 30]."),
]


def _options(source, years, no_horizon, url, timeout) -> dict:
    """The source's options, checked as a study's ``weather`` section checks them."""
    from pydantic import ValidationError

    from foldopt.inputs.study import format_errors
    from foldopt.inputs.weather_section import Weather

    given = {"source": source, "years": years, "url": url, "timeout_s": timeout}
    given = {key: value for key, value in given.items() if value is not None}
    if no_horizon:
        given["usehorizon"] = False
    try:
        return Weather.model_validate(given)
    except ValidationError as error:
        fail(_labelled(format_errors(error)))


#: A source's option as the commands name it.
_LABELS = {
    "source": "SOURCE",
    "years": "--years",
    "url": "--url",
    "timeout_s": "--timeout",
    "usehorizon": "--no-horizon",
}


def _labelled(lines: list[str]) -> list[str]:
    """Validation's lines, each field named as the command's option."""
    return [re.sub(r"^\w+", lambda found: _LABELS.get(found[0], found[0]), line) for line in lines]


def fetch(
    source: Source = "pvgis-tmy",
    lat: Lat = ...,
    lon: Lon = ...,
    years: Years = None,
    no_horizon: NoHorizon = False,
    url: Url = None,
    timeout: Timeout = None,
    quiet: Quiet = False,
    output_format: OutputFormat = "table",
):
    """Fetch a site's weather into the cache (nothing is fetched where it is cached), and say
    which file holds it; a study or a sweep then runs offline with it.

    \b
    Examples:
      foldopt weather fetch pvgis-tmy --lat 45.8 --lon 8.6
      foldopt weather fetch pvgis-tmy --lat 45.8 --lon 8.6 --years 2005:2020
      foldopt weather fetch pvgis-hourly --lat 45.8 --lon 8.6 --years 2020:2021
      foldopt weather fetch pvgis-tmy --lat 45.8 --lon 8.6 --format json
    """
    output_format = _format(output_format)
    spec = _options(source, years, no_horizon, url, timeout)
    from foldopt.inputs.weather.sources import fetch as fetch_source

    try:
        found = fetch_source(spec.source, lat, lon, spec)
    except ConfigError as error:
        fail(error.errors)
    if output_format == "json":
        echo(json.dumps(found.to_dict(), indent=2))
    elif not quiet:
        echo(f"{found.source} ({found.params['lat']:g}, {found.params['lon']:g}): {found.file}")
        echo(f"  {found.bytes:,} bytes, sha256 {found.sha256}, retrieved {found.retrieved}")
        echo(f"  from {found.url}")


def list_cache(output_format: OutputFormat = "table"):
    """List the cached weather: source, site, options, when it was retrieved, its file.

    \b
    Examples:
      foldopt weather list
      foldopt weather list --format json
    """
    output_format = _format(output_format)
    from foldopt.inputs.weather.sources import cached_entries, weather_cache

    entries = cached_entries()
    if output_format == "json":
        echo(json.dumps([entry.to_dict() for entry in entries], indent=2))
        return
    if not entries:
        echo(f"no cached weather in {weather_cache()}")
        return
    echo(f"{len(entries)} cached in {weather_cache()}:")
    for entry in entries:
        params = entry.params
        options = " ".join(
            f"{key}={value}"
            for key, value in params.items()
            if key not in ("lat", "lon", "outputformat")
        )
        echo(
            f"  {entry.source} {entry.service_version} ({params['lat']:g}, {params['lon']:g})"
            f"{' ' + options if options else ''}, retrieved {entry.retrieved}, "
            f"{entry.bytes / 1e6:.1f} MB: {Path(entry.file).name}"
        )


def path(
    source: Source = "pvgis-tmy",
    lat: Lat = ...,
    lon: Lon = ...,
    years: Years = None,
    no_horizon: NoHorizon = False,
    url: Url = None,
    out: Annotated[
        Path | None,
        typer.Option(
            "--out",
            help="Copy the cached answer to this file: a standard weather file (PVGIS TMY JSON; "
            "an hourly series with --weather-format pvgis-hourly) that --weather FILE reads, to "
            "keep beside the study.",
        ),
    ] = None,
    overwrite: Overwrite = False,
):
    """The cached file of a site's weather (nothing is fetched), or a copy of it with --out.

    \b
    Examples:
      foldopt weather path pvgis-tmy --lat 45.8 --lon 8.6
      foldopt weather path pvgis-tmy --lat 45.8 --lon 8.6 --out site-tmy.json
    """
    spec = _options(source, years, no_horizon, url, None)
    from foldopt.cache import offline_mode
    from foldopt.inputs.weather.sources import fetch as fetch_source

    try:
        with offline_mode():
            found = fetch_source(spec.source, lat, lon, spec)
    except ConfigError as error:
        fail(error.errors)
    if out is None:
        echo(found.file)
        return
    if out.exists() and not overwrite:
        fail([f"--out {out}: exists; pass --overwrite to replace it"])
    if out.exists() and not out.is_file():
        fail([f"--out {out}: is not a file"])
    from foldopt.cache import write_atomically

    try:
        write_atomically(out, lambda temporary: _copy(found.file, temporary))
    except OSError as error:
        fail([f"--out {out}: cannot be written ({error.strerror or error})"])
    echo(f"wrote {out} ({found.source}, sha256 {found.sha256})")


def _format(output_format: str) -> str:
    """``--format`` as the registry names it; a bad one ends the command."""
    try:
        return names.canonical(output_format, names.OUTPUT_FORMATS)
    except ValueError as error:
        fail([f"--format = {output_format!r}: {error}"])


def _copy(source: str, target: Path) -> None:
    """A copy with the permissions of a new file (the cache's are the user's alone)."""
    shutil.copyfile(source, target)
    umask = os.umask(0)
    os.umask(umask)
    target.chmod(0o666 & ~umask)


#: The commands of this module: name, function, and the line the command list shows.
COMMANDS = [
    ("fetch", fetch, "Fetch a site's weather into the cache (ahead of a trip)."),
    ("list", list_cache, "List the cached weather."),
    ("path", path, "The cached file of a site's weather, or a copy (--out)."),
]
