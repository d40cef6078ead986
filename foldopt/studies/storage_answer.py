"""What an answer says of a buffer (issue 41): the part of a day's result and its lines
(:func:`answer_part`), a year's lines (:func:`year_lines`), where folding pays
(:func:`folding_part`, :func:`folding_line`) and the buffer itself (:func:`buffer_text`). Every
key of a part is written here as it is read. The numbers are
:mod:`foldopt.studies.storage_days`' and :mod:`foldopt.studies.storage_sizing`'s.

The module may import numpy, pandas and the storage modules whose numbers it says.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from foldopt.studies.storage_days import SOC_DESIGNS, YEAR_DESIGNS, DayStorage
from foldopt.studies.storage_sizing import FoldingPays

if TYPE_CHECKING:
    import pandas as pd


def not_monotone_note(designs) -> str:
    """The note of a sizing whose target a larger capacity of the grid misses again, for
    ``designs`` (an iterable of their names)."""
    return (
        f"note: a larger buffer than the one given falls short of the target again for "
        f"{', '.join(designs)} (hysteresis or self-discharge: powered time is not monotone in "
        "capacity); each is the least capacity evaluated that reaches it"
    )


def _digits(value) -> str:
    """A value to 3 significant digits, written out (3840, not 3.84e+03)."""
    return np.format_float_positional(float(f"{value:.3g}"), trim="-")


def _wh(value) -> str:
    return "-" if value != value else f"{_digits(value)} Wh"


def _signed(value: float, digits: int) -> str:
    """``value`` with its sign to ``digits`` decimals, a rounded zero as +0 (never -0.00)."""
    return f"{round(value, digits) + 0.0:+.{digits}f}"


def folding_part(folding: FoldingPays) -> dict:
    """Where folding pays, as the answer's result holds it: ``folding_pays`` (one of
    :data:`~foldopt.studies.storage_sizing.FOLDING_STATES`), ``folding_stops_paying_wh`` (the
    threshold, NaN but below one), ``folding_pays_up_to_wh`` (the largest capacity evaluated at
    which folding pays, NaN where none: a threshold's bracket's bottom),
    ``folding_does_not_pay_from_wh`` (the least capacity from which on it pays at none evaluated,
    NaN where there is none above the largest at which it pays: a threshold's bracket's top) and
    ``folding_searched_up_to_wh``, all [Wh]."""
    return {
        "folding_pays": folding.state,
        "folding_stops_paying_wh": folding.stops_wh,
        "folding_pays_up_to_wh": folding.pays_wh,
        "folding_does_not_pay_from_wh": folding.holds_from_wh,
        "folding_searched_up_to_wh": folding.top_wh,
    }


def folding_line(folding: FoldingPays) -> str:
    """The answer's line on where folding pays
    (:func:`~foldopt.studies.storage_sizing.folding_pays`)."""
    top = _wh(folding.top_wh)
    return {
        "unknown": "whether folding pays with a buffer is not known: no capacity evaluated found "
        "a periodic state",
        "never": f"folding never pays with a buffer up to {top}: at every capacity evaluated flat "
        "runs the load within the near-optimal tolerance of the best twofold angle",
        "below_threshold": f"folding stops paying from {_wh(folding.stops_wh)} of buffer: from "
        f"there up to {top} flat runs the load within the near-optimal tolerance of the best "
        "twofold angle",
        "between": f"folding pays at {_wh(folding.pays_wh)} of buffer and at none evaluated from "
        f"{_wh(folding.holds_from_wh)} up to {top}; the buffers between found no periodic state "
        "(no threshold is known)",
        "at_every_capacity": f"folding pays at every buffer evaluated up to {top}",
        "at_largest_capacity": f"folding still pays at {_wh(folding.pays_wh)}, the largest buffer "
        + (
            "evaluated"
            if folding.pays_wh == folding.top_wh
            else f"whose periodic state is known (none up to {top})"
        ),
    }[folding.state]


def buffer_text(storage) -> str:
    """A buffer as an answer says it: ``5 Wh supercapacitor (cut-off 25 %, reconnect 30 %,
    efficiencies 0.98/0.98, self-discharge 2 %/day)``."""
    kind = storage.preset or "buffer"
    limits = [
        f"{name} {value:g} W"
        for name, value in (
            ("charge", storage.max_charge_w),
            ("discharge", storage.max_discharge_w),
        )
        if value is not None
    ]
    start = (
        "periodic steady state"
        if storage.initial_soc is None
        else f"from {100 * storage.initial_soc:g} %"
    )
    return (
        f"{storage.capacity_wh:g} Wh {kind} (cut-off {100 * storage.min_soc:g} %, reconnect "
        f"{100 * storage.restart_soc:g} %, efficiencies {storage.charge_efficiency:g}/"
        f"{storage.discharge_efficiency:g}, self-discharge {100 * storage.self_discharge:g} %/day"
        + (", max " + ", ".join(limits) if limits else "")
        + f"; {start})"
    )


def answer_part(buffered: DayStorage, designs=("flat", "twofold", "tracker", "tracker-net")):
    """What a day's answer says of its buffer: the part of its result and its lines.

    Parameters
    ----------
    buffered : DayStorage
    designs : tuple of str
        The designs the result names one by one.

    Returns
    -------
    result : dict
        JSON-ready but for NaN (the answer's :func:`~foldopt.studies.answer.plain` makes it null).
    lines : list of str
    """
    storage, sizing = buffered.storage, buffered.sizing
    by = buffered.designs.set_index("design")

    def per_design(column):
        return {d: float(by.loc[d, column]) for d in designs}

    # In the answer's pattern, <quantity>_by_design_<unit>, of the table's <quantity>_<unit>.
    per = {
        "powered_by_design_h": per_design("powered_h"),
        "t_solar_by_design_h": per_design("t_solar_h"),
        "availability_by_design_pct": per_design("availability_pct"),
        "powered_days_ge24h_by_design_pct": per_design("powered_days_ge24h_pct"),
        "energy_missing_by_design_wh": per_design("energy_missing_wh"),
        "energy_lost_by_design_wh": per_design("energy_lost_wh"),
        "days_full_by_design_pct": per_design("days_full_pct"),
        "days_empty_by_design_pct": per_design("days_empty_pct"),
    }
    best_h = float(buffered.powered_by_angle.max())
    part = {
        "buffer": buffer_text(storage),
        # The section's fields as the engine's Buffer takes them.
        "capacity_wh": storage.capacity_wh,
        "min_soc": storage.min_soc,
        "restart_soc": storage.restart_soc,
        "charge_efficiency": storage.charge_efficiency,
        "discharge_efficiency": storage.discharge_efficiency,
        "self_discharge": storage.self_discharge,
        "max_charge_w": storage.max_charge_w,
        "max_discharge_w": storage.max_discharge_w,
        "initial_soc": storage.initial_soc,
        "preset": storage.preset,
        "fold_angle_deg": buffered.fold_angle_deg,
        "powered_h": best_h,
        **buffered.near_optimal,
        **per,
        "soc_hours_by_design_h": {d: buffered.soc_hours[d].tolist() for d in designs},
        **folding_part(sizing.folding),
        "engine": buffered.engine,
        "converged": buffered.converged,
    }
    powered, t_solar = per["powered_by_design_h"], per["t_solar_by_design_h"]
    lines = [
        f"with the {buffer_text(storage)}: powered time "
        + ", ".join(f"{d} {powered[d]:.2f} h (t_solar {t_solar[d]:.2f} h)" for d in designs)
    ]
    near = buffered.near_optimal
    if best_h <= 0:
        lines.append("no fold angle runs the load with the buffer: powered 0 h at every angle")
    else:
        lines.append(
            f"best fold angle for the buffer {buffered.fold_angle_deg:g} deg: powered "
            f"{best_h:.2f} h, {_signed(best_h - powered['flat'], 2)} h over flat; near-optimal "
            f"{near['near_optimal_lo_deg']:g} to {near['near_optimal_hi_deg']:g} deg, "
            f"recommended {near['recommended_deg']:g} deg "
            f"({near['recommended_powered_h']:.2f} h)"
        )
    lines.append(
        "availability "
        + ", ".join(f"{d} {per['availability_by_design_pct'][d]:.1f} %" for d in designs[:3])
        + "; energy missing/lost a day "
        + ", ".join(
            f"{d} {_digits(per['energy_missing_by_design_wh'][d])}/"
            f"{_wh(per['energy_lost_by_design_wh'][d])}"
            for d in designs[:3]
        )
        + "; days full/empty "
        + ", ".join(
            f"{d} {per['days_full_by_design_pct'][d]:.0f}/"
            f"{per['days_empty_by_design_pct'][d]:.0f} %"
            for d in designs[:3]
        )
    )
    if "cold_lost_h" in by:
        first = by.iloc[0]
        part["cold"] = {
            "charge_blocked_h": float(first["charge_blocked_h"]),
            "charge_blocked_days_n": int(first["charge_blocked_days_n"]),
            "cold_lost_by_design_h": per_design("cold_lost_h"),
        }
        lines.append(
            f"the cold: charge blocked {first['charge_blocked_h']:g} h of the day; powered time "
            "lost "
            + ", ".join(f"{d} {part['cold']['cold_lost_by_design_h'][d]:.2f} h" for d in designs)
        )
    top = sizing.folding.top_wh
    lines.append(folding_line(sizing.folding))
    if len(sizing.table):
        target = storage.target
        table = sizing.table.set_index("design")
        need = table["capacity_wh"]
        angle = float(table.loc["twofold", "fold_angle_deg"])
        saving = float(table.loc["twofold", "capacity_gain_vs_flat_pct"])
        part["sizing"] = {
            "target_powered_h": target.powered_h,
            "target_days_pct": target.days_pct,
            "capacity_by_design_wh": {d: float(need[d]) for d in table.index},
            "fold_angle_twofold_deg": angle,
            "capacity_twofold_vs_flat_pct": saving,
            "monotone_by_design": {d: bool(table.loc[d, "monotone"]) for d in table.index},
            "searched_up_to_wh": top,
        }
        if "capacity_cold_off_wh" in table:
            part["sizing"]["capacity_cold_off_by_design_wh"] = {
                d: float(table.loc[d, "capacity_cold_off_wh"]) for d in table.index
            }
        said = f"{target.powered_h:g} h" + (
            f" on {target.days_pct:g} % of days" if target.days_pct < 100 else ""
        )
        none = f"no buffer up to {_wh(top)} reaches it"

        def needs(label, value):
            return f"{label} needs {_wh(value)}" if value == value else f"{label}: {none}"

        lines.append(
            f"for {said}: {none} (flat, folded at {angle:g} deg, the tracker gross or net)"
            if need.isna().all()
            else f"for {said}: {needs('flat', need['flat'])}, "
            f"{needs(f'folded at {angle:g} deg', need['twofold'])}"
            + (f" ({_signed(saving, 0)} %)" if saving == saving else "")
            + f", {needs('the tracker', need['tracker'])}"
            + f" ({needs('net of its drive', need['tracker-net'])})"
        )
        if "capacity_cold_off_wh" in table:
            lines.append(
                "buffer needed with the cold off: "
                + ", ".join(f"{d} {_wh(table.loc[d, 'capacity_cold_off_wh'])}" for d in table.index)
            )
        if not table["monotone"].all():
            lines.append(not_monotone_note(table.index[~table["monotone"].to_numpy()]))
    if not buffered.converged:
        lines.append(
            "note: the buffer found no periodic state for some designs or angles (its end state "
            "never repeats its start's): their powered time is the last pass's"
        )
    return part, lines


_MONTHS = "Jan Feb Mar Apr May Jun Jul Aug Sep Oct Nov Dec".split()


def cold_line(by: pd.DataFrame, named: dict, designs) -> str:
    """A year's line on what the cold costs, of one load's rows by design (:func:`year_lines`):
    the charger blocked (hours, days), the powered time lost beside the same run with the cold
    off (a day, and in the worst month), and the buffer needed with and without the cold."""
    first = by.iloc[0]
    lost = ", ".join(
        f"{named[d]} {by.loc[d, 'cold_lost_mean_h']:.2f} h"
        + (
            f" ({by.loc[d, 'cold_lost_worst_month_h']:.2f} h in "
            f"{_MONTHS[int(by.loc[d, 'cold_worst_month']) - 1]})"
            if by.loc[d, "cold_worst_month"] > 0
            else ""
        )
        for d in designs
    )
    line = (
        f"  the cold: charge blocked {first['charge_blocked_h']:g} h on "
        f"{first['charge_blocked_days_n']:g} days; powered time lost a day {lost}"
    )
    if "capacity_cold_off_wh" in by:
        line += "; buffer needed with/without the cold " + ", ".join(
            f"{named[d]} {_wh(by.loc[d, 'capacity_wh'])}/{_wh(by.loc[d, 'capacity_cold_off_wh'])}"
            for d in designs
        )
    return line


#: The designs a year's answer names one by one.
YEAR_SAID = ("flat", "twofold", "twofold-buffer", "tracker")


def _another(angle) -> bool:
    """Whether the angle the objective of powered time keeps was chosen and is not
    ``t_solar``'s (the year's lines then name it apart)."""
    chosen = angle["twofold-buffer"]
    return chosen == chosen and chosen != angle["twofold"]


def _best_for_buffer(by: pd.DataFrame, angle) -> str:
    """A year's line on the fold angle the objective of powered time keeps, of one load's rows
    by design (:func:`year_lines`)."""
    best = by.loc["twofold-buffer"]
    statistic = best["objective"]
    said = f"  best fold angle for the buffer ({statistic} powered time)"
    return (
        f"{said}: {angle['twofold-buffer']:g} deg, {best['powered_objective_h']:.2f} h (t_solar's "
        f"{angle['twofold']:g} deg: {by.loc['twofold', 'powered_objective_h']:.2f} h; flat "
        f"{by.loc['flat', 'powered_objective_h']:.2f} h); "
        + (
            f"near-optimal {best['near_optimal_lo_deg']:g} to {best['near_optimal_hi_deg']:g} deg, "
            f"recommended {best['recommended_deg']:g} deg"
            if best["near_optimal_lo_deg"] == best["near_optimal_lo_deg"]
            else f"no fold angle runs the load ({statistic} powered time 0 h at every angle): no "
            "near-optimal range"
        )
    )


def worst_years(years: pd.DataFrame) -> pd.DataFrame:
    """Each load's and design's worst calendar year, where the days span several
    (``storage_years.csv``' flagged rows; none over one year), with ``powered_typical_h``, the
    median year's mean daily powered time [h].

    Parameters
    ----------
    years : pandas.DataFrame
        :func:`foldopt.studies.storage_periods.storage_years`' rows, case after case.
    """
    block = (years["design"] != years["design"].shift()).cumsum()
    several = block.map(block.value_counts()) > 1
    rows = years[years["worst_year"] & several].copy()
    rows["powered_typical_h"] = rows["powered_mean_h"] - rows["powered_vs_typical_h"]
    return rows.reset_index(drop=True)


def _worst_year_line(named: dict, worst: pd.DataFrame) -> str:
    """A load's line on its designs' worst years (:func:`worst_years`' rows by design)."""
    return "  worst year: " + "; ".join(
        f"{named[d]} {row['year']:d}: {row['powered_mean_h']:.2f} h a day "
        f"({_signed(row['powered_vs_typical_h'], 2)} h on the typical year's "
        f"{row['powered_typical_h']:.2f} h; worst month {_MONTHS[row['worst_month'] - 1]} "
        f"{row['powered_worst_month_h']:.2f} h), all 24 h on "
        f"{row['powered_days_ge24h_pct']:.0f} % of its days"
        for d, row in worst.iterrows()
        if d in named
    )


def year_lines(
    storage, table: pd.DataFrame, in_sequence: bool, worst: pd.DataFrame | None = None
) -> list[str]:
    """What an annual answer says of its buffer, per load (at most 8): powered time per design,
    the fold angle the objective of powered time keeps beside the one ``t_solar``'s keeps, and
    over several calendar years each design's worst year (``worst``: :func:`worst_years`, in
    the table's order) and the sizing for the target in ``storage.target.years`` of them."""
    how = (
        "the days in sequence from the last one's end state"
        if in_sequence
        else "each day repeated to its periodic state"
    )
    lines = [f"with the {buffer_text(storage)}, {how}:"]
    cases = [
        table.iloc[start : start + len(YEAR_DESIGNS)]
        for start in range(0, len(table), len(YEAR_DESIGNS))
    ]
    sites = table[["latitude", "longitude"]].drop_duplicates()
    worst = worst if worst is not None and len(worst) else None
    for case, rows in enumerate(cases[:8]):
        by = rows.set_index("design")
        first = rows.iloc[0]
        p_load = first["p_load_w"]
        site = (
            f"{first['site_name'] or f'{first.latitude:g}, {first.longitude:g}'}: "
            if len(sites) > 1
            else ""
        )
        angle = by["fold_angle_deg"]
        named = {
            "flat": "flat",
            "twofold": f"twofold {angle['twofold']:g} deg",
            "twofold-buffer": f"twofold {angle['twofold-buffer']:g} deg",
            "tracker": "tracker",
        }
        lines.append(
            f"  {site}P_load {p_load:g}: mean powered time "
            + ", ".join(
                f"{named[d]} {by.loc[d, 'powered_mean_h']:.2f} h "
                f"(t_solar {by.loc[d, 't_solar_mean_h']:.2f} h)"
                for d in YEAR_SAID
                if d != "twofold-buffer" or _another(angle)
            )
            + "; all 24 h on "
            + ", ".join(f"{d} {by.loc[d, 'powered_days_ge24h_pct']:.0f} %" for d in SOC_DESIGNS)
            + " of days; days full/empty "
            + ", ".join(
                f"{d} {by.loc[d, 'days_full_pct']:.0f}/{by.loc[d, 'days_empty_pct']:.0f} %"
                for d in SOC_DESIGNS
            )
        )
        lines.append(_best_for_buffer(by, angle))
        if worst is not None:
            shown = {
                d: text for d, text in named.items() if d != "twofold-buffer" or _another(angle)
            }
            lines.append(
                _worst_year_line(
                    shown,
                    worst.iloc[case * len(YEAR_DESIGNS) : (case + 1) * len(YEAR_DESIGNS)].set_index(
                        "design"
                    ),
                )
            )
        if "capacity_wh" in by:
            said = storage.target.said(worst is not None)
            need, saving = by["capacity_wh"], by["capacity_gain_vs_flat_pct"]
            lines.append(
                f"  for {said}: "
                + ", ".join(
                    (
                        f"{named[d]} needs {_wh(need[d])}"
                        + (
                            f" ({_signed(saving[d], 0)} %)"
                            if d != "flat" and saving[d] == saving[d]
                            else ""
                        )
                        if need[d] == need[d]
                        else f"{named[d]}: no buffer up to the search's top reaches it"
                    )
                    for d in YEAR_SAID
                    if d != "twofold-buffer" or _another(angle)
                )
            )
        if "cold_lost_mean_h" in by:
            lines.append(
                cold_line(
                    by, named, [d for d in YEAR_SAID if d != "twofold-buffer" or _another(angle)]
                )
            )
    if len(cases) > 8:
        lines.append(f"  ... and {len(cases) - 8} more (storage_annual.csv)")
    if "monotone" in table and not table["monotone"].all():
        lines.append(not_monotone_note(dict.fromkeys(table.loc[~table["monotone"], "design"])))
    if not table["converged"].all():
        lines.append(
            "note: the buffer found no periodic state for some designs: their powered time is "
            "the last pass's"
        )
    return lines
