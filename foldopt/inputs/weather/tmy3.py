"""NREL TMY3 files (CSV), through pvlib ``iotools.read_tmy3``.

Two header lines (the site, then the column names) and one row per hour, each stamped with the
end of its hour (``01:00`` is the hour 00:00-01:00), on the site's standard time.
"""

from __future__ import annotations

from functools import partial

import pandas as pd

from foldopt.inputs.weather.formats import (
    WeatherFormat,
    check_site_fields,
    header_fields,
    header_site,
    line_locator,
    read_with_pvlib,
    refuse_february_29,
    table_index,
    table_rows,
)

#: Lines before the first row.
HEADER_LINES = 2
#: The first header line's fields, as pvlib names them.
HEADER_FIELDS = ("USAF", "Name", "State", "TZ", "latitude", "longitude", "altitude")


def check_header(fail, first_line: str) -> None:
    """The first line of a TMY3 file: a station number and the site's fields, as pvlib reads them.

    Parameters
    ----------
    fail : callable
        ``fail(message)``: the error to raise.
    first_line : str
    """
    fields = header_fields(fail, FORMAT.label, HEADER_FIELDS, first_line)
    usaf = fields[0].strip()
    if not usaf.lstrip("+-").isdigit():
        raise fail(
            f"line 1: USAF = {usaf[:20]!r}: not a station number, so not a TMY3 header "
            f"({', '.join(HEADER_FIELDS)})"
        )
    check_site_fields(fail, HEADER_FIELDS, fields)


def read(path: str, text: str, year: int, fail):
    """A TMY3 file through pvlib, its year coerced to ``year``, and the file line of each row.

    Parameters
    ----------
    path : str
    text : str
        The file's text.
    year : int
    fail : callable
        ``fail(message)``: the error to raise.

    Returns
    -------
    tuple
        ``(data, meta, index, where)`` (:class:`~foldopt.inputs.weather.formats.WeatherFormat`).
    """
    lines = [line.rstrip("\r") for line in text.split("\n")]
    check_header(fail, lines[0])
    line_of = table_rows(lines, HEADER_LINES, FORMAT.label, fail)
    # pvlib reads a TMY3 file's February 29 as March 1: a leap year's hours would collide.
    refuse_february_29(
        fail,
        [n for n in line_of if lines[n - 1].lstrip('"').startswith("02/29/")],
        "pvlib reads a TMY3 file's February 29 as March 1",
    )
    data, meta = read_with_pvlib(
        fail, FORMAT.label, "read_tmy3", path, coerce_year=year, map_variables=True
    )
    index = table_index(data, HEADER_LINES, fail)
    last = index[-1]
    if last.year == year + 1 and (last.month, last.day, last.hour, last.minute) != (1, 1, 0, 0):
        # pvlib moves the last row to the next year, right for a year's closing 24:00 only: a file
        # that ends earlier keeps its last row in the year.
        index = index[:-1].append(pd.DatetimeIndex([last.replace(year=year)]))
    return data, meta, index, line_locator(line_of, len(data), HEADER_LINES)


FORMAT = WeatherFormat(
    name="tmy3",
    label="TMY3",
    interval_label="end",
    suffixes=(".csv",),
    signature=r"\A[^\n]*\n\s*Date \(MM/DD/YYYY\),Time",
    columns={
        "ghi": "GHI (W/m^2)",
        "dni": "DNI (W/m^2)",
        "dhi": "DHI (W/m^2)",
        "temp_air": "Dry-bulb (C)",
        "wind_speed": "Wspd (m/s)",
    },
    columns_at="line 2, the column names",
    read=read,
    site=partial(header_site, name="Name"),
    cover=("TotCld (tenths)", 10.0),
)
