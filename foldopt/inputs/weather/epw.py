"""EnergyPlus weather files (EPW), through pvlib ``iotools.read_epw``.

Eight header lines (the first, ``LOCATION``, holds the site) and one row per hour, stamped with
the end of its hour; pvlib moves the stamps back an hour, to the start of each interval.
"""

from __future__ import annotations

from functools import partial

import pandas as pd
import pvlib

from foldopt.inputs.weather.formats import (WeatherFormat, check_site_fields, header_fields, header_site, line_locator,
                                            read_with_pvlib, refuse_february_29, table_index, table_rows)

#: Lines before the first row.
HEADER_LINES = 8
#: The first header line's fields, as pvlib names them.
HEADER_FIELDS = ("LOCATION", "city", "state-prov", "country", "data_type", "WMO_code", "latitude", "longitude", "TZ",
                 "altitude")


def check_header(fail, first_line: str) -> None:
    """The first line of an EPW file: ``LOCATION`` and the site's fields, as pvlib reads them.

    Parameters
    ----------
    fail : callable
        ``fail(message)``: the error to raise.
    first_line : str
    """
    if first_line.rstrip("\r\n").split(",")[0].strip() != "LOCATION":
        raise fail(f"line 1: not an EPW header: it starts {first_line[:20]!r}, not 'LOCATION,'")
    check_site_fields(fail, HEADER_FIELDS, header_fields(fail, FORMAT.label, HEADER_FIELDS, first_line))


def read(path: str, text: str, year: int, fail):
    """An EPW file through pvlib, its year coerced to ``year``, and the file line of each row.

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
    # pvlib cannot coerce an EPW file's February 29 to a year without one.
    if not pd.Timestamp(year=year, month=1, day=1).is_leap_year:
        refuse_february_29(fail, [n for n in line_of if [f.strip() for f in lines[n - 1].split(",", 3)[1:3]]
                                  == ["2", "29"]], f"{year} has none")
    data, meta = read_with_pvlib(fail, FORMAT.label, pvlib.iotools.read_epw, path, coerce_year=year)
    index = table_index(data, HEADER_LINES, fail)
    return data, meta, index, line_locator(line_of, len(data), HEADER_LINES)


FORMAT = WeatherFormat(
    name="epw", label="EPW", interval_label="start", suffixes=(".epw",),
    columns={"ghi": "field 14", "dni": "field 15", "dhi": "field 16", "temp_air": "field 7", "wind_speed": "field 22"},
    columns_at="its rows", read=read, site=partial(header_site, name="city"), stamp_lag=1.0,
    # Missing values of the columns used (EnergyPlus, "EnergyPlus Weather File (EPW) Data Dictionary").
    missing={"ghi": 9999.0, "dni": 9999.0, "dhi": 9999.0, "temp_air": 99.9, "wind_speed": 999.0})
