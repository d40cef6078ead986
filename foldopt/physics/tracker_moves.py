"""The compiled passes of a tracker's moves (numba), for :mod:`foldopt.physics.trackers`, which
documents the method: the half chords between consecutive normals (:func:`half_chords`), the turns
they make (:func:`turns`), and a Newton step of the moves' times (:func:`newton_step`). Apart
from :mod:`foldopt.physics.trackers` so that a study's tracker imports numba only where it moves.

Each pass does the elementwise arithmetic of the NumPy expressions it replaced, in their order
(no fused multiply-add; a square root is exact either way), one step at a time where NumPy went
over every step once per operation. The transcendental functions stay NumPy's calls between the
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


@njit(cache=True, nogil=True, error_model="numpy")
def gather_moves(degrees, gear_ratio, moves, target):
    """The moves among turns ``degrees`` [deg] (1-D; a turn's sign ignored, 0 or NaN no move):
    their places into ``moves`` and the gear-motor's angle of each, ``|turn| gear_ratio``, into
    ``target``. Returns how many there are."""
    count = 0
    for i in range(degrees.size):
        turn = abs(degrees[i])
        if turn > 0.0:
            moves[count] = i
            target[count] = turn * gear_ratio
            count += 1
    return count


@njit(cache=True, nogil=True, error_model="numpy")
def spread_energy(moves, duration, target, motor, energy):
    """Each move's drive energy [Wh] into ``energy`` at its place ``moves``, from its time
    ``duration`` [s] and gear-motor angle ``target`` [deg]: the charge ``I_stall T - (I_stall -
    I_free) angle / omega_ss`` at the motor's voltage; ``motor`` is ``(I_stall, I_free,
    omega_ss, voltage)``."""
    stall, free, speed, voltage = motor
    for m in range(moves.size):
        charge = stall * duration[m] - (stall - free) * target[m] / speed
        energy[moves[m]] = voltage * charge / 3600.0
