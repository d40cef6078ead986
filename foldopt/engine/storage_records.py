"""The records and the output columns of the buffer's simulation: what
:func:`foldopt.engine.storage.simulate` hands its loops (the compiled one of
:mod:`foldopt.engine.storage_kernel`, numba's named tuples, and its NumPy reference) and the columns
they write. Apart from the compiled loop, so that the NumPy path reads them without importing
numba.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class Curves(NamedTuple):
    """What a buffer runs over: for every series, (n_series or 1, ...) arrays; in the loops over
    one series, that series' (the first axis taken).

    Attributes
    ----------
    power : (n_series or 1, n_days, n_steps) float
        Power at step centres [W], less the design's own draw.
    load, draw : (n_series or 1, n_days or 1, n_steps or 1) float
        The load and the design's own draw at step centres [W].
    step_hours : float
        Step length [h].
    """

    power: np.ndarray
    load: np.ndarray
    draw: np.ndarray
    step_hours: float


class Parameters(NamedTuple):
    """A buffer and its charge controller as the loops read them
    (:func:`foldopt.engine.storage.simulate`): for every series, each field a (n_series,) float
    array; in the loops over one series, that series' float.

    Attributes
    ----------
    capacity : float
        [Wh].
    min_soc, restart_soc : float
        The controller's cut-off and reconnection [-].
    eta_charge, eta_discharge : float
        Charge and discharge efficiencies [-].
    keep_step, keep_half : float
        The share of the content a step and a half step keep against self-discharge [-].
    max_charge, max_discharge : float
        Power limits into and out of the buffer [W] (inf: none).
    initial_soc : float
        State of charge at the start [-]; NaN: the periodic state.
    """

    capacity: np.ndarray
    min_soc: np.ndarray
    restart_soc: np.ndarray
    eta_charge: np.ndarray
    eta_discharge: np.ndarray
    keep_step: np.ndarray
    keep_half: np.ndarray
    max_charge: np.ndarray
    max_discharge: np.ndarray
    initial_soc: np.ndarray


class Days(NamedTuple):
    """What the loops write: for every series, (n_series, ...) arrays; in the loops over one
    series, that series' (the first axis taken).

    Attributes
    ----------
    out : (n_series, n_days, HISTOGRAM + n_bins) float
        Each day's outputs (the columns below).
    state : (n_series, n_days + 1, 2) float
        Content [Wh] and load on (1) or off (0) at each midnight.
    soc : (n_series, n_days, n_steps) or (1, 1, 1) float
        The state of charge at each step centre where ``keep_soc`` (else a placeholder).
    keep_soc : bool
    """

    out: np.ndarray
    state: np.ndarray
    soc: np.ndarray
    keep_soc: bool


# Columns of a day's outputs; the state-of-charge histogram follows from HISTOGRAM on.
POWERED, SERVED, MISSING, LOST, HARVESTED = 0, 1, 2, 3, 4
CHARGE_LOSS, DISCHARGE_LOSS, SELF_DISCHARGE, FULL, EMPTY = 5, 6, 7, 8, 9
DRAWN = 10
HISTOGRAM = 11

# The buffer's temperature as the loops take it, per segment of a day (the ``n_steps + 1``
# segments between step centres, foldopt.engine.storage.simulate): one array (n_series or 1,
# n_days or 1, n_steps + 1 or 1, 4) (a size 1 serves every series, day or segment), in the loops
# over one series that series'. Its last axis: 1 where the buffer may charge (COLD_CHARGE) and
# discharge (COLD_DISCHARGE) over the segment, 0 where blocked; the share of the usable range
# [min_soc, 1] the cold puts out of reach (COLD_CUT: the cut-off and the reconnection are raised
# by it, foldopt.physics.buffer_temperature.cold_cut_off); and the share of the content the
# segment keeps against self-discharge (COLD_KEEP; NaN: the buffer's own keep_step or keep_half).
COLD_CHARGE, COLD_DISCHARGE, COLD_CUT, COLD_KEEP = 0, 1, 2, 3

#: Plain fixed-point iterations (the buffer's own year after year) before the periodic state is
#: bisected instead (a state that drifts by a little a day would take many plain ones).
PLAIN_ITERATIONS = 4
