"""``foldopt weather fetch | list | path``: the cache of weather fetched from public services
(:mod:`foldopt.inputs.weather.sources`). Fetch a site ahead of a field trip, list what is cached,
and give a cached answer's file (or a copy of it, a standard weather file to keep beside a study).
Each takes ``--quiet`` and ``--format json`` as every command does, and checks the site and every
option before anything is asked.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path
from typing import Annotated

import typer

from foldopt import names
from foldopt.cli.options import OutputFormat, Overwrite, Quiet, rename_fields
from foldopt.cli.output import Output, as_text, echo, fail
from foldopt.errors import ConfigError, redacted

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
    typer.Option(
        "--timeout",
        help="Seconds to wait at most for the service's whole answer (connecting, every read, "
        "every retry) [default: 30].",
    ),
]
Database = Annotated[
    str | None,
    typer.Option(
        "--raddatabase",
        help="pvgis-hourly's radiation database (PVGIS-SARAH3, PVGIS-ERA5) [default: PVGIS's "
        "for the site].",
    ),
]

#: A source's option as the commands name it.
_LABELS = {
    "source": "SOURCE",
    "years": "--years",
    "url": "--url",
    "timeout_s": "--timeout",
    "usehorizon": "--no-horizon",
    "raddatabase": "--raddatabase",
    "site.latitude": "--lat",
    "site.longitude": "--lon",
}


def _checked(
    output_format: str,
    source: str | None = None,
    lat=None,
    lon=None,
    years=None,
    no_horizon=False,
    raddatabase=None,
    url=None,
    timeout=None,
):
    """``--format``, the site and the source's options (where a source is given), each checked as
    a study's sections check them before anything is asked: every fault one line, then the
    command ends.

    Returns
    -------
    tuple
        The canonical format and the ``weather`` section
        (:class:`foldopt.inputs.weather_section.Weather`), or None without a source.
    """
    from pydantic import ValidationError

    from foldopt.inputs.study import format_errors
    from foldopt.inputs.weather.sources import site_problems
    from foldopt.inputs.weather_section import Weather

    errors, spec = [], None
    try:
        output_format = names.canonical(output_format, names.OUTPUT_FORMATS)
    except ValueError as error:
        errors.append(f"--format = {output_format!r}: {error}")
    if source is not None:
        errors += site_problems(lat, lon)
        given = {
            "source": source,
            "years": years,
            "raddatabase": raddatabase,
            "url": url,
            "timeout_s": timeout,
        }
        given = {key: value for key, value in given.items() if value is not None}
        if no_horizon:
            given["usehorizon"] = False
        try:
            spec = Weather.model_validate(given)
        except ValidationError as error:
            errors += format_errors(error)
    if errors:
        fail([redacted(rename_fields(line, _LABELS)) for line in errors])
    return output_format, spec


def fetch(
    source: Source = "pvgis-tmy",
    lat: Lat = ...,
    lon: Lon = ...,
    years: Years = None,
    no_horizon: NoHorizon = False,
    raddatabase: Database = None,
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
    output_format, spec = _checked(
        output_format, source, lat, lon, years, no_horizon, raddatabase, url, timeout
    )
    output = Output(quiet, output_format)
    from foldopt.inputs.weather.sources import fetch as fetch_source

    try:
        found = fetch_source(spec.source, lat, lon, spec)
    except ConfigError as error:
        fail(error.errors)
    if output.json:
        echo(json.dumps(found.to_dict(), indent=2))
    elif not quiet:
        echo(f"{found.source} ({found.params['lat']:g}, {found.params['lon']:g}): {found.file}")
        echo(f"  {found.bytes:,} bytes, sha256 {found.sha256}, retrieved {found.retrieved}")
        echo(f"  from {found.url}")


def list_cache(quiet: Quiet = False, output_format: OutputFormat = "table"):
    """List the cached weather: source, site, options, when it was retrieved, its file. A
    damaged cached answer is named on stderr (fetch it again to replace it).

    \b
    Examples:
      foldopt weather list
      foldopt weather list --format json
    """
    output_format, _ = _checked(output_format)
    output = Output(quiet, output_format)
    from foldopt.cache import notice
    from foldopt.inputs.weather.sources import cached_entries, damaged_entries, weather_cache

    entries = cached_entries()
    for path, why in damaged_entries():
        notice(f"the cached copy {path} is damaged ({why}); foldopt weather fetch replaces it")
    if output.json:
        echo(json.dumps([entry.to_dict() for entry in entries], indent=2))
        return
    if quiet:
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
    raddatabase: Database = None,
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
    quiet: Quiet = False,
    output_format: OutputFormat = "table",
):
    """The cached file of a site's weather (nothing is fetched), or a copy of it with --out;
    --format json: the cached answer's provenance record (and ``out``, the copy).

    \b
    Examples:
      foldopt weather path pvgis-tmy --lat 45.8 --lon 8.6
      foldopt weather path pvgis-tmy --lat 45.8 --lon 8.6 --out site-tmy.json
    """
    output_format, spec = _checked(
        output_format, source, lat, lon, years, no_horizon, raddatabase, url
    )
    output = Output(quiet, output_format)
    from foldopt.inputs.weather.sources import lookup

    try:
        found = lookup(spec.source, lat, lon, spec)
    except ConfigError as error:
        fail(error.errors)
    record = found.to_dict()
    if out is not None:
        _copy_out(found.file, out, overwrite)
        record["out"] = as_text(str(out))
    if output.json:
        echo(json.dumps(record, indent=2))
    elif quiet:
        return
    elif out is None:
        echo(found.file)
    else:
        echo(f"wrote {out} ({found.source}, sha256 {found.sha256})")


def _copy_out(file: str, out: Path, overwrite: bool) -> None:
    """Copy a cached answer to ``--out``; a fault ends the command."""
    if out.exists() and not overwrite:
        fail([f"--out {out}: exists; pass --overwrite to replace it"])
    if out.exists() and not out.is_file():
        fail([f"--out {out}: is not a file"])
    from foldopt.cache import write_atomically

    try:
        write_atomically(out, lambda temporary: _copy(file, temporary))
    except OSError as error:
        fail([f"--out {out}: cannot be written ({error.strerror or error})"])


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
