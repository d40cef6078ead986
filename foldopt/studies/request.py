"""Requests: a study and the fields a user changed, turned into the plan that runs.

:func:`plan_request` is the one place where a request becomes a study: the command line's
``run``, ``sweep ...`` and ``size`` and the API's :func:`foldopt.sweep` and
:meth:`foldopt.Study.variant` all call it (or its policy, :func:`foldopt.inputs.policy.apply`), so the
same request gives the same plan, to the bit, whichever way it is made. It applies the study
policy, each sweep axis's default range and the year of day-of-year ranges, and lists what the
answer took from the study rather than from the request (:attr:`Request.taken`).

The command line's options become requests here too, not in the command line: a sweep's options
become field changes (:func:`sweep_changes`, :func:`sweep_request`), a map's become a map's study,
sites and loads (:func:`map_request_from`), and a sizing's costs are checked against
:data:`SIZING_LIMITS` (:func:`sizing_problems`), the same limits :func:`foldopt.size` keeps.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, replace

from foldopt.cache import offline_mode
from foldopt.inputs import policy
from foldopt.names import WEATHER_SOURCES, did_you_mean
from foldopt.inputs.study_file import default_study_path, parse_study_text, read_study
from foldopt.inputs.optimize_section import vary_names
from foldopt.engine.choice import engine_for
from foldopt.names import FIELD_OF_PARAMETER, FIELD_OPTIONS, OPTIMIZE_VARIABLES
from foldopt.inputs.plan import Plan, make_plan, parse_values, range_parts
from foldopt.errors import ConfigError

#: A sweep's axis -> the field it varies (``angle`` varies the fold angle of one case).
SWEEP_AXES = {"angle": None, "latitude": "site.latitude", "day": "date", "load": "p_load"}
#: Each sweep axis's range where the request leaves it out (``load``: see :func:`_default_loads`).
DEFAULT_RANGES = {"site.latitude": "-60:60:5", "date": "1:365:7"}
#: Short names of fields inside a section, for :func:`foldopt.sweep`'s keywords.
KEYWORDS = {
    "latitude": "site.latitude",
    "longitude": "site.longitude",
    "altitude": "site.altitude",
    "timezone": "site.timezone",
    "area": "panel.area",
    "efficiency": "panel.efficiency",
    "tilt": "panel.tilt",
    "azimuth": "panel.azimuth",
    "standby_w": "tracker.standby_w",
    "visits": "objective.visits",
}
#: Loads of a load sweep's default range: shares of the panel's rating (area x 1000 W/m^2 x efficiency).
DEFAULT_LOAD_SHARES = 20
_ISO_DATE = re.compile(r"^(\d{4})-\d\d-\d\d$")
#: Sweep options that take a value, a range or a list (:func:`foldopt.inputs.plan.parse_values`).
_LISTED = ("lat", "lon", "p_load", "p_load_scale", "tilt", "days")
#: Sweep flags and what each sets its field to.
_FLAGS = {entry.parameter: entry.flag for entry in FIELD_OPTIONS if entry.flag is not None}
#: The sizing's largest values and their units, by parameter (:attr:`foldopt.studies.sizing.SizingResult.parameters`).
#: Within them every benefit, cost and net benefit over areas up to 1000 m^2 stays far below float
#: overflow (the largest is some 1e13 $); beyond them a value is a slip, and 1e308 $/m^2 would print
#: as a 309-digit net benefit, or as -inf.
SIZING_LIMITS = {
    "cost_per_m2": (1e9, " $/m^2"),
    "cost_per_w": (1e6, " $/W"),
    "c_grid_usd_per_kwh": (1e3, " $/kWh"),
    "years": (1e3, " years"),
    "days_per_year": (366, " days"),
}


@dataclass(frozen=True)
class Request:
    """A request made into a plan.

    Attributes
    ----------
    plan : Plan
        What runs: the study and its sweep axes.
    source : str
        The study the request started from (a file, or ``the given study``).
    taken : tuple of str
        What the answer took from the study or from defaults, not from the request.
    """

    plan: Plan
    source: str
    taken: tuple

    @property
    def defaults(self) -> dict | None:
        """``{"study": source, "taken": [...]}``, or None where nothing was taken."""
        return {"study": self.source, "taken": list(self.taken)} if self.taken else None


def _default_loads(data: dict) -> list[float]:
    panel = data.get("panel") or {}
    rating = float(panel.get("area", 0.1)) * 1000.0 * float(panel.get("efficiency", 0.2))
    return [
        round(rating * share / DEFAULT_LOAD_SHARES, 4)
        for share in range(1, DEFAULT_LOAD_SHARES + 1)
    ]


def plan_request(
    data: dict,
    changes: dict | None = None,
    *,
    axis: str | None = None,
    source: str = "the given study",
    name: str | None = None,
) -> Request:
    """The plan of a study with some fields changed, and what it took from the study.

    Parameters
    ----------
    data : dict
        The study's fields (a YAML study's data, or :meth:`foldopt.Study.data`).
    changes : dict, optional
        Dotted field paths (or sections with mappings) to values: a value sets the field, a list or
        a range ``"start:stop:step"`` makes it an axis; ``date`` also takes ``"year"`` and
        ``"equinoxes-solstices"``, ``year`` the year of day-of-year ranges.
    axis : {'angle', 'latitude', 'day', 'load'}, optional
        A sweep's own axis: its field takes :data:`DEFAULT_RANGES` where ``changes`` leave it out,
        and ``angle`` is one case (with a weather file, one fold angle for the file's year).
    source : str
        How the answer names the study the request started from.
    name : str, optional
        The plan's study name (default the study's).

    Returns
    -------
    Request

    Raises
    ------
    foldopt.ConfigError
        One line per fault, naming the field.
    """
    if axis is not None and axis not in SWEEP_AXES:
        raise ConfigError([f"sweep: unknown axis {axis!r}; one of {', '.join(SWEEP_AXES)}"])
    changes = policy.flatten(dict(changes or {}))
    field = SWEEP_AXES.get(axis)
    if field is not None and field in changes and policy.is_single(changes[field]):
        raise ConfigError([f"{field}: sweep {axis} needs a range start:stop:step or a list"])
    new, decided = policy.apply(data, changes, field)
    if field is not None and field not in changes:
        new = policy.set_path(
            new, field, _default_loads(new) if field == "p_load" else DEFAULT_RANGES[field]
        )
    weather = new.get("weather")
    ensemble = isinstance(weather, dict) and weather.get("members") is not None
    if (
        axis == "angle"
        and weather is not None
        and "objective" not in new
        and (ensemble or not ("date" in changes and policy.is_single(changes["date"])))
    ):
        # a year of weather (or a day's ensemble) at one fold angle
        new["objective"] = {"statistic": "mean"}
    study_year = _ISO_DATE.match(str(data.get("date", "")))
    if "year" not in new and study_year:
        new["year"] = int(study_year.group(1))  # days of year are the study's year's
    if name is not None:
        new["name"] = name
    plan = make_plan(new)
    if axis == "angle":
        varied = [
            path
            for path, _ in plan.axes
            if not (path == "date" and plan.base.objective is not None)
        ]
        if varied:
            raise ConfigError(
                [
                    f"sweep angle: one site, day and load; {', '.join(varied)} vary (use sweep latitude, "
                    "day or load)"
                ]
            )
    return Request(plan, source, tuple(_taken(plan, changes, field, new, decided)))


def _taken(
    plan: Plan, changes: dict, field: str | None, data: dict, decided: list[str]
) -> list[str]:
    """What a request took from its study and its defaults, for the answer's "from" line."""
    from foldopt.inputs.load_profile import load_text

    study = plan.base
    given = set(changes)
    weather = "weather" in given
    taken = []
    if field is not None and field not in given:
        if field == "p_load":
            taken.append(
                f"{DEFAULT_LOAD_SHARES} loads, 5 % to 100 % of {data['p_load'][-1]:g} W (default range)"
            )
        else:
            year = f" of {data['year']}" if field == "date" and data.get("year") else ""
            label = {"site.latitude": "latitude", "date": "day"}[field]
            taken.append(f"{label} {DEFAULT_RANGES[field]}{year} (default range)")
    if not policy.touched(given, "site") and not weather and field != "site.latitude":
        taken.append(f"site {study.site.latitude:g}, {study.site.longitude:g}")
    if "date" not in given and not weather and field != "date":
        taken.append(f"date {study.date}")
    if "panel.area" not in given:
        taken.append(f"panel {study.panel.area:g} m^2")
    if "p_load" not in given and field != "p_load":
        taken.append(load_text(study))
    notes = [note for note in (policy.EXACT_NOTE, policy.MOUNTING_NOTE) if note in decided]
    if "mode" not in given:
        taken.append(notes[0] if notes else f"{study.mode} mode")
    if "pv_model" not in given:
        taken.append(f"{study.pv_model} PV model")
    taken += [item for item in decided if item not in notes]
    return taken


def size_request(plan: Plan, source: str, cost_given: bool) -> Request:
    """A sizing's request: the study's one case, and what the sizing took from it.

    Parameters
    ----------
    plan : Plan
        The study; a sizing takes one case, so a plan with sweep axes is refused.
    source : str
        How the answer (and an error) names the study.
    cost_given : bool
        Whether the request gives a panel cost; if not, the answer says it took the paper's.

    Returns
    -------
    Request
        ``taken``: the site, day, load and efficiency, and the paper's panel cost where no cost is
        given.

    Raises
    ------
    foldopt.ConfigError
        For a plan that sweeps fields.
    """
    from foldopt.inputs.load_profile import load_text
    from foldopt.inputs.costs import PAPER_COST_PER_M2

    if plan.axes:
        raise ConfigError(
            [f"config: {source} sweeps {', '.join(p for p, _ in plan.axes)}; size takes one case"]
        )
    study = plan.base
    taken = [f"site, day, {load_text(study)}, efficiency {study.panel.efficiency:g}"]
    if not cost_given:
        taken.append(
            f"panel cost {PAPER_COST_PER_M2:g} $/m^2 (what Shin et al.'s 0.108 m^2 optimum implies; "
            "cost_per_m2 or cost_per_w)"
        )
    return Request(plan, source, tuple(taken))


def sizing_problems(parameters: dict) -> list[str]:
    """The sizing's parameters that are no number in (0, :data:`SIZING_LIMITS`], one line each.

    :func:`foldopt.size` refuses them, and the command line checks them before it reads the study.

    Parameters
    ----------
    parameters : dict
        Parameter name (a key of :data:`SIZING_LIMITS`) -> value, or None where not given.

    Returns
    -------
    list of str
        ``name = value: must be a finite number > 0 and at most <limit> <unit>``, in the order of
        :data:`SIZING_LIMITS`.
    """
    problems = []
    for name, (largest, unit) in SIZING_LIMITS.items():
        value = parameters.get(name)
        if value is None or (isinstance(value, (int, float)) and 0 < value <= largest):
            continue
        shown = f"{value:g}" if isinstance(value, (int, float)) else repr(value)
        problems.append(
            f"{name} = {shown}: must be a finite number > 0 and at most {largest:g}{unit}"
        )
    return problems


def parse_setting(setting: str) -> tuple[str, object]:
    """One ``--set KEY=VALUE``: a dotted field path and a YAML value.

    Parameters
    ----------
    setting : str
        ``KEY=VALUE``, e.g. ``panel.efficiency=0.21``.

    Returns
    -------
    tuple
        The field path (``str``) and the value as YAML reads it.

    Raises
    ------
    foldopt.ConfigError
        For text without ``=`` or a key, or a value that is no YAML value.
    """
    key, separator, text = setting.partition("=")
    if not separator or not key.strip():
        raise ConfigError([f"--set = {setting!r}: expected KEY=VALUE, e.g. panel.efficiency=0.21"])
    source = f"--set {key}"
    try:
        value, _ = parse_study_text(text, source)
    except ConfigError as error:
        # parse_study_text's line is "config: <source> at line <n>: <problem>"; the problem is kept.
        problem = re.sub(rf"^config: {re.escape(source)}(?: at line \d+)?: ", "", error.errors[0])
        raise ConfigError([f"--set {key} = {text!r}: not a YAML value ({problem})"]) from None
    return key.strip(), value


def settings_plan(path, settings=()) -> Plan:
    """A YAML study's plan with fields changed by ``--set``, as if its file said so.

    Parameters
    ----------
    path : str or pathlib.Path
        The study file.
    settings : sequence of str
        ``KEY=VALUE`` texts (:func:`parse_setting`), applied in order.

    Returns
    -------
    Plan

    Raises
    ------
    foldopt.ConfigError
        One line per fault: a setting that is no ``KEY=VALUE``, or the study's validation (a
        field a setting changed without the file's line, which no longer holds it).
    """
    data, lines = read_study(path)
    errors = []
    for setting in settings:
        try:
            key, value = parse_setting(setting)
        except ConfigError as error:
            errors += error.errors
            continue
        if isinstance(data, dict):
            data = policy.set_path(data, key, value)
        parts = tuple(key.split("."))
        # Neither the changed field's lines nor its sections' (whose line a message falls back on) hold it now.
        lines = {
            loc: line
            for loc, line in lines.items()
            if loc[: len(parts)] != parts and parts[: len(loc)] != loc
        }
    if errors:
        raise ConfigError(errors)
    return make_plan(data, lines)


def sweep_changes(options: dict, data: dict) -> dict:
    """The fields the command line's sweep options change, by field path; ``--set`` last.

    Parameters
    ----------
    options : dict
        Each option of ``foldopt sweep`` by its parameter name (the keys of
        :data:`foldopt.names.FIELD_OF_PARAMETER` and ``settings``, the ``--set`` texts) -> its
        value, None (or False) where not given.
    data : dict
        The study's fields the sweep starts from.

    Returns
    -------
    dict
        Field path -> value, a range or a list (:func:`plan_request`'s ``changes``).

    Raises
    ------
    foldopt.ConfigError
        One line per fault, naming the option.
    """
    changes, errors = {}, []
    if options["p_load_scale"] is not None:
        if options["p_load"] is not None:
            errors.append(
                "--p-load / --p-load-scale: a constant load or a profile's scale, not both"
            )
        elif data.get("load_profile") is None and options["load_profile"] is None:
            errors.append(
                "--p-load-scale: scales a load profile; give one with --load-profile (or load_profile in "
                "the study)"
            )
    lonely = [
        option
        for option in ("weather_format", "members", "seed", "years")
        if options.get(option) is not None
    ]
    if lonely and options.get("weather") is None and data.get("weather") is None:
        errors.append(
            f"--{lonely[0].replace('_', '-')}: an option of a weather file; give one with --weather"
        )
    for option, value in options.items():
        if option == "settings" or value is None or value is False:
            continue
        if option in _FLAGS:
            value = _FLAGS[option]
        elif option in _LISTED:
            try:
                value = parse_values(value, numeric=option != "days")
            except ValueError as error:
                flag = "--" + option.replace("_", "-")
                errors.append(f"{flag} = {options[option]!r}: {error}")
                continue
        elif option == "weather" and str(value) in WEATHER_SOURCES:
            value = {"source": str(value)}  # a source's name: its answer for the site
        elif option == "weather":
            hint = did_you_mean(str(value), WEATHER_SOURCES)
            if hint and not os.path.lexists(str(value)):  # a misspelt source, not a file
                errors.append(
                    f"--weather = {str(value)!r}: no such file, nor a weather source "
                    f"({', '.join(WEATHER_SOURCES)}){hint}"
                )
                continue
            value = {"path": str(value)}  # a new file: none of the study's file's options
        elif option == "load_profile":
            value = {"file": str(value)}
        elif option == "horizon":
            value = {"file": str(value)}
        elif option == "load_voltage":
            changes["circuit.coupling"] = "direct"
        changes[FIELD_OF_PARAMETER[option]] = value
    if errors:
        raise ConfigError(errors)
    for setting in options["settings"] or ():
        changes.update([parse_setting(setting)])
    return changes


#: The joint optimisation's parameters, as :func:`optimize_section` and the command line name them.
OPTIMIZE_OPTIONS = {
    "vary": "--vary",
    "fold_angle": "--fold-range",
    "tilt": "--tilt-range",
    "azimuth": "--azimuth-range",
    "tolerance_h": "--tolerance",
}


def optimize_section(
    vary=None, fold_angle=None, tilt=None, azimuth=None, tolerance_h=None, labels=None
) -> dict:
    """The ``optimize`` section of a study from the API's or the command line's parameters.

    Parameters
    ----------
    vary : str or sequence of str, optional
        Variables of :data:`foldopt.names.OPTIMIZE_VARIABLES`, or them joined by commas.
    fold_angle, tilt, azimuth : str or sequence of float, optional
        Each variable's range, ``"min:max:step"`` or ``(min, max, step)`` [deg].
    tolerance_h : float, optional
    labels : dict, optional
        How messages name each parameter (:data:`OPTIMIZE_OPTIONS` for the command line).

    Returns
    -------
    dict
        The section's given fields, validated with the study (:class:`foldopt.inputs.optimize_section.Optimize`).

    Raises
    ------
    foldopt.ConfigError
        For a range that is not three numbers.
    """
    labels = labels or {}
    section, errors = {}, []
    if vary is not None:
        section["vary"] = (
            [item.strip() for item in vary.split(",")] if isinstance(vary, str) else list(vary)
        )
    for name, value in (("fold_angle", fold_angle), ("tilt", tilt), ("azimuth", azimuth)):
        if value is None:
            continue
        try:
            low, high, step = (
                range_parts(value) if isinstance(value, str) else (float(part) for part in value)
            )
        except (TypeError, ValueError):
            errors.append(
                f"{labels.get(name, name)} = {value!r}: expected min:max:step in degrees, e.g. 0:90:1"
            )
            continue
        section[name] = {"min": low, "max": high, "step": step}
    if tolerance_h is not None:
        section["tolerance_h"] = tolerance_h
    if errors:
        raise ConfigError(errors)
    return section


def sweep_request(
    study, options: dict, axis: str | None, source: str, section: dict | None = None
) -> Request:
    """The request of ``foldopt sweep AXIS``: the study, changed by the sweep's options.

    Parameters
    ----------
    study : dict, str, pathlib.Path or None
        The study's fields, or a YAML study to read them from; None for the embedded study.
    options : dict
        The sweep's options (:func:`sweep_changes`).
    axis : {'angle', 'latitude', 'day', 'load'} or None
        None for ``foldopt optimize``, which sweeps no axis of its own.
    source : str
        How the answer names the study.
    section : dict, optional
        ``foldopt optimize``'s ``optimize`` section (:func:`optimize_section`), over the study's own.

    Returns
    -------
    Request
        Its plan is named ``sweep-<axis>`` (or ``optimize``) and described as the command that made it.

    Raises
    ------
    foldopt.ConfigError
        One line per fault, naming the option or the field.
    """
    options = dict(options)
    with offline_mode(options.pop("offline", False)):  # --offline: a weather source's cache only
        return _sweep_request(study, options, axis, source, section)


def _sweep_request(study, options: dict, axis, source: str, section) -> Request:
    data = (
        study
        if isinstance(study, dict)
        else read_study(default_study_path() if study is None else study)[0]
    )
    changes = sweep_changes(options, data)
    command = "optimize" if section is not None else f"sweep {axis}"
    changes["description"] = f"foldopt {command} from {source} (see command)"
    if section is not None:
        changes["optimize"] = {**(data.get("optimize") or {}), **section}
    return plan_request(
        data, changes, axis=axis, source=source, name=f"{command.replace(' ', '-')}"
    )


def map_request_from(
    study=None,
    *,
    source: str = "the given study",
    objective: str = "mean",
    area=None,
    efficiency=None,
    step_min=None,
    angle_step=None,
    fold_search: bool = False,
    optimize=None,
    settings=(),
    loads=None,
    **where,
):
    """The request of ``foldopt map``: a study made into a map's study by the map's options, and
    the map's sites and loads (:func:`foldopt.studies.worldmap.map_request`).

    Parameters
    ----------
    study : dict, str, pathlib.Path or None
        The study's fields, or a YAML study to read them from, that the map takes its panel, models
        and load from; None for the embedded study, whose mode gives way to
        :data:`foldopt.studies.worldmap.MAP_DEFAULTS` (its sky and geometry exact mode's).
    source : str
        How the answer names the study.
    objective : str
        What each period's fold angle maximises: ``mean``, ``min``, ``worst-month`` or ``pNN``.
    area, efficiency : float, optional
        The flat panel's area [m^2] and PV efficiency [-]; default the study's.
    step_min : float, optional
        Time step [min]; default the study's.
    angle_step : float, optional
        Fold-angle grid step [deg], the grid from it to 180; default the study's grid.
    fold_search : bool
        Search each site's fold angles (``optimize: {vary: [fold_angle]}``,
        :func:`foldopt.studies.site_search.fold_search`) instead of evaluating every one.
    optimize : str or sequence of str, optional
        What the search varies with the fold angle: ``tilt`` (each site's best base tilt, the flat
        panel's own beside it); names joined by commas or a list.
    settings : sequence of str
        ``KEY=VALUE`` texts (:func:`parse_setting`), set last.
    loads : float, sequence of float or str, optional
        Default the study's ``p_load`` [W].
    **where
        ``sites``, ``weather_dir``, ``latitudes``, ``longitudes``, ``land_only``, ``relative``,
        ``year`` and ``show_period`` of :func:`foldopt.studies.worldmap.map_request`.

    Returns
    -------
    foldopt.studies.worldmap.MapRequest
        With ``taken``: the panel area, load and step the map took from the study, its PV model
        and mode.

    Raises
    ------
    foldopt.ConfigError
        One line per fault, naming the field or the parameter.
    """
    from foldopt.studies.worldmap import map_request, map_study

    data = (
        study
        if isinstance(study, dict)
        else read_study(default_study_path() if study is None else study)[0]
    )
    changes = {"objective": {"statistic": objective}}
    for field, value in (
        ("panel.area", area),
        ("panel.efficiency", efficiency),
        ("step_min", step_min),
    ):
        if value is not None:
            changes[field] = value
    if angle_step is not None:
        changes["fold_angles"] = {"start": angle_step, "stop": 180.0, "step": angle_step}
    if fold_search or optimize:
        try:
            varied = vary_names(optimize or [])
        except ValueError as error:
            raise ConfigError([f"optimize = {optimize!r}: {error}"]) from None
        if any(name not in OPTIMIZE_VARIABLES for name in varied):
            raise ConfigError(
                [f"optimize = {optimize!r}: must name some of {', '.join(OPTIMIZE_VARIABLES)}"]
            )
        extra = [name for name in varied if name != "fold_angle"]
        changes["optimize"] = {**(data.get("optimize") or {}), "vary": ["fold_angle", *extra]}
    made = map_study(data, embedded=study is None, **changes)
    for setting in settings:
        field, value = parse_setting(setting)
        made = policy.set_path(made, field, value)
    # The study's load as its file gives it: a value, a list or a range text, checked like --p-load.
    request = map_request(made, (data.get("p_load") or 1.0) if loads is None else loads, **where)
    study_loads = (
        f"P_load {request.loads[0]:g} W"
        if len(request.loads) == 1
        else f"P_load {len(request.loads)} loads, {min(request.loads):g} to {max(request.loads):g} W"
    )
    made = request.study
    taken = [
        f"panel {made.panel.area:g} m^2" if area is None else None,
        study_loads if loads is None and not request.relative else None,
        f"{made.pv_model} PV model",
        f"{made.mode} mode",
        f"{made.step_min:g}-min steps" if step_min is None else None,
    ]
    return replace(request, source=source, taken=tuple(item for item in taken if item))


def request_engine(engine: str, plan) -> str:
    """The engine of every evaluation of one request (:data:`foldopt.names.ENGINES`), decided once
    where the request enters the API (:func:`foldopt.run`, :func:`foldopt.optimize`,
    :func:`foldopt.world_map`, :func:`foldopt.reproduce`): downstream every evaluation takes it,
    so one request's numbers come from one engine, the same every time.

    ``auto`` (:mod:`foldopt.engine.choice`) takes the NumPy reference path where the request's
    clear-sky days at its fold angles come to at most
    :data:`foldopt.names.AUTO_NUMPY_ROW_STEPS` rows x steps: a day's study, its sweeps of the
    angle or the load, a few latitudes or days (nothing to compile). A weather file's or a cloud
    ensemble's days, more days, a joint search over the tilt or the azimuth (some 10^4 designs),
    a study with a buffer (whose reference path walks the time steps in Python) and a map
    (``plan`` None: a year at every site) take the compiled kernel.

    Parameters
    ----------
    engine : {'auto', 'numba', 'numpy'}
    plan : foldopt.inputs.plan.Plan, foldopt.Study or None
        The request's plan or study; None for a map's.

    Returns
    -------
    str
        ``'numba'`` or ``'numpy'``; an unknown ``engine`` raises ValueError naming the valid ones.
    """
    if plan is None:
        return engine_for(engine, math.inf)
    base, cases = (plan.base, plan.n_cases) if isinstance(plan, Plan) else (plan, 1)
    if base.weather is not None:
        return engine_for(engine, math.inf)
    if base.storage is not None:
        # The buffer's reference path walks the time steps in Python, 0.8 s a pass over a day of
        # 1-min steps however few the curves, and a periodic state takes 2 to 60 passes: a day's
        # buffer sized for a target took 55 s there, 0.23 s compiled (its first compile 6 s).
        return engine_for(engine, math.inf)
    if base.optimize is not None and set(base.optimize.vary) != {"fold_angle"}:
        # A joint search over the tilt or the azimuth evaluates some 10^4 designs of a day (the
        # embedded study's 15,915: results/examples/optimize/added.csv), 23 M rows x steps.
        return engine_for(engine, math.inf)
    return engine_for(engine, cases * base.fold_angles.count() * round(24 * 60 / base.step_min))
