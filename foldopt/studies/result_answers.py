"""Each kind of result made into its :class:`~foldopt.studies.answer.Answer`: one builder per result
(:func:`of_study` for one day, :func:`of_sweep` for a plan of cases or an annual objective,
:func:`of_sizing`, :func:`of_reproduction`, :func:`of_map`) that reads the result's tables into the
question asked (:func:`study_question`), the result in the objective's own terms, the designs
compared, the near-optimal ranges, the re-fold schedules, the notes (:func:`design_notes`) and the
summary in words. Views only render what these build.
"""

from __future__ import annotations

import calendar
import math
from pathlib import Path
from typing import TYPE_CHECKING

from foldopt.columnar import Columns
from foldopt.studies.answer import Answer, plain, records
from foldopt.studies.designs import PLANES_DESIGN
from foldopt.studies.horizon_paths import horizon_notes
from foldopt.studies.least_cost import least_cost_answer
from foldopt.studies.storage_answer import answer_part, buffer_text, worst_years, year_lines
from foldopt.studies.storage_days import design_columns, sequential
from foldopt.names import FLAT_FOLD_ANGLE
from foldopt.studies.objectives import ENSEMBLE_PERCENTILES
from foldopt.studies.worldmap import searched_tilt

if TYPE_CHECKING:
    import pandas as pd
#: The designs an answer compares, first the ones every study has.
MAIN_DESIGNS = ("flat", "twofold", "tracker", "tracker-net")
NEAR_OPTIMAL = (
    "near_optimal_lo_deg",
    "near_optimal_hi_deg",
    "recommended_deg",
    "near_optimal_tolerance_h",
)


def _missing(value) -> bool:
    """Whether a number is missing: None or NaN (as ``pandas.isna`` of a scalar)."""
    return value is None or value != value


def _hours(value) -> str:
    return "-" if _missing(value) else f"{value:.2f} h"


def _pct(value, signed: bool = True) -> str:
    return "-" if _missing(value) else (f"{value:+.1f} %" if signed else f"{value:.1f} %")


def _fold_text(angle: float) -> str:
    """A fold angle [deg] to a tenth of a degree, or to a thousandth where a fold short of the flat
    panel would read 180.0 (a refined optimum a few hundredths below it is not the flat panel)."""
    short = f"{angle:.1f}" == f"{FLAT_FOLD_ANGLE:.1f}" and angle < FLAT_FOLD_ANGLE
    return f"{angle:.3f}" if short else f"{angle:.1f}"


def versus_flat(fold_angle, gain, flat_hours, flat_text: str = "") -> str:
    """The twofold panel at its best against the flat panel, as a line gives it: the gain [%], or
    where the best is the flat panel (a 180 deg fold) that no fold gains over it, or where the flat
    panel carries none of the load (no ratio to give) that it does not.

    Parameters
    ----------
    fold_angle : float
        The best fold angle [deg].
    gain : float
        [%] over the flat panel.
    flat_hours : float
        The flat panel's objective [h].
    flat_text : str, default ""
        Said of the flat panel after its hours (its worst month).
    """
    if fold_angle == FLAT_FOLD_ANGLE:
        return "the flat panel itself: no fold gains over it"
    flat = f"{_hours(flat_hours)}{flat_text}"
    if not flat_hours > 0:
        return f"where the flat panel carries none of the load (flat {flat})"
    return f"{_pct(gain)} over flat ({flat})"


def design_notes(table, case_count: int | None = None) -> list[dict]:
    """Each note of a table's ``note`` column with the designs it concerns (none where it concerns
    them all) and, for sweeps, in how many cases.

    Parameters
    ----------
    table : pandas.DataFrame or foldopt.columnar.Columns
        With ``design`` and ``note`` columns.
    case_count : int, optional
        A sweep's number of cases; None for one case.
    """
    if "note" not in table or not len(table):
        return []
    designs_of = list(table["design"])
    # A case is a row's values of these columns, NaN one value (as pandas' drop_duplicates).
    keys = [
        c for c in table.columns if c in ("site_name", "latitude", "longitude", "date", "p_load_w")
    ]
    case_of = list(
        zip(*([None if _missing(v) else v for v in table[c]] for c in keys), strict=True)
    )
    # Each note's rows, a row once per time its note text holds it.
    rows_of: dict = {}
    for row, text in enumerate(table["note"]):
        for note in str(text).split("; "):
            if note != "":
                rows_of.setdefault(note, []).append(row)
    every = set(designs_of)
    notes = []
    for note in sorted(rows_of):
        rows = rows_of[note]
        designs = list(dict.fromkeys(designs_of[row] for row in rows))
        entry = {"note": note, "designs": [] if set(designs) == every else designs}
        if case_count is not None:
            entry.update(
                cases=len({case_of[row] for row in rows}) if keys else len(rows), of=case_count
            )
        notes.append(entry)
    return notes


def weather_notes(result) -> list[dict]:
    """What reading a measured weather file did, as notes that concern every design.

    Parameters
    ----------
    result : foldopt.studies.sweeps.SweepResult or foldopt.studies.day.StudyResult
    """
    return [{"note": note, "designs": []} for note in getattr(result, "weather_notes", ())]


def series_notes(result) -> list[dict]:
    """Why a study over many days writes no time series (:mod:`foldopt.studies.series`)."""
    note = getattr(result, "timeseries_note", "")
    return [{"note": note, "designs": []}] if note else []


def study_question(study, varied: tuple = ()) -> dict:
    """What a study asks, label to text; the config paths in ``varied`` are said to vary.

    Parameters
    ----------
    study : Study
    varied : tuple of str, default ()
    """
    from foldopt.inputs.load_profile import load_text

    site = study.site
    where = f"{site.name + ', ' if site.name else ''}{site.latitude:g}, {site.longitude:g} ({site.timezone})"
    panel = study.panel
    tolerance = study.near_optimal
    question = {
        "site": "varies (see the table)"
        if {"site", "site.latitude", "site.longitude"} & set(varied)
        else where,
        "day": "varies (see the table)" if "date" in varied else study.date.isoformat(),
        "load": "varies (see the table)" if "p_load" in varied else load_text(study),
        "panel": f"{panel.area:g} m^2, efficiency {panel.efficiency:g}, tilt {panel.tilt:g} deg, azimuth "
        f"{panel.azimuth:g} deg"
        + (" (per latitude)" if "site.latitude" in varied else "")
        + (
            f" (the base of the planes {', '.join('/'.join(f'{v:g}' for v in p) for p in panel.planes)})"
            if panel.planes is not None
            else ""
        ),
        "models": f"{study.mode} mode, {study.geometry} geometry, {study.pv_model_text()}, {study.connection}, "
        + sky_text(study, varied),
        "fold angles": f"{study.fold_angles.start:g} to {study.fold_angles.stop:g} deg by {study.fold_angles.step:g}",
        "near-optimal": f"within {100 * tolerance.fraction:g} % or {tolerance.minutes:g} min of the best, "
        "whichever is larger",
        "objective": "t_solar of the day",
    }
    if site.horizon is not None:
        question["site"] += f", {site.horizon.describe()}"
    if not study.circuit.ideal or any(path.startswith("circuit") for path in varied):
        question["circuit"] = study.circuit.describe()
    if study.objective is not None and "date" in varied:
        objective = study.objective
        season = f" of months {', '.join(map(str, objective.months))}" if objective.months else ""
        question["objective"] = (
            f"one fold angle for all days, maximising the {objective.statistic} of daily "
            f"t_solar{season}"
            + (
                f"; re-fold schedules of up to {objective.visits} settings"
                if objective.visits
                else ""
            )
        )
    return question


#: How the question names each sky and transposition.
SKY_LABELS = {
    "meinel": "Meinel",
    "hottel": "Hottel",
    "ineichen": "Ineichen",
    "simplified-solis": "simplified Solis",
}
TRANSPOSITION_LABELS = {"isotropic": "isotropic", "haydavies": "Hay-Davies", "perez": "Perez"}


def sky_text(study, varied: tuple = ()) -> str:
    """The whole sky in force in a study, as its question says it: the clear sky or the weather
    file, the Linke turbidity of Ineichen's (the study's, or pvlib's climatology at the site and
    day, said as a number where neither varies), the transposition and the albedo, or beam only.

    Parameters
    ----------
    study : Study
        Resolved: its sky decided by its mode.
    varied : tuple of str, default ()
        The config paths a sweep varies.

    Returns
    -------
    str
        ``Ineichen clear sky at Linke turbidity 3.8 (pvlib climatology for the site and day), Perez
        diffuse, albedo 0.2`` (exact mode's default, Berlin on 21 June), ``Meinel clear sky, beam
        only (Shin et al.)`` (paper mode's).
    """
    transposition = study.sky_transposition()
    if study.weather is not None:
        parts = [f"weather {Path(study.weather.path).name}"]
    else:
        parts = [
            f"{SKY_LABELS[study.sky]} clear sky"
            + (f" ({study.climate})" if study.sky == "hottel" else "")
        ]
        if study.sky == "ineichen":
            parts[0] += f" at Linke turbidity {_turbidity_text(study, varied)}"
    if transposition == "none":
        parts.append(
            "beam only"
            + (" (Shin et al.)" if study.mode == "paper" and study.sky == "meinel" else "")
        )
    else:
        parts += [f"{TRANSPOSITION_LABELS[transposition]} diffuse", f"albedo {study.albedo:g}"]
    return ", ".join(parts)


def _turbidity_text(study, varied: tuple) -> str:
    """The Linke turbidity of a study's Ineichen sky: the study's own, or pvlib's climatology at its
    site on the UTC day of its solar noon (as the engine looks it up per site and UTC day)."""
    import numpy as np

    from foldopt.inputs.turbidity import linke_turbidity

    if study.linke_turbidity is not None:
        return f"{study.linke_turbidity:g}"
    if {"site", "site.latitude", "site.longitude", "date"} & set(varied):
        return "from pvlib climatology for each site and day"
    site = study.site
    noon = np.datetime64(f"{study.date.isoformat()}T12:00") - np.timedelta64(
        round(site.longitude * 240), "s"
    )
    value = linke_turbidity(
        site.latitude, site.longitude, noon.astype("datetime64[ns]").astype(np.int64)
    )
    return f"{float(value):.1f} (pvlib climatology for the site and day)"


def _range_text(row) -> str:
    lo, hi, recommended = (row.get(key) for key in NEAR_OPTIMAL[:3])
    if _missing(lo):
        return "near-optimal: no fold angle carries the load"
    return (
        f"near-optimal {lo:g} to {hi:g} deg (within {60 * row['near_optimal_tolerance_h']:.1f} min); "
        f"recommended {recommended:g} deg"
    )


def of_study(result) -> Answer:
    """The answer of one day's study.

    Parameters
    ----------
    result : foldopt.studies.day.StudyResult

    Returns
    -------
    foldopt.studies.answer.Answer
        Of kind ``study``: the best fold angle and its t_solar [h] against the flat panel and the
        tracker, the near-optimal range and the recommended angle, the designs compared.
    """
    from foldopt.inputs.load_profile import describe_load, load_text

    study, summary = result.study, result.summary_columns
    twofold = summary.row("design", "twofold")
    near = dict(result.near_optimal)
    near_table = Columns({key: [value] for key, value in near.items()})
    heuristic = result.heuristic_fold_angle
    break_even = result.standby_columns.break_even_w
    result_part = {
        "objective": "t_solar of the day",
        "load": describe_load(study),
        "fold_angle_deg": result.optimal_fold_angle,
        "t_solar_h": float(twofold["t_solar_h"]),
        "fold_angle_twofold_heuristic_deg": heuristic,
        "gain_vs_flat_pct": float(twofold["gain_vs_flat_pct"]),
        "share_of_tracker_pct": float(twofold["share_of_tracker_pct"]),
        "flat_area_ratio": float(twofold["flat_area_ratio"]),
        "break_even_standby_tracker_w": float(break_even),
        **near,
        "t_solar_by_design_h": {
            d: float(summary.row("design", d)["t_solar_h"]) for d in MAIN_DESIGNS
        },
    }
    site = study.site
    where = site.name or f"{site.latitude:g}, {site.longitude:g}"
    lines = [
        f"{study.name}: {where}, {study.date}, {load_text(study)} ({study.mode} mode, {study.pv_model} + "
        f"{study.connection})"
    ]
    hours = result_part["t_solar_by_design_h"]
    if not hours["twofold"]:
        lines.append(
            f"no fold angle reaches the load: t_solar 0 h (flat {_hours(hours['flat'])}, tracker "
            f"{_hours(hours['tracker'])})"
        )
    else:
        lines.append(
            f"best fold angle {_fold_text(result.optimal_fold_angle)} deg"
            + heuristic_text(study, heuristic, result.heuristic_outside)
            + f": t_solar {_hours(hours['twofold'])}, "
            + versus_flat(result.optimal_fold_angle, twofold["gain_vs_flat_pct"], hours["flat"])
            + (
                f", {_pct(twofold['share_of_tracker_pct'], False)} of the tracker's "
                f"{_hours(hours['tracker'])}"
                if hours["tracker"] > 0
                else ", where the tracker carries none of it (0.00 h)"
            )
        )
        lines.append(_range_text(near) + f" (t_solar {_hours(near['recommended_t_solar_h'])})")
    planes = planes_part(study)
    if planes is not None:
        row = summary.row("design", PLANES_DESIGN)
        planes.update(
            {
                key: float(row[key])
                for key in ("t_solar_h", "energy_harvested_wh", "gain_vs_flat_pct")
            }
        )
        result_part["planes"] = planes
        lines.append(planes_text(planes, "t_solar", hours["twofold"]))
    extras = []
    if not math.isnan(twofold["flat_area_ratio"]):
        extras.append(f"a flat panel would need {twofold['flat_area_ratio']:.2f}x the area")
    if not math.isnan(break_even):
        extras.append(
            f"the twofold panel outlasts the tracker once its standby draw exceeds "
            f"{break_even:.2f} W"
        )
    if extras:
        lines.append("; ".join(extras))
    columns = [
        "design",
        "fold_angle_deg",
        "t_solar_h",
        "energy_harvested_wh",
        "gain_vs_flat_pct",
        "share_of_tracker_pct",
        "note",
    ]
    buffered = getattr(result, "storage", None)
    if buffered is not None:
        # The buffer's part, said once here for every view (studies.storage_answer).
        result_part["storage"], more = answer_part(buffered)
        lines += more
        if buffered.design_space is not None:
            said, result_part["least_cost"] = least_cost_answer(
                buffered.design_space, study.costs, study.storage.target, study.tracker.model
            )
            lines += said
        columns[3:3] = design_columns(buffered.designs)
    return Answer(
        "study",
        study.name,
        study_question(study),
        request_defaults(result),
        result_part,
        summary[columns],
        near_table,
        Columns({}),
        design_notes(summary) + weather_notes(result.day.sky) + horizon_notes(study, [study.date]),
        tuple(lines),
    )


def planes_part(study) -> dict | None:
    """The existing array's planes as they stand (``panel.planes``): which plane is which half
    and the base and fold angle that make them; None without planes.

    Parameters
    ----------
    study : Study
    """
    design = study.planes_design()
    if design is None:
        return None
    planes = [list(plane) for plane in study.panel.planes]
    east, west = planes if design["first_east"] else planes[::-1]
    return {
        "design": PLANES_DESIGN,
        "plane_east": east,
        "plane_west": west,
        "surface_tilt": study.panel.tilt,
        "surface_azimuth": study.panel.azimuth,
        "geometry": study.geometry,
        "fold_angle_deg": design["fold_angle"],
    }


def planes_text(planes: dict, t_solar: str, best_hours: float) -> str:
    """The answer's line for the planes as they stand (:func:`planes_part`).

    Parameters
    ----------
    planes : dict
        :func:`planes_part`'s, with the design's ``t_solar_h`` (a day's) or
        ``t_solar_objective_h`` (over days) [h] and ``energy_harvested_wh`` [Wh].
    t_solar : str
        What its t_solar is: ``t_solar``, ``mean t_solar``.
    best_hours : float
        The best fold's, in the same terms [h].
    """
    east, west = (
        "/".join(f"{value:g}" for value in planes[side]) for side in ("plane_east", "plane_west")
    )
    hours = planes.get("t_solar_h", planes.get("t_solar_objective_h"))
    against = (
        f", {_pct(100.0 * (hours / best_hours - 1.0))} against the best fold"
        if best_hours > 0
        else ""
    )
    return (
        f"the planes as they stand ({east} east, {west} west: base tilt "
        f"{planes['surface_tilt']:.4g} deg, azimuth {planes['surface_azimuth']:.4g} deg, "
        f"{planes['geometry']} folded to {_fold_text(planes['fold_angle_deg'])} deg): {t_solar} "
        f"{_hours(hours)}, {planes['energy_harvested_wh']:.2f} Wh{against}"
    )


def heuristic_text(study, heuristic: float, outside: str) -> str:
    """The paper's heuristic (Shin et al. Eq. 8) beside the best fold angle: its angle where it was
    evaluated among the study's fold angles, else where the rule's angle lies and why (never a
    clamped bound as if it were the rule's).

    Parameters
    ----------
    study : Study
    heuristic : float
        Its fold angle [deg], NaN where it has none among the study's.
    outside : str
        :attr:`foldopt.studies.day.StudyResult.heuristic_outside`: ``below``, ``above`` or empty.
    """
    grid = study.fold_angles
    if not math.isnan(heuristic):
        where = f"{heuristic:.1f} deg"
    elif outside == "below":
        where = f"at or below {grid.start:g} deg, the grid's first: the noon valley reaches the load there"
    elif outside == "above" and grid.stop < FLAT_FOLD_ANGLE:
        where = f"above {grid.stop:g} deg, the grid's last: the noon valley falls short of the load there"
    elif outside == "above":
        where = "none, the load exceeds the flat panel's noon power"
    else:
        return ""
    return f" (the paper's heuristic: {where})"


def request_defaults(result) -> dict | None:
    """What a result's request took from its study (:attr:`foldopt.studies.request.Request.defaults`),
    None without a request.

    Parameters
    ----------
    result : object
        A result with a ``request`` attribute.
    """
    request = getattr(result, "request", None)
    return request.defaults if request is not None else None


def of_sweep(result) -> Answer:
    """The answer of a plan of cases or of an annual objective.

    Parameters
    ----------
    result : foldopt.studies.sweeps.SweepResult

    Returns
    -------
    foldopt.studies.answer.Answer
        Of kind ``annual`` where ``result.extras`` holds ``annual_objective`` (one fold angle over
        many days), else ``sweep``: the gain over flat [%] and the fold angles [deg] over the cases.
    """
    import pandas as pd

    if "annual_objective" in result.extras:
        return _of_annual(result)
    from foldopt.inputs.load_profile import describe_load

    plan, table = result.plan, result.table
    twofold = table[table["design"] == "twofold"]
    gains = twofold["gain_vs_flat_pct"].dropna()
    axes = " x ".join(f"{len(values)} {path.split('.')[-1]}" for path, values in plan.axes)
    lines = [f"{plan.base.name}: {plan.n_cases} cases ({axes})"]
    part = {
        "cases": plan.n_cases,
        "axes": {path: len(values) for path, values in plan.axes},
        "load": describe_load(plan.base),
        "fold_angle_deg": {
            "min": twofold["fold_angle_deg"].min(),
            "max": twofold["fold_angle_deg"].max(),
        },
        "recommended_deg": {
            "min": twofold["recommended_deg"].min(),
            "max": twofold["recommended_deg"].max(),
        },
    }
    if len(gains):
        best = twofold.loc[gains.idxmax()]
        at = {
            column: best[column]
            for column in result.varied
            if column in best and column != "dayofyear"
        }
        part["gain_vs_flat_pct"] = {"median": gains.median(), "max": gains.max(), "at": at}
        where = ", ".join(
            f"{key} {value:g}" if isinstance(value, float) else f"{key} {value}"
            for key, value in at.items()
        )
        lines.append(
            f"twofold over flat: median {_pct(gains.median())}, best {_pct(gains.max())} ({where}); "
            f"fold angles {part['fold_angle_deg']['min']:g} to {part['fold_angle_deg']['max']:g} deg"
        )
    rec = part["recommended_deg"]
    if not math.isnan(rec["min"]):
        lines.append(
            "recommended fold angles (each case's near-optimal centre, flat where flat is best) "
            f"{rec['min']:g} to {rec['max']:g} deg (near_optimal_lo_deg, near_optimal_hi_deg in the "
            "table)"
        )
    keys = [
        c
        for c in ("site_name", "latitude", "longitude", "date", "p_load_w", *result.varied)
        if c in table
    ]
    near = twofold[list(dict.fromkeys(keys)) + ["fold_angle_deg", *NEAR_OPTIMAL]].reset_index(
        drop=True
    )
    designs = table[
        [
            c
            for c in (
                *dict.fromkeys(keys),
                "design",
                "fold_angle_deg",
                "t_solar_h",
                "energy_harvested_wh",
                "gain_vs_flat_pct",
                "share_of_tracker_pct",
                "note",
            )
            if c in table
        ]
    ]
    question = study_question(plan.base, tuple(path for path, _ in plan.axes))
    question["sweep"] = ", ".join(f"{path} ({len(values)} values)" for path, values in plan.axes)
    return Answer(
        "sweep",
        plan.base.name,
        question,
        request_defaults(result),
        plain(part),
        designs,
        near,
        pd.DataFrame(),
        design_notes(table, plan.n_cases)
        + weather_notes(result)
        + series_notes(result)
        + horizon_notes(plan.base, _dates(plan)),
        tuple(lines),
    )


def _of_annual(result) -> Answer:
    """One fold angle over many days: the objective per design in its own terms, the near-optimal
    range of the angle kept all year, the re-fold schedules."""
    from foldopt.inputs.load_profile import describe_load, load_text

    plan = result.plan
    study = plan.base
    objective = study.objective
    statistic = objective.statistic
    objectives = result.extras["annual_objective"]
    keys = [
        c
        for c in objectives.columns
        if c
        not in (
            "design",
            "objective",
            "t_solar_objective_h",
            "worst_month",
            "t_solar_mean_h",
            "fold_angle_deg",
            "energy_harvested_wh",
            *NEAR_OPTIMAL,
            *ENSEMBLE_COLUMNS,
        )
    ]
    members = study.weather.members if study.weather is not None and study.weather.members else None
    count = len(_dates(plan))
    lines = [
        f"{study.name}: {count} day{'s' if count != 1 else ''}, one fold angle "
        f"{_period(count)}, maximising the {statistic} of daily t_solar"
    ]
    groups = list(objectives.groupby(keys, sort=False))
    part = {"objective": statistic, "load": describe_load(study), "per_case": []}
    schedule = _schedule(result.extras)
    for key, rows in groups[:8]:
        by = rows.set_index("design")
        twofold, flat, tracker = by.loc["twofold"], by.loc["flat"], by.loc["tracker"]
        where = dict(zip(keys, key if isinstance(key, tuple) else (key,), strict=True))
        load = where.get("p_load_w")
        case = {
            **where,
            "fold_angle_deg": twofold["fold_angle_deg"],
            "t_solar_objective_h": {d: by.loc[d, "t_solar_objective_h"] for d in MAIN_DESIGNS},
            "t_solar_mean_h": {d: by.loc[d, "t_solar_mean_h"] for d in MAIN_DESIGNS},
            **{k: twofold[k] for k in NEAR_OPTIMAL},
        }
        month = ""
        if statistic == "worst-month":
            case["worst_month"] = {d: int(by.loc[d, "worst_month"]) for d in MAIN_DESIGNS}
            month = f" (in {calendar.month_name[case['worst_month']['twofold']]})"
        part["per_case"].append(case)
        gain = (
            100.0 * (twofold["t_solar_objective_h"] / flat["t_solar_objective_h"] - 1.0)
            if flat["t_solar_objective_h"] > 0
            else float("nan")
        )
        flat_month = (
            f" in {calendar.month_name[case['worst_month']['flat']]}"
            if statistic == "worst-month"
            else ""
        )
        label = load_text(study, load)
        site = where.get("site_name") or (
            f"{where['latitude']:g}, {where['longitude']:g}"
            if len(groups) > 1 and "latitude" in where
            else ""
        )
        head = f"{site + ': ' if site else ''}{label}: "
        if not twofold["t_solar_objective_h"] > 0:
            # Every angle ties at nothing: the tie-break is no choice, nor is there a gain to give.
            lines.append(
                f"{head}no fold angle carries the load: {statistic} t_solar 0.00 h (flat "
                f"{_hours(flat['t_solar_objective_h'])}); tracker "
                f"{_hours(tracker['t_solar_objective_h'])}"
            )
        else:
            lines.append(
                f"{head}fold angle {twofold['fold_angle_deg']:g} deg {_period(count)}; "
                f"{statistic} t_solar {_hours(twofold['t_solar_objective_h'])}{month}, "
                + versus_flat(
                    twofold["fold_angle_deg"], gain, flat["t_solar_objective_h"], flat_month
                )
                + f"; tracker {_hours(tracker['t_solar_objective_h'])}"
                + (
                    ""
                    if statistic == "mean"
                    else f"; mean t_solar {_hours(twofold['t_solar_mean_h'])}"
                )
            )
        if twofold["t_solar_objective_h"] > 0:
            lines.append("  " + _range_text(twofold.to_dict()))
        if members:
            spread = {
                column: {d: by.loc[d, column] for d in MAIN_DESIGNS}
                for column in (
                    f"t_solar_objective_members_p{pct}_h" for pct in ENSEMBLE_PERCENTILES
                )
            }
            case.update(spread)
            case["members"] = members
            case.update({key: twofold[key] for key in ("chosen_wins_pct", "within_tolerance_pct")})
            lines.append(
                f"  over {members} cloud members: {statistic} t_solar "
                + "/".join(f"P{pct}" for pct in ENSEMBLE_PERCENTILES)
                + " "
                + "; ".join(
                    f"{d} " + "/".join(_hours(values[d]) for values in spread.values())
                    for d in MAIN_DESIGNS
                )
            )
            lines.append(
                f"  {twofold['fold_angle_deg']:g} deg is the best angle of {twofold['chosen_wins_pct']:.0f} % "
                f"of the members and within the near-optimal tolerance of their best for "
                f"{twofold['within_tolerance_pct']:.0f} %"
            )
        if len(schedule):
            mine = schedule[(schedule["p_load_w"] == load)] if load is not None else schedule
            for settings, visits in mine.groupby("settings_n", sort=True):
                first = visits.iloc[0]
                when = ", ".join(
                    f"{v.date} at {v.fold_angle_deg:g} deg" for v in visits.itertuples()
                )
                added = "" if settings == 1 else f" (+{first['added_by_setting_h'] * 60:.1f} min)"
                lines.append(
                    f"  {settings} setting{'s' if settings > 1 else ''}: {statistic} t_solar "
                    f"{_hours(first['t_solar_objective_h'])}{added}: {when}"
                )
    if len(groups) > 8:
        lines.append(f"... and {len(groups) - 8} more cases (annual_objective.csv)")
    planes = planes_part(study)
    if planes is not None:
        # The planes' rows of every case and load; the lines, of the first case's loads.
        rows = objectives[objectives["design"] == PLANES_DESIGN]
        best = objectives[objectives["design"] == "twofold"]["t_solar_objective_h"].to_numpy()
        planes["per_case"] = records(
            rows[[*keys, "t_solar_objective_h", "t_solar_mean_h", "energy_harvested_wh"]]
        )
        for case, best_hours in list(zip(planes["per_case"], best, strict=True))[:8]:
            label = load_text(study, case.get("p_load_w")) + ": " if len(best) > 1 else ""
            lines.append(
                label + planes_text({**planes, **case}, f"{statistic} t_solar", best_hours)
            )
        part["planes"] = planes
    buffered = result.extras.get("storage_annual")
    if buffered is not None:
        # The buffer over the days, said once here for every view (studies.storage_answer).
        in_sequence = sequential(_dates(plan), study.weather is not None)
        # Real years, a weather file's (a clear sky's days are no real years).
        worst = worst_years(result.extras["storage_years"]) if study.weather is not None else None
        lines += year_lines(study.storage, buffered, in_sequence, worst)
        chosen = buffered.loc[buffered["design"] == "twofold-buffer", "fold_angle_deg"]
        part["storage"] = {
            # Over several calendar years, each case's, load's and design's worst.
            **({"worst_years": records(worst)} if worst is not None and len(worst) else {}),
            "buffer": buffer_text(study.storage),
            "days_in_sequence": in_sequence,
            "fold_angle_twofold_deg": result.extras["fold_angle"],
            # The first case's and load's (each case's and load's: per_case).
            "fold_angle_buffer_deg": float(chosen.iloc[0]),
            "per_case": records(buffered),
        }
    space = result.extras.get("design_space")
    if space is not None:
        said, part["least_cost"] = least_cost_answer(
            space,
            study.costs,
            study.storage.target,
            study.tracker.model,
            # Several calendar years, as the buffer's lines say them.
            over_years="worst_years" in part.get("storage", {}),
        )
        lines += said
    designs = objectives[
        [
            *keys,
            "design",
            "objective",
            "t_solar_objective_h",
            "worst_month",
            "t_solar_mean_h",
            "fold_angle_deg",
            *[c for c in ENSEMBLE_COLUMNS if c in objectives],
        ]
    ]
    if statistic != "worst-month":
        designs = designs.drop(columns="worst_month")
    twofold_rows = objectives[objectives["design"] == "twofold"]
    near = twofold_rows[[*keys, "fold_angle_deg", *NEAR_OPTIMAL]].reset_index(drop=True)
    question = study_question(study, tuple(path for path, _ in plan.axes))
    question["sweep"] = ", ".join(f"{path} ({len(values)} values)" for path, values in plan.axes)
    return Answer(
        "annual",
        study.name,
        question,
        request_defaults(result),
        plain(part),
        designs,
        near,
        schedule,
        design_notes(result.table, plan.n_cases)
        + weather_notes(result)
        + series_notes(result)
        + horizon_notes(study, _dates(plan)),
        tuple(lines),
    )


#: The annual objective's columns over a cloud ensemble (foldopt.studies.sweeps.objective_table).
ENSEMBLE_COLUMNS = (
    *(f"t_solar_objective_members_p{pct}_h" for pct in ENSEMBLE_PERCENTILES),
    "chosen_wins_pct",
    "within_tolerance_pct",
)


def _period(count: int) -> str:
    """How long one fold angle is kept: ``all year`` for a year's days (or more), else the days."""
    return "all year" if count >= 365 else "for the day" if count == 1 else f"for the {count} days"


def _dates(plan) -> tuple:
    return dict(plan.axes).get("date", (plan.base.date,))


def _schedule(extras: dict) -> pd.DataFrame:
    """Each re-fold visit with its schedule's objective and what its last setting adds."""
    import pandas as pd

    if "refold_schedule" not in extras:
        return pd.DataFrame()
    visits, values = extras["refold_schedule"], extras["refold_value"]
    keys = [c for c in visits.columns if c not in ("visit", "date", "fold_angle_deg")]
    merged = visits.merge(
        values[
            [*keys, "objective", "t_solar_objective_h", "added_by_setting_h", "gain_vs_fixed_pct"]
        ],
        on=keys,
        how="left",
    )
    return merged


def of_sizing(
    table: pd.DataFrame, best: pd.DataFrame, study, parameters: dict, defaults: dict | None
) -> Answer:
    """The answer of a panel sizing: :func:`foldopt.studies.sizing.size_panel`'s ``table`` and its ``best``
    row per design, with the ``parameters`` used (costs, ``c_grid_usd_per_kwh``, ``years``).

    Parameters
    ----------
    table, best : pandas.DataFrame
    study : Study
    parameters, defaults : dict
        ``defaults``: what was taken from the study (:attr:`Answer.defaults`), or None.
    """
    import pandas as pd
    from foldopt.inputs.load_profile import load_text

    cost = (
        f"{parameters['cost_per_m2']:g} $/m^2"
        if parameters.get("cost_per_w") is None
        else f"{parameters['cost_per_w']:g} $/W"
    )
    lines = [
        f"{study.name} ({load_text(study)}): the area with the largest lifetime net benefit at {cost}, C_grid "
        f"{parameters['c_grid_usd_per_kwh']:g} $/kWh over {parameters['years']:g} years"
    ]
    for row in best.itertuples():
        angle = "" if row.design == "flat" else f", folded to {row.fold_angle_deg:g} deg"
        lines.append(
            f"  {row.design}: {row.area_m2:.3f} m^2{angle}, t_solar {row.t_solar_h:.2f} h, "
            f"net ${row.net_benefit_usd:.1f}"
        )
    question = {
        **study_question(study),
        "sizing": ", ".join(f"{k} {v:g}" for k, v in parameters.items() if v is not None),
    }
    return Answer(
        "size",
        study.name,
        question,
        defaults,
        plain({**parameters, "best": records(best)}),
        best,
        pd.DataFrame(),
        pd.DataFrame(),
        [],
        tuple(lines),
    )


def of_reproduction(tables: dict, study) -> Answer:
    """Shin et al.'s published values beside foldopt's.

    Parameters
    ----------
    tables : dict of str to pandas.DataFrame
        The tables of :func:`foldopt.studies.reproduce.reproduce` by file stem.
    study : foldopt.Study
        The paper's study.

    Returns
    -------
    foldopt.studies.answer.Answer
        Of kind ``reproduce``: each quantity's paper value beside the paper and exact modes.
    """
    import pandas as pd

    lines = []
    for name, table in tables.items():
        model = (
            "ideal PV model"
            if name == "reproduction"
            else "A-300 single-diode cells with switching"
        )
        lines.append(f"Shin et al. ({model}): paper value | paper mode | exact mode")
        for row in table.itertuples():
            paper = "-" if math.isnan(row.paper) else f"{row.paper:g}"
            lines.append(
                f"  {row.quantity:28s} {paper:>7s} | {row.paper_mode:8.3f} | {row.exact_mode:8.3f}  "
                f"{row.unit}"
            )
    combined = pd.concat(
        [table.assign(table=name) for name, table in tables.items()], ignore_index=True
    )
    return Answer(
        "reproduce",
        "Shin et al. reproduced",
        study_question(study),
        None,
        {name: records(table) for name, table in tables.items()},
        combined,
        pd.DataFrame(),
        pd.DataFrame(),
        [],
        tuple(lines),
    )


def _count(number: int, noun: str) -> str:
    return f"{number} {noun}{'' if number == 1 else 's'}"


def of_map(result, relative: bool, defaults: dict | None = None) -> Answer:
    """The answer of a map of many sites: per load, over the sites, where folding pays in the year and
    the recommended fold angles.

    Parameters
    ----------
    result : foldopt.studies.cluster.MapRun
    relative : bool
        Loads as fractions of each site's flat peak (``p_load_frac``), else in W.
    defaults : dict, optional
    """
    import pandas as pd

    table, spec = result.table, result.spec
    study = spec.study
    tilts = searched_tilt(study)
    year = table[table["period"] == "year"]
    key = "p_load_frac" if relative else "p_load_w"
    per_load = []
    # A fraction is watts over each site's peak: the same load to 12 digits at every site.
    for load, rows in year.groupby(year[key].round(12), sort=True):
        gain = rows["gain_vs_flat_pct"]
        best = rows.loc[gain.idxmax()] if gain.notna().any() else None
        per_load.append(
            {
                key: float(load),
                "sites": int(len(rows)),
                "sites_folding_pays": int((gain > 0.05).sum()),
                "gain_vs_flat_median_pct": gain.median(),
                "gain_vs_flat_max_pct": gain.max(),
                "best_site": None
                if best is None
                else {
                    "site_name": best["site_name"],
                    "latitude": best["latitude"],
                    "longitude": best["longitude"],
                },
                "fold_angle_deg": {
                    "min": rows["fold_angle_deg"].min(),
                    "median": rows["fold_angle_deg"].median(),
                    "max": rows["fold_angle_deg"].max(),
                },
                "recommended_deg": {
                    "min": rows["recommended_deg"].min(),
                    "median": rows["recommended_deg"].median(),
                    "max": rows["recommended_deg"].max(),
                },
                "near_optimal_width_median_deg": (
                    rows["near_optimal_hi_deg"] - rows["near_optimal_lo_deg"]
                ).median(),
                **{
                    column: {
                        "min": rows[column].min(),
                        "median": rows[column].median(),
                        "max": rows[column].max(),
                    }
                    for column in ("surface_tilt", "surface_tilt_flat_deg")
                },
                "share_of_tracker_median_pct": rows["share_of_tracker_pct"].median(),
                "break_even_standby_tracker_median_w": rows[
                    "break_even_standby_tracker_w"
                ].median(),
            }
        )
    statistic = study.objective.statistic if study.objective is not None else "mean"
    part = plain(
        {
            "sites": int(table["site_id"].nunique()),
            "objective": statistic,
            "loads": per_load,
            "cluster": result.cluster,
            "dashboard": result.dashboard,
            "chunks_computed": len(result.computed),
            "chunks_from_disk": len(result.from_disk),
            "seconds": round(result.seconds, 2),
        }
    )
    weather = any("weather" in site for site in spec.sites)
    sky = (
        "weather files"
        if weather
        else "Ineichen clear sky"
        if study.sky == "ineichen"
        else f"{study.sky} sky"
    )
    lines = [
        f"map: {_count(part['sites'], 'site')}, year {spec.year}, {sky}, objective {part['objective']}, "
        f"{study.panel.area:g} m^2 panel"
    ]
    for load in part["loads"]:
        what = (
            f"P_load {load['p_load_frac']:g} x flat peak"
            if relative
            else f"P_load {load['p_load_w']:g} W"
        )
        best = load["best_site"]
        where = (
            ""
            if best is None
            else (best["site_name"] or f"{best['latitude']:g}, {best['longitude']:g}")
        )
        rec = load["recommended_deg"]
        standby = load["break_even_standby_tracker_median_w"]
        tracker = (
            ""
            if standby is None
            else ", whose own moves already cost it its lead"
            if standby == 0
            else f", which loses its lead above a median {standby:.2f} W of standby"
        )
        best_angles = load["fold_angle_deg"]
        rec_text = (
            "no fold angle carries the load"
            if rec["min"] is None
            else f"best fold angles {best_angles['min']:g} to {best_angles['max']:g} deg, recommended "
            f"{rec['min']:g} to {rec['max']:g} deg (median {rec['median']:g}, near-optimal ranges a median "
            f"{load['near_optimal_width_median_deg']:g} deg wide)"
        )
        if tilts is not None and rec["min"] is not None:
            tilt, flat = load["surface_tilt"], load["surface_tilt_flat_deg"]
            rec_text += (
                f", at base tilts {tilt['min']:g} to {tilt['max']:g} deg (median {tilt['median']:g}; "
                f"the flat panel's own best {flat['min']:g} to {flat['max']:g}, median {flat['median']:g})"
            )
        # Where no site carries the load there is no gain to give, nor a best site.
        gains = (
            ""
            if best is None
            else f" (median {_pct(load['gain_vs_flat_median_pct'])}, best "
            f"{_pct(load['gain_vs_flat_max_pct'])} at {where})"
        )
        lines.append(
            f"{what}: folding beats flat at {load['sites_folding_pays']} of {_count(load['sites'], 'site')}"
            f"{gains}; {rec_text}; "
            + (
                f"the tracker carries it at no site{' either' if rec['min'] is None else ''}"
                if load["share_of_tracker_median_pct"] is None
                else f"median {_pct(load['share_of_tracker_median_pct'], False)} of the "
                f"tracker{tracker}"
            )
        )
    rate = len(spec.sites) / part["seconds"] if part["seconds"] else 0
    computed = (
        f"computed {_count(part['chunks_computed'], 'chunk')} on {part['cluster']}"
        if part["chunks_computed"]
        else "nothing to compute"
    )
    resumed = f", {part['chunks_from_disk']} from disk" if part["chunks_from_disk"] else ""
    lines.append(f"{computed}{resumed} in {part['seconds']:.1f} s ({rate:.1f} sites/s)")
    loads = ", ".join(f"{load:g}" for load in spec.loads)
    question = {
        "sites": f"{len(spec.sites):,}",
        "loads": f"{loads} {'x each site' + chr(39) + 's flat peak' if relative else 'W'}",
        "year": str(spec.year),
        "panel": f"{study.panel.area:g} m^2 facing the equator at "
        + (
            "|latitude|"
            if tilts is None
            else f"each site's best base tilt, {tilts.lo:g} to {tilts.hi:g} by {tilts.step:g} deg "
            "(the flat panel's own)"
        ),
        "objective": part["objective"],
        "models": f"{study.mode} mode, {study.pv_model_text()}, "
        + (sky if weather else sky_text(study, ("site", "date"))),
    }
    columns = [
        "site_id",
        "site_name",
        "latitude",
        "longitude",
        key,
        "fold_angle_deg",
        "surface_tilt",
        "surface_tilt_flat_deg",
        *NEAR_OPTIMAL,
    ]
    return Answer(
        "map",
        "map",
        question,
        defaults,
        part,
        year[[c for c in year.columns if c not in NEAR_OPTIMAL]],
        year[columns].reset_index(drop=True),
        pd.DataFrame(),
        [],
        tuple(lines),
    )
