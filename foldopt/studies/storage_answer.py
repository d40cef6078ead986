"""A day's study with a buffer (issue 41): how long the load runs with the study's ``storage``, per
design and per fold angle, and how much buffer each design needs for a stated target.

The day is the study's clear-sky day repeated until its midnight state of charge repeats (the
periodic steady state of :func:`foldopt.engine.storage.simulate`), or started from the
section's ``initial_soc``. Every curve simulated is the one the study's ``t_solar`` was reduced
from, so that a buffer of 0 Wh gives each design's ``t_solar`` (to the last bit of a sum).

The sizing (:func:`size_buffers`, :func:`smallest_buffers`) is a bracketed search on the
capacity, run for every design at once: a geometric grid of capacities (the one the figure of
powered time against capacity draws), then the bracket between the least capacity of the grid
reaching the target and the one below it (which does not) cut into :data:`REFINE_POINTS` + 1
parts, the least part reaching it and the part below it the next bracket, until it is within
:data:`CAPACITY_RTOL` of its top. The capacity given is therefore always one evaluated that
reaches the target, every smaller capacity of the grid falls short of it, and so does an
evaluated one within :data:`CAPACITY_RTOL` below it. The capacity from which folding stops
paying is found by the same search (:func:`folding_pays`), at the capacities the sizing names too,
so that every capacity the answer states is one evaluated and found to hold, and the lines hold
against each other.

That this is *the* smallest buffer rests on powered time not falling as the capacity grows. It
holds, to within one step, only for a controller without hysteresis (``restart_soc`` =
``min_soc``) and a buffer that does not leak (``self_discharge`` 0)
(:mod:`foldopt.engine.storage`). With a hysteresis band or a leak it does not: the band that must
be recharged before the load reconnects, and the floor that leaks, grow with the buffer, so that
a larger buffer can run the load less (a band larger than a day's harvest never reconnects the
load: it runs on PV alone), and some repeated days find no periodic state (a two-day cycle: such a
capacity reaches nothing). The search then finds the least capacity reaching the target at the
grid's resolution (a capacity that reaches it between two grid points that do not is missed),
bisects only its bracket, and says, per design (``monotone``), whether every larger capacity of the
grid reaches the target too; where one does not, the answer notes it.

The module may import numpy, pandas, :mod:`foldopt.engine` and :mod:`foldopt.inputs`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from foldopt.engine.choice import engine_for
from foldopt.engine.storage import Buffer, StorageResult, simulate
from foldopt.names import FLAT_FOLD_ANGLE
from foldopt.studies.objectives import best_angle_index, near_optimal, objective_value

#: The designs whose state of charge the day's figure draws and ``timeseries.csv`` holds.
SOC_DESIGNS = ("flat", "twofold", "tracker")
#: Capacities of the grid [-, times the day's load energy over the usable fraction] (0 Wh first),
#: with the study's own: the sizing's first bracket and the figure's curve of powered time
#: against capacity.
GRID = np.concatenate([[0.0], np.geomspace(1.0 / 64.0, 4.0, 25)])
#: Interior points each refinement of a bracket evaluates.
REFINE_POINTS = 8
#: A capacity is found once its bracket is within this fraction of its top.
CAPACITY_RTOL = 1e-3
#: Twofold angles the sizing compares (the grid's, thinned to about this many, with the angle
#: best for the study's own buffer).
SIZING_ANGLES = 12
#: How far below the target [h] a day's powered time may fall and still reach it (sums' rounding).
TARGET_SLACK_H = 1e-9


def buffer_of(storage, **changes) -> Buffer:
    """The engine's :class:`~foldopt.engine.storage.Buffer` of a study's ``storage`` section.

    Parameters
    ----------
    storage : foldopt.inputs.storage_section.Storage
    **changes
        Fields to replace (``capacity_wh`` as an array over series in a sizing).
    """
    fields = {name: getattr(storage, name) for name in Buffer._fields}
    return Buffer(**{**fields, **changes})


def storage_engine(engine: str) -> str:
    """The engine that simulates a buffer: ``engine``, or for ``auto`` the compiled loop (a
    request's engine is decided so already: :func:`foldopt.studies.request.request_engine`).

    Parameters
    ----------
    engine : {'auto', 'numba', 'numpy'}
    """
    return engine_for(engine, math.inf)


def run_buffer(
    power, load, buffer: Buffer, step_hours: float, engine: str, soc_curves=False, draw=None
):
    """:func:`foldopt.engine.storage.simulate` of a day's curves (periodic steady state, or from
    ``initial_soc``) on ``engine`` ('numba' or 'numpy'), with the designs' own ``draw``."""
    return simulate(power, load, buffer, step_hours, engine, soc_curves=soc_curves, draw=draw)


#: The columns of a design's buffer (summary.csv, the answer), by the names of
#: :meth:`foldopt.engine.storage.StorageResult.summary` they take.
SUMMARY_COLUMNS = {
    "powered_h": "powered_h",
    "availability_pct": "availability_pct",
    "days_without_outage_pct": "powered_days_ge24h_pct",
    "missing_wh": "energy_missing_wh",
    "lost_wh": "energy_lost_wh",
    "days_full_pct": "days_full_pct",
    "days_empty_pct": "days_empty_pct",
}


def day_columns(result: StorageResult) -> dict:
    """Per series, the day's (or the mean day's) buffered metrics by the columns' names
    (:data:`SUMMARY_COLUMNS`): ``powered_h`` [h a day], ``availability_pct`` (the load's energy
    served, of its demand), ``powered_days_ge24h_pct`` (days with no energy missing),
    ``energy_missing_wh`` and ``energy_lost_wh`` [Wh a day], ``days_full_pct`` and
    ``days_empty_pct`` (PVGIS's), each (n_series,).

    Parameters
    ----------
    result : foldopt.engine.storage.StorageResult
    """
    summary = result.summary()
    return {column: summary[name] for name, column in SUMMARY_COLUMNS.items()}


def reaches(result: StorageResult, target) -> np.ndarray:
    """(n_series,) bool: whether each series runs the load ``target.powered_h`` on at least
    ``target.days_pct`` of its days, from a periodic state (a series whose end state never
    repeats its start's reaches nothing)."""
    return _reaching(result.powered_h, result.converged, target)


def _reaching(powered_h, converged, target) -> np.ndarray:
    """:func:`reaches` of daily powered time [h] (n, n_days) and (n,) periodic states."""
    days = powered_h >= target.powered_h - TARGET_SLACK_H
    return (100.0 * days.mean(axis=1) >= target.days_pct - 1e-9) & converged


@dataclass(frozen=True)
class Sizing:
    """Each design's smallest buffer for a target, and the buffer from which folding stops paying
    (:func:`size_buffers`).

    Attributes
    ----------
    table : pandas.DataFrame
        Per design (``flat``, ``twofold`` at the angle needing the least, ``tracker``,
        ``tracker-net``): ``design``, ``fold_angle_deg``, ``capacity_wh`` (NaN where no buffer up
        to the grid's top reaches the target), ``monotone`` (every larger capacity of the grid
        reaches it too; module docstring) and ``capacity_gain_vs_flat_pct``.
    curve : pandas.DataFrame
        ``capacity_wh`` and ``powered_{flat,twofold,tracker}_h``: powered time against capacity,
        the twofold panel at each capacity's best of the angles compared.
    folding : FoldingPays
        Where folding pays (:func:`folding_pays`).
    """

    table: pd.DataFrame
    curve: pd.DataFrame
    folding: FoldingPays


def size_buffers(
    curves: dict,
    fold_angles,
    own,
    load,
    storage,
    step_hours,
    engine,
    tolerance,
    draws=None,
):
    """Each design's smallest buffer for ``storage.target``, powered time against capacity, and
    the buffer from which folding stops paying.

    Parameters
    ----------
    curves : dict
        ``flat``, ``tracker``, ``tracker-net`` -> power [W], (n_steps,); ``twofold`` -> power at
        ``fold_angles``, (k, n_steps).
    fold_angles : array_like
        (k,) [deg].
    own : float
        The fold angle best for the study's own buffer [deg], one of ``fold_angles``.
    load : float or numpy.ndarray
        [W], or (1, n_steps).
    storage : foldopt.inputs.storage_section.Storage
        Its ``target`` (may be None: the curve only).
    step_hours : float
    engine : str
    tolerance : foldopt.inputs.sections.NearOptimal
    draws : dict, optional
        Design -> its own draw [W], (n_steps,): ``tracker-net``'s drive, whose power in
        ``curves`` is then its whole power (:func:`foldopt.engine.storage.simulate`'s ``draw``).

    Returns
    -------
    Sizing
    """
    fold_angles = np.asarray(fold_angles, dtype=float)
    power = np.vstack([curves["flat"], curves["tracker"], curves["tracker-net"], curves["twofold"]])
    own_draws = [None, None, (draws or {}).get("tracker-net")] + [None] * len(fold_angles)
    capacities = capacity_grid(load, storage, step_hours, power.shape[-1])
    n, m = power.shape[0], capacities.size
    run = _Runs(power, own_draws, load, storage, step_hours, engine, in_sequence=True)
    hours, ok = run(np.arange(n), np.broadcast_to(capacities, (n, m)))
    twofold = hours[3:]
    best = best_angle_index(np.nan_to_num(twofold.T, nan=-1.0))
    curve = pd.DataFrame(
        {
            "capacity_wh": capacities,
            "powered_flat_h": hours[0],
            "powered_twofold_h": twofold[best, np.arange(m)],
            "powered_tracker_h": hours[1],
            "fold_angle_deg": fold_angles[best],
        }
    )
    table = pd.DataFrame()
    if storage.target is not None:
        first = np.where(ok.any(axis=1), np.argmax(ok, axis=1), -1)
        # The twofold angles reaching the target at the grid's least capacity are refined with
        # flat and the trackers (an angle reaching it only at a larger one needs more than
        # each of them); where none reaches it, the row names the angle best for the study's
        # own buffer.
        angles = first[3:]
        tied = 3 + (
            np.flatnonzero(angles == angles[angles >= 0].min())
            if (angles >= 0).any()
            else np.flatnonzero(fold_angles == own)[:1]
        )
        keep = np.concatenate([[0], tied, [1, 2]])
        found = _smallest(run, keep, first[keep], capacities)
        # The least of them, ties to the least folded.
        least = tied.size - 1 - int(np.argmin(found[tied.size : 0 : -1]))
        pick = int(tied[least])
        keep = np.array([0, pick, 1, 2])
        found = found[[0, 1 + least, -2, -1]]
        table = pd.DataFrame(
            {
                "design": ["flat", "twofold", "tracker", "tracker-net"],
                "fold_angle_deg": [FLAT_FOLD_ANGLE, fold_angles[pick - 3], np.nan, np.nan],
                "capacity_wh": found,
                "monotone": _held_above(ok[keep], first[keep]),
            }
        )
        with np.errstate(invalid="ignore", divide="ignore"):
            table["capacity_gain_vs_flat_pct"] = np.where(
                np.isfinite(found) & (found[0] > 0), (found / found[0] - 1.0) * 100.0, np.nan
            )
    # The capacities the sizing found are points of the search too, so that what the answer says
    # of folding holds at the buffers it names beside it.
    named = table["capacity_wh"].dropna().to_numpy() if len(table) else np.empty(0)
    folding = folding_pays(run, capacities, hours, named, tolerance)
    return Sizing(table, curve, folding)


class _Runs:
    """Designs' curves through a study's buffer at any capacities: each call
    :func:`_at_capacities` of some of the curves, ``(rows, capacities (r, m))`` ->
    ``(hours, ok)``; ``draws`` per curve as its (None: none)."""

    def __init__(self, power, draws, load, storage, step_hours, engine, in_sequence: bool):
        draws = [None] * len(power) if draws is None else draws
        self.power, self.draws, self.load, self.storage = power, draws, load, storage
        self.step_hours, self.engine, self.in_sequence = step_hours, engine, in_sequence

    def __call__(self, rows, capacities):
        return _at_capacities(
            self.power[rows],
            capacities,
            self.load,
            self.storage,
            self.step_hours,
            self.engine,
            self.in_sequence,
            [self.draws[row] for row in rows],
        )


@dataclass(frozen=True)
class FoldingPays:
    """Where the best twofold angle runs the load longer than flat by more than the near-optimal
    tolerance ("folding pays"), over the capacities evaluated (:func:`folding_pays`).

    Attributes
    ----------
    holds_from_wh : float
        The least capacity evaluated from which on folding pays at no capacity evaluated, above
        ``pays_wh``; NaN where folding never pays or still pays at ``top_wh``.
    pays_wh : float
        The largest capacity evaluated at which folding pays; NaN where it pays at none.
    top_wh : float
        The largest capacity evaluated [Wh].
    everywhere : bool
        Folding pays at every capacity evaluated.
    known : bool
        Some capacity found its periodic state for flat and a twofold angle (else nothing is
        said).
    """

    holds_from_wh: float
    pays_wh: float
    top_wh: float
    everywhere: bool
    known: bool

    @property
    def state(self) -> str:
        """One of :data:`FOLDING_STATES`."""
        if not self.known:
            return "unknown"
        if self.pays_wh != self.pays_wh:
            return "never"
        if self.holds_from_wh == self.holds_from_wh:
            bracketed = self.holds_from_wh - self.pays_wh <= CAPACITY_RTOL * self.holds_from_wh
            return "below_threshold" if bracketed else "between"
        return "at_every_capacity" if self.everywhere else "at_largest_capacity"

    @property
    def stops_wh(self) -> float:
        """The capacity from which folding stops paying [Wh], bracketed within
        :data:`CAPACITY_RTOL`; NaN where the answer states none."""
        return self.holds_from_wh if self.state == "below_threshold" else np.nan


#: Where folding pays (:attr:`FoldingPays.state`): at no capacity evaluated; below a threshold
#: found; at some capacity and at none evaluated from a larger one on, with no periodic state
#: between them; at every capacity; at the largest whose periodic state is known; not known.
FOLDING_STATES = (
    "never",
    "below_threshold",
    "between",
    "at_every_capacity",
    "at_largest_capacity",
    "unknown",
)


def _fold_gain(flat, twofold, tolerance):
    """Whether folding pays, and whether it does not, at each capacity: two (m,) bool arrays,
    both False where no periodic state says.

    Parameters
    ----------
    flat : numpy.ndarray
        Flat's powered time [h], (m,).
    twofold : numpy.ndarray
        The twofold angles' compared, (k, m) [h].
    tolerance : foldopt.inputs.sections.NearOptimal
    """
    known = np.isfinite(flat) & np.isfinite(twofold).any(axis=0)
    best = np.where(known, np.max(np.nan_to_num(twofold, nan=-np.inf), axis=0), 0.0)
    flat = np.where(known, flat, 0.0)
    pays = known & (best - flat > tolerance.tolerance_h(best))
    return pays, known & ~pays


def folding_pays(run, capacities, hours, named, tolerance) -> FoldingPays:
    """The buffer from which folding stops paying, a bracketed search on the capacity as the
    sizing's (:func:`_bracket`): on the grid, and at the capacities the answer names beside it
    (``named``), the largest capacity at which folding pays and the next at which it does not
    are cut until within :data:`CAPACITY_RTOL` of the top, the top then the least capacity
    evaluated from which on it pays at none.

    Parameters
    ----------
    run : _Runs
        Flat (row 0) and the twofold angles compared (rows 3 on).
    capacities : numpy.ndarray
        The grid (m,) [Wh], and ``hours``, (n, m) [h], powered time on it.
    named : numpy.ndarray
        Other capacities [Wh] to evaluate (the sizing's).
    tolerance : foldopt.inputs.sections.NearOptimal
    """
    rows = np.concatenate([[0], np.arange(3, len(run.power))])

    def gain(capacities):
        # Flat and the twofold angles at capacities (m,): where folding pays, and where not.
        hours, _ = run(rows, np.broadcast_to(capacities, (rows.size, capacities.size)))
        return _fold_gain(hours[0], hours[1:], tolerance)

    pays, holds = _fold_gain(hours[0], hours[3:], tolerance)
    if named.size:
        more = gain(named)
        order = np.argsort(np.concatenate([capacities, named]), kind="stable")
        capacities = np.concatenate([capacities, named])[order]
        pays = np.concatenate([pays, more[0]])[order]
        holds = np.concatenate([holds, more[1]])[order]
    top = float(capacities[-1])
    known = bool((pays | holds).any())
    if not pays.any():
        return FoldingPays(np.nan, np.nan, top, False, known)
    last = int(np.flatnonzero(pays)[-1])
    after = np.flatnonzero(holds & (np.arange(capacities.size) > last))
    if not after.size:
        everywhere = bool(pays[(pays | holds)].all())
        return FoldingPays(np.nan, float(capacities[last]), top, everywhere, known)

    def stops(_, inner):
        pays, holds = gain(inner[0])
        return holds[None], pays[None]

    lo, hi = _bracket(
        stops, np.array([capacities[last]]), np.array([capacities[after[0]]]), after_last=True
    )
    return FoldingPays(float(hi[0]), float(lo[0]), top, False, True)


def capacity_grid(load, storage, step_hours, n_steps) -> np.ndarray:
    """The sizing's grid of capacities [Wh]: :data:`GRID` times a day's load energy (the days'
    mean) over the usable fraction, with the study's own capacity (a point of the curve)."""
    daily = np.broadcast_to(load, (1, n_steps)) if np.ndim(load) < 2 else load
    demand_wh = float(np.sum(daily) / (daily.size // n_steps) * step_hours)
    scale = max(demand_wh, 1e-6) / ((1.0 - storage.min_soc) * storage.discharge_efficiency)
    return np.unique(np.minimum(np.append(GRID * scale, storage.capacity_wh), 1e6))


def _at_capacities(
    power, capacities, load, storage, step_hours, engine, in_sequence: bool, draws=None
):
    """Each design's buffer at each of its capacities.

    Parameters
    ----------
    power : numpy.ndarray
        (n, n_steps) a day per design, or (n, n_days, n_steps) days.
    capacities : numpy.ndarray
        (n, m) [Wh].
    load : float or numpy.ndarray
        [W], or a profile (1, n_steps) or (1, n_days, n_steps).
    in_sequence : bool
        The days follow each other (a day repeated to its periodic state is in sequence); else
        each day is its own periodic series.
    draws : sequence, optional
        Per design, its own draw [W] shaped as its curve, or None (none).

    Returns
    -------
    hours : numpy.ndarray
        (n, m) mean powered time [h]; NaN where some series found no periodic state.
    ok : numpy.ndarray
        (n, m) bool: :func:`reaches` ``storage.target`` (all False without a target).
    """
    draws = [None] * len(power) if draws is None else draws
    target = storage.target
    if in_sequence and power.ndim == 2:
        # A day per design: every design at every capacity in one call (a call's threads cost
        # more than a few days' series).
        n, m = capacities.shape
        own = (
            None
            if all(draw is None for draw in draws)
            else np.repeat([np.zeros(power.shape[-1]) if d is None else d for d in draws], m, 0)
        )
        buffer = buffer_of(storage, capacity_wh=capacities.ravel())
        result = run_buffer(np.repeat(power, m, 0), load, buffer, step_hours, engine, draw=own)
        converged = result.converged.reshape(n, m)
        reached = (
            _reaching(result.powered_h, result.converged, target).reshape(n, m)
            if target is not None
            else np.zeros((n, m), bool)
        )
        return np.where(converged, result.powered_h.reshape(n, m), np.nan), reached
    hours, ok = [], []
    for curve, capacity, own in zip(power, capacities, draws, strict=True):
        days = curve.reshape(-1, curve.shape[-1])
        if in_sequence:
            # One curve of days serves every capacity, without a copy.
            series, buffer = curve[None], buffer_of(storage, capacity_wh=capacity)
            each = load
            draw = None if own is None else own[None]
        else:
            # A series per capacity and day, capacity by capacity.
            def per_capacity(curves):
                return np.tile(curves.reshape(days.shape)[:, None, :], (capacity.size, 1, 1))

            series = per_capacity(days)
            buffer = buffer_of(storage, capacity_wh=np.repeat(capacity, len(days)))
            each = (
                load
                if np.ndim(load) == 0
                else per_capacity(
                    np.broadcast_to(np.reshape(load, (-1, days.shape[-1])), days.shape)
                )
            )
            draw = None if own is None else per_capacity(own)
        result = run_buffer(series, each, buffer, step_hours, engine, draw=draw)
        powered = result.powered_h.reshape(capacity.size, -1)  # (m, days)
        converged = result.converged.reshape(capacity.size, -1).all(axis=1)
        # A series with no periodic state has no powered time to draw (NaN: the figure leaves
        # it out).
        hours.append(np.where(converged, powered.mean(axis=1), np.nan))
        ok.append(
            _reaching(powered, converged, target)
            if target is not None
            else np.zeros(capacity.size, bool)
        )
    return np.array(hours), np.array(ok)


def _bracket(holds, lo, hi, after_last: bool):
    """Brackets on the capacity cut until within :data:`CAPACITY_RTOL` of their tops, each into
    :data:`REFINE_POINTS` + 1 parts at a time: the bracket's bottom ``lo`` [Wh] does not hold
    and its top ``hi`` does (NaN: no bracket), and so do the new ones.

    Parameters
    ----------
    holds : callable
        ``(rows, capacities (r, k))`` -> two (r, k) bool arrays: the capacities that hold, and
        those that do not (neither where it is not known: such a point cuts nothing).
    lo, hi : numpy.ndarray
        (n,) [Wh].
    after_last : bool
        The new top is the least capacity that holds above the last that does not (the least
        from which on every capacity evaluated holds); else the least that holds.

    Returns
    -------
    lo, hi : numpy.ndarray
        (n,) [Wh].
    """
    lo, hi = lo.astype(float), hi.astype(float)
    cut = np.isfinite(hi)
    index = np.arange(REFINE_POINTS)
    while True:
        open_ = np.flatnonzero(cut & (hi - lo > CAPACITY_RTOL * hi))
        if not open_.size:
            return lo, hi
        inner = lo[open_, None] + (hi - lo)[open_, None] * ((index + 1) / (REFINE_POINTS + 1))
        ok, fails = holds(open_, inner)
        tops = ok & (index > _last(fails)[:, None]) if after_last else ok
        at = np.where(tops.any(axis=1), np.argmax(tops, axis=1), REFINE_POINTS)
        under = _last(fails & (index < at[:, None]))
        rows = np.arange(open_.size)
        top = np.where(
            at < REFINE_POINTS, inner[rows, np.minimum(at, REFINE_POINTS - 1)], hi[open_]
        )
        floor = np.where(under >= 0, inner[rows, np.maximum(under, 0)], lo[open_])
        # A bracket none of whose points is known cannot be cut further.
        cut[open_[~(ok | fails).any(axis=1)]] = False
        lo[open_], hi[open_] = floor, top


def _last(mask) -> np.ndarray:
    """(r,) the index of each row's last True in ``mask`` (r, k); -1 where none."""
    return np.where(mask.any(axis=1), mask.shape[1] - 1 - np.argmax(mask[:, ::-1], axis=1), -1)


def _smallest(run, rows, first, capacities) -> np.ndarray:
    """Each of ``rows``' least capacity reaching the target [Wh]: the bracket between the grid's
    capacity ``first`` (the least reaching it; -1: none does, NaN) and the one below it, cut by
    :func:`_bracket`."""
    found = np.where(first >= 0, capacities[np.maximum(first, 0)], np.nan)
    lo = np.where(first > 0, capacities[np.maximum(first - 1, 0)], found)

    def reach(open_, inner):
        _, ok = run(rows[open_], inner)
        return ok, ~ok

    return _bracket(reach, lo, found, after_last=False)[1]


def smallest_buffers(power, load, storage, step_hours, engine, in_sequence: bool, draws=None):
    """Each design's smallest buffer [Wh] for ``storage.target`` over its days (NaN: none up to
    the grid's top), by :func:`size_buffers`' search, and whether every larger capacity of the
    grid reaches it too (:func:`_held_above`).

    Parameters
    ----------
    power : numpy.ndarray
        (n, n_days, n_steps) [W].
    load, in_sequence
        As :func:`_at_capacities`'.
    draws : sequence, optional
        As :func:`_at_capacities`'.
    """
    capacities = capacity_grid(load, storage, step_hours, power.shape[-1])
    run = _Runs(power, draws, load, storage, step_hours, engine, in_sequence)
    rows = np.arange(power.shape[0])
    _, ok = run(rows, np.broadcast_to(capacities, (rows.size, capacities.size)))
    first = np.where(ok.any(axis=1), np.argmax(ok, axis=1), -1)
    return _smallest(run, rows, first, capacities), _held_above(ok, first)


def _held_above(ok, first) -> np.ndarray:
    """(n,) bool: every capacity of the grid from the least reaching the target on reaches it
    too (the premise of a bracketed search; True where none reaches it)."""
    index = np.arange(ok.shape[1])
    return (ok | (index < first[:, None])).all(axis=1) | (first < 0)


@dataclass(frozen=True)
class DayStorage:
    """A day's study with its buffer (:func:`day_storage`).

    Attributes
    ----------
    storage : foldopt.inputs.storage_section.Storage
    designs : pandas.DataFrame
        Per design of the summary, in its order: ``design``, ``fold_angle_deg``, ``t_solar_h``
        and :func:`day_columns`' columns.
    powered_by_angle : numpy.ndarray
        Powered time [h] of the twofold panel at each fold angle of the grid.
    fold_angle_deg : float
        The grid's fold angle with the longest powered time (ties to the least folded).
    near_optimal : dict
        :func:`foldopt.studies.objectives.near_optimal` of powered time over the grid, with
        ``recommended_powered_h``.
    soc : dict
        Design of :data:`SOC_DESIGNS` -> state of charge [-] at each step centre, (n_steps,).
    soc_hours : dict
        Design -> hours a day [h] the state of charge spends in each tenth (0-10 %, ...,
        90-100 %), as PVGIS's histogram, (10,).
    sizing : Sizing
    engine : str
        The engine the buffer was simulated on ('numba' or 'numpy').
    converged : bool
        Whether every series reached its periodic state (or started from ``initial_soc``).
    series : foldopt.engine.storage.StorageResult
        The designs' day with the buffer, in ``designs``' order: its energies, net trackers'
        with their own draw served.
    """

    storage: object
    designs: pd.DataFrame
    powered_by_angle: np.ndarray
    fold_angle_deg: float
    near_optimal: dict
    soc: dict
    soc_hours: dict
    sizing: Sizing
    engine: str
    converged: bool
    series: StorageResult


def day_storage(
    study, step_hours, load, fold_angles, grid_power, rows: dict, t_solar, engine, draws=None
) -> DayStorage:
    """Simulate a day's study's buffer for every design it compares.

    Parameters
    ----------
    study : foldopt.Study
        With a ``storage`` section.
    step_hours : float
    load : float or numpy.ndarray
        The load [W], or its curve (1, n_steps) under a load profile.
    fold_angles : array_like
        The grid's fold angles [deg], (k,).
    grid_power : numpy.ndarray
        The twofold panel's power at each, the study's connection [W], (k, n_steps).
    rows : dict
        The summary's designs, in its order -> (fold angle [deg], power [W], (n_steps,)).
    t_solar : array_like
        Each design's ``t_solar`` [h] without the buffer, in ``rows``' order.
    engine : str
    draws : dict, optional
        Design -> its own draw [W], (n_steps,) (a net tracker's drive: its power in ``rows`` is
        then its whole power, :func:`foldopt.engine.storage.simulate`'s ``draw``).

    Returns
    -------
    DayStorage
    """
    storage = study.storage
    fold_angles = np.asarray(fold_angles, dtype=float)
    buffer = buffer_of(storage)
    engine = storage_engine(engine)
    names = list(rows)
    draws = draws or {}

    def own(names):
        # The designs' own draws, none for most (a draw of 0 W is none, to the bit).
        if not any(name in draws for name in names):
            return None
        zero = np.zeros(np.shape(rows[names[0]][1]))
        return np.vstack([draws.get(name, zero) for name in names])

    designs = run_buffer(
        np.vstack([power for _, power in rows.values()]),
        load,
        buffer,
        step_hours,
        engine,
        draw=own(names),
    )
    soc = run_buffer(
        np.vstack([rows[name][1] for name in SOC_DESIGNS]),
        load,
        buffer,
        step_hours,
        engine,
        soc_curves=True,
        draw=own(SOC_DESIGNS),
    )
    grid = run_buffer(grid_power, load, buffer, step_hours, engine)
    by_angle = grid.powered_h[:, 0]
    near = {
        key: float(value)
        for key, value in near_optimal(fold_angles, by_angle, study.near_optimal).items()
    }
    best = int(best_angle_index(by_angle))
    recommended = near["recommended_deg"]
    near["recommended_powered_h"] = (
        float(by_angle[fold_angles == recommended][0]) if recommended == recommended else np.nan
    )
    table = pd.DataFrame(
        {
            "design": names,
            "fold_angle_deg": [angle for angle, _ in rows.values()],
            "t_solar_h": np.asarray(t_solar, dtype=float),
            **day_columns(designs),
        }
    )
    step = max(1, -(-fold_angles.size // SIZING_ANGLES))
    compared = np.union1d(fold_angles[::step], [fold_angles[best]])
    sizing = size_buffers(
        {
            **{name: rows[name][1] for name in ("flat", "tracker", "tracker-net")},
            "twofold": grid_power[np.searchsorted(fold_angles, compared)],
        },
        compared,
        fold_angles[best],
        load,
        storage,
        step_hours,
        engine,
        study.near_optimal,
        {name: draw for name, draw in draws.items() if name == "tracker-net"},
    )
    return DayStorage(
        storage,
        table,
        by_angle,
        float(fold_angles[best]),
        near,
        {name: soc.soc[i, 0] for i, name in enumerate(SOC_DESIGNS)},
        dict(zip(names, designs.soc_hours.mean(axis=1), strict=True)),
        sizing,
        engine,
        bool(designs.converged.all() and grid.converged.all()),
        designs,
    )


#: The note of a sizing whose target a larger capacity of the grid misses again.
NOT_MONOTONE = (
    "note: a larger buffer than the one given falls short of the target again for {designs} "
    "(hysteresis or self-discharge: powered time is not monotone in capacity); each is the "
    "least capacity evaluated that reaches it"
)


def _digits(value) -> str:
    """A value to 3 significant digits, written out (3840, not 3.84e+03)."""
    return np.format_float_positional(float(f"{value:.3g}"), trim="-")


def _wh(value) -> str:
    return "-" if value != value else f"{_digits(value)} Wh"


def _signed(value: float, digits: int) -> str:
    """``value`` with its sign to ``digits`` decimals, a rounded zero as +0 (never -0.00)."""
    return f"{round(value, digits) + 0.0:+.{digits}f}"


def folding_part(folding: FoldingPays) -> dict:
    """Where folding pays, as the answer's result holds it: ``folding_pays`` (one of
    :data:`FOLDING_STATES`), ``folding_stops_paying_wh`` (the threshold, NaN but below one),
    ``folding_pays_up_to_wh`` (the largest capacity evaluated at which folding pays, NaN where
    none: a threshold's bracket's bottom), ``folding_does_not_pay_from_wh`` (the least capacity
    from which on it pays at none evaluated, NaN where there is none above the largest at which
    it pays: a threshold's bracket's top) and ``folding_searched_up_to_wh``, all [Wh]."""
    return {
        "folding_pays": folding.state,
        "folding_stops_paying_wh": folding.stops_wh,
        "folding_pays_up_to_wh": folding.pays_wh,
        "folding_does_not_pay_from_wh": folding.holds_from_wh,
        "folding_searched_up_to_wh": folding.top_wh,
    }


def folding_line(folding: FoldingPays) -> str:
    """The answer's line on where folding pays (:func:`folding_pays`)."""
    top = _wh(folding.top_wh)
    return {
        "unknown": "whether folding pays with a buffer is not known: no capacity evaluated found "
        "a periodic state",
        "never": f"folding never pays with a buffer up to {top}: at every capacity evaluated flat "
        "runs the load within the near-optimal tolerance of the best twofold angle",
        "below_threshold": f"folding stops paying from {_wh(folding.stops_wh)} of buffer: from "
        f"there up to {top} flat runs the load within the near-optimal tolerance of the best "
        "twofold angle",
        "between": f"folding pays at {_wh(folding.pays_wh)} of buffer and at none evaluated from "
        f"{_wh(folding.holds_from_wh)} up to {top}; the buffers between found no periodic state "
        "(no threshold is known)",
        "at_every_capacity": f"folding pays at every buffer evaluated up to {top}",
        "at_largest_capacity": f"folding still pays at {_wh(folding.pays_wh)}, the largest buffer "
        + (
            "evaluated"
            if folding.pays_wh == folding.top_wh
            else f"whose periodic state is known (none up to {top})"
        ),
    }[folding.state]


def buffer_text(storage) -> str:
    """A buffer as an answer says it: ``5 Wh supercapacitor (cut-off 25 %, reconnect 30 %,
    efficiencies 0.98/0.98, self-discharge 2 %/day)``."""
    kind = storage.preset or "buffer"
    limits = [
        f"{name} {value:g} W"
        for name, value in (
            ("charge", storage.max_charge_w),
            ("discharge", storage.max_discharge_w),
        )
        if value is not None
    ]
    start = (
        "periodic steady state"
        if storage.initial_soc is None
        else f"from {100 * storage.initial_soc:g} %"
    )
    return (
        f"{storage.capacity_wh:g} Wh {kind} (cut-off {100 * storage.min_soc:g} %, reconnect "
        f"{100 * storage.restart_soc:g} %, efficiencies {storage.charge_efficiency:g}/"
        f"{storage.discharge_efficiency:g}, self-discharge {100 * storage.self_discharge:g} %/day"
        + (", max " + ", ".join(limits) if limits else "")
        + f"; {start})"
    )


def answer_part(buffered: DayStorage, designs=("flat", "twofold", "tracker", "tracker-net")):
    """What a day's answer says of its buffer: the part of its result and its lines.

    Parameters
    ----------
    buffered : DayStorage
    designs : tuple of str
        The designs the result names one by one.

    Returns
    -------
    result : dict
        JSON-ready but for NaN (the answer's :func:`~foldopt.studies.answer.plain` makes it null).
    lines : list of str
    """
    storage, sizing = buffered.storage, buffered.sizing
    by = buffered.designs.set_index("design")
    per = {
        column: {d: float(by.loc[d, column]) for d in designs}
        for column in (
            "powered_h",
            "t_solar_h",
            "availability_pct",
            "powered_days_ge24h_pct",
            "energy_missing_wh",
            "energy_lost_wh",
            "days_full_pct",
            "days_empty_pct",
        )
    }
    best_h = float(buffered.powered_by_angle.max())
    part = {
        "buffer": buffer_text(storage),
        **{name: getattr(storage, name) for name in Buffer._fields},
        "preset": storage.preset,
        "fold_angle_deg": buffered.fold_angle_deg,
        "powered_h": best_h,
        **buffered.near_optimal,
        # In the answer's pattern, <quantity>_by_design_<unit> (t_solar_by_design_h).
        **{
            "{}_by_design_{}".format(*column.rsplit("_", 1)): values
            for column, values in per.items()
        },
        "soc_hours_by_design_h": {d: buffered.soc_hours[d].tolist() for d in designs},
        **folding_part(sizing.folding),
        "engine": buffered.engine,
        "converged": buffered.converged,
    }
    powered, t_solar = per["powered_h"], per["t_solar_h"]
    lines = [
        f"with the {buffer_text(storage)}: powered time "
        + ", ".join(f"{d} {powered[d]:.2f} h (t_solar {t_solar[d]:.2f} h)" for d in designs)
    ]
    near = buffered.near_optimal
    if best_h <= 0:
        lines.append("no fold angle runs the load with the buffer: powered 0 h at every angle")
    else:
        lines.append(
            f"best fold angle for the buffer {buffered.fold_angle_deg:g} deg: powered "
            f"{best_h:.2f} h, {_signed(best_h - powered['flat'], 2)} h over flat; near-optimal "
            f"{near['near_optimal_lo_deg']:g} to {near['near_optimal_hi_deg']:g} deg, "
            f"recommended {near['recommended_deg']:g} deg "
            f"({near['recommended_powered_h']:.2f} h)"
        )
    lines.append(
        "availability "
        + ", ".join(f"{d} {per['availability_pct'][d]:.1f} %" for d in designs[:3])
        + "; energy missing/lost a day "
        + ", ".join(
            f"{d} {_digits(per['energy_missing_wh'][d])}/{_wh(per['energy_lost_wh'][d])}"
            for d in designs[:3]
        )
        + "; days full/empty "
        + ", ".join(
            f"{d} {per['days_full_pct'][d]:.0f}/{per['days_empty_pct'][d]:.0f} %"
            for d in designs[:3]
        )
    )
    top = sizing.folding.top_wh
    lines.append(folding_line(sizing.folding))
    if len(sizing.table):
        target = storage.target
        table = sizing.table.set_index("design")
        need = table["capacity_wh"]
        angle = float(table.loc["twofold", "fold_angle_deg"])
        saving = float(table.loc["twofold", "capacity_gain_vs_flat_pct"])
        part["sizing"] = {
            "target_powered_h": target.powered_h,
            "target_days_pct": target.days_pct,
            "capacity_by_design_wh": {d: float(need[d]) for d in table.index},
            "fold_angle_twofold_deg": angle,
            "capacity_twofold_vs_flat_pct": saving,
            "monotone_by_design": {d: bool(table.loc[d, "monotone"]) for d in table.index},
            "searched_up_to_wh": top,
        }
        said = f"{target.powered_h:g} h" + (
            f" on {target.days_pct:g} % of days" if target.days_pct < 100 else ""
        )
        none = f"no buffer up to {_wh(top)} reaches it"

        def needs(label, value):
            return f"{label} needs {_wh(value)}" if value == value else f"{label}: {none}"

        lines.append(
            f"for {said}: {none} (flat, folded at {angle:g} deg, the tracker gross or net)"
            if need.isna().all()
            else f"for {said}: {needs('flat', need['flat'])}, "
            f"{needs(f'folded at {angle:g} deg', need['twofold'])}"
            + (f" ({_signed(saving, 0)} %)" if saving == saving else "")
            + f", {needs('the tracker', need['tracker'])}"
            + f" ({needs('net of its drive', need['tracker-net'])})"
        )
        if not table["monotone"].all():
            lines.append(
                NOT_MONOTONE.format(designs=", ".join(table.index[~table["monotone"].to_numpy()]))
            )
    if not buffered.converged:
        lines.append(
            "note: the buffer found no periodic state for some designs or angles (its end state "
            "never repeats its start's): their powered time is the last pass's"
        )
    return part, lines


#: The columns a buffer adds to a day's designs (summary.csv and the answer's table).
DESIGN_COLUMNS = tuple(SUMMARY_COLUMNS.values())


#: The designs a year's buffer is simulated for: the twofold panel at the angle ``t_solar``'s
#: objective keeps all year, and at the one the objective of powered time keeps
#: (``twofold-buffer``, :func:`powered_by_angle`).
YEAR_DESIGNS = ("flat", "twofold", "twofold-buffer", "tracker", "tracker-net")
#: The designs a year's answer names one by one.
YEAR_SAID = ("flat", "twofold", "twofold-buffer", "tracker")


def _year_series(power, load, in_sequence: bool, draw=None):
    """Series of (rows, days, steps) curves, their load and their own draw (or None) as
    :func:`simulate` takes them: the days in sequence, or each day its own periodic series."""
    if in_sequence:
        return power, load, draw
    series = power.reshape(-1, 1, power.shape[-1])
    return (
        series,
        load if np.ndim(load) == 0 else load.reshape(series.shape),
        None if draw is None else draw.reshape(series.shape),
    )


def powered_by_angle(storage, chunks, loads, load_shape, dates, step_hours, weather, engine):
    """Daily powered time of the twofold panel at every fold angle of a grid over an annual group's
    days, a chunk of angles at a time (their curves are the memory).

    Parameters
    ----------
    storage : foldopt.inputs.storage_section.Storage
    chunks : iterable of numpy.ndarray
        The power [W] of consecutive angles of the grid, (k, n_days, n_steps) each.
    loads, load_shape, dates, step_hours, weather, engine
        As :func:`year_storage`'s.

    Returns
    -------
    numpy.ndarray
        (n_days, n_loads, n_angles) [h]; a series with no periodic state counts its last pass.
    """
    engine = storage_engine(engine)
    in_sequence = sequential(dates, weather)
    buffer = buffer_of(storage)
    hours = []
    for power in chunks:
        per_load = []
        for p_load in np.asarray(loads, dtype=float):
            load = (
                p_load if load_shape is None else p_load * np.broadcast_to(load_shape, power.shape)
            )
            series, load, _ = _year_series(power, load, in_sequence)
            result = simulate(series, load, buffer, step_hours, engine)
            per_load.append(result.powered_h.reshape(power.shape[:2]))
        hours.append(np.stack(per_load))  # (loads, k, days)
    return np.concatenate(hours, axis=1).transpose(2, 0, 1)


def year_storage(
    storage,
    curves: dict,
    loads,
    load_shape,
    dates,
    step_hours,
    weather: bool,
    engine,
    choice: dict,
    draws=None,
) -> pd.DataFrame:
    """A buffer over an annual group's days, per load and design.

    Parameters
    ----------
    storage : foldopt.inputs.storage_section.Storage
    curves : dict
        Design of :data:`YEAR_DESIGNS` -> power [W], (n_days, n_loads, n_steps) or, the same for
        every load, (n_days, n_steps).
    loads : array_like
        (n_loads,) [W], or a load profile's scales.
    load_shape : numpy.ndarray or None
        A load profile's shape per day, (n_days, n_steps).
    dates : sequence of datetime.date
        (n_days,) the days, in order.
    step_hours : float
    weather : bool
        The days are a weather file's: where they follow each other the buffer carries over from
        day to day, starting from the state at the last one's end (:func:`sequential`); else
        each day is a clear-sky day repeated to its own periodic state.
    engine : str
    choice : dict
        ``site`` (the group's), ``objective`` (:class:`foldopt.inputs.sections.Objective`),
        ``fold_angle_deg``: design -> (n_loads,) [deg] (NaN for a tracker), and ``near``:
        :func:`foldopt.studies.objectives.near_optimal` of the objective of powered time over the
        grid, (n_loads,) each, the ``twofold-buffer`` row's.
    draws : dict, optional
        Design -> its own draw [W], (n_days, n_steps): ``tracker-net``'s drive, whose power in
        ``curves`` is then its whole power (:func:`foldopt.engine.storage.simulate`'s ``draw``).

    Returns
    -------
    pandas.DataFrame
        Per load and design: ``site_name``, ``latitude``, ``longitude``, ``p_load_w``,
        ``design``, ``fold_angle_deg``, ``days``, ``objective`` (the statistic),
        ``powered_objective_h`` (of the daily powered time), ``powered_mean_h``,
        ``powered_min_h``, ``t_solar_mean_h`` (of the same curves, with no buffer: the 0 Wh
        run) and :func:`day_columns`' ``availability_pct``, ``powered_days_ge24h_pct``,
        ``energy_missing_wh``, ``energy_lost_wh`` (a day, the days' mean), ``days_full_pct``,
        ``days_empty_pct``; ``converged`` where every series found its periodic state; with
        ``storage.target``, ``capacity_wh``, the smallest buffer reaching it over the days
        (:func:`smallest_buffers`; NaN: none up to the grid's top), ``capacity_gain_vs_flat_pct``
        and ``monotone``; the near-optimal range of ``twofold-buffer`` (NaN in the other
        rows).
    """
    engine = storage_engine(engine)
    loads = np.asarray(loads, dtype=float)
    in_sequence = sequential(dates, weather)
    objective, site = choice["objective"], choice["site"]
    months = [date.month for date in dates]
    rows = []
    for index, p_load in enumerate(loads):
        power = np.stack(
            [curves[d] if curves[d].ndim == 2 else curves[d][:, index] for d in YEAR_DESIGNS]
        )  # (designs, days, steps)
        own = (
            np.stack([draws.get(d, np.zeros(power.shape[1:])) for d in YEAR_DESIGNS])
            if draws
            else None
        )
        load = p_load if load_shape is None else p_load * np.broadcast_to(load_shape, power.shape)
        series, load, draw = _year_series(power, load, in_sequence, own)
        result = simulate(series, load, buffer_of(storage), step_hours, engine, draw=draw)
        bare = simulate(
            series, load, buffer_of(storage, capacity_wh=0.0), step_hours, engine, draw=draw
        )
        shape = (len(YEAR_DESIGNS), -1)
        if not in_sequence:
            result = _by_design(result, len(YEAR_DESIGNS))
            bare = _by_design(bare, len(YEAR_DESIGNS))
        powered = result.powered_h.reshape(shape)
        sized = {}
        if storage.target is not None:
            # Each design's smallest buffer for the target over the days (a load profile's day
            # by day).
            need, monotone = smallest_buffers(
                power,
                p_load if load_shape is None else p_load * load_shape[None],
                storage,
                step_hours,
                engine,
                in_sequence,
                None if own is None else list(own),
            )
            with np.errstate(invalid="ignore", divide="ignore"):
                vs_flat = (need / need[0] - 1.0) * 100.0 if need[0] > 0 else np.nan * need
            sized = {
                "capacity_wh": need,
                "capacity_gain_vs_flat_pct": vs_flat,
                "monotone": monotone,
            }
        score = objective_value(powered.T, months, objective.statistic, objective.months)
        angles = np.array([choice["fold_angle_deg"][d][index] for d in YEAR_DESIGNS])
        chosen = np.asarray(YEAR_DESIGNS) == "twofold-buffer"
        rows.append(
            pd.DataFrame(
                {
                    "site_name": site.name or "",
                    "latitude": site.latitude,
                    "longitude": site.longitude,
                    "p_load_w": p_load,
                    "design": YEAR_DESIGNS,
                    "fold_angle_deg": angles,
                    "days_n": powered.shape[1],
                    "objective": objective.statistic,
                    "powered_objective_h": score,
                    "powered_mean_h": powered.mean(axis=1),
                    "powered_min_h": powered.min(axis=1),
                    "t_solar_mean_h": bare.powered_h.reshape(shape).mean(axis=1),
                    **{k: v for k, v in day_columns(result).items() if k != "powered_h"},
                    "converged": result.converged.reshape(shape[0], -1).all(axis=1),
                    **sized,
                    **{
                        key: np.where(chosen, value[index], np.nan)
                        for key, value in choice["near"].items()
                    },
                }
            )
        )
    return pd.concat(rows, ignore_index=True)


def sequential(dates, weather: bool) -> bool:
    """Whether a buffer carries over from day to day: a weather file's days that follow each
    other (a clear sky's days are each repeated to their own periodic state)."""
    days = np.asarray([date.toordinal() for date in dates])
    return bool(weather and (np.diff(days) == 1).all())


def _by_design(result: StorageResult, designs: int) -> StorageResult:
    """A result of (designs x days) one-day series as (designs, days) series of days."""
    return result._replace(
        **{
            name: getattr(result, name).reshape(designs, -1, *getattr(result, name).shape[2:])
            for name in (
                "powered_h",
                "served_wh",
                "missing_wh",
                "lost_wh",
                "full",
                "empty",
                "soc_hours",
            )
        },
        passes=np.where(
            (result.passes.reshape(designs, -1) > 0).all(axis=1),
            1,
            -1,
        ),
    )


def _another(angle) -> bool:
    """Whether the angle the objective of powered time keeps was chosen and is not
    ``t_solar``'s (the year's lines then name it apart)."""
    chosen = angle["twofold-buffer"]
    return chosen == chosen and chosen != angle["twofold"]


def _best_for_buffer(by: pd.DataFrame, angle) -> str:
    """A year's line on the fold angle the objective of powered time keeps, of one load's rows
    by design (:func:`year_lines`)."""
    best = by.loc["twofold-buffer"]
    statistic = best["objective"]
    said = f"  best fold angle for the buffer ({statistic} powered time)"
    return (
        f"{said}: {angle['twofold-buffer']:g} deg, {best['powered_objective_h']:.2f} h (t_solar's "
        f"{angle['twofold']:g} deg: {by.loc['twofold', 'powered_objective_h']:.2f} h; flat "
        f"{by.loc['flat', 'powered_objective_h']:.2f} h); "
        + (
            f"near-optimal {best['near_optimal_lo_deg']:g} to {best['near_optimal_hi_deg']:g} deg, "
            f"recommended {best['recommended_deg']:g} deg"
            if best["near_optimal_lo_deg"] == best["near_optimal_lo_deg"]
            else f"no fold angle runs the load ({statistic} powered time 0 h at every angle): no "
            "near-optimal range"
        )
    )


def year_lines(storage, table: pd.DataFrame, in_sequence: bool) -> list[str]:
    """What an annual answer says of its buffer, per load (at most 8): powered time per design,
    and the fold angle the objective of powered time keeps beside the one ``t_solar``'s keeps."""
    how = (
        "the days in sequence from the last one's end state"
        if in_sequence
        else "each day repeated to its periodic state"
    )
    lines = [f"with the {buffer_text(storage)}, {how}:"]
    cases = [
        table.iloc[start : start + len(YEAR_DESIGNS)]
        for start in range(0, len(table), len(YEAR_DESIGNS))
    ]
    sites = table[["latitude", "longitude"]].drop_duplicates()
    for rows in cases[:8]:
        by = rows.set_index("design")
        first = rows.iloc[0]
        p_load = first["p_load_w"]
        site = (
            f"{first['site_name'] or f'{first.latitude:g}, {first.longitude:g}'}: "
            if len(sites) > 1
            else ""
        )
        angle = by["fold_angle_deg"]
        named = {
            "flat": "flat",
            "twofold": f"twofold {angle['twofold']:g} deg",
            "twofold-buffer": f"twofold {angle['twofold-buffer']:g} deg",
            "tracker": "tracker",
        }
        lines.append(
            f"  {site}P_load {p_load:g}: mean powered time "
            + ", ".join(
                f"{named[d]} {by.loc[d, 'powered_mean_h']:.2f} h "
                f"(t_solar {by.loc[d, 't_solar_mean_h']:.2f} h)"
                for d in YEAR_SAID
                if d != "twofold-buffer" or _another(angle)
            )
            + "; all 24 h on "
            + ", ".join(f"{d} {by.loc[d, 'powered_days_ge24h_pct']:.0f} %" for d in SOC_DESIGNS)
            + " of days; days full/empty "
            + ", ".join(
                f"{d} {by.loc[d, 'days_full_pct']:.0f}/{by.loc[d, 'days_empty_pct']:.0f} %"
                for d in SOC_DESIGNS
            )
        )
        lines.append(_best_for_buffer(by, angle))
        if "capacity_wh" in by:
            target = storage.target
            said = f"{target.powered_h:g} h" + (
                f" on {target.days_pct:g} % of days" if target.days_pct < 100 else " every day"
            )
            need, saving = by["capacity_wh"], by["capacity_gain_vs_flat_pct"]
            lines.append(
                f"  for {said}: "
                + ", ".join(
                    (
                        f"{named[d]} needs {_wh(need[d])}"
                        + (
                            f" ({_signed(saving[d], 0)} %)"
                            if d != "flat" and saving[d] == saving[d]
                            else ""
                        )
                        if need[d] == need[d]
                        else f"{named[d]}: no buffer up to the search's top reaches it"
                    )
                    for d in YEAR_SAID
                    if d != "twofold-buffer" or _another(angle)
                )
            )
    if len(cases) > 8:
        lines.append(f"  ... and {len(cases) - 8} more (storage_annual.csv)")
    if "monotone" in table and not table["monotone"].all():
        lines.append(
            NOT_MONOTONE.format(
                designs=", ".join(dict.fromkeys(table.loc[~table["monotone"], "design"]))
            )
        )
    if not table["converged"].all():
        lines.append(
            "note: the buffer found no periodic state for some designs: their powered time is "
            "the last pass's"
        )
    return lines
