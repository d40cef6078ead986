"""Sweeps: many sites, days, loads and designs, as one tidy table.

The cases of a plan are blocks of skies (:mod:`foldopt.engine.sky`): cases that share everything but the
site, the date and the load share one sky and one engine call, in chunks of bounded size. The
designs come from :mod:`foldopt.studies.designs`: every (case, fold angle) row gets ``t_solar`` for all
loads in one pass; the best angle per case and load is the best point of the grid (no local
refinement, which a single-study run adds), with its near-optimal range, and its full metrics come
from a second, targeted pass. With an objective, one fold angle serves all the days of a case (an
annual group), and the group's objective per design, in its own terms, is a table of its own.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import json
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from foldopt.engine import evaluation as engines
from foldopt.inputs.plan import Plan
from foldopt.studies.designs import (
    PLANES_DESIGN,
    DESIGNS,
    Blocks,
    design_metrics,
    fold_hours,
    setup_key,
    tracker_curves,
)
from foldopt.studies.objectives import (
    ENSEMBLE_PERCENTILES,
    best_angle_index,
    ensemble_choice,
    near_optimal,
    objective_value,
    season_days,
    worst_month,
)
from foldopt.engine.metrics import notes, relative_to
from foldopt.engine.sky import Sky
from foldopt.physics.spa import SunTerms
from foldopt.studies.series import series_refused, year_piece, year_series
from foldopt.studies.least_cost import search_angles, year_design_space
from foldopt.studies.storage_cold import cold_steps, sky_air_temperature
from foldopt.studies.storage_days import (
    YearChoice,
    YearDays,
    powered_by_angle,
    storage_engine,
    year_storage,
)
from foldopt.names import DEFAULT_ENGINE, FLAT_FOLD_ANGLE


@dataclass(frozen=True)
class SweepResult:
    """A plan and its tidy table: one row per case x design."""

    plan: Plan
    table: pd.DataFrame
    # day x hour curves of an annual objective
    extras: dict = dataclasses.field(default_factory=dict)
    engine: str = DEFAULT_ENGINE
    weather_light: dict | None = None  # a weather file's irradiation and what the steps keep of it
    request: object = None  # the foldopt.studies.request.Request the plan came from, if any
    weather_notes: tuple = ()  # what reading a measured weather file did (foldopt.engine.sky.Sky.weather_notes)
    # Every step of a study over many days at each case's fold angle (foldopt.studies.series)
    timeseries: pd.DataFrame | None = None
    timeseries_note: str = ""  # why a study over many days has none (foldopt.studies.series)

    @functools.cached_property
    def answer(self):
        """The :class:`foldopt.studies.answer.Answer` every view of this result renders."""
        from foldopt.studies.result_answers import of_sweep

        return of_sweep(self)

    @property
    def varied(self) -> list[str]:
        """Table columns that vary across cases."""
        columns = [
            c for c in CASE_COLUMNS if c in self.table and self.table[c].nunique(dropna=False) > 1
        ]
        extra = [
            path for path, values in self.plan.axes if path not in _AXIS_COLUMNS and len(values) > 1
        ]
        return columns + extra


CASE_COLUMNS = ("site_name", "latitude", "longitude", "date", "dayofyear", "p_load_w")
#: Axes whose values the case columns above already show.
_AXIS_COLUMNS = frozenset(
    {"site", "site.name", "site.latitude", "site.longitude", "date", "p_load"}
)


def run_plan(
    plan: Plan,
    progress: Callable[[int, int], None] | None = None,
    engine: str = DEFAULT_ENGINE,
    request=None,
) -> SweepResult:
    """Evaluate every case of a plan: flat, optimal twofold and tracker per case.

    Parameters
    ----------
    plan : Plan
    progress : callable, optional
        Called as ``progress(done, total)`` with the days done so far, counted once per case
        (an annual objective passes over each day twice: halves count).
    engine : {'auto', 'numba', 'numpy'}
        :data:`foldopt.engine.evaluation.ENGINES`.
    request : foldopt.studies.request.Request, optional
        The request the plan was made from: what the answer says it took from the study.

    Returns
    -------
    SweepResult
        Columns: the case (``site_name``, ``latitude``, ``longitude``, ``date``, ``dayofyear``,
        ``p_load_w`` and any other swept field by its path), ``design``, ``fold_angle_deg`` and the
        daily metrics, ``gain_vs_flat_pct``, ``share_of_tracker_pct`` and ``note``
        (:func:`foldopt.engine.metrics.notes`: polar night, polar day, overcast, load above peak).
    """
    axes = dict(plan.axes)
    # The validated study's load: a load profile's scale defaults to 1 where the data leave it out.
    loads = np.asarray(axes.pop("p_load", (plan.base.p_load,)), dtype=float)
    objective = plan.base.objective
    dates = axes.pop("date", None) if objective is not None else None
    weather = plan.base.weather
    if objective is not None and dates is None and weather is not None and weather.members:
        dates = (plan.base.date,)  # one day's cloud ensemble: one fold angle over its members
    paths = list(axes)
    choices = [
        dict(zip(paths, values, strict=True)) for values in itertools.product(*axes.values())
    ]
    # A fixed panel keeps one fold angle all year: an annual group is the dates of one choice.
    studies = [
        plan.study({**choice, "p_load": float(loads[0]), **({"date": dates[0]} if dates else {})})
        for choice in choices
    ]
    passes = 2 if dates else 1  # an annual group: find the angle over the days, then evaluate them
    total = len(choices) * (len(dates) if dates else 1)
    done = 0

    def advance(count):
        nonlocal done
        done += count
        if progress is not None:
            progress(done / passes, total)

    results: list = [None] * len(choices)
    extras: dict = {}
    light: dict = {}

    weather_notes: dict = {}

    sun_terms = SunTerms()  # the run's skies share SPA's time-only terms

    def sky_of(blocks: Blocks) -> Sky:
        """The blocks' sky, its weather's balance and notes counted for the run."""
        sky = blocks.sky(sun_terms)
        for key, (total, kept) in (sky.weather_balance or {}).items():
            light[key] = np.add(light.get(key, (0.0, 0.0)), (total, kept))
        weather_notes.update(dict.fromkeys(sky.weather_notes))
        return sky

    # A study over many days (a cloud ensemble's members have no series of their own) has its
    # series, if not too long to hold.
    series: list = []
    many_days = bool(dates or "date" in axes) and not (weather is not None and weather.members)
    refused = series_refused(total * loads.size * round(1440 / plan.base.step_min))
    with_series = many_days and not refused
    if dates:
        refolds: dict[str, list] = {}
        for index, study in enumerate(studies):
            results[index], group_extras = _annual_group(
                Blocks.of_dates(study, dates),
                loads,
                objective,
                advance,
                engine,
                sky_of,
                with_series,
            )
            if "series" in group_extras:
                series.append(
                    group_extras.pop("series").assign(
                        **{
                            path: _plain(value)
                            for path, value in choices[index].items()
                            if path not in _AXIS_COLUMNS
                        }
                    )
                )
            extras = extras or group_extras
            for key in GROUP_TABLES:
                if key in group_extras:
                    refolds.setdefault(key, []).append(
                        group_extras[key].assign(
                            **{
                                path: _plain(value)
                                for path, value in choices[index].items()
                                if path not in _AXIS_COLUMNS
                            }
                        )
                    )
        extras.update(
            {key: pd.concat(frames, ignore_index=True) for key, frames in refolds.items()}
        )
        cases = [
            (study.site, date, choice)
            for study, choice in zip(studies, choices, strict=True)
            for date in dates
        ]
    else:
        # Cases of one setup share skies and engine calls, whatever their order in the plan. A
        # sweep of days writes their series, each day at its own best angle.
        over_days = with_series
        pieces: list = [None] * len(choices)
        zones = []
        setups: dict[str, list[int]] = {}
        for index, study in enumerate(studies):
            setups.setdefault(setup_key(study), []).append(index)
        for members in setups.values():
            blocks = Blocks.of([studies[i] for i in members])
            for part in blocks.chunks(loads.size):
                chunk = blocks[part]
                sky = sky_of(chunk)
                fold_angles, hours, _ = fold_hours(sky, chunk, loads, engine)
                hours = hours.transpose(0, 2, 1)  # (blocks, loads, angles)
                best = best_angle_index(hours)
                tracker = tracker_curves(sky, chunk.study, every=chunk.members, engine=engine)
                metrics = design_metrics(
                    sky,
                    chunk,
                    loads,
                    fold_angles,
                    best,
                    engine,
                    tracker,
                    curves=over_days,
                    curve_outputs=("east", "west"),
                )
                if over_days:
                    zones.append(sky.grid.timezones[0])
                    curves = metrics.pop("curves")
                    every = engines.fold_orientations(
                        chunk.study.geometry, chunk.tilt, chunk.azimuth, fold_angles
                    )
                    piece = year_piece(
                        sky,
                        np.take_along_axis(every, best[..., None], axis=1),
                        loads,
                        fold_angles[best],
                        {**curves, "twofold": curves[chunk.study.connection]},
                        tracker.power,
                    )
                    for offset, index in enumerate(members[part]):
                        pieces[index] = {
                            name: values[offset : offset + 1] for name, values in piece.items()
                        }
                metrics.update(
                    _twofold_only(near_optimal(fold_angles, hours, chunk.study.near_optimal))
                )
                for offset, index in enumerate(members[part]):
                    results[index] = {
                        name: values[offset : offset + 1] for name, values in metrics.items()
                    }
                advance(len(chunk))
        cases = [
            (study.site, study.date, choice) for study, choice in zip(studies, choices, strict=True)
        ]
        if over_days:
            # Local times where the sites share a time zone; UTC where they do not.
            series.append(
                year_series(pieces, zones[0] if len(set(map(str, zones))) == 1 else "UTC")
            )
    table = _table(
        cases, loads, {name: np.concatenate([r[name] for r in results]) for name in results[0]}
    )
    kept = {
        key: {"file_wh_m2": float(total), "kept_pct": float(100 * kept / total) if total else 100.0}
        for key, (total, kept) in light.items()
    } or None
    return SweepResult(
        plan,
        table,
        extras,
        engine,
        kept,
        request,
        tuple(weather_notes),
        timeseries=pd.concat(series) if series else None,
        timeseries_note=refused if many_days else "",
    )


def _annual_group(blocks: Blocks, loads, objective, advance, engine, sky_of, with_series=True):
    """One fold angle per load for all the days of a group: the one that maximises the objective
    over the days' t_solar at every angle. Returns the group's metrics and its day x hour curves
    (and, ``with_series``, its time series)."""
    parts = blocks.chunks(loads.size)
    skies, daily = [], []
    sample: dict = {}
    # The existing array's planes as they stand (panel.planes), beside the grid's angles.
    planes = blocks.study.planes_design()
    planes_days = []
    for part in parts:
        skies.append(sky_of(blocks[part]))
        _keep_sample(sample, skies[-1], blocks[part], blocks.members)
        fold_angles, hours, _ = fold_hours(skies[-1], blocks[part], loads, engine)
        daily.append(hours)
        if planes is not None:
            planes_days.append(
                fold_hours(skies[-1], blocks[part], loads, engine, [planes["fold_angle"]])[1:]
            )
        advance(len(blocks[part]) // blocks.members)
    members = blocks.members
    months = [date.month for date in blocks.dates[::members]]
    # (blocks, loads, angles): a day's members together
    daily = np.concatenate(daily).transpose(0, 2, 1)
    study = blocks.study
    ensemble = None
    if members > 1:
        by_member = daily.reshape(len(months), members, *daily.shape[1:]).swapaxes(0, 1)
        ensemble = ensemble_choice(
            by_member, months, objective.statistic, objective.months, study.near_optimal
        )
        score, fixed = ensemble["score"], ensemble["fixed"]
    else:
        score = objective_value(daily, months, objective.statistic, objective.months)
        fixed = best_angle_index(score)  # (n_loads,)
    metrics, series = [], {"p_twofold_w": [], "switch_state": []}
    # A buffer is run over the days on the curves each design's row is reduced from, and the
    # days' time series is drawn from them (a cloud ensemble's members have none of their own).
    buffered = study.storage is not None and members == 1
    drawn: dict = {}
    pieces: list = []
    with_series = with_series and members == 1
    every = (
        engines.fold_orientations(study.geometry, blocks.tilt, blocks.azimuth, fold_angles)
        if with_series
        else None
    )
    for part, sky in zip(parts, skies, strict=True):
        chunk = blocks[part]
        # The day x hour maps of the first load's angle, every day at once.
        # The maps show the first member of each day.
        first = list(range(0, len(chunk), members))
        orientation = engines.fold_orientations(
            study.geometry, chunk.tilt[first], chunk.azimuth[first], fold_angles[fixed[:1]]
        )
        powers, state = engines.powers(
            sky,
            orientation=orientation[:, 0],
            electrical=chunk.options.electrical,
            blocks=first,
            series=study.switch_series,
            with_state=True,
        )
        series["p_twofold_w"].append(powers[study.connection])
        series["switch_state"].append(np.where(powers["switching"] > 0, state, -1))
        tracker = tracker_curves(sky, study, study.tracker.model, every=members, engine=engine)
        metrics.append(
            design_metrics(
                sky,
                chunk,
                loads,
                fold_angles,
                np.broadcast_to(fixed, (sky.n_blocks, loads.size)),
                engine,
                tracker,
                curves=with_series or buffered,
                curve_outputs=("east", "west"),
            )
        )
        if with_series or buffered:
            curves = metrics[-1].pop("curves")
        if with_series:
            pieces.append(
                year_piece(
                    sky,
                    every[part][:, fixed],
                    loads,
                    np.broadcast_to(fold_angles[fixed], (sky.n_blocks, loads.size)),
                    {**curves, "twofold": curves[study.connection]},
                    tracker.power,
                )
            )
        if buffered:
            # The net tracker's whole power, with its own draw a load beside the device's.
            for name, power in (
                ("flat", curves["flat"]),
                ("twofold", curves[study.connection]),
                ("tracker", tracker.power),
                ("tracker-net", tracker.power),
                ("tracker-net-draw", tracker.draw),
            ):
                drawn.setdefault(name, []).append(power)
        advance(len(chunk) // members)
    clock = skies[0].grid.clock_hours[0]
    design_hours = np.concatenate([m["t_solar_h"] for m in metrics])  # (blocks, loads, designs)
    near = near_optimal(fold_angles, score, study.near_optimal)  # each (loads,)
    spread = None
    if ensemble is not None:
        design_hours = design_hours.reshape(len(months), members, *design_hours.shape[1:])
        spread = {
            "member_objective_h": np.stack(
                [
                    objective_value(
                        design_hours[:, m], months, objective.statistic, objective.months
                    )
                    for m in range(members)
                ]
            ),
            **{
                key: ensemble[key]
                for key in ("chosen_wins_pct", "within_tolerance_pct", "regret_h")
            },
        }
        design_hours = design_hours.mean(axis=1)  # (days, loads, designs): the members' mean day
    refold = {
        "annual_objective": objective_table(
            blocks, loads, fold_angles[fixed], design_hours, months, objective, near, spread
        )
    }
    if planes is not None:
        hours = np.concatenate([chunk[0] for chunk in planes_days]).transpose(0, 2, 1)
        table = objective_table(
            blocks,
            loads,
            np.full(loads.size, planes["fold_angle"]),
            hours,
            months,
            objective,
            {},
            designs=(PLANES_DESIGN,),
        )
        table["energy_harvested_wh"] = sum(float(chunk[1].sum()) for chunk in planes_days)
        refold["annual_objective"] = pd.concat(
            [refold["annual_objective"], table], ignore_index=True
        )
    if objective.visits:
        refold.update(
            refold_tables(blocks, loads, fold_angles, daily, months, objective, design_hours)
        )
    extras = {
        **({"series": year_series(pieces, skies[0].grid.timezones[0])} if pieces else {}),
        "dates": list(blocks.dates[::members]),
        "hours": clock,
        "fold_angle": float(fold_angles[fixed[0]]),
        **refold,
        **({"weather_sample": sample} if sample else {}),
        **{key: np.concatenate(value) for key, value in series.items()},
        "by_angle": pd.DataFrame(
            {
                "p_load_w": np.repeat(loads, fold_angles.size),
                "fold_angle_deg": np.tile(fold_angles, loads.size),
                "t_solar_objective_h": score.ravel(),
                "t_solar_mean_h": daily.mean(axis=0).ravel(),
                "t_solar_min_h": daily.min(axis=0).ravel(),
                "chosen": np.ravel(np.arange(fold_angles.size) == fixed[:, None]),
                **({"wins_pct": ensemble["wins_pct"].ravel()} if ensemble is not None else {}),
            }
        ),
    }
    if buffered:
        extras |= _year_buffer(
            blocks,
            parts,
            skies,
            loads,
            objective=objective,
            fold_angles=fold_angles,
            fixed=fixed,
            drawn=drawn,
            engine=engine,
        )
    group = {name: np.concatenate([m[name] for m in metrics]) for name in metrics[0]}
    if members > 1:
        group = _over_members(group, members)
    group.update(
        _twofold_only(
            {key: np.broadcast_to(value, (len(months), loads.size)) for key, value in near.items()}
        )
    )
    return group, extras


#: Bytes of the twofold curves a year's buffer holds at once (a chunk of fold angles' days).
CURVE_BYTES = 100e6


def _year_buffer(blocks, parts, skies, loads, *, objective, fold_angles, fixed, drawn, engine):
    """storage_annual, storage_years and storage_monthly: the buffer over an annual group's days
    for each design, the twofold panel at the angle t_solar's objective keeps and at the one the
    objective of daily powered time keeps, simulated at every angle of the grid (a chunk of
    angles' curves at a time); with the study's costs, design_space
    (:func:`foldopt.studies.least_cost.year_design_space`)."""
    study = blocks.study
    shapes = [sky.load_shape for sky in skies]
    days = YearDays(
        loads=loads,
        load_shape=None if shapes[0] is None else np.concatenate(shapes),
        dates=blocks.dates,
        step_hours=skies[0].step_hours,
        weather=study.weather is not None,
    )
    temp_air = np.concatenate([sky_air_temperature(sky) for sky in skies])  # the buffer's air
    per_angle = len(blocks) * skies[0].n_steps * 8
    size = max(1, int(CURVE_BYTES // per_angle))
    powered = powered_by_angle(
        study.storage,
        days,
        (
            _twofold_curves(blocks, parts, skies, fold_angles[first : first + size], engine)
            for first in range(0, fold_angles.size, size)
        ),
        engine=engine,
        temp_air=temp_air,
    )  # (days, loads, angles)
    months = [date.month for date in blocks.dates]
    score = objective_value(powered, months, objective.statistic, objective.months)
    # To the nanosecond-hour: powered time saturates at 24 h, where the sums' last bits would
    # pick the angle (ties go to the least folded, as for t_solar).
    best = best_angle_index(np.round(score, 9))  # (loads,)
    chosen, which = np.unique(best, return_inverse=True)
    curves = _twofold_curves(blocks, parts, skies, fold_angles[chosen], engine)
    drawn = {name: np.concatenate(power) for name, power in drawn.items()}
    drawn["twofold-buffer"] = curves[which].transpose(1, 0, 2)  # (days, loads, steps)
    own = {"tracker-net": drawn.pop("tracker-net-draw")}
    tracker = np.full(loads.size, np.nan)
    choice = YearChoice(
        site=study.site,
        objective=objective,
        fold_angle_deg={
            "flat": np.full(loads.size, FLAT_FOLD_ANGLE),
            "twofold": fold_angles[fixed],
            "twofold-buffer": fold_angles[best],
            "tracker": tracker,
            "tracker-net": tracker,
        },
        near=near_optimal(fold_angles, score, study.near_optimal),
    )
    tables = year_storage(
        study.storage, days, drawn, choice, engine=engine, draws=own, temp_air=temp_air
    )._asdict()
    if study.costs is not None:
        angles = search_angles(fold_angles, np.concatenate([fold_angles[best], fold_angles[fixed]]))
        tables["design_space"] = year_design_space(
            study.storage,
            study.costs,
            days,
            {name: drawn[name] for name in ("flat", "tracker-net")},
            _twofold_curves(blocks, parts, skies, angles, engine),
            angles,
            area_m2=study.panel.area,
            tracker_model=study.tracker.model,
            engine=storage_engine(engine),
            draw=own["tracker-net"],
            cold=cold_steps(study.storage, temp_air),
        )
    return tables


def _twofold_curves(blocks: Blocks, parts, skies, angles, engine) -> np.ndarray:
    """The twofold panel's power [W] (the study's connection) at ``angles`` over every block of an
    annual group, angle by angle: (n_angles, n_blocks, n_steps)."""
    study = blocks.study
    power = []
    for part, sky in zip(parts, skies, strict=True):
        chunk = blocks[part]
        orientation = engines.fold_orientations(study.geometry, chunk.tilt, chunk.azimuth, angles)
        rows = np.repeat(np.arange(sky.n_blocks), angles.size)
        metrics = engines.row_metrics(
            sky,
            rows=engines.PanelRows(rows, orientation.reshape(-1, 4)),
            loads=np.ones(1),
            electrical=chunk.options.electrical,
            outputs=(study.connection,),
            engine=engine,
            # Kept angle by angle, each angle's days in order.
            curves=np.arange(rows.size).reshape(sky.n_blocks, angles.size).T.ravel(),
        )
        power.append(metrics.power.reshape(angles.size, sky.n_blocks, -1))
    return np.concatenate(power, axis=1)


def _keep_sample(sample: dict, sky: Sky, blocks: Blocks, members: int) -> None:
    """Keep, in ``sample``, the day of a weather study whose light varies most within its hours
    (its first member's): its GHI at every step, every member's, and its hourly means, for the
    report's figure of the minutes (:mod:`foldopt.output.figures.weather`)."""
    weather = blocks.study.weather
    if weather is None or sky.ghi is None:
        return
    per_hour = round(1.0 / sky.step_hours)
    first = sky.ghi[::members].reshape(-1, 24, per_hour)
    spread = first.std(axis=-1).mean(axis=-1)
    day = int(np.argmax(spread))
    if sample and spread[day] <= sample["spread"]:
        return
    sample.update(
        spread=float(spread[day]),
        date=blocks.dates[day * members].isoformat(),
        hours=sky.grid.clock_hours[day * members],
        ghi=sky.ghi[day * members : (day + 1) * members],
        hourly_ghi=first[day].mean(axis=-1),
        kind="measured" if weather.measured else "members" if members > 1 else "smooth",
    )


def _over_members(group: dict, members: int) -> dict:
    """Each day's metrics over the members of a cloud ensemble (blocks of a day's members together):
    their mean, and the spread of t_solar across members (P10, P50, P90) [h]."""
    out = {}
    for name, values in group.items():
        shaped = values.reshape(values.shape[0] // members, members, *values.shape[1:])
        out[name] = (
            shaped[:, 0] if name in ("condition", "fold_angle_deg") else np.nanmean(shaped, axis=1)
        )
    hours = group["t_solar_h"].reshape(-1, members, *group["t_solar_h"].shape[1:])
    for pct in ENSEMBLE_PERCENTILES:
        out[f"t_solar_members_p{pct}_h"] = np.percentile(hours, pct, axis=1)
    return out


def _twofold_only(values: dict) -> dict:
    """Per-block-and-load values of the twofold panel (blocks, loads) as per-design arrays
    (blocks, loads, designs), NaN for the other designs."""
    out = {}
    for key, value in values.items():
        full = np.full(np.shape(value) + (len(DESIGNS),), np.nan)
        full[..., DESIGNS.index("twofold")] = value
        out[key] = full
    return out


def objective_table(
    blocks: Blocks,
    loads,
    fold_angles,
    design_hours,
    months,
    objective,
    near,
    spread: dict | None = None,
    *,
    designs=DESIGNS,
) -> pd.DataFrame:
    """The objective of one annual group in its own terms, per load and design: the statistic, its
    value [h], for ``worst-month`` the month it is found in, the mean daily t_solar [h], the fold
    angle kept all year and, for the twofold panel, the near-optimal range and recommended angle
    (:func:`foldopt.studies.objectives.near_optimal`).

    Parameters
    ----------
    blocks : Blocks
        The group's days (its study names the site).
    loads : array_like
        (n_loads,) [W].
    fold_angles : array_like
        (n_loads,) the twofold panel's fold angle kept all year [deg].
    design_hours : numpy.ndarray
        (days, loads, designs) daily t_solar [h] in the order of ``designs``.
    months : array_like
        (days,) month of each day.
    objective : Objective
        The statistic and season.
    near : dict of numpy.ndarray
        The twofold panel's :func:`foldopt.studies.objectives.near_optimal`, (n_loads,) each.
    spread : dict, optional
        Over a cloud ensemble: ``member_objective_h`` (members, loads, designs), each member's
        objective, whose mean is the objective and whose P10/P50/P90 the table adds; and the
        twofold panel's ``chosen_wins_pct`` and ``within_tolerance_pct`` (loads,)
        (:func:`foldopt.studies.objectives.ensemble_choice`). ``design_hours`` is then the
        members' mean day.
    designs : sequence of str, default :data:`DESIGNS`
        The designs of ``design_hours``; a twofold one (the planes of an existing array,
        :data:`foldopt.studies.designs.PLANES_DESIGN`) kept at ``fold_angles``.

    Returns
    -------
    pandas.DataFrame
        One row per load and design.
    """
    statistic = objective.statistic
    values = objective_value(design_hours, months, statistic, objective.months)  # (loads, designs)
    if spread is not None:
        values = spread["member_objective_h"].mean(axis=0)
        quantiles = {
            pct: np.percentile(spread["member_objective_h"], pct, axis=0)
            for pct in ENSEMBLE_PERCENTILES
        }
    season = season_days(months, objective.months)
    month = (
        worst_month(design_hours[season], np.asarray(months)[season])
        if statistic == "worst-month"
        else None
    )
    site = blocks.study.site
    rows = []
    for index, load in enumerate(loads):
        for d, design in enumerate(designs):
            twofold = design == "twofold"
            rows.append(
                {
                    "site_name": site.name or "",
                    "latitude": site.latitude,
                    "longitude": site.longitude,
                    "p_load_w": float(load),
                    "design": design,
                    "objective": statistic,
                    "t_solar_objective_h": float(values[index, d]),
                    "worst_month": int(month[index, d]) if month is not None else np.nan,
                    "t_solar_mean_h": float(design_hours[season][:, index, d].mean()),
                    "fold_angle_deg": float(fold_angles[index])
                    if design.startswith("twofold")
                    else (FLAT_FOLD_ANGLE if design == "flat" else np.nan),
                    **{
                        key: float(value[index]) if twofold else np.nan
                        for key, value in near.items()
                    },
                }
            )
            if spread is not None:
                rows[-1].update(
                    {
                        f"t_solar_objective_members_p{pct}_h": float(q[index, d])
                        for pct, q in quantiles.items()
                    }
                )
                rows[-1].update(
                    {
                        key: float(spread[key][index]) if twofold else np.nan
                        for key in ("chosen_wins_pct", "within_tolerance_pct")
                    }
                )
    return pd.DataFrame(rows)


def _table(cases, loads, metrics) -> pd.DataFrame:
    """The tidy table: per case (site, date, axis choice), load and design, in that order."""
    n_cases, n_loads, n_designs = len(cases), loads.size, len(DESIGNS)
    repeat = n_loads * n_designs
    columns = {}
    case_rows = [_case(*case) for case in cases]
    for name in case_rows[0]:
        columns[name] = np.repeat(np.array([row[name] for row in case_rows], dtype=object), repeat)
    columns["p_load_w"] = np.tile(np.repeat(loads, n_designs), n_cases)
    columns["design"] = np.tile(np.array(DESIGNS, dtype=object), n_cases * n_loads)
    columns["fold_angle_deg"] = metrics["fold_angle_deg"].ravel()
    hours = metrics["t_solar_h"]
    for name in metrics:
        if name not in ("fold_angle_deg", "condition"):
            columns[name] = metrics[name].ravel()
    columns["gain_vs_flat_pct"] = ((relative_to(hours, hours[..., :1]) - 1.0) * 100.0).ravel()
    columns["share_of_tracker_pct"] = (relative_to(hours, hours[..., 2:3]) * 100.0).ravel()
    columns["note"] = notes(metrics["condition"], hours).ravel()
    table = pd.DataFrame(columns)
    for name in case_rows[0]:
        table[name] = table[name].infer_objects()
    return table


def _case(site, date, choice: dict) -> dict:
    return {
        "site_name": site.name or "",
        "latitude": site.latitude,
        "longitude": site.longitude,
        "date": date.isoformat(),
        "dayofyear": date.timetuple().tm_yday,
        **{path: _plain(value) for path, value in choice.items() if path not in _AXIS_COLUMNS},
    }


def _plain(value):
    """A case's value as a table cell: a date in ISO form, a section (``circuit: [{...}, ...]``) as
    compact JSON, which a CSV reader can parse back."""
    if isinstance(value, (dict, list, tuple)):
        return json.dumps(value, separators=(", ", ": "), default=str)
    return value.isoformat() if hasattr(value, "isoformat") else value


#: The tables of every annual group, one row per load (and design, setting or visit) and group.
GROUP_TABLES = (
    "annual_objective",
    "refold_value",
    "refold_schedule",
    "storage_annual",
    "design_space",
    "storage_years",
    "storage_monthly",
)


def refold_tables(
    blocks: Blocks, loads, fold_angles, daily, months, objective, design_hours
) -> dict:
    """The best re-fold schedules of one annual group (:func:`foldopt.engine.schedule.best_schedules`):

    ``refold_value``, per load and number of settings k: the objective and the mean daily t_solar
    [h], the gain over the single fixed angle [%] and what the k-th setting adds [h], beside the
    flat panel's and the tracker's objective; ``refold_schedule``, per load, k and visit: the date
    and the fold angle set until the next visit (the last runs on over New Year).

    Parameters
    ----------
    blocks : Blocks
        The group's days.
    loads : array_like
        (n_loads,) [W].
    fold_angles : numpy.ndarray
        The fold-angle grid [deg].
    daily : numpy.ndarray
        (days, loads, angles) daily t_solar of the twofold panel [h].
    months : array_like
        (days,) month of each day.
    objective : Objective
        The statistic (``mean`` or ``worst-month``) and the number of visits.
    design_hours : numpy.ndarray
        (days, loads, designs) daily t_solar [h] in :data:`DESIGNS` order.

    Returns
    -------
    dict of pandas.DataFrame
        ``refold_value`` and ``refold_schedule``.
    """
    from foldopt.engine.schedule import best_schedules

    statistic = objective.statistic
    site = blocks.study.site
    where = {"site_name": site.name or "", "latitude": site.latitude, "longitude": site.longitude}
    values, visits = [], []
    for index, load in enumerate(loads):
        schedules = best_schedules(daily[:, index, :], months, objective.visits, statistic)
        flat, tracker = (
            objective_value(design_hours[:, index, d], months, statistic) for d in (0, 2)
        )
        fixed = schedules[0].objective_h
        previous = None
        for k, schedule in enumerate(schedules, start=1):
            chosen = daily[np.arange(len(months)), index, schedule.daily_angles(len(months))]
            values.append(
                {
                    **where,
                    "p_load_w": float(load),
                    "settings_n": k,
                    "objective": statistic,
                    "t_solar_objective_h": schedule.objective_h,
                    "t_solar_mean_h": float(chosen.mean()),
                    "gain_vs_fixed_pct": 100.0 * (schedule.objective_h / fixed - 1.0)
                    if fixed > 0
                    else np.nan,
                    "added_by_setting_h": np.nan
                    if previous is None
                    else schedule.objective_h - previous,
                    "t_solar_flat_objective_h": float(flat),
                    "t_solar_tracker_objective_h": float(tracker),
                }
            )
            previous = schedule.objective_h
            for visit, (start, angle) in enumerate(
                zip(schedule.starts, schedule.angles, strict=True), start=1
            ):
                visits.append(
                    {
                        **where,
                        "p_load_w": float(load),
                        "settings_n": k,
                        "visit": visit,
                        "date": blocks.dates[start].isoformat(),
                        "fold_angle_deg": float(fold_angles[angle]),
                    }
                )
    return {"refold_value": pd.DataFrame(values), "refold_schedule": pd.DataFrame(visits)}
