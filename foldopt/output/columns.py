"""The vocabulary: one name per quantity, in every CSV, JSON document, report.html and the API.

A column is one of three kinds, and :data:`COLUMNS` lists each once with its unit and meaning:

- a quantity foldopt names, by one grammar (:data:`GRAMMAR`)::

      <quantity>[_<design>][_<statistic>]_<unit>

  the quantity first, then the design or connection it is of, then the statistic over days (or
  over a cloud ensemble's members) and last, always, the unit (:data:`UNITS`): ``t_solar_h``,
  ``t_solar_flat_mean_h``, ``t_solar_objective_members_p10_h``, ``energy_harvested_tracker_wh``,
  ``poa_global_wh_m2``. A statistic stands nowhere but just before the unit, so a quantity's
  statistics sort together; a count ends in ``_n``, a share of a whole in ``_frac``;
- a quantity pvlib names (:data:`PVLIB_NAMES`), written as pvlib's nomenclature [1]_ writes it, in
  pvlib's unit: ``latitude``, ``surface_tilt``, ``dni``, ``temp_air``. These are the names a
  weather file or a map's ``--sites`` file is read with, so what is written back is read the
  same way; extended by a design or a statistic, a pvlib word is foldopt's name and takes its
  unit (``surface_tilt_flat_deg``, ``poa_global_wh_m2``);
- a quantity PVGIS's off-grid calculator names (:data:`PVGIS_NAMES`), in ``storage_monthly.csv``
  only, as its response writes it (``E_d``, ``f_f``, ``f_CS_01``), so that the table reads as
  PVGIS's answer does;
- a label, which says which row this is or what it is (a site's name, a date, a design, a note,
  a flag): no unit.

A name with ``{design}``, ``{connection}``, ``{half}``, ``{pct}``, ``{hours}``, ``{month}`` or
``{bin}`` stands for one column per design (``flat``, ``twofold``, ``tracker``, ``tracker_net``),
connection, half of the panel (``east``, ``west``), percentile of a cloud ensemble (10, 50, 90),
threshold, month or bin of a histogram. A sweep's other varied fields are columns
named by their dotted path in a study file (``tracker.standby_w``). The manual's table
(``docs/columns.rst``) is :func:`rst_table`, and a test checks every command's columns against
:func:`describe` and :func:`parse`.

``python -m foldopt.output.columns`` prints the table.

References
----------
.. [1] pvlib python, Nomenclature (pvlib-python.readthedocs.io, user_guide/extras/nomenclature).
"""

from __future__ import annotations

import re
import textwrap

from foldopt.names import CONNECTIONS
from foldopt.studies.annual import THRESHOLDS_H
from foldopt.studies.objectives import ENSEMBLE_PERCENTILES

#: The unit a quantity's name ends in -> the unit as the manual writes it, and in UDUNITS spelling
#: (what ``map.nc``'s ``units`` attributes say).
UNITS = {
    "h": ("h", "h"),
    "wh": ("Wh", "W h"),
    "w": ("W", "W"),
    "wh_m2": ("Wh/m^2", "W h m-2"),
    "w_m2": ("W/m^2", "W m-2"),
    "deg": ("deg", "degree"),
    "pct": ("%", "percent"),
    "frac": ("0-1", "1"),
    "ratio": ("x", "1"),
    "n": ("count", "1"),
    "m2": ("m^2", "m2"),
    "m": ("m", "m"),
    "c": ("C", "degC"),
    "m_s": ("m/s", "m s-1"),
    "usd": ("$", "USD"),
}
#: What each unit that is no physical one means.
UNIT_MEANINGS = {
    "frac": "a share of a whole, 0 to 1",
    "ratio": "how many times another quantity",
    "n": "a count (of days, designs, settings)",
}
#: The designs and connections a quantity may be of, as names spell them.
DESIGN_WORDS = ("flat", "twofold", "tracker", "tracker_net")
CONNECTION_WORDS = tuple(CONNECTIONS)
#: The statistics over days (or a map's sites): ``objective`` is the study's own (mean, min,
#: worst-month or pNN), ``days_ge<x>h`` counts the days reaching x hours, ``month<mm>_mean`` is a
#: month's mean; over a cloud ensemble's members, ``members_p<pct>`` follows the statistic over
#: days, if any.
DAY_STATISTIC = r"(?:month\d\d_)?(?:mean|median|min|max|p\d\d|objective|days_ge\d+h)"
MEMBER_STATISTIC = r"members_p\d\d"
#: Words a quantity holds none of: a statistic's (its place is before the unit) and kilo-units
#: (energy is in Wh everywhere).
_NOT_IN_QUANTITY = re.compile(r"^(?:mean|min|max|median|objective|p\d\d|month\d\d|kwh|kw)$")


def _alternatives(words) -> str:
    return "|".join(sorted(words, key=len, reverse=True))


#: ``<quantity>[_<design>][_<statistic>]_<unit>``: the quantity as short as the rest allows.
GRAMMAR = re.compile(
    r"^(?P<quantity>[a-z][a-z0-9]*(?:_[a-z0-9]+)*?)"
    rf"(?:_(?P<design>{_alternatives(DESIGN_WORDS + CONNECTION_WORDS)}))?"
    rf"(?:_(?P<statistic>{DAY_STATISTIC}(?:_{MEMBER_STATISTIC})?|{MEMBER_STATISTIC}))?"
    rf"_(?P<unit>{_alternatives(UNITS)})$"
)
#: Quantities pvlib names, in its units: written bare, as a weather or sites file is read.
PVLIB_NAMES = {
    "latitude": "deg",
    "longitude": "deg",
    "altitude": "m",
    "surface_tilt": "deg",
    "surface_azimuth": "deg",
    "apparent_zenith": "deg",
    "zenith": "deg",
    "solar_azimuth": "deg",
    "dni": "w_m2",
    "ghi": "w_m2",
    "dhi": "w_m2",
    "temp_air": "c",
    "wind_speed": "m_s",
}
#: Quantities PVGIS's off-grid calculator (``SHScalc``) names, in its units (an energy a day as
#: ``wh``): written as its response writes them, for a table compared with its answer.
PVGIS_NAMES = {
    "d_total": "n",
    "E_d": "wh",
    "E_lost_d": "wh",
    "f_f": "pct",
    "f_e": "pct",
    **{f"f_CS_{index:02d}": "pct" for index in range(1, 11)},
    "E_miss": "wh",
    "E_lost": "wh",
}
#: The unit of a value whose unit is its row's ``unit`` column (the reproduction's tables).
ROW_UNIT = "row"

#: (name, unit, meaning), in the order the manual lists them: the unit is a key of
#: :data:`UNITS`, :data:`ROW_UNIT`, or empty for a label.
COLUMNS = (
    # the case
    ("site_id", "", "the site's index in a map"),
    ("site_name", "", "the site's name (empty for a grid point)"),
    ("name", "", "a named site (sites.csv of a map)"),
    ("latitude", "deg", "site latitude, north positive"),
    ("longitude", "deg", "site longitude, east positive"),
    ("altitude", "m", "site altitude"),
    ("timezone", "", "the site's time zone"),
    ("weather", "", "the weather file a map's site comes from"),
    ("date", "", "the local day (YYYY-MM-DD); in a schedule, the day of a re-fold visit"),
    ("dayofyear", "", "day of the year of ``date`` (1-366)"),
    (
        "p_load_w",
        "w",
        "the load; with a load profile, the profile's scale [-] (the answer names the profile)",
    ),
    ("p_load_frac", "frac", "the load as a share of the site's flat peak (maps)"),
    ("peak_power_flat_w", "w", "the flat panel's largest power over the year (maps)"),
    ("period", "", "year, or the season DJF, MAM, JJA, SON (maps)"),
    ("days_n", "n", "days of the period or case"),
    (
        "design",
        "",
        "flat, twofold (at the optimum), twofold-heuristic, twofold-planes (an existing "
        "array's planes as they stand, panel.planes), twofold-<connection>, tracker, "
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
        "surface_tilt_flat_deg",
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
    ("energy_harvested_wh", "wh", "energy at the maximum power point over the day (or the period)"),
    (
        "energy_harvested_{connection}_wh",
        "wh",
        "energy of one connection at each fold angle (sweep.csv); "
        "independent's through a converter per sub-panel, as its t_solar",
    ),
    ("energy_harvested_{design}_wh", "wh", "energy of one design over the period (maps)"),
    ("energy_served_wh", "wh", "energy the load draws while solar-powered"),
    (
        "energy_wasted_wh",
        "wh",
        "harvested but not served; never negative (a tracker whose drive costs more than it "
        "harvests has a negative net harvest, served and wasted 0, and a note)",
    ),
    ("peak_power_w", "w", "the day's largest power"),
    (
        "poa_global_wh_m2",
        "wh_m2",
        "plane-of-array irradiation: pvlib's poa_global summed over the day (or the period); "
        "a twofold panel's is the mean of its two sub-panels'",
    ),
    (
        "noon_valley_w",
        "w",
        "the parallel curve's minimum between the sub-panels' peaks (Shin et al. Eq. 8)",
    ),
    (
        "flat_area_ratio",
        "ratio",
        "how many times larger a flat panel must be to reach the design's t_solar",
    ),
    ("gain_vs_flat_pct", "pct", "t_solar (or the objective) over the flat panel's, less 100"),
    ("share_of_tracker_pct", "pct", "t_solar (or the objective) as a share of the tracker's"),
    (
        "energy_harvested_gain_vs_flat_pct",
        "pct",
        "harvested energy over the flat panel's, less 100",
    ),
    (
        "energy_harvested_share_of_tracker_pct",
        "pct",
        "harvested energy as a share of the tracker's",
    ),
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
        "recommended_deg",
        "deg",
        "the centre of the near-optimal range: a fold angle, 180 where the flat panel is best "
        "(in near_optimal.csv of foldopt optimize, of the row's variable)",
    ),
    (
        "recommended_t_solar_h",
        "h",
        "t_solar at the recommended fold angle (the answer's near-optimal range, run.json)",
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
        "added_h",
        "h",
        "what a variable adds to the objective as it joins the search (fold angle, tilt, azimuth)",
    ),
    ("designs_evaluated_n", "n", "designs the search evaluated"),
    ("designs_grid_n", "n", "designs of the full grid, what a brute-force sweep evaluates"),
    # statistics over days
    ("objective", "", "the statistic maximised: mean, min, worst-month or pNN"),
    ("t_solar_objective_h", "h", "the objective's value: that statistic of daily t_solar"),
    ("t_solar_{design}_objective_h", "h", "the objective of one design"),
    ("worst_month", "", "the month (1-12) of the lowest monthly mean, for worst-month"),
    ("t_solar_mean_h", "h", "mean daily t_solar"),
    ("t_solar_{design}_mean_h", "h", "mean daily t_solar of one design (maps)"),
    ("t_solar_min_h", "h", "the least daily t_solar"),
    ("t_solar_p10_h", "h", "10th percentile of daily t_solar"),
    ("t_solar_p50_h", "h", "median daily t_solar"),
    ("t_solar_p90_h", "h", "90th percentile of daily t_solar"),
    ("t_solar_days_ge{hours}h_n", "n", "days with t_solar of at least that many hours"),
    ("t_solar_month{month}_mean_h", "h", "mean daily t_solar of that month"),
    ("chosen", "", "the fold angle chosen for the year (annual_fold_angles.csv)"),
    (
        "break_even_standby_tracker_w",
        "w",
        "the tracker's standby draw at which the twofold panel catches up",
    ),
    ("standby_w", "w", "the tracker's standby draw"),
    # re-fold schedules
    ("settings_n", "n", "fold settings a year (1 = one fixed angle)"),
    ("visit", "", "the visit's number in its schedule"),
    (
        "gain_vs_fixed_pct",
        "pct",
        "the schedule's objective over the single fixed angle's, less 100",
    ),
    ("added_by_setting_h", "h", "what the schedule's last setting adds to the objective"),
    # a cloud ensemble (weather.members)
    (
        "t_solar_members_p{pct}_h",
        "h",
        "a day's t_solar over the ensemble's members: percentile 10, 50 or 90",
    ),
    (
        "t_solar_objective_members_p{pct}_h",
        "h",
        "the objective over the ensemble's members: percentile 10, 50 or 90",
    ),
    ("chosen_wins_pct", "pct", "the members whose own best fold angle is the one chosen"),
    (
        "within_tolerance_pct",
        "pct",
        "the members for which the angle chosen is within the near-optimal tolerance "
        "of their own best",
    ),
    ("wins_pct", "pct", "the members whose own best fold angle is this one"),
    # the time series (a day's, or every day's of a study over many days)
    ("time", "", "the step's centre, local time with its UTC offset"),
    (
        "apparent_zenith",
        "deg",
        "the sun's zenith angle with atmospheric refraction (pvlib's apparent_zenith, NREL SPA): "
        "exact mode's sun",
    ),
    (
        "zenith",
        "deg",
        "the sun's geometric zenith angle, no refraction (pvlib's zenith): paper mode's sun "
        "(Shin et al. Eq. 3-6)",
    ),
    ("solar_azimuth", "deg", "solar azimuth, clockwise from north"),
    ("dni", "w_m2", "direct normal irradiance"),
    ("ghi", "w_m2", "global horizontal irradiance (with diffuse light)"),
    ("dhi", "w_m2", "diffuse horizontal irradiance (with diffuse light)"),
    (
        "temp_air",
        "c",
        "the air temperature the cells see (a weather file's, with its wind folded in)",
    ),
    ("wind_speed", "m_s", "a weather file's wind speed"),
    (
        "poa_global_{half}_w_m2",
        "w_m2",
        "plane-of-array irradiance incident on a half at the fold angle "
        "(pvlib's poa_global, before an incidence-angle modifier)",
    ),
    ("p_{design}_w", "w", "a design's power at the optimum (p_twofold_w: the study's connection)"),
    (
        "p_{connection}_w",
        "w",
        "a connection's power at the optimum; p_east_w and p_west_w: each half's alone",
    ),
    (
        "solar_powered_{design}",
        "",
        "whether the design runs the load at the step (P_pv >= P_load): its steps times the step "
        "length are its t_solar to within a step at each crossing of the load",
    ),
    ("switch_state", "", "the connection switching chose (off where no power)"),
    # a buffer (a study's storage section)
    (
        "powered_h",
        "h",
        "hours a day the load runs with the buffer, from PV or from it (summary.csv per design; "
        "sweep.csv at each fold angle)",
    ),
    ("availability_pct", "pct", "the load's energy served, of its demand, with the buffer"),
    (
        "powered_days_ge24h_pct",
        "pct",
        "days on which the load ran all day (no energy missing)",
    ),
    ("energy_missing_wh", "wh", "the load's energy not served a day (the load off)"),
    ("energy_lost_wh", "wh", "PV energy a day neither served nor stored (the buffer full)"),
    ("days_full_pct", "pct", "days on which the buffer was full at some time (PVGIS's)"),
    ("days_empty_pct", "pct", "days on which the controller cut the load off (PVGIS's)"),
    ("soc_{design}_frac", "frac", "the buffer's state of charge at the step (timeseries.csv)"),
    (
        "capacity_wh",
        "wh",
        "a buffer's usable energy: on the curve, or a design's least for the target",
    ),
    ("powered_{design}_h", "h", "powered time of one design at a capacity (storage_capacity.csv)"),
    (
        "capacity_gain_vs_flat_pct",
        "pct",
        "the design's buffer for the target over flat's, less 100",
    ),
    (
        "monotone",
        "",
        "every larger capacity of the sizing's grid reaches the target too (False: hysteresis or "
        "self-discharge; the capacity is the least evaluated that reaches it)",
    ),
    ("powered_mean_h", "h", "mean daily powered time with the buffer (storage_annual.csv)"),
    (
        "powered_min_h",
        "h",
        "the least daily powered time with the buffer (storage_annual.csv)",
    ),
    (
        "powered_objective_h",
        "h",
        "the objective's statistic of daily powered time with the buffer (storage_annual.csv)",
    ),
    (
        "converged",
        "",
        "whether every series of the buffer found its periodic state (storage_annual.csv)",
    ),
    ("cold_lost_h", "h", "powered time the cold takes (beside the same day with the cold off)"),
    ("charge_blocked_h", "h", "hours the buffer's charger is blocked by the cold, over the days"),
    (
        "charge_blocked_days_n",
        "n",
        "days on which the cold blocks the buffer's charger at some step",
    ),
    (
        "cold_lost_mean_h",
        "h",
        "powered time the cold takes a day (beside the same run with the cold off), the mean",
    ),
    ("cold_lost_month{month}_mean_h", "h", "powered time the cold takes a day in that month"),
    (
        "cold_lost_worst_month_h",
        "h",
        "powered time the cold takes a day in the month it takes most, that month's mean",
    ),
    ("cold_worst_month", "", "the month the cold takes most powered time in (1-12; 0: none)"),
    (
        "capacity_cold_off_wh",
        "wh",
        "a design's least buffer for the target with the cold off (storage_annual.csv)",
    ),
    # the buffer by calendar year (storage_years.csv) and month (storage_monthly.csv)
    ("year", "", "the calendar year of a row (storage_years.csv)"),
    ("month", "", "the calendar month of a row, 1-12, over every year (storage_monthly.csv)"),
    ("energy_missing_total_wh", "wh", "the load's energy not served over the period"),
    (
        "powered_worst_month_h",
        "h",
        "the least of the year's months' mean daily powered time (storage_years.csv)",
    ),
    (
        "powered_vs_typical_h",
        "h",
        "the year's mean daily powered time less the median year's (storage_years.csv)",
    ),
    ("worst_year", "", "the design's year of least mean daily powered time (storage_years.csv)"),
    ("d_total", "n", "PVGIS's: the days of the month over every year (storage_monthly.csv)"),
    ("E_d", "wh", "PVGIS's: average energy a day delivered to the load (Wh/d)"),
    ("E_lost_d", "wh", "PVGIS's: average PV energy a day not captured, the buffer full (Wh/d)"),
    ("f_f", "pct", "PVGIS's: the days on which the buffer became full"),
    ("f_e", "pct", "PVGIS's: the days on which the buffer became empty (the cut-off)"),
    (
        "f_CS_{bin}",
        "pct",
        "PVGIS's: the steps whose state of charge is in the bin-th tenth from the cut-off to full",
    ),
    ("E_miss", "wh", "PVGIS's total: average energy a day missing, over every day (Wh/d)"),
    ("E_lost", "wh", "PVGIS's total: average energy a day not captured, over every day (Wh/d)"),
    # sizing
    ("area_m2", "m2", "the panel's area"),
    ("benefit_usd", "usd", "lifetime benefit C_grid x t_solar x P_load (Shin et al. Eq. 7)"),
    (
        "cost_usd",
        "usd",
        "the panel's cost (foldopt size); a design's, panel, buffer, hinge or drive and fixed "
        "costs (design_space.csv)",
    ),
    # the least-cost search (design_space.csv)
    ("meets", "", "some buffer up to the sizing grid's top meets storage.target at this area"),
    (
        "capacity_bracket_frac",
        "frac",
        "how far below capacity_wh the least buffer meeting the target may lie: the sizing's "
        "tolerance where the search refined the row, else its grid's step (design_space.csv)",
    ),
    (
        "frontier",
        "",
        "the design's least buffer at this area (a twofold panel's best fold angle there)",
    ),
    ("least_cost", "", "the design's cheapest row that meets the target"),
    ("net_benefit_usd", "usd", "benefit less cost"),
    # reproduction
    ("quantity", "", "a reproduced quantity of Shin et al., named by this grammar"),
    ("unit", "", "its unit"),
    ("paper", ROW_UNIT, "Shin et al.'s published value"),
    ("paper_mode", ROW_UNIT, "foldopt's value in paper mode"),
    ("exact_mode", ROW_UNIT, "foldopt's value in exact mode"),
    ("table", "", "which reproduction table a row comes from"),
)

#: What each placeholder of a name stands for: every value, as a name spells it.
WORDS = {
    "design": DESIGN_WORDS,
    "connection": CONNECTION_WORDS,
    "half": ("east", "west"),
    "pct": tuple(str(pct) for pct in ENSEMBLE_PERCENTILES),
    "hours": tuple(str(hours) for hours in THRESHOLDS_H),
    "month": tuple(f"{month:02d}" for month in range(1, 13)),
    "bin": tuple(f"{index:02d}" for index in range(1, 11)),
}
_PATTERNS = [
    (
        re.compile(
            "^"
            + re.sub(
                r"\\\{(\w+)\\\}",
                lambda m: "(" + "|".join(WORDS[m.group(1)]) + ")",
                re.escape(name),
            )
            + "$"
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
        its unit (a key of :data:`UNITS`, :data:`ROW_UNIT`, or empty for a label) and its
        meaning; for a swept study field its dotted path; None for an unknown name.
    """
    for pattern, name, unit, meaning in _PATTERNS:
        if pattern.match(column):
            return name, unit, meaning
    from foldopt.inputs.study import Study

    if _FIELD_PATH.match(column) or column in Study.model_fields:
        return column, "", "a swept study field, by its path"
    return None


def parse(name: str) -> dict | None:
    """A name's parts by :data:`GRAMMAR`.

    Parameters
    ----------
    name : str
        A quantity's name (``t_solar_flat_mean_h``).

    Returns
    -------
    dict or None
        ``quantity``, ``design``, ``statistic`` (None where the name has none) and ``unit``; None
        where the name does not follow the grammar: no unit last, a statistic's word (``mean``,
        ``p10``, ``objective``...) anywhere but just before the unit, or a kilo-unit.

    Examples
    --------
    >>> parse("t_solar_tracker_net_objective_members_p10_h")["statistic"]
    'objective_members_p10'
    >>> parse("p10_t_solar_h") is None and parse("soc_flat") is None
    True
    """
    match = GRAMMAR.match(name)
    if match is None or any(_NOT_IN_QUANTITY.match(word) for word in match["quantity"].split("_")):
        return None
    return match.groupdict()


def unit_text(unit: str) -> str:
    """A registry unit as the manual writes it (``Wh/m^2``; ``row's unit``; blank for a label)."""
    if unit == ROW_UNIT:
        return "the row's ``unit``"
    return UNITS[unit][0] if unit else " "


def rst_table() -> str:
    """The manual's table of columns (``docs/columns.rst``).

    Returns
    -------
    str
        reStructuredText: a title, the grammar, the units and a list table of :data:`COLUMNS`.
    """
    words = ", ".join(DESIGN_WORDS + CONNECTION_WORDS)
    grammar = (
        "the quantity first (``t_solar``, ``energy_harvested``, ``poa_global``...), then the design "
        f"or connection it is of ({words}), then the statistic over days or sites (``mean``, "
        "``median``, ``min``, ``max``, ``p10``; ``objective``: the study's own; ``days_ge10h``: "
        "the days reaching 10 h; ``month01_mean``) or over a cloud ensemble's members (``members_p10``, after the "
        "statistic over days if any), and last, always, the unit: ``t_solar_flat_mean_h`` is the "
        "flat panel's mean daily t_solar in hours. A quantity pvlib names (``latitude``, "
        "``surface_tilt``, ``dni``, ``temp_air``...) is written as pvlib writes it, in pvlib's "
        "unit: a weather file and a map's ``--sites`` file are read by those names. A quantity "
        "PVGIS's off-grid calculator names (``E_d``, ``E_lost_d``, ``f_f``, ``f_e``, ``f_CS_01``"
        "...) is written as its response writes it, in ``storage_monthly.csv``. A label "
        "(which site, day or design; a note; a flag) has no unit. A name with ``{design}``, "
        "``{connection}``, ``{half}``, ``{pct}``, ``{hours}``, ``{month}`` or ``{bin}`` stands for "
        "one column per design, connection, half of the panel (east, west), percentile, "
        "threshold, month or bin of a histogram. "
        "A sweep's other varied fields are columns named by their dotted path "
        "(``tracker.standby_w``)."
    )
    lines = [
        "Columns",
        "=======",
        "",
        "One name per quantity, in every CSV file, JSON document, report.html and the Python API. A",
        "quantity foldopt names follows one grammar::",
        "",
        "    <quantity>[_<design>][_<statistic>]_<unit>",
        "",
        *textwrap.wrap(grammar, 100),
        "",
        "Generated by ``python -m foldopt.output.columns`` from :mod:`foldopt.output.columns`; the test",
        "suite checks every command's columns against it.",
        "",
        ".. list-table:: Units",
        "   :header-rows: 1",
        "   :widths: 20 20 60",
        "",
        "   * - ends in",
        "     - unit",
        "     - ",
    ]
    for suffix, (unit, _) in UNITS.items():
        lines += [
            f"   * - ``_{suffix}``",
            f"     - {unit}",
            f"     - {UNIT_MEANINGS.get(suffix, ' ')}",
        ]
    lines += [
        "",
        ".. list-table:: Columns",
        "   :header-rows: 1",
        "   :widths: 30 10 60",
        "",
        "   * - column",
        "     - unit",
        "     - meaning",
    ]
    for name, unit, meaning in COLUMNS:
        lines += [f"   * - ``{name}``", f"     - {unit_text(unit)}", f"     - {meaning}"]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":  # pragma: no cover
    print(rst_table(), end="")
