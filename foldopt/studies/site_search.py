"""A map site's fold angles, searched: its best angle, near-optimal range and recommended angle for
every period and load, from a small share of the grid's angles and days.

:class:`FoldSearch` asks for fold angles, each on the days it needs, and is told their daily
t_solar; a map runs one per site and evaluates what all the sites of a batch ask for in one pass
of the engine (:func:`search_sites`), so that a call's cost is shared by many sites and the kernel
sees many rows at once.

Each period (the year, each season) is searched on its own days for every load together (its
*targets*), the year's evaluations serving the seasons too:

1. :class:`foldopt.engine.search.GridSearch` on the study's grid of fold angles, coarse to fine:
   every target's best within the search's tolerance of the grid's (its argument is there).
2. Each target's near-optimal range (:func:`foldopt.studies.objectives.near_optimal`) on the
   evaluated angles has edges that lie between an evaluated angle inside the range and one outside
   it. Each such gap is narrowed to the grid's step by evaluating the two grid angles either side
   of where the objective crosses the range's threshold (``best - tolerance``) on the line between
   the gap's ends (the secant: on a smooth flank it lands within a step, so one round closes the
   gap), and, while a gap is wider than :data:`SECANT_ONLY_STEPS` steps, its middle as well
   (bisection, which halves it whatever the flank's shape). The range is then the full grid's
   wherever the objective falls monotonically away from the plateau, as a full sweep's.
3. The recommended angle, the grid angle nearest the range's centre, is evaluated too.

A season's angles are evaluated on its own days (a quarter of the year's), which is where most of
a map's edges lie: five periods of ten loads have a hundred. ``tests/test_worldmap.py`` holds the
answers to a full sweep of the grid on random sites, loads and objectives.
"""

from __future__ import annotations

import math

import numpy as np

from foldopt.engine.search import Axis, GridSearch
from foldopt.studies.designs import requested_hours
from foldopt.studies.objectives import near_optimal, objective_quantum, objective_value

#: A gap at most this many grid steps wide is narrowed by the secant alone (two angles a round);
#: a wider one is also halved.
SECANT_ONLY_STEPS = 4


class _PeriodEdges:
    """One period's near-optimal edges and recommended angles over grid indices, from the values
    the grid search left: asks for indices, is told their objective per load."""

    def __init__(self, axis: Axis, days, values: dict, near_optimal_tolerance):
        self.axis, self.days, self.near = axis, days, near_optimal_tolerance
        self.values = values  # grid index -> objective per load
        self.rounds = 2 * math.ceil(math.log2(max(axis.size, 2))) + 4
        self.asked = np.zeros(0, dtype=int)

    def ask(self):
        """Grid indices to evaluate next, or None when the period is done."""
        while self.rounds > 0:
            self.rounds -= 1
            wanted = self._edges() or self._recommended()
            if wanted:
                self.asked = np.array(sorted(wanted), dtype=int)
                return self.asked
            self.rounds = 0
        return None

    def tell(self, values) -> None:
        """The objective per load of each asked index, (n, loads)."""
        for position, index in enumerate(self.asked):
            self.values[int(index)] = values[position]

    def _ranges(self):
        indices = np.array(sorted(self.values))
        values = np.stack([self.values[index] for index in indices], axis=-1)  # (loads, n)
        return indices, values, near_optimal(self.axis.values(indices), values, self.near)

    def _edges(self) -> set:
        """Grid indices that narrow the gaps beyond each target's near-optimal range."""
        indices, values, ranges = self._ranges()
        angles = self.axis.values(indices)
        top = np.nanmax(values, axis=1)
        wanted = set()
        for target, (lo, hi) in enumerate(zip(ranges["near_optimal_lo_deg"], ranges["near_optimal_hi_deg"],
                                              strict=True)):
            if lo != lo:
                continue  # no angle carries the load
            line = top[target] - ranges["near_optimal_tolerance_h"][target]
            first, last = np.searchsorted(angles, [lo - 1e-9, hi - 1e-9])
            for a, b in ((first - 1, first), (last, last + 1)):
                if not (0 <= a and b < indices.size and indices[b] - indices[a] > 1):
                    continue
                low, high = int(indices[a]), int(indices[b])
                fa, fb = values[target, a], values[target, b]
                # Where the line between the gap's ends crosses the threshold, in grid steps.
                cross = low + (fa - line) / (fa - fb) * (high - low) if fa != fb else (low + high) / 2
                cross = min(max(cross, low), high)
                wanted.update(k for k in (math.floor(cross), math.floor(cross) + 1) if low < k < high)
                if high - low > SECANT_ONLY_STEPS:
                    wanted.add((low + high) // 2)
        return wanted - set(self.values)

    def _recommended(self) -> set:
        """Grid indices of each target's recommended angle (nearest the range's centre, ties to
        the less folded, as :func:`near_optimal` breaks them) not evaluated yet."""
        _, _, ranges = self._ranges()
        centres = (ranges["near_optimal_lo_deg"] + ranges["near_optimal_hi_deg"]) / 2
        grid = self.axis.values()
        nearest = {int(np.argmin(np.abs(grid - centre) - 1e-9 * grid)) for centre in centres[np.isfinite(centres)]}
        return nearest - set(self.values)


class FoldSearch:
    """One site's search of the fold-angle grid for every period's objective and every load.

    Parameters
    ----------
    axis : Axis
        The study's grid of fold angles.
    months : numpy.ndarray
        (days,) month of each day.
    statistic : str
        :func:`foldopt.studies.objectives.objective_value`'s.
    seasons : sequence
        Each period's months (None: every day).
    tolerance_h : float
        The grid search's tolerance [h].
    quantum : float
        The objective's own jumps [h] (:func:`foldopt.studies.objectives.objective_quantum`).
    near_optimal_tolerance : foldopt.inputs.sections.NearOptimal
    """

    def __init__(self, axis: Axis, months, statistic: str, seasons, tolerance_h: float, quantum: float,
                 near_optimal_tolerance):
        self.axis, self.months, self.statistic = axis, np.asarray(months), statistic
        self.days = [np.isin(self.months, season) if season else np.ones(self.months.size, bool) for season in seasons]
        self.near = near_optimal_tolerance
        self.grid = GridSearch([axis], tolerance_h, quantum)
        self.periods: list = []
        # Each grid angle's daily t_solar (days, loads, angles) and energy (days, angles), NaN until evaluated.
        self.hours = self.energy = None
        self.evaluated = np.zeros((self.months.size, axis.size), bool)
        self._pending: dict[int, np.ndarray] = {}
        self._requests: list = []

    def ask(self):
        """What to evaluate next, or None when the search is done: a list of ``(angles [deg],
        days)``, each the angles (n,) to evaluate on the days (indices) given."""
        if self.grid is not None:
            points = self.grid.ask()
            if points is not None:
                indices = np.where(points[:, 0] == self.axis.hi, self.axis.size - 1,
                                   np.rint((points[:, 0] - self.axis.lo) / self.axis.step)).astype(int)
                self._requests = [(indices, np.arange(self.months.size))]
                return [(points[:, 0], self._requests[0][1])]
            self.grid = None
            # Every grid-search angle was evaluated on every day: each period starts from all of them.
            known = np.flatnonzero(self.evaluated.all(axis=0))
            self.periods = [_PeriodEdges(self.axis, days, dict(zip(known.tolist(), self._objective(known, days),
                                                                   strict=True)), self.near) for days in self.days]
        while True:
            self._pending = {}
            for number, period in enumerate(self.periods):
                asked = period.ask()
                if asked is not None:
                    self._pending[number] = asked
            if not self._pending:
                return None
            needs: dict[int, np.ndarray] = {}
            for number, asked in self._pending.items():
                missing = self.periods[number].days[:, None] & ~self.evaluated[:, asked]  # (days, asked)
                for position, index in enumerate(asked.tolist()):
                    needs[index] = needs[index] | missing[:, position] if index in needs else missing[:, position]
            groups: dict[bytes, list] = {}
            for index, days in needs.items():
                if days.any():
                    groups.setdefault(days.tobytes(), [days, []])[1].append(index)
            self._requests = [(np.array(sorted(indices)), np.flatnonzero(days)) for days, indices in groups.values()]
            if self._requests:
                return [(self.axis.values(indices), days) for indices, days in self._requests]
            self._tell_periods()  # every asked angle was known already (another period had it)

    def tell(self, results) -> None:
        """For each request of :meth:`ask`, in its order, ``(hours (days, n, loads), energy (days, n))``
        on its days."""
        for (indices, days), (hours, energy) in zip(self._requests, results, strict=True):
            if self.hours is None:  # filled where evaluated (read only there)
                self.hours = np.empty((self.months.size, hours.shape[2], self.axis.size))
                self.energy = np.empty((self.months.size, self.axis.size))
            self.hours[days[:, None], :, indices[None, :]] = hours
            self.energy[days[:, None], indices[None, :]] = energy
            self.evaluated[days[:, None], indices[None, :]] = True
        if self.grid is not None:
            asked = self._requests[0][0]
            self.grid.tell(np.concatenate([self._objective(asked, days) for days in self.days], axis=1))
        self._tell_periods()

    def _objective(self, indices, days) -> np.ndarray:
        """(n, loads) the objective of the grid indices' angles over the days of a period."""
        hours = self.hours[:, :, np.asarray(indices)][days]  # (days, loads, n)
        return objective_value(hours, self.months[days], self.statistic).T

    def _tell_periods(self) -> None:
        for number, asked in self._pending.items():
            self.periods[number].tell(self._objective(asked, self.periods[number].days))
        self._pending = {}

    def result(self):
        """``(angles (n,), hours (days, loads, n), energy (days, n))`` over every evaluated angle, NaN
        on the days an angle was not evaluated (a season's angles on the other seasons' days)."""
        indices = np.flatnonzero(self.evaluated.any(axis=0))
        unknown = ~self.evaluated[:, indices]
        hours, energy = self.hours[:, :, indices], self.energy[:, indices]
        hours[np.broadcast_to(unknown[:, None, :], hours.shape)] = np.nan
        energy[unknown] = np.nan
        return self.axis.values(indices), hours, energy


def search_sites(searches, evaluate) -> list:
    """Run many sites' searches together: each round, what every unfinished search asks for goes
    to ``evaluate`` in one call.

    Parameters
    ----------
    searches : sequence of FoldSearch
    evaluate : callable
        ``evaluate({site: requests})`` -> ``{site: results}``: ``site`` a search's position in
        ``searches``, its requests and results those of :meth:`FoldSearch.ask` and
        :meth:`FoldSearch.tell`.

    Returns
    -------
    list
        Each search's :meth:`FoldSearch.result`.
    """
    asked = {site: search.ask() for site, search in enumerate(searches)}
    asked = {site: requests for site, requests in asked.items() if requests is not None}
    while asked:
        for site, results in evaluate(asked).items():
            searches[site].tell(results)
        asked = {site: searches[site].ask() for site in asked}
        asked = {site: requests for site, requests in asked.items() if requests is not None}
    return [search.result() for search in searches]


def fold_search(months, statistic: str, seasons, tolerance_h: float, near_optimal_tolerance):
    """The fold angles of a batch of a map's sites, searched (:class:`FoldSearch`, one a site), as
    :func:`foldopt.studies.designs.site_designs` takes them.

    Parameters
    ----------
    months : sequence of numpy.ndarray
        Each site's month of each day, (days,).
    statistic : str
        :func:`foldopt.studies.objectives.objective_value`'s.
    seasons : sequence
        Each period's months (None: every day).
    tolerance_h : float
        The grid search's tolerance [h].
    near_optimal_tolerance : foldopt.inputs.sections.NearOptimal

    Returns
    -------
    callable
        ``fold(parts, sites, loads, loadset, engine)`` -> per site ``(angles, hours (days, loads,
        angles), energy (days, angles))``, NaN on the days an angle was not evaluated.
    """

    def fold(parts, sites, loads, loadset, engine):
        study = parts[0][0].study
        grid = study.fold_angles
        axis = Axis("fold_angle", grid.start, grid.stop, grid.step)
        step_hours = parts[0][1].step_hours
        tilt = np.concatenate([chunk.tilt for chunk, _ in parts])
        azimuth = np.concatenate([chunk.azimuth for chunk, _ in parts])
        searches = [FoldSearch(axis, days, statistic, seasons, tolerance_h,
                               objective_quantum(statistic, step_hours, len(days), days), near_optimal_tolerance)
                    for days in months]

        def evaluate(asked):
            requests, owners = [], []
            for site, site_requests in asked.items():
                first = sites[site][0]
                for angles, days in site_requests:
                    base = np.ones(angles.size)
                    points = np.column_stack([angles, tilt[first] * base, azimuth[first] * base])
                    requests.append((first + days, points))
                    owners.append(site)
            done: dict[int, list] = {}
            for site, result in zip(owners, requested_hours(parts, requests, loads, loadset, engine=engine),
                                    strict=True):
                done.setdefault(site, []).append(result)
            return done

        return search_sites(searches, evaluate)

    return fold
