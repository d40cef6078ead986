"""The Linke turbidity climatology that pvlib bundles, read once per site and day.

pvlib's ``clearsky.lookup_linke_turbidity`` [1]_ opens ``LinkeTurbidities.h5`` (12 monthly
values on a 5-arcminute grid, as 20 x the turbidity, gzip-compressed in chunks of 135 x 270 grid
points) at every call and interpolates the month values to the UTC day of year of every time
stamp. :func:`linke_turbidity` gives the same values, to the bit (tests/test_atmosphere.py holds
it to pvlib's own lookup on random sites and days), for a whole clock grid at once: the file is
kept open in the process, so that its chunk cache serves the neighbouring sites of a map, and the
interpolation runs once per UTC day, not per step: pvlib's lookup opens the file, decompresses a
chunk and builds a pandas index of every step at each call, a cost per site that a map pays at
every site (docs/performance.rst).

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


@functools.lru_cache(maxsize=1)
def _dataset():
    """The climatology's dataset, its file open for the life of the process (read-only)."""
    import h5py
    import pvlib

    path = Path(pvlib.__file__).parent / "data" / "LinkeTurbidities.h5"
    return h5py.File(path, "r")["LinkeTurbidity"]


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


def linke_turbidity(latitude: float, longitude: float, utc_ns) -> np.ndarray:
    """The Linke turbidity [-] of a site at UTC instants, as pvlib's ``lookup_linke_turbidity``:
    the monthly values interpolated linearly to the UTC day of year, each at its month's middle.

    Parameters
    ----------
    latitude, longitude : float
        [deg north], [deg east].
    utc_ns : array_like of int64
        UTC instants [ns since 1970-01-01], any shape.

    Returns
    -------
    numpy.ndarray
        The turbidity, shaped as ``utc_ns``.
    """
    # pvlib interpolates the values as 20 x the turbidity and divides after.
    monthly = np.asarray(
        _dataset()[
            _grid_index(latitude, 90.0, -90.0, GRID_SHAPE[0]),
            _grid_index(longitude, -180.0, 180.0, GRID_SHAPE[1]),
        ]
    )
    around = np.concatenate([[monthly[-1]], monthly, [monthly[0]]])
    days = np.floor_divide(np.asarray(utc_ns, dtype=np.int64), NS_PER_DAY)
    if days.size == 0:
        return np.zeros(days.shape)
    first = int(days.min())
    dates = np.arange(first, int(days.max()) + 1).astype("datetime64[D]")
    years = dates.astype("datetime64[Y]")
    dayofyear = (dates - years).astype(np.int64) + 1
    year = years.astype(np.int64) + 1970
    leap = (year % 4 == 0) & ((year % 100 != 0) | (year % 400 == 0))
    values = np.where(
        leap,
        np.interp(dayofyear, _month_middles(True), around),
        np.interp(dayofyear, _month_middles(False), around),
    )
    return (values / 20.0)[days - first]
