"""The vocabulary: one name per quantity, in every CSV, JSON document, report.html and the API.

:data:`COLUMNS` lists every column a command writes, once, with its unit and meaning; a name with
``{design}`` or ``{connection}`` stands for one column per design (``flat``, ``twofold``,
``tracker``, ``tracker_net``) or connection, ``{pct}`` for one per percentile of a cloud
ensemble (10, 50, 90). A sweep's other varied fields are columns named by
their dotted path (``tracker.standby_w``). The manual's table (``docs/columns.rst``) is
:func:`rst_table`, and a test checks every command's columns against :func:`describe`.

``python -m foldopt.output.columns`` prints the table.
"""

from __future__ import annotations

import re

from foldopt.studies.objectives import ENSEMBLE_PERCENTILES

#: (name, unit, meaning), in the order the manual lists them.
COLUMNS = (
    # the case
    ("site_id", "-", "the site's index in a map"),
    ("site_name", "", "the site's name (empty for a grid point)"),
    ("name", "", "a named site (sites.csv of a map)"),
    ("latitude", "deg", "site latitude, north positive"),
    ("longitude", "deg", "site longitude, east positive"),
    ("altitude", "m", "site altitude"),
    ("timezone", "", "the site's time zone"),
    ("weather", "", "the weather file a map's site comes from"),
    ("date", "", "the local day (YYYY-MM-DD); in a schedule, the day of a re-fold visit"),
    ("dayofyear", "-", "day of the year of ``date``"),
    (
        "p_load_w",
        "W",
        "the load; with a load profile, the profile's scale [-] (the answer names the profile)",
    ),
    ("p_load_fraction", "-", "the load as a share of the site's flat peak (maps)"),
    ("peak_power_flat_w", "W", "the flat panel's largest power over the year (maps)"),
    ("period", "", "year, or the season DJF, MAM, JJA, SON (maps)"),
    ("days", "-", "days of the period or case"),
    (
        "design",
        "",
        "flat, twofold (at the optimum), twofold-heuristic, twofold-<connection>, tracker, "
        "tracker-net (net of its own draw), tracker:<model> and tracker:<model>-net",
    ),
    # the design's settings and its daily metrics
    (
        "fold_angle_deg",
        "deg",
        "the fold angle Θ (180 = flat); empty for trackers, and in annual_summary.csv where "
        "the angle varies by day",
    ),
    ("fold_angle_min_deg", "deg", "the least of the days' fold angles (annual_summary.csv)"),
    ("fold_angle_max_deg", "deg", "the largest of the days' fold angles (annual_summary.csv)"),
    (
        "surface_tilt",
        "deg",
        "the panel's base tilt from horizontal (foldopt optimize; a map's twofold panel)",
    ),
    (
        "surface_tilt_flat",
        "deg",
        "the flat panel's tilt: the site's, or its own best with map --optimize tilt",
    ),
    ("surface_azimuth", "deg", "the panel's base azimuth, clockwise from north (foldopt optimize)"),
    ("t_solar_h", "h", "solar-powered time of the day: P_pv >= P_load"),
    ("t_solar_contiguous_h", "h", "the longest contiguous solar-powered interval"),
    (
        "t_solar_{connection}_h",
        "h",
        "t_solar of one connection at each fold angle (sweep.csv); independent's "
        "runs through a converter per sub-panel, even where the load is wired "
        "directly (circuit.coupling direct)",
    ),
    (
        "t_solar_{design}_h",
        "h",
        "t_solar of one design as the tracker's standby grows (tracker_standby.csv)",
    ),
    ("energy_harvested_wh", "Wh", "energy at the maximum power point over the day (or the period)"),
    (
        "energy_harvested_{connection}_wh",
        "Wh",
        "energy of one connection at each fold angle (sweep.csv); "
        "independent's through a converter per sub-panel, as its t_solar",
    ),
    ("energy_harvested_{design}_wh", "Wh", "energy of one design over the period (maps)"),
    ("energy_served_wh", "Wh", "energy the load draws while solar-powered"),
    (
        "energy_wasted_wh",
        "Wh",
        "harvested but not served; never negative (a tracker whose drive costs more than it "
        "harvests has a negative net harvest, served and wasted 0, and a note)",
    ),
    ("peak_power_w", "W", "the day's largest power"),
    ("poa_kwh_m2", "kWh/m^2", "plane-of-array irradiation (mean of the two sub-panels)"),
    (
        "noon_valley_w",
        "W",
        "the parallel curve's minimum between the sub-panels' peaks (Shin et al. Eq. 8)",
    ),
    (
        "flat_area_multiple",
        "-",
        "how many times larger a flat panel must be to reach the design's t_solar",
    ),
    ("gain_vs_flat_pct", "%", "t_solar (or the objective) over the flat panel's, less 100"),
    ("pct_of_tracker", "%", "t_solar (or the objective) as a share of the tracker's"),
    ("energy_gain_vs_flat_pct", "%", "harvested energy over the flat panel's, less 100"),
    ("energy_pct_of_tracker", "%", "harvested energy as a share of the tracker's"),
    (
        "note",
        "",
        "polar night, polar day, overcast, load above peak (of that design); in annual_summary.csv, "
        "that the fold angle varies by day, or that the totals are the days' evaluated, not their "
        "period's",
    ),
    # the near-optimal range
    ("near_optimal_lo_deg", "deg", "the least fold angle on the best one's plateau"),
    ("near_optimal_hi_deg", "deg", "the largest fold angle on the best one's plateau"),
    (
        "recommended_fold_angle_deg",
        "deg",
        "the angle at the centre of the near-optimal range; 180 where the flat panel is best",
    ),
    (
        "near_optimal_tolerance_h",
        "h",
        "how far below the best an angle may fall and still be near-optimal",
    ),
    (
        "near_optimal_width_deg",
        "deg",
        "near_optimal_hi_deg - near_optimal_lo_deg (a map's figure of it)",
    ),
    # the joint optimisation (foldopt optimize)
    (
        "variable",
        "",
        "fold_angle, tilt or azimuth: the variable a row of near_optimal.csv or added.csv is of; "
        "its near-optimal range is then in that variable's degrees",
    ),
    (
        "recommended_deg",
        "deg",
        "the value at the centre of a variable's near-optimal range; a fold of 180 where flat "
        "is best",
    ),
    (
        "added_h",
        "h",
        "what a variable adds to the objective as it joins the search (fold angle, tilt, azimuth)",
    ),
    ("evaluated_designs", "-", "designs the search evaluated"),
    ("grid_designs", "-", "designs of the full grid, what a brute-force sweep evaluates"),
    # statistics over days
    ("objective", "", "the statistic maximised: mean, min, worst-month or pNN"),
    ("objective_h", "h", "the objective's value: that statistic of daily t_solar"),
    ("objective_{design}_h", "h", "the objective of one design"),
    ("worst_month", "-", "the month (1-12) of the lowest monthly mean, for worst-month"),
    ("mean_t_solar_h", "h", "mean daily t_solar"),
    ("mean_t_solar_{design}_h", "h", "mean daily t_solar of one design (maps)"),
    ("min_t_solar_h", "h", "the least daily t_solar"),
    ("p10_t_solar_h", "h", "10th percentile of daily t_solar"),
    ("p50_t_solar_h", "h", "median daily t_solar"),
    ("p90_t_solar_h", "h", "90th percentile of daily t_solar"),
    ("days_ge_{hours}h", "-", "days with t_solar of at least that many hours"),
    ("month_{month}_mean_t_solar_h", "h", "mean daily t_solar of that month"),
    ("chosen", "", "the fold angle chosen for the year (annual_fold_angles.csv)"),
    (
        "break_even_standby_tracker_w",
        "W",
        "the tracker's standby draw at which the twofold panel catches up",
    ),
    ("standby_w", "W", "the tracker's standby draw"),
    # re-fold schedules
    ("settings", "-", "fold settings a year (1 = one fixed angle)"),
    ("visit", "-", "the visit's number in its schedule"),
    ("gain_vs_fixed_pct", "%", "the schedule's objective over the single fixed angle's, less 100"),
    ("added_by_setting_h", "h", "what the schedule's last setting adds to the objective"),
    # a cloud ensemble (weather.members)
    (
        "t_solar_p{pct}_h",
        "h",
        "a day's t_solar over the ensemble's members: percentile 10, 50 or 90",
    ),
    (
        "objective_p{pct}_h",
        "h",
        "the objective over the ensemble's members: percentile 10, 50 or 90",
    ),
    ("chosen_wins_pct", "%", "the members whose own best fold angle is the one chosen"),
    (
        "within_tolerance_pct",
        "%",
        "the members for which the angle chosen is within the near-optimal tolerance "
        "of their own best",
    ),
    ("wins_pct", "%", "the members whose own best fold angle is this one"),
    # the day's time series
    ("time", "", "the step's centre, local time with its offset"),
    ("solar_zenith", "deg", "solar zenith angle"),
    ("solar_azimuth", "deg", "solar azimuth, clockwise from north"),
    ("dni", "W/m^2", "direct normal irradiance"),
    ("ghi", "W/m^2", "global horizontal irradiance (with diffuse light)"),
    ("dhi", "W/m^2", "diffuse horizontal irradiance (with diffuse light)"),
    (
        "temp_air",
        "C",
        "the air temperature the cells see (a weather file's, with its wind folded in)",
    ),
    ("wind_speed", "m/s", "a weather file's wind speed"),
    ("p_{design}_w", "W", "a design's power at the optimum (p_twofold_w: the study's connection)"),
    ("p_{connection}_w", "W", "a connection's power at the optimum"),
    ("switch_state", "", "the connection switching chose (off where no power)"),
    # a buffer (a study's storage section)
    (
        "powered_h",
        "h",
        "hours a day the load runs with the buffer, from PV or from it (summary.csv per design; "
        "sweep.csv at each fold angle)",
    ),
    ("availability_pct", "%", "the load's energy served, of its demand, with the buffer"),
    ("days_powered_24h_pct", "%", "days on which the load ran all day (no energy missing)"),
    ("energy_missing_wh", "Wh", "the load's energy not served a day (the load off)"),
    ("energy_lost_wh", "Wh", "PV energy a day neither served nor stored (the buffer full)"),
    ("days_full_pct", "%", "days on which the buffer was full at some time (PVGIS's)"),
    ("days_empty_pct", "%", "days on which the controller cut the load off (PVGIS's)"),
    ("soc_{design}", "-", "the buffer's state of charge at the step (timeseries.csv)"),
    (
        "capacity_wh",
        "Wh",
        "a buffer's usable energy: on the curve, or a design's least for the target",
    ),
    ("powered_{design}_h", "h", "powered time of one design at a capacity (storage_capacity.csv)"),
    ("capacity_vs_flat_pct", "%", "the design's buffer for the target over flat's, less 100"),
    (
        "monotone",
        "",
        "every larger capacity of the sizing's grid reaches the target too (False: hysteresis or "
        "self-discharge; the capacity is the least evaluated that reaches it)",
    ),
    ("mean_powered_h", "h", "mean daily powered time with the buffer (storage_annual.csv)"),
    ("min_powered_h", "h", "the least daily powered time with the buffer (storage_annual.csv)"),
    (
        "objective_powered_h",
        "h",
        "the objective's statistic of daily powered time with the buffer (storage_annual.csv)",
    ),
    (
        "converged",
        "",
        "whether every series of the buffer found its periodic state (storage_annual.csv)",
    ),
    # sizing
    ("area_m2", "m^2", "the panel's area"),
    ("benefit_usd", "$", "lifetime benefit C_grid x t_solar x P_load (Shin et al. Eq. 7)"),
    ("cost_usd", "$", "the panel's cost"),
    ("net_benefit_usd", "$", "benefit less cost"),
    # reproduction
    ("quantity", "", "a reproduced quantity of Shin et al."),
    ("unit", "", "its unit"),
    ("paper", "", "Shin et al.'s published value"),
    ("paper_mode", "", "foldopt's value in paper mode"),
    ("exact_mode", "", "foldopt's value in exact mode"),
    ("table", "", "which reproduction table a row comes from"),
)

_WORDS = {
    "design": "(flat|twofold|tracker|tracker_net)",
    "connection": "(east|west|parallel|series|independent|switching)",
    "hours": r"(\d+)",
    "month": r"(\d\d)",
    "pct": "(" + "|".join(str(pct) for pct in ENSEMBLE_PERCENTILES) + ")",
}
_PATTERNS = [
    (
        re.compile(
            "^" + re.sub(r"\\\{(\w+)\\\}", lambda m: _WORDS[m.group(1)], re.escape(name)) + "$"
        ),
        name,
        unit,
        meaning,
    )
    for name, unit, meaning in COLUMNS
]
#: A sweep's other varied fields: their dotted paths, or a study field's name.
_FIELD_PATH = re.compile(r"^[a-z][a-z_]*(\.[a-z][a-z_]*)+$")


def describe(column: str) -> tuple[str, str, str] | None:
    """The registry's entry of a column.

    Parameters
    ----------
    column : str
        A column's name as a table has it (``t_solar_flat_h``, ``tracker.standby_w``...).

    Returns
    -------
    tuple of str or None
        ``(name, unit, meaning)``: the name as :data:`COLUMNS` lists it (``t_solar_{design}_h``),
        its unit and its meaning; for a swept study field its dotted path; None for an unknown
        name.
    """
    for pattern, name, unit, meaning in _PATTERNS:
        if pattern.match(column):
            return name, unit, meaning
    from foldopt.inputs.study import Study

    if _FIELD_PATH.match(column) or column in Study.model_fields:
        return column, "", "a swept study field, by its path"
    return None


def rst_table() -> str:
    """The manual's table of columns (``docs/columns.rst``).

    Returns
    -------
    str
        reStructuredText: a title, a paragraph and a list table of :data:`COLUMNS`.
    """
    lines = [
        "Columns",
        "=======",
        "",
        "One name per quantity, in every CSV file, JSON document, report.html and the Python API. A name with",
        "``{design}`` or ``{connection}`` stands for one column per design (flat, twofold, tracker, tracker_net)",
        "or connection. A sweep's other varied fields are columns named by their dotted path",
        "(``tracker.standby_w``). Generated by ``python -m foldopt.output.columns`` from "
        ":mod:`foldopt.output.columns`; the",
        "test suite checks every command's columns against it.",
        "",
        ".. list-table::",
        "   :header-rows: 1",
        "   :widths: 30 10 60",
        "",
        "   * - column",
        "     - unit",
        "     - meaning",
    ]
    for name, unit, meaning in COLUMNS:
        lines += [f"   * - ``{name}``", f"     - {unit or ' '}", f"     - {meaning}"]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":  # pragma: no cover
    print(rst_table(), end="")
