"""A grid map's table as NetCDF (``map.nc``): an xarray Dataset over latitude x longitude x load x
period with CF metadata [1]_, the form gridded solar data takes elsewhere, so that xarray and GIS
tools (QGIS, Panoply, CDO) open it directly.

The file is NetCDF-3 (classic), written by xarray's SciPy backend, which needs no HDF5 library. It
is written where a map's sites are points of a regular latitude x longitude grid (a sea point, or a
whole row of them, of a land-only grid is missing, its values ``_FillValue``); a map of named sites
or weather files keeps its tables alone. Each variable carries its unit (UDUNITS spelling [2]_)
and meaning from the column registry (:mod:`foldopt.output.columns`).

References
----------
.. [1] NetCDF Climate and Forecast (CF) Metadata Conventions, version 1.8, 2020 (cfconventions.org):
   Sec. 4.1 (latitude: ``units = degrees_north``, ``standard_name = latitude``), 4.2 (longitude),
   2.5.1 (``_FillValue`` for missing data), 2.6.1 (the ``Conventions`` attribute).
.. [2] UDUNITS-2, Unidata: the unit strings of ``units`` (``h``, ``W h``, ``percent``, ``degree``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from foldopt.files import versions, write_atomically
from foldopt.inputs.sites import lattice
from foldopt.output.columns import UNITS, describe
from foldopt.studies.map_request import PERIODS

#: Columns that are coordinates or labels, not variables.
_NOT_VARIABLES = ("site_id", "site_name", "weather", "latitude", "longitude", "period")


def _udunits(unit: str) -> str:
    """A registry unit in UDUNITS spelling, as CF asks (``1`` for a label's number)."""
    return UNITS[unit][1] if unit in UNITS else "1"


def grid_dataset(table: pd.DataFrame, relative: bool, title: str = "foldopt map"):
    """The map's rows as a Dataset, or None where its sites are no grid.

    Parameters
    ----------
    table : pandas.DataFrame
        A map's table (:attr:`foldopt.MapRun.table`): a row per site, load and period.
    relative : bool
        Whether the loads are fractions of each site's flat peak: the ``load`` dimension is then
        ``p_load_frac`` (and ``p_load_w`` a variable), else ``p_load_w``.
    title : str

    Returns
    -------
    xarray.Dataset or None
        Dimensions ``latitude``, ``longitude``, ``load`` and ``period``.
    """

    if (table["site_name"].astype(str) != "").any() or (table["weather"].astype(str) != "").any():
        return None
    latitudes, longitudes = lattice(table["latitude"]), lattice(table["longitude"])
    if latitudes is None or longitudes is None:
        return None
    load = "p_load_frac" if relative else "p_load_w"
    # A fraction is watts over the site's peak: the same load to 12 digits at every site.
    frame = (
        table.assign(load=table[load].round(12))
        .drop(columns=load)
        .set_index(["latitude", "longitude", "load", "period"])
    )
    variables = [
        c
        for c in frame.columns
        if c not in _NOT_VARIABLES and pd.api.types.is_numeric_dtype(frame[c])
    ]
    data = frame[variables].astype(float).to_xarray()
    data = data.reindex(
        latitude=latitudes,
        longitude=longitudes,
        period=[period for period in PERIODS if period in set(table["period"])],
    )
    for name in variables:
        entry = describe(name)
        if entry is not None:
            data[name].attrs.update(units=_udunits(entry[1]), long_name=entry[2])
    data["latitude"].attrs.update(
        units="degrees_north", standard_name="latitude", long_name="latitude", axis="Y"
    )
    data["longitude"].attrs.update(
        units="degrees_east", standard_name="longitude", long_name="longitude", axis="X"
    )
    entry = describe(load)
    data = data.assign_coords(load=data["load"])
    data["load"].attrs.update(units=_udunits(entry[1]), long_name=f"{load}: {entry[2]}")
    data["period"].attrs.update(long_name="year, or the season DJF, MAM, JJA, SON")
    data.attrs.update(
        Conventions="CF-1.8",
        title=title,
        source=f"foldopt {versions()['foldopt']}",
        references="Shin et al., Reconfigurable three dimensional photovoltaic panel architecture for "
        "solar-powered time extension",
    )
    return data


def write_grid_netcdf(
    table: pd.DataFrame, out: Path, relative: bool, title: str = "foldopt map"
) -> str | None:
    """Write ``map.nc`` in a map's folder, atomically, where its sites are a grid.

    Returns
    -------
    str or None
        ``"map.nc"``, or None where nothing was written.
    """
    data = grid_dataset(table, relative, title)
    if data is None:
        return None
    encoding = {name: {"_FillValue": np.nan} for name in data.data_vars}
    write_atomically(
        Path(out) / "map.nc",
        lambda temporary: data.to_netcdf(temporary, engine="scipy", encoding=encoding),
    )
    return "map.nc"
