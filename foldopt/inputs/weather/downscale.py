"""Light at every step of a study: a weather file's hourly means brought to the study's own step,
and pvlib's clear skies.

A file's hourly means become a smooth series at the study's own step (:func:`mean_preserving`):
the clear-sky index (each interval's mean irradiance over the clear sky's mean over the same
interval [1]_) is drawn as one curve that is continuous across interval boundaries, takes every
interval's mean exactly, and is multiplied by the clear sky, so that light begins at sunrise and
ends at sunset. The curve is the mean-preserving construction of Lai & Kaplan [2]_: values at the
interval edges from the neighbouring means, a line between them, and one shape term per interval,
zero at its edges, whose size is set by the interval's mean (here weighted by the clear sky). It
replaces the iterative smoothing of Rymes & Myers [3]_ with a closed form of the same properties
(continuous, mean-preserving, non-negative), vectorised over days and intervals.

:func:`hourly_light` applies it to the direct normal light along the clear sky's, and to the
diffuse light along the clear sky's global light (a cloudy sky's diffuse light, far above a clear
sky's, follows the sun as the global light does), and makes the global light from them,
``ghi = dni cos(zenith) + dhi``, at every step. The file's hourly DNI and DHI are kept, the two
that light a tilted panel; its GHI follows, within the file's own closure (on the Greensboro TMY3
sample the year's GHI comes out 0.09 % above the file's). :func:`interpolate_points` brings air
temperature and wind, which a file gives at its stamps, linearly to every step.

The clear skies are pvlib's (:func:`clear_sky`): Ineichen and Perez's with the Linke turbidity
[4]_, or the simplified Solis.

References
----------
.. [1] The clear-sky index, pvlib ``irradiance.clearsky_index`` (bounded by 2 for
   over-irradiance, as pvlib bounds it).
.. [2] L. O. Lai, J. O. Kaplan, "A fast mean-preserving spline for interpolating interval
   data", Journal of Atmospheric and Oceanic Technology 39(4), 503-512, 2022: continuous curves
   through interval-edge values with one control per interval set by its mean, and bounds by
   adjusting the edge values.
.. [3] M. D. Rymes, D. R. Myers, "Mean preserving algorithm for smoothly interpolating averaged
   data", Solar Energy 71(4), 225-231, 2001.
.. [4] P. Ineichen, R. Perez, "A new airmass independent formulation for the Linke turbidity
   coefficient", Solar Energy 73(3), 151-157, 2002 (pvlib ``clearsky.ineichen``); pvlib
   ``clearsky.simplified_solis`` and ``clearsky.lookup_linke_turbidity`` (bundled climatology).
"""

from __future__ import annotations


import numpy as np

from foldopt.names import CLEAR_SKIES

#: Bound of the clear-sky index at every step (pvlib's default: over-irradiance up to twice clear).
MAX_CLEARSKY_INDEX = 2.0
#: Below this cosine of the zenith (89 deg) no direct light is placed (here, in the cloud
#: ensemble and in measured files): a step's DNI from ``beam / cos(zenith)`` would hang on
#: rounding, and the sun is barely clear of the horizon of its refracted position.
MIN_COS_ZENITH = 0.0175
#: An edge value may be at most this multiple of either neighbouring interval's index: then the
#: shape term of the weaker interval cannot pull its curve below zero (with uniform weights the
#: curve's minimum is 1.5 K - (b0 + b1) / 4 for edge values b0, b1 and mean K).
EDGE_CAP = 2.0
#: Widths of the ramps of :func:`_ramped`, as parts of an interval, widest first (then two steps).
RAMP_WIDTHS = (0.5, 0.35, 0.25, 0.15, 0.1, 0.05)


def fill_dark(index, lit):
    """Each dark interval's index from the nearest lit interval of its day (0 for a dark day), so
    that the curve of a lit interval next to a dark one follows the lit one.

    Parameters
    ----------
    index : numpy.ndarray
        (n_days, n_intervals) an index per interval [-].
    lit : numpy.ndarray of bool
        Same shape: the intervals whose index counts.

    Returns
    -------
    numpy.ndarray
        ``index`` where ``lit``, else its day's nearest lit interval's; 0 all day without one.
    """
    n = index.shape[1]
    positions = np.arange(n)
    before = np.maximum.accumulate(np.where(lit, positions, -1), axis=1)
    after = np.flip(
        np.minimum.accumulate(np.flip(np.where(lit, positions, n), axis=1), axis=1), axis=1
    )
    nearest = np.where(before >= 0, before, np.where(after < n, after, 0))
    return np.where(
        lit, index, np.take_along_axis(index, nearest, axis=1) * lit.any(axis=1, keepdims=True)
    )


def mean_preserving(means, clear, steps_per_interval: int, max_index: float = MAX_CLEARSKY_INDEX):
    """Irradiance at every step from interval means, continuous across intervals (module docstring).

    In interval ``i`` of ``n`` steps, at ``u = (k + 0.5) / n`` for its step ``k``, the clear-sky
    index is ``x = b_i (1 - u) + b_(i+1) u + c_i 4 u (1 - u)``: a line between the edge values
    ``b`` plus a shape term zero at both edges, with ``c_i`` such that the interval's mean of
    ``x * clear`` is the file's mean [2]_. The edge values are the mean of the two neighbouring
    indices, at most :data:`EDGE_CAP` times the smaller and ``max_index``; the first and last
    edges take their interval's index. An interval whose curve would leave ``[0, max_index]`` (a
    bright interval next to a dark one, or one whose clear sky rises steeply at sunrise) takes
    instead a plateau reached by ramps from the same edge values (:func:`_ramped`): continuous,
    within bounds, and with the sharp change inside the interval rather than at its edge (Lai &
    Kaplan bound their spline by adjusting it within the interval, too [2]_). Only an interval
    whose mean the bound cannot hold (a clear-sky index above ``max_index``) is clipped and
    rescaled.

    Parameters
    ----------
    means : array_like
        (n_days, n_intervals) mean irradiance of each interval [W/m^2].
    clear : array_like
        (n_days, n_intervals * steps_per_interval) the clear sky's same component at the steps
        [W/m^2], zero when dark.
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
    n = steps_per_interval
    weight = clear.reshape(n_days, n_intervals, n)
    clear_mean = weight.mean(axis=-1)
    lit = clear_mean > 0
    with np.errstate(invalid="ignore", divide="ignore"):
        import pvlib

        index = np.asarray(
            pvlib.irradiance.clearsky_index(means, clear_mean, max_index), dtype=float
        )
    index = fill_dark(np.where(lit, index, 0.0), lit)
    cap = EDGE_CAP * np.minimum(index[:, 1:], index[:, :-1])
    # An interval at the bound (light at twice the clear sky, at sunrise) stays at it up to its
    # edge where its neighbour can take that (the cap), so that it keeps what light it can.
    saturated = lit & (means >= max_index * clear_mean * (1.0 - 1e-9))
    inner = np.where(
        saturated[:, 1:] | saturated[:, :-1],
        cap,
        np.minimum(0.5 * (index[:, 1:] + index[:, :-1]), cap),
    )
    edges = np.minimum(np.concatenate([index[:, :1], inner, index[:, -1:]], axis=1), max_index)
    u = (np.arange(n) + 0.5) / n
    bump = 4.0 * u * (1.0 - u)
    weighted_bump = (weight * bump).mean(axis=-1)
    line = edges[:, :-1, None] * (1.0 - u) + edges[:, 1:, None] * u
    with np.errstate(invalid="ignore", divide="ignore"):
        size = np.where(
            lit & (weighted_bump > 0), (means - (weight * line).mean(axis=-1)) / weighted_bump, 0.0
        )
    shaped = line + size[..., None] * bump
    bad = lit & ((shaped.min(axis=-1) < 0.0) | (shaped.max(axis=-1) > max_index))
    if bad.any():
        shaped = np.where(bad[..., None], _ramped(means, weight, edges, bad, max_index), shaped)
    values = np.clip(shaped, 0.0, max_index) * weight
    kept = values.mean(axis=-1)
    # An interval whose mean the bound can hold keeps it exactly; one whose cannot (light above
    # twice the clear sky, at sunrise) keeps what the bound lets through, and its edges.
    feasible = ~saturated
    with np.errstate(invalid="ignore", divide="ignore"):
        rescale = np.where(feasible & (kept > 0), means / kept, 1.0)
    values = np.minimum(values * rescale[..., None], max_index * weight)
    return values.reshape(n_days, -1), values.mean(axis=-1)


def _ramped(means, weight, edges, bad, max_index):
    """The index of intervals the smooth curve cannot keep in bounds: a plateau reached from each
    edge value by a straight ramp over a part ``d`` of the interval, the plateau set by the mean,
    ``d`` the widest of :data:`RAMP_WIDTHS` whose plateau lies in ``[0, max_index]`` (a narrow
    enough ramp always gives one, the plateau tending to the interval's index). Continuous at the
    edges and within bounds, it carries a sharp change from a dark hour to a bright one (an
    overcast hour after a clear one) without leaving the bounds; (n_days, n_intervals, n)."""
    n = weight.shape[-1]
    u = (np.arange(n) + 0.5) / n
    # The narrowest ramp spans two steps: its change at the interval's edge is then half its
    # largest inside (a one-step ramp would put half its change on the edge).
    widths = np.array(RAMP_WIDTHS + (min(2.0 / n, 0.5),))
    # (n_widths, n) from the left edge
    rise = np.clip(1.0 - u[None, :] / widths[:, None], 0.0, None)
    fall = rise[:, ::-1]  # from the right edge
    left, right = edges[:, :-1, None], edges[:, 1:, None]
    ramps = weight @ rise.T, weight @ fall.T  # (n_days, n_intervals, n_widths) weighted sums
    rest = weight.sum(axis=-1, keepdims=True) - ramps[0] - ramps[1]
    with np.errstate(invalid="ignore", divide="ignore"):
        plateau = (means[..., None] * n - left * ramps[0] - right * ramps[1]) / rest
    fits = (plateau >= 0.0) & (plateau <= max_index) & (rest > 0)
    choice = np.where(fits.any(axis=-1), np.argmax(fits, axis=-1), widths.size - 1)
    # Where none fits (an interval the bound cannot hold: the narrowest ramp), the plateau is the bound.
    level = np.clip(
        np.nan_to_num(np.take_along_axis(plateau, choice[..., None], axis=-1)), 0.0, max_index
    )
    r0, r1 = rise[choice], fall[choice]
    return np.where(bad[..., None], level * (1.0 - r0 - r1) + left * r0 + right * r1, 0.0)


def hourly_light(
    dni, dhi, clear_ghi, clear_dni, cos_zenith, steps_per_interval: int, dni_extra=None
):
    """Direct, diffuse and global light at every step from interval means, closed at every step
    (module docstring).

    Parameters
    ----------
    dni, dhi : array_like
        (n_days, n_intervals) the file's mean direct normal and diffuse horizontal irradiance
        [W/m^2].
    clear_ghi, clear_dni : array_like
        (n_days, n_steps) the clear sky's global and direct normal light at the steps [W/m^2]:
        the shapes of the diffuse and the direct light.
    cos_zenith : array_like
        (n_days, n_steps) cosine of the solar zenith at the steps [-].
    steps_per_interval : int
    dni_extra : array_like, optional
        Extraterrestrial normal irradiance [W/m^2], broadcast to the steps: a bound of the DNI
        (QCRad's physically possible limit of :mod:`foldopt.inputs.weather.qc`).

    Returns
    -------
    light : dict
        ``ghi``, ``dni``, ``dhi`` (n_days, n_steps) [W/m^2], with ``ghi = dni cos(zenith) + dhi``
        at every step, all non-negative; no direct light below 1 deg of sun
        (:data:`MIN_COS_ZENITH`).
    placed : dict
        ``ghi``, ``dhi``, ``dni``: (n_days, n_intervals) the interval means the steps keep [W/m^2].
    """
    cos_zenith = np.asarray(cos_zenith, dtype=float)
    direct, _ = mean_preserving(dni, clear_dni, steps_per_interval)
    if dni_extra is not None:
        direct = np.minimum(direct, dni_extra)
    up = cos_zenith >= MIN_COS_ZENITH
    direct = np.where(up, direct, 0.0)
    diffuse, _ = mean_preserving(dhi, clear_ghi, steps_per_interval)
    light = {"ghi": direct * np.where(up, cos_zenith, 0.0) + diffuse, "dni": direct, "dhi": diffuse}
    shape = np.shape(dni) + (steps_per_interval,)
    return light, {key: values.reshape(shape).mean(axis=-1) for key, values in light.items()}


def interpolate_points(values, offset: float, steps_per_interval: int):
    """Values given at one point of each interval, linear to every step of their day (held
    beyond the day's first and last points, so that days need not be consecutive).

    Parameters
    ----------
    values : array_like
        (n_days, n_intervals) e.g. air temperature [C], given at each interval's centre plus
        ``offset`` intervals (``0.5``: its end, as TMY3 and EPW stamp their meteorological fields).
    offset : float
        Where in its interval each value stands, from the centre [intervals], in [-0.5, 0.5].
    steps_per_interval : int

    Returns
    -------
    numpy.ndarray
        (n_days, n_intervals * steps_per_interval).
    """
    values = np.asarray(values, dtype=float)
    n_intervals = values.shape[1]
    at = (np.arange(n_intervals) + 0.5 + offset) * steps_per_interval
    steps = np.arange(n_intervals * steps_per_interval) + 0.5
    right = np.clip(np.searchsorted(at, steps, side="right"), 1, max(n_intervals - 1, 1))
    if n_intervals == 1:
        return np.repeat(values, steps_per_interval, axis=1)
    weight = np.clip((steps - at[right - 1]) / (at[right] - at[right - 1]), 0.0, 1.0)
    return values[:, right - 1] * (1.0 - weight) + values[:, right] * weight


def clear_sky(
    apparent_zenith, airmass, dni_extra, altitude, model="ineichen", linke_turbidity=None
):
    """pvlib's clear sky at some steps, arrays in and out.

    Parameters
    ----------
    apparent_zenith : array_like
        The sun's apparent zenith [deg].
    airmass : array_like
        Relative air mass [-] (Kasten & Young's, pvlib's default; NaN or 0 with the sun down).
    dni_extra : array_like
        Extraterrestrial irradiance [W/m^2].
    altitude : float
        [m].
    model : {'ineichen', 'simplified-solis'}
        ``ineichen`` takes ``linke_turbidity``; ``simplified-solis`` uses its defaults (aerosol
        optical depth 0.1, precipitable water 1 cm).
    linke_turbidity : float or array_like, optional
        [-], for ``ineichen``: the study's, or the climatology's at the site
        (:func:`foldopt.inputs.turbidity.linke_turbidity`) [4]_.

    Returns
    -------
    dict
        ``ghi``, ``dni``, ``dhi`` [W/m^2], 0 with the sun down.

    Raises
    ------
    ValueError
        For a model that is not one of :data:`foldopt.names.CLEAR_SKIES`.
    """
    if model == "ineichen":
        import pvlib

        absolute = pvlib.atmosphere.get_absolute_airmass(
            airmass, pvlib.atmosphere.alt2pres(altitude)
        )
        with np.errstate(divide="ignore", invalid="ignore"):  # night: zero air mass terms
            sky = pvlib.clearsky.ineichen(
                apparent_zenith, absolute, linke_turbidity, altitude, dni_extra
            )
    elif model == "simplified-solis":
        import pvlib

        sky = pvlib.clearsky.simplified_solis(
            90.0 - np.asarray(apparent_zenith), pressure=pvlib.atmosphere.alt2pres(altitude)
        )
    else:
        raise ValueError(f"clear sky must be one of {', '.join(CLEAR_SKIES)}; got {model!r}")
    return {key: np.nan_to_num(np.asarray(sky[key], dtype=float)) for key in ("ghi", "dni", "dhi")}
