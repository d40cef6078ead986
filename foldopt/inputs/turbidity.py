"""The Linke turbidity climatology that pvlib bundles, read once per site and day.

pvlib's ``clearsky.lookup_linke_turbidity`` [1]_ opens ``LinkeTurbidities.h5`` (12 monthly
values on a 5-arcminute grid, as 20 x the turbidity, gzip-compressed in chunks of 135 x 270 grid
points) at every call and interpolates the month values to the UTC day of year of every time
stamp. :func:`linke_turbidity` gives the same values, to the bit (tests/test_atmosphere.py holds
it to pvlib's own lookup on random sites and days, one site or many in a call), for a whole
clock grid of many sites at once: the file is kept open in the process with a chunk cache that
holds the neighbouring sites of a map's chunks (a site's 12 months are 6 chunks), and the
interpolation runs once per site and UTC day, not per step: pvlib's lookup opens the file,
decompresses the chunks and builds a pandas index of every step at each call, a cost per site
that a map pays at every site (docs/performance.rst). A one-site study reads its 6 chunks only.

References
----------
.. [1] pvlib ``clearsky.lookup_linke_turbidity``, from the SoDa/Meteotest climatology of
   J. Remund et al., "Worldwide Linke turbidity information", Proc. ISES Solar World Congress,
   2003: the grid's rows from 90 N to 90 S, columns from 180 W to 180 E, months January to
   December, each value at the middle of its month.
"""

from __future__ import annotations

import calendar
import functools
from pathlib import Path

import numpy as np

NS_PER_DAY = 86_400_000_000_000
#: Rows and columns of the climatology's grid (5 arcminutes).
GRID_SHAPE = (2160, 4320)


#: The file's chunk cache [bytes]: 460 of its 1,536 chunks of 135 x 270 points x 2 months
#: (73 kB decompressed), the neighbouring sites of a map's chunks on a worker, a site's 12 months
#: being 6 chunks (h5py's default of 1 MiB holds two sites' tiles, where a map going round a
#: latitude row meets 16 tiles before it comes back to one). Filled only as sites are read.
CHUNK_CACHE_BYTES = 32 << 20
#: Hash slots of the chunk cache: a prime, about 100 times the chunks it holds (as HDF5 advises).
CHUNK_CACHE_SLOTS = 49_999
#: Rows of steps given their turbidity at a time (256 rows of 288 steps: 0.6 MB of instants).
ROWS_AT_ONCE = 256


@functools.lru_cache(maxsize=1)
def _dataset():
    """The climatology's dataset, its file open for the life of the process (read-only)."""
    import h5py
    import pvlib

    path = Path(pvlib.__file__).parent / "data" / "LinkeTurbidities.h5"
    file = h5py.File(path, "r", rdcc_nbytes=CHUNK_CACHE_BYTES, rdcc_nslots=CHUNK_CACHE_SLOTS)
    return file["LinkeTurbidity"]


def _grid_index(degrees: float, low: float, high: float, count: int) -> int:
    """The grid point nearest ``degrees`` on ``count`` points from ``low`` to ``high`` (cell
    centres), as pvlib rounds it; within half a point beyond either end, the end point."""
    scale = count / (high - low)
    index = (degrees - (low + 1.0 / scale / 2.0)) * scale
    if index > count - 1 or index < 0:
        if min(abs(index - (count - 1)), abs(index)) > 0.500001:
            raise ValueError(f"{degrees} deg is outside the turbidity grid ({low}, {high})")
        return count - 1 if index > count - 1 else 0
    return int(np.around(index))


def _month_middles(leap: bool) -> np.ndarray:
    """The day of year of each month's middle, with last year's December before and next
    January after, as pvlib places the monthly values."""
    days = np.array(calendar.mdays[1:], dtype=float)
    if leap:
        days[1] += 1
    return np.concatenate(
        [
            [-calendar.mdays[12] / 2.0],
            np.cumsum(days) - days / 2.0,
            [days.sum() + calendar.mdays[1] / 2.0],
        ]
    )


def linke_turbidity(latitude, longitude, utc_ns) -> np.ndarray:
    """The Linke turbidity [-] of sites at UTC instants, as pvlib's ``lookup_linke_turbidity``:
    the monthly values interpolated linearly to the UTC day of year, each at its month's middle.

    One call serves many sites (a map's chunk of blocks): each distinct site's months are read
    once and interpolated once per UTC day, and the steps take their day's value.

    Parameters
    ----------
    latitude, longitude : float or array_like
        [deg north], [deg east]: one site, or one per row of ``utc_ns`` (shape ``(n_rows,)``).
    utc_ns : array_like of int64
        UTC instants [ns since 1970-01-01], any shape (with a site per row: ``(n_rows, ...)``).

    Returns
    -------
    numpy.ndarray
        The turbidity, shaped as ``utc_ns``.
    """
    utc_ns = np.asarray(utc_ns, dtype=np.int64)
    if utc_ns.size == 0:
        return np.zeros(utc_ns.shape)
    latitude, longitude = np.asarray(latitude, dtype=float), np.asarray(longitude, dtype=float)
    # The distinct sites, as complex numbers: a 1-D sort, much quicker than unique rows.
    places, site = np.unique(latitude.ravel() + 1j * longitude.ravel(), return_inverse=True)
    steps = utc_ns.reshape(len(site), -1)
    low = np.floor_divide(steps.min(axis=1), NS_PER_DAY)
    high = np.floor_divide(steps.max(axis=1), NS_PER_DAY)
    first = int(low.min())
    table = _daily_values(places, first, int(high.max()))
    if np.all(high - low <= 1):
        # A row (a day's block) spans at most two UTC days: its steps before the second day's
        # midnight take the first day's value, the rest the second's (no division per step),
        # ROWS_AT_ONCE rows at a time so that a map's many rows pass through the CPU's cache.
        turbidity = np.empty(steps.shape)
        midnight = ((low + 1) * NS_PER_DAY)[:, None]
        before, after = table[site, low - first][:, None], table[site, high - first][:, None]
        for rows in range(0, len(steps), ROWS_AT_ONCE):
            part = slice(rows, rows + ROWS_AT_ONCE)
            np.copyto(turbidity[part], after[part])
            np.copyto(turbidity[part], before[part], where=steps[part] < midnight[part])
    else:
        turbidity = table[site[:, None], np.floor_divide(steps, NS_PER_DAY) - first]
    return turbidity.reshape(utc_ns.shape)


def _daily_values(places: np.ndarray, first: int, last: int) -> np.ndarray:
    """The turbidity [-] of ``places`` (n latitudes + 1j x longitudes [deg]) on the UTC days
    ``first`` to ``last`` [days since 1970-01-01], shaped (n, days)."""
    dates = np.arange(first, last + 1).astype("datetime64[D]")
    years = dates.astype("datetime64[Y]")
    dayofyear = (dates - years).astype(np.int64) + 1
    year = years.astype(np.int64) + 1970
    leap = (year % 4 == 0) & ((year % 100 != 0) | (year % 400 == 0))
    # pvlib interpolates the values as 20 x the turbidity and divides after.
    table = np.empty((len(places), len(dates)))
    for index, place in enumerate(places):
        monthly = np.asarray(
            _dataset()[
                _grid_index(place.real, 90.0, -90.0, GRID_SHAPE[0]),
                _grid_index(place.imag, -180.0, 180.0, GRID_SHAPE[1]),
            ]
        )
        around = np.concatenate([[monthly[-1]], monthly, [monthly[0]]])
        table[index] = np.interp(dayofyear, _month_middles(False), around)
        if leap.any():
            table[index, leap] = np.interp(dayofyear[leap], _month_middles(True), around)
    return table / 20.0
