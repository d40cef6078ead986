"""Weather files and pvlib clear skies: global, direct and diffuse irradiance per time step.

Weather files are read through pvlib.iotools (TMY3, EPW, PVGIS TMY) once per study. As pvlib
returns them, timestamps mark the end of each interval for TMY3 and its start for EPW (pvlib moves
EPW's hour-ending rows back an hour) and for PVGIS (hour-start stamps); foldopt moves them to the
interval centre, like its own clear-sky steps. ``label`` overrides the convention. Years are coerced to one (a TMY mixes
years), so a non-leap year matches the files' 365 days.

References
----------
.. [1] pvlib.iotools.read_tmy3, read_epw, read_pvgis_tmy; pvlib.clearsky.ineichen,
   simplified_solis; pvlib.clearsky.lookup_linke_turbidity (bundled climatology).
"""

from __future__ import annotations

import functools
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pvlib

WEATHER_FORMATS = ("tmy3", "epw", "pvgis")
#: Which edge of its interval each format's timestamp marks, as pvlib.iotools returns it
#: (checked for TMY3 and EPW in tests/test_weather.py).
INTERVAL_LABELS = {"tmy3": "end", "epw": "start", "pvgis": "start"}
CLEAR_SKIES = ("ineichen", "simplified-solis")


def weather_format(path: Path, fmt: str | None = None) -> str:
    """The file's format: given, or from its extension (``.epw``; ``.csv`` is TMY3; ``.json`` PVGIS)."""
    if fmt is not None:
        if fmt not in WEATHER_FORMATS:
            raise ValueError(f"weather format must be one of {', '.join(WEATHER_FORMATS)}; got {fmt!r}")
        return fmt
    suffix = Path(path).suffix.lower()
    return {".epw": "epw", ".csv": "tmy3", ".json": "pvgis"}.get(suffix, "tmy3")


@functools.lru_cache(maxsize=8)
def _read(path: str, fmt: str, year: int, mtime: float):
    if fmt == "tmy3":
        data, meta = pvlib.iotools.read_tmy3(path, coerce_year=year, map_variables=True)
    elif fmt == "epw":
        data, meta = pvlib.iotools.read_epw(path, coerce_year=year)
    else:
        data, _, _, meta = pvlib.iotools.read_pvgis_tmy(path, map_variables=True)
        data.index = data.index.map(lambda t: t.replace(year=year))
    return data, meta


def read_weather(path, fmt: str | None = None, year: int = 2025, label: str | None = None) -> pd.DataFrame:
    """Weather as ``ghi``, ``dni``, ``dhi`` [W/m^2], ``temp_air`` [C], ``wind_speed`` [m/s].

    Indexed by tz-aware interval centres (the file's own time zone), years coerced to ``year``.
    ``label`` (``start``, ``end`` or ``centre``) overrides the format's timestamp convention.
    """
    path = Path(path)
    fmt = weather_format(path, fmt)
    data, _ = _read(str(path.resolve()), fmt, year, path.stat().st_mtime)
    index = pd.DatetimeIndex(data.index)
    step = pd.Series(index).diff().median()
    label = label or INTERVAL_LABELS[fmt]
    shift = {"end": -step / 2, "start": step / 2, "centre": step * 0}[label]
    frame = pd.DataFrame(
        {name: pd.to_numeric(data[name], errors="coerce").to_numpy() for name in ("ghi", "dni", "dhi", "temp_air", "wind_speed")},
        index=index + shift,
    )
    return frame.sort_index().fillna({"temp_air": 20.0, "wind_speed": 1.0}).fillna(0.0)


def weather_days(frame: pd.DataFrame, dates) -> np.ndarray:
    """Row numbers of ``frame`` whose interval centres fall on each of ``dates`` (local to the
    file), (n_dates, n_steps): every date must hold the same number of rows."""
    days = frame.index.tz_localize(None).to_numpy().astype("datetime64[D]")
    wanted = np.array(dates, dtype="datetime64[D]")
    start, stop = np.searchsorted(days, wanted, side="left"), np.searchsorted(days, wanted, side="right")
    missing = [str(date) for date, a, b in zip(dates, start, stop, strict=True) if a == b]
    if missing:
        raise ValueError(f"the weather file has no data for {', '.join(missing[:3])}"
                         + (f" and {len(missing) - 3} more dates" if len(missing) > 3 else ""))
    counts = np.unique(stop - start)
    if counts.size != 1:
        raise ValueError(f"the weather file's days have different numbers of steps: {counts.tolist()}")
    return start[:, None] + np.arange(counts[0])


def weather_day(frame: pd.DataFrame, date) -> pd.DataFrame:
    """The intervals of ``frame`` whose centres fall on ``date`` (local to the file)."""
    return frame.iloc[weather_days(frame, [date])[0]]


def clear_sky(times, apparent_zenith, latitude, longitude, altitude, model="ineichen", linke_turbidity=None):
    """pvlib clear-sky ``ghi``, ``dni``, ``dhi`` [W/m^2] at ``times``.

    ``ineichen`` takes ``linke_turbidity``, or looks it up in pvlib's bundled climatology (offline);
    ``simplified-solis`` uses its defaults (aerosol optical depth 0.1, precipitable water 1 cm).
    """
    if model == "ineichen":
        turbidity = linke_turbidity
        if turbidity is None:
            with warnings.catch_warnings():
                # pvlib reads DatetimeIndex.dayofyear, which pandas 3 deprecates; not ours to fix.
                warnings.simplefilter("ignore", DeprecationWarning)
                warnings.simplefilter("ignore", FutureWarning)
                turbidity = pvlib.clearsky.lookup_linke_turbidity(times, latitude, longitude).to_numpy()
        airmass = pvlib.atmosphere.get_absolute_airmass(
            pvlib.atmosphere.get_relative_airmass(apparent_zenith), pvlib.atmosphere.alt2pres(altitude)
        )
        dni_extra = np.asarray(pvlib.irradiance.get_extra_radiation(times.day_of_year), dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):  # night: zero air mass terms
            sky = pvlib.clearsky.ineichen(apparent_zenith, airmass, turbidity, altitude, dni_extra)
    elif model == "simplified-solis":
        sky = pvlib.clearsky.simplified_solis(90.0 - np.asarray(apparent_zenith), pressure=pvlib.atmosphere.alt2pres(altitude))
    else:
        raise ValueError(f"clear sky must be one of {', '.join(CLEAR_SKIES)}; got {model!r}")
    return {key: np.nan_to_num(np.asarray(sky[key], dtype=float)) for key in ("ghi", "dni", "dhi")}
