"""The names foldopt accepts, in one registry: configuration, command line and physics share it.

Every model, connection and option that is chosen by name is listed here, once, with the other
spellings a user may type (pvlib's, as in ``simplified_solis``, ``singlediode`` or ``singleaxis``,
and any case). :func:`canonical` turns a spelling into foldopt's name or raises an error that lists
the valid names and the closest ones. The module imports nothing heavy, so that the command line
can check its input and print its help before numpy, pandas or pvlib load.
"""

from __future__ import annotations

import difflib
import re
import typing


class Registry(tuple):
    """The members of one kind (PV models, connections, trackers...): their names in order, each
    with a one-line description that help text and the docs print.

    A registry is a tuple of names, so ``name in PV_MODELS`` and ``", ".join(PV_MODELS)`` read it
    as before; :meth:`describe` and :meth:`choices` give the descriptions, and
    :func:`canonical` accepts other spellings of its names. Adding a member is one entry here
    and its implementation in the module that dispatches on it.

    Parameters
    ----------
    kind : str
        What the members are, as a field of a study would name it (``"pv_model"``).
    members : dict of str to str
        Each member's name and its one-line description.
    """

    def __new__(cls, kind: str, members: dict[str, str]):
        registry = super().__new__(cls, members)
        registry.kind, registry.descriptions = kind, dict(members)
        return registry

    def describe(self, name: str) -> str:
        """The one-line description of a member.

        Parameters
        ----------
        name : str
            One of the registry's names.

        Examples
        --------
        >>> MODES.describe("paper")[:22]
        "Shin et al.'s formulas"
        """
        return self.descriptions[name]

    def choices(self) -> str:
        """The names joined for help text: ``ideal | single-diode | b-model``."""
        return " | ".join(self)

    def __add__(self, other):
        if isinstance(other, Registry):
            return Registry(self.kind, {**self.descriptions, **other.descriptions})
        return tuple(self) + tuple(other)

    def __reduce__(self):  # pickled to Dask workers with its descriptions
        return Registry, (self.kind, self.descriptions)


MODES = Registry(
    "mode",
    {
        "paper": "Shin et al.'s formulas: their solar position, air mass, beam-only sky and incidence (Eq. 1-6)",
        "exact": "pvlib's SPA solar position, a clear-sky or weather sky, transposition and angle of incidence",
    },
)
GEOMETRIES = Registry(
    "geometry",
    {
        "azimuth-split": "the sub-panels keep the base tilt and turn east and west of the base azimuth (the paper's)",
        "hinge": "the sub-panel normals turn about the fold line, up the panel's slope (a ridge tent at tilt 0)",
    },
)
BEAM_SKIES = Registry(
    "sky",
    {  # beam only
        "meinel": "Meinel & Meinel's beam irradiance from air mass (Shin et al. Eq. 2)",
        "hottel": "Hottel's clear-sky beam transmittance by climate and altitude",
    },
)
CLEAR_SKIES = Registry(
    "sky",
    {  # global, direct and diffuse
        "ineichen": "pvlib's Ineichen-Perez clear sky with Linke turbidity",
        "simplified-solis": "pvlib's simplified Solis clear sky from aerosol and water vapour",
    },
)
SKIES = BEAM_SKIES + CLEAR_SKIES
TRANSPOSITIONS = Registry(
    "transposition",
    {
        "none": "beam only: no diffuse or reflected light",
        "isotropic": "isotropic sky diffuse (Liu & Jordan) and ground reflection",
        "haydavies": "Hay & Davies: circumsolar and isotropic sky diffuse",
        "perez": "Perez et al. 1990: circumsolar, isotropic and horizon-band sky diffuse",
    },
)
IAMS = Registry(
    "iam",
    {
        "none": "no reflection loss at the cover",
        "ashrae": "ASHRAE incidence angle modifier (pvlib.iam.ashrae)",
        "physical": "Fresnel and absorption in the cover glass (pvlib.iam.physical)",
    },
)
PV_MODELS = Registry(
    "pv_model",
    {
        "ideal": "P = efficiency x area x irradiance, no I-V curve (the paper's)",
        "single-diode": "De Soto et al.'s five-parameter single-diode model of a CEC module, through pvlib",
        "b-model": "Robles Algarin et al.'s empirical I-V model of a 200 W panel (Eq. 8-11, b = 0.068)",
        "pvwatts": "PVWatts DC: rating x irradiance / 1000 x (1 + gamma_pdc (T_cell - 25 C)), less "
        "system losses (pvlib.pvsystem.pvwatts_dc), no I-V curve",
    },
)
#: The :data:`PV_MODELS` with an I-V curve: the pairs' connections, the circuit as built and the
#: electrical tables are theirs; the others' sub-panels deliver their sum in any connection.
IV_MODELS = ("single-diode", "b-model")
TEMPERATURE_MODELS = Registry(
    "temperature_model",
    {
        "fixed": "cells at the air temperature",
        "sapm": "Sandia's cell temperature model from irradiance, air temperature and wind",
    },
)
CONNECTIONS = Registry(
    "connection",
    {
        "east": "the east sub-panel alone",
        "west": "the west sub-panel alone",
        "parallel": "the sub-panels in parallel at one operating voltage",
        "series": "the sub-panels in series at one current (bypass diodes)",
        "independent": "each sub-panel at its own maximum power point (two converters)",
        "switching": "the best of east, west, parallel and series at each step (a reconfigurable switch)",
    },
)
DIODE_MODELS = Registry(
    "diode model",
    {
        "ideal": "no forward drop: the diode only stops reverse current",
        "constant": "a constant forward drop, the datasheet V_F at its rated current",
        "shockley": "Shockley's diode with series resistance, V = n Vt ln(1 + I/Is) + I Rs (a SPICE model)",
    },
)
CONVERTER_MODELS = Registry(
    "converter model",
    {
        "ideal": "every converter delivers its whole input (the paper's)",
        "pvwatts": "the PVWatts part-load efficiency curve from a nominal efficiency (pvlib.inverter.pvwatts)",
        "curve": "a table of efficiency against input power as a fraction of the rating",
    },
)
COUPLINGS = Registry(
    "coupling",
    {
        "mppt": "a maximum-power-point converter between the panel and the load",
        "direct": "the load wired to the panel, at the load's own voltage (no converter)",
    },
)
#: What a joint optimisation varies: field-like names (pvlib's vocabulary), so not among the
#: kebab-case model names of :data:`REGISTRIES`.
OPTIMIZE_VARIABLES = Registry(
    "variable",
    {
        "fold_angle": "the dihedral angle between the sub-panels [deg] (180 is flat)",
        "tilt": "the base tilt of the unfolded panel [deg from horizontal]",
        "azimuth": "the base azimuth of the unfolded panel [deg clockwise from north]",
    },
)
TRACKERS = Registry(
    "tracker",
    {
        "dual-axis": "ideal: the normal always on the sun (Shin et al. Sec. IV-A)",
        "equatorial": "a polar daily axis following the hour angle, the seasonal axis set daily (Alexandru)",
        "dual-axis-steps": "the equatorial mount moved in N equal open-loop steps a day (Alexandru's law)",
        "single-axis": "pvlib's single-axis tracker: a N-S axis, optionally tilted, optional backtracking",
    },
)
DRIVES = Registry(
    "drive",
    {
        "motor": "Robles Algarin et al.'s DC gear motor: the energy of each move from its speed and current",
        "wh-per-degree": "a fixed energy per degree of rotation",
    },
)
WEATHER_FORMATS = Registry(
    "weather format",
    {
        "tmy3": "NREL TMY3 CSV (pvlib.iotools.read_tmy3)",
        "epw": "EnergyPlus weather (pvlib.iotools.read_epw)",
        "pvgis": "PVGIS typical meteorological year, CSV or JSON (pvlib.iotools.read_pvgis_tmy)",
        "surfrad": "NOAA SURFRAD daily file: measured 1-min light, air temperature and wind "
        "(pvlib.iotools.read_surfrad)",
        "midc": "NREL MIDC daily or raw-data file: measured 1-min columns; give the site (pvlib.iotools.read_midc)",
        "srml": "UO SRML archival file: measured 1- to 60-min columns; give the site (pvlib.iotools.read_srml)",
        "bsrn": "BSRN station-to-archive file: measured 1-min light and air temperature (pvlib.iotools.read_bsrn)",
        "solrad": "NOAA SOLRAD daily file: measured 1-min light (pvlib.iotools.read_solrad)",
        "crn": "NOAA USCRN sub-hourly file: measured 5-min global light, air temperature, wind "
        "(pvlib.iotools.read_crn)",
        "csv": "a measured CSV: timestamp, ghi, dni, dhi [, temp_air, wind_speed] at any step; give the site",
        "pvgis-hourly": "PVGIS hourly series of a horizontal plane, JSON: real hours of real years, "
        "read at its hourly step (pvlib.iotools.read_pvgis_hourly)",
    },
)
#: The weather formats of hourly files (typical years), brought to the study's step; the others of
#: :data:`WEATHER_FORMATS` are measured files, evaluated at their own step.
HOURLY_WEATHER_FORMATS = ("tmy3", "epw", "pvgis")
#: Weather fetched from a public service by name, cached and replayed offline
#: (:data:`foldopt.inputs.weather.sources.SOURCES`): ``weather.source`` or ``--weather NAME``.
WEATHER_SOURCES = Registry(
    "weather source",
    {
        "pvgis-tmy": "PVGIS's typical meteorological year of the site (EU JRC, SARAH3 / ERA5 "
        "satellite and reanalysis data; pvlib.iotools.get_pvgis_tmy's request)",
        "pvgis-hourly": "PVGIS's hourly series of the site, real years (--years START:END, "
        "2005 to 2023; pvlib.iotools.get_pvgis_hourly's request for a horizontal plane)",
    },
)
#: The :data:`WEATHER_SOURCES` whose answer is read as a measured file (its real days at its own
#: step, :data:`foldopt.inputs.weather.sources.SOURCES`' ``format``), the others as a typical year.
MEASURED_WEATHER_SOURCES = ("pvgis-hourly",)
DECOMPOSITIONS = Registry(
    "decomposition",
    {
        "erbs": "Erbs, Klein and Duffie 1982: the diffuse fraction from the clearness index (pvlib.irradiance.erbs)",
        "boland": "Boland, Huang and Ridley 2013: a logistic diffuse fraction (pvlib.irradiance.boland)",
        "dirint": "Perez et al. 1992: DISC with the index's changes and dew point (pvlib.irradiance.dirint)",
    },
)
INTERVAL_LABELS = Registry(
    "interval label",
    {
        "start": "a timestamp marks the start of its interval",
        "end": "a timestamp marks the end of its interval",
        "centre": "a timestamp marks the centre of its interval",
    },
)
HOTTEL_CLIMATES = Registry(
    "hottel climate",
    {
        "tropical": "Hottel's tropical correction factors",
        "midlatitude-summer": "Hottel's mid-latitude summer correction factors",
        "subarctic-summer": "Hottel's subarctic summer correction factors",
        "midlatitude-winter": "Hottel's mid-latitude winter correction factors",
    },
)
#: Rows x time steps up to which the ``auto`` engine takes the NumPy reference path while the
#: kernel is not compiled (the default study's month of days at 181 fold angles): below it the
#: reference path's extra time is well under the kernel's first compile (figures in
#: docs/performance.rst, from bench/startup.py).
AUTO_NUMPY_ROW_STEPS = 10_000_000
#: Rows x time steps up to which ``auto`` takes the NumPy reference path though numba's cache holds
#: the compiled kernel: a day's study and a few of its variants, whose reference path costs less
#: than loading the kernel from the cache (figures in docs/performance.rst).
AUTO_CACHED_NUMPY_ROW_STEPS = 1_000_000
ENGINES = Registry(
    "engine",
    {
        "auto": "the compiled kernel above "
        f"{AUTO_CACHED_NUMPY_ROW_STEPS // 1_000_000} M rows x steps where numba's cache holds it, "
        "a day's study on the NumPy reference path; before the kernel's first compile, the "
        f"reference path up to {AUTO_NUMPY_ROW_STEPS // 1_000_000} M rows x steps, with no "
        "compile wait",
        "numba": "the compiled kernel",
        "numpy": "the NumPy reference path the kernel is tested against",
    },
)
#: The engine of every command and API call that names none.
DEFAULT_ENGINE = "auto"
#: A buffer's chemistry, whose datasheet-typical values fill the ``storage`` fields a study leaves
#: out (the values and their sources: :data:`foldopt.inputs.storage_section.PRESETS`).
STORAGE_PRESETS = Registry(
    "storage preset",
    {
        "supercapacitor": "an EDLC bank behind a converter: usable down to half its voltage (a quarter "
        "of its energy), ~96 % round trip, ~2 %/day self-discharge",
        "lifepo4": "a small LiFePO4 pack: cut off at 20 % (80 % depth of discharge), 92 % round trip, "
        "~3 %/month self-discharge; not charged below 0 C, 70 % of its capacity at -20 C",
        "nmc": "a small Li-ion (NMC) pack: cut off at 20 %, not charged below 0 C nor discharged "
        "below -20 C, 70 % of its capacity at -18 C, ~5 %/month self-discharge",
    },
)
OUTPUT_FORMATS = Registry(
    "format",
    {
        "table": "a short answer on the terminal",
        "json": "one JSON document of the answer and its rows",
    },
)
#: Every registry, in the order the docs list them.
REGISTRIES = (
    MODES,
    GEOMETRIES,
    SKIES,
    TRANSPOSITIONS,
    IAMS,
    PV_MODELS,
    TEMPERATURE_MODELS,
    CONNECTIONS,
    CONVERTER_MODELS,
    COUPLINGS,
    TRACKERS,
    DRIVES,
    WEATHER_FORMATS,
    WEATHER_SOURCES,
    DECOMPOSITIONS,
    INTERVAL_LABELS,
    HOTTEL_CLIMATES,
    ENGINES,
    OUTPUT_FORMATS,
    DIODE_MODELS,
    STORAGE_PRESETS,
)


class FieldOption(typing.NamedTuple):
    """One command-line option and the study field it sets (:data:`FIELD_OPTIONS`).

    Attributes
    ----------
    option : str
        The option, ``--p-load``; its parameter (:attr:`parameter`) is its name in snake case.
    field : str
        The study field it sets, a dotted path.
    aliases : tuple of str
        Other spellings of the option (``--date`` for ``--days``); messages name them all.
    flag : bool, optional
        For a flag, the value it sets the field to (``--no-bypass`` sets ``bypass_diodes`` False).
    also : tuple of str
        Other fields messages name by this option (``--angle-step`` also sets where the fold
        angles start).
    """

    option: str
    field: str
    aliases: tuple = ()
    flag: bool | None = None
    also: tuple = ()

    @property
    def parameter(self) -> str:
        """The option as a Python parameter: ``--p-load-scale`` -> ``p_load_scale``."""
        return self.option.lstrip("-").replace("-", "_")

    @property
    def label(self) -> str:
        """The option as a message names it: ``--days/--date``."""
        return "/".join((self.option, *self.aliases))


#: The command line's options that set study fields, each once: ``foldopt sweep``'s and
#: ``optimize``'s options become field changes by it (:data:`FIELD_OF_PARAMETER`), and the
#: library's messages name the options instead of the fields (:func:`option_labels`).
FIELD_OPTIONS = (
    FieldOption("--lat", "site.latitude"),
    FieldOption("--lon", "site.longitude"),
    FieldOption("--altitude", "site.altitude"),
    FieldOption("--timezone", "site.timezone"),
    FieldOption("--days", "date", aliases=("--date",)),
    FieldOption("--year", "year"),
    FieldOption("--p-load", "p_load"),
    FieldOption("--p-load-scale", "p_load"),
    FieldOption("--area", "panel.area"),
    FieldOption("--efficiency", "panel.efficiency"),
    FieldOption("--tilt", "panel.tilt"),
    FieldOption("--azimuth", "panel.azimuth"),
    FieldOption("--planes", "panel.planes"),
    FieldOption("--fold-angle", "fold_angles"),
    FieldOption("--mode", "mode"),
    FieldOption("--geometry", "geometry"),
    FieldOption("--sky", "sky"),
    FieldOption("--climate", "climate"),
    FieldOption("--weather", "weather"),
    FieldOption("--years", "weather.years"),
    FieldOption("--force-site", "force_site", flag=True),
    FieldOption("--transposition", "transposition"),
    FieldOption("--albedo", "albedo"),
    FieldOption("--iam", "iam"),
    FieldOption("--objective", "objective.statistic"),
    FieldOption("--visits", "objective.visits"),
    FieldOption("--tracker", "tracker.model"),
    FieldOption("--tracker-standby", "tracker.standby_w"),
    FieldOption("--pv-model", "pv_model"),
    FieldOption("--module", "module"),
    FieldOption("--connection", "connection"),
    FieldOption("--switch-series", "switch_series", flag=True),
    FieldOption("--no-bypass", "bypass_diodes", flag=False),
    FieldOption("--converter-efficiency", "converter_efficiency"),
    FieldOption("--temp-air", "temp_air"),
    FieldOption("--exact-electrical", "exact_electrical", flag=True),
    FieldOption("--step-min", "step_min"),
    FieldOption("--angle-step", "fold_angles.step", also=("fold_angles.start",)),
    FieldOption("--load-profile", "load_profile"),
    FieldOption("--weather-format", "weather.format"),
    FieldOption("--members", "weather.members"),
    FieldOption("--seed", "weather.seed"),
    FieldOption("--horizon", "site.horizon"),
    FieldOption("--blocking-diode", "circuit.blocking_diode.model"),
    FieldOption("--bypass-diode", "circuit.bypass_diode.model"),
    FieldOption("--converter", "circuit.converter.model"),
    FieldOption("--load-voltage", "circuit.load_voltage"),
    FieldOption("--switch-resistance", "circuit.switch_resistance"),
    FieldOption("--storage-wh", "storage.capacity_wh"),
    FieldOption("--min-soc", "storage.min_soc"),
)
#: Each option's parameter -> the field it sets.
FIELD_OF_PARAMETER = {entry.parameter: entry.field for entry in FIELD_OPTIONS}


def option_labels(given=()) -> dict[str, str]:
    """Study fields as the options that set them name them, for messages.

    Parameters
    ----------
    given : collection of str
        The parameters of the options given: of several options that set one field
        (``--p-load``, ``--p-load-scale``), the one given names it; else the first.

    Returns
    -------
    dict
        Field path -> option label (:attr:`FieldOption.label`).

    Examples
    --------
    >>> option_labels()["p_load"], option_labels({"p_load_scale"})["p_load"]
    ('--p-load', '--p-load-scale')
    """
    labels = {}
    for entry in FIELD_OPTIONS:
        for field in (entry.field, *entry.also):
            if field not in labels or entry.parameter in given:
                labels[field] = entry.label
    return labels


#: Study fields as the options that set them name them (:func:`option_labels`, none given).
OPTION_OF_FIELD = option_labels()

#: The fold angle of the flat panel [deg]: a twofold panel unfolded is the flat panel. (An azimuth
#: of 180 deg is south, another quantity: it keeps its number.)
FLAT_FOLD_ANGLE = 180.0

#: Alexandru's half law as offsets of the afternoon moves from solar noon [h] (foldopt.physics.trackers).
#: His 12 actuating times (local time) pair up symmetrically about 13.319 h: 8.839/17.799,
#: 9.819/16.819, 10.619/16.019, 11.489/15.149, 12.189/14.449, 12.919/13.719. (He gives solar noon
#: as 13.206 h local; the 6.8 min offset is left out, the law being symmetric about solar noon by
#: construction.)
ALEXANDRU_STEP_OFFSETS_H = (0.400, 1.130, 1.830, 2.700, 3.500, 4.480)

#: Other spellings of a name, beyond case, ``_``/`` `` for ``-`` and dropped separators.
ALIASES = {
    "hay-davies": "haydavies",
    "hay_davies": "haydavies",
    "desoto": "single-diode",
    "de-soto": "single-diode",
    "cec": "single-diode",
    "sapm-cell": "sapm",
    "two-axis": "dual-axis",
    "2-axis": "dual-axis",
    "one-axis": "single-axis",
    "1-axis": "single-axis",
    "center": "centre",
    "pvgis-tmy": "pvgis",
}


def _squash(name: str) -> str:
    """A spelling without case or separators: ``Single_Diode`` and ``singlediode`` meet."""
    return re.sub(r"[\s_\-]+", "", name.lower())


def canonical(value, names, field: str = "name"):
    """foldopt's name for ``value`` among ``names``, accepting pvlib's and other spellings.

    Parameters
    ----------
    value : str or object
        A spelling; anything but a string is returned as it is (for the validator that follows).
    names : sequence of str
        The valid names, e.g. a :class:`Registry`.
    field : str, default 'name'
        Not used (no caller passes it).

    Returns
    -------
    str
        The member of ``names``.

    Raises
    ------
    ValueError
        Naming the valid names and, where a spelling is close to one, "did you mean ...".

    Examples
    --------
    >>> canonical("singlediode", PV_MODELS)
    'single-diode'
    >>> canonical("SingleAxis", TRACKERS)
    'single-axis'
    """
    if not isinstance(value, str):
        return value
    text = value.strip()
    if text in names:
        return text
    lowered = text.lower().replace("_", "-").replace(" ", "-")
    lowered = ALIASES.get(lowered, ALIASES.get(text.lower(), lowered))
    if lowered in names:
        return lowered
    squashed = {_squash(name): name for name in names}
    if _squash(text) in squashed:
        return squashed[_squash(text)]
    raise ValueError(f"must be one of {', '.join(names)}{did_you_mean(text, names)}")


def close_names(value: str, names) -> list[str]:
    """The names a misspelling most likely meant: those it begins (``singl`` for ``single-diode``),
    then the closest by :mod:`difflib`, compared without case or separators; of more than two, the
    two most similar (``st`` is ``set`` a letter short more likely than it begins ``storage-wh``).

    Parameters
    ----------
    value : str
        The spelling given.
    names : sequence of str
        The valid names.

    Returns
    -------
    list of str
        At most two names, the likeliest first; none where nothing is close.

    Examples
    --------
    >>> close_names("worst-mnth", ("mean", "min", "worst-month"))
    ['worst-month']
    >>> close_names("singl", PV_MODELS)
    ['single-diode']
    """
    squashed = {_squash(name): name for name in names}
    key = _squash(value)
    begun = [name for short, name in squashed.items() if len(key) >= 2 and short.startswith(key)]
    near = [squashed[short] for short in difflib.get_close_matches(key, squashed, n=2, cutoff=0.6)]
    similarity = {
        name: difflib.SequenceMatcher(None, key, _squash(name)).ratio()
        for name in dict.fromkeys(begun + near)
    }
    likeliest = sorted(similarity, key=lambda name: -similarity[name])[:2]
    return [name for name in similarity if name in likeliest]


def did_you_mean(value: str, names) -> str:
    """``"; did you mean 'x'?"`` for the names :func:`close_names` finds, or ``""``: the end of
    every message that refuses a name.

    Parameters
    ----------
    value : str
    names : sequence of str

    Returns
    -------
    str
    """
    close = close_names(value, names)
    return f"; did you mean {' or '.join(repr(name) for name in close)}?" if close else ""


#: Seconds [s] foldopt waits for a Dask scheduler to answer, every step of reaching it counted (the
#: name looked up, the port connected, Dask's greeting, the client's connection)
#: (:mod:`foldopt.studies.dask_client`; here for the map's help, which then loads none of it).
CONNECT_TIMEOUT = 5.0
#: Seconds [s] foldopt then waits for the scheduler's first worker (a worker starting takes seconds).
WORKER_TIMEOUT = 30.0
