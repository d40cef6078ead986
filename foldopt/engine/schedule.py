"""Re-folding a panel by hand a few times a year: the dates and fold angles that serve best.

A maintenance crew can re-fold the panel on k visits a year; between visits it keeps one fold angle.
Given the t_solar of every day of the year at every fold angle of the grid (``hours``, days x
angles: :func:`foldopt.studies.sweeps.fold_hours` over a year), the best schedule of k settings is an
optimal cyclic segmentation of the year: k arcs of consecutive days, each at its own best angle.
The year is cyclic, so the setting made at the last visit runs on over 31 December into the next
January.

``mean`` (the year's mean daily t_solar) is additive over days, so the segmentation is solved
exactly by dynamic programming (:func:`best_schedules`):

- ``best[i, L]``, the best angle's total over the L days from day i (wrapping), comes from
  cumulative sums per angle in O(D^2 A) for D days and A angles;
- for every first visit day s, ``f[m, j]``, the best total of the first j days after s in m arcs,
  is ``max_i f[m-1, i] + best[s + i, j - i]``: O(K D^2) per s, O(K D^3) in all (365 days, 12 visits:
  about a second in NumPy).

``worst-month`` (the lowest monthly mean) is not additive over days: a month split between two
settings mixes them. Its visits are therefore on the first day of a month, where every month has
one setting; the year's 12 months in k arcs are then few enough (at most 924 ways) to be searched
exhaustively, each arc at the angle that maximises its worst month. That is exact for visits at
month starts, which is how the schedule is stated.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

#: Objectives a schedule maximises.
SCHEDULE_OBJECTIVES = ("mean", "worst-month")
MAX_VISITS = 12


@dataclass(frozen=True)
class Schedule:
    """k fold settings a year, each kept until the next visit.

    Parameters
    ----------
    starts : tuple of int
        Day index of each visit, ascending (the first the earliest in the year).
    angles : tuple of int
        Index into the fold-angle grid of each visit's setting.
    objective_h : float
        The objective the schedule reaches [h] (:data:`SCHEDULE_OBJECTIVES`).
    """

    starts: tuple
    angles: tuple
    objective_h: float

    def daily_angles(self, n_days: int) -> np.ndarray:
        """The angle index in force on every day (the last setting wraps into January).

        Parameters
        ----------
        n_days : int
            Days of the year.

        Returns
        -------
        numpy.ndarray of int
            (n_days,) index into the fold-angle grid.

        Examples
        --------
        >>> print(Schedule((2, 5), (7, 9), 0.0).daily_angles(7))
        [9 9 7 7 7 9 9]
        """
        index = np.empty(n_days, dtype=int)
        starts = list(self.starts)
        for position, start in enumerate(starts):
            stop = starts[position + 1] if position + 1 < len(starts) else n_days
            index[start:stop] = self.angles[position]
        index[: starts[0]] = self.angles[-1]
        return index


def _wrapped_best(hours: np.ndarray):
    """``best[i, L - 1]`` and ``angle[i, L - 1]``: the largest total of the L days from day i
    (wrapping) at one angle, and that angle (ties: the least folded, the last of the grid)."""
    n_days, n_angles = hours.shape
    doubled = np.concatenate([hours, hours])  # (2D, A)
    cumulative = np.vstack([np.zeros(n_angles), np.cumsum(doubled, axis=0)])  # (2D + 1, A)
    best = np.empty((n_days, n_days))
    angle = np.empty((n_days, n_days), dtype=int)
    for start in range(n_days):
        totals = cumulative[start + 1 : start + n_days + 1] - cumulative[start]  # (L, A)
        reversed_index = np.argmax(totals[:, ::-1], axis=1)
        angle[start] = n_angles - 1 - reversed_index
        best[start] = totals[np.arange(n_days), angle[start]]
    return best, angle


def _mean_schedules(hours: np.ndarray, max_visits: int) -> list[Schedule]:
    n_days = hours.shape[0]
    best, angle = _wrapped_best(hours)
    schedules = []
    whole = best[0, n_days - 1]
    schedules.append(Schedule((0,), (int(angle[0, n_days - 1]),), whole / n_days))
    if max_visits == 1:
        return schedules
    offsets = np.arange(n_days + 1)
    found = {k: (-np.inf, None) for k in range(2, max_visits + 1)}
    lengths = offsets[None, :] - offsets[:, None]  # j - i
    valid = lengths > 0
    for first in range(n_days):
        # segment[i, j]: the best total of days first+i .. first+j-1 (wrapping).
        rows = (first + offsets[:, None]) % n_days
        segment = np.where(valid, best[rows, np.clip(lengths - 1, 0, n_days - 1)], -np.inf)
        value = segment[0].copy()  # one arc: days 0..j-1 after `first`
        back = []
        for k in range(2, max_visits + 1):
            candidates = value[:, None] + segment  # (i, j)
            previous = np.argmax(candidates, axis=0)
            value = candidates[previous, offsets]
            back.append(previous)
            if value[n_days] > found[k][0]:
                found[k] = (value[n_days], (first, list(back)))
    for k in range(2, max_visits + 1):
        total, (first, back) = found[k]
        cuts = [n_days]
        for previous in reversed(back[: k - 1]):
            cuts.append(int(previous[cuts[-1]]))
        cuts = [0, *cuts[::-1]]  # 0 = c_0 < c_1 < ... < c_k = D, offsets from `first`
        starts = [(first + cut) % n_days for cut in cuts[:-1]]
        fold_angles = [
            int(angle[(first + cuts[m]) % n_days, cuts[m + 1] - cuts[m] - 1]) for m in range(k)
        ]
        order = np.argsort(starts)
        schedules.append(
            Schedule(
                tuple(int(starts[i]) for i in order),
                tuple(fold_angles[i] for i in order),
                total / n_days,
            )
        )
    return schedules


def _worst_month_schedules(
    hours: np.ndarray, months: np.ndarray, max_visits: int
) -> list[Schedule]:
    present = np.unique(months)
    monthly = np.stack([hours[months == m].mean(axis=0) for m in present])  # (M, A)
    first_day = [int(np.flatnonzero(months == m)[0]) for m in present]
    n_months, n_angles = monthly.shape
    schedules = []
    for k in range(1, min(max_visits, n_months) + 1):
        best = (-np.inf, None)
        for cuts in itertools.combinations(range(n_months), k):
            value, fold_angles = np.inf, []
            for position, start in enumerate(cuts):
                stop = cuts[position + 1] if position + 1 < k else cuts[0] + n_months
                arc = [(start + m) % n_months for m in range(stop - start)]
                worst = monthly[arc].min(axis=0)
                choice = n_angles - 1 - int(np.argmax(worst[::-1]))
                fold_angles.append(choice)
                value = min(value, worst[choice])
            if value > best[0]:
                best = (value, (cuts, fold_angles))
        value, (cuts, fold_angles) = best
        schedules.append(
            Schedule(tuple(first_day[c] for c in cuts), tuple(fold_angles), float(value))
        )
    return schedules


def best_schedules(hours, months, max_visits: int, objective: str = "mean") -> list[Schedule]:
    """The best schedule of k = 1 ... ``max_visits`` fold settings a year.

    Parameters
    ----------
    hours : array_like
        (days, angles) daily t_solar [h] of the days of one year, in order.
    months : array_like
        (days,) month of each day.
    max_visits : int
        K, at most :data:`MAX_VISITS`.
    objective : {'mean', 'worst-month'}
        The year's mean daily t_solar (visits on any day), or its lowest monthly mean (visits on
        the first of a month).

    Returns
    -------
    list of Schedule
        Index k - 1 holds the best schedule of k settings; k = 1 is the single fixed angle.

    Raises
    ------
    ValueError
        If ``objective`` is unknown or ``max_visits`` is outside [1, min(12, days)].

    Examples
    --------
    Two angles, one best in the first half of a 4-day "year", the other in the second:

    >>> hours = [[9.0, 8.0], [9.0, 8.0], [8.0, 9.0], [8.0, 9.0]]
    >>> one, two = best_schedules(hours, [1, 1, 2, 2], 2)
    >>> print(one.objective_h, two.starts, two.angles, two.objective_h)
    8.5 (0, 2) (0, 1) 9.0
    """
    hours = np.asarray(hours, dtype=float)
    if objective not in SCHEDULE_OBJECTIVES:
        raise ValueError(
            f"objective must be one of {', '.join(SCHEDULE_OBJECTIVES)}; got {objective!r}"
        )
    if not 1 <= max_visits <= min(MAX_VISITS, hours.shape[0]):
        raise ValueError(
            f"max_visits must be in [1, {min(MAX_VISITS, hours.shape[0])}]; got {max_visits}"
        )
    if objective == "mean":
        return _mean_schedules(hours, max_visits)
    return _worst_month_schedules(hours, np.asarray(months), max_visits)
