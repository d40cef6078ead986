"""Weather files and pvlib clear skies: global, direct and diffuse irradiance per time step.

Weather files are read through pvlib.iotools (TMY3, EPW, PVGIS TMY) once per study, with the site
in their header (:func:`weather_site`). As pvlib returns them, timestamps mark the end of each
interval for TMY3 and its start for EPW (pvlib moves EPW's hour-ending rows back an hour) and for
PVGIS (hour-start stamps, in UTC, moved here to the site's standard time); foldopt moves them to
the interval centre, like its own clear-sky steps. ``label`` overrides the convention. Years are
coerced to one (a TMY mixes years), so a non-leap year matches the files' 365 days.

A file's hourly means are evaluated on the study's own step (:func:`sub_hourly`): each hour's
clear-sky index, the ratio of its mean irradiance to the mean of the clear sky over the same hour
[3]_, is interpolated between hour centres and multiplied by the clear sky at every step, then
scaled so that each hour keeps its mean. Light then begins at sunrise and ends at sunset, as the
clear sky does, instead of being spread linearly from one hour's centre to the next.

References
----------
.. [1] pvlib.iotools.read_tmy3, read_epw, read_pvgis_tmy; pvlib.clearsky.ineichen,
   simplified_solis; pvlib.clearsky.lookup_linke_turbidity (bundled climatology).
.. [2] P. Ineichen, R. Perez, "A new airmass independent formulation for the Linke turbidity
   coefficient", Solar Energy 73(3), 151-157, 2002 (pvlib ``clearsky.ineichen``).
.. [3] The clear-sky index (pvlib ``irradiance.clearsky_index``, bounded by 2 for over-irradiance
   as pvlib bounds it); used to bring hourly irradiance to finer steps e.g. in A. P. Grantham,
   P. J. Pudney, J. W. Boland, M. Belusko, "Synthetically interpolated five-minute direct normal
   irradiance", MODSIM 2013, whose deterministic part (without the synthetic fluctuations) this is.
"""

from __future__ import annotations

import functools
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pvlib

from foldopt.names import CLEAR_SKIES, WEATHER_FORMATS

#: Which edge of its interval each format's timestamp marks, as pvlib.iotools returns it
#: (checked for TMY3 and EPW in tests/test_weather.py).
INTERVAL_LABELS = {"tmy3": "end", "epw": "start", "pvgis": "start"}
#: Bound of the clear-sky index at every step (pvlib's default: over-irradiance up to twice clear).
MAX_CLEARSKY_INDEX = 2.0


def weather_format(path: Path, fmt: str | None = None) -> str:
    """The file's format: given, or from its extension (``.epw``; ``.csv`` is TMY3; ``.json`` PVGIS)."""
    if fmt is not None:
        if fmt not in WEATHER_FORMATS:
            raise ValueError(f"weather format must be one of {', '.join(WEATHER_FORMATS)}; got {fmt!r}")
        return fmt
    suffix = Path(path).suffix.lower()
    return {".epw": "epw", ".csv": "tmy3", ".json": "pvgis"}.get(suffix, "tmy3")


def _offset_zone(hours: float) -> str:
    """A fixed UTC offset as foldopt spells it (``UTC-05:00``)."""
    minutes = round(hours * 60)
    sign = "+" if minutes >= 0 else "-"
    return f"UTC{sign}{abs(minutes) // 60:02d}:{abs(minutes) % 60:02d}"


def _site_of(fmt: str, meta: dict) -> dict:
    if fmt == "pvgis":
        inputs = meta["inputs"]
        location = inputs.get("location", inputs)
        latitude, longitude = float(location["latitude"]), float(location["longitude"])
        return {"name": None, "latitude": latitude, "longitude": longitude,
                "altitude": float(location["elevation"]), "timezone": _offset_zone(round(longitude / 15.0))}
    name = meta.get("Name") if fmt == "tmy3" else meta.get("city")
    return {"name": str(name).strip('" ') if name else None, "latitude": float(meta["latitude"]),
            "longitude": float(meta["longitude"]), "altitude": float(meta["altitude"]),
            "timezone": _offset_zone(float(meta["TZ"]))}


@functools.lru_cache(maxsize=8)
def _read(path: str, fmt: str, year: int, mtime: float):
    if fmt == "tmy3":
        data, meta = pvlib.iotools.read_tmy3(path, coerce_year=year, map_variables=True)
    elif fmt == "epw":
        data, meta = pvlib.iotools.read_epw(path, coerce_year=year)
    else:
        data, meta = pvlib.iotools.read_pvgis_tmy(path, map_variables=True)
        # PVGIS stamps are UTC: on the site's standard time, with the year wrapped around (a TMY
        # is a cyclic year) so that every local day is whole.
        zone = _site_of(fmt, meta)["timezone"]
        local = pd.DatetimeIndex(data.index).tz_convert(zone)
        data.index = local.map(lambda t: t.replace(year=year))
        data = data.sort_index()
    return data, meta


def weather_site(path, fmt: str | None = None) -> dict:
    """The site a weather file describes, from its header: ``name``, ``latitude``, ``longitude``
    [deg], ``altitude`` [m] and ``timezone`` (the fixed offset its timestamps keep)."""
    path = Path(path)
    fmt = weather_format(path, fmt)
    _, meta = _read(str(path.resolve()), fmt, 2025, path.stat().st_mtime)
    return _site_of(fmt, meta)


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
    columns = ("ghi", "dni", "dhi", "temp_air", "wind_speed")
    frame = pd.DataFrame({name: pd.to_numeric(data[name], errors="coerce").to_numpy() for name in columns},
                         index=index + shift)
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


def sub_hourly(means, clear, steps_per_interval: int, max_index: float = MAX_CLEARSKY_INDEX):
    """Irradiance at every step from interval means, by the clear-sky index (module docstring).

    Parameters
    ----------
    means : array_like
        (n_days, n_intervals) mean irradiance of each interval [W/m^2] (one component: GHI, DNI
        or DHI).
    clear : array_like
        (n_days, n_intervals * steps_per_interval) the clear sky's same component at the steps.
    steps_per_interval : int
        Steps in an interval; the steps fill the intervals in order.
    max_index : float, default 2
        Bound of the index at every step.

    Returns
    -------
    values : numpy.ndarray
        (n_days, n_steps) [W/m^2]: zero wherever the clear sky is, at most ``max_index`` times
        it, and with each interval's mean equal to the file's (to rounding), but where the clear
        sky is dark all interval long or the bound cuts in.
    placed : numpy.ndarray
        (n_days, n_intervals) the interval means the steps keep [W/m^2].
    """
    means = np.asarray(means, dtype=float)
    clear = np.asarray(clear, dtype=float)
    n_days, n_intervals = means.shape
    clear_mean = clear.reshape(n_days, n_intervals, steps_per_interval).mean(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        index = np.asarray(pvlib.irradiance.clearsky_index(means, clear_mean, max_index), dtype=float)
    # Dark intervals take the nearest lit interval's index, so the index does not ramp down toward
    # them inside a lit one; their own light is zero whatever the index.
    lit = clear_mean > 0
    positions = np.arange(n_intervals)
    before = np.maximum.accumulate(np.where(lit, positions, -1), axis=1)
    after = np.flip(np.minimum.accumulate(np.flip(np.where(lit, positions, n_intervals), axis=1), axis=1), axis=1)
    nearest = np.where(before >= 0, before, np.where(after < n_intervals, after, 0))
    index = np.where(lit, index, np.take_along_axis(index, nearest, axis=1) * lit.any(axis=1, keepdims=True))
    # Linear between interval centres, held beyond the first and the last.
    centres = (positions + 0.5) * steps_per_interval - 0.5
    steps = np.arange(n_intervals * steps_per_interval)
    right = np.clip(np.searchsorted(centres, steps, side="right"), 1, n_intervals - 1)
    weight = np.clip((steps - centres[right - 1]) / steps_per_interval, 0.0, 1.0)
    values = (index[:, right - 1] * (1.0 - weight) + index[:, right] * weight) * clear
    # Each interval keeps its mean, then the bound holds at every step.
    shaped = values.reshape(n_days, n_intervals, steps_per_interval)
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.where(shaped.mean(axis=-1) > 0, means / shaped.mean(axis=-1), 0.0)
    values = np.minimum(shaped * scale[..., None], max_index * clear.reshape(shaped.shape))
    return values.reshape(n_days, -1), values.mean(axis=-1)


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
