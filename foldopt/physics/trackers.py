"""Sun trackers as they are built: their orientation over the day and the energy they spend.

Every model gives the panel's ``surface_tilt`` and ``surface_azimuth`` per time step, so the
study's own incidence model applies (exact angle of incidence, or Shin et al. Eq. 5, which is 1
for a panel facing the sun in both cases):

- ``dual-axis``: ideal, the normal always on the sun (Shin et al. Sec. IV-A).
- ``equatorial``: a polar daily axis turning with the hour angle and a seasonal axis set once a
  day to the declination at solar noon (Alexandru, Fig. 1a).
- ``dual-axis-steps``: the same equatorial mount driven by Alexandru's open-loop step law: N
  equal moves of the daily axis a day, symmetric about solar noon, over a given angular field;
  back to the morning position at night.
- ``single-axis``: pvlib's single-axis tracker (horizontal N-S axis by default, optionally
  tilted, with optional backtracking), by pvlib's formulas (:func:`singleaxis_orientation`).

Energy: a controller's standby power, drawn while the sun is up, plus a drive energy per move,
from Robles Algarin et al.'s DC motor model or a fixed Wh per degree (:class:`TrackerDrive`).

References
----------
.. [1] C. Alexandru, "A Novel Open-Loop Tracking Strategy for Photovoltaic Systems", The
   Scientific World Journal 2013, 205396: Sec. 4, the 12-step law for Brasov at the summer
   solstice (actuating times 8.839 ... 17.799 h local time).
.. [2] C. Robles Algarin, A. Ospino Castro, J. Casas Naranjo, "Dual-Axis Solar Tracker for Using
   in Photovoltaic Systems": Eq. 1 (motor transfer function), Sec. 2.1 (1:653 worm gear) and
   Sec. 3.3 (12 V gear motors, 5 A stall and 0.3 A free current, 4288 encoder counts per output
   revolution).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from foldopt.physics.geometry import normal_vector, orientation_from_normal
from foldopt.names import ALEXANDRU_STEP_OFFSETS_H, DRIVES, TRACKERS


def equatorial_normal(hour_angle, declination, latitude):
    """East-north-up unit vector toward a point of the sky given in equatorial coordinates.

    The normal of an equatorial mount whose daily (polar) axis is at ``hour_angle`` and whose
    seasonal axis is at ``declination`` [1]_ (Fig. 1a); with the sun's own coordinates it is the
    sun vector of Shin et al. Eq. 3 and 6.

    Parameters
    ----------
    hour_angle : array_like
        Hour angle [deg], negative to the east (before solar noon).
    declination : array_like
        Declination [deg].
    latitude : float or array_like
        Site latitude [deg north]; all three broadcast.

    Returns
    -------
    numpy.ndarray
        Shape ``broadcast + (3,)``: east, north and up components [-].
    """
    h, d, lat = np.radians(hour_angle), np.radians(declination), np.radians(latitude)
    east = -np.cos(d) * np.sin(h)
    north = np.sin(d) * np.cos(lat) - np.cos(d) * np.sin(lat) * np.cos(h)
    up = np.sin(d) * np.sin(lat) + np.cos(d) * np.cos(lat) * np.cos(h)
    return np.stack([east, north, up], axis=-1)


def step_law(hour_angle, steps=12, angular_field=90.0, offsets_h=ALEXANDRU_STEP_OFFSETS_H):
    """Daily angle [deg] of Alexandru's open-loop step law at the sun's hour angles.

    The daily axis starts the day at ``-angular_field / 2`` (facing east), moves by
    ``angular_field / steps`` at each of ``steps`` actuating times, which lie at ``-/+ offsets_h``
    hours from solar noon, and ends at ``+angular_field / 2``; the law is odd about noon.

    Parameters
    ----------
    hour_angle : array_like
        The sun's hour angle [deg], negative before solar noon.
    steps : int
        Moves a day (even).
    angular_field : float
        Total swing of the daily axis [deg].
    offsets_h : sequence of float
        ``steps / 2`` positive offsets of the afternoon moves from solar noon [h].

    Returns
    -------
    numpy.ndarray
        The daily axis' angle [deg] at each hour angle, in ``[-angular_field / 2,
        angular_field / 2]``.

    Raises
    ------
    ValueError
        If ``steps`` is not twice the number of ``offsets_h``.

    References
    ----------
    .. [1] C. Alexandru, "A Novel Open-Loop Tracking Strategy for Photovoltaic Systems", The
       Scientific World Journal 2013, 205396, Sec. 4.

    Examples
    --------
    Two moves a day, an hour either side of solar noon, over a 90 deg field:

    >>> print(step_law([-30.0, 0.0, 30.0], steps=2, angular_field=90.0, offsets_h=(1.0,)))
    [-45.   0.  45.]
    """
    offsets = np.sort(np.asarray(offsets_h, dtype=float))
    if steps != 2 * offsets.size:
        raise ValueError(f"steps ({steps}) must be twice the number of offsets ({offsets.size})")
    times = np.concatenate([-offsets[::-1], offsets]) * 15.0  # hour angles of the moves [deg]
    moves_done = np.searchsorted(times, np.asarray(hour_angle, dtype=float), side="right")
    return -angular_field / 2.0 + moves_done * angular_field / steps


def tracker_orientation(
    model,
    solar_zenith,
    solar_azimuth,
    hour_angle,
    declination,
    latitude,
    options=None,
    sun_vector=None,
):
    """Panel orientation of a tracker over the day.

    Parameters
    ----------
    model : str
        One of :data:`TRACKERS`.
    solar_zenith, solar_azimuth, hour_angle, declination : array_like
        The sun over the day [deg]; time on the last axis, any leading axes (days).
    latitude : float or array_like
        [deg], broadcast against the leading axes (shape (n_days, 1) for one per day).
    options : TrackerOptions, optional
        Step law and single-axis settings.
    sun_vector : array_like, optional
        The sun's unit vector (east, north, up) on a last axis of 3, where the caller has it: the
        ideal tracker's normal (default worked out from the zenith and azimuth).

    Returns
    -------
    surface_tilt, surface_azimuth : numpy.ndarray
        [deg] per time step.
    normal : numpy.ndarray
        The panel's unit normal (east, north, up) per time step, on a last axis of 3: what the
        light on the panel and its moves are worked out from.

    Raises
    ------
    ValueError
        If ``model`` is not one of :data:`foldopt.names.TRACKERS`.

    Notes
    -----
    While the sun is below the horizon a tracker rests in its stow position: the ideal and the
    equatorial trackers horizontal (facing the equator's side), the step-law tracker at its
    morning position (Alexandru's open-loop law returns there at night), the single-axis tracker
    flat along its axis (pvlib returns no angle then).
    """
    if model not in TRACKER_MODELS:
        raise ValueError(f"tracker must be one of {', '.join(TRACKERS)}; got {model!r}")
    return TRACKER_MODELS[model].orientation(
        solar_zenith,
        solar_azimuth,
        hour_angle,
        declination,
        latitude,
        options or TrackerOptions(),
        sun_vector,
    )


_UP = np.array([0.0, 0.0, 1.0])  # a level panel's normal


def _resting(solar_zenith, latitude):
    """The sun's zenith [deg] as floats, where the sun is down, and the azimuth [deg] of a level
    panel at rest (facing the equator's side)."""
    solar_zenith = np.asarray(solar_zenith, dtype=float)
    return solar_zenith, solar_zenith >= 90.0, np.where(np.asarray(latitude) >= 0, 180.0, 0.0)


def _noon_declination(hour_angle, declination):
    """The declination at each day's solar noon [deg], where an equatorial mount sets its seasonal axis."""
    noon = np.argmin(np.abs(hour_angle), axis=-1)[..., None]
    return np.take_along_axis(np.broadcast_to(declination, hour_angle.shape), noon, axis=-1)


def _dual_axis(solar_zenith, solar_azimuth, hour_angle, declination, latitude, options, sun_vector):
    """The ideal tracker: the normal on the sun, level at night."""
    solar_zenith, down, level_azimuth = _resting(solar_zenith, latitude)
    solar_azimuth = np.asarray(solar_azimuth, dtype=float)
    on_sun = (
        normal_vector(solar_zenith, solar_azimuth)
        if sun_vector is None
        else np.asarray(sun_vector, dtype=float)
    )
    # The normal made with its components along the time steps, as the sun's vector is laid out
    # where it comes from a sky and as the moves and the irradiance read it: no copy across.
    shape = np.broadcast_shapes(down.shape + (1,), on_sun.shape)
    normal = np.array(np.moveaxis(np.broadcast_to(on_sun, shape), -1, -2), order="C")
    for component, level in enumerate(_UP):  # (a mask a component: a third quicker than one where)
        np.copyto(normal[..., component, :], level, where=down)
    return (
        np.where(down, 0.0, solar_zenith),
        np.where(down, level_azimuth, solar_azimuth),
        np.moveaxis(normal, -2, -1),
    )


def _equatorial(
    solar_zenith, solar_azimuth, hour_angle, declination, latitude, options, sun_vector
):
    """The equatorial mount following the hour angle, level at night."""
    _, down, level_azimuth = _resting(solar_zenith, latitude)
    hour_angle = np.asarray(hour_angle, dtype=float)
    normal = equatorial_normal(hour_angle, _noon_declination(hour_angle, declination), latitude)
    surface_tilt, surface_azimuth = orientation_from_normal(normal, level_azimuth=level_azimuth)
    return (
        np.where(down, 0.0, surface_tilt),
        np.where(down, level_azimuth, surface_azimuth),
        np.where(down[..., None], _UP, normal),
    )


def _dual_axis_steps(
    solar_zenith, solar_azimuth, hour_angle, declination, latitude, options, sun_vector
):
    """The equatorial mount on Alexandru's step law, at its morning position at night."""
    _, down, level_azimuth = _resting(solar_zenith, latitude)
    hour_angle = np.asarray(hour_angle, dtype=float)
    seasonal = _noon_declination(hour_angle, declination)
    daily = step_law(hour_angle, options.steps, options.angular_field, options.step_offsets_h)
    daily = np.where(down, -options.angular_field / 2.0, daily)
    normal = equatorial_normal(daily, seasonal, latitude)
    return (*orientation_from_normal(normal, level_azimuth=level_azimuth), normal)


def _single_axis(
    solar_zenith, solar_azimuth, hour_angle, declination, latitude, options, sun_vector
):
    """pvlib's single-axis tracker (:func:`singleaxis_orientation`), flat along its axis at
    night."""
    solar_zenith, _, level_azimuth = _resting(solar_zenith, latitude)
    axis_azimuth = options.axis_azimuth if options.axis_azimuth is not None else level_azimuth
    axis_azimuth = np.broadcast_to(np.asarray(axis_azimuth, dtype=float), solar_zenith.shape)
    surface_tilt, surface_azimuth = singleaxis_orientation(
        solar_zenith,
        np.asarray(solar_azimuth, dtype=float),
        axis_tilt=options.axis_tilt,
        axis_azimuth=axis_azimuth,
        max_angle=options.max_angle,
        backtrack=options.backtrack,
        gcr=options.gcr,
    )
    # At night the tracker's angles are NaN; the panel then rests flat along the axis.
    surface_tilt = np.asarray(np.nan_to_num(surface_tilt, nan=options.axis_tilt))
    surface_azimuth = np.where(np.isnan(surface_azimuth), axis_azimuth, surface_azimuth)
    return surface_tilt, surface_azimuth, normal_vector(surface_tilt, surface_azimuth)


def _sind(angle):
    return np.sin(np.radians(angle))


def _cosd(angle):
    return np.cos(np.radians(angle))


def singleaxis_orientation(
    apparent_zenith, solar_azimuth, axis_tilt, axis_azimuth, max_angle, backtrack, gcr
):
    """The surface of a single-axis tracker, as ``pvlib.tracking.singleaxis`` orients it [3]_ (no
    cross-axis slope): the rotation that puts the sun in the plane normal to the panel through
    the axis, turned back against the next row's shade where ``backtrack`` (Anderson & Mikofski
    Eq. 14), clipped to ``max_angle``.

    pvlib's operations in pvlib's order (``shading.projected_solar_zenith_angle``,
    ``tracking.calc_surface_orientation``), so that the two agree to the bit
    (tests/test_tracker.py): a study with a single-axis tracker then imports no pvlib, whose
    import (with the scipy it loads) takes longer than the day's whole computation.

    Parameters
    ----------
    apparent_zenith, solar_azimuth : numpy.ndarray
        [deg], any shape.
    axis_tilt : float
        [deg].
    axis_azimuth : float or numpy.ndarray
        [deg], broadcast against the sun's angles.
    max_angle : float
        The largest rotation either way [deg].
    backtrack : bool
    gcr : float
        Ground coverage ratio [-].

    Returns
    -------
    surface_tilt, surface_azimuth : numpy.ndarray
        [deg], azimuth in [0, 360); NaN with the sun below the horizon (zenith above 90 deg).

    References
    ----------
    .. [3] pvlib ``tracking.singleaxis`` (BSD-3-Clause); K. Anderson, M. Mikofski, "Slope-Aware
       Backtracking for Single-Axis Trackers", NREL/TP-5K00-76626, 2020; W. F. Marion,
       A. P. Dobos, "Rotation Angle for the Optimum Tracking of One-Axis Trackers",
       NREL/TP-6A20-58891, 2013, Eq. 1.
    """
    sin_zenith = _sind(apparent_zenith)
    cos_axis_azimuth, sin_axis_azimuth = _cosd(axis_azimuth), _sind(axis_azimuth)
    sin_axis_tilt = _sind(axis_tilt)
    sx = sin_zenith * _sind(solar_azimuth)
    sy = sin_zenith * _cosd(solar_azimuth)
    sz = _cosd(apparent_zenith)
    sx_prime = sx * cos_axis_azimuth - sy * sin_axis_azimuth
    sz_prime = (
        sx * sin_axis_azimuth * sin_axis_tilt
        + sy * sin_axis_tilt * cos_axis_azimuth
        + sz * _cosd(axis_tilt)
    )
    down = np.asarray(apparent_zenith) > 90
    ideal = np.where(down, np.nan, np.degrees(np.arctan2(sx_prime, sz_prime)))
    rotation = ideal
    if backtrack:
        # The rows' spacing in panel widths; where the cosine is out of arccos's range at midday
        # no row shades the next and nothing is turned back.
        spread = np.abs(1 / gcr * _cosd(ideal))
        with np.errstate(invalid="ignore"):
            correction = np.degrees(-np.sign(ideal) * np.arccos(spread))
            rotation = ideal + np.where(spread < 1, correction, 0)
    rotation = np.clip(rotation, -max_angle, max_angle)
    with np.errstate(invalid="ignore", divide="ignore"):
        surface_tilt = np.degrees(np.arccos(_cosd(rotation) * _cosd(axis_tilt)))
    # The rotated surface's unit normal, projected on the ground for its azimuth.
    cos_a, sin_a = _cosd(-axis_azimuth), _sind(-axis_azimuth)
    sin_t = _sind(-axis_tilt)
    east = sin_a * sin_t * _cosd(rotation) + cos_a * _sind(rotation)
    north = sin_a * _sind(rotation) - cos_a * sin_t * _cosd(rotation)
    surface_azimuth = np.degrees(np.arctan2(east, north))
    surface_azimuth = np.mod(
        np.where(surface_tilt == 0.0, axis_azimuth - 90.0, surface_azimuth), 360.0
    )
    return np.where(down, np.nan, surface_tilt), np.where(down, np.nan, surface_azimuth)


@dataclass(frozen=True)
class TrackerModel:
    """One tracker model of :data:`TRACKER_MODELS`.

    Parameters
    ----------
    orientation : callable
        ``orientation(solar_zenith, solar_azimuth, hour_angle, declination, latitude, options,
        sun_vector)`` returning ``(surface_tilt, surface_azimuth, normal)``, as
        :func:`tracker_orientation`.
    options : tuple of str
        The fields of :class:`TrackerOptions` it reads; a study refuses the others given a value
        (:meth:`foldopt.inputs.sections.Tracker.idle_settings`).
    """

    orientation: Callable
    options: tuple = ()


#: The tracker models by name, as :data:`foldopt.names.TRACKERS` lists and describes them: a new
#: model is its function and its entry here (and its name and description there).
TRACKER_MODELS = {
    "dual-axis": TrackerModel(_dual_axis),
    "equatorial": TrackerModel(_equatorial),
    "dual-axis-steps": TrackerModel(_dual_axis_steps, ("steps", "angular_field", "step_offsets_h")),
    "single-axis": TrackerModel(
        _single_axis, ("axis_tilt", "axis_azimuth", "max_angle", "backtrack", "gcr")
    ),
}


@dataclass(frozen=True)
class TrackerOptions:
    """Settings of the step law and the single-axis tracker.

    Parameters
    ----------
    steps : int, default 12
        Moves a day of the step law (:func:`step_law`).
    angular_field : float, default 90
        Swing of the step law's daily axis [deg].
    step_offsets_h : tuple of float, default :data:`foldopt.names.ALEXANDRU_STEP_OFFSETS_H`
        The step law's afternoon moves after solar noon [h].
    axis_tilt : float, default 0
        Single-axis tracker: tilt of its axis [deg].
    axis_azimuth : float, optional
        Single-axis tracker: azimuth of its axis [deg]; default toward the equator (a N-S axis).
    max_angle : float, default 90
        Single-axis tracker: largest rotation [deg].
    backtrack : bool, default False
        Single-axis tracker: backtracking against row-to-row shading.
    gcr : float, default 0.35
        Single-axis tracker: ground coverage ratio [-], for backtracking.
    """

    steps: int = 12
    angular_field: float = 90.0
    step_offsets_h: tuple = ALEXANDRU_STEP_OFFSETS_H
    axis_tilt: float = 0.0
    axis_azimuth: float | None = None
    max_angle: float = 90.0
    backtrack: bool = False
    gcr: float = 0.35


@dataclass(frozen=True)
class TrackerDrive:
    """Energy a tracker spends: standby plus drive energy per move.

    ``motor`` follows Robles Algarin et al. [2]_: the identified speed response
    ``omega(s)/V(s) = 5571.57 / ((1 + 0.37138 s)(1 + 0.09175 s))``, read as encoder counts per
    second of the gear-motor output (4288 counts a revolution) for the 12 V step they used as
    unit input: 78 rpm at steady state, within the motors' 150-350 rpm no-load ratings. The panel
    turns 1/653 of the gear-motor output (worm gear). The current falls linearly from the 5 A
    stall current to the 0.3 A free current as the motor speeds up, all at 12 V. The paper does not
    state the unit of omega; this reading is foldopt's, and ``wh-per-degree`` replaces it with a
    measured figure.

    Parameters
    ----------
    standby_w : float, default 0
        The controller's draw while the sun is up [W].
    drive : {'motor', 'wh-per-degree'}
        Drive energy by the motor model or by ``wh_per_degree``.
    wh_per_degree : float, default 0
        Drive energy per degree the panel turns [Wh/deg] (``wh-per-degree``).
    gear_ratio : float, default 653
        Gear-motor output turns per panel turn [-].
    motor_voltage : float, default 12
        [V].
    stall_current, free_current : float, default 5 and 0.3
        Motor current at rest and at full speed [A].
    counts_per_revolution : float, default 4288
        Encoder counts per gear-motor output revolution [-].
    gain : float, default 5571.57
        Steady-state speed for the 12 V step [counts/s].
    tau_1, tau_2 : float, default 0.37138 and 0.09175
        Time constants of the two-pole speed response [s].
    """

    standby_w: float = 0.0
    drive: str = "motor"
    wh_per_degree: float = 0.0
    gear_ratio: float = 653.0
    motor_voltage: float = 12.0
    stall_current: float = 5.0
    free_current: float = 0.3
    counts_per_revolution: float = 4288.0
    gain: float = 5571.57  # [counts/s] for the unit (12 V) step
    tau_1: float = 0.37138  # [s]
    tau_2: float = 0.09175  # [s]

    def move_energy_wh(self, degrees, engine: str = "numpy"):
        """Drive energy of moves of the panel, each from rest.

        Parameters
        ----------
        degrees : array_like
            Angle of each move of the panel [deg]; the sign is ignored.
        engine : {'numpy', 'numba'}
            How the moves' times are solved (:func:`_time_to_turn`): the same bits either way.

        Returns
        -------
        numpy.ndarray
            Energy per move [Wh]; 0 for no move.

        Raises
        ------
        ValueError
            If :attr:`drive` is not one of :data:`foldopt.names.DRIVES`.

        Examples
        --------
        >>> print(TrackerDrive(drive="wh-per-degree", wh_per_degree=0.01).move_energy_wh([-15.0, 0.0]))
        [0.15 0.  ]
        """
        degrees = np.abs(np.asarray(degrees, dtype=float))
        if self.drive == "wh-per-degree":
            return self.wh_per_degree * degrees
        if self.drive != "motor":
            raise ValueError(f"drive must be one of {', '.join(DRIVES)}; got {self.drive!r}")
        # gear-motor output at steady state [deg/s]
        speed = self.gain / self.counts_per_revolution * 360.0
        moved = degrees > 0
        energy = np.zeros(degrees.shape)
        # gear-motor output rotation [deg]; only the moves are solved
        target = degrees[moved] * self.gear_ratio
        duration = _time_to_turn(target, speed, self.tau_1, self.tau_2, engine)
        # I(t) = I_stall - (I_stall - I_free) * omega(t) / omega_ss, so the charge is
        # I_stall * T - (I_stall - I_free) * angle / omega_ss.
        charge = (
            self.stall_current * duration
            - (self.stall_current - self.free_current) * target / speed
        )
        energy[moved] = self.motor_voltage * charge / 3600.0
        return energy


#: [s] Newton's last step for a move's time (:func:`_time_to_turn`): its energy then to 1e-11 Wh.
TURN_TOLERANCE_S = 1e-12

#: Moves solved together by :func:`_time_to_turn` (some 130 kB an array: within a core's cache).
TURN_BATCH = 1 << 14


def _time_to_turn(angle, speed, tau_1, tau_2, engine: str = "numpy"):
    """Time [s] to turn each ``angle`` [deg] of a 1-D array from rest, by Newton's method on the angle turned by ``t``
    [s] after a voltage step, for the two-pole speed response,
    ``speed (t - (tau_1^2 (1 - exp(-t / tau_1)) - tau_2^2 (1 - exp(-t / tau_2))) / (tau_1 - tau_2))``.

    It starts on the asymptote ``angle / speed + tau_1 + tau_2`` (the motor at full speed after its
    delay), which lies above the root; the angle turned ``f`` is convex in time, so the steps descend
    onto it monotonically. Newton's error after a step is at most ``max f'' / (2 f'(t))`` times the
    square of the error before it (``t`` the step's start, ``f'`` increasing), and that error is at
    most twice the step once the steps halve it; ``f''`` peaks at ``t* = ln(tau_1 / tau_2) tau_1
    tau_2 / (tau_1 - tau_2)``. Each move stops once that bound on what its last step left, or the
    step itself, is at most :data:`TURN_TOLERANCE_S`: a map's moves (some 53,000 a site) in two
    steps where waiting for a step below the tolerance took three, the times the same to within
    their last bits (some moves never settle on a fixed point: they change in their last bit, back
    and forth).

    The moves go :data:`TURN_BATCH` at a time, each step's arithmetic in place: the same operations
    on each move as on its own, over arrays that stay in the core's cache. With ``engine="numba"``
    each step's arithmetic is one compiled pass (:func:`_newton_compiled`), the same bits: a
    sky's many moves (a map's); ``numpy`` imports no numba (a day's study).

    References
    ----------
    .. [1] E. Süli, D. Mayers, "An Introduction to Numerical Analysis", Cambridge University Press,
       2003, Sec. 1.4: Newton's error ``e_{n+1} = f''(xi) / (2 f'(x_n)) e_n^2``.
    """
    angle = np.asarray(angle, dtype=float)
    t = angle / speed + tau_1 + tau_2
    peak = math.log(tau_1 / tau_2) * tau_1 * tau_2 / (tau_1 - tau_2)
    bend = speed * (math.exp(-peak / tau_1) - math.exp(-peak / tau_2)) / (tau_1 - tau_2)  # max f''
    solve = _newton_compiled if engine == "numba" else _newton
    for first in range(0, t.size, TURN_BATCH):
        batch = slice(first, first + TURN_BATCH)
        solve(angle[batch], t[batch], speed, tau_1, tau_2, bend)
    return t


def _newton(angle, t, speed, tau_1, tau_2, bend):
    """:func:`_time_to_turn`'s Newton steps on a batch of moves, ``t`` (their starts) updated in
    place. Each move stops on its own (its answer the same bits whatever other moves it is solved
    with): the steps go over the whole batch, nearly every move taking as many, and are kept for
    the moves still going alone."""
    span = tau_1 - tau_2
    going = np.ones(t.shape, dtype=bool)
    for _ in range(50):
        if not going.any():
            break
        decay_1, decay_2 = np.expm1(-t / tau_1), np.expm1(-t / tau_2)
        # turned = speed * (t + (tau_1^2 decay_1 - tau_2^2 decay_2) / span), the angle turned
        turned = tau_1**2 * decay_1
        turned -= tau_2**2 * decay_2
        turned /= span
        turned += t
        turned *= speed
        # rate = speed * (1 - (tau_1 (decay_1 + 1) - tau_2 (decay_2 + 1)) / span), its derivative
        decay_1 += 1.0
        decay_1 *= tau_1
        decay_2 += 1.0
        decay_2 *= tau_2
        decay_1 -= decay_2
        decay_1 /= span
        rate = np.subtract(1.0, decay_1, out=decay_1)
        rate *= speed
        # step = max(t - (turned - angle) / rate, 1e-9)
        turned -= angle
        turned /= rate
        step = np.subtract(t, turned, out=turned)
        np.maximum(step, 1e-9, out=step)
        moved = np.subtract(step, t, out=decay_2)
        np.abs(moved, out=moved)
        np.copyto(t, step, where=going)
        # left = bend / (2 rate) * (2 moved)^2, at most what the step left
        rate *= 2.0
        left = np.divide(bend, rate, out=rate)
        square = moved * 2.0
        left *= np.square(square, out=square)
        going &= np.minimum(moved, left, out=left) > TURN_TOLERANCE_S


def _newton_compiled(angle, t, speed, tau_1, tau_2, bend):
    """:func:`_newton` with each step's arithmetic one compiled pass
    (:func:`foldopt.physics.tracker_moves.newton_step`) between the batch's two ``expm1``."""
    from foldopt.physics.tracker_moves import newton_step  # numba's compiled pass

    drive = tuple(float(v) for v in (speed, tau_1, tau_2, tau_1**2, tau_2**2, tau_1 - tau_2))
    going = np.ones(t.shape, dtype=bool)
    decay = np.stack([-t / tau_1, -t / tau_2])
    for _ in range(50):
        np.expm1(decay, out=decay)
        if not newton_step(decay, t, angle, going, drive, float(bend), TURN_TOLERANCE_S):
            break


def moved_degrees(normal, engine: str = "numpy"):
    """Angle the panel normal turns between consecutive steps.

    Tracking by day, and the moves into and out of the stow position at sunset and sunrise
    (:func:`tracker_orientation`).

    Parameters
    ----------
    normal : array_like
        The panel's unit normal per step (east, north, up on the last axis), time on the one
        before, any leading axes.
    engine : {'numpy', 'numba'}
        ``numba``: the chords and turns in compiled passes around NumPy's ``arcsin``
        (:mod:`foldopt.physics.tracker_moves`), the same bits, for a sky's many steps; ``numpy``
        imports no numba.

    Returns
    -------
    numpy.ndarray
        Turn into each step [deg], shaped as the normals' leading axes; 0 at the first step and
        where the panel holds still (turns below 1e-6 deg).
    """
    normal = np.asarray(normal, dtype=float)
    if engine == "numba" and normal.shape[-2] > 0:
        return _moved_degrees_compiled(normal)
    turn = np.zeros(normal.shape[:-1])
    # The chord between unit vectors is 2 sin(angle / 2): exact from a standstill to a half turn.
    # Its arithmetic in place over the steps' differences, the normals' axes side by side.
    chord = np.diff(normal, axis=-2)
    np.multiply(chord, chord, out=chord)
    length = chord[..., 0] + chord[..., 1]
    length += chord[..., 2]
    np.sqrt(length, out=length)
    length /= 2.0
    np.minimum(length, 1.0, out=length)
    angle = np.arcsin(length)
    angle *= 2.0
    np.degrees(angle, out=turn[..., 1:])
    # A panel that holds still must not be charged a motor start: drop rounding-level turns.
    turn[~(turn > 1e-6)] = 0.0
    return turn


def _moved_degrees_compiled(normal):
    """:func:`moved_degrees` by :mod:`foldopt.physics.tracker_moves`' passes."""
    from foldopt.physics.tracker_moves import half_chords, turns  # numba's compiled passes

    n_steps = normal.shape[-2]
    # Each component along the steps: a view of the sky's own layout (a dual-axis tracker's
    # normal is the sun's vector), a copy of any other.
    series = np.ascontiguousarray(np.moveaxis(normal.reshape(-1, n_steps, 3), -1, 1))
    half_angle = np.empty((series.shape[0], n_steps - 1))
    half_chords(series, half_angle)
    np.arcsin(half_angle, out=half_angle)
    turn = np.empty(series.shape[::2])
    turns(half_angle, 1e-6, turn)
    return turn.reshape(normal.shape[:-1])


def tracker_draw(normal, sun_up, step_hours, drive: TrackerDrive, engine: str = "numpy"):
    """The tracker's own power draw per step: standby while the sun is up, plus moves.

    Each step's moves are spread over the step (their energy / step length).

    Parameters
    ----------
    normal : array_like
        The panel's unit normal per step (:func:`tracker_orientation`), east, north and up on the
        last axis, time on the one before.
    sun_up : array_like of bool
        Steps with the sun above the horizon, broadcast against the normals' leading axes.
    step_hours : float
        Step length [h].
    drive : TrackerDrive
        Standby and drive energy.
    engine : {'numpy', 'numba'}
        How the turns and the moves' times are worked out (:func:`moved_degrees`): the same bits.

    Returns
    -------
    numpy.ndarray
        Draw [W] per step.
    """
    draw = drive.move_energy_wh(moved_degrees(normal, engine), engine)
    draw /= step_hours  # each step's moves spread over it
    draw += np.where(np.asarray(sun_up, dtype=bool), drive.standby_w, 0.0)
    return draw
