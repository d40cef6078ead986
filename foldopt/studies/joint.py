"""The joint optimisation of a twofold panel: its fold angle, base tilt and base azimuth together.

A designer chooses all three when mounting a device, and for a storage-less load the best tilt of a
folded panel is not the best tilt of a flat one. :func:`optimize_plan` takes a study (its site,
days, loads, objective and models) with an ``optimize`` section (:class:`foldopt.inputs.optimize_section.Optimize`)
and finds, per load, the design that maximises the study's objective over its days, by the
coarse-to-fine search of :func:`foldopt.engine.search.grid_search` on the grid of the varied
variables. Alongside, for a fair comparison, the flat panel's own best tilt and azimuth (the same
search without the fold), and the default mounting (tilt ``|latitude|``, facing the equator, or the
study's panel) with its best fold angle on the study's grid, the flat panel and the tracker there
(:func:`foldopt.studies.designs.daily_designs`, which every study shares). The optimum, the flat
panel's own best and each variable's step are the best design evaluated within their ranges, by any
of these searches: a 180 deg fold is the flat panel, so the flat panel's own best is never beaten by
an unfolded design the twofold search found, nor the optimum by one the flat search found.

What each variable adds is the objective gained as the variables join the search in the order of
:data:`foldopt.names.OPTIMIZE_VARIABLES`: the fold angle alone at the default mounting, then with
the tilt, then with the azimuth. The near-optimal region of each variable is every value at which
some evaluated design comes within the study's near-optimal tolerance of the optimum
(:func:`foldopt.studies.objectives.near_optimal` on the profile, the best over the other variables):
the designs the search evaluated and the variable's whole grid with the others at the optimum,
so its edges are on the grid (or at the optimum, where that is a default mounting off it) and never
narrower than at the optimum's own mounting. The landscape
is the objective over tilt x fold angle at the optimum's azimuth, on a grid of its own.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from foldopt import names
from foldopt.engine.search import Axis, SearchResult, grid_search
from foldopt.errors import ConfigError
from foldopt.inputs.optimize_section import DEFAULT_TILT, MAX_DESIGNS
from foldopt.inputs.plan import Plan
from foldopt.inputs.study import Study
from foldopt.studies.designs import Blocks, daily_designs, design_hours
from foldopt.names import DEFAULT_ENGINE, FLAT_FOLD_ANGLE
from foldopt.physics.spa import SunTerms
from foldopt.studies.objectives import (
    best_angle_index,
    near_optimal,
    objective_quantum,
    objective_value,
    season_days,
)

#: Points of the landscape's grid along the fold angle and the tilt.
LANDSCAPE_POINTS = (46, 31)


@dataclass(frozen=True)
class OptimizeResult:
    """A joint optimisation (:func:`optimize_plan`).

    Attributes
    ----------
    study : Study
        The study (resolved): its panel is the default mounting.
    dates : tuple of datetime.date
    loads : numpy.ndarray
        (n_loads,) [W].
    twofold, flat : SearchResult
        The searches over the varied variables (targets: the loads); the flat panel's over the
        varied tilt and azimuth (none: its default mounting alone).
    steps : tuple of (str, SearchResult)
        The searches as the variables join (the last is ``twofold``).
    table : pandas.DataFrame
        Per load and design (``twofold``, ``flat``, ``twofold-default``, ``flat-default``,
        ``tracker``, ``tracker-net``): ``fold_angle_deg``, ``surface_tilt``, ``surface_azimuth``,
        ``t_solar_objective_h`` and
        ``gain_vs_flat_pct`` (over the flat panel at its own best); ``twofold`` and ``flat`` are the
        best designs evaluated within their ranges (:func:`_best_within`).
    near_optimal : pandas.DataFrame
        Per load and variable: ``near_optimal_lo_deg``, ``near_optimal_hi_deg``, ``recommended_deg``,
        ``near_optimal_tolerance_h``.
    added : pandas.DataFrame
        Per load and variable: the objective once it joined the search and what that added [h],
        with the designs evaluated and the grid's.
    landscape : pandas.DataFrame
        The first load's objective over ``fold_angle_deg`` x ``surface_tilt`` at the optimum's azimuth.
    request : object, optional
    engine : str
        The engine the designs were evaluated by (``numba`` or ``numpy``).
    """

    study: Study
    dates: tuple
    loads: np.ndarray
    statistic: str
    twofold: SearchResult
    flat: SearchResult
    steps: tuple
    table: pd.DataFrame
    near_optimal: pd.DataFrame
    added: pd.DataFrame
    landscape: pd.DataFrame
    request: object = None
    engine: str = "numba"

    @functools.cached_property
    def answer(self):
        """The :class:`foldopt.studies.answer.Answer` every view of this result renders."""
        from foldopt.studies.optimize_answer import of_optimize

        return of_optimize(self)


def _axes(study: Study, vary, fold_angle: float = FLAT_FOLD_ANGLE) -> dict[str, Axis]:
    """The search's axes by variable; a variable not varied is a one-point axis at the default
    mounting (the study's panel, folded to ``fold_angle``)."""
    spec = study.optimize
    fixed = {"fold_angle": fold_angle, "tilt": study.panel.tilt, "azimuth": study.panel.azimuth}
    axes = {}
    for name in names.OPTIMIZE_VARIABLES:
        lo, hi, step = spec.searched_range(name, study.fold_angles, study.panel.azimuth)
        axes[name] = (
            Axis(name, lo, hi, step) if name in vary else Axis(name, fixed[name], fixed[name], 1.0)
        )
    return axes


def optimize_plan(plan: Plan, engine: str = DEFAULT_ENGINE, request=None) -> OptimizeResult:
    """The best fold angle, tilt and azimuth of a study's panel, and the flat panel's own best.

    Parameters
    ----------
    plan : Plan
        A study with an ``optimize`` section; its axes may be ``date`` (the days the objective
        is taken over) and ``p_load`` (the loads), no other.
    engine : {'auto', 'numba', 'numpy'}
    request : foldopt.studies.request.Request, optional

    Returns
    -------
    OptimizeResult

    Raises
    ------
    foldopt.ConfigError
        For other axes, a cloud ensemble, a season (``objective.months``) none of the days is in, or
        more designs x loads than :data:`foldopt.inputs.optimize_section.MAX_DESIGNS`.
    """
    study = plan.base
    spec = study.optimize
    axes = dict(plan.axes)
    other = [path for path in axes if path not in ("date", "p_load")]
    if other:
        raise ConfigError(
            [
                f"optimize: one site and setup over its days and loads; {', '.join(other)} vary (run "
                f"one study each)"
            ]
        )
    if study.weather is not None and study.weather.members:
        raise ConfigError(
            [
                "optimize: a cloud ensemble (weather.members) is not searched; leave out weather.members"
            ]
        )
    dates = tuple(axes.get("date", (study.date,)))
    loads = np.asarray(axes.get("p_load", (study.p_load,)), dtype=float)
    # The search holds, and evaluated.csv writes, each evaluated design's objective per load.
    designs = math.prod(axis.size for axis in _axes(study, spec.vary).values())
    if designs * loads.size > MAX_DESIGNS:
        raise ConfigError(
            [
                f"p_load: {loads.size:,} loads x {designs:,} designs = {designs * loads.size:.2g} to "
                f"search; the limit is {MAX_DESIGNS:,} (fewer loads, coarser steps, or "
                f"FOLDOPT_MAX_DESIGNS)"
            ]
        )
    statistic = study.objective.statistic if study.objective is not None else "mean"
    season = study.objective.months if study.objective is not None else None
    months = np.array([date.month for date in dates])
    counted = months[season_days(months, season)]  # the days the objective takes
    blocks = Blocks.of_dates(study, dates)
    study = blocks.study
    sun_terms = SunTerms()  # the chunks' skies share SPA's time-only terms
    parts = [(blocks[part], blocks[part].sky(sun_terms)) for part in blocks.chunks(loads.size)]
    quantum = objective_quantum(statistic, parts[0][1].step_hours, counted.size, counted)

    def objective(flat):
        def evaluate(points):
            return objective_value(
                design_hours(parts, points, loads, flat, engine), months, statistic, season
            )

        return evaluate

    days_of = daily_designs(parts, loads, engine)
    default = {
        # (loads, angles)
        "twofold-default": objective_value(days_of.twofold_h, months, statistic, season),
        "flat-default": objective_value(days_of.flat_h, months, statistic, season),
        "tracker": objective_value(days_of.tracker_h, months, statistic, season),
        # net of its own draw (standby, drive): what the study's tracker section sets
        "tracker-net": objective_value(days_of.tracker_net_h, months, statistic, season),
    }
    best_default = best_angle_index(default["twofold-default"])
    # A fold angle that does not vary stays at the default mounting's best (the first load's).
    fold_angle = float(days_of.angles[best_default[0]])
    vary = [name for name in names.OPTIMIZE_VARIABLES if name in spec.vary]
    all_axes = _axes(study, vary, fold_angle)
    # Each search starts from the one before's optimum, so a variable that joins never loses.
    steps, seeds = (
        [],
        [[days_of.angles[best], study.panel.tilt, study.panel.azimuth] for best in best_default],
    )
    for count in range(1, len(vary) + 1):
        search = grid_search(
            objective(False),
            list(_axes(study, vary[:count], fold_angle).values()),
            spec.tolerance_h,
            quantum,
            seeds=seeds,
        )
        steps.append((vary[count - 1], search))
        seeds = search.best_point
    flat_axes = _axes(study, [name for name in vary if name != "fold_angle"])
    flat = grid_search(
        objective(True),
        list(flat_axes.values()),
        spec.tolerance_h,
        quantum,
        seeds=[[FLAT_FOLD_ANGLE, study.panel.tilt, study.panel.azimuth]],
    )
    # Each variable's near-optimal region walks its whole grid through the optimum.
    twofold = steps[-1][1].with_lines(objective(False))
    steps[-1] = (steps[-1][0], twofold)
    mounting = [study.panel.tilt, study.panel.azimuth]
    # Every design evaluated: the searches' and the default mounting's, folded and flat.
    evaluated = _designs(
        [(search.points, search.values) for _, search in steps]
        + [
            (flat.points, flat.values),
            (
                np.column_stack([days_of.angles, np.tile(mounting, (days_of.angles.size, 1))]),
                default["twofold-default"].T,
            ),
            (np.array([[FLAT_FOLD_ANGLE, *mounting]]), default["flat-default"][None]),
        ]
    )
    # The optimum, the flat panel's own best and each step's: the best design evaluated within each
    # one's ranges, so that none is beaten by a design the answer holds. A 180 deg fold is the flat
    # panel: the flat search's designs are the twofold panel's where its fold angles reach 180 deg,
    # and the twofold search's at 180 deg are the flat panel's.
    optimum = _best_within(*evaluated, list(twofold.axes))
    table = _table(
        study,
        loads,
        optimum,
        _best_within(*evaluated, list(flat_axes.values())),
        days_of.angles,
        best_default,
        default,
    )
    near = _near_optimal(study, loads, twofold, optimum)
    # What the first variable adds is over the default mounting as it stands: flat where the fold
    # angle joins the search, else folded to the fixed angle (the tilt alone took the fold's gain).
    start = (
        default["flat-default"]
        if "fold_angle" in vary
        else default["twofold-default"][:, best_default[0]]
    )
    added = _added(
        loads,
        [(name, search, _best_within(*evaluated, list(search.axes))[1]) for name, search in steps],
        start,
    )
    landscape = _landscape(
        parts,
        study,
        all_axes,
        optimum[0][0],
        loads[:1],
        months=months,
        statistic=statistic,
        season=season,
        engine=engine,
    )
    return OptimizeResult(
        study,
        dates,
        loads,
        statistic,
        twofold,
        flat,
        tuple(steps),
        table,
        near,
        added,
        landscape,
        request,
        engine,
    )


def _designs(evaluated) -> tuple:
    """``(points (n, 3) [deg], values (n, n_targets))`` of the designs ``evaluated``, a sequence of
    such pairs, together (a design evaluated twice, by two searches, is there twice)."""
    return (
        np.vstack([np.asarray(points, dtype=float) for points, _ in evaluated]),
        np.vstack([np.asarray(values, dtype=float) for _, values in evaluated]),
    )


def _best_within(points, values, axes) -> tuple:
    """Per target, the best of the designs ``points`` (n, 3) [deg], of ``values`` (n, n_targets),
    that lie within the ranges of ``axes`` (a variable not varied at its value; an azimuth modulo
    360 deg); ties to the least folded, then the steepest, then the largest azimuth, as
    :class:`SearchResult` breaks them.

    Returns
    -------
    point : numpy.ndarray
        (n_targets, 3) fold angle, tilt and azimuth [deg].
    value : numpy.ndarray
        (n_targets,) [h].
    """
    inside = np.ones(points.shape[0], bool)
    for column, axis in enumerate(axes):
        offset = points[:, column] - axis.lo + 1e-9
        if axis.name == "azimuth":
            offset %= 360.0
        inside &= (offset >= 0.0) & (offset <= axis.hi - axis.lo + 2e-9)
    order = np.flatnonzero(inside)[np.lexsort(points[inside].T[::-1])]
    ranked = values[order]
    best = order[ranked.shape[0] - 1 - np.argmax(ranked[::-1], axis=0)]
    return points[best], values[best, np.arange(values.shape[1])]


def _table(study, loads, optimum, flat, fold_angles, best_default, default) -> pd.DataFrame:
    rows = []
    flat_point, flat_best = flat
    for index, load in enumerate(loads):
        designs = [
            ("twofold", *optimum[0][index], optimum[1][index]),
            ("flat", FLAT_FOLD_ANGLE, *flat_point[index][1:], flat_best[index]),
            (
                "twofold-default",
                fold_angles[best_default[index]],
                study.panel.tilt,
                study.panel.azimuth,
                default["twofold-default"][index, best_default[index]],
            ),
            (
                "flat-default",
                FLAT_FOLD_ANGLE,
                study.panel.tilt,
                study.panel.azimuth,
                default["flat-default"][index],
            ),
            ("tracker", np.nan, np.nan, np.nan, default["tracker"][index]),
            ("tracker-net", np.nan, np.nan, np.nan, default["tracker-net"][index]),
        ]
        for design, fold, tilt, azimuth, value in designs:
            rows.append(
                {
                    "p_load_w": load,
                    "design": design,
                    "fold_angle_deg": fold,
                    "surface_tilt": tilt,
                    "surface_azimuth": azimuth % 360.0,
                    "t_solar_objective_h": value,
                    "gain_vs_flat_pct": 100.0 * (value / flat_best[index] - 1.0)
                    if flat_best[index] > 0
                    else np.nan,
                }
            )
    return pd.DataFrame(rows)


def _near_optimal(study, loads, search: SearchResult, optimum) -> pd.DataFrame:
    """Per load and varied variable, the range of values within the near-optimal tolerance, on the
    profile of the best design evaluated at each value: the search's, which holds every value of each
    variable with the others at each load's optimum (:meth:`SearchResult.with_lines`), and the
    optimum ``(points, values)`` itself where it lies off the grid (a default mounting), so that
    every range holds it. The search alone refines only where the optimum may be: its sparse
    profile, interpolated, gave a fold angle of 29 to 31 deg where the optimum's own azimuth and
    tilt keep 29 to 60 deg near-optimal."""
    rows = []
    points, values = search.points, search.values
    for axis_index, axis in enumerate(search.axes):
        if axis.size == 1:
            continue
        for index, load in enumerate(loads):
            grid = np.union1d(axis.values(), optimum[0][index, axis_index])
            profile = np.full(grid.size, -np.inf)
            position = np.searchsorted(grid, points[:, axis_index] - 1e-9)
            np.maximum.at(profile, position, values[:, index])
            at = np.searchsorted(grid, optimum[0][index, axis_index] - 1e-9)
            profile[at] = max(profile[at], optimum[1][index])
            ranges = near_optimal(grid, profile, study.near_optimal, fold=axis.name == "fold_angle")
            rows.append(
                {
                    "p_load_w": load,
                    "variable": axis.name,
                    "near_optimal_lo_deg": float(ranges["near_optimal_lo_deg"]),
                    "near_optimal_hi_deg": float(ranges["near_optimal_hi_deg"]),
                    "recommended_deg": float(ranges["recommended_deg"]),
                    "near_optimal_tolerance_h": float(ranges["near_optimal_tolerance_h"]),
                }
            )
    return pd.DataFrame(rows)


def _added(loads, steps, start) -> pd.DataFrame:
    """What each variable adds as it joins the search, over ``start`` (per load, the default
    mounting's objective before any joins): the fold angle, then the tilt, then the azimuth [h].
    ``steps`` holds per variable its search and its objective [h], (n_loads,): the best design
    evaluated within the search's ranges."""
    rows, before = [], np.asarray(start, dtype=float)
    for name, search, value in steps:
        for index, load in enumerate(loads):
            rows.append(
                {
                    "p_load_w": load,
                    "variable": name,
                    "t_solar_objective_h": value[index],
                    "added_h": value[index] - before[index],
                    "designs_evaluated_n": search.index.shape[0],
                    "designs_grid_n": search.grid_size,
                }
            )
        before = value
    return pd.DataFrame(rows)


def _landscape(
    parts, study, axes, best, loads, *, months, statistic, season, engine
) -> pd.DataFrame:
    """The objective over fold angle x tilt at the optimum's azimuth, on :data:`LANDSCAPE_POINTS`
    (the objective of ``statistic`` over the days' ``months`` in ``season``)."""
    fold_axis = (
        axes["fold_angle"]
        if axes["fold_angle"].size > 1
        else _axes(study, ["fold_angle"])["fold_angle"]
    )
    tilt_axis = axes["tilt"] if axes["tilt"].size > 1 else Axis("tilt", *DEFAULT_TILT)
    folds = np.linspace(fold_axis.lo, fold_axis.hi, LANDSCAPE_POINTS[0])
    tilts = np.linspace(tilt_axis.lo, tilt_axis.hi, LANDSCAPE_POINTS[1])
    fold, tilt = (grid.ravel() for grid in np.meshgrid(folds, tilts, indexing="ij"))
    points = np.stack([fold, tilt, np.full(fold.size, best[2])], axis=-1)
    value = objective_value(
        design_hours(parts, points, loads, False, engine), months, statistic, season
    )[:, 0]
    return pd.DataFrame(
        {
            "fold_angle_deg": fold,
            "surface_tilt": tilt,
            "surface_azimuth": best[2] % 360.0,
            "t_solar_objective_h": value,
        }
    )
