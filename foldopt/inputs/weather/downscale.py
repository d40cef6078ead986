"""Light at every step of a study: a weather file's hourly means brought to the study's own step,
and pvlib's clear skies.

A file's hourly means are evaluated on the study's own step (:func:`sub_hourly`): each hour's
clear-sky index, the ratio of its mean irradiance to the mean of the clear sky over the same hour
[1]_, is interpolated between hour centres and multiplied by the clear sky at every step, then
scaled so that each hour keeps its mean. Light then begins at sunrise and ends at sunset, as the
clear sky does, instead of being spread linearly from one hour's centre to the next. The clear
skies are pvlib's (:func:`clear_sky`): Ineichen and Perez's with the Linke turbidity [2]_, or the
simplified Solis.

References
----------
.. [1] The clear-sky index (pvlib ``irradiance.clearsky_index``, bounded by 2 for over-irradiance
   as pvlib bounds it); used to bring hourly irradiance to finer steps e.g. in A. P. Grantham,
   P. J. Pudney, J. W. Boland, M. Belusko, "Synthetically interpolated five-minute direct normal
   irradiance", MODSIM 2013, whose deterministic part (without the synthetic fluctuations) this is.
.. [2] P. Ineichen, R. Perez, "A new airmass independent formulation for the Linke turbidity
   coefficient", Solar Energy 73(3), 151-157, 2002 (pvlib ``clearsky.ineichen``); pvlib
   ``clearsky.simplified_solis`` and ``clearsky.lookup_linke_turbidity`` (bundled climatology).
"""

from __future__ import annotations

import warnings

import numpy as np
import pvlib

from foldopt.names import CLEAR_SKIES

#: Bound of the clear-sky index at every step (pvlib's default: over-irradiance up to twice clear).
MAX_CLEARSKY_INDEX = 2.0


def sub_hourly(means, clear, steps_per_interval: int, max_index: float = MAX_CLEARSKY_INDEX):
    """Irradiance at every step from interval means, by the clear-sky index (module docstring, [1]_).

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
    """pvlib's clear sky at some times.

    Parameters
    ----------
    times : pandas.DatetimeIndex
        tz-aware.
    apparent_zenith : array_like
        The sun's apparent zenith at ``times`` [deg].
    latitude, longitude : float
        [deg].
    altitude : float
        [m].
    model : {'ineichen', 'simplified-solis'}
        ``ineichen`` takes ``linke_turbidity``, or looks it up in pvlib's bundled climatology
        (offline) [2]_; ``simplified-solis`` uses its defaults (aerosol optical depth 0.1,
        precipitable water 1 cm).
    linke_turbidity : float or array_like, optional
        [-].

    Returns
    -------
    dict
        ``ghi``, ``dni``, ``dhi`` [W/m^2] at ``times``, 0 at night.

    Raises
    ------
    ValueError
        For a model that is not one of :data:`foldopt.names.CLEAR_SKIES`.
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
        sky = pvlib.clearsky.simplified_solis(90.0 - np.asarray(apparent_zenith),
                                              pressure=pvlib.atmosphere.alt2pres(altitude))
    else:
        raise ValueError(f"clear sky must be one of {', '.join(CLEAR_SKIES)}; got {model!r}")
    return {key: np.nan_to_num(np.asarray(sky[key], dtype=float)) for key in ("ghi", "dni", "dhi")}
