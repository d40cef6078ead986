"""How much buffer (issue 41): the capacity searches of a buffered study, run for every design at
once: each design's smallest buffer for a stated target (:func:`size_buffers` for a day,
:func:`smallest_buffers` for a year's days) and the buffer from which folding stops paying
(:func:`folding_pays`).

The sizing is a bracketed search on the capacity: a geometric grid of capacities (the one the
figure of powered time against capacity draws), then the bracket between the least capacity of
the grid reaching the target and the one below it (which does not) cut into
:data:`REFINE_POINTS` + 1 parts, the least part reaching it and the part below it the next
bracket, until it is within :data:`CAPACITY_RTOL` of its top. The capacity given is therefore always one evaluated that
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

The module may import numpy, pandas, :mod:`foldopt.engine`, :mod:`foldopt.inputs` and
:mod:`foldopt.studies.objectives` and :mod:`foldopt.studies.storage_periods`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from foldopt.names import FLAT_FOLD_ANGLE
from foldopt.engine.storage import Buffer, StorageResult, simulate
from foldopt.studies.objectives import best_angle_index
from foldopt.studies.storage_cold import per_series
from foldopt.studies.storage_periods import years_meeting

if TYPE_CHECKING:
    import pandas as pd

#: Capacities of the grid [-, times the day's load energy over the usable fraction] (0 Wh first),
#: with the study's own: the sizing's first bracket and the figure's curve of powered time
#: against capacity.
GRID = np.concatenate([[0.0], np.geomspace(1.0 / 64.0, 4.0, 25)])
#: Interior points each refinement of a bracket evaluates.
REFINE_POINTS = 8
#: A capacity is found once its bracket is within this fraction of its top.
CAPACITY_RTOL = 1e-3
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


def reaches(result: StorageResult, target) -> np.ndarray:
    """(n_series,) bool: whether each series runs the load ``target.powered_h`` on at least
    ``target.days_pct`` of its days, from a periodic state (a series whose end state never
    repeats its start's reaches nothing)."""
    return _reaching(result.powered_h, result.converged, target)


def _reaching(powered_h, converged, target, years=None) -> np.ndarray:
    """:func:`reaches` of daily powered time [h] (n, n_days) and (n,) periodic states; with
    ``years``, each day's year (n_days,), in ``target.years_pct`` of the years
    (:func:`~foldopt.studies.storage_periods.years_meeting`)."""
    days = powered_h >= target.powered_h - TARGET_SLACK_H
    if years is None:
        return (100.0 * days.mean(axis=1) >= target.days_pct - 1e-9) & converged
    return years_meeting(days, years, target.days_pct, target.years_pct) & converged


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
    *,
    own: float,
    load,
    storage,
    step_hours: float,
    engine: str,
    tolerance,
    draws=None,
    cold=None,
) -> Sizing:
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
    cold : foldopt.engine.storage.ColdSteps, optional
        The buffer's temperature's effects at each step of the day, (n_steps,) fields; default
        none.

    Returns
    -------
    Sizing
    """
    import pandas as pd

    fold_angles = np.asarray(fold_angles, dtype=float)
    power = np.vstack([curves["flat"], curves["tracker"], curves["tracker-net"], curves["twofold"]])
    own_draws = [None, None, (draws or {}).get("tracker-net")] + [None] * len(fold_angles)
    capacities = capacity_grid(load, storage, step_hours, power.shape[-1])
    n, m = power.shape[0], capacities.size
    run = _Runs(power, own_draws, load, storage, step_hours, engine, in_sequence=True, cold=cold)
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
    ``(hours, ok)``; ``draws`` per curve as its (None: none), ``cold`` the days' (one for every
    curve)."""

    def __init__(
        self,
        power,
        draws,
        load,
        storage,
        step_hours,
        engine,
        in_sequence: bool,
        *,
        cold=None,
        years=None,
    ):
        draws = [None] * len(power) if draws is None else draws
        self.power, self.draws, self.load, self.storage = power, draws, load, storage
        self.step_hours, self.engine, self.in_sequence = step_hours, engine, in_sequence
        self.cold, self.years = cold, years

    def __call__(self, rows, capacities):
        return _at_capacities(
            self.power[rows],
            capacities,
            self.load,
            self.storage,
            self.step_hours,
            self.engine,
            self.in_sequence,
            draws=[self.draws[row] for row in rows],
            cold=self.cold,
            years=self.years,
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
    power,
    capacities,
    load,
    storage,
    step_hours,
    engine,
    in_sequence: bool,
    *,
    draws=None,
    cold=None,
    years=None,
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
    cold : foldopt.engine.storage.ColdSteps, optional
        The buffer's temperature's effects at each step of the days (fields (n_steps,) or
        (n_days, n_steps), every design's), default none.
    years : array_like, optional
        (n_days,) each day's year: the target is met in ``target.years_pct`` of the years
        (:func:`_reaching`); default over the days as one.

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
        result = simulate(
            np.repeat(power, m, 0), load, buffer, step_hours, engine, draw=own, cold=cold
        )
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
            steps = cold
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
            steps = per_series(cold, lambda field: per_capacity(np.broadcast_to(field, days.shape)))
        result = simulate(series, each, buffer, step_hours, engine, draw=draw, cold=steps)
        powered = result.powered_h.reshape(capacity.size, -1)  # (m, days)
        converged = result.converged.reshape(capacity.size, -1).all(axis=1)
        # A series with no periodic state has no powered time to draw (NaN: the figure leaves
        # it out).
        hours.append(np.where(converged, powered.mean(axis=1), np.nan))
        ok.append(
            _reaching(powered, converged, target, years)
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


def smallest_buffers(
    power,
    load,
    storage,
    step_hours,
    engine,
    in_sequence: bool,
    draws=None,
    *,
    cold=None,
    years=None,
):
    """Each design's smallest buffer [Wh] for ``storage.target`` over its days (NaN: none up to
    the grid's top), by :func:`size_buffers`' search, and whether every larger capacity of the
    grid reaches it too (:func:`_held_above`).

    Parameters
    ----------
    power : numpy.ndarray
        (n, n_days, n_steps) [W].
    load, in_sequence
        As :func:`_at_capacities`'.
    draws, cold, years : optional
        As :func:`_at_capacities`'.
    """
    run, capacities = _on_grid(
        power, load, storage, step_hours, engine, in_sequence, draws, cold=cold, years=years
    )
    rows = np.arange(power.shape[0])
    _, ok = run(rows, np.broadcast_to(capacities, (rows.size, capacities.size)))
    first = np.where(ok.any(axis=1), np.argmax(ok, axis=1), -1)
    return _smallest(run, rows, first, capacities), _held_above(ok, first)


def bracketed_buffers(power, first, *given, **keywords) -> np.ndarray:
    """:func:`smallest_buffers`' capacities [Wh] where each design's least capacity of the grid
    reaching the target is known (``first``, its index in :func:`capacity_grid`; -1: none, NaN):
    its bracket cut alone, the grid not evaluated again.

    Parameters
    ----------
    power : numpy.ndarray
        (n, n_days, n_steps) [W].
    first : numpy.ndarray
        (n,) int.
    *given, **keywords
        :func:`smallest_buffers`' arguments after ``power``.
    """
    run, capacities = _on_grid(power, *given, **keywords)
    return _smallest(run, np.arange(power.shape[0]), np.asarray(first), capacities)


def _on_grid(
    power, load, storage, step_hours, engine, in_sequence, draws=None, *, cold=None, years=None
):
    """A sizing's runs (:class:`_Runs`) and its grid of capacities [Wh] (:func:`capacity_grid`)."""
    run = _Runs(
        power, draws, load, storage, step_hours, engine, in_sequence, cold=cold, years=years
    )
    return run, capacity_grid(load, storage, step_hours, power.shape[-1])


def _held_above(ok, first) -> np.ndarray:
    """(n,) bool: every capacity of the grid from the least reaching the target on reaches it
    too (the premise of a bracketed search; True where none reaches it)."""
    index = np.arange(ok.shape[1])
    return (ok | (index < first[:, None])).all(axis=1) | (first < 0)


def reaching(
    power,
    capacities,
    load,
    storage,
    step_hours,
    engine,
    in_sequence: bool,
    draws=None,
    *,
    cold=None,
    years=None,
):
    """(n,) bool: whether each of ``power``'s curves (n, n_days, n_steps) [W] reaches
    ``storage.target`` at its own capacity (n,) [Wh] (:func:`reaches`), every curve in one call
    of the engine (a call's threads cost more than a year's series).

    Parameters
    ----------
    power : numpy.ndarray
        (n, n_days, n_steps) [W].
    capacities : numpy.ndarray
        (n,) [Wh].
    load, in_sequence
        As :func:`_at_capacities`'.
    draws : sequence, optional
        Per curve, its own draw [W], (n_days, n_steps), or None (none: a draw of 0 W).
    cold, years : optional
        As :func:`_at_capacities`'.
    """
    n, days, steps = power.shape
    draw = (
        None
        if draws is None
        else np.stack([np.zeros((days, steps)) if d is None else d for d in draws])
    )
    load = load if np.ndim(load) == 0 else np.broadcast_to(load, power.shape)
    if not in_sequence:
        # Each day its own periodic series.
        power, capacities = power.reshape(-1, 1, steps), np.repeat(capacities, days)
        load = load if np.ndim(load) == 0 else load.reshape(power.shape)
        draw = None if draw is None else draw.reshape(power.shape)
        cold = per_series(
            cold, lambda field: np.broadcast_to(field, (n, days, steps)).reshape(power.shape)
        )
    buffer = buffer_of(storage, capacity_wh=capacities)
    result = simulate(power, load, buffer, step_hours, engine, draw=draw, cold=cold)
    return _reaching(
        result.powered_h.reshape(n, days),
        result.converged.reshape(n, -1).all(axis=1),
        storage.target,
        years,
    )
