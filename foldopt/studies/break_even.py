"""The standby draw at which a tracker loses its lead over the twofold panel: a map's
``break_even_standby_tracker_w`` (:func:`break_even_standby`).

The module may import numpy, :mod:`foldopt.engine` and :mod:`foldopt.studies.objectives`.
"""

from __future__ import annotations

import math

import numpy as np

from foldopt.engine import evaluation as engines
from foldopt.studies.objectives import period_days, period_values
from foldopt.names import DEFAULT_ENGINE

#: The break-even search's brackets close to this share of the largest power (a 20 W tracker's
#: break-even to 2e-5 W), in at most so many passes of the engine.
BREAK_EVEN_TOLERANCE, BREAK_EVEN_ROUNDS = 1e-6, 40
#: Rungs of the ladder of loads that brackets each break-even draw first (:func:`_ladder_brackets`).
BREAK_EVEN_LADDER = 64


def break_even_standby(
    available,
    targets,
    p_load,
    months,
    statistic: str,
    seasons,
    step_hours: float,
    engine: str = DEFAULT_ENGINE,
):
    """The tracker's standby draw [W] at which its objective over each period falls to ``targets``,
    at several sites of the same days at once.

    A standby draw ``s`` while the sun is up is the load ``P_load + s`` on ``available`` (see
    :func:`foldopt.studies.day.standby_sweep`), and every day's t_solar, so every objective, falls as the
    load rises. The root lies between 0 and the largest available power (no time at all); a ladder
    of loads narrows that bracket in one pass of the engine (:func:`_ladder_brackets`), and the root
    is found for every site, period and load together, one draw a bracket per pass, by false
    position with the Illinois rule [1]_ (the end kept twice has its value halved, so that both
    ends move): the objective is piecewise linear in the draw, and the brackets close to
    :data:`BREAK_EVEN_TOLERANCE` of the site's largest power in a few more passes.

    Parameters
    ----------
    available : numpy.ndarray
        (sites x days, steps) [W], each site's days in turn: the tracker's power left for the load
        and a standby draw (:func:`foldopt.studies.designs.standby_available`).
    targets : numpy.ndarray
        (sites, periods, loads) the twofold panel's objective [h].
    p_load : numpy.ndarray
        (sites, loads) [W].
    months : numpy.ndarray
        (days,) month of each day, the same at every site.
    statistic : str
        :func:`foldopt.studies.objectives.objective_value`'s.
    seasons : sequence
        Each period's months (None: every day).
    step_hours : float
        Step length [h].
    engine : {'auto', 'numba', 'numpy'}

    Returns
    -------
    numpy.ndarray
        (sites, periods, loads) [W]: 0 where the tracker without standby is already no better; NaN
        where the target is 0 h.

    References
    ----------
    .. [1] M. Dowell, P. Jarratt, "A modified regula falsi method for computing the root of an
       equation", BIT 11, 168-174, 1971.
    """
    n_sites, n_periods, n_loads = targets.shape
    n_days = len(months)
    top = available.reshape(n_sites, -1).max(axis=1).clip(0.0)[:, None, None]  # (sites, 1, 1)
    period = np.broadcast_to(np.arange(n_periods)[:, None], (n_periods, n_loads))

    site_of_day = np.repeat(np.arange(n_sites), n_days)
    member = period_days(months, seasons)  # every pass's periods
    span = engines.power_span(available)
    reach = available.max(axis=1)  # each day's largest power [W]

    def objectives(sets, count, days=None):
        """(sites, periods, n) every period's objective [h] at each site's first ``count[site]``
        loads of ``sets`` (sites, n) [W], the rest padded with loads no power reaches, so that each
        site's loads go to the engine as its own set and get the same bits whatever other sites
        ask; a site with none is not walked (NaN). ``days`` (sites x days,) bool, where given, the
        days whose periods the caller reads (the others' objectives are then not the days').

        A day whose power stays below all of its site's loads carries none of them: its t_solar
        is 0 walked or not (no segment of it reaches a load), so it is not walked."""
        lowest = np.where(count > 0, sets.min(axis=1, initial=np.inf), np.inf)
        keep = reach >= lowest[site_of_day]
        if days is not None:
            keep &= days
        walked = np.where(keep[:, None], span, 0)
        # Each site's loads in ascending order, the order the engine takes them in (it sorts
        # them): its answers then need no reordering row by row, only each site's own at the end.
        order = np.argsort(sets, axis=1, kind="stable")
        daily = (
            engines.curve_metrics(
                available,
                np.take_along_axis(sets, order, axis=1),
                step_hours,
                site_of_day,
                engine=engine,
                span=walked,
            )
            .t_solar[:, 0]
            .reshape(n_sites, n_days, -1)
        )
        value = np.full((n_sites, n_periods, sets.shape[1]), np.nan)
        for site in np.flatnonzero(count):
            place = np.argsort(order[site])[: count[site]]  # each load's place among the sorted
            value[site, :, : count[site]] = period_values(
                daily[site][:, place],
                months,
                statistic,
                seasons,
                member,
            )
        return value

    def shortfall(draws, asked):
        """(sites, periods, loads) each asked target's objective at its load plus its draw, less its
        target (NaN where not asked)."""
        count = asked.reshape(n_sites, -1).sum(axis=1)
        sets = np.full((n_sites, max(int(count.max()), 1)), np.inf)
        for site in np.flatnonzero(count):
            sets[site, : count[site]] = (p_load[site][None, :] + draws[site])[asked[site]]
        # Only the days of the periods some asked target of the site is of.
        days = (asked.any(axis=2)[:, :, None] & member[None]).any(axis=1).ravel()
        every = objectives(sets, count, days)
        value = np.full(targets.shape, np.nan)
        for site in np.flatnonzero(count):
            mine = asked[site]  # each target's own period kept
            value[site][mine] = (
                every[site][period[mine], np.arange(count[site])] - targets[site][mine]
            )
        return value

    low, high, at_low, at_high = _ladder_brackets(objectives, p_load, top[:, 0, 0], targets)
    found = np.where(at_low <= 0, 0.0, np.nan)
    side = np.zeros(targets.shape, dtype=int)
    for _ in range(BREAK_EVEN_ROUNDS):
        open_ = np.isnan(found) & (high - low > BREAK_EVEN_TOLERANCE * np.maximum(top, 1e-12))
        if not open_.any():
            break
        with np.errstate(divide="ignore", invalid="ignore"):
            draw = np.where(
                at_low != at_high,
                (low * at_high - high * at_low) / (at_high - at_low),
                (low + high) / 2,
            )
        # A secant that lands on an end (the objective flat there to its last bits) halves instead.
        draw = np.where((draw > low) & (draw < high), draw, (low + high) / 2)
        value = shortfall(draw, open_)
        found = np.where(open_ & (value == 0), draw, found)  # the objective is the target there
        above = open_ & (value > 0)
        below = open_ & (value < 0)
        # Illinois: an end kept a second time in a row has its value halved.
        at_high = np.where(above & (side == 1), at_high / 2, at_high)
        at_low = np.where(below & (side == -1), at_low / 2, at_low)
        low, at_low = np.where(above, draw, low), np.where(above, value, at_low)
        high, at_high = np.where(below, draw, high), np.where(below, value, at_high)
        side = np.where(above, 1, np.where(below, -1, side))
    found = np.where(np.isnan(found), (low + high) / 2, found)
    return np.where((targets > 0) & np.isfinite(p_load[:, None, :]), found, math.nan)


def _ladder_brackets(objectives, p_load, top, targets):
    """Each target's first bracket of the break-even draw, from one pass of the engine: every
    period's objective at a ladder of loads per site, :data:`BREAK_EVEN_LADDER` steps from its
    lowest load to its highest plus its largest power, with its loads and its loads plus that
    power among them (the draws 0 and ``top``). A target's draw lies between the last rung of its
    own range (its load to its load plus ``top``) where the objective is still above the target
    and the next, so the false position starts on a bracket some 1/60 of the range wide instead
    of the whole range, and needs fewer passes of the engine (docs/performance.rst).

    Parameters
    ----------
    objectives : callable
        ``objectives(sets, count)`` -> (sites, periods, n) every period's objective at each site's
        first ``count`` loads of ``sets`` [h].
    p_load : numpy.ndarray
        (sites, loads) [W].
    top : numpy.ndarray
        (sites,) each site's largest available power [W].
    targets : numpy.ndarray
        (sites, periods, loads) [h].

    Returns
    -------
    low, high, at_low, at_high : numpy.ndarray
        (sites, periods, loads) the bracket's draws [W] and the objective there less the target
        [h]; ``at_low <= 0`` where the draw 0 already reaches the target (NaN where the site has
        no finite load).
    """
    n_sites, n_periods, n_loads = targets.shape
    ladders = []
    for site in range(n_sites):
        finite = p_load[site][np.isfinite(p_load[site])]
        ladders.append(
            np.unique(
                np.concatenate(
                    [
                        finite,
                        finite + top[site],
                        np.linspace(finite.min(), finite.max() + top[site], BREAK_EVEN_LADDER),
                    ]
                )
            )
            if finite.size
            else np.zeros(0)
        )
    count = np.array([ladder.size for ladder in ladders])
    sets = np.full((n_sites, max(int(count.max()), 1)), np.inf)
    for site, ladder in enumerate(ladders):
        sets[site, : ladder.size] = ladder
    value = objectives(sets, count)
    low, high, at_low, at_high = (np.full(targets.shape, np.nan) for _ in range(4))
    for site in np.flatnonzero(count):
        rungs, load = sets[site, : count[site]], p_load[site][:, None]
        inside = (rungs >= load) & (rungs <= load + top[site])  # (loads, rungs): the draws 0 to top
        # (periods, loads, rungs)
        above = (value[site][:, None, :] - targets[site][:, :, None] > 0) & inside
        first, last = (
            np.argmax(inside, axis=1),
            count[site] - 1 - np.argmax(inside[:, ::-1], axis=1),
        )
        # The last rung still above the target, and the next (the load's own rung where none is).
        start = np.where(
            above.any(axis=-1), count[site] - 1 - np.argmax(above[..., ::-1], axis=-1), first
        )
        start = np.maximum(np.minimum(start, last - 1), first)
        stop = np.minimum(start + 1, last)
        periods = np.arange(n_periods)[:, None]
        low[site], high[site] = rungs[start] - load[:, 0], rungs[stop] - load[:, 0]
        at_low[site] = value[site][periods, start] - targets[site]
        at_high[site] = value[site][periods, stop] - targets[site]
    return low, high, at_low, at_high
