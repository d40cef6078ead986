"""The cheapest panel and buffer that meet the buffer's target (issue 50), per kind of design:
panel area, fold angle and buffer capacity chosen together at a study's prices
(:class:`foldopt.inputs.costs_section.Costs`), as HOMER's optimizer chooses a PV array's and a
battery bank's sizes for the least net present cost among those meeting a capacity-shortage
constraint [1]_, here with the fold angle beside them and the buffer simulated on the study's
own steps: over a weather file's days in sequence (:func:`year_design_space`), a year of clear
days, or a day's clear sky repeated to its periodic state (:func:`day_design_space`).

The search (:func:`design_space`): for each kind (``flat``; ``twofold`` at each fold angle of
:func:`search_angles`, :data:`SEARCH_ANGLES` of the study's grid with the angles best for
``t_solar`` and for powered time; ``tracker-net``, the study's tracker with its drive's draw served
by the buffer, where its drive has a price) and each panel area of a geometric grid around the
study's (:data:`AREA_FACTORS`: a quarter to four times it, steps of 2^(1/4), 19 %), the smallest
buffer meeting ``storage.target``; none above the sizing grid's top, four days' load energy over
the usable fraction (:func:`foldopt.studies.storage_sizing.capacity_grid`). An area's power is
the study's power curve scaled by the area's ratio: exact where the PV model's power is
proportional to the area, as ``ideal``'s and ``pvwatts``' are (their rating is efficiency x area x
1000 W/m^2; a given ``pvwatts.pdc0`` is scaled at its W/m^2), and the study refuses the section for
a model with an I-V curve (:func:`foldopt.inputs.costs_section.costs_problem`) rather than scale
what does not scale; a tracker's drive draws what it draws at any area. A design's cost is ``area
x panel_usd_per_m2 + capacity x buffer_usd_per_wh``, plus the hinge (twofold) or the drive
(tracker), plus ``fixed_usd``.

It runs in two steps, every design's curves through the engine together:

1. **the frontier on the grids** (:func:`_grid_bounds`): at each area, the least capacity of the
   sizing's grid meeting the target, by a walk along each kind's frontier from the largest area
   down (a capacity that meets the target at an area meets it at every larger one, and a larger
   capacity at the same area: each area's least capacity is at least the next larger area's);
   the least capacity and the one below it, which does not meet the target, bound the least
   capacity between them (both evaluated at the area, each area and capacity once: a row where
   either is not what the premise says is sized on the whole grid);
2. **branch and bound**: a row whose cost at its lower bound is below its kind's least cost at
   an upper bound is sized exactly, its bracket on the grid cut as the sizing cuts it
   (:func:`foldopt.studies.storage_sizing.bracketed_buffers`, within its
   :data:`~foldopt.studies.storage_sizing.CAPACITY_RTOL`); the others cannot be the least. The
   least-cost design of a kind is the cheapest row sized (ties to the smallest area, then the
   least folded): exact in the capacity, and as fine as the area grid.

Both steps rest on the sizing's premise, powered time not falling as the buffer or the panel
grows: it holds for a controller without hysteresis and a buffer that does not leak
(:mod:`foldopt.studies.storage_sizing`); with a hysteresis band or a leak a larger design can run
the load less, and the search may miss a design meeting the target between two that do not.
Every capacity the table gives was evaluated at its area and meets the target.

The module may import numpy, pandas, :mod:`foldopt.inputs` and
:mod:`foldopt.studies.storage_sizing`.

References
----------
.. [1] UL Solutions (HOMER Energy), "HOMER Pro 3.16 User Manual": Design > Project tab >
   Optimization (support.ul-renewables.com/homer-manuals-pro/optimization.html): the systems
   simulated over a search space of component sizes (PV, storage) between a lower and an upper
   bound, ranked by net present cost; Constraints: the maximum annual capacity shortage a
   feasible system meets (0 % by default, the load fully supplied).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from foldopt.inputs.costs_section import DRIVE_FIELD
from foldopt.names import FLAT_FOLD_ANGLE
from foldopt.studies.storage_sizing import (
    CAPACITY_RTOL,
    bracketed_buffers,
    capacity_grid,
    reaching,
    smallest_buffers,
)

if TYPE_CHECKING:
    import pandas as pd

#: The panel areas searched, as multiples of the study's [-]: a quarter to four times it in
#: steps of 2^(1/4).
AREA_FACTORS = 2.0 ** np.arange(-2.0, 2.0 + 1e-9, 0.25)
#: Bytes of the curves one evaluation of the search holds at once.
CURVE_BYTES = 100e6
#: design_space.csv's columns, in order.
COLUMNS = (
    "design",
    "fold_angle_deg",
    "area_m2",
    "capacity_wh",
    "capacity_bracket_frac",
    "cost_usd",
    "meets",
    "frontier",
    "least_cost",
)


def design_space(
    curves: dict,
    fold_angles,
    *,
    area_m2: float,
    load,
    storage,
    costs,
    tracker_model: str,
    step_hours: float,
    engine: str,
    in_sequence: bool,
    draw=None,
    cold=None,
    years=None,
) -> pd.DataFrame:
    """Each kind's smallest buffer for ``storage.target`` at each area of the grid, its cost and
    the least-cost design (module docstring).

    Parameters
    ----------
    curves : dict
        ``flat`` and ``tracker-net`` -> power [W] at the study's area, (n_days, n_steps);
        ``twofold`` -> at ``fold_angles``, (k, n_days, n_steps). A net tracker's is its whole
        power, its drive's draw ``draw``.
    fold_angles : array_like
        (k,) [deg].
    area_m2 : float
        The study's panel area [m^2].
    load : float or numpy.ndarray
        [W], or a profile (1, n_days, n_steps).
    storage : foldopt.inputs.storage_section.Storage
        With a ``target``.
    costs : foldopt.inputs.costs_section.Costs
    tracker_model : str
        The study's ``tracker.model``: which drive's price the tracker takes.
    step_hours : float
    engine : str
        The storage engine (``numba`` or ``numpy``).
    in_sequence : bool
        The days follow each other (:func:`foldopt.studies.storage_days.sequential`).
    draw : numpy.ndarray, optional
        The tracker's own draw [W], (n_days, n_steps).
    cold : foldopt.engine.storage.ColdSteps, optional
        The buffer's temperature's effects at each step of the days (the same at every area:
        the buffer's temperature is the air's, whatever the panel).
    years : array_like, optional
        (n_days,) each day's year, for a target met in ``storage.target.years`` of them.

    Returns
    -------
    pandas.DataFrame
        :data:`COLUMNS`, a row per kind, fold angle and area: ``capacity_wh`` and ``cost_usd``
        NaN where no buffer up to the sizing grid's top meets the target (``meets`` False);
        ``capacity_bracket_frac``, how far below ``capacity_wh`` the least capacity meeting it
        may lie (the sizing's tolerance where the row was refined, else the grid's step);
        ``frontier``, the kind's least capacity at its area (a twofold panel's best angle
        there); ``least_cost``, the kind's cheapest row.
    """
    import pandas as pd

    fold_angles = np.asarray(fold_angles, dtype=float)
    drive = costs.drive_usd(tracker_model)
    kinds = [("flat", FLAT_FOLD_ANGLE, curves["flat"], 0.0, None)]
    kinds += [
        ("twofold", angle, curve, costs.hinge_usd, None)
        for angle, curve in zip(fold_angles, curves["twofold"], strict=True)
    ]
    if drive is not None:
        kinds.append(("tracker-net", np.nan, curves["tracker-net"], drive, draw))
    power = np.stack([kind[2] for kind in kinds])  # (r, n_days, n_steps)
    n, m = len(kinds), AREA_FACTORS.size

    def scaled(rows):
        # Rows kind-major, each an area's curve: its kind's scaled (made when evaluated, a
        # chunk at a time: every row's at once would hold n x m curves).
        return power[rows // m] * AREA_FACTORS[rows % m, None, None]

    draws = [kind[4] for kind in kinds for _ in range(m)]
    if drive is None or draw is None:
        draws = None
    run = _Run((load, storage, step_hours, engine, in_sequence), {"cold": cold, "years": years})
    grid = capacity_grid(load, storage, step_hours, power.shape[-1])
    known = _Known(scaled, draws, run)
    upper, lower = _grid_bounds(known, grid, (n, m))  # (n * m,) each
    areas = np.tile(AREA_FACTORS * area_m2, n)
    extra = np.repeat([kind[3] for kind in kinds], m) + costs.fixed_usd
    names = np.repeat([kind[0] for kind in kinds], m)

    def cost(capacity):
        return areas * costs.panel_usd_per_m2 + capacity * costs.buffer_usd_per_wh + extra

    # Branch and bound: a row is refined where its cost with the least capacity it may need is
    # below its kind's least cost with the capacity known to meet.
    high = np.where(np.isfinite(upper), cost(upper), np.inf)
    bound = pd.Series(high).groupby(names).transform("min").to_numpy()
    refine = np.isfinite(upper) & (cost(lower) <= bound)
    # The bounds are the premise's: a row whose upper bound does not meet the target at its own
    # area, or whose lower one does, is sized on the whole grid, so that every capacity said was
    # evaluated; the others' brackets are the grid's.
    rows = np.flatnonzero(np.isfinite(upper))
    below = rows[upper[rows] > 0]
    whole = np.zeros(n * m, bool)
    whole[rows[~known.reach(rows, upper[rows])]] = True
    whole[below[known.reach(below, lower[below])]] = True
    refine |= whole
    # A row that meets nowhere on the grid (an infinite upper bound) has no bracket to say.
    need, bracket = upper.copy(), np.zeros_like(upper)
    np.divide(upper - lower, upper, out=bracket, where=np.isfinite(upper) & (upper > 0))
    first = np.searchsorted(grid, upper)
    for chosen in (np.flatnonzero(refine & ~whole), np.flatnonzero(whole)):
        if not chosen.size:
            continue
        given = (*run.given, None if draws is None else [draws[i] for i in chosen])
        found = (
            smallest_buffers(scaled(chosen), *given, **run.keywords)[0]
            if whole[chosen[0]]
            else bracketed_buffers(scaled(chosen), first[chosen], *given, **run.keywords)
        )
        need[chosen], bracket[chosen] = found, np.where(found > 0, CAPACITY_RTOL, 0.0)
    refine = np.flatnonzero(refine)
    table = pd.DataFrame(
        {
            "design": names,
            "fold_angle_deg": np.repeat([kind[1] for kind in kinds], m),
            "area_m2": areas,
            "capacity_wh": need,
            "capacity_bracket_frac": np.where(np.isfinite(need), bracket, np.nan),
            "cost_usd": cost(need),
            "meets": np.isfinite(need),
        }
    )
    meets = table["meets"]
    least_at_area = table[meets].groupby(["design", "area_m2"])["capacity_wh"].transform("min")
    table["frontier"] = False
    table.loc[meets, "frontier"] = table.loc[meets, "capacity_wh"] == least_at_area
    table["least_cost"] = False
    # Ties to the smallest area, then the least folded; only refined rows can be the least.
    chosen = table.iloc[refine][meets.iloc[refine].to_numpy()]
    order = chosen.sort_values(
        ["design", "cost_usd", "area_m2", "fold_angle_deg"],
        ascending=[True, True, True, False],
        kind="stable",
    )
    table.loc[order.groupby("design").head(1).index, "least_cost"] = True
    return table[list(COLUMNS)]


class _Run(NamedTuple):
    """The sizing's arguments every evaluation of the search passes on: ``given``, ``(load,
    storage, step_hours, engine, in_sequence)``, and ``keywords``, the days' ``cold`` and
    ``years`` (:func:`foldopt.studies.storage_sizing.reaching`)."""

    given: tuple
    keywords: dict


class _Known:
    """Whether rows of the search meet the target at capacities, each (row, capacity) evaluated
    once (:func:`foldopt.studies.storage_sizing.reaching`), a chunk of rows' curves at a time
    (their copies are the memory).

    Parameters
    ----------
    scaled : callable
        Rows (r,) of the kinds' areas, kind-major -> their curves (r, n_days, n_steps) [W].
    draws : list or None
        Per row, its own draw (or None).
    run : _Run
        The sizing's arguments.
    """

    def __init__(self, scaled, draws, run: _Run):
        self.scaled, self.draws, self.run = scaled, draws, run
        self.size = max(1, int(CURVE_BYTES // scaled(np.zeros(1, int)).nbytes))
        self.found = {}

    def reach(self, rows, capacities) -> np.ndarray:
        """(r,) bool: whether each of ``rows`` (r,) meets the target at its capacity (r,) [Wh]."""
        pairs = list(zip(rows.tolist(), np.asarray(capacities, dtype=float).tolist()))
        new = list(dict.fromkeys(pair for pair in pairs if pair not in self.found))
        for at in range(0, len(new), self.size):
            chunk = new[at : at + self.size]
            index = np.array([row for row, _ in chunk], dtype=int)
            ok = reaching(
                self.scaled(index),
                np.array([capacity for _, capacity in chunk]),
                *self.run.given,
                None if self.draws is None else [self.draws[row] for row in index],
                **self.run.keywords,
            )
            self.found.update(zip(chunk, ok.tolist()))
        return np.array([self.found[pair] for pair in pairs], dtype=bool)


def _grid_bounds(known: _Known, grid, shape):
    """Each row's least capacity of the sizing's ``grid`` [Wh] meeting the target (NaN: none)
    and the grid's capacity below it (which does not; 0 where the least is the grid's first),
    found by a walk along each kind's frontier: from the largest area down, each area's least
    capacity is at least the next larger area's (a capacity that meets the target at an area
    meets it at every larger one, the premise of the sizing with the area for the capacity), so
    that the walk steps up the capacities or down the areas, each kind at most n_areas + the
    grid's size evaluations (its first step a bisection).

    Parameters
    ----------
    known : _Known
        The search's evaluations.
    grid : numpy.ndarray
        (g,) ascending [Wh].
    shape : tuple
        ``(n_kinds, n_areas)``.
    """
    n_kinds, n_areas = shape
    # Per kind and area: the index of its least capacity meeting the target (grid.size: none).
    first = np.full((n_kinds, n_areas), grid.size)
    area = np.full(n_kinds, n_areas - 1)
    kinds = np.arange(n_kinds)
    # The largest area's least capacity bisected (a capacity that meets the target there is
    # followed by larger ones that do: the premise with the capacity): the walk's first column
    # takes log2 of the grid's size evaluations rather than its size.
    step, top = np.zeros(n_kinds, dtype=int), np.full(n_kinds, grid.size)
    while (open_ := kinds[step < top]).size:
        mid = (step[open_] + top[open_]) // 2
        ok = known.reach(open_ * n_areas + area[open_], grid[mid])
        top[open_[ok]] = mid[ok]
        step[open_[~ok]] = mid[~ok] + 1
    # A kind whose largest capacity fails at an area fails at every smaller one: done.
    while (open_ := np.flatnonzero((area >= 0) & (step < grid.size))).size:
        ok = known.reach(open_ * n_areas + area[open_], grid[step[open_]])
        met, missed = open_[ok], open_[~ok]
        first[met, area[met]] = step[met]
        area[met] -= 1
        step[missed] += 1
    first = first.ravel()
    upper = np.where(first < grid.size, grid[np.minimum(first, grid.size - 1)], np.nan)
    lower = np.where(
        (first > 0) & (first < grid.size),
        grid[np.clip(first - 1, 0, grid.size - 1)],
        np.where(first == 0, 0.0, np.nan),
    )
    return upper, lower


#: Twofold angles the search compares: the grid's, thinned to about this many, with the angle
#: best for powered time with the study's own buffer.
SEARCH_ANGLES = 6


def search_angles(fold_angles, best) -> np.ndarray:
    """The fold angles [deg] the search compares (:data:`SEARCH_ANGLES`): the grid's
    ``fold_angles`` thinned, with ``best`` (array_like of angles of the grid)."""
    fold_angles = np.asarray(fold_angles, dtype=float)
    step = max(1, -(-fold_angles.size // SEARCH_ANGLES))
    return np.union1d(fold_angles[::step], np.asarray(best, dtype=float))


def year_design_space(
    storage,
    costs,
    days,
    curves: dict,
    twofold,
    angles,
    *,
    area_m2,
    tracker_model,
    engine,
    draw,
    cold=None,
) -> pd.DataFrame:
    """:func:`design_space` per load of an annual group's days, with its ``p_load_w``.

    Parameters
    ----------
    storage, costs
        The study's sections.
    days : foldopt.studies.storage_days.YearDays
    curves : dict
        ``flat`` and ``tracker-net`` -> power [W], (n_days, n_steps).
    twofold : numpy.ndarray
        The twofold panel's power at ``angles`` [W], (k, n_days, n_steps).
    angles : numpy.ndarray
        (k,) [deg], :func:`search_angles`.
    area_m2 : float
    tracker_model : str
    engine : str
        The storage engine.
    draw : numpy.ndarray
        The tracker's own draw [W], (n_days, n_steps).
    cold : foldopt.engine.storage.ColdSteps, optional
        The days' (:func:`foldopt.studies.storage_cold.cold_steps`).
    """
    import pandas as pd

    tables = []
    for p_load in np.asarray(days.loads, dtype=float):
        table = design_space(
            {**curves, "twofold": twofold},
            angles,
            area_m2=area_m2,
            load=p_load if days.load_shape is None else p_load * days.load_shape[None],
            storage=storage,
            costs=costs,
            tracker_model=tracker_model,
            step_hours=days.step_hours,
            engine=engine,
            in_sequence=days.in_sequence,
            draw=draw,
            cold=cold,
            # A clear sky's days are no real years: the days as one, whatever their dates.
            years=[date.year for date in days.dates] if days.weather else None,
        )
        tables.append(table.assign(p_load_w=p_load))
    columns = ["p_load_w", *COLUMNS]
    return pd.concat(tables, ignore_index=True)[columns]


def day_design_space(study, power: dict, grid: tuple, load, *, step_hours, engine, draw, cold=None):
    """:func:`design_space` of a day's study: its clear-sky day repeated to its periodic state.

    Parameters
    ----------
    study : foldopt.Study
        With ``storage.target`` and ``costs``.
    power : dict
        ``flat`` and ``tracker-net`` -> the day's power [W], (n_steps,).
    grid : tuple
        The fold-angle grid [deg] (k,), the twofold panel's power at each (k, n_steps) [W] and
        the angle best for powered time with the study's buffer.
    load : float or numpy.ndarray
        [W], or a profile (1, n_steps).
    step_hours : float
    engine : str
        The storage engine.
    draw : numpy.ndarray or None
        The tracker's own draw [W], (n_steps,).
    cold : foldopt.engine.storage.ColdSteps, optional
        The day's (:func:`foldopt.studies.storage_cold.cold_steps`).
    """
    fold_angles, grid_power, best = grid
    angles = search_angles(fold_angles, [best])
    table = design_space(
        {
            "flat": power["flat"][None],
            "tracker-net": power["tracker-net"][None],
            "twofold": grid_power[np.searchsorted(fold_angles, angles), None],
        },
        angles,
        area_m2=study.panel.area,
        load=load if np.ndim(load) == 0 else np.reshape(load, (1, 1, -1)),
        storage=study.storage,
        costs=study.costs,
        tracker_model=study.tracker.model,
        step_hours=step_hours,
        engine=engine,
        in_sequence=True,
        draw=None if draw is None else draw[None],
        cold=cold,
    )
    return table.assign(p_load_w=study.p_load)[["p_load_w", *COLUMNS]]


#: How the answer names each kind.
KIND_WORDS = {"flat": "flat", "twofold": "folded", "tracker-net": "tracker"}
#: Groups of design_space.csv the answer's lines show (the rest are in the file).
LINES_SHOWN = 8


def least_cost_answer(
    space: pd.DataFrame, costs, target, tracker_model: str, over_years: bool = False
):
    """What the answer says of the least-cost search: its lines and its part of the answer.

    Parameters
    ----------
    space : pandas.DataFrame
        design_space.csv: :func:`design_space`'s rows with ``p_load_w`` and a sweep's case
        columns.
    costs : foldopt.inputs.costs_section.Costs
    target : foldopt.inputs.storage_section.StorageTarget
    tracker_model : str
    over_years : bool, default False
        The days span several calendar years (:meth:`StorageTarget.said
        <foldopt.inputs.storage_section.StorageTarget.said>`).

    Returns
    -------
    lines : list of str
    part : dict
        ``costs`` (the prices, ``currency``), ``areas_m2`` (the grid's least and largest, the first
        group's), ``tracker_searched`` and ``least_cost`` (a row per group and kind: the least-cost
        design, ``cost_vs_flat_pct`` and ``at_grid_edge``; NaN where none meets the target).
    """
    keys = [c for c in space.columns if c not in COLUMNS]
    said = target.said(over_years)
    prices = [f"panel ${costs.panel_usd_per_m2:g}/m^2", f"buffer ${costs.buffer_usd_per_wh:g}/Wh"]
    drive = costs.drive_usd(tracker_model)
    for price, text in (
        (costs.hinge_usd, "hinge"),
        (drive, f"{tracker_model} drive"),
        (costs.fixed_usd, "fixed"),
    ):
        if price:
            prices.append(f"{text} ${price:g}")
    areas = space["area_m2"]
    lines = [
        f"the cheapest panel and buffer for {said} ({', '.join(prices)}; panel areas "
        f"{areas.min():.3g} to {areas.max():.3g} m^2):"
    ]
    rows = []
    groups = list(space.groupby(keys, sort=False)) if keys else [((), space)]
    for index, (key, group) in enumerate(groups):
        best = _least_per_kind(group)
        rows += [{**dict(zip(keys, np.atleast_1d(key), strict=True)), **row} for row in best]
        if index < LINES_SHOWN:
            label = ", ".join(
                f"P_load {v:g}" if k == "p_load_w" else f"{k} {v}"
                for k, v in zip(keys, np.atleast_1d(key), strict=True)
            )
            lines.append(f"  {label}: " + _headline(best))
    if len(groups) > LINES_SHOWN:
        lines.append(f"  ... and {len(groups) - LINES_SHOWN} more (design_space.csv)")
    if drive is None:
        lines.append(
            f"  the {tracker_model} tracker is not searched: its drive has no price "
            f"(costs.{DRIVE_FIELD[tracker_model]})"
        )
    edge = [r for r in rows if r["at_grid_edge"]]
    if edge:
        lines.append(
            "note: the least cost of "
            + ", ".join(sorted({KIND_WORDS[r["design"]] for r in edge}))
            + " lies at an end of the area grid: a panel beyond it may cost less (design_space.csv)"
        )
    part = {
        "costs": {**costs.model_dump(), "currency": "USD"},
        "areas_m2": [float(areas.min()), float(areas.max())],
        "tracker_searched": drive is not None,
        "least_cost": rows,
    }
    return lines, part


def _least_per_kind(group: pd.DataFrame) -> list[dict]:
    """Each kind's least-cost row of one group (NaN where none meets the target), with
    ``cost_vs_flat_pct`` and ``at_grid_edge`` (its area the grid's least or largest)."""
    out = []
    flat = group[(group["design"] == "flat") & group["least_cost"]]
    flat_cost = float(flat["cost_usd"].iloc[0]) if len(flat) else np.nan
    for kind in dict.fromkeys(group["design"]):
        chosen = group[(group["design"] == kind) & group["least_cost"]]
        if not len(chosen):
            out.append(
                {"design": kind, "meets": False, "at_grid_edge": False}
                | dict.fromkeys(("fold_angle_deg", "area_m2", "capacity_wh", "cost_usd"), np.nan)
                | {"cost_vs_flat_pct": np.nan}
            )
            continue
        row = chosen.iloc[0]
        edge = row["area_m2"] in (group["area_m2"].min(), group["area_m2"].max())
        out.append(
            {
                "design": kind,
                "meets": True,
                "fold_angle_deg": float(row["fold_angle_deg"]),
                "area_m2": float(row["area_m2"]),
                "capacity_wh": float(row["capacity_wh"]),
                "cost_usd": float(row["cost_usd"]),
                "cost_vs_flat_pct": (float(row["cost_usd"]) / flat_cost - 1.0) * 100.0,
                "at_grid_edge": bool(edge),
            }
        )
    return out


def _design_words(row: dict) -> str:
    """``0.12 m^2 and 31 Wh for $X`` of a least-cost row."""
    return f"{row['area_m2']:.3g} m^2 and {row['capacity_wh']:.3g} Wh for ${row['cost_usd']:.4g}"


def _headline(best: list[dict]) -> str:
    """One group's line: the cheapest kind against flat's, then the other kinds'."""
    meeting = [r for r in best if r["meets"]]
    if not meeting:
        return (
            "no kind meets the target at any area of the grid with a buffer up to the search's top"
        )
    cheapest = min(meeting, key=lambda r: r["cost_usd"])
    parts = []
    for row in [cheapest] + [r for r in best if r is not cheapest]:
        name = KIND_WORDS[row["design"]]
        if row["design"] == "twofold" and row["meets"]:
            name += f" at {row['fold_angle_deg']:g} deg"
        if not row["meets"]:
            parts.append(f"{name}: meets it at no area of the grid")
            continue
        text = f"{name}: {_design_words(row)}"
        flat = best[0]  # design_space's first kind
        if row["design"] != "flat" and flat["meets"]:
            pct = row["cost_vs_flat_pct"]
            # Flat's own design is said once: here where it is not said first.
            than = (
                f"flat's {flat['area_m2']:.3g} m^2 and {flat['capacity_wh']:.3g} Wh"
                if row is cheapest
                else "flat"
            )
            text += (
                ", as dear as " + than
                if pct == 0
                else f", {abs(pct):.0f} % {'cheaper' if pct < 0 else 'dearer'} than {than}"
            )
        parts.append(text)
    return "; ".join(parts)
