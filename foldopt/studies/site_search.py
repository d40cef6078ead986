"""A map site's fold angles, searched: its best angle for every period and load from a small share
of the grid's angles.

:class:`DesignSearch` asks for designs and is told their daily t_solar; a map runs one per site
and evaluates what all the sites of a batch ask for in one pass of the engine (:func:`search_sites`),
so that a call's cost is shared by many sites and the kernel sees many rows at once.

The search, per site, is :class:`foldopt.engine.search.GridSearch` on the study's grid of fold
angles over every period's objective and every load together (its *targets*; a map has five
periods of ten loads): every target's best within the search's tolerance of the grid's (the
argument is there). The targets share every evaluated angle, and each refines where its own
objective bends, so that the union, some 60 of 180 angles on a map's sites, holds every load's
plateau finely: that shared refinement is what keeps the search's answers on the full sweep's
(measured on 40 land sites: no target more than 0.005 h short, where a search per
period, a quarter of the days for each season, evaluates some 20 % fewer days' angles and was
twice short by more than the tolerance). The near-optimal ranges are then placed on the grid from
the evaluated angles (:func:`foldopt.studies.objectives.near_optimal_on_grid`).
``tests/test_worldmap.py`` holds the answers to a full sweep of the grid on random sites, loads and
objectives.

With the base tilt (``foldopt map --optimize tilt``) the grid is the fold angle by the tilt, searched
together the same way, and the flat panel's own best tilt is searched beside it (a grid of the tilt
alone), so that the gain over flat compares each design at its own best mounting.
"""

from __future__ import annotations

import numpy as np

from foldopt.engine.evaluation import fold_orientations
from foldopt.engine.search import Axis, GridSearch, tell_together
from foldopt.names import FLAT_FOLD_ANGLE
from foldopt.studies.designs import requested_hours
from foldopt.studies.objectives import objective_quantum, period_days, period_values


class DesignSearch:
    """One site's search of a grid of designs (the fold angle, and the base tilt where a map varies
    it) for every period's objective and every load.

    Parameters
    ----------
    axes : sequence of Axis
        The grid's variables.
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

    def __init__(self, axes, months, statistic: str, seasons, tolerance_h: float, quantum: float):
        self.months, self.statistic, self.seasons = np.asarray(months), statistic, list(seasons)
        self.member = period_days(self.months, self.seasons)  # told at every level
        self.grid = GridSearch(axes, tolerance_h, quantum)
        self.found: list = []  # (points (n, axes), hours (days, n, loads), energy (days, n)) as told
        self._asked = None

    def ask(self):
        """The designs to evaluate next on every day, (n, axes) in the axes' units, or None when the
        search is done."""
        self._asked = self.grid.ask()
        return self._asked

    def objectives(self, hours, energy):
        """Keep the asked designs' daily t_solar [h], (days, n, loads), and harvested energy [Wh],
        (days, n), and give what the grid search is told: every period's and load's objective,
        (n, periods x loads)."""
        hours, energy = np.asarray(hours, dtype=float), np.asarray(energy, dtype=float)
        self.found.append((self._asked, hours, energy))
        return (
            period_values(hours, self.months, self.statistic, self.seasons, self.member)
            .transpose(1, 0, 2)
            .reshape(self._asked.shape[0], -1)
        )

    def result(self):
        """``(points (n, axes), hours (days, loads, n), energy (days, n))`` over every evaluated design,
        in ascending order of the first axis, then the next."""
        points = np.concatenate([points for points, _, _ in self.found])
        order = np.lexsort(points.T[::-1])
        # Laid out as the statistics over the days read it (a transposed view is copied again
        # by each of them).
        hours = np.ascontiguousarray(
            np.concatenate([hours for _, hours, _ in self.found], axis=1)[:, order].transpose(
                0, 2, 1
            )
        )
        energy = np.concatenate([energy for _, _, energy in self.found], axis=1)[:, order]
        return points[order], hours, energy


def search_sites(searches, evaluate) -> list:
    """Run many sites' searches together: each round, what every unfinished search asks for goes
    to ``evaluate`` in one call.

    Parameters
    ----------
    searches : sequence of DesignSearch
    evaluate : callable
        ``evaluate({site: designs})`` -> ``{site: (hours (days, n, loads), energy (days, n))}``,
        ``site`` a search's position in ``searches``.

    Returns
    -------
    list
        Each search's :meth:`DesignSearch.result`.
    """
    asked = {site: search.ask() for site, search in enumerate(searches)}
    asked = {site: designs for site, designs in asked.items() if designs is not None}
    while asked:
        told = evaluate(asked)
        # The grid searches' next levels worked out together: one pass over every site's boxes.
        tell_together(
            [searches[site].grid for site in told],
            [searches[site].objectives(hours, energy) for site, (hours, energy) in told.items()],
        )
        asked = {site: searches[site].ask() for site in asked}
        asked = {site: designs for site, designs in asked.items() if designs is not None}
    return [search.result() for search in searches]


def fold_search(months, statistic: str, seasons, tolerance_h: float, tilt: Axis | None = None):
    """The designs of a batch of a map's sites, searched (:class:`DesignSearch`, one a site), as
    :func:`foldopt.studies.designs.site_designs` takes them: the fold angle at the site's tilt, or
    with ``tilt`` the fold angle and the tilt together, and the flat panel's own best tilt beside.

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
    tilt : Axis, optional
        The base tilt's range and resolution, where the map varies it.

    Returns
    -------
    callable
        ``search(parts, sites, loads, loadset, engine)`` -> per site ``(points (n, 2) fold angle and
        tilt, hours (days, loads, n), energy (days, n), flat)``, ``flat`` the flat panel's ``(tilts
        (m,), hours (days, loads, m), energy (days, m))`` with ``tilt``, else None.
    """

    def search(parts, sites, loads, loadset, engine):
        study = parts[0][0].study
        grid = study.fold_angles
        fold_axis = Axis("fold_angle", grid.start, grid.stop, grid.step)
        step_hours = parts[0][1].step_hours
        tilts = np.concatenate([chunk.tilt for chunk, _ in parts])
        azimuth = np.concatenate([chunk.azimuth for chunk, _ in parts])
        firsts = [blocks[0] for blocks in sites]
        # At the site's tilt, each site's sub-panels at every angle of the grid, worked out once
        # for all its rounds (each design's the same bits as on its own: elementwise).
        angles = fold_axis.values()
        grid_orientations = (
            None
            if tilt is not None
            else fold_orientations(study.geometry, tilts[firsts], azimuth[firsts] % 360.0, angles)
        )

        def run(axes, flat):
            searches = [
                DesignSearch(
                    axes,
                    days,
                    statistic,
                    seasons,
                    tolerance_h,
                    objective_quantum(statistic, step_hours, len(days), days),
                )
                for days in months
            ]

            def evaluate(asked):
                requests, orientations = [], []
                for site, points in asked.items():
                    first = sites[site][0]
                    angle = np.full(points.shape[0], FLAT_FOLD_ANGLE) if flat else points[:, 0]
                    tilt_of = (
                        points[:, -1]
                        if tilt is not None
                        else np.full(points.shape[0], tilts[first])
                    )
                    requests.append(
                        (
                            np.asarray(sites[site]),
                            np.column_stack(
                                [angle, tilt_of, np.full(points.shape[0], azimuth[first])]
                            ),
                        )
                    )
                    if grid_orientations is not None:
                        orientations.append(
                            grid_orientations[site, np.searchsorted(angles, points[:, 0])]
                        )
                done = requested_hours(
                    parts,
                    requests,
                    loads,
                    loadset,
                    flat=flat,
                    engine=engine,
                    orientations=orientations or None,
                )
                return dict(zip(asked, done, strict=True))

            return search_sites(searches, evaluate)

        if tilt is None:
            return [
                (
                    np.column_stack([points[:, 0], np.full(points.shape[0], tilts[site[0]])]),
                    hours,
                    energy,
                    None,
                )
                for site, (points, hours, energy) in zip(
                    sites, run([fold_axis], False), strict=True
                )
            ]
        flats = run([tilt], True)
        return [
            (points, hours, energy, (flat_points[:, 0], flat_hours, flat_energy))
            for (points, hours, energy), (flat_points, flat_hours, flat_energy) in zip(
                run([fold_axis, tilt], False), flats, strict=True
            )
        ]

    return search
