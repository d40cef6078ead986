"""A buffer through a day's designs and through a year's days (issue 41): how long the load runs
with the study's ``storage``, per design and per fold angle (:func:`day_storage`,
:func:`year_storage`, :func:`powered_by_angle`); the sizing's searches they call are
:mod:`foldopt.studies.storage_sizing`'s, what the answer says of them
:mod:`foldopt.studies.storage_answer`'s.

The day is the study's clear-sky day repeated until its midnight state of charge repeats (the
periodic steady state of :func:`foldopt.engine.storage.simulate`), or started from the
section's ``initial_soc``. Every curve simulated is the one the study's ``t_solar`` was reduced
from, so that a buffer of 0 Wh gives each design's ``t_solar`` (to the last bit of a sum). A
year's days are each such a day, or, a weather file's days that follow each other, one series
carried over from day to day (:func:`sequential`).

The module may import numpy, pandas, :mod:`foldopt.engine`, :mod:`foldopt.inputs` and the
studies it builds on (:mod:`~foldopt.studies.objectives`, :mod:`~foldopt.studies.storage_sizing`,
:mod:`~foldopt.studies.storage_periods`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple
from typing import TYPE_CHECKING

import numpy as np

from foldopt.engine.choice import engine_for
from foldopt.engine.storage import StorageResult, simulate
from foldopt.studies.least_cost import day_design_space
from foldopt.studies.objectives import best_angle_index, near_optimal, objective_value
from foldopt.studies.storage_cold import (
    charge_blocked,
    cold_columns,
    cold_steps,
    per_series,
)
from foldopt.studies.storage_periods import storage_monthly, storage_years
from foldopt.studies.storage_sizing import Sizing, buffer_of, size_buffers, smallest_buffers

if TYPE_CHECKING:
    import pandas as pd

#: The designs whose state of charge the day's figure draws and ``timeseries.csv`` holds.
SOC_DESIGNS = ("flat", "twofold", "tracker")
#: Twofold angles the sizing compares (the grid's, thinned to about this many, with the angle
#: best for the study's own buffer).
SIZING_ANGLES = 12


def storage_engine(engine: str) -> str:
    """The engine that simulates a buffer: ``engine``, or for ``auto`` the compiled loop (a
    request's engine is decided so already: :func:`foldopt.studies.request.request_engine`).

    Parameters
    ----------
    engine : {'auto', 'numba', 'numpy'}
    """
    return engine_for(engine, math.inf)


#: The columns of a design's buffer (summary.csv, the answer), by the names of
#: :meth:`foldopt.engine.storage.StorageResult.summary` they take.
SUMMARY_COLUMNS = {
    "powered_h": "powered_h",
    "availability_pct": "availability_pct",
    "days_without_outage_pct": "powered_days_ge24h_pct",
    "missing_wh": "energy_missing_wh",
    "lost_wh": "energy_lost_wh",
    "days_full_pct": "days_full_pct",
    "days_empty_pct": "days_empty_pct",
}


def day_columns(result: StorageResult) -> dict:
    """Per series, the day's (or the mean day's) buffered metrics by the columns' names
    (:data:`SUMMARY_COLUMNS`): ``powered_h`` [h a day], ``availability_pct`` (the load's energy
    served, of its demand), ``powered_days_ge24h_pct`` (days with no energy missing),
    ``energy_missing_wh`` and ``energy_lost_wh`` [Wh a day], ``days_full_pct`` and
    ``days_empty_pct`` (PVGIS's), each (n_series,).

    Parameters
    ----------
    result : foldopt.engine.storage.StorageResult
    """
    summary = result.summary()
    return {column: summary[name] for name, column in SUMMARY_COLUMNS.items()}


#: The columns a buffer adds to a day's designs (summary.csv and the answer's table).
DESIGN_COLUMNS = tuple(SUMMARY_COLUMNS.values())
#: The columns the cold adds to them where it acts (:func:`day_storage`).
COLD_COLUMNS = ("cold_lost_h", "charge_blocked_h", "charge_blocked_days_n")


def design_columns(designs: pd.DataFrame) -> list:
    """The columns a buffer adds to a day's designs (``DayStorage.designs``): :data:`DESIGN_COLUMNS`
    and, where the cold acts, :data:`COLD_COLUMNS`."""
    return [*DESIGN_COLUMNS, *(c for c in COLD_COLUMNS if c in designs)]


@dataclass(frozen=True)
class DayStorage:
    """A day's study with its buffer (:func:`day_storage`).

    Attributes
    ----------
    storage : foldopt.inputs.storage_section.Storage
    designs : pandas.DataFrame
        Per design of the summary, in its order: ``design``, ``fold_angle_deg``, ``t_solar_h``
        and :func:`day_columns`' columns.
    powered_by_angle : numpy.ndarray
        Powered time [h] of the twofold panel at each fold angle of the grid.
    fold_angle_deg : float
        The grid's fold angle with the longest powered time (ties to the least folded).
    near_optimal : dict
        :func:`foldopt.studies.objectives.near_optimal` of powered time over the grid, with
        ``recommended_powered_h``.
    soc : dict
        Design of :data:`SOC_DESIGNS` -> state of charge [-] at each step centre, (n_steps,).
    soc_hours : dict
        Design -> hours a day [h] the state of charge spends in each tenth (0-10 %, ...,
        90-100 %), as PVGIS's histogram, (10,).
    sizing : Sizing
    engine : str
        The engine the buffer was simulated on ('numba' or 'numpy').
    converged : bool
        Whether every series reached its periodic state (or started from ``initial_soc``).
    series : foldopt.engine.storage.StorageResult
        The designs' day with the buffer, in ``designs``' order: its energies, net trackers'
        with their own draw served.
    design_space : pandas.DataFrame or None
        With the study's ``costs``: the least-cost search's table
        (:func:`foldopt.studies.least_cost.day_design_space`).
    """

    storage: object
    designs: pd.DataFrame
    powered_by_angle: np.ndarray
    fold_angle_deg: float
    near_optimal: dict
    soc: dict
    soc_hours: dict
    sizing: Sizing
    engine: str
    converged: bool
    series: StorageResult
    design_space: pd.DataFrame | None = None


class BufferedDesigns(NamedTuple):
    """A day's designs as its buffer takes them (:func:`day_storage`), in the summary's order.

    Attributes
    ----------
    fold_angle_deg : dict
        Design -> its fold angle [deg] (NaN: a tracker).
    power : dict
        Design -> the curve its ``t_solar`` was reduced from [W], (n_steps,); a net tracker's
        whole power, its own draw in ``draws``.
    t_solar_h : numpy.ndarray
        Each design's ``t_solar`` [h] without the buffer, (n_designs,).
    draws : dict
        Design -> its own draw [W], (n_steps,): a net tracker's drive
        (:func:`foldopt.engine.storage.simulate`'s ``draw``); none for the others.
    """

    fold_angle_deg: dict
    power: dict
    t_solar_h: np.ndarray
    draws: dict


def day_storage(
    study,
    designs: BufferedDesigns,
    *,
    fold_angles,
    grid_power,
    load,
    step_hours: float,
    engine: str,
    temp_air=None,
) -> DayStorage:
    """Simulate a day's study's buffer for every design it compares, and size it.

    Parameters
    ----------
    study : foldopt.Study
        With a ``storage`` section.
    designs : BufferedDesigns
    fold_angles : array_like
        The grid's fold angles [deg], (k,).
    grid_power : numpy.ndarray
        The twofold panel's power at each, the study's connection [W], (k, n_steps).
    load : float or numpy.ndarray
        The load [W], or its curve (1, n_steps) under a load profile.
    step_hours : float
    engine : str
    temp_air : numpy.ndarray, optional
        The air temperature of the day's steps [C], (n_steps,): the buffer's temperature acts
        (:func:`foldopt.studies.storage_cold.cold_steps`); default none.

    Returns
    -------
    DayStorage
    """
    import pandas as pd

    storage = study.storage
    fold_angles = np.asarray(fold_angles, dtype=float)
    buffer = buffer_of(storage)
    engine = storage_engine(engine)
    names, power, draws = list(designs.power), designs.power, designs.draws
    cold = None if temp_air is None else cold_steps(storage, temp_air)

    def own(names):
        # The designs' own draws, none for most (a draw of 0 W is none, to the bit).
        if not any(name in draws for name in names):
            return None
        zero = np.zeros(np.shape(power[names[0]]))
        return np.vstack([draws.get(name, zero) for name in names])

    every = np.vstack(list(power.values()))
    result = simulate(every, load, buffer, step_hours, engine, draw=own(names), cold=cold)
    soc = simulate(
        np.vstack([power[name] for name in SOC_DESIGNS]),
        load,
        buffer,
        step_hours,
        engine,
        soc_curves=True,
        draw=own(SOC_DESIGNS),
        cold=cold,
    )
    grid = simulate(grid_power, load, buffer, step_hours, engine, cold=cold)
    by_angle = grid.powered_h[:, 0]
    near = {
        key: float(value)
        for key, value in near_optimal(fold_angles, by_angle, study.near_optimal).items()
    }
    best = int(best_angle_index(by_angle))
    recommended = near["recommended_deg"]
    near["recommended_powered_h"] = (
        float(by_angle[fold_angles == recommended][0]) if recommended == recommended else np.nan
    )
    table = pd.DataFrame(
        {
            "design": names,
            "fold_angle_deg": list(designs.fold_angle_deg.values()),
            "t_solar_h": np.asarray(designs.t_solar_h, dtype=float),
            **day_columns(result),
        }
    )
    if cold is not None:
        # What the cold costs each design, beside the same day with the cold off.
        warm = simulate(every, load, buffer, step_hours, engine, draw=own(names))
        table["cold_lost_h"] = warm.powered_h[:, 0] - result.powered_h[:, 0]
        for key, value in charge_blocked(storage, temp_air, step_hours).items():
            table[key] = value
    step = max(1, -(-fold_angles.size // SIZING_ANGLES))
    compared = np.union1d(fold_angles[::step], [fold_angles[best]])

    def sized(steps):
        return size_buffers(
            {
                **{name: power[name] for name in ("flat", "tracker", "tracker-net")},
                "twofold": grid_power[np.searchsorted(fold_angles, compared)],
            },
            compared,
            own=fold_angles[best],
            load=load,
            storage=storage,
            step_hours=step_hours,
            engine=engine,
            tolerance=study.near_optimal,
            draws={name: draw for name, draw in draws.items() if name == "tracker-net"},
            cold=steps,
        )

    sizing = sized(cold)
    if cold is not None and len(sizing.table):
        sizing.table["capacity_cold_off_wh"] = sized(None).table["capacity_wh"].to_numpy()
    space = None
    if study.costs is not None:
        space = day_design_space(
            study,
            power,
            (fold_angles, grid_power, fold_angles[best]),
            load,
            step_hours=step_hours,
            engine=engine,
            draw=draws.get("tracker-net"),
            cold=cold,
        )
    return DayStorage(
        storage=storage,
        designs=table,
        powered_by_angle=by_angle,
        fold_angle_deg=float(fold_angles[best]),
        near_optimal=near,
        soc={name: soc.soc[i, 0] for i, name in enumerate(SOC_DESIGNS)},
        soc_hours=dict(zip(names, result.soc_hours.mean(axis=1), strict=True)),
        sizing=sizing,
        engine=engine,
        converged=bool(result.converged.all() and grid.converged.all()),
        series=result,
        design_space=space,
    )


#: The designs a year's buffer is simulated for: the twofold panel at the angle ``t_solar``'s
#: objective keeps all year, and at the one the objective of powered time keeps
#: (``twofold-buffer``, :func:`powered_by_angle`).
YEAR_DESIGNS = ("flat", "twofold", "twofold-buffer", "tracker", "tracker-net")


def _year_series(power, load, in_sequence: bool, draw=None, cold=None):
    """Series of (rows, days, steps) curves, their load, their own draw (or None) and the days'
    :class:`~foldopt.engine.storage.ColdSteps` (fields (days, steps) of every row, or None) as
    :func:`~foldopt.engine.storage.simulate` takes them: the days in sequence, or each day its
    own periodic series."""
    if in_sequence:
        return power, load, draw, cold
    series = power.reshape(-1, 1, power.shape[-1])
    return (
        series,
        load if np.ndim(load) == 0 else load.reshape(series.shape),
        None if draw is None else draw.reshape(series.shape),
        per_series(cold, lambda field: np.broadcast_to(field, power.shape).reshape(series.shape)),
    )


class YearDays(NamedTuple):
    """An annual group's days as a buffer runs over them (:func:`year_storage`,
    :func:`powered_by_angle`).

    Attributes
    ----------
    loads : numpy.ndarray
        (n_loads,) [W], or a load profile's scales.
    load_shape : numpy.ndarray or None
        A load profile's shape per day, (n_days, n_steps).
    dates : sequence of datetime.date
        (n_days,) the days, in order.
    step_hours : float
    weather : bool
        The days are a weather file's: where they follow each other the buffer carries over from
        day to day, starting from the state at the last one's end (:func:`sequential`); else
        each day is a clear-sky day repeated to its own periodic state.
    """

    loads: np.ndarray
    load_shape: np.ndarray | None
    dates: tuple
    step_hours: float
    weather: bool

    @property
    def in_sequence(self) -> bool:
        """Whether the buffer carries over from day to day (:func:`sequential`)."""
        return sequential(self.dates, self.weather)

    def load(self, p_load: float, shape: tuple):
        """The load [W] of one load of :attr:`loads` over curves of ``shape`` (..., n_days,
        n_steps): the load itself, or its profile's curve."""
        return (
            p_load if self.load_shape is None else p_load * np.broadcast_to(self.load_shape, shape)
        )


def powered_by_angle(storage, days: YearDays, chunks, *, engine: str, temp_air=None) -> np.ndarray:
    """Daily powered time of the twofold panel at every fold angle of a grid over an annual group's
    days, a chunk of angles at a time (their curves are the memory).

    Parameters
    ----------
    storage : foldopt.inputs.storage_section.Storage
    days : YearDays
    chunks : iterable of numpy.ndarray
        The power [W] of consecutive angles of the grid, (k, n_days, n_steps) each.
    engine : str
    temp_air : numpy.ndarray, optional
        The air temperature [C] of the days' steps, (n_days, n_steps): the buffer's temperature
        acts (:func:`foldopt.studies.storage_cold.cold_steps`); default none.

    Returns
    -------
    numpy.ndarray
        (n_days, n_loads, n_angles) [h]; a series with no periodic state counts its last pass.
    """
    engine = storage_engine(engine)
    in_sequence = days.in_sequence
    buffer = buffer_of(storage)
    cold = None if temp_air is None else cold_steps(storage, temp_air)
    hours = []
    for power in chunks:
        per_load = []
        for p_load in np.asarray(days.loads, dtype=float):
            series, load, _, steps = _year_series(
                power, days.load(p_load, power.shape), in_sequence, cold=cold
            )
            result = simulate(series, load, buffer, days.step_hours, engine, cold=steps)
            per_load.append(result.powered_h.reshape(power.shape[:2]))
        hours.append(np.stack(per_load))  # (loads, k, days)
    return np.concatenate(hours, axis=1).transpose(2, 0, 1)


class YearChoice(NamedTuple):
    """What a year's buffer table says beside its numbers (:func:`year_storage`).

    Attributes
    ----------
    site : foldopt.inputs.sections.Site
        The group's.
    objective : foldopt.inputs.sections.Objective
    fold_angle_deg : dict
        Design of :data:`YEAR_DESIGNS` -> (n_loads,) [deg] (NaN for a tracker).
    near : dict
        :func:`foldopt.studies.objectives.near_optimal` of the objective of powered time over the
        grid, (n_loads,) each: the ``twofold-buffer`` row's.
    """

    site: object
    objective: object
    fold_angle_deg: dict
    near: dict


class YearStorage(NamedTuple):
    """A buffer over an annual group's days (:func:`year_storage`): the tables of the run.

    Attributes
    ----------
    storage_annual : pandas.DataFrame
        Per load and design, over every day.
    storage_years : pandas.DataFrame
        Per load, design and calendar year
        (:func:`~foldopt.studies.storage_periods.storage_years`).
    storage_monthly : pandas.DataFrame
        Per load, design and calendar month, in PVGIS's names
        (:func:`~foldopt.studies.storage_periods.storage_monthly`).
    """

    storage_annual: pd.DataFrame
    storage_years: pd.DataFrame
    storage_monthly: pd.DataFrame


def year_storage(
    storage,
    days: YearDays,
    curves: dict,
    choice: YearChoice,
    *,
    engine: str,
    draws=None,
    temp_air=None,
) -> YearStorage:
    """A buffer over an annual group's days, per load and design.

    Parameters
    ----------
    storage : foldopt.inputs.storage_section.Storage
    days : YearDays
    curves : dict
        Design of :data:`YEAR_DESIGNS` -> power [W], (n_days, n_loads, n_steps) or, the same for
        every load, (n_days, n_steps).
    choice : YearChoice
    engine : str
    draws : dict, optional
        Design -> its own draw [W], (n_days, n_steps): ``tracker-net``'s drive, whose power in
        ``curves`` is then its whole power (:func:`foldopt.engine.storage.simulate`'s ``draw``).
    temp_air : numpy.ndarray, optional
        The air temperature [C] of the days' steps, (n_days, n_steps): the buffer's temperature
        acts (:func:`foldopt.studies.storage_cold.cold_steps`); default none.

    Returns
    -------
    YearStorage
        Its ``storage_annual``, per load and design: ``site_name``, ``latitude``, ``longitude``,
        ``p_load_w``, ``design``, ``fold_angle_deg``, ``days``, ``objective`` (the statistic),
        ``powered_objective_h`` (of the daily powered time), ``powered_mean_h``,
        ``powered_min_h``, ``t_solar_mean_h`` (of the same curves, with no buffer: the 0 Wh
        run) and :func:`day_columns`' ``availability_pct``, ``powered_days_ge24h_pct``,
        ``energy_missing_wh``, ``energy_lost_wh`` (a day, the days' mean), ``days_full_pct``,
        ``days_empty_pct``; ``converged`` where every series found its periodic state; with
        ``storage.target``, ``capacity_wh``, the smallest buffer reaching it over the days
        (:func:`~foldopt.studies.storage_sizing.smallest_buffers`; NaN: none up to the grid's
        top; over several calendar years, in ``storage.target.years`` of them),
        ``capacity_gain_vs_flat_pct`` and ``monotone``; the near-optimal range of
        ``twofold-buffer`` (NaN in the other rows). Where the buffer's temperature acts, what
        the cold costs: ``charge_blocked_h`` and ``charge_blocked_days_n`` (the days', every
        row's), :func:`~foldopt.studies.storage_cold.cold_columns` beside the same run with the
        cold off, and with ``storage.target`` ``capacity_cold_off_wh`` (the smallest buffer with
        the cold off). Its ``storage_years`` and ``storage_monthly``, the same days' simulation
        by period.
    """
    import pandas as pd

    engine = storage_engine(engine)
    loads = np.asarray(days.loads, dtype=float)
    in_sequence, step_hours = days.in_sequence, days.step_hours
    objective, site = choice.objective, choice.site
    months = [date.month for date in days.dates]
    cold = None if temp_air is None else cold_steps(storage, temp_air)
    years = [date.year for date in days.dates]
    rows, per_year, per_month = [], [], []
    for index, p_load in enumerate(loads):
        power = np.stack(
            [curves[d] if curves[d].ndim == 2 else curves[d][:, index] for d in YEAR_DESIGNS]
        )  # (designs, days, steps)
        own = (
            np.stack([draws.get(d, np.zeros(power.shape[1:])) for d in YEAR_DESIGNS])
            if draws
            else None
        )
        series, load, draw, steps = _year_series(
            power, days.load(p_load, power.shape), in_sequence, own, cold
        )
        # The state of charge at every step is the monthly table's histogram.
        result = simulate(
            series,
            load,
            buffer_of(storage),
            step_hours,
            engine,
            draw=draw,
            cold=steps,
            soc_curves=True,
        )
        bare = simulate(
            series, load, buffer_of(storage, capacity_wh=0.0), step_hours, engine, draw=draw
        )
        shape = (len(YEAR_DESIGNS), -1)
        if not in_sequence:
            result = _by_design(result, len(YEAR_DESIGNS))
            bare = _by_design(bare, len(YEAR_DESIGNS))
        powered = result.powered_h.reshape(shape)
        costs = {}
        if cold is not None:
            warm = simulate(series, load, buffer_of(storage), step_hours, engine, draw=draw)
            if not in_sequence:
                warm = _by_design(warm, len(YEAR_DESIGNS))
            costs = {
                **charge_blocked(storage, temp_air, step_hours),
                **cold_columns(powered, warm.powered_h.reshape(shape), months),
            }
        sized = {}
        if storage.target is not None:
            # Each design's smallest buffer for the target over the days (a load profile's day
            # by day), and with the cold off where it acts.
            def smallest(steps):
                return smallest_buffers(
                    power,
                    p_load if days.load_shape is None else p_load * days.load_shape[None],
                    storage,
                    step_hours,
                    engine,
                    in_sequence,
                    None if own is None else list(own),
                    cold=steps,
                    # A clear sky's days are no real years: the days as one, whatever their dates.
                    years=years if days.weather else None,
                )

            need, monotone = smallest(cold)
            if cold is not None:
                costs["capacity_cold_off_wh"] = smallest(None)[0]
            with np.errstate(invalid="ignore", divide="ignore"):
                vs_flat = (need / need[0] - 1.0) * 100.0 if need[0] > 0 else np.nan * need
            sized = {
                "capacity_wh": need,
                "capacity_gain_vs_flat_pct": vs_flat,
                "monotone": monotone,
            }
        score = objective_value(powered.T, months, objective.statistic, objective.months)
        angles = np.array([choice.fold_angle_deg[d][index] for d in YEAR_DESIGNS])
        chosen = np.asarray(YEAR_DESIGNS) == "twofold-buffer"
        keys = pd.DataFrame(
            {
                "site_name": site.name or "",
                "latitude": site.latitude,
                "longitude": site.longitude,
                "p_load_w": p_load,
                "design": YEAR_DESIGNS,
                "fold_angle_deg": angles,
            }
        )
        per_year.append(storage_years(keys, result, days.dates))
        per_month.append(storage_monthly(keys, result, days.dates, storage.min_soc, step_hours))
        rows.append(
            keys.assign(
                **{
                    "days_n": powered.shape[1],
                    "objective": objective.statistic,
                    "powered_objective_h": score,
                    "powered_mean_h": powered.mean(axis=1),
                    "powered_min_h": powered.min(axis=1),
                    "t_solar_mean_h": bare.powered_h.reshape(shape).mean(axis=1),
                    **{k: v for k, v in day_columns(result).items() if k != "powered_h"},
                    "converged": result.converged.reshape(shape[0], -1).all(axis=1),
                    **sized,
                    **costs,
                    **{
                        key: np.where(chosen, value[index], np.nan)
                        for key, value in choice.near.items()
                    },
                }
            )
        )
    return YearStorage(
        *(pd.concat(frames, ignore_index=True) for frames in (rows, per_year, per_month))
    )


def sequential(dates, weather: bool) -> bool:
    """Whether a buffer carries over from day to day: a weather file's days that follow each
    other (a clear sky's days are each repeated to their own periodic state)."""
    days = np.asarray([date.toordinal() for date in dates])
    return bool(weather and (np.diff(days) == 1).all())


def _by_design(result: StorageResult, designs: int) -> StorageResult:
    """A result of (designs x days) one-day series as (designs, days) series of days."""
    return result._replace(
        **{
            name: getattr(result, name).reshape(designs, -1, *getattr(result, name).shape[2:])
            for name in (
                "powered_h",
                "served_wh",
                "missing_wh",
                "lost_wh",
                "full",
                "empty",
                "soc_hours",
                *(("soc",) if result.soc is not None else ()),
            )
        },
        passes=np.where(
            (result.passes.reshape(designs, -1) > 0).all(axis=1),
            1,
            -1,
        ),
    )
