"""Many-site studies: where in the world a folded panel pays, for which loads, in which season.

A map is one study (panel, PV and electrical models, tracker, objective) evaluated over a whole
year at every site of a list (:mod:`foldopt.inputs.sites`): a latitude x longitude grid, a table of
named sites or a folder of weather files, each file a site.
Without weather the sky is the study's clear sky (pvlib's Ineichen model with pvlib's monthly
Linke turbidity climatology for a map). Per site, load and period (the year and the four
three-month seasons) the table gives the fold angle that maximises the study's objective over the
period's days, the objective, the mean daily t_solar and the harvested energy of the flat panel,
the twofold panel at that angle and the tracker, and the tracker's break-even standby draw.

Loads are in watts or, with ``relative=True``, fractions of each site's flat peak (the largest
power of the flat panel over the year), so that one map compares like with like from the tropics
to the poles. :func:`map_request` checks a map's sites, loads, year and period, once for the command
line and :func:`foldopt.world_map`.

This module computes; :mod:`foldopt.studies.cluster` spreads the sites over a Dask cluster and writes
the files.
"""

from __future__ import annotations

import datetime as dt
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from pydantic import ValidationError

from foldopt import names
from foldopt.engine import rows as engines
from foldopt.inputs.load import resolve_files
from foldopt.inputs.optimize_section import vary_names
from foldopt.inputs.plan import parse_dates, parse_values, year_problem
from foldopt.inputs.sites import SITE_COLUMNS, grid_sites, read_sites, weather_sites
from foldopt.inputs.study import Study, format_errors
from foldopt.errors import ConfigError
from foldopt.studies.designs import Blocks, daily_designs
from foldopt.studies.joint import fold_search
from foldopt.studies.objectives import best_angle_index, near_optimal, objective_value

#: Three-month seasons by their months' initials: the same months in both hemispheres.
SEASONS = {"DJF": (12, 1, 2), "MAM": (3, 4, 5), "JJA": (6, 7, 8), "SON": (9, 10, 11)}
PERIODS = ("year", *SEASONS)
#: Rounds and points per round of the break-even search: the bracket shrinks (points + 1)-fold a
#: round, so a 20 W tracker's break-even is found to 4e-5 W.
_BREAK_EVEN_ROUNDS, _BREAK_EVEN_POINTS = 6, 8


#: The grid a map covers where it is given no sites: latitudes and longitudes [deg], start:stop:step.
DEFAULT_GRID = ("-60:60:10", "-180:180:30")
#: Loads a map takes: watts, or fractions of each site's flat peak (``relative``).
LOAD_BOUNDS = {False: (1e6, "loads must be in (0, 1e+06] W"), True: (2.0, "fractions must be in (0, 2]")}


#: What a map changes in the embedded study (the paper's): its beam-only sky and Eq. 5 are for the
#: paper's own site and day, the world needs a clear sky with diffuse light; a 5-min step keeps a
#: year's mean t_solar within 0.005 h of 1-min steps (README, "Maps") at a fifth of the work.
MAP_DEFAULTS = {"mode": "exact", "sky": "ineichen", "step_min": 5.0}
#: A study's fields that a map sets per site or not at all.
_PER_SITE = ("site", "date", "p_load", "year", "sweep", "weather", "force_site")


def map_study(data: dict, embedded: bool = True, **changes) -> dict:
    """A map's study (a study's fields but site, date and load) from a study's data.

    The panel faces the equator at a tilt of ``|latitude|`` at every site unless
    ``panel.tilt``/``panel.azimuth`` are in ``changes``; the objective is the mean unless set.

    Parameters
    ----------
    data : dict
        A study's fields.
    embedded : bool, default True
        The data is the embedded paper study, whose mode, sky, geometry and step give way to
        :data:`MAP_DEFAULTS`; a user's own study keeps its own.
    **changes
        Field paths (dotted, ``panel.area``) to values, set last.

    Returns
    -------
    dict
        The map's study, without the fields a map sets per site.
    """
    from foldopt.inputs.policy import set_path

    study = {key: value for key, value in data.items() if key not in _PER_SITE}
    panel = {key: value for key, value in (study.get("panel") or {}).items() if key not in ("tilt", "azimuth")}
    study["panel"] = panel
    if embedded:
        study.pop("geometry", None)
        study.update(MAP_DEFAULTS)
    study.setdefault("objective", {"statistic": "mean"})
    for path, value in changes.items():
        study = set_path(study, path, value)
    return study


@dataclass(frozen=True)
class MapRequest:
    """A map's request made into what runs (:func:`map_request`).

    Attributes
    ----------
    study : dict
        The map's study: a study's fields but site, date and load (:func:`map_study`).
    sites : tuple of dict
        Each a site's fields or a weather file's site (:func:`evaluate_sites`).
    loads : tuple of float
        Loads [W], or with ``relative`` fractions [-] of each site's flat peak.
    relative : bool
    year : int
    source : str
        How the answer names the study the map took its panel and models from.
    taken : tuple of str
        What the answer took from that study or from defaults, not from the request.
    """

    study: dict
    sites: tuple
    loads: tuple
    relative: bool = False
    year: int = 2025
    source: str = "the given study"
    taken: tuple = ()

    @property
    def defaults(self) -> dict | None:
        """``{"study": source, "taken": [...]}``, or None where nothing was taken."""
        return {"study": self.source, "taken": list(self.taken)} if self.taken else None


def _values(name: str, values) -> list:
    """A value, a sequence, or text (a value, a range start:stop:step or a list a,b,c:
    :func:`foldopt.inputs.plan.parse_values`, the parser of every sweep axis too) as a list."""
    if isinstance(values, str):
        try:
            values = parse_values(values)
        except ValueError as error:
            raise ConfigError([f"{name} = {values!r}: {error}"]) from None
    return list(values) if isinstance(values, (list, tuple)) or hasattr(values, "tolist") else [values]


def map_request(study: dict, loads, *, sites=None, weather_dir: Path | str | None = None, latitudes=None,
                longitudes=None, land_only: bool = False, relative: bool = False, year: int = 2025,
                show_period: str = "year") -> MapRequest:
    """A map's sites, loads, year and period, each checked, with its study: what the command line
    and :func:`foldopt.world_map` both run.

    Parameters
    ----------
    study : dict
        The map's study (:func:`map_study`); checked at the first site.
    loads : float, sequence of float or str
        Loads [W] in (0, 1e6], or with ``relative`` fractions of each site's flat peak in (0, 2];
        text is a value, a range ``start:stop:step`` or a list ``a,b,c``.
    sites : sequence of dict, str or pathlib.Path, optional
        The sites (:func:`~foldopt.inputs.sites.grid_sites`, :func:`~foldopt.inputs.sites.read_sites`,
        :func:`~foldopt.inputs.sites.weather_sites`), or a CSV of named sites (``read_sites``).
    weather_dir : str or pathlib.Path, optional
        Without ``sites``: a folder of weather files, each a site
        (:func:`~foldopt.inputs.sites.weather_sites`).
    latitudes, longitudes : sequence of float or str, optional
        Without ``sites`` or ``weather_dir``: the grid [deg], as values or text like ``loads``;
        default :data:`DEFAULT_GRID`.
    land_only : bool
        Keep the grid's points on land.
    relative : bool
    year : int
        The year of clear-sky days, or what a weather file's typical year stands for.
    show_period : str
        The period the world maps show: one of :data:`PERIODS`.

    Returns
    -------
    MapRequest

    Raises
    ------
    foldopt.ConfigError
        One line per fault, naming the parameter (``latitudes``, ``loads``, ``show_period``...),
        for more than :data:`foldopt.inputs.plan.MAX_CASES` sites, or for a study that fails at
        the first site.
    """
    from foldopt.inputs.plan import MAX_CASES

    errors = []
    if show_period not in PERIODS:
        errors.append(f"show_period = {show_period!r}: must be one of {', '.join(PERIODS)}")
    if year_problem(year):
        errors.append(f"year = {year}: {year_problem(year)}")
    if errors:
        raise ConfigError(errors)
    grid = sites is None and weather_dir is None
    # An empty text is no value (an error), not the default grid.
    grid_values = [_values(name, default if given is None else given) if grid else []
                   for name, given, default in (("latitudes", latitudes, DEFAULT_GRID[0]),
                                                ("longitudes", longitudes, DEFAULT_GRID[1]))]
    for name, values, bound in zip(("latitudes", "longitudes"), grid_values, (90, 180), strict=True):
        if any(not -bound <= value <= bound for value in values):
            errors.append(f"{name}: must be in [-{bound}, {bound}] deg")
    load_values = _values("loads", loads)
    largest, bounds = LOAD_BOUNDS[relative]
    if any(not 0 < value <= largest for value in load_values):
        errors.append(f"loads = {loads!r}: {bounds}")
    vary = (study.get("optimize") or {}).get("vary", list(names.OPTIMIZE_VARIABLES))
    try:
        fold_only = vary_names(vary) == ["fold_angle"]
    except ValueError:
        fold_only = True  # no list of names: the study's validation at the first site says so
    if study.get("optimize") is not None and not fold_only:
        errors.append(f"optimize.vary = {vary!r}: a map searches the fold angle alone (the tilt and azimuth "
                      f"with it: foldopt optimize, one site at a time)")
    if errors:
        raise ConfigError(errors)
    if isinstance(sites, (str, Path)):
        sites = read_sites(sites)
    elif sites is None and weather_dir is not None:
        sites = weather_sites(weather_dir)
    elif sites is None:
        sites = grid_sites(*grid_values, land_only)
        if not sites:
            raise ConfigError(["land_only: no grid point is on land"])
    if len(sites) > MAX_CASES:
        raise ConfigError([f"sites: {len(sites):,}; the limit is {MAX_CASES:,} (FOLDOPT_MAX_CASES raises it)"])
    if len(sites):
        site_study(study, sites[0], year)  # a bad setting fails here, before any cluster starts
    return MapRequest(study, tuple(sites), tuple(load_values), relative, year)


def site_study(study: dict, site: dict, year: int) -> tuple[Study, list[dt.date]]:
    """The study at one site of a map and the days of its year.

    Parameters
    ----------
    study : dict
        A study's fields but the site, date and load (:func:`map_study`).
    site : dict
        A :class:`foldopt.inputs.sections.Site`'s fields, or a weather file's site (``weather``: the
        path, its site read from the file).
    year : int
        The year of clear-sky days, or what a weather file's typical year stands for.

    Returns
    -------
    tuple of (foldopt.Study, list of datetime.date)
        The study at the site (its ``p_load`` 1 W, to be replaced by the map's loads) and every
        day of ``year``.

    Raises
    ------
    foldopt.ConfigError
        For a bad year, a load profile (maps take constant loads) or a study that fails
        validation at the site.
    """
    if year_problem(year):
        raise ConfigError([f"year = {year!r}: {year_problem(year)}"])
    dates = parse_dates("year", year)
    if study.get("load_profile") is not None:
        raise ConfigError(["load_profile: maps take constant loads (watts or fractions of the flat peak); run a "
                           "profile at one site with foldopt run"])
    data = {**study, "date": dates[0], "p_load": 1.0}
    if "weather" in site:
        data["weather"] = site["weather"]  # the site comes from the file; its light from the file
        data.pop("site", None)
        data.pop("sky", None)
    else:
        data["site"] = {key: site[key] for key in SITE_COLUMNS if site.get(key) is not None}
    try:
        return Study.model_validate(data, context=resolve_files(data)), dates
    except ValidationError as error:
        raise ConfigError(format_errors(error)) from None


def evaluate_sites(study: dict, sites: Sequence[dict], loads: Sequence[float], relative: bool = False,
                   year: int = 2025, engine: str = "numba") -> pd.DataFrame:
    """The map's rows for some sites: per site, load and period (:data:`PERIODS`).

    Parameters
    ----------
    study : dict
        A study's fields but ``site``, ``date`` and ``p_load``; its ``objective`` (default mean)
        chooses each period's fold angle.
    sites : sequence of dict
        Each a site's fields (``name``, ``latitude``, ``longitude``, ``altitude``, ``timezone``) or a
        weather file's site (``weather``, the path). A ``site_id`` key, if given, is kept.
    loads : sequence of float
        Loads [W], or with ``relative`` fractions [-] of each site's flat peak.
    relative : bool
    year : int
        The year of clear-sky days, or what a weather file's typical year stands for.
    engine : {'numba', 'numpy'}

    Returns
    -------
    pandas.DataFrame
        One row per site, load and period: ``site_id``, ``site_name``, ``latitude``,
        ``longitude``, ``weather``, ``flat_peak_w``, ``p_load_w``, ``p_load_fraction``, ``period``,
        ``days``, ``fold_angle_deg``; the objective [h] of each design (``objective_flat_h``,
        ``objective_twofold_h``, ``objective_tracker_h``); mean daily t_solar [h]
        (``mean_t_solar_flat_h``, ``mean_t_solar_twofold_h``, ``mean_t_solar_tracker_h``, the tracker's net of its
        own draw ``mean_t_solar_tracker_net_h``); harvested energy [Wh] (``energy_harvested_flat_wh``,
        ``energy_harvested_twofold_wh``, ``energy_harvested_tracker_wh``); ``gain_vs_flat_pct`` and
        ``pct_of_tracker`` (of the objective), ``energy_gain_vs_flat_pct``; and
        the near-optimal range of the fold angle and the recommended angle at its centre
        (``near_optimal_lo_deg``, ``near_optimal_hi_deg``, ``recommended_fold_angle_deg``,
        ``near_optimal_tolerance_h``: :func:`foldopt.studies.objectives.near_optimal`);
        ``tracker_break_even_standby_w``, the standby draw [W] above which the twofold panel's
        objective exceeds the tracker's (0 where it already does; NaN where the twofold panel
        never carries the load).
    """
    frames = [_evaluate_site(study, site, np.asarray(loads, dtype=float), relative, year, engine) for site in sites]
    return pd.concat(frames, ignore_index=True)


def _evaluate_site(study_data: dict, site: dict, loads, relative: bool, year: int, engine: str) -> pd.DataFrame:
    study, dates = site_study(study_data, site, year)
    objective = study.objective
    statistic = objective.statistic if objective is not None else "mean"
    blocks = Blocks.of_dates(study, dates)
    study = blocks.study
    parts = blocks.chunks(loads.size)
    skies = [blocks[part].sky() for part in parts]
    step_hours = skies[0].step_hours
    flat_peak = max(float(engines.row_metrics(sky, study, np.arange(sky.n_blocks),
                                              engines.flat_orientation(blocks[part].tilt, blocks[part].azimuth),
                                              [1.0], outputs=("panel",), engine=engine).peak.max())
                    for part, sky in zip(parts, skies, strict=True))
    watts = loads * flat_peak if relative else loads
    # A load of 0 W (a site whose flat panel never sees the sun) has no t_solar to speak of.
    usable = np.where(watts > 0, watts, np.inf)
    months = np.array([date.month for date in dates])
    seasons = [None, *SEASONS.values()]
    # A map searches the fold angles (foldopt.studies.joint.fold_search) unless its study sweeps them all.
    search = study.optimize
    fold = None if search is None else fold_search(months, statistic, seasons, search.tolerance_h,
                                                   study.near_optimal)
    days_of = daily_designs([(blocks[part], sky) for part, sky in zip(parts, skies, strict=True)], usable, engine,
                            fold)
    angles, hours, harvest = days_of.angles, days_of.twofold_h, days_of.twofold_wh
    flat_hours, flat_energy = days_of.flat_h, days_of.flat_wh
    tracker_hours, tracker_net, tracker_energy = days_of.tracker_h, days_of.tracker_net_h, days_of.tracker_wh
    available = days_of.available

    def statistic_of(daily, season):
        return objective_value(daily, months, statistic, season)

    rows = []
    targets = []
    for period, season in zip(PERIODS, seasons, strict=True):
        days = np.isin(months, season) if season else np.ones(months.size, bool)
        best = best_angle_index(statistic_of(hours, season))  # (loads,)
        at_best = hours[:, np.arange(loads.size), best]  # (days, loads)
        values = {
            "objective_flat_h": statistic_of(flat_hours, season),
            "objective_twofold_h": statistic_of(at_best, season),
            "objective_tracker_h": statistic_of(tracker_hours, season),
            "objective_tracker_net_h": statistic_of(tracker_net, season),
            "mean_t_solar_flat_h": flat_hours[days].mean(axis=0),
            "mean_t_solar_twofold_h": at_best[days].mean(axis=0),
            "mean_t_solar_tracker_h": tracker_hours[days].mean(axis=0),
            "mean_t_solar_tracker_net_h": tracker_net[days].mean(axis=0),
            "energy_harvested_flat_wh": np.full(loads.size, flat_energy[days].sum()),
            "energy_harvested_twofold_wh": harvest[days][:, best].sum(axis=0),
            "energy_harvested_tracker_wh": np.full(loads.size, tracker_energy[days].sum()),
            **near_optimal(angles, statistic_of(hours, season), study.near_optimal),
        }
        targets.append(values["objective_twofold_h"])
        rows.append((period, int(days.sum()), angles[best], values))
    break_even = _break_even_standby(available, np.array(targets), usable, months, statistic, seasons, step_hours,
                                     engine)
    frames = []
    for (period, n_days, fold_angle, values), standby in zip(rows, break_even, strict=True):
        with np.errstate(divide="ignore", invalid="ignore"):
            gain = 100.0 * (values["objective_twofold_h"] / values["objective_flat_h"] - 1.0)
            energy_gain = 100.0 * (values["energy_harvested_twofold_wh"] / values["energy_harvested_flat_wh"] - 1.0)
            share = 100.0 * values["objective_twofold_h"] / values["objective_tracker_h"]
        frames.append(pd.DataFrame({
            "site_id": site.get("site_id", 0),
            "site_name": site.get("name") or "",
            "latitude": study.site.latitude,
            "longitude": study.site.longitude,
            "weather": Path(site["weather"]).name if "weather" in site else "",
            "flat_peak_w": flat_peak,
            "p_load_w": watts,
            "p_load_fraction": watts / flat_peak if flat_peak > 0 else np.nan,
            "period": period,
            "days": n_days,
            "fold_angle_deg": np.where(np.isfinite(usable), fold_angle, np.nan),
            **values,
            "gain_vs_flat_pct": np.where(values["objective_flat_h"] > 0, gain, np.nan),
            "energy_gain_vs_flat_pct": energy_gain,
            "pct_of_tracker": np.where(values["objective_tracker_h"] > 0, share, np.nan),
            "tracker_break_even_standby_w": standby,
        }))
    return pd.concat(frames, ignore_index=True)


def _break_even_standby(available, targets, loads, months, statistic: str, seasons, step_hours: float,
                        engine: str):
    """The tracker's standby draw [W] at which its objective over each period falls to ``targets``.

    A standby draw ``s`` while the sun is up is the load ``P_load + s`` on ``available`` (see
    :func:`foldopt.studies.day.standby_sweep`), and every day's t_solar, so every objective, falls as the
    load rises. The root is bracketed by 0 and the largest available power (no time at all) and
    found for every period and load together: each round evaluates
    :data:`_BREAK_EVEN_POINTS` draws inside every bracket in one pass of the engine.

    Parameters
    ----------
    available : numpy.ndarray
        (days, steps) [W].
    targets : numpy.ndarray
        (periods, loads) the twofold panel's objective [h].
    loads : numpy.ndarray
        (loads,) [W].

    Returns
    -------
    numpy.ndarray
        (periods, loads) [W]: 0 where the tracker without standby is already no better; NaN where
        the target is 0 h.
    """
    n_periods, n_loads = targets.shape
    points = _BREAK_EVEN_POINTS
    low = np.zeros((n_periods, n_loads))
    high = np.full((n_periods, n_loads), max(float(available.max()), 0.0))
    at_zero = None
    for _ in range(_BREAK_EVEN_ROUNDS):
        fractions = np.arange(0, points + 1) / (points + 1) if at_zero is None else np.arange(1, points + 1) / (
            points + 1)
        draws = low[..., None] + (high - low)[..., None] * fractions  # (periods, loads, points)
        daily = engines.curve_metrics(available, (loads[None, :, None] + draws).ravel(), step_hours,
                                      engine=engine).t_solar[:, 0].reshape(-1, n_periods, n_loads, draws.shape[-1])
        value = np.stack([objective_value(daily[:, index], months, statistic, season)
                          for index, season in enumerate(seasons)])
        if at_zero is None:
            at_zero = value[..., 0]
            draws, value = draws[..., 1:], value[..., 1:]
        # The objective falls with the draw: the first `above` points are still above the target.
        above = (value > targets[..., None]).sum(axis=-1)
        index = np.arange(points)
        low = np.where(above > 0, np.sum(np.where(index == above[..., None] - 1, draws, 0.0), axis=-1), low)
        high = np.where(above < points, np.sum(np.where(index == above[..., None], draws, 0.0), axis=-1), high)
    found = (low + high) / 2
    found = np.where(at_zero <= targets, 0.0, found)
    return np.where((targets > 0) & np.isfinite(loads), found, math.nan)
