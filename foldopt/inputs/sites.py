"""The sites of a map of many sites, as a list of site fields: a latitude x longitude grid, on land
or not (:func:`grid_sites`, the land mask of :mod:`foldopt.inputs.land`), a table of named sites
(:func:`read_sites`, every bad value or row reported at once) or a folder of weather files, each
file a site (:func:`weather_sites`). Each site is what :class:`foldopt.inputs.sections.Site` takes
(or a weather file's path and the site read from it); :mod:`foldopt.studies.map_request` checks
them and :mod:`foldopt.studies.worldmap` evaluates them.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from pydantic import ValidationError

from foldopt.errors import ConfigError
from foldopt.inputs.horizon import read_horizon
from foldopt.inputs.reading import MAX_CSV_BYTES, read_input
from foldopt.inputs.sections import Site
from foldopt.inputs.study import format_errors

if TYPE_CHECKING:
    import numpy as np

#: Weather files a folder of sites may hold, by extension (pvlib's readers).
WEATHER_SUFFIXES = (".csv", ".epw", ".json")
#: Columns of a table of named sites; name, latitude and longitude are required.
SITE_COLUMNS = ("name", "latitude", "longitude", "altitude", "timezone", "horizon")


def grid_sites(
    latitudes: Sequence[float], longitudes: Sequence[float], land_only: bool = False
) -> list[dict]:
    """Sites at every latitude x longitude [deg], latitude slowest; ``land_only`` keeps the points
    on land (:func:`foldopt.inputs.land.is_land`). A longitude of 180 is the same meridian as -180 and is
    dropped when both are given.

    Parameters
    ----------
    latitudes : sequence of float
        Latitudes [deg north].
    longitudes : sequence of float
        Longitudes [deg east].
    land_only : bool, default False
        Keep only the points on land.

    Returns
    -------
    list of dict
        ``latitude`` and ``longitude`` [deg] of each site.

    Raises
    ------
    ImportError
        With ``land_only``, without the ``global-land-mask`` package (``pip install foldopt[map]``).
    """
    longitudes = [lon for lon in longitudes if not (lon == 180 and -180 in longitudes)]
    sites = [
        {"latitude": float(lat), "longitude": float(lon)} for lat in latitudes for lon in longitudes
    ]
    if land_only:
        from foldopt.inputs.land import is_land

        keep = is_land([s["latitude"] for s in sites], [s["longitude"] for s in sites])
        sites = [site for site, land in zip(sites, keep, strict=True) if land]
    return sites


def lattice(values) -> np.ndarray | None:
    """The regular lattice that values sit on, whole rows of a grid missing allowed (a land grid's
    sea), or None where they sit on none.

    Parameters
    ----------
    values : array_like
        Latitudes or longitudes [deg] of a grid's sites.

    Returns
    -------
    numpy.ndarray or None
        Ascending, from the least value to the largest by the smallest spacing; a single value is
        its own lattice.
    """
    import numpy as np  # a map's figures and files, not its request

    values = np.unique(values)
    if values.size < 2:
        return values
    step = np.diff(values).min()
    steps = (values - values[0]) / step
    if not np.allclose(steps, np.round(steps), atol=1e-6):
        return None
    return values[0] + step * np.arange(int(round(steps[-1])) + 1)


def read_sites(path: Path | str) -> list[dict]:
    """Named sites from a CSV file with a header of :data:`SITE_COLUMNS` (altitude [m] and time zone
    optional), UTF-8 with or without a byte-order mark, each name at most once.

    Parameters
    ----------
    path : str or pathlib.Path
        The CSV file, at most :data:`foldopt.inputs.reading.MAX_CSV_BYTES`.

    Returns
    -------
    list of dict
        Each row's :class:`foldopt.inputs.sections.Site` fields as given: ``latitude``,
        ``longitude`` [deg] and, where given, ``name``, ``altitude`` [m], ``timezone`` and
        ``horizon`` (a horizon file, relative to the table's folder, read into its points:
        :func:`foldopt.inputs.horizon.read_horizon`).

    Raises
    ------
    foldopt.ConfigError
        With the file, line and field of every bad value or row, for a bad header, or where the
        file holds no site.
    """
    path = Path(path)
    text = read_input(path, "--sites", MAX_CSV_BYTES, "MAX_CSV_BYTES", "sites file")
    try:
        reader = csv.reader(io.StringIO(text, newline=""))
        header = [name.strip() for name in next(reader, [])]
        rows = [(reader.line_num, cells) for cells in reader if cells]  # a blank line is no row
    except csv.Error as error:
        raise ConfigError([f"--sites: cannot read {path}: {error}"]) from None
    missing = [name for name in ("latitude", "longitude") if name not in header]
    unknown = [name[:30] for name in header if name not in SITE_COLUMNS][:5]
    twice = sorted({name for name in header if header.count(name) > 1})
    if missing or unknown or twice:
        raise ConfigError(
            [
                f"--sites {path}: the header must name {', '.join(SITE_COLUMNS)} (name, altitude, "
                f"timezone and horizon optional); "
                + "; ".join(
                    ([f"missing {', '.join(missing)}"] if missing else [])
                    + ([f"unknown {', '.join(unknown)}"] if unknown else [])
                    + ([f"{', '.join(twice)} twice"] if twice else [])
                )
            ]
        )
    sites, errors, named = [], [], {}
    for line, cells in rows:
        # a cell more than the header names: a stray comma, or a shifted row
        if len(cells) > len(header):
            errors.append(
                f"--sites {path}, line {line}: {len(cells)} fields; the header names {len(header)}"
            )
            continue
        data = {key: value.strip() for key, value in zip(header, cells) if value.strip() != ""}
        if "horizon" in data:
            # A horizon file is named relative to the table of sites, and read here (the model opens none).
            file = (
                data["horizon"]
                if Path(data["horizon"]).is_absolute()
                else str(path.parent / data["horizon"])
            )
            try:
                azimuth, elevation = read_horizon(file)
            except ConfigError as error:
                errors.append(f"--sites {path}, line {line}: {error.errors[0]}")
                continue
            data["horizon"] = {
                "file": file,
                "points": [[float(a), float(e)] for a, e in zip(azimuth, elevation)],
            }
        try:
            site = Site.model_validate(data)
        except ValidationError as error:
            errors += [
                f"--sites {path}, line {line}: {message}" for message in format_errors(error)
            ]
            continue
        if site.name is not None:
            if site.name in named:  # the map's rows and figures tell sites by name
                errors.append(
                    f"--sites {path}, line {line}: name {site.name!r} is also on line {named[site.name]}; "
                    "give each site its own name"
                )
                continue
            named[site.name] = line
        given = site.model_dump(exclude_none=True)
        if "timezone" not in site.model_fields_set:
            given.pop("timezone")  # the longitude's standard offset: each site's study decides it
        sites.append(given)
    if not sites and not errors:
        errors.append(f"--sites {path}: no sites (a header and one row per site)")
    if errors:
        raise ConfigError(errors)
    return sites


def weather_sites(folder: Path | str) -> list[dict]:
    """One site per weather file of ``folder`` (TMY3, EPW, PVGIS JSON/CSV), in name order, each with
    its site read from the file (:func:`foldopt.inputs.weather.reader.weather_site`).

    Parameters
    ----------
    folder : str or pathlib.Path
        Holds the weather files (:data:`WEATHER_SUFFIXES`); other files are left out.

    Returns
    -------
    list of dict
        ``weather`` (the file's path), ``name`` (the file's site name, else its stem),
        ``latitude``, ``longitude`` [deg] and ``altitude`` [m].

    Raises
    ------
    foldopt.ConfigError
        Where ``folder`` is not a folder or holds no weather file.
    foldopt.errors.WeatherError
        Where a weather file fails its checks.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise ConfigError([f"--weather-dir: not a folder: {folder}"])
    files = sorted(
        path
        for path in folder.iterdir()
        if path.suffix.lower() in WEATHER_SUFFIXES and path.is_file()
    )
    if not files:
        raise ConfigError(
            [f"--weather-dir {folder}: no weather files ({', '.join(WEATHER_SUFFIXES)})"]
        )
    from foldopt.inputs.weather.reader import weather_site  # pandas and pvlib: files to read

    sites = []
    for path in files:
        site = weather_site(str(path), None)
        sites.append(
            {
                "weather": str(path),
                "name": site["name"] or path.stem,
                "latitude": site["latitude"],
                "longitude": site["longitude"],
                "altitude": site.get("altitude", 0.0),
            }
        )
    return sites
