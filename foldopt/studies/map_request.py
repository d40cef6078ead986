"""A map's request: its sites, loads, year and period, each checked, with its study
(:func:`map_request`), and what decides its numbers (:class:`MapSpec`).

The front door (:func:`foldopt.studies.request.make_request`) makes a map's request here; a bad
grid, load, period, year, search or study is refused before any of the libraries a map's
evaluation needs (numpy, pandas, pvlib, the engine) loads: a refusal is as quick as any other
command's. Reading a table of sites, a folder of weather files or a land mask loads what it needs
where it is read. :mod:`foldopt.studies.worldmap` evaluates a map's sites;
:mod:`foldopt.studies.cluster` spreads them over a Dask cluster and writes the files.
"""

from __future__ import annotations

import calendar
import dataclasses
import datetime as dt
import functools
import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

from foldopt import names
from foldopt.errors import ConfigError
from foldopt.inputs.optimize_section import DEFAULT_TILT, grid_points, vary_names
from foldopt.inputs.fields import year_problem
from foldopt.inputs.plan import check_distinct, parse_dates, parse_values
from foldopt.inputs.sites import SITE_COLUMNS, grid_sites, read_sites, weather_sites
from foldopt.inputs.study import Study, make_study
from foldopt.inputs.study_file import resolve_files
from foldopt.inputs.weather_files import with_fetched_sites
from foldopt.names import DEFAULT_ENGINE

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
#: Ineichen's with diffuse light, and whose PV model PVWatts'). Its step is the study's, as in
#: every command, so that a map and a sweep of one site give one answer; ``--step-min 5`` keeps a
#: year's mean t_solar within 0.005 h of 1-min steps (README, "Maps") at a fifth of the work.
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
        its sky, geometry and PV model to exact mode's); a user's own study keeps its own.
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
        study.pop("pv_model", None)
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
    MapSpec

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
#: Single-core seconds of a map's site, the chunk size's estimate (:func:`site_seconds`), fitted to
#: ``bench/map.py --phases``' sites (W4's sweep of 18 to 180 angles and W5's search, at 1-, 5- and
#: 15-min steps, within 25 %): per day x time step whatever it evaluates (its sky, flat panel,
#: tracker and break-even), per day x design evaluated (the search's and the rows' bookkeeping)
#: and per day x time step x design (the kernel's rows).
SECONDS_PER_STEP = 3.7e-7
SECONDS_PER_DESIGN_DAY = 3.5e-7
SECONDS_PER_EVALUATION = 1.3e-9
#: What a site whose designs are searched (``optimize``) costs in designs of its grid, by the
#: axes searched: the fold angle's search evaluates some 60 of 180 angles; with the tilt, some
#: 2,000 of 180 x 91 designs, whose search's own bookkeeping (its boxes, its days x loads x
#: designs tables) costs more than three times their rows' (W5's sites and ten loads; fewer
#: loads refine fewer plateaus, three some 30 angles, and their chunks run short, not long).
SEARCHED_SHARE = {1: 0.34, 2: 0.42}


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
        :attr:`MapSpec.study` (its fold angles, search and step).
    year : int
    """
    count = max(1, int(CHUNK_SECONDS / site_seconds(study, year)))
    # Whole batches of sites where a chunk holds one or more, so that no batch runs part-full.
    return count if count < SITES_PER_BATCH else SITES_PER_BATCH * round(count / SITES_PER_BATCH)


def site_seconds(study: Study, year: int) -> float:
    """The single-core seconds a map's site costs, estimated: its year's steps, and the designs it
    evaluates on each, every fold angle of the grid or, searched, a share of the grid's designs
    (:data:`SEARCHED_SHARE`).

    Parameters
    ----------
    study : Study
        :attr:`MapSpec.study`.
    year : int

    Returns
    -------
    float
        [s]
    """
    designs = float(len(study.fold_angles.grid()))
    search = study.optimize
    if search is not None:
        tilted = "tilt" in vary_names(search.vary)
        if tilted:
            designs *= grid_points(*search.range_of("tilt", DEFAULT_TILT))
        designs *= SEARCHED_SHARE[1 + tilted]
    days = 366 if calendar.isleap(year) else 365
    steps = days * 1440 / study.step_min
    return (
        steps * (SECONDS_PER_STEP + designs * SECONDS_PER_EVALUATION)
        + days * designs * SECONDS_PER_DESIGN_DAY
    )


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

    The study a map ships to its workers (:class:`MapSpec`); each site's
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
