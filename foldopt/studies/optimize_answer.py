"""The answer of a joint optimisation (:class:`foldopt.studies.joint.OptimizeResult`): per load the
optimum fold angle, tilt and azimuth with the objective, the flat panel at its own best, the
default mounting and the tracker, the near-optimal region of each variable, what each variable
adds, and how much of the grid the search evaluated."""

from __future__ import annotations

from foldopt.studies.answer import Answer, records
from foldopt.names import FLAT_FOLD_ANGLE
from foldopt.studies.result_answers import request_defaults, study_question

#: How the answer names each variable and its unit.
_LABELS = {"fold_angle": ("fold", "deg"), "tilt": ("tilt", "deg"), "azimuth": ("azimuth", "deg")}


def _tracker_text(gross, net) -> str:
    """The tracker's objective, and net of its own draw (standby, drive) where that costs any."""
    text = f"tracker {gross.t_solar_objective_h:.2f} h"
    if net.t_solar_objective_h < gross.t_solar_objective_h:
        text += f" ({net.t_solar_objective_h:.2f} h net of its own draw)"
    return text


def _row(table, load, design):
    return table[(table["p_load_w"] == load) & (table["design"] == design)].iloc[0]


def _mounting(row) -> str:
    return f"tilt {row.surface_tilt:g} deg, azimuth {row.surface_azimuth:g} deg"


def _over_flat(best, flat) -> str:
    """The optimum against the flat panel at its own best: a gain in per cent, or where the flat
    panel carries nothing (no ratio to give), its hours."""
    where = f"the flat panel at its own best ({_mounting(flat)}: {flat.t_solar_objective_h:.2f} h)"
    if flat.t_solar_objective_h > 0:
        return f"{best.gain_vs_flat_pct:+.1f} % over {where}"
    return f"where {where} carries none of it"


def of_optimize(result) -> Answer:
    """The answer of :func:`foldopt.studies.joint.optimize_plan`.

    Parameters
    ----------
    result : foldopt.studies.joint.OptimizeResult

    Returns
    -------
    foldopt.studies.answer.Answer
        Of kind ``optimize``.
    """
    study, table = result.study, result.table
    spec = study.optimize
    days = len(result.dates)
    over = "the day" if days == 1 else f"{days} days"
    objective = "t_solar" if days == 1 else f"{result.statistic} of daily t_solar"
    question = {
        **study_question(study, ("date",) if days > 1 else ()),
        "optimize": ", ".join(
            f"{name} {axis.lo:g} to {axis.hi:g} by {axis.step:g} deg"
            for name, axis in zip(spec.vary, _varied_axes(result), strict=True)
        )
        + f"; within {spec.tolerance_h:g} h",
        "objective": f"the {objective} over {over}",
    }
    varied = [name.replace("_", " ") for name in spec.vary]
    joined = varied[0] if len(varied) == 1 else f"{', '.join(varied[:-1])} and {varied[-1]}"
    lines = [
        f"{study.name}: the best {joined}{' together' if len(varied) > 1 else ''}, maximising the {objective} "
        f"over {over}"
    ]
    fixed_fold = "fold_angle" not in spec.vary
    if fixed_fold and len(result.loads) > 1:
        lines.append(
            f"  the fold angle stays at {result.twofold.best_point[0][0]:g} deg for every load, the first "
            f"load's best at the default mounting (--vary fold_angle searches it)"
        )
    per_load = []
    for load in result.loads:
        best, flat = _row(table, load, "twofold"), _row(table, load, "flat")
        default, flat_default = (
            _row(table, load, "twofold-default"),
            _row(table, load, "flat-default"),
        )
        tracker = _tracker_text(_row(table, load, "tracker"), _row(table, load, "tracker-net"))
        near = result.near_optimal[result.near_optimal["p_load_w"] == load]
        added = result.added[result.added["p_load_w"] == load]
        label = (
            f"load profile x {load:g}" if study.load_profile is not None else f"P_load {load:g} W"
        )
        carried = best.t_solar_objective_h > 0
        if not carried:
            # Every design ties at nothing: the search's tie-break is no optimum, nor is there a gain
            # or a near-optimal region to give.
            near = near.iloc[:0]
            lines.append(
                f"{label}: no design carries the load: the {objective} is 0.00 h at every design searched "
                f"(and the flat panel's); {tracker}"
            )
        else:
            # A 180 deg fold is the flat panel: there the optimum is the flat panel's own best.
            lines.append(
                f"{label}: flat (fold 180 deg), {_mounting(best)}: "
                f"{best.t_solar_objective_h:.2f} h, the flat panel at its own best: no fold gains "
                f"over it; {tracker}"
                if best.fold_angle_deg == FLAT_FOLD_ANGLE
                else f"{label}: fold {best.fold_angle_deg:g} deg, {_mounting(best)}: "
                f"{best.t_solar_objective_h:.2f} h, {_over_flat(best, flat)}; {tracker}"
            )
            if len(near):
                lines.append(
                    "  near-optimal: "
                    + ", ".join(
                        f"{_LABELS[row.variable][0]} {row.near_optimal_lo_deg:g} to {row.near_optimal_hi_deg:g} deg "
                        f"(recommended {row.recommended_deg:g})"
                        for row in near.itertuples()
                    )
                    + f", each within {near['near_optimal_tolerance_h'].iloc[0] * 60:.1f} min"
                )
            # What the variables add starts from the default mounting folded as the search holds it.
            first = added.iloc[0]
            folded = (
                (best.fold_angle_deg, first.t_solar_objective_h - first.added_h)
                if fixed_fold
                else (default.fold_angle_deg, default.t_solar_objective_h)
            )
            # + 0.0: no "-0.0" for a roundoff
            lines.append(
                f"  over the default mounting ({_mounting(flat_default)}: flat "
                f"{flat_default.t_solar_objective_h:.2f} h, folded to {folded[0]:g} deg {folded[1]:.2f} h): "
                + ", ".join(
                    f"{_LABELS[row.variable][0]} {round(row.added_h * 60, 1) + 0.0:+.1f} min"
                    for row in added.itertuples()
                )
            )
        per_load.append(
            {
                "p_load_w": load,
                "carried": bool(carried),
                "fold_angle_deg": best.fold_angle_deg,
                "surface_tilt": best.surface_tilt,
                "surface_azimuth": best.surface_azimuth,
                "t_solar_objective_h": best.t_solar_objective_h,
                "gain_vs_flat_pct": best.gain_vs_flat_pct,
                "flat": {
                    "surface_tilt": flat.surface_tilt,
                    "surface_azimuth": flat.surface_azimuth,
                    "t_solar_objective_h": flat.t_solar_objective_h,
                },
                "default": {
                    "fold_angle_deg": default.fold_angle_deg,
                    "t_solar_objective_h": default.t_solar_objective_h,
                    "t_solar_flat_objective_h": flat_default.t_solar_objective_h,
                },
                "t_solar_tracker_objective_h": _row(table, load, "tracker").t_solar_objective_h,
                "t_solar_tracker_net_objective_h": _row(
                    table, load, "tracker-net"
                ).t_solar_objective_h,
                "added_h": dict(zip(added["variable"], added["added_h"], strict=True)),
                "near_optimal": records(near.drop(columns="p_load_w")),
            }
        )
    search = result.twofold
    # The search's tolerance is the one asked for, or the objective's own step where that is coarser.
    raised = (
        ""
        if search.tolerance <= spec.tolerance_h
        else (
            f" (the objective's own step: it counts no finer than the {spec.tolerance_h:g} h asked for)"
        )
    )
    lines.append(
        f"search: {search.index.shape[0]:,} of the grid's {search.grid_size:,} designs evaluated "
        f"({100 * search.index.shape[0] / search.grid_size:.1f} %), within {search.tolerance:.3g} h of its "
        f"best{raised}"
    )
    summary = {
        "statistic": result.statistic,
        "days": days,
        "loads": per_load,
        "search": {
            "designs_evaluated_n": int(search.index.shape[0]),
            "designs_grid_n": search.grid_size,
            "levels": [list(level) for level in search.levels],
            "tolerance_h": search.tolerance,
        },
    }
    return Answer(
        "optimize",
        study.name,
        question,
        request_defaults(result),
        summary,
        table,
        result.near_optimal,
        summary=tuple(lines),
    )


def _varied_axes(result):
    axes = {axis.name: axis for axis in result.twofold.axes}
    return [axes[name] for name in result.study.optimize.vary]
