"""The compiled passes of a tracker's moves (numba), for :mod:`foldopt.physics.trackers`, which
documents the method: the half chords between consecutive normals (:func:`half_chords`), the turns
they make (:func:`turns`), and a Newton step of the moves' times (:func:`newton_step`). Apart
from :mod:`foldopt.physics.trackers` so that a day's study, which takes its NumPy expressions
(``engine="numpy"``), imports no numba; a sky of many steps (a map's) takes these.

Each pass does the elementwise arithmetic of those NumPy expressions, in their order (no fused
multiply-add; a square root is exact either way), one step at a time where NumPy goes over every
step once per operation. The transcendental functions stay NumPy's calls between the
passes (its ``arcsin`` and ``expm1`` are SVML's on x86-64 CPUs with AVX-512, other bits than the C
library's that numba calls): so the moves' turns and times keep their bits, as
tests/test_tracker.py holds. ``error_model="numpy"``: no division here can be by zero (a
normal's step is finite, a move's rate positive), and Python's check on each would keep the loops
from being vectorised.
"""

from __future__ import annotations

import math

from numba import njit

_TO_DEGREES = 180.0 / math.pi  # np.degrees' factor


@njit(cache=True, nogil=True, error_model="numpy")
def half_chords(normal, out):
    """Half the chord between consecutive unit normals, capped at 1 (the sine of half the angle
    between them), of ``normal`` (n_series, 3, n_steps) into ``out`` (n_series, n_steps - 1)."""
    for b in range(normal.shape[0]):
        for i in range(normal.shape[2] - 1):
            east = normal[b, 0, i + 1] - normal[b, 0, i]
            north = normal[b, 1, i + 1] - normal[b, 1, i]
            up = normal[b, 2, i + 1] - normal[b, 2, i]
            length = east * east + north * north
            length = math.sqrt(length + up * up) / 2.0
            out[b, i] = 1.0 if length > 1.0 else length


@njit(cache=True, nogil=True, error_model="numpy")
def turns(half_angle, still, turn):
    """The turn into each step [deg], ``turn`` (n_series, n_steps), from half the angle [rad]
    between consecutive normals, ``half_angle`` (n_series, n_steps - 1): 0 into the first step
    and for turns not above ``still`` [deg]."""
    for b in range(turn.shape[0]):
        turn[b, 0] = 0.0
        for i in range(half_angle.shape[1]):
            degrees = half_angle[b, i] * 2.0 * _TO_DEGREES
            turn[b, i + 1] = degrees if degrees > still else 0.0


@njit(cache=True, nogil=True, error_model="numpy")
def newton_step(decay, t, angle, going, drive, bend, tolerance):
    """One Newton step of the moves still ``going``, for :func:`foldopt.physics.trackers._newton`:
    ``decay`` (2, n_moves) holds ``expm1(-t / tau_1)`` and ``expm1(-t / tau_2)`` at the moves'
    times ``t`` [s] on entry and the arguments of the next step's (``-t / tau``) on return; ``t``
    and ``going`` are updated in place. ``drive`` is ``(speed, tau_1, tau_2, tau_1**2,
    tau_2**2, tau_1 - tau_2)``. Returns whether a move is still going."""
    speed, tau_1, tau_2, tau_1_2, tau_2_2, span = drive
    left_going = False
    for i in range(t.size):
        start = t[i]
        decay_1, decay_2 = decay[0, i], decay[1, i]
        # the angle turned and its rate, as trackers._newton writes them
        turned = ((tau_1_2 * decay_1 - tau_2_2 * decay_2) / span + start) * speed
        rate = (1.0 - ((decay_1 + 1.0) * tau_1 - (decay_2 + 1.0) * tau_2) / span) * speed
        step = start - (turned - angle[i]) / rate
        step = step if (step >= 1e-9 or step != step) else 1e-9  # np.maximum's NaN
        moved = abs(step - start)
        now = step if going[i] else start
        t[i] = now
        square = moved * 2.0
        left = bend / (rate * 2.0) * (square * square)
        least = moved if (moved < left or moved != moved) else left  # np.minimum's NaN
        still = going[i] and least > tolerance
        going[i] = still
        left_going |= still
        decay[0, i] = -now / tau_1
        decay[1, i] = -now / tau_2
    return left_going
