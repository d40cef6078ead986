"""A map site's fold angles, searched: its best angle for every period and load from a small share
of the grid's angles.

:class:`FoldSearch` asks for fold angles and is told their daily t_solar; a map runs one per site
and evaluates what all the sites of a batch ask for in one pass of the engine (:func:`search_sites`),
so that a call's cost is shared by many sites and the kernel sees many rows at once.

The search, per site, is :class:`foldopt.engine.search.GridSearch` on the study's grid of fold
angles over every period's objective and every load together (its *targets*; a map has five
periods of ten loads): every target's best within the search's tolerance of the grid's (the
argument is there). The targets share every evaluated angle, and each refines where its own
objective bends, so that the union, some 70 of 180 angles on a map's sites, holds the steep flanks
below every load's plateau finely: that shared refinement is what keeps the search's answers on the
full sweep's (measured on 40 land sites: no target more than 0.005 h short, where a search per
period, a quarter of the days for each season, evaluates some 20 % fewer days' angles and was
twice short by more than the tolerance). The near-optimal ranges are then placed on the grid from
the evaluated angles (:func:`foldopt.studies.objectives.near_optimal_on_grid`).
``tests/test_worldmap.py`` holds the answers to a full sweep of the grid on random sites, loads and
objectives.
"""

from __future__ import annotations

import numpy as np

from foldopt.engine.search import Axis, GridSearch
from foldopt.studies.designs import requested_hours
from foldopt.studies.objectives import objective_quantum, period_values


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
    """

    def __init__(self, axis: Axis, months, statistic: str, seasons, tolerance_h: float, quantum: float):
        self.months, self.statistic, self.seasons = np.asarray(months), statistic, list(seasons)
        self.grid = GridSearch([axis], tolerance_h, quantum)
        self.found: list = []  # (angles (n,), hours (days, n, loads), energy (days, n)) as told
        self._asked = np.zeros(0)

    def ask(self):
        """The fold angles [deg] to evaluate next on every day, (n,), or None when the search is done."""
        points = self.grid.ask()
        self._asked = None if points is None else points[:, 0]
        return self._asked

    def tell(self, hours, energy) -> None:
        """The asked angles' daily t_solar [h], (days, n, loads), and harvested energy [Wh], (days, n)."""
        hours, energy = np.asarray(hours, dtype=float), np.asarray(energy, dtype=float)
        self.found.append((self._asked, hours, energy))
        self.grid.tell(period_values(hours, self.months, self.statistic, self.seasons).transpose(1, 0, 2).reshape(
            self._asked.size, -1))

    def result(self):
        """``(angles (n,), hours (days, loads, n), energy (days, n))`` over every evaluated angle, ascending."""
        angles = np.concatenate([angles for angles, _, _ in self.found])
        order = np.argsort(angles)
        hours = np.concatenate([hours for _, hours, _ in self.found], axis=1)[:, order].transpose(0, 2, 1)
        energy = np.concatenate([energy for _, _, energy in self.found], axis=1)[:, order]
        return angles[order], hours, energy


def search_sites(searches, evaluate) -> list:
    """Run many sites' searches together: each round, what every unfinished search asks for goes
    to ``evaluate`` in one call.

    Parameters
    ----------
    searches : sequence of FoldSearch
    evaluate : callable
        ``evaluate({site: angles})`` -> ``{site: (hours (days, n, loads), energy (days, n))}``,
        ``site`` a search's position in ``searches``.

    Returns
    -------
    list
        Each search's :meth:`FoldSearch.result`.
    """
    asked = {site: search.ask() for site, search in enumerate(searches)}
    asked = {site: angles for site, angles in asked.items() if angles is not None}
    while asked:
        for site, (hours, energy) in evaluate(asked).items():
            searches[site].tell(hours, energy)
        asked = {site: searches[site].ask() for site in asked}
        asked = {site: angles for site, angles in asked.items() if angles is not None}
    return [search.result() for search in searches]


def fold_search(months, statistic: str, seasons, tolerance_h: float):
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

    Returns
    -------
    callable
        ``fold(parts, sites, loads, loadset, engine)`` -> per site ``(angles, hours (days, loads,
        angles), energy (days, angles))``.
    """

    def fold(parts, sites, loads, loadset, engine):
        study = parts[0][0].study
        grid = study.fold_angles
        axis = Axis("fold_angle", grid.start, grid.stop, grid.step)
        step_hours = parts[0][1].step_hours
        tilt = np.concatenate([chunk.tilt for chunk, _ in parts])
        azimuth = np.concatenate([chunk.azimuth for chunk, _ in parts])
        searches = [FoldSearch(axis, days, statistic, seasons, tolerance_h,
                               objective_quantum(statistic, step_hours, len(days), days)) for days in months]

        def evaluate(asked):
            requests = []
            for site, angles in asked.items():
                first, base = sites[site][0], np.ones(angles.size)
                requests.append((np.asarray(sites[site]), np.column_stack([angles, tilt[first] * base,
                                                                           azimuth[first] * base])))
            done = requested_hours(parts, requests, loads, loadset, engine=engine)
            return dict(zip(asked, done, strict=True))

        return search_sites(searches, evaluate)

    return fold
