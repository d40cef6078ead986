"""A coarse-to-fine search of a box grid for the maximum of an objective, with a bound on what it
can miss.

The designs of a panel (fold angle, base tilt, base azimuth: any of them) form a box grid, each
variable from its lower to its upper bound at its resolution (:class:`Axis`). A brute-force sweep
evaluates every point; :func:`grid_search` evaluates a coarse lattice of the grid and then, level by
level, halves the lattice's stride only inside the cells that may still hold a better point.

The argument. On a level of stride ``s_i`` grid steps along axis ``i``, the grid is cut into boxes
whose corners are lattice points, at most ``s_i`` apart (``h_i = s_i step_i`` in the variable's
units), and every corner is evaluated. Inside a box the multilinear interpolant of the corners
never exceeds the largest corner, and a function whose second derivative along axis ``i`` is at
most ``M_i`` departs from that interpolant by at most ``sum_i M_i h_i^2 / 8`` (the error of
tensor-product linear interpolation [1]_); t_solar, counted in whole time steps, also jumps by up to
``quantum``. So every grid point ``q`` of the box has

    f(q) <= max(f(corners)) + sum_i M_i h_i^2 / 8 + quantum.

A box is dropped when that bound lies at or below the best value found so far plus the
``tolerance``: it cannot hold a point better than the best by more than the tolerance, and the
best only grows. A tolerance below ``quantum`` is raised to it: the objective cannot tell designs
apart more finely than its own jumps (for one day's t_solar, one time step). At the bound, not only
below it: a plateau at the best (a landscape of zeros where no design carries the load, at polar
night) bounds each of its boxes by the best plus ``quantum``, the tolerance there, and was refined
to every grid point; now its coarse lattice ends the search. Kept boxes are halved along every
axis and their new corners evaluated; at stride 1 a box has no grid point but its corners, so
every grid point was either evaluated or lies in a dropped box. ``M_i`` is not known
in advance: each level estimates it from the second differences at the box's corners on that
level's lattice (the largest anywhere along the axis where none is evaluated), times ``safety``
(default 2). The guarantee is as good as that estimate: a peak narrower than the coarse lattice
can hide between its points. A kink between lattice points (a corner in the objective, not a bend)
leaves no trace in the second differences at them, so a box is also kept while the chords beside
it, extended over it, cross above the best plus the tolerance (:func:`_tent`): a concave objective
lies below its chords' extensions, so a kinked plateau is bounded too, whatever its curvature (on
the 1-degree land grid, a site at 65 N whose summer objective peaks at a fold angle of 2 deg,
between the lattice's 1 and 5 deg, 0.012 h above both, was missed by the curvature alone).
Conversely, on a grid of one variable a box whose lattice shows the objective concave around it
(no positive second difference at its ends and at the two lattice points either side,
:func:`_concave`) is bounded by its tent alone: a concave function lies below the tent, whatever
its curvature, so the concave corner where a load's steep flank meets its plateau, whose second
differences are large, is not refined to the last degree unless its tent reaches the best (the
same trust in the lattice as the curvature's estimate; two points a side, so that a convex kink
just outside the box shows: with one, a site's peak between the lattice's 13 and 17 deg was
missed by 0.020 h). On 650 land sites' full sweeps (50 targets each: mean, worst-month), it takes
a map's search from 62 to 56 angles a site, every target within 0.0089 h of the grid's best.
Curvature, not slope, bounds a box, so the steep flanks of the objective (t_solar against a small
fold angle) are dropped at once and only the broad plateau is refined. ``tests/test_search.py``
holds the answer to the brute-force grid on random sites, days, loads and objectives.

Every level's points go to ``evaluate`` in one call, so the caller vectorises across the points and
its own targets (loads, objectives): the search keeps the union of the cells any target keeps.

References
----------
.. [1] C. de Boor, "A Practical Guide to Splines", revised ed., Springer, 2001, Ch. II: broken-line
   interpolation errs by at most ``h^2 / 8 max|f''|`` on an interval of width ``h``; applied along
   each axis in turn, the tensor-product (multilinear) interpolant errs by at most the sum of the
   axes' terms.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from foldopt.inputs.optimize_section import grid_points

#: Points of the coarse lattice along each axis, at least (the stride is a power of two).
COARSE_POINTS = 7
#: The factor on each level's estimate of the objective's change per unit.
SAFETY = 2.0
#: Values (boxes x corners x targets x lookups) a level bounds at once: some 130 MB a lookup array.
BOX_VALUES = 1 << 24
#: A box's corners and their lattice neighbours along an axis, in strides (:func:`_box_bounds`).
_CORNER_LOOKUPS = range(-2, 3)


@dataclass(frozen=True)
class Axis:
    """One variable of the search: ``lo`` to ``hi`` by ``step``, always ending on ``hi`` (as
    :meth:`foldopt.inputs.sections.FoldAngles.grid` does).

    Parameters
    ----------
    name : str
    lo, hi, step : float
        Bounds and resolution in the variable's units; ``step > 0``, ``hi >= lo``.
    """

    name: str
    lo: float
    hi: float
    step: float

    @property
    def size(self) -> int:
        return grid_points(self.lo, self.hi, self.step)

    def values(self, index=None) -> np.ndarray:
        """The grid's values [units], all or at integer ``index``."""
        index = np.arange(self.size) if index is None else np.asarray(index)
        return np.where(index == self.size - 1, self.hi, np.round(self.lo + self.step * index, 12))


@dataclass(frozen=True)
class SearchResult:
    """What :func:`grid_search` evaluated and found.

    Attributes
    ----------
    axes : tuple of Axis
    index : numpy.ndarray of int
        (n_evaluated, n_axes) grid indices of every evaluated point, in order of evaluation.
    values : numpy.ndarray
        (n_evaluated, n_targets) the objective there.
    best : numpy.ndarray of int
        (n_targets,) row of ``index`` of each target's best point.
    levels : tuple of (int, int)
        Per level, the largest stride and the points evaluated.
    tolerance : float
        What the search may have missed above its best, in the objective's units.
    """

    axes: tuple
    index: np.ndarray
    values: np.ndarray
    best: np.ndarray
    levels: tuple
    tolerance: float = 0.0

    @property
    def points(self) -> np.ndarray:
        """(n_evaluated, n_axes) every evaluated point in the variables' units."""
        return np.stack(
            [axis.values(self.index[:, i]) for i, axis in enumerate(self.axes)], axis=-1
        )

    @property
    def best_point(self) -> np.ndarray:
        """(n_targets, n_axes) each target's best point."""
        return self.points[self.best]

    @property
    def best_value(self) -> np.ndarray:
        """(n_targets,) each target's best value."""
        return self.values[self.best, np.arange(self.best.size)]

    @property
    def grid_size(self) -> int:
        """Points of the full grid, what a brute-force sweep evaluates."""
        return int(np.prod([axis.size for axis in self.axes]))

    def with_lines(self, evaluate: Callable[[np.ndarray], np.ndarray]) -> SearchResult:
        """The search with, for each target, every grid point along each axis through its best point
        evaluated too (those not evaluated yet, as one last level): each variable's whole profile
        near the optimum, and a better point there, if any, the best.

        Parameters
        ----------
        evaluate : callable
            As :func:`grid_search`'s.

        Returns
        -------
        SearchResult
        """
        sizes = np.array([axis.size for axis in self.axes])
        lines = []
        for start in self.index[self.best]:
            for axis in np.flatnonzero(sizes > 1):
                line = np.repeat(start[None], sizes[axis], axis=0)
                line[:, axis] = np.arange(sizes[axis])
                lines.append(line)
        if not lines:
            return self
        store = _Store(sizes)
        store.add(self.index, self.values)
        new = store.missing(np.vstack(lines))
        if new.shape[0]:
            points = np.stack([axis.values(new[:, i]) for i, axis in enumerate(self.axes)], axis=-1)
            store.add(new, np.asarray(evaluate(points), dtype=float).reshape(new.shape[0], -1))
        return SearchResult(
            self.axes,
            store.index,
            store.values,
            _best_rows(store.index, store.values),
            (*self.levels, (1, int(new.shape[0]))),
            self.tolerance,
        )


def _best_rows(index, values):
    """Each target's best row; ties go to the largest indices (least folded, ...), as
    :func:`foldopt.studies.objectives.best_angle_index` breaks them on one axis."""
    order = np.lexsort(index.T[::-1])  # ascending in the first axis, then the next...
    ranked = values[order]
    last = ranked.shape[0] - 1 - np.argmax(ranked[::-1], axis=0)
    return order[last]


def grid_search(
    evaluate: Callable[[np.ndarray], np.ndarray],
    axes,
    tolerance: float,
    quantum: float = 0.0,
    safety: float = SAFETY,
    coarse_points: int = COARSE_POINTS,
    seeds=None,
) -> SearchResult:
    """The best point of a box grid for each target, coarse to fine (the module's argument).

    Parameters
    ----------
    evaluate : callable
        Maps points, (n, n_axes) in the variables' units, to the objective, (n, n_targets).
    axes : sequence of Axis
    tolerance : float
        What a dropped box may hold above the best, in the objective's units (>= 0); at least
        ``quantum`` (:attr:`SearchResult.tolerance` is the one used).
    quantum : float, default 0
        The objective's own jumps (t_solar's time step over the days it counts).
    safety : float, default :data:`SAFETY`
    coarse_points : int, default :data:`COARSE_POINTS`
    seeds : array_like, optional
        (k, n_axes) points [units] evaluated first, snapped to the grid: a known good design (the
        optimum of fewer variables) keeps the best from falling below it.

    Returns
    -------
    SearchResult
    """
    search = GridSearch(axes, tolerance, quantum, safety, coarse_points, seeds)
    while (points := search.ask()) is not None:
        search.tell(evaluate(points))
    return search.result()


class GridSearch:
    """:func:`grid_search` as a search that asks for points and is told their values, so that a
    caller can run many at once and evaluate what they all ask for together (a map's sites).

    Parameters
    ----------
    axes, tolerance, quantum, safety, coarse_points, seeds
        As :func:`grid_search`'s.
    """

    def __init__(
        self,
        axes,
        tolerance: float,
        quantum: float = 0.0,
        safety: float = SAFETY,
        coarse_points: int = COARSE_POINTS,
        seeds=None,
    ):
        self.axes = tuple(axes)
        self.tolerance = max(float(tolerance), float(quantum))
        self.quantum, self.safety = float(quantum), float(safety)
        self.sizes = np.array([axis.size for axis in self.axes])
        self.steps = np.array([axis.step for axis in self.axes])
        self.strides = np.array(
            [
                1 << max(0, int(math.floor(math.log2(max(1.0, (n - 1) / (coarse_points - 1))))))
                for n in self.sizes
            ]
        )
        self.store = _Store(self.sizes)
        # The coarse lattice, each axis's last grid point included so the bounds are evaluated.
        lattice = [
            np.union1d(np.arange(0, n, s), [n - 1])
            for n, s in zip(self.sizes, self.strides, strict=True)
        ]
        first = np.stack(np.meshgrid(*lattice, indexing="ij"), axis=-1).reshape(-1, len(self.axes))
        if seeds is not None:
            snapped = np.stack(
                [
                    np.clip(
                        np.rint((np.asarray(seeds, float)[:, i] - a.lo) / a.step), 0, a.size - 1
                    )
                    for i, a in enumerate(self.axes)
                ],
                axis=-1,
            ).astype(int)
            first = np.vstack([first, snapped])
        # Boxes by their lower and upper corners: consecutive lattice points along every axis.
        edges = [
            (points[:-1], points[1:]) if points.size > 1 else (points, points) for points in lattice
        ]
        self.lower, self.upper = (
            np.stack(np.meshgrid(*ends, indexing="ij"), axis=-1).reshape(-1, len(self.axes))
            for ends in zip(*edges, strict=True)
        )
        self.levels: list = []
        self._asked = self.store.missing(first)

    def ask(self):
        """The points [units] to evaluate next, (n, n_axes), or None when the search is done."""
        while self._asked is not None and self._asked.shape[0] == 0:
            self._advance()
        if self._asked is None:
            return None
        return np.stack(
            [axis.values(self._asked[:, i]) for i, axis in enumerate(self.axes)], axis=-1
        )

    def tell(self, values) -> None:
        """The values of the points :meth:`ask` gave, (n, n_targets)."""
        tell_together([self], [values])

    def _advance(self) -> None:
        """The next level's new corners, or None once the last level's are known."""
        _advance_together([self])

    def result(self) -> SearchResult:
        """What the search evaluated and found (once :meth:`ask` gives None)."""
        store = self.store
        return SearchResult(
            self.axes,
            store.index,
            store.values,
            _best_rows(store.index, store.values),
            tuple(self.levels),
            self.tolerance,
        )


def tell_together(searches, values) -> None:
    """:meth:`GridSearch.tell` of many searches (a map's sites), each told the values of the points
    it asked for, (n, n_targets), and their next levels worked out together
    (:func:`_advance_together`).

    Parameters
    ----------
    searches : sequence of GridSearch
    values : sequence of array_like
        Each search's values.
    """
    for search, found in zip(searches, values, strict=True):
        search.store.add(
            search._asked, np.asarray(found, dtype=float).reshape(search._asked.shape[0], -1)
        )
    _advance_together(searches)


def _advance_together(searches) -> None:
    """Each search's next level's new corners, or None once its last level's are known. The boxes
    of searches of one grid, level and number of targets are bounded in one pass, as the boxes of
    one search over a grid with the search as one more axis, along which no box extends: every
    box's bound the bits its own search's would be (each value's operations are its own, and
    where an axis's largest second difference stands in, it is its own search's)."""
    groups: dict = {}
    for search in searches:
        search.levels.append((int(search.strides.max()), int(search._asked.shape[0])))
        if search.strides.max() <= 1:
            search._asked = None
            continue
        key = (
            tuple(search.sizes),
            tuple(search.steps),
            tuple(search.strides),
            search.safety,
            search.store.values.shape[1],
        )
        groups.setdefault(key, []).append(search)
    for group in groups.values():
        first = group[0]
        own = np.concatenate([np.full(search.lower.shape[0], k) for k, search in enumerate(group)])
        store = _Store(np.array([len(group), *first.sizes]))
        store.add(
            np.concatenate(
                [
                    np.column_stack([np.full(search.store.index.shape[0], k), search.store.index])
                    for k, search in enumerate(group)
                ]
            ),
            np.concatenate([search.store.values for search in group]),
        )
        lower, upper = (
            np.column_stack([own, np.concatenate([getattr(search, end) for search in group])])
            for end in ("lower", "upper")
        )
        bound = _box_bounds(
            store,
            lower,
            upper,
            np.array([0, *first.strides]),
            np.array([0.0, *first.steps]),
            np.array([1, *first.sizes]),
            first.safety,
            own,
        )
        for k, search in enumerate(group):
            mine = own == k
            keep = np.any(
                bound[mine] + search.quantum > search.store.best_values() + search.tolerance,
                axis=1,
            )
            search.strides = np.maximum(search.strides // 2, 1)
            search.lower, search.upper = _split(
                search.lower[keep], search.upper[keep], search.strides
            )
            corners = _corners(search.lower, search.upper)
            search._asked = search.store.missing(corners.reshape(-1, len(search.axes)))


class _Store:
    """The evaluated points by grid index, looked up by their flat key."""

    def __init__(self, sizes):
        self.sizes = sizes
        self.index = np.zeros((0, len(sizes)), dtype=int)
        self.values = None
        self.keys = np.zeros(0, dtype=np.int64)

    def missing(self, index):
        """The points of ``index`` not evaluated yet, once each."""
        keys = np.ravel_multi_index(index.T, self.sizes)
        keys, first = np.unique(keys, return_index=True)
        if self.keys.size == 0:
            return index[first]
        at = np.clip(np.searchsorted(self._sorted, keys), 0, self.keys.size - 1)
        return index[first[self._sorted[at] != keys]]

    def add(self, index, found):
        """The values ``found`` (n, n_targets) of the points ``index`` (n, n_axes), new ones."""
        if index.shape[0] == 0:
            return
        keys = np.ravel_multi_index(index.T, self.sizes)
        self.index = np.vstack([self.index, index])
        self.values = found if self.values is None else np.vstack([self.values, found])
        self.keys = np.concatenate([self.keys, keys])
        self._order = np.argsort(self.keys)
        self._sorted = self.keys[self._order]

    def lookup(self, index):
        """(n, n_targets) the values at ``index`` (NaN where not evaluated or outside the grid)."""
        inside = np.all((index >= 0) & (index < self.sizes), axis=-1)
        keys = np.ravel_multi_index(
            np.where(inside[..., None], index, 0).reshape(-1, len(self.sizes)).T, self.sizes
        )
        at = np.clip(np.searchsorted(self._sorted, keys), 0, self.keys.size - 1)
        found = inside.ravel() & (self._sorted[at] == keys)
        values = np.full((keys.size, self.values.shape[1]), np.nan)
        values[found] = self.values[self._order[at[found]]]
        return values.reshape(*index.shape[:-1], self.values.shape[1])

    def best_values(self):
        return np.nanmax(self.values, axis=0)


def _corners(lower, upper):
    """(n_boxes, 2^n_axes, n_axes) every corner of each box."""
    picks = np.stack(np.meshgrid(*[np.arange(2)] * lower.shape[1], indexing="ij"), axis=-1).reshape(
        -1, lower.shape[1]
    )
    return np.where(picks[None].astype(bool), upper[:, None, :], lower[:, None, :])


def _box_bounds(store, lower, upper, strides, steps, sizes, safety, group=None):
    """(n_boxes, n_targets) what a box may hold at most: its largest corner plus ``safety`` times
    the multilinear interpolant's error bound, ``sum_i M_i h_i^2 / 8`` (``h_i`` the box's width).
    ``M_i`` is the largest second difference per unit^2 along axis ``i`` at the box's corners, on
    the lattice of ``strides``; where none is evaluated there (a neighbour dropped, an axis of two
    points), the axis's largest second difference anywhere (in the box's ``group``, (n_boxes,)
    int, where given: its search's, :func:`_advance_together`) stands in. On a grid of one
    variable, a box where the lattice shows the objective concave (:func:`_concave`) is bounded
    by its tent alone. The boxes go a batch at a time (:data:`BOX_VALUES`): their corners and
    neighbours are looked up per target, and 100,000 boxes of 40 loads held 5.5 GB at once."""
    n_targets = store.values.shape[1]
    per = max(1, BOX_VALUES // (len(_CORNER_LOOKUPS) * 2 ** lower.shape[1] * n_targets))
    # one batch of none where none is left
    batches = [
        _box_terms(
            store, lower[first : first + per], upper[first : first + per], strides, steps, sizes
        )
        for first in range(0, max(lower.shape[0], 1), per)
    ]
    terms = list(zip(*batches, strict=True))
    top, error, tent, concave = (np.concatenate(terms[k]) for k in (0, 1, 4, 5))
    unknown, width, curvature = (np.concatenate(terms[k], axis=1) for k in (2, 3, 6))
    group = np.zeros(lower.shape[0], dtype=int) if group is None else group
    # (n_axes, n_groups, n_targets), -inf where none is known anywhere in the group
    largest = np.full((lower.shape[1], group.max(initial=0) + 1, top.shape[1]), -np.inf)
    for axis, axis_curvature in enumerate(curvature):
        np.maximum.at(largest[axis], group, axis_curvature)
    for axis, axis_largest in enumerate(np.maximum(largest, 0.0)):
        error += (
            np.where(unknown[axis], axis_largest[group], 0.0) * (width[axis] ** 2 / 8.0)[:, None]
        )
    return np.where(concave, np.maximum(top, tent), np.maximum(top + safety * error, tent))


def _box_terms(store, lower, upper, strides, steps, sizes):
    """The parts of :func:`_box_bounds` of a batch of boxes: the largest corner, the error term of
    the axes with a second difference known at the box, per axis where none is (n_axes, n_boxes,
    n_targets, bool) and the box's width (n_axes, n_boxes), the tent, whether concave, and per axis
    the box's largest second difference (n_axes, n_boxes, n_targets; -inf where none is known)."""
    corners = _corners(lower, upper)
    top = np.nanmax(store.lookup(corners), axis=1)
    n_axes = lower.shape[1]
    error = np.zeros_like(top)
    unknown = np.zeros((n_axes, *top.shape), bool)
    widths = np.zeros((n_axes, top.shape[0]))
    largest = np.full((n_axes, *top.shape), -np.inf)
    tent = np.full(top.shape, -np.inf)
    concave = np.zeros(top.shape, bool)
    for axis in range(n_axes):
        if sizes[axis] == 1:
            continue
        shift = np.zeros(n_axes, dtype=int)
        shift[axis] = strides[axis]
        # The corners and their lattice neighbours along the axis, looked up in one call.
        offsets = np.array(_CORNER_LOOKUPS)[:, None, None, None] * shift  # (5, 1, 1, n_axes)
        beyond_below, below, here, above, beyond_above = store.lookup(corners[None] + offsets)
        # (boxes, corners, targets)
        second = np.abs(above - 2.0 * here + below) / (strides[axis] * steps[axis]) ** 2
        known = np.isfinite(second)
        curvature = np.max(np.where(known, second, -np.inf), axis=1)  # (boxes, targets)
        largest[axis] = curvature
        unknown[axis] = ~known.any(axis=1)
        widths[axis] = (upper[:, axis] - lower[:, axis]) * steps[axis]
        error += (
            np.where(unknown[axis], 0.0, np.maximum(curvature, 0.0))
            * (widths[axis] ** 2 / 8.0)[:, None]
        )
        # The box's edges along the axis: each from a corner with the axis's lower end to the one
        # with its upper end (the corners' order is _corners', the axis's bit 1 << n_axes-1-axis).
        low = np.flatnonzero((np.arange(corners.shape[1]) >> (n_axes - 1 - axis)) & 1 == 0)
        high = low + (1 << (n_axes - 1 - axis))
        tent = np.maximum(
            tent,
            _tent(
                below[:, low],
                here[:, low],
                here[:, high],
                above[:, high],
                strides[axis] * steps[axis],
                widths[axis][:, None, None],
            ).max(axis=1),
        )
        if np.count_nonzero(sizes > 1) == 1:
            # Equally spaced: the grid's last box, narrower than the stride, has its neighbour above off the grid.
            concave = _concave(
                beyond_below[:, 0],
                below[:, 0],
                here[:, 0],
                here[:, 1],
                above[:, 1],
                beyond_above[:, 1],
            )
    return top, error, unknown, widths, tent, concave, largest


def _concave(*values):
    """Whether a lattice's consecutive values (each (n_boxes, n_targets)), an edge's two ends and two
    points either side, have no positive second difference: the objective taken as concave over
    them. Two points a side, so that a convex kink just outside the edge (a load's steep flank
    turning up into a narrow peak) shows."""
    values = np.stack(values)
    second = values[2:] - 2.0 * values[1:-1] + values[:-2]
    # NaN (a point not evaluated or off the grid) compares False
    return np.all(second <= 0.0, axis=0)


def _tent(before, start, end, after, spacing, width):
    """The largest a concave function can be on an edge from ``start`` to ``end`` (``width`` apart),
    given its values a lattice ``spacing`` before the start and after the end: the lowest of the two
    neighbouring chords extended over the edge (a concave function lies below its chords' extensions),
    one where only one is known, -inf where neither is.

    A peak between two lattice points leaves no trace in the second differences at them, but it does
    in the chords beside it: the bound holds where the objective is concave near the edge (its
    plateau, where the search's answer is), whatever its curvature."""
    rising = (start - before) / spacing  # the chord before the edge, extended forward
    falling = (after - end) / spacing  # the chord after it, extended backward
    with np.errstate(invalid="ignore", divide="ignore"):
        # Where the two extensions cross inside the edge, the bound is their crossing, else an end's.
        cross = np.clip((end - start - falling * width) / (rising - falling), 0.0, width)
    cross = np.where(np.isfinite(cross), cross, 0.0)
    candidates = []
    for at in (np.zeros_like(cross), cross, np.broadcast_to(width, cross.shape)):
        forward = start + rising * at
        backward = end + falling * (at - width)
        candidates.append(np.fmin(forward, backward))  # fmin: one chord where the other is unknown
    bound = np.max(candidates, axis=0)
    return np.where(np.isnan(bound), -np.inf, bound)


def _split(lower, upper, strides):
    """Each box halved along every axis longer than the new ``strides``."""
    for axis, stride in enumerate(strides):
        middle = lower[:, axis] + stride
        split = middle < upper[:, axis]
        low_half_upper = upper.copy()
        low_half_upper[split, axis] = middle[split]
        high_lower = lower[split].copy()
        high_lower[:, axis] = middle[split]
        lower = np.vstack([lower, high_lower])
        upper = np.vstack([low_half_upper, upper[split]])
    return lower, upper
