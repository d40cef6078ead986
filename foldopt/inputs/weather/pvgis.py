"""PVGIS typical meteorological years (JSON), through pvlib ``iotools.read_pvgis_tmy``.

One record per hour in ``outputs.tmy_hourly``, stamped with the start of its hour in UTC, and
the site in ``inputs.location``; the stamps move to the site's standard time once the records
are checked (:func:`to_local`).
"""

from __future__ import annotations

import io
import json

import numpy as np
import pandas as pd

from foldopt.inputs.weather.formats import WeatherFormat, offset_zone, read_with_pvlib, site_value


def answer_records(text: str, key: str, kind: str, fail) -> tuple[dict, list]:
    """A PVGIS answer's JSON and its list of hourly records ``outputs[key]`` (a TMY's
    ``tmy_hourly``, an hourly series' ``hourly``).

    Parameters
    ----------
    text : str
        The answer's text.
    key : str
    kind : str
        What the answer is, for the message (``a PVGIS TMY file``).
    fail : callable
        ``fail(message)``: the error to raise.

    Returns
    -------
    tuple
        ``(answer, records)``: the decoded JSON and its records, possibly empty.
    """
    try:
        answer = json.loads(text)
    except json.JSONDecodeError as error:
        raise fail(
            f"not valid JSON: {error.msg} at line {error.lineno} column {error.colno}"
        ) from None
    outputs = answer.get("outputs") if isinstance(answer, dict) else None
    records = outputs.get(key) if isinstance(outputs, dict) else None
    if not isinstance(records, list):
        raise fail(f"not {kind}: no outputs.{key} list of hourly records")
    return answer, records


def read(path: str, text: str, year: int, fail):
    """A PVGIS TMY (JSON) file through pvlib, its stamps coerced to ``year`` (still UTC).

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
        ``(data, meta, index, where)`` (:class:`~foldopt.inputs.weather.formats.WeatherFormat`);
        ``where(i)`` names the record (``record 5``).
    """
    _, hourly = answer_records(text, "tmy_hourly", "a PVGIS TMY file", fail)
    if not hourly:
        raise fail("no data rows: outputs.tmy_hourly is empty")
    data, meta = read_with_pvlib(
        fail,
        FORMAT.label,
        "read_pvgis_tmy",
        io.StringIO(text),
        pvgis_format="json",
        map_variables=True,
    )
    inputs = meta.get("inputs") or {}
    location = inputs.get("location", inputs)
    for key in ("latitude", "longitude", "elevation"):
        if key not in location:
            raise fail(f"inputs.location has no {key}")
        site_value(fail, f"inputs.location.{key}", key, location[key])
    utc = pd.DatetimeIndex(data.index)
    leap = (utc.month == 2) & (utc.day == 29)
    if leap.any() and not pd.Timestamp(year=year, month=1, day=1).is_leap_year:
        first = int(np.flatnonzero(leap)[0])
        raise fail(
            f"record {first + 1} ({utc[first]:%Y-%m-%d %H:%M} UTC): February 29: {year} has none"
            + (f"; and {leap.sum() - 1} more rows" if leap.sum() > 1 else "")
        )
    index = in_year(utc, year)

    def where(i: int) -> str:
        return f"record {i + 1}"

    return data, meta, index, where


def site(meta: dict) -> dict:
    """The site of a PVGIS file's ``inputs.location``.

    Parameters
    ----------
    meta : dict
        pvlib's metadata.

    Returns
    -------
    dict
        ``name`` (None), ``latitude``, ``longitude`` [deg], ``altitude`` [m] (the elevation) and
        ``timezone``, the longitude's standard offset (PVGIS gives none).
    """
    inputs = meta["inputs"]
    location = inputs.get("location", inputs)
    latitude, longitude = float(location["latitude"]), float(location["longitude"])
    return {
        "name": None,
        "latitude": latitude,
        "longitude": longitude,
        "altitude": float(location["elevation"]),
        "timezone": offset_zone(round(longitude / 15.0)),
    }


def to_local(frame: pd.DataFrame, site: dict, year: int) -> pd.DataFrame:
    """Checked rows with UTC stamps on the site's standard time.

    Parameters
    ----------
    frame : pandas.DataFrame
        Indexed by UTC stamps of ``year``.
    site : dict
        The file's site (:func:`site`).
    year : int

    Returns
    -------
    pandas.DataFrame
        Indexed by local stamps, the year wrapped around (a TMY is a cyclic year) so that every
        local day is whole, in time order.
    """
    frame.index = in_year(frame.index.tz_convert(site["timezone"]), year)
    return frame.sort_index()


def in_year(stamps: pd.DatetimeIndex, year: int) -> pd.DatetimeIndex:
    """The stamps with their year replaced by ``year``, as ``Timestamp.replace(year=year)`` gives
    each: the same month, day and time of day, on the same fixed offset; without a Python call per
    stamp.

    Parameters
    ----------
    stamps : pandas.DatetimeIndex
        Naive or on a fixed offset from UTC (a zone without daylight saving time).
    year : int

    Returns
    -------
    pandas.DatetimeIndex
        Of the stamps' unit and zone, without a frequency.

    Raises
    ------
    ValueError
        For a February 29 and a ``year`` that has none.
    """
    wall = stamps.tz_localize(None)
    dates = wall.normalize()
    moved = pd.to_datetime({"year": year, "month": dates.month, "day": dates.day}).to_numpy()
    shifted = wall + (moved - dates.to_numpy())
    return pd.DatetimeIndex(shifted.as_unit(stamps.unit), freq=None).tz_localize(stamps.tz)


FORMAT = WeatherFormat(
    name="pvgis",
    label="PVGIS TMY",
    interval_label="start",
    suffixes=(".json",),
    # not an hourly series (``outputs.hourly``, the ``pvgis-hourly`` format's)
    signature=r'\A\s*\{\s*"(?:inputs|outputs|meta)"(?![\s\S]*"outputs"\s*:\s*\{\s*"hourly")',
    columns={
        "ghi": "G(h)",
        "dni": "Gb(n)",
        "dhi": "Gd(h)",
        "temp_air": "T2m",
        "wind_speed": "WS10m",
    },
    columns_at="outputs.tmy_hourly",
    read=read,
    site=site,
    to_local=to_local,
)
