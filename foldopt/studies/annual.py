"""The year of an annual study in numbers: per case and design, the daily t_solar's statistics,
the totals over the days and each design's gain over flat and share of the tracker
(``annual_summary.csv``, the table ``report.html`` shows for an annual study)."""

from __future__ import annotations

import pandas as pd

from foldopt.engine.metrics import relative_to

#: The daily t_solar thresholds [h] whose days :func:`annual_summary` counts
#: (``t_solar_days_ge<x>h_n``).
THRESHOLDS_H = (2, 4, 6, 8, 10, 12)


def annual_cases(result) -> list[str]:
    """The columns that tell one case of an annual study from another: its site and load, and any
    other field the plan varies but the date.

    Parameters
    ----------
    result : foldopt.studies.sweeps.SweepResult
        A sweep that varies the date (or the day of the year).

    Returns
    -------
    list of str
        Column names of ``result.table``, for :func:`annual_summary`'s ``cases``.
    """
    others = [
        c
        for c in result.varied
        if c not in ("date", "dayofyear", "site_name", "latitude", "p_load_w")
    ]
    return ["site_name", "latitude", *others, "p_load_w"]


def _note(group: pd.DataFrame, lo: float, hi: float) -> str:
    """What a row's numbers are not: one fold angle (where the days' differ), the period's totals
    (where the days evaluated skip some of it, e.g. every 7th day)."""
    dates = pd.to_datetime(group["date"])
    span = (dates.max() - dates.min()).days + 1
    notes = [
        f"fold angle varies by day, {lo:g} to {hi:g} deg (each day's: results.csv)"
        if lo < hi
        else "",
        f"totals over the {len(group)} days evaluated, not the {span} from {dates.min():%Y-%m-%d} to "
        f"{dates.max():%Y-%m-%d}"
        if len(group) < span
        else "",
    ]
    return "; ".join(filter(None, notes))


def annual_summary(
    table: pd.DataFrame, cases=("site_name", "latitude", "longitude", "p_load_w")
) -> pd.DataFrame:
    """The year per case and design: the daily t_solar's statistics, the totals over the days and
    each design's standing against the case's flat panel and tracker.

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep's tidy table (:attr:`foldopt.SweepResult.table`): a row per day, case and design,
        with ``date``, ``design``, ``fold_angle_deg`` [deg], ``t_solar_h`` [h],
        ``energy_harvested_wh``, ``energy_served_wh``, ``energy_wasted_wh`` [Wh] and, where the
        sweep has it, ``poa_global_wh_m2`` [Wh/m^2].
    cases : sequence of str, default ('site_name', 'latitude', 'longitude', 'p_load_w')
        The columns that tell one case from another, but the date (:func:`annual_cases`); those
        missing from ``table`` are ignored.

    Returns
    -------
    pandas.DataFrame
        A row per case and design with ``days_n``, the fold angle [deg] and:

        - ``fold_angle_deg``, the design's angle where every day has the same (a flat panel's, an
          objective's); empty where it varies by day (each day its own best), as for a tracker,
          which has none; ``fold_angle_min_deg`` and ``fold_angle_max_deg``, the least and
          largest of the days' angles; ``note``, where the angle varies, that it does;

        - daily t_solar [h]: ``t_solar_mean_h``, ``t_solar_p10_h``, ``t_solar_p50_h``,
          ``t_solar_p90_h``, ``t_solar_min_h``, the days reaching each of :data:`THRESHOLDS_H`
          (``t_solar_days_ge<x>h_n``) and the monthly means ``t_solar_month<mm>_mean_h``;
        - the totals over the days evaluated: energy harvested, served and wasted [Wh] and the
          plane-of-array irradiation ``poa_global_wh_m2`` [Wh/m^2] (where they skip days of their
          period, e.g. every 7th day, the ``note`` says so: not the period's totals);
        - each design's gain over the case's flat panel (``gain_vs_flat_pct``) and share of its
          tracker (``share_of_tracker_pct``) in mean daily t_solar, and the same in energy
          harvested (``energy_harvested_gain_vs_flat_pct``,
          ``energy_harvested_share_of_tracker_pct``) [%]; served energy is the load times t_solar,
          so it moves with the time.
    """
    table = table.assign(month=pd.to_datetime(table["date"]).dt.month)
    cases = [c for c in cases if c in table]
    keys = cases + ["design"]
    rows = []
    for key, group in table.groupby(keys, sort=False):
        hours = group["t_solar_h"]
        row = dict(zip(keys, key if isinstance(key, tuple) else (key,), strict=True))
        lo, hi = group["fold_angle_deg"].min(), group["fold_angle_deg"].max()
        # One angle stands for the days only where every day has it: a design re-folded to each day's
        # best has a range, not an angle, and the first day's would stand for no other day.
        row.update(
            days_n=len(group),
            fold_angle_deg=lo if lo == hi else float("nan"),
            fold_angle_min_deg=lo,
            fold_angle_max_deg=hi,
            note=_note(group, lo, hi),
            t_solar_mean_h=hours.mean(),
            energy_harvested_wh=group["energy_harvested_wh"].sum(),
            energy_served_wh=group["energy_served_wh"].sum(),
            energy_wasted_wh=group["energy_wasted_wh"].sum(),
        )
        if "poa_global_wh_m2" in group:
            row["poa_global_wh_m2"] = group["poa_global_wh_m2"].sum()
        row.update(
            t_solar_p10_h=hours.quantile(0.1),
            t_solar_p50_h=hours.median(),
            t_solar_p90_h=hours.quantile(0.9),
            t_solar_min_h=hours.min(),
        )
        row.update({f"t_solar_days_ge{x}h_n": int((hours >= x).sum()) for x in THRESHOLDS_H})
        row.update(
            {
                f"t_solar_month{m:02d}_mean_h": v
                for m, v in group.groupby("month")["t_solar_h"].mean().items()
            }
        )
        rows.append(row)
    summary = pd.DataFrame(rows)
    for reference, gain, energy_gain in (
        ("flat", "gain_vs_flat_pct", "energy_harvested_gain_vs_flat_pct"),
        ("tracker", "share_of_tracker_pct", "energy_harvested_share_of_tracker_pct"),
    ):
        base = summary[summary["design"] == reference].set_index(cases)[
            ["energy_harvested_wh", "t_solar_mean_h"]
        ]
        matched = base.reindex(
            pd.MultiIndex.from_frame(summary[cases]) if len(cases) > 1 else summary[cases[0]]
        )
        energy = relative_to(
            summary["energy_harvested_wh"], matched["energy_harvested_wh"].to_numpy()
        )
        time = relative_to(summary["t_solar_mean_h"], matched["t_solar_mean_h"].to_numpy())
        summary[energy_gain] = (energy - 1.0) * 100.0 if reference == "flat" else energy * 100.0
        summary[gain] = (time - 1.0) * 100.0 if reference == "flat" else time * 100.0
    return summary
