"""What a fold angle is chosen by: the longest t_solar on a grid of angles (:func:`best_angle_index`),
a statistic of daily t_solar over the days of a study (:func:`objective_value`, :func:`worst_month`),
the plateau of near-optimal angles around the best (:func:`near_optimal`), and over a cloud
ensemble, the members' spread and how sure the choice is (:func:`ensemble_choice`).

The module may import numpy, scipy, :mod:`foldopt.inputs.sections` and :mod:`foldopt.engine.curve_reduction`.
"""

from __future__ import annotations

import math

import numpy as np

from foldopt.inputs.sections import NearOptimal
from foldopt.names import FLAT_FOLD_ANGLE


def best_angle_index(hours):
    """Index (...) of the longest t_solar along the last axis; ties go to the least folded angle.

    Parameters
    ----------
    hours : numpy.ndarray
        t_solar [h] on an ascending fold-angle grid, (..., n_angles).
    """
    return hours.shape[-1] - 1 - np.argmax(hours[..., ::-1], axis=-1)


def season_days(months, season=None) -> np.ndarray:
    """(days,) bool: the days whose month is in ``season`` (every day for None or no months).

    Parameters
    ----------
    months : array_like of int
        (days,) month of each day [1-12].
    season : sequence of int, optional
        Months [1-12].
    """
    months = np.asarray(months)
    if not season:
        return np.ones(months.shape, bool)
    # A table of the twelve months rather than np.isin, which costs a map's search a sort per call.
    table = np.zeros(13, bool)
    table[list(season)] = True
    return table[months]


def period_days(months, seasons) -> np.ndarray:
    """(periods, days) bool: each period's days (:func:`season_days` of each of ``seasons``).

    Parameters
    ----------
    months : array_like of int
        (days,) month of each day [1-12].
    seasons : sequence
        Each period's months (None: every day).
    """
    return np.stack([season_days(months, season) for season in seasons])


def objective_value(hours, months, statistic: str, season=None):
    """A study-wide statistic of daily t_solar: ``hours`` (days, ...) -> (...).

    Parameters
    ----------
    hours : array_like
        Daily t_solar [h], (days, ...).
    months : array_like
        (days,) month of each day [1-12].
    statistic : str
        ``mean``, ``min``, ``pNN`` (the NN-th percentile over days) or ``worst-month`` (the lowest
        monthly mean).
    season : sequence of int, optional
        Months that restrict the days.

    Returns
    -------
    numpy.ndarray
        The statistic [h], (...).
    """
    hours, months = np.asarray(hours, dtype=float), np.asarray(months)
    if season:
        keep = season_days(months, season)
        hours, months = hours[keep], months[keep]
    if statistic == "mean":
        return hours.mean(axis=0)
    if statistic == "min":
        return hours.min(axis=0)
    if statistic == "worst-month":
        return np.min([hours[months == m].mean(axis=0) for m in np.unique(months)], axis=0)
    return np.percentile(hours, float(statistic[1:]), axis=0)


def period_values(hours, months, statistic: str, seasons, member=None):
    """:func:`objective_value` of ``hours`` (days, ...) over several periods, (periods, ...).

    Each value is its own period's reduction over its days alone, so that it is the same bits
    whatever else the array holds (other sites, loads, angles): a map's answers do not depend on
    how its sites were batched.

    Parameters
    ----------
    hours : array_like
        Daily t_solar [h], (days, ...).
    months : array_like
        (days,) month of each day [1-12].
    statistic : str
        :func:`objective_value`'s.
    seasons : sequence
        Each period's months (None: every day).
    member : numpy.ndarray, optional
        (periods, days) bool, each period's days (:func:`period_days`), where the caller has them
        (a search asks at every level for the same days).
    """
    hours, months = np.asarray(hours, dtype=float), np.asarray(months)
    if (
        statistic not in ("mean", "worst-month")
        or math.prod(hours.shape[1:]) < 2
        or hours.shape[0] == 0
    ):
        # One value a day: NumPy sums it pairwise, not in the days' order (and no day: its NaN or error).
        return np.stack([objective_value(hours, months, statistic, season) for season in seasons])
    # The same bits as objective_value's, the means summed in one pass over the days (no copy of a
    # period's days): a period's mean, or the lowest of its months' means (a season keeps whole months).
    from foldopt.engine.curve_reduction import period_means  # compiled (numba)

    flat = np.ascontiguousarray(hours.reshape(hours.shape[0], -1))
    if statistic == "mean":
        value = period_means(flat, period_days(months, seasons) if member is None else member)
    else:
        present = np.unique(months)
        monthly = period_means(flat, months[None, :] == present[:, None])
        value = np.stack([monthly[season_days(present, season)].min(axis=0) for season in seasons])
    return value.reshape((len(seasons),) + hours.shape[1:])


def objective_quantum(statistic: str, step_hours: float, n_days: int, months) -> float:
    """The objective's own jumps [h]: one time step of one day, over the days a statistic averages."""
    if statistic == "mean":
        return step_hours / n_days
    if statistic == "worst-month":
        return step_hours / min(np.bincount(months)[np.unique(months)])
    return step_hours


def worst_month(hours, months):
    """The month [1-12], (...), of the lowest monthly mean: where a ``worst-month`` objective is found.

    Parameters
    ----------
    hours : array_like
        Daily t_solar [h], (days, ...).
    months : array_like
        (days,) month of each day [1-12].
    """
    hours, months = np.asarray(hours, dtype=float), np.asarray(months)
    present = np.unique(months)
    means = np.stack([hours[months == m].mean(axis=0) for m in present])
    return present[np.argmin(means, axis=0)]


def near_optimal(fold_angles, values, tolerance: NearOptimal, fold: bool = True) -> dict:
    """The plateau of fold angles around the best: every grid angle on the best one's side of the
    first angles that fall short, and the recommended angle at its centre.

    An angle is near-optimal when its value lies within ``tolerance`` of the best
    (:meth:`foldopt.inputs.sections.NearOptimal.tolerance_h`: 1 % or 1 min by default, whichever is
    larger). The range is the contiguous run of such angles that holds the best one
    (:func:`best_angle_index`); the recommended angle is the grid angle nearest its centre (ties to
    the less folded), so that a hinge set a few degrees off still lies on the plateau, except
    where the best is the flat panel (:func:`recommended_angle`).

    Parameters
    ----------
    fold_angles : array_like
        The fold angles evaluated [deg], ascending, (n_angles,): a grid, and with it any optimum
        refined between its angles (:func:`foldopt.engine.optimize.optimal_fold_angle`), which the
        range then holds, as it holds the best of the angles given.
    values : array_like
        t_solar or an objective [h] at each angle, (..., n_angles).
    tolerance : foldopt.inputs.sections.NearOptimal
    fold : bool, default True
        The values are of the fold angle (a best at 180 deg is the flat panel); False for another
        variable (a tilt, an azimuth) ranged the same way.

    Returns
    -------
    dict of numpy.ndarray
        ``near_optimal_lo_deg``, ``near_optimal_hi_deg``, ``recommended_deg`` [deg] and
        ``near_optimal_tolerance_h`` [h], each (...); NaN where no angle carries the load.
    """
    fold_angles = np.asarray(fold_angles, dtype=float)
    values = np.asarray(values, dtype=float)
    best = best_angle_index(values)
    top = np.take_along_axis(values, best[..., None], axis=-1)[..., 0]
    tol = tolerance.tolerance_h(top)
    index = np.arange(fold_angles.size)
    short = values < (top - tol)[..., None]
    below, above = short & (index < best[..., None]), short & (index > best[..., None])
    lo = np.where(below.any(axis=-1), fold_angles.size - np.argmax(below[..., ::-1], axis=-1), 0)
    hi = np.where(above.any(axis=-1), np.argmax(above, axis=-1) - 1, fold_angles.size - 1)
    carried = top > 0
    lo, hi = np.where(carried, fold_angles[lo], np.nan), np.where(carried, fold_angles[hi], np.nan)
    return {
        "near_optimal_lo_deg": lo,
        "near_optimal_hi_deg": hi,
        "recommended_deg": recommended_angle(
            fold_angles, lo, hi, fold_angles[best] if fold else None
        ),
        "near_optimal_tolerance_h": np.where(carried, tol, np.nan),
    }


def recommended_angle(angles, lo, hi, best=None):
    """The angle to recommend of a near-optimal range: the one of ``angles`` inside the range
    nearest its centre (ties to the less folded), so that a hinge set a few degrees off still lies
    on the plateau; but the flat panel where the best fold angle is 180 deg, for a panel that is
    best unfolded needs no hinge to set, and no fold gains over it.

    Parameters
    ----------
    angles : array_like
        The candidates [deg], ascending, (n,): the grid, and any angle evaluated off it.
    lo, hi : array_like
        The range's edges [deg], (...); NaN where no angle carries the load.
    best : array_like, optional
        The best fold angle [deg], (...); None where the angles are not fold angles.

    Returns
    -------
    numpy.ndarray
        [deg], (...), always within ``lo`` to ``hi``; NaN where the range is.
    """
    angles = np.asarray(angles, dtype=float)
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    centre = (lo + hi) / 2.0
    with np.errstate(invalid="ignore"):
        inside = (angles >= lo[..., None]) & (angles <= hi[..., None])
    distance = np.where(inside, np.abs(angles - centre[..., None]), np.inf)
    chosen = np.where(inside.any(axis=-1), angles[best_angle_index(-distance)], np.nan)
    if best is not None:
        chosen = np.where(np.asarray(best) == FLAT_FOLD_ANGLE, FLAT_FOLD_ANGLE, chosen)
    return np.where(np.isfinite(centre), chosen, np.nan)


def near_optimal_on_grid(fold_angles, values, tolerance: NearOptimal, grid) -> dict:
    """:func:`near_optimal` on a grid of fold angles from values at some of them (a search's): each
    edge lies between the evaluated angle inside the range and the one outside, at the last grid
    angle before the monotone cubic through the values [1]_ (SciPy's ``PchipInterpolator``) falls
    below the threshold (the best less the tolerance); the recommended angle is the grid angle nearest the
    range's centre (:func:`recommended_angle`; an evaluated angle where the range holds no grid
    angle). Where every grid angle is evaluated, it is :func:`near_optimal`.

    Parameters
    ----------
    fold_angles : array_like
        The evaluated fold angles [deg], ascending, (n,), on ``grid``.
    values : array_like
        t_solar or an objective [h] at each, (targets, n).
    tolerance : foldopt.inputs.sections.NearOptimal
    grid : array_like
        The grid [deg], ascending.

    Returns
    -------
    dict of numpy.ndarray
        As :func:`near_optimal`'s, (targets,).

    References
    ----------
    .. [1] F. N. Fritsch, R. E. Carlson, "Monotone piecewise cubic interpolation", SIAM Journal on
       Numerical Analysis 17(2), 238-246, 1980.
    """
    fold_angles, values, grid = (np.asarray(a, dtype=float) for a in (fold_angles, values, grid))
    ranges = near_optimal(fold_angles, values, tolerance)
    if fold_angles.size < 2:
        return ranges
    best = best_angle_index(values)
    top = np.take_along_axis(values, best[:, None], axis=-1)[:, 0]
    line = top - tolerance.tolerance_h(top)
    # A slope of a few ulp overflows in the harmonic mean of the slopes; it then goes to 0, as it should.
    with np.errstate(over="ignore"):
        from scipy.interpolate import PchipInterpolator

        cubic_at = PchipInterpolator(fold_angles, values, axis=-1)(grid)  # (targets, grid)
    place = np.arange(grid.size)
    for name, outward in {"near_optimal_lo_deg": -1, "near_optimal_hi_deg": 1}.items():
        edge = ranges[name]
        # Each target's gap between its evaluated edge (inner) and the next evaluated angle outward.
        inner = np.searchsorted(
            fold_angles, np.where(np.isfinite(edge), edge, fold_angles[0]) - 1e-9
        )
        outer = inner + outward
        has_gap = np.isfinite(edge) & (outer >= 0) & (outer < fold_angles.size)
        outer = np.clip(outer, 0, fold_angles.size - 1)
        low, high = fold_angles[np.minimum(inner, outer)], fold_angles[np.maximum(inner, outer)]
        gap = has_gap[:, None] & (grid > low[:, None]) & (grid < high[:, None])  # (targets, grid)
        below = gap & (cubic_at < line[:, None])
        # The gap's grid angles from the inner end outward while the cubic stays at or above the line.
        if outward > 0:
            stop = np.where(below.any(axis=1), np.argmax(below, axis=1), grid.size)
            kept = gap & (place < stop[:, None])
            last = grid.size - 1 - np.argmax(kept[:, ::-1], axis=1)
        else:
            stop = np.where(
                below.any(axis=1), grid.size - 1 - np.argmax(below[:, ::-1], axis=1), -1
            )
            kept = gap & (place > stop[:, None])
            last = np.argmax(kept, axis=1)
        ranges[name] = np.where(kept.any(axis=1), grid[last], edge)
    ranges["recommended_deg"] = recommended_angle(
        np.union1d(grid, fold_angles),
        ranges["near_optimal_lo_deg"],
        ranges["near_optimal_hi_deg"],
        fold_angles[best],
    )
    return ranges


#: The percentiles over a cloud ensemble's members that the answer gives of each day's t_solar and
#: of the objective (``t_solar_members_p10_h``..., ``t_solar_objective_members_p10_h``...).
ENSEMBLE_PERCENTILES = (10, 50, 90)


def ensemble_choice(daily, months, statistic: str, season, tolerance: NearOptimal) -> dict:
    """One fold angle chosen over the members of a cloud ensemble, and how sure the choice is.

    Each member is a year (or the days) of its own clouds: its objective at every angle
    (:func:`objective_value`), and its own best angle. The angle chosen maximises the members'
    mean objective, the expected value of the objective over the clouds the hourly file allows.
    How sure: the share of members whose own best angle it is, and the share for which it lies
    within the near-optimal tolerance of the member's own best (its regret, the objective the
    member loses by the ensemble's angle, within :meth:`NearOptimal.tolerance_h`).

    Parameters
    ----------
    daily : array_like
        Daily t_solar [h], (members, days, loads, angles).
    months : array_like
        (days,) month of each day.
    statistic : str
        :func:`objective_value`'s.
    season : sequence of int or None
        :func:`objective_value`'s.
    tolerance : foldopt.inputs.sections.NearOptimal

    Returns
    -------
    dict
        ``score`` (loads, angles): the members' mean objective [h]; ``member_score`` (members,
        loads, angles) [h]; ``fixed`` (loads,) the chosen angle's index; ``wins_pct`` (loads,
        angles): the share of members whose own best each angle is [%]; ``chosen_wins_pct`` and
        ``within_tolerance_pct`` (loads,) [%]; ``regret_h`` (members, loads) [h].
    """
    daily = np.asarray(daily, dtype=float)
    member_score = np.stack(
        [objective_value(member, months, statistic, season) for member in daily]
    )
    score = member_score.mean(axis=0)
    fixed = best_angle_index(score)
    own = best_angle_index(member_score)  # (members, loads)
    n_angles = score.shape[-1]
    wins = (own[..., None] == np.arange(n_angles)).mean(axis=0) * 100.0
    best_value = np.take_along_axis(member_score, own[..., None], axis=-1)[..., 0]
    chosen = np.take_along_axis(
        member_score, np.broadcast_to(fixed, own.shape)[..., None], axis=-1
    )[..., 0]
    regret = best_value - chosen
    within = (regret <= tolerance.tolerance_h(best_value) + 1e-12).mean(axis=0) * 100.0
    return {
        "score": score,
        "member_score": member_score,
        "fixed": fixed,
        "wins_pct": wins,
        "chosen_wins_pct": np.take_along_axis(wins, fixed[:, None], axis=-1)[:, 0],
        "within_tolerance_pct": within,
        "regret_h": regret,
    }
