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
to the poles. :func:`map_request` checks a map's sites, loads, year and period once and makes the map's
study a :class:`~foldopt.inputs.study.Study` (:func:`map_template`); the command line hands that request
to :func:`foldopt.world_map` as it is. Each site's study is the map's moved to the site (:func:`site_study`).

This module computes; :mod:`foldopt.studies.cluster` spreads the sites over a Dask cluster and writes
the files.
"""

from __future__ import annotations

import dataclasses
import datetime as dt
import functools
import hashlib
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from foldopt import names
from foldopt.engine import evaluation as engines
from foldopt.inputs.study_file import resolve_files
from foldopt.engine.search import Axis
from foldopt.inputs.optimize_section import DEFAULT_TILT, Optimize, vary_names
from foldopt.inputs.plan import check_distinct, parse_dates, parse_values, year_problem
from foldopt.inputs.sites import SITE_COLUMNS, grid_sites, read_sites, weather_sites
from foldopt.inputs.study import Study, make_study
from foldopt.inputs.weather_files import with_fetched_sites
from foldopt.errors import ConfigError
from foldopt.physics.spa import SunTerms
from foldopt.studies.break_even import break_even_standby
from foldopt.studies.designs import Blocks, setup_key, site_designs
from foldopt.studies.site_search import fold_search
from foldopt.engine.choice import engine_for
from foldopt.names import DEFAULT_ENGINE, FLAT_FOLD_ANGLE
from foldopt.studies.objectives import (
    best_angle_index,
    near_optimal_on_grid,
    objective_value,
    period_values,
    season_days,
)

#: Three-month seasons by their months' initials: the same months in both hemispheres.
SEASONS = {"DJF": (12, 1, 2), "MAM": (3, 4, 5), "JJA": (6, 7, 8), "SON": (9, 10, 11)}
PERIODS = ("year", *SEASONS)


#: The grid a map covers where it is given no sites: latitudes and longitudes [deg], start:stop:step.
DEFAULT_GRID = ("-60:60:10", "-180:180:30")
#: Loads a map takes: watts, or fractions of each site's flat peak (``relative``).
LOAD_BOUNDS = {
    False: (1e6, "loads must be in (0, 1e+06] W"),
    True: (2.0, "fractions must be in (0, 2]"),
}


#: What a map's search may vary (``optimize.vary``): the fold angle, and the base tilt with it.
MAP_VARIABLES = ("fold_angle", "tilt")
#: Sites evaluated together at most: their days one set of blocks, every engine call and search
#: round over all of them (within the chunk bounds of foldopt.studies.blocks). More sites share more
#: of each call's fixed cost and hold more memory; twelve is where the first stops paying for the
#: second (docs/performance.rst, "Maps at scale").
SITES_PER_BATCH = 12


#: What a map changes in the embedded study (the paper's): its beam-only sky and Eq. 5 are for the
#: paper's own site and day, the world runs in exact mode (whose own sky, as everywhere, is
#: Ineichen's with diffuse light). Its step is the study's, as in every command, so that a map and a
#: sweep of one site give one answer; ``--step-min 5`` keeps a year's mean t_solar within 0.005 h of
#: 1-min steps (README, "Maps") at a fifth of the work.
MAP_DEFAULTS = {"mode": "exact"}
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
        The data is the embedded paper study, whose mode gives way to :data:`MAP_DEFAULTS` (and
        its sky and geometry to exact mode's); a user's own study keeps its own.
    **changes
        Field paths (dotted, ``panel.area``) to values, set last.

    Returns
    -------
    dict
        The map's study, without the fields a map sets per site.
    """
    from foldopt.inputs.policy import set_path

    study = {key: value for key, value in data.items() if key not in _PER_SITE}
    panel = {
        key: value
        for key, value in (study.get("panel") or {}).items()
        if key not in ("tilt", "azimuth")
    }
    study["panel"] = panel
    if embedded:
        study.pop("geometry", None)  # exact mode's own geometry and sky
        study.pop("sky", None)
        study.update(MAP_DEFAULTS)
    study.setdefault("objective", {"statistic": "mean"})
    for path, value in changes.items():
        study = set_path(study, path, value)
    return study


def _values(name: str, values) -> list:
    """A value, a sequence, or text (a value, a range start:stop:step or a list a,b,c:
    :func:`foldopt.inputs.plan.parse_values`, the parser of every sweep axis too) as a list."""
    if isinstance(values, str):
        try:
            values = parse_values(values)
        except ValueError as error:
            raise ConfigError([f"{name} = {values!r}: {error}"]) from None
    values = (
        list(values) if isinstance(values, (list, tuple)) or hasattr(values, "tolist") else [values]
    )
    try:
        return check_distinct(values)
    except ValueError as error:
        raise ConfigError([f"{name}: {error}"]) from None


def map_request(
    study: dict,
    loads,
    *,
    sites=None,
    weather_dir: Path | str | None = None,
    latitudes=None,
    longitudes=None,
    land_only: bool = False,
    relative: bool = False,
    year: int = 2025,
    show_period: str = "year",
    weather: dict | None = None,
) -> MapSpec:
    """A map's sites, loads, year and period, each checked, with its study: what the command line
    and :func:`foldopt.world_map` both run (the front door's map,
    :func:`foldopt.studies.request.make_request`).

    Parameters
    ----------
    study : dict or Study
        The map's study (:func:`map_study`), made and checked at the first site (:func:`map_template`).
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
    weather : dict, optional
        A weather source's section (``{"source": "pvgis-tmy", "years": ...}``): each site's
        weather fetched (or taken from the cache) once, before the map starts
        (:func:`~foldopt.inputs.weather_files.with_fetched_sites`).

    Returns
    -------
    foldopt.studies.cluster.MapSpec

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
        errors.append(
            f"show_period = {show_period!r}: must be one of {', '.join(PERIODS)}"
            f"{names.did_you_mean(str(show_period), PERIODS)}"
        )
    if year_problem(year):
        errors.append(f"year = {year}: {year_problem(year)}")
    if errors:
        raise ConfigError(errors)
    grid = sites is None and weather_dir is None
    # An empty text is no value (an error), not the default grid.
    grid_values = [
        _values(name, default if given is None else given) if grid else []
        for name, given, default in (
            ("latitudes", latitudes, DEFAULT_GRID[0]),
            ("longitudes", longitudes, DEFAULT_GRID[1]),
        )
    ]
    for name, values, bound in zip(
        ("latitudes", "longitudes"), grid_values, (90, 180), strict=True
    ):
        if any(not -bound <= value <= bound for value in values):
            errors.append(f"{name}: must be in [-{bound}, {bound}] deg")
    load_values = _values("loads", loads)
    largest, bounds = LOAD_BOUNDS[relative]
    if any(not 0 < value <= largest for value in load_values):
        errors.append(f"loads = {loads!r}: {bounds}")
    optimize = map_data(study).get("optimize")
    vary = (optimize or {}).get("vary", list(names.OPTIMIZE_VARIABLES))
    try:
        searchable = "fold_angle" in vary_names(vary) and set(vary_names(vary)) <= set(
            MAP_VARIABLES
        )
    except ValueError:
        searchable = True  # no list of names: the study's validation at the first site says so
    if optimize is not None and not searchable:
        errors.append(
            f"optimize.vary = {vary!r}: a map searches the fold angle, or the fold angle and the tilt "
            f"(the azimuth with them: foldopt optimize, one site at a time)"
        )
    if errors:
        raise ConfigError(errors)
    # as read_sites names a file
    field = f"--sites {sites}" if isinstance(sites, (str, Path)) else "sites"
    if isinstance(sites, (str, Path)):
        sites = read_sites(sites)
    elif sites is None and weather_dir is not None:
        sites = weather_sites(weather_dir)
    elif sites is None:
        sites = grid_sites(*grid_values, land_only)
        if not sites:
            raise ConfigError(["land_only: no grid point is on land"])
    if weather is not None:  # not with a weather folder: the front door refuses the pair
        sites = with_fetched_sites(list(sites), weather)
    if len(sites) > MAX_CASES:
        raise ConfigError(
            [f"sites: {len(sites):,}; the limit is {MAX_CASES:,} (FOLDOPT_MAX_CASES raises it)"]
        )
    # A map's rows, figures and map.nc tell sites by place, name and weather file: one given twice is refused.
    try:
        check_distinct(
            [
                {key: site.get(key) for key in ("latitude", "longitude", "name", "weather")}
                for site in sites
            ],
            "site",
            lambda site: (
                f"the site at {site['latitude']:g}, {site['longitude']:g}"
                + (f" ({site['name']})" if site["name"] else "")
            ),
        )
    except ValueError as error:
        raise ConfigError([f"{field}: {error}"]) from None
    if not len(sites):
        raise ConfigError(["sites: a map needs at least one site"])
    study = map_template(study, sites[0], year)
    site_study(study, sites[0], year)  # a bad setting fails here, before any cluster starts
    return MapSpec(study, tuple(sites), tuple(load_values), relative, year)


#: Seconds of work a chunk aims at: long enough that scheduling costs little (a task costs Dask
#: about a millisecond), short enough that a lost worker loses little and progress moves.
CHUNK_SECONDS = 5.0
#: Single-core seconds per site-day x fold angle x time step of a map, everything included (sky,
#: trackers, break-even search): the chunk size's estimate, calibrated by ``bench/map.py``'s W4.
SECONDS_PER_EVALUATION = 13e-9


@dataclass(frozen=True)
class MapSpec:
    """Everything that decides a map's numbers.

    Parameters
    ----------
    study : Study
        The map's study (:func:`map_template`; a map study's fields,
        :func:`map_study`, are made into it at the first site).
    sites : tuple of dict
        ``latitude``, ``longitude`` and optionally ``name``, ``altitude``, ``timezone``; each gets a ``site_id``.
    loads : tuple of float
        Loads [W], or with ``relative`` fractions of each site's flat peak [-].
    relative : bool, default False
    year : int, default 2025
    sites_per_chunk : int, default 0
        0: sized for about :data:`CHUNK_SECONDS` of one core's work (:func:`default_sites_per_chunk`).
    engine : {'auto', 'numba', 'numpy'}
    """

    study: Study
    sites: tuple
    loads: tuple
    relative: bool = False
    year: int = 2025
    sites_per_chunk: int = 0
    engine: str = DEFAULT_ENGINE

    def __post_init__(self):
        if not self.sites:
            raise ConfigError(["sites: a map needs at least one site"])
        object.__setattr__(self, "study", map_template(self.study, self.sites[0], self.year))
        if self.sites_per_chunk <= 0:
            object.__setattr__(
                self, "sites_per_chunk", default_sites_per_chunk(self.study, self.year)
            )
        sites = tuple({**site, "site_id": index} for index, site in enumerate(self.sites))
        object.__setattr__(self, "sites", sites)

    def chunks(self) -> list[range]:
        """The chunks' site indices, ``sites_per_chunk`` each (the last may be short)."""
        size = self.sites_per_chunk
        return [
            range(start, min(start + size, len(self.sites)))
            for start in range(0, len(self.sites), size)
        ]

    def as_dict(self) -> dict:
        """The spec as plain data (``run.json``'s ``spec``): the study as the fields a map keeps for
        every site (:func:`map_data`)."""
        return {
            **{field.name: getattr(self, field.name) for field in dataclasses.fields(self)},
            "study": map_data(self.study),
        }

    @functools.cached_property
    def key(self) -> str:
        """A digest of the spec: a resumed run must have the same. Worked out once: every part written
        and read carries it, and the spec holds every site, so a large grid's digest is dear."""
        text = json.dumps(self.as_dict(), sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def default_sites_per_chunk(study: Study, year: int) -> int:
    """Sites per chunk for about :data:`CHUNK_SECONDS` of one core's work (at least 1), in whole batches
    of :data:`SITES_PER_BATCH` where it holds one or more.

    Parameters
    ----------
    study : Study
        :attr:`MapSpec.study` (its fold angles and step).
    year : int
    """
    angles = len(study.fold_angles.grid())
    steps = 1440 / study.step_min
    per_site = 365 * angles * steps * SECONDS_PER_EVALUATION
    count = max(1, int(CHUNK_SECONDS / per_site))
    # Whole batches of sites where a chunk holds one or more, so that no batch runs part-full.
    return count if count < SITES_PER_BATCH else SITES_PER_BATCH * round(count / SITES_PER_BATCH)


def map_data(study: dict | Study) -> dict:
    """A map's study as data: a study's fields but those a map sets per site.

    Parameters
    ----------
    study : dict or Study
        A map's study's fields (:func:`map_study`), or the map's study (:func:`map_template`).

    Returns
    -------
    dict
        Without the fields of :data:`_PER_SITE` and, of a :class:`Study`, without its decided
        defaults (each site decides its own: its tilt, its time zone).
    """
    data = study.data() if isinstance(study, Study) else study
    return {key: value for key, value in data.items() if key not in _PER_SITE}


def map_template(study: dict | Study, site: dict, year: int) -> Study:
    """A map's study made a :class:`Study`: validated and resolved at one of its sites' places.

    The study a map ships to its workers (:class:`foldopt.studies.cluster.MapSpec`); each site's
    is this one moved to the site (:func:`site_study`). A weather file's site stands at its place
    without its file, so that the map's own sky stays for a map's other sites.

    Parameters
    ----------
    study : dict or Study
        A map's study's fields (:func:`map_study`); a :class:`Study` is returned as it is.
    site : dict
        A site of the map (:func:`site_study`'s).
    year : int

    Returns
    -------
    Study

    Raises
    ------
    foldopt.ConfigError
        As :func:`site_study`.
    """
    if isinstance(study, Study):
        return study
    place = {key: site[key] for key in ("latitude", "longitude") if site.get(key) is not None}
    return site_study(study, place if "weather" in site and len(place) == 2 else site, year)[0]


def site_study(study: dict | Study, site: dict, year: int) -> tuple[Study, list[dt.date]]:
    """The study at one site of a map and the days of its year.

    The map's study moved to the site: what the site does not give (the panel's tilt and azimuth,
    the time zone) the site decides, unless the map's study gives it.

    Parameters
    ----------
    study : dict or Study
        The map's study (:func:`map_template`) or its fields (:func:`map_data`).
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
    study = map_data(study)
    if study.get("load_profile") is not None:
        raise ConfigError(
            [
                "load_profile: maps take constant loads (watts or fractions of the flat peak); run a "
                "profile at one site with foldopt run"
            ]
        )
    data = {**study, "date": dates[0], "p_load": 1.0}
    if "weather" in site:
        data["weather"] = site["weather"]  # the site comes from the file; its light from the file
        data.pop("site", None)
        data.pop("sky", None)
    else:
        data["site"] = {key: site[key] for key in SITE_COLUMNS if site.get(key) is not None}
    return make_study(data, resolve_files(data)), dates


def evaluate_sites(
    study: Study | dict,
    sites: Sequence[dict],
    loads: Sequence[float],
    relative: bool = False,
    year: int = 2025,
    engine: str = DEFAULT_ENGINE,
) -> pd.DataFrame:
    """The map's rows for some sites: per site, load and period (:data:`PERIODS`).

    Parameters
    ----------
    study : Study or dict
        The map's study (:func:`map_template`), or a study's fields but ``site``, ``date`` and
        ``p_load``; its ``objective`` (default mean) chooses each period's fold angle.
    sites : sequence of dict
        Each a site's fields (``name``, ``latitude``, ``longitude``, ``altitude``, ``timezone``) or a
        weather file's site (``weather``, the path). A ``site_id`` key, if given, is kept.
    loads : sequence of float
        Loads [W], or with ``relative`` fractions [-] of each site's flat peak.
    relative : bool
    year : int
        The year of clear-sky days, or what a weather file's typical year stands for.
    engine : {'auto', 'numba', 'numpy'}
        ``auto`` is the compiled kernel: a site's numbers are then the same whichever sites share
        its batch (:func:`foldopt.studies.request.request_engine`, a map's).

    Returns
    -------
    pandas.DataFrame
        One row per site, load and period: ``site_id``, ``site_name``, ``latitude``,
        ``longitude``, ``weather``, ``peak_power_flat_w``, ``p_load_w``, ``p_load_frac``,
        ``period``, ``days_n``, ``fold_angle_deg``; the objective [h] of each design
        (``t_solar_flat_objective_h``, ``t_solar_twofold_objective_h``,
        ``t_solar_tracker_objective_h``); mean daily t_solar [h] (``t_solar_flat_mean_h``,
        ``t_solar_twofold_mean_h``, ``t_solar_tracker_mean_h``, the tracker's net of its own draw
        ``t_solar_tracker_net_mean_h``); harvested energy [Wh] (``energy_harvested_flat_wh``,
        ``energy_harvested_twofold_wh``, ``energy_harvested_tracker_wh``); ``gain_vs_flat_pct`` and
        ``share_of_tracker_pct`` (of the objective), ``energy_harvested_gain_vs_flat_pct``; and
        the near-optimal range of the fold angle and the recommended angle at its centre
        (``near_optimal_lo_deg``, ``near_optimal_hi_deg``, ``recommended_deg``,
        ``near_optimal_tolerance_h``: :func:`foldopt.studies.objectives.near_optimal`);
        ``break_even_standby_tracker_w``, the standby draw [W] above which the twofold panel's
        objective exceeds the tracker's (0 where it already does; NaN where the twofold panel
        never carries the load).
    """
    loads = np.asarray(loads, dtype=float)
    engine = engine_for(engine, math.inf)
    frames, batch, key = [], [], None
    study = map_data(study)  # once, not per site
    sun_terms = SunTerms()  # the sites of one year share every instant of SPA's time-only terms
    for site in sites:
        here, dates = site_study(study, site, year)
        this = setup_key(here)
        if batch and (this != key or len(batch) == SITES_PER_BATCH):
            frames.append(_evaluate_batch(batch, loads, relative, engine, sun_terms))
            batch = []
        batch.append((site, here, dates))
        key = this
    if batch:
        frames.append(_evaluate_batch(batch, loads, relative, engine, sun_terms))
    return pd.concat(frames, ignore_index=True)


def _evaluate_batch(batch, loads, relative: bool, engine: str, sun_terms: SunTerms) -> pd.DataFrame:
    """The rows of sites that share a setup (:func:`foldopt.studies.designs.setup_key`), their days
    one set of blocks: every engine call runs over all of them (:func:`site_designs`)."""
    blocks = Blocks.join([Blocks.of_dates(study, dates) for _, study, dates in batch])
    study = blocks.study
    objective = study.objective
    statistic = objective.statistic if objective is not None else "mean"
    starts = np.cumsum([0, *(len(dates) for _, _, dates in batch)])
    sites = [range(first, stop) for first, stop in zip(starts[:-1], starts[1:], strict=True)]
    parts = [(blocks[part], blocks[part].sky(sun_terms)) for part in blocks.chunks(loads.size)]
    step_hours = parts[0][1].step_hours
    flat_peak = None
    if relative:
        # Loads as fractions of each site's flat peak over all its days: the flat panel's pass for
        # its peak comes before the loads, and site_designs' flat pass needs them.
        peak = np.concatenate(
            [
                engines.row_metrics(
                    sky,
                    rows=engines.PanelRows(
                        np.arange(sky.n_blocks), engines.flat_orientation(chunk.tilt, chunk.azimuth)
                    ),
                    loads=[1.0],
                    electrical=chunk.options.electrical,
                    outputs=("panel",),
                    engine=engine,
                ).peak[:, 0]
                for chunk, sky in parts
            ]
        )
        flat_peak = np.array([float(peak[days].max()) for days in sites])
    p_load = (
        loads[None, :] * flat_peak[:, None]
        if relative
        else np.broadcast_to(loads, (len(batch), loads.size))
    )
    # A load of 0 W (a site whose flat panel never sees the sun) has no t_solar to speak of.
    p_load_evaluated = np.where(p_load > 0, p_load, np.inf)
    months = [np.array([date.month for date in dates]) for _, _, dates in batch]
    seasons = [None, *SEASONS.values()]
    # A map searches the fold angles (foldopt.studies.site_search) unless its study sweeps them all.
    search = study.optimize
    searcher = (
        None
        if search is None
        else fold_search(months, statistic, seasons, search.tolerance_h, _tilt_axis(search))
    )
    designs = site_designs(parts, sites, p_load_evaluated, engine, searcher)
    if flat_peak is None:
        # Loads in watts: the peak of the flat panel's one pass, the one its rows come from.
        flat_peak = np.array([float(days_of.peak_power_flat_w.max()) for days_of in designs])
    columns: dict[str, list] = {}
    for (site, here, _), days_of, site_months, peak_w, site_p_load, site_p_load_evaluated in zip(
        batch, designs, months, flat_peak, p_load, p_load_evaluated, strict=True
    ):
        for name, values in _site_rows(
            days_of, site_months, statistic, seasons, site_p_load_evaluated, study, here.panel.tilt
        ).items():
            columns.setdefault(name, []).append(values)
        count = len(PERIODS) * loads.size
        fixed = {
            "site_id": site.get("site_id", 0),
            "site_name": site.get("name") or "",
            "latitude": here.site.latitude,
            "longitude": here.site.longitude,
            "weather": Path(site["weather"]).name if "weather" in site else "",
            "peak_power_flat_w": peak_w,
        }
        for name, value in fixed.items():
            columns.setdefault(name, []).append(
                np.full(count, value, dtype=object if isinstance(value, str) else None)
            )
        columns.setdefault("p_load_w", []).append(np.tile(site_p_load, len(PERIODS)))
        fraction = site_p_load / peak_w if peak_w > 0 else np.full(loads.size, np.nan)
        columns.setdefault("p_load_frac", []).append(np.tile(fraction, len(PERIODS)))
    # The tracker's break-even standby of every site of the same days at once (their sites' own else).
    targets = np.stack(columns["t_solar_twofold_objective_h"]).reshape(
        len(batch), len(PERIODS), loads.size
    )
    same_days = all(np.array_equal(site_months, months[0]) for site_months in months)
    groups = [list(range(len(batch)))] if same_days else [[site] for site in range(len(batch))]
    standby = np.empty(targets.shape)
    for group in groups:
        standby[group] = break_even_standby(
            np.concatenate([designs[i].available for i in group]),
            targets[group],
            p_load_evaluated[group],
            months[group[0]],
            statistic,
            seasons,
            step_hours,
            engine,
        )
    columns["break_even_standby_tracker_w"] = list(standby.reshape(len(batch), -1))
    order = [
        "site_id",
        "site_name",
        "latitude",
        "longitude",
        "weather",
        "peak_power_flat_w",
        "p_load_w",
        "p_load_frac",
        "period",
        "days_n",
        "fold_angle_deg",
        "surface_tilt",
        "surface_tilt_flat_deg",
        *ROW_VALUES,
        "gain_vs_flat_pct",
        "energy_harvested_gain_vs_flat_pct",
        "share_of_tracker_pct",
        "break_even_standby_tracker_w",
    ]
    return pd.DataFrame({name: np.concatenate(columns[name]) for name in order})


def searched_tilt(study: Study) -> Axis | None:
    """The base tilt's range [deg] a map's study searches with the fold angle (``foldopt map
    --optimize tilt``), or None where the panel keeps the site's tilt."""
    return None if study.optimize is None else _tilt_axis(study.optimize)


def _tilt_axis(search: Optimize) -> Axis | None:
    """The base tilt's range a map's ``optimize`` section searches, or None (the site's tilt)."""
    return Axis("tilt", *search.range_of("tilt", DEFAULT_TILT)) if "tilt" in search.vary else None


#: The values of a map's row from the designs (in the order of its table).
ROW_VALUES = (
    "t_solar_flat_objective_h",
    "t_solar_twofold_objective_h",
    "t_solar_tracker_objective_h",
    "t_solar_tracker_net_objective_h",
    "t_solar_flat_mean_h",
    "t_solar_twofold_mean_h",
    "t_solar_tracker_mean_h",
    "t_solar_tracker_net_mean_h",
    "energy_harvested_flat_wh",
    "energy_harvested_twofold_wh",
    "energy_harvested_tracker_wh",
    "near_optimal_lo_deg",
    "near_optimal_hi_deg",
    "recommended_deg",
    "near_optimal_tolerance_h",
)


def _chosen(hours, energy, months, statistic: str, seasons, member):
    """Each period's and load's best of some designs, and the objective, the mean daily t_solar and
    the harvested energy there: ``hours`` (days, loads, n), ``energy`` (days, n) -> ``best``,
    ``objective``, ``mean_h`` and ``energy_wh``, each (periods, loads); also every design's
    objective, (periods, loads, n)."""
    n_loads = hours.shape[1]
    every = period_values(hours, months, statistic, seasons)  # (periods, loads, n)
    # (periods, loads); ties to the last (the least folded, the steepest)
    best = best_angle_index(every)
    at_best = hours[:, np.arange(n_loads)[None, :], best]  # (days, periods, loads)
    objective = np.stack(
        [
            objective_value(at_best[:, period], months, statistic, season)
            for period, season in enumerate(seasons)
        ]
    )
    mean_h = np.stack([at_best[days, period].mean(axis=0) for period, days in enumerate(member)])
    energy_wh = np.stack(
        [energy[days][:, best[period]].sum(axis=0) for period, days in enumerate(member)]
    )
    return best, objective, mean_h, energy_wh, every


def _site_rows(
    days_of, months, statistic: str, seasons, p_load_evaluated, study, surface_tilt: float
) -> dict:
    """One site's columns, per period and load (periods slowest), from its :class:`DailyDesigns`."""
    angles, tilts, twofold_h, twofold_energy = (
        days_of.angles,
        days_of.tilts,
        days_of.twofold_h,
        days_of.twofold_wh,
    )
    n_loads = p_load_evaluated.size
    member = np.stack([season_days(months, season) for season in seasons])
    # The flat panel at the site's mounting, or at each period's and load's own best tilt.
    flat_hours, flat_energy, flat_tilts = (
        days_of.flat_h[..., None],
        days_of.flat_wh[:, None],
        np.array([surface_tilt]),
    )
    if days_of.flat_tilted is not None:
        flat_tilts, flat_hours, flat_energy = days_of.flat_tilted
        # A 180 deg fold is the flat panel: each search's designs are the other's too (the
        # twofold panel's where its fold angles reach 180 deg), so that neither's best misses one
        # the other evaluated.
        unfolded = angles == FLAT_FOLD_ANGLE
        flat_tilts = np.concatenate([flat_tilts, tilts[unfolded]])
        order = np.argsort(flat_tilts, kind="stable")  # ties to the steepest, as the search's
        flat_tilts, flat_hours, flat_energy = (
            flat_tilts[order],
            np.concatenate([flat_hours, twofold_h[..., unfolded]], axis=-1)[..., order],
            np.concatenate([flat_energy, twofold_energy[:, unfolded]], axis=-1)[:, order],
        )
        if study.fold_angles.stop == FLAT_FOLD_ANGLE:
            angles = np.concatenate([angles, np.full(flat_tilts.size, FLAT_FOLD_ANGLE)])
            tilts = np.concatenate([tilts, flat_tilts])
            # In ascending order of the fold angle, then the tilt, as the search's designs are.
            order = np.lexsort((tilts, angles))
            angles, tilts = angles[order], tilts[order]
            twofold_h = np.concatenate([twofold_h, flat_hours], axis=-1)[..., order]
            twofold_energy = np.concatenate([twofold_energy, flat_energy], axis=-1)[:, order]
    best, twofold, twofold_mean, twofold_wh, objective = _chosen(
        twofold_h, twofold_energy, months, statistic, seasons, member
    )
    flat_best, flat, flat_mean, flat_wh, _ = _chosen(
        flat_hours, flat_energy, months, statistic, seasons, member
    )
    trackers = np.stack([days_of.tracker_h, days_of.tracker_net_h], axis=1)  # (days, 2, loads)
    tracker, tracker_mean = (
        period_values(trackers, months, kind, seasons) for kind in (statistic, "mean")
    )
    tracker_wh = np.stack([days_of.tracker_wh[days].sum() for days in member])
    # The fold angle's near-optimal range: over the tilts too (the best of them at each angle) where searched.
    fold_angles, profile = angles, objective.reshape(-1, angles.size)
    if tilts is not None:
        fold_angles, column = np.unique(angles, return_inverse=True)
        profile = np.full((profile.shape[0], fold_angles.size), -np.inf)
        np.maximum.at(profile, (slice(None), column.ravel()), objective.reshape(-1, angles.size))
    ranges = near_optimal_on_grid(
        fold_angles, profile, study.near_optimal, np.asarray(study.fold_angles.grid())
    )
    carried = np.isfinite(p_load_evaluated)
    rows = {
        "period": np.repeat(np.array(PERIODS, dtype=object), n_loads),
        "days_n": np.repeat(member.sum(axis=1), n_loads),
        "fold_angle_deg": np.where(carried, angles[best], np.nan).ravel(),
        "surface_tilt": np.where(
            carried,
            tilts[best] if tilts is not None else np.full(best.shape, surface_tilt),
            np.nan,
        ).ravel(),
        "surface_tilt_flat_deg": np.where(carried, flat_tilts[flat_best], np.nan).ravel(),
        "t_solar_flat_objective_h": flat.ravel(),
        "t_solar_twofold_objective_h": twofold.ravel(),
        "t_solar_tracker_objective_h": tracker[:, 0].ravel(),
        "t_solar_tracker_net_objective_h": tracker[:, 1].ravel(),
        "t_solar_flat_mean_h": flat_mean.ravel(),
        "t_solar_twofold_mean_h": twofold_mean.ravel(),
        "t_solar_tracker_mean_h": tracker_mean[:, 0].ravel(),
        "t_solar_tracker_net_mean_h": tracker_mean[:, 1].ravel(),
        "energy_harvested_flat_wh": flat_wh.ravel(),
        "energy_harvested_twofold_wh": twofold_wh.ravel(),
        "energy_harvested_tracker_wh": np.repeat(tracker_wh, n_loads),
        **ranges,
    }
    with np.errstate(divide="ignore", invalid="ignore"):
        gain = 100.0 * (
            rows["t_solar_twofold_objective_h"] / rows["t_solar_flat_objective_h"] - 1.0
        )
        energy_gain = 100.0 * (
            rows["energy_harvested_twofold_wh"] / rows["energy_harvested_flat_wh"] - 1.0
        )
        share = 100.0 * rows["t_solar_twofold_objective_h"] / rows["t_solar_tracker_objective_h"]
    rows["gain_vs_flat_pct"] = np.where(rows["t_solar_flat_objective_h"] > 0, gain, np.nan)
    rows["energy_harvested_gain_vs_flat_pct"] = energy_gain
    rows["share_of_tracker_pct"] = np.where(rows["t_solar_tracker_objective_h"] > 0, share, np.nan)
    return rows
