"""The compiled passes of SPA (numba), each on numba's threads, for :mod:`foldopt.physics.spa`,
which documents the method: the periodic series of its time-only part (:func:`periodic_sums`), its
time-only terms at every instant (:func:`equatorial_steps`), and its topocentric step, the sun's
direction, elevation, azimuth and hour angle of every step of every block (:func:`site_sun`).
Apart from :mod:`foldopt.physics.spa` so that the paper's sun imports no numba.

Their sines and cosines are the C library's (numba's ``math.sin`` and ``math.cos``), which
NumPy's float64 ``sin`` and ``cos`` call on x86-64 Linux (2 M arguments compared; NumPy 2.4 takes
vectorised, other bits for its ``arcsin``, ``tan``, ``arctan2`` and ``power``, which these passes
take only where they were compiled already): so the passes give the bits of the NumPy and
``pvlib.spa`` expressions they replaced, as tests/test_solarposition.py holds. A numba built with
Intel's SVML (``numba.config.USING_SVML``) would vectorise their loops by other bits; those
tests would show it.
"""

from __future__ import annotations

import math

from numba import njit, uint64

# The unit, not imported from foldopt.physics.spa: spa imports this module where its compiled
# passes run, and importing it back would make a cycle.
NS_PER_HOUR = 3_600_000_000_000  # [ns]
NS_PER_DAY = 24 * NS_PER_HOUR  # [ns]

SPA_TEMPERATURE = 12.0  # [C], pvlib's default for the refraction correction
SPA_ATMOS_REFRACT = 0.5667  # [deg], SPA's refraction at sunrise and sunset


@njit(cache=True, inline="always")
def _raised(east, north, up, t):
    """The unit vector (east, north, up) raised by ``t`` [rad] toward the zenith in its vertical
    plane. The turn is SPA's refraction, under 0.011 rad: its sine and cosine by their series to the
    9th and 10th power, exact in double precision (the next terms are below 1e-21)."""
    t2 = t * t
    sin_t = t * (1.0 - t2 / 6.0 * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0 * (1.0 - t2 / 72.0))))
    cos_t = 1.0 - t2 / 2.0 * (
        1.0 - t2 / 12.0 * (1.0 - t2 / 30.0 * (1.0 - t2 / 56.0 * (1.0 - t2 / 90.0)))
    )
    level = math.sqrt(east * east + north * north)
    along = (level * cos_t - up * sin_t) / level if level > 0.0 else 0.0
    return east * along, north * along, up * cos_t + level * sin_t


@njit(cache=True, inline="always")
def _turn_mod(angle):
    """``angle % 360.0`` by Python's rule (NumPy's remainder), the same bits without ``fmod`` on
    the hour angle's range: from 360 to 720 the difference is exact (Sterbenz), from -360 to 0
    the sum is the one the rule rounds (its ``fmod`` gives the angle itself); -360 and -0.0 give
    0.0 and -0.0, which the hour angle's ``- 180`` makes the same."""
    if 0.0 <= angle < 360.0:
        return angle
    if 360.0 <= angle < 720.0:
        return angle - 360.0
    if -360.0 <= angle < 0.0:
        return angle + 360.0
    return angle % 360.0


@njit(cache=True, nogil=True, error_model="numpy")
def site_sun(
    terms,
    utc_ns,
    first,
    longitude,
    sin_lam,
    cos_lam,
    sin_phi,
    cos_phi,
    x,
    y,
    pressure,
    direction,
    apparent_zenith,
    solar_azimuth,
    hour_angle,
):
    """Every step of every block in one pass: the geometric topocentric unit vector toward the sun
    (east, north, up), from ``terms[:, first[b] + i]``
    (:meth:`foldopt.physics.spa.SunTerms.on_lattice`) and the site's arguments per block; its
    elevation and azimuth; SPA's refraction (Eq. 42, ``pvlib.spa``'s formula and switch, at
    ``pressure`` [hPa] per block and :data:`SPA_TEMPERATURE`), which raises the vector in its
    vertical plane (:func:`_raised`) and the elevation; the hour angle from the UTC instant
    ``utc_ns`` [ns], the ``longitude`` [deg] and the equation of time (``terms[4]``) by pvlib's
    formula. Writes ``direction`` (n_blocks, 3, n_steps), ``apparent_zenith``, ``solar_azimuth``
    and ``hour_angle`` [deg] (n_blocks, n_steps), each value by the operations of the NumPy
    expressions this pass replaced, in their order (a float's ``%`` by Python's rule, as NumPy's
    remainder). ``error_model="numpy"``: no division here is by zero (a unit vector's norm, the
    refraction's tangent above its cut), and Python's check of each would keep the vectors' loop
    from being vectorised."""
    n_blocks, n_steps = direction.shape[0], direction.shape[2]
    to_degrees, to_radians = 180.0 / math.pi, math.pi / 180.0
    cut = -1.0 * (0.26667 + SPA_ATMOS_REFRACT)
    for b in range(n_blocks):
        start = uint64(first[b])
        # Eq. 42's factor of pressure and temperature, as pvlib groups it.
        scale = (pressure[b] / 1010.0) * (283.0 / (273 + SPA_TEMPERATURE)) * 1.02
        cos_l, sin_l, cos_p, sin_p = cos_lam[b], sin_lam[b], cos_phi[b], sin_phi[b]
        x_b, y_b = x[b], y[b]
        # The block's geometric unit vectors first: arithmetic alone, which the compiler
        # vectorises (a loop that calls the C library's asin and atan2 it does not).
        for i in range(uint64(n_steps)):
            k = start + i
            # cos(delta) cos(H) and cos(delta) sin(H) at the site's hour angle H = H_G + longitude.
            cos_h = terms[0, k] * cos_l - terms[1, k] * sin_l
            sin_h = terms[1, k] * cos_l + terms[0, k] * sin_l
            # Less the site's position: toward the meridian on the equator, and toward the pole.
            meridian, pole = cos_h - x_b * terms[3, k], terms[2, k] - y_b * terms[3, k]
            east = -sin_h
            north = pole * cos_p - meridian * sin_p
            up = pole * sin_p + meridian * cos_p
            norm = 1.0 / math.sqrt(east * east + north * north + up * up)
            direction[b, 0, i], direction[b, 1, i] = east * norm, north * norm
            direction[b, 2, i] = up * norm
        midnight = 0  # [ns] of the UTC day of the step before
        for i in range(uint64(n_steps)):
            k = start + i
            # utc_ns % NS_PER_DAY, without a division but where a step crosses a UTC midnight
            since = utc_ns[b, i] - midnight
            if since < 0 or since >= NS_PER_DAY:
                midnight = utc_ns[b, i] // NS_PER_DAY * NS_PER_DAY
                since = utc_ns[b, i] - midnight
            utc_hours = since / NS_PER_HOUR
            hour_angle[b, i] = (
                _turn_mod(15.0 * (utc_hours - 12.0) + longitude[b] + terms[4, k] / 4.0 + 180.0)
                - 180.0
            )
            east, north, up = direction[b, 0, i], direction[b, 1, i], direction[b, 2, i]
            elevation = math.asin(min(max(up, -1.0), 1.0)) * to_degrees
            heading = math.atan2(east, north) * to_degrees
            solar_azimuth[b, i] = heading + 360.0 if heading < 0.0 else heading
            if elevation >= cut:
                refraction = scale / (
                    60 * math.tan((elevation + 10.3 / (elevation + 5.11)) * to_radians)
                )
                east, north, up = _raised(east, north, up, refraction * to_radians)
                elevation += refraction
                direction[b, 0, i], direction[b, 1, i], direction[b, 2, i] = east, north, up
            apparent_zenith[b, i] = 90.0 - elevation


@njit(cache=True, nogil=True)
def equatorial_steps(utc_ns, index, at_nodes, change, out, start, stop):
    """SPA's time-only terms of the sun at every instant in one pass, for
    :func:`foldopt.physics.spa._equatorial`, which documents them: the geocentric terms
    ``at_nodes`` (5, n_nodes) at whole UTC hours, interpolated by their hourly ``change`` (5,
    n_nodes - 1) at each instant ``utc_ns`` [ns] (its hour the node ``index``), and of them the
    sun's direction in the Greenwich frame, ``sin(xi)`` and the equation of time, written to
    ``out`` (5, n_instants), instants ``start`` to ``stop - 1`` (a thread's share).

    Each value by the operations of the NumPy expressions this pass replaced, in their order (a
    true division of the hour's fraction, ``np.radians``' product by pi / 180, no fused
    multiply-add): their bits (see the module's docstring)."""
    to_radians = math.pi / 180.0
    for i in range(start, stop):
        hour = utc_ns[i] // NS_PER_HOUR
        weight = (utc_ns[i] - hour * NS_PER_HOUR) / NS_PER_HOUR
        k = index[i]
        alpha = at_nodes[0, k] + weight * change[0, k]
        delta = (at_nodes[1, k] + weight * change[1, k]) * to_radians
        v = at_nodes[2, k] + weight * change[2, k]
        xi = at_nodes[3, k] + weight * change[3, k]
        greenwich = (v - alpha) * to_radians
        cos_delta = math.cos(delta)
        out[0, i] = cos_delta * math.cos(greenwich)
        out[1, i] = cos_delta * math.sin(greenwich)
        out[2, i] = math.sin(delta)
        out[3, i] = math.sin(xi * to_radians)
        out[4, i] = at_nodes[4, k] + weight * change[4, k]


@njit(cache=True, nogil=True)
def periodic_sums(terms, bounds, jme, abcd, y, jce, x, sums, nutation, start, stop):
    """SPA's periodic series at every instant in one pass, for
    :func:`foldopt.physics.spa._periodic`, which documents them: the sum of table ``t``'s terms
    (rows ``bounds[t]`` to ``bounds[t + 1]`` of ``terms``, ``A cos(B + C jme)``) in ``sums[t]``,
    and the nutation's two sums (``(a + b jce) sin(arg)`` and ``(c + d jce) cos(arg)`` with ``arg``
    the radians of ``y . x``, before their scale) in ``nutation`` (2, n_instants); instants
    ``start`` to ``stop - 1`` (a thread's share).

    Each value by the operations of ``pvlib.spa``'s NumPy loops in their order: their bits (see
    the module's docstring)."""
    to_radians = math.pi / 180.0
    for i in range(start, stop):
        for t in range(bounds.shape[0] - 1):
            total = 0.0
            for j in range(bounds[t], bounds[t + 1]):
                total = total + terms[j, 0] * math.cos(terms[j, 1] + terms[j, 2] * jme[i])
            sums[t, i] = total
        psi, epsilon = 0.0, 0.0
        for j in range(y.shape[0]):
            arg = (
                y[j, 0] * x[0, i]
                + y[j, 1] * x[1, i]
                + y[j, 2] * x[2, i]
                + y[j, 3] * x[3, i]
                + y[j, 4] * x[4, i]
            ) * to_radians
            psi = psi + (abcd[j, 0] + abcd[j, 1] * jce[i]) * math.sin(arg)
            epsilon = epsilon + (abcd[j, 2] + abcd[j, 3] * jce[i]) * math.cos(arg)
        nutation[0, i], nutation[1, i] = psi, epsilon
