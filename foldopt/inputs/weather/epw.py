"""EnergyPlus weather files (EPW), through pvlib ``iotools.read_epw``.

Eight header lines (the first, ``LOCATION``, holds the site) and one row per hour, stamped with
the end of its hour; pvlib moves the stamps back an hour, to the start of each interval.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

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
HEADER_LINES = 8
#: The first header line's fields, as pvlib names them.
HEADER_FIELDS = (
    "LOCATION",
    "city",
    "state-prov",
    "country",
    "data_type",
    "WMO_code",
    "latitude",
    "longitude",
    "TZ",
    "altitude",
)


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
    check_site_fields(
        fail, HEADER_FIELDS, header_fields(fail, FORMAT.label, HEADER_FIELDS, first_line)
    )


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
        refuse_february_29(
            fail,
            [
                n
                for n in line_of
                if [f.strip() for f in lines[n - 1].split(",", 3)[1:3]] == ["2", "29"]
            ],
            f"{year} has none",
        )
    data, meta = read_with_pvlib(fail, FORMAT.label, "read_epw", path, coerce_year=year)
    index = table_index(data, HEADER_LINES, fail)
    return data, meta, index, line_locator(line_of, len(data), HEADER_LINES)


FORMAT = WeatherFormat(
    name="epw",
    label="EPW",
    interval_label="start",
    suffixes=(".epw",),
    signature=r"\ALOCATION,",
    columns={
        "ghi": "field 14",
        "dni": "field 15",
        "dhi": "field 16",
        "temp_air": "field 7",
        "wind_speed": "field 22",
    },
    columns_at="its rows",
    read=read,
    site=partial(header_site, name="city"),
    stamp_lag=1.0,
    cover=("total_sky_cover", 10.0),
    # Missing values of the columns used (EnergyPlus, "EnergyPlus Weather File (EPW) Data Dictionary").
    missing={"ghi": 9999.0, "dni": 9999.0, "dhi": 9999.0, "temp_air": 99.9, "wind_speed": 999.0},
)


def write_epw(path, hourly: pd.DataFrame, site: dict) -> None:
    """Write hourly means as an EPW file that :func:`read` (and pvlib) reads back.

    Parameters
    ----------
    path : str or pathlib.Path
    hourly : pandas.DataFrame
        ``ghi``, ``dni``, ``dhi`` [W/m^2], ``temp_air`` [C], ``wind_speed`` [m/s], indexed by the
        tz-aware centres of whole hours on the site's standard time.
    site : dict
        ``name``, ``latitude``, ``longitude`` [deg], ``altitude`` [m], ``timezone`` (a fixed offset
        ``UTC-07:00``).

    Notes
    -----
    The fields other than these (humidity, pressure, sky cover...) are EPW's missing-value markers
    or neutral values; EPW hour ``h`` is the interval ``(h - 1, h]`` (EnergyPlus, "EnergyPlus
    Weather File (EPW) Data Dictionary"), and air temperature and wind are written at it as the
    hour's means.
    """
    offset = pd.Timestamp("2000-01-01", tz=hourly.index.tz).utcoffset().total_seconds() / 3600.0
    name = str(site.get("name") or "measured").replace(",", " ")
    header = [
        f"LOCATION,{name},-,-,measured,000000,{site['latitude']},{site['longitude']},{offset:g},"
        f"{site['altitude']}",
        "DESIGN CONDITIONS,0",
        "TYPICAL/EXTREME PERIODS,0",
        "GROUND TEMPERATURES,0",
        "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0",
        "COMMENTS 1,hourly means of a measured file written by foldopt",
        "COMMENTS 2,",
        "DATA PERIODS,1,1,Data,Sunday, 1/1,12/31",
    ]
    rows = []
    for when, row in zip(hourly.index, hourly.itertuples(index=False), strict=True):
        start = when - pd.Timedelta(minutes=30)
        fields = [
            start.year,
            start.month,
            start.day,
            start.hour + 1,
            60,
            "?",
            round(row.temp_air, 2),
            99.9,
            999,
            999999,
            9999,
            9999,
            9999,
            round(row.ghi, 3),
            round(row.dni, 3),
            round(row.dhi, 3),
            999999,
            999999,
            999999,
            9999,
            999,
            round(row.wind_speed, 2),
            99,
            99,
            9999,
            99999,
            9,
            999999999,
            999,
            0.999,
            999,
            99,
            999,
            999,
            99,
        ]
        rows.append(",".join(str(field) for field in fields))
    Path(path).write_text("\n".join(header + rows) + "\n")
