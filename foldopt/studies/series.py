"""A study's time series, step by step: the sun, the light and air, each half's plane-of-array
irradiance, the powers of flat, twofold (its halves and its connection) and tracker, and whether
each design runs the load (``timeseries.csv`` of a day's study and of a study over many days).

Every column comes from the evaluation the study's numbers come from: the power curves its
rows' ``t_solar`` were reduced from (:func:`foldopt.studies.designs.design_metrics`' ``curves``),
the tracker its rows were reduced from and the sky they saw, so that a design's
``solar_powered_<design>`` steps, times the step, are its ``t_solar`` to within half a step at
each crossing of the load (``t_solar`` takes the power as linear between step centres). Whole arrays,
(blocks, steps) or (blocks, loads, steps): no loop over the steps.

A study over many days writes its series as ``timeseries.csv`` up to :data:`PARQUET_ROWS` rows and
as ``timeseries.parquet`` (pyarrow) above: a year of 1-min steps for two loads is a million rows.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from foldopt.engine import evaluation as engines
from foldopt.engine.metrics import per_load
from foldopt.engine.sky import Sky

if TYPE_CHECKING:
    import pandas as pd

#: Rows of a study's series above which it is written as ``timeseries.parquet``, not ``.csv``.
PARQUET_ROWS = 20_000
#: Rows of a study's series above which it is not made: some 20 numbers a row, a few GB held at
#: once (a year of minutes for 19 loads is 10 M rows); the answer says so and how to get it.
MAX_ROWS = 10_000_000
#: Columns of a series that hold one value a case (or a site): a parquet file keeps them as a
#: dictionary; the other numbers byte-stream-split, which makes a year of minutes a fifth
#: smaller than plain zstd, and faster to write.
CASE_COLUMNS = ("latitude", "p_load_w", "fold_angle_deg")
#: The zenith a mode's sun gives, by pvlib's names: exact mode's SPA refracted (the apparent
#: zenith), paper mode's geometric (Shin et al.'s Eq. 3-6, no refraction).
ZENITH = {"exact": "apparent_zenith", "paper": "zenith"}
#: The designs whose ``solar_powered_<design>`` a series has: those whose curves it holds.
POWERED = ("flat", "twofold", "tracker")


def sky_columns(sky: Sky) -> dict:
    """The sun, light and air every step of a sky used (the weather's, or the clear sky's).

    Parameters
    ----------
    sky : Sky

    Returns
    -------
    dict of numpy.ndarray
        ``apparent_zenith`` (exact mode) or ``zenith`` (paper mode), ``solar_azimuth`` [deg],
        ``dni``, ``ghi``, ``dhi`` (where the sky has them) [W/m^2], ``temp_air`` [C] and
        ``wind_speed`` [m/s] (a weather file's), each (n_blocks, n_steps).
    """
    shape = sky.dni.shape
    return {
        ZENITH[sky.mode]: sky.solar_zenith,
        "solar_azimuth": sky.solar_azimuth,
        "dni": sky.dni,
        **({"ghi": sky.ghi, "dhi": sky.dhi} if sky.ghi is not None else {}),
        "temp_air": (
            sky.temp_steps
            if sky.temp_steps is not None
            else np.broadcast_to(np.asarray(sky.temp_air, dtype=float)[:, None], shape)
        ),
        **({"wind_speed": sky.wind_speed} if sky.wind_speed is not None else {}),
    }


def half_poa(sky: Sky, orientation) -> dict:
    """Each half's plane-of-array irradiance: pvlib's ``poa_global``, the light incident on it
    (before an incidence-angle modifier), as the study's irradiation totals take it.

    Parameters
    ----------
    sky : Sky
    orientation : array_like
        (n_blocks, 4) one panel per block: east tilt, east azimuth, west tilt, west azimuth [deg].

    Returns
    -------
    dict of numpy.ndarray
        ``poa_global_east_w_m2`` and ``poa_global_west_w_m2`` [W/m^2], (n_blocks, n_steps).
    """
    orientation = np.asarray(orientation, dtype=float)
    paper = sky.mode == "paper"
    return {
        f"poa_global_{side}_w_m2": engines.poa(
            sky,
            orientation[:, 2 * index, None],
            orientation[:, 2 * index + 1, None],
            paper=paper,
            incident=True,
        )
        for index, side in enumerate(("east", "west"))
    }


def solar_powered(power, load, load_shape=None) -> np.ndarray:
    """Whether a power meets the load at each step: ``P_pv >= P_load`` (``t_solar``'s test).

    Parameters
    ----------
    power : array_like
        [W], time on the last axis.
    load : float or array_like
        The load [W] (a load profile's scale), broadcast against ``power``'s leading axes.
    load_shape : array_like, optional
        A load profile's P_load(t) for a scale of 1, broadcast against ``power``.

    Returns
    -------
    numpy.ndarray of bool
    """
    return per_load(np.asarray(power, dtype=float), load_shape) >= np.asarray(load)[..., None]


def year_piece(sky: Sky, orientation, loads, fold_angle_deg, curves: dict, tracker_power) -> dict:
    """One chunk of days of a study over many days, for :func:`year_series`.

    Parameters
    ----------
    sky : Sky
        The chunk's sky.
    orientation : array_like
        (n_blocks, n_loads, 4) the twofold panel's halves at each load's fold angle [deg].
    loads : numpy.ndarray
        (n_loads,) [W].
    fold_angle_deg : array_like
        (n_blocks, n_loads) the twofold panel's fold angle [deg].
    curves : dict
        :func:`foldopt.studies.designs.design_metrics`' ``curves``: ``flat`` (n_blocks, n_steps),
        ``east``, ``west`` and ``twofold`` (the study's connection), (n_blocks, n_loads, n_steps).
    tracker_power : numpy.ndarray
        (n_blocks, n_steps) [W].

    Returns
    -------
    dict of numpy.ndarray
        Per step (n_blocks, n_steps) or per load and step (n_blocks, n_loads, n_steps).
    """
    orientation = np.asarray(orientation, dtype=float)
    shape = sky.dni.shape
    poa = [half_poa(sky, orientation[:, load]) for load in range(loads.size)]
    load_shape = None if sky.load_shape is None else sky.load_shape[:, None]
    powers = {
        "p_flat_w": curves["flat"],
        "p_east_w": curves["east"],
        "p_west_w": curves["west"],
        "p_twofold_w": curves["twofold"],
        "p_tracker_w": tracker_power,
    }
    return {
        "utc_ns": sky.grid.utc_ns,
        "latitude": np.broadcast_to(np.asarray(sky.latitude, dtype=float)[:, None], shape),
        "p_load_w": np.broadcast_to(
            np.asarray(loads, dtype=float)[:, None], (shape[0], *loads.shape, shape[1])
        ),
        "fold_angle_deg": np.broadcast_to(
            np.asarray(fold_angle_deg, dtype=float)[..., None], (shape[0], loads.size, shape[1])
        ),
        **sky_columns(sky),
        **{name: np.stack([one[name] for one in poa], axis=1) for name in poa[0]},
        **powers,
        **{
            f"solar_powered_{design}": solar_powered(
                powers[f"p_{design}_w"]
                if design == "twofold"
                else powers[f"p_{design}_w"][:, None],
                loads[None, :],
                load_shape,
            )
            for design in POWERED
        },
    }


def year_series(pieces: list, timezone) -> pd.DataFrame:
    """A study's series over its days, a load after another, each of its days (and sites) in
    order: every step.

    Parameters
    ----------
    pieces : list of dict
        :func:`year_piece` of each chunk of days, in order.
    timezone : str or datetime.tzinfo
        The time zone the times are written in (the first site's).

    Returns
    -------
    pandas.DataFrame
        Indexed by the steps' tz-aware centres (``time``), local time with its UTC offset; the
        site's ``latitude``, the load ``p_load_w`` (a load profile's scale) and the twofold
        panel's ``fold_angle_deg``, then the sun, light and air (:func:`sky_columns`), the halves'
        ``poa_global`` (:func:`half_poa`), ``p_flat_w``, ``p_east_w``, ``p_west_w``,
        ``p_twofold_w`` (the study's connection), ``p_tracker_w`` [W] and
        ``solar_powered_flat``, ``_twofold``, ``_tracker``.
    """
    import pandas as pd

    n_loads = pieces[0]["p_load_w"].shape[1]
    sizes = [piece["utc_ns"].shape[0] for piece in pieces]
    starts = np.cumsum([0, *sizes])
    n_steps = pieces[0]["utc_ns"].shape[1]

    def per_load(name, out):
        # Written in place, a load after another: (days, steps) repeats for each load,
        # (days, loads, steps) is taken load by load.
        laid = out.reshape(n_loads, starts[-1], n_steps)
        for piece, first, last in zip(pieces, starts[:-1], starts[1:], strict=True):
            values = piece[name]
            laid[:, first:last] = values[None] if values.ndim == 2 else np.moveaxis(values, 1, 0)
        return out

    rows = n_loads * starts[-1] * n_steps
    utc = per_load("utc_ns", np.empty(rows, dtype=np.int64))
    time = pd.DatetimeIndex(utc.astype("datetime64[ns]"), tz="UTC").tz_convert(timezone)
    names = [name for name in pieces[0] if name != "utc_ns"]
    floats = [name for name in names if pieces[0][name].dtype.kind == "f"]
    # The numbers as one block, column by column, that the frame takes as it is (no copy).
    block = np.empty((len(floats), rows))
    for index, name in enumerate(floats):
        per_load(name, block[index])
    frame = pd.DataFrame(block.T, columns=floats, index=time.rename("time"), copy=False)
    for name in (name for name in names if name not in floats):
        frame[name] = per_load(name, np.empty(rows, dtype=pieces[0][name].dtype))
    return frame


def series_refused(rows: int) -> str:
    """Why a study's series of ``rows`` rows is not made (above :data:`MAX_ROWS`), or ``""``."""
    if rows <= MAX_ROWS:
        return ""
    return (
        f"no timeseries: its {rows:,} rows (days x loads x steps) are above {MAX_ROWS:,}; fewer "
        "days or loads, or a longer step_min, write it"
    )


def parquet_options(series: pd.DataFrame) -> dict:
    """pyarrow's ``write_table`` options for a series (:data:`CASE_COLUMNS`)."""
    cases = [name for name in CASE_COLUMNS if name in series]
    numbers = [
        name for name, dtype in series.dtypes.items() if dtype.kind == "f" and name not in cases
    ]
    return {
        "compression": "zstd",
        "use_dictionary": cases,
        "column_encoding": dict.fromkeys(numbers, "BYTE_STREAM_SPLIT"),
    }


def series_file(series: pd.DataFrame) -> str:
    """The name a study's series is written as: ``timeseries.csv``, or ``timeseries.parquet`` above
    :data:`PARQUET_ROWS` rows."""
    return "timeseries.parquet" if len(series) > PARQUET_ROWS else "timeseries.csv"
