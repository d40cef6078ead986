"""Land and sea, offline: which grid sites are on land, and coastlines to draw maps against.

The source is the ``global-land-mask`` package (NOAA's GLOBE 30-arc-second land mask, 1 km),
shipped with it, so nothing is downloaded. The full mask is 930 MB in memory and takes seconds to
load; foldopt keeps a 5-arc-minute land fraction of it (each cell's share of land pixels) in its
cache folder (:func:`foldopt.cache.cache_dir`), built once and written atomically with a
checksum (:func:`foldopt.cache.store_cache`): a damaged cache is built again.
"""

from __future__ import annotations

from functools import cache

import numpy as np

#: 30-arc-second cells per cell of the cached land fraction (5 arc minutes, ~9 km).
_FACTOR = 10


@cache
def land_fraction() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The share of land of every 5-arc-minute cell, from the cache or built once.

    Returns
    -------
    latitudes, longitudes : numpy.ndarray
        Cell centres [deg], ascending.
    fraction : numpy.ndarray
        (2160, 4320) float32 share of land [-] of each cell.

    Raises
    ------
    ImportError
        Without the ``global-land-mask`` package (``pip install foldopt[map]``).
    """
    from foldopt.cache import cache_dir, load_cache, store_cache

    path = cache_dir() / f"land-fraction-{_FACTOR}.npz"
    stored = load_cache(path)
    if stored is not None:
        return stored["latitude"], stored["longitude"], stored["fraction"]
    latitude, longitude, fraction = _build()
    store_cache(
        path, {"latitude": latitude, "longitude": longitude, "fraction": fraction}, compress=True
    )
    return latitude, longitude, fraction


def _build() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`land_fraction` from the full mask."""
    from global_land_mask import globe  # loads the full mask: seconds, once per cache

    # (21600, 43200) True on water, latitude descending from 90, longitude from -180
    water = globe._mask
    rows, columns = water.shape[0] // _FACTOR, water.shape[1] // _FACTOR
    fraction = np.zeros((rows, columns), dtype=np.float32)
    for start in range(0, rows, 120):  # in bands, to keep the float copy small
        band = water[start * _FACTOR : (start + 120) * _FACTOR].reshape(
            -1, _FACTOR, columns, _FACTOR
        )
        fraction[start : start + 120] = 1.0 - band.mean(axis=(1, 3), dtype=np.float32)
    fraction = fraction[::-1].copy()  # latitude ascending
    step = 180.0 / rows
    latitude = -90 + step * (np.arange(rows) + 0.5)
    longitude = -180 + step * (np.arange(columns) + 0.5)
    return latitude, longitude, fraction


def is_land(latitude, longitude) -> np.ndarray:
    """Whether points lie on land.

    Parameters
    ----------
    latitude, longitude : array_like
        The points [deg], broadcast together.

    Returns
    -------
    numpy.ndarray of bool
        Whether each point lies in a 5-arc-minute cell that is mostly land (:func:`land_fraction`).

    Raises
    ------
    ImportError
        Without the ``global-land-mask`` package and no cached fraction.
    """
    lat_centres, lon_centres, fraction = land_fraction()
    step = lat_centres[1] - lat_centres[0]
    rows = np.clip(
        ((np.asarray(latitude, dtype=float) + 90) / step).astype(int), 0, lat_centres.size - 1
    )
    columns = np.clip(
        ((np.asarray(longitude, dtype=float) + 180) / step).astype(int) % lon_centres.size,
        0,
        lon_centres.size - 1,
    )
    return fraction[rows, columns] >= 0.5


def draw_coastlines(ax, color: str = "0.3", linewidth: float = 0.5) -> bool:
    """Coastlines on a map: the 0.5 contour of the land fraction, at 15 arc minutes (plenty for a
    world map).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Longitude [deg] on x, latitude [deg] on y.
    color : str
        The lines' colour.
    linewidth : float
        [pt].

    Returns
    -------
    bool
        Whether they were drawn: False, drawing nothing, without the mask package.
    """
    try:
        longitude, latitude, coarse = _coastline_grid()
    except ImportError:
        return False
    ax.contour(longitude, latitude, coarse, levels=[0.5], colors=color, linewidths=linewidth)
    return True


#: The coastlines' grid and the land fraction it was made of (:func:`_coastline_grid`).
_COASTLINE_GRID = {}


def _coastline_grid() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The land fraction at 15 arc minutes (the mean of 3 x 3 cells) and its cell centres [deg]:
    made once per land fraction (:func:`land_fraction`), as a map draws it on each of its figures
    and the mean over its 9 million cells costs more than the contour."""
    latitude, longitude, fraction = land_fraction()
    if _COASTLINE_GRID.get("of") is not fraction:
        coarse = fraction.reshape(fraction.shape[0] // 3, 3, fraction.shape[1] // 3, 3).mean(
            axis=(1, 3)
        )
        grid = (longitude.reshape(-1, 3).mean(axis=1), latitude.reshape(-1, 3).mean(axis=1), coarse)
        _COASTLINE_GRID.update(of=fraction, grid=grid)
    return _COASTLINE_GRID["grid"]
