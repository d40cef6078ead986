"""The front door: every request becomes one validated plan here, by :func:`make_request`.

A request is a command (:data:`foldopt.capabilities.COMMANDS`), the study it starts from (a YAML
file, the embedded study, a mapping, a :class:`~foldopt.Study` or a :class:`~foldopt.Plan`) and
what the user changed: the command line's options, ``--set KEY=VALUE`` texts, the API's
keywords, a joint search's ranges, a sizing's target or a map's sites. The command line's
``run``, ``sweep ...``, ``optimize``, ``size`` and ``map`` and the API's :func:`foldopt.run`,
:func:`foldopt.sweep`, :func:`foldopt.optimize`, :func:`foldopt.size` and
:func:`foldopt.world_map` all call :func:`make_request`, so one request gives one plan to the bit
whichever way it is made. Its steps:

1. **merge** (:func:`_merge`): each entry's field changes, one value per field: a field given
   twice (``--storage-wh 20 --set storage.capacity_wh=30``, two ``--set`` of one key) is refused in
   one line naming both;
2. **decide** (:func:`foldopt.inputs.policy.apply`): the study policy, each sweep axis's default
   range, the year of day-of-year ranges; what the answer took from the study is listed
   (:attr:`Request.taken`);
3. **validate** (:func:`foldopt.inputs.plan.make_plan`, or
   :func:`foldopt.studies.map_request.map_request` for a map), reading the files the study names
   once; a weather file completes a partial site (given fields win, the rest is the file's);
4. **refuse** what the request's run does not honour (:data:`foldopt.capabilities.CAPABILITIES`), so
   that no command ignores a section silently.

Messages name fields by what the user typed (:attr:`Request.labels`): ``--storage-wh`` where
that option was given, ``--set storage.capacity_wh`` where that was, the keyword for the API.
"""

from __future__ import annotations

import copy
import math
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from foldopt.cache import offline_mode
from foldopt.capabilities import COMMAND_RUNS, COMMANDS, SET_BY_RUN, refusal, refusals
from foldopt.engine.choice import engine_for
from foldopt.errors import ConfigError
from foldopt.inputs import policy
from foldopt.inputs.fields import year_problem
from foldopt.inputs.optimize_section import vary_names
from foldopt.inputs.plan import Plan, make_plan, parse_values, range_parts
from foldopt.inputs.study import Study
from foldopt.inputs.study_file import default_study_path, parse_study_text, read_study
from foldopt.names import (
    FIELD_OF_PARAMETER,
    FIELD_OPTIONS,
    FLAT_FOLD_ANGLE,
    OPTIMIZE_VARIABLES,
    WEATHER_SOURCES,
    did_you_mean,
)

#: How answers and messages name the embedded study.
EMBEDDED = "configs/shin2015.yaml"
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
    "planes": "panel.planes",
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
#: Each field option's parameter -> how messages name it (``--days/--date``).
_LABEL_OF_PARAMETER = {entry.parameter: entry.label for entry in FIELD_OPTIONS}
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
#: The joint optimisation's parameters, as :func:`optimize_section` and the command line name them.
OPTIMIZE_OPTIONS = {
    "vary": "--vary",
    "fold_angle": "--fold-range",
    "tilt": "--tilt-range",
    "azimuth": "--azimuth-range",
    "tolerance_h": "--tolerance",
}
#: A map's fields that its options set (the rest of its study is the study file's).
MAP_OPTIONS = {
    "area": "panel.area",
    "efficiency": "panel.efficiency",
    "step_min": "step_min",
    "objective": "objective.statistic",
    "p_load": "p_load",
    "year": "year",
}


@dataclass(frozen=True)
class Request:
    """A request made into what runs (:func:`make_request`).

    Attributes
    ----------
    command : str
        One of :data:`foldopt.capabilities.COMMANDS`.
    plan : Plan or foldopt.studies.map_request.MapSpec
        What runs: the validated studies and their sweep axes, or a map's study, sites and loads.
    source : str
        The study the request started from (a file, or ``the given study``).
    taken : tuple of str
        What the answer took from the study or from defaults, not from the request.
    labels : dict
        Field path -> how the request gave it (``--storage-wh``, ``--set storage.capacity_wh``,
        a keyword): messages of later stages name fields so (:meth:`rename`).
    run : str
        The kind of run (:data:`foldopt.capabilities.RUNS`).
    """

    command: str
    plan: object
    source: str
    taken: tuple = ()
    labels: Mapping = field(default_factory=dict)
    run: str = "day"

    @property
    def defaults(self) -> dict | None:
        """``{"study": source, "taken": [...]}``, or None where nothing was taken."""
        return {"study": self.source, "taken": list(self.taken)} if self.taken else None

    def rename(self, line: str) -> str:
        """A message's leading field as the request gave it (:func:`rename_field`)."""
        return rename_field(line, self.labels)


_FIELD = re.compile(r"^([A-Za-z_.]+)(\[[\d,]+\])?")


def rename_field(line: str, labels: Mapping) -> str:
    """A message's leading field path as the request gave it.

    Parameters
    ----------
    line : str
        ``field: problem`` or ``field = value: problem``.
    labels : mapping
        Field path -> label; the longest path that the line's field is or lies in is used.

    Returns
    -------
    str
        The line with its field renamed (``--storage-wh = nan: ...``), or as it was.
    """
    match = _FIELD.match(line)
    if not match:
        return line
    path, end = match.group(1), match.end(1)
    if path in labels:
        return labels[path] + line[end:]
    # A part of what an option gave: --tilt-range step (a --set names its own key's parts).
    parts = path.split(".")
    for cut in range(len(parts) - 1, 0, -1):
        label = labels.get(".".join(parts[:cut]))
        if label is not None:
            if not label.startswith("--") or label.startswith("--set "):
                return line
            return f"{label} {' '.join(parts[cut:])}{line[end:]}"
    return line


def make_request(
    command: str,
    study=None,
    *,
    options: Mapping | None = None,
    settings: Sequence[str] = (),
    fields: Mapping | None = None,
    optimize: Mapping | None = None,
    target_h: float | None = None,
    where: Mapping | None = None,
    costs: Mapping | None = None,
    source: str | None = None,
) -> Request:
    """The one front door: a request made into a validated plan, or refused in one line per fault.

    Parameters
    ----------
    command : str
        One of :data:`foldopt.capabilities.COMMANDS` (``run``, ``sweep angle``, ``optimize``,
        ``size``, ``size --storage``, ``map``...).
    study : None, str, pathlib.Path, dict, Study or Plan
        The study the request starts from; None for the embedded study.
    options : mapping, optional
        The command line's options that set study fields, by parameter name (the keys of
        :data:`foldopt.names.FIELD_OF_PARAMETER`; for a map, :data:`MAP_OPTIONS` and
        ``angle_step``, ``fold_search``, ``optimize``, ``p_load_fraction``), and ``offline``;
        None (or False) where not given.
    settings : sequence of str
        ``--set KEY=VALUE`` texts (:func:`parse_setting`).
    fields : mapping, optional
        The API's keywords: dotted field paths, or the short names of :data:`KEYWORDS`, to values;
        a list or a range ``"start:stop:step"`` sweeps a field; ``fold_angle``, one fold angle
        [deg] (:func:`one_fold_angle`, as ``--fold-angle``).
    optimize : mapping, optional
        A joint search's parameters (:func:`optimize_section`'s): ``vary``, ``fold_angle``,
        ``tilt``, ``azimuth``, ``tolerance_h``, and ``labels``, how messages name them.
    target_h : float, optional
        ``run``, ``size --storage``: the hours a day the load runs (``storage.target.powered_h``,
        ``--target-h``).
    where : mapping, optional
        A map's sites and how they are shown: ``sites``, ``weather_dir``, ``latitudes``,
        ``longitudes``, ``land_only``, ``show_period``, ``weather`` (a source's section) of
        :func:`foldopt.studies.map_request.map_request`, one source of sites among the grid,
        ``sites`` and ``weather_dir`` (:func:`_where_problems`); and ``labels``, how messages
        name them (the command line's options: ``{"latitudes": "--lat", ...}``).
    costs : mapping, optional
        ``size``: the sizing's parameters (keys of :data:`SIZING_LIMITS`), None where not given:
        each is checked, and the answer says where it took the paper's panel cost.
    source : str, optional
        How the answer names the study; default its file, or ``the given study``.

    Returns
    -------
    Request

    Raises
    ------
    foldopt.ConfigError
        One line per fault, naming the field as the request gave it.
    """
    if command not in COMMANDS:
        raise ValueError(
            f"command must be one of {', '.join(COMMANDS)}{did_you_mean(command, COMMANDS)}"
        )
    options = dict(options or {})
    if costs is not None and sizing_problems(costs):
        raise ConfigError(sizing_problems(costs))
    with offline_mode(options.pop("offline", False)):  # --offline: a weather source's cache only
        data, lines, named = _study_data(study)
        source = source or named
        entries = _entries(command, data, options, settings, fields, optimize, target_h)
        changes, labels = _merge(entries)
        labels.update(_also_labels(options, labels))
        try:
            if command == "map":
                return _map_request(data, study is None, changes, labels, options, where, source)
            return _plan_request(command, study, data, lines, changes, labels, source, costs)
        except ConfigError as error:
            raise ConfigError(
                [
                    rename_field(_missing_hint(line, labels, bool(options)), labels)
                    for line in error.errors
                ]
            ) from None


def _also_labels(options: Mapping, labels: Mapping) -> dict:
    """The fields an option sets beside its own (``--angle-step``: where the grid starts), named
    by it where no entry names them."""
    return {
        also: entry.label
        for entry in FIELD_OPTIONS
        if options.get(entry.parameter) is not None and options.get(entry.parameter) is not False
        for also in entry.also
        if also not in labels
    }


def _missing_hint(line: str, labels: Mapping, has_options: bool) -> str:
    """A section's missing field said with what made the section: ``--min-soc`` alone makes a
    buffer that has no capacity. The option that gives the field is named where the command
    takes options (``has_options``)."""
    path, _, problem = line.partition(": ")
    if problem != "required field is missing":
        return line
    section = path.rpartition(".")[0]
    makers = [label for given, label in labels.items() if policy.touched([given], section)]
    if not makers:
        return line
    option = next((entry.label for entry in FIELD_OPTIONS if entry.field == path), None)
    how = f"{option} (or {path})" if option and has_options else path
    return f"{makers[0]}: {section} needs {path.rpartition('.')[2]} too; give {how}"


def _study_data(study) -> tuple[dict, dict, str]:
    """The fields of the study a request starts from, the YAML line of each key, and its name."""
    if study is None or isinstance(study, (str, Path)):
        data, lines = read_study(default_study_path() if study is None else study)
        if not isinstance(data, dict):
            raise ConfigError([f"study: expected a mapping of fields, got {type(data).__name__}"])
        return data, lines, EMBEDDED if study is None else str(study)
    if isinstance(study, Plan):
        return study.data, {}, "the given study"
    if isinstance(study, Study):
        return study.data(), {}, "the given study"
    if not isinstance(study, dict):
        raise ConfigError([f"study: expected a mapping of fields, got {type(study).__name__}"])
    return study, {}, "the given study"


def _entries(command, data, options, settings, fields, optimize, target_h) -> list[tuple]:
    """Each entry of a request as ``(label of a path, {path: value})`` pairs, in the order they
    apply: the command's options, the API's keywords, the joint search's ranges, ``--set``."""
    entries = []
    if options and command == "map":
        entries += _map_entries(options, data)
    elif options:
        entries += _option_entries(options, data)
    for name, value in (fields or {}).items():
        if name == "fold_angle":  # one angle, as --fold-angle gives it
            try:
                entries.append((name, {"fold_angles": one_fold_angle(value)}))
            except ValueError as error:
                raise ConfigError([f"fold_angle = {value!r}: {error}"]) from None
            continue
        path = KEYWORDS.get(name, name)
        entries.append((name, {path: _plain(value)}))
    if optimize:
        labels = optimize.get("labels") or {}
        section = optimize_section(
            **{k: v for k, v in optimize.items() if k != "labels"}, labels=labels
        )
        entries += [
            (labels.get(name, f"optimize.{name}"), {f"optimize.{name}": value})
            for name, value in section.items()
        ]
    if target_h is not None:
        entries.append(("--target-h", {"storage.target.powered_h": target_h}))
    errors = []
    for setting in settings or ():
        try:
            key, value = parse_setting(setting)
        except ConfigError as error:
            errors += error.errors
            continue
        entries.append((f"--set {key}", {key: value}, False))  # its key is the field's name
    if errors:
        raise ConfigError(errors)
    return entries


def _leaves(path: str, value) -> list[str]:
    """The field paths a change sets: a section's mapping sets only the fields it names."""
    if (
        isinstance(value, dict)
        and value
        and path.partition(".")[0]
        in policy.SECTIONS
        + (
            "weather",
            "circuit",
            "optimize",
            "load_profile",
        )
    ):
        return [leaf for key, item in value.items() for leaf in _leaves(f"{path}.{key}", item)]
    return [path]


def _merge(entries: list[tuple]) -> tuple[dict, dict]:
    """One value per field: the entries' changes in order, and the label of each field whose
    entry names it otherwise (an option, a keyword: messages say it so).

    Parameters
    ----------
    entries : list of tuple
        ``(label, {path: value})``, or ``(label, {path: value}, False)`` for an entry whose
        messages keep the field's own name (a ``--set`` key, a field an option chose).

    Raises
    ------
    foldopt.ConfigError
        For a field two entries set (or one inside a field another sets whole): one line naming
        both and their values.
    """
    changes, labels, owners, errors = {}, {}, {}, []
    for label, items, *renames in entries:
        for path, value in items.items():
            for leaf in _leaves(path, value):
                clash = next(
                    (
                        other
                        for other in owners
                        if other == leaf
                        or other.startswith(leaf + ".")
                        or leaf.startswith(other + ".")
                    ),
                    None,
                )
                if clash is not None and owners[clash][0] != label:
                    first, given = owners[clash]
                    errors.append(
                        f"{leaf}: given twice, as {first} = {_shown(given)} and {label} = "
                        f"{_shown(_value_at(path, value, leaf))}; give one"
                    )
                    continue
                if clash is not None:
                    errors.append(f"{label}: given twice; give each setting once")
                    continue
                owners[leaf] = (label, _value_at(path, value, leaf))
            changes[path] = value
            # a --set key, a field an option chose: messages keep the field's own name
            labels[path] = label if renames != [False] else path
    if errors:
        raise ConfigError(list(dict.fromkeys(errors)))
    return changes, labels


def _value_at(path: str, value, leaf: str):
    """The value a change gives one of its leaves."""
    for key in leaf[len(path) + 1 :].split(".") if leaf != path else ():
        value = value.get(key) if isinstance(value, dict) else value
    return value


def _shown(value) -> str:
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        return f"{value:g}"
    return repr(value) if isinstance(value, str) else str(value)


def _option_entries(options: dict, data: dict) -> list[tuple]:
    """The command line's field options as entries (the option's label, its field's change)."""
    errors, entries = [], []
    if options.get("p_load_scale") is not None:
        if options.get("p_load") is not None:
            errors.append(
                "--p-load / --p-load-scale: a constant load or a profile's scale, not both"
            )
        elif data.get("load_profile") is None and options.get("load_profile") is None:
            errors.append(
                "--p-load-scale: scales a load profile; give one with --load-profile (or load_profile in "
                "the study)"
            )
    if options.get("fold_angle") is not None and options.get("angle_step") is not None:
        errors.append("--fold-angle / --angle-step: one fold angle or a grid's step, not both")
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
        if value is None or value is False:
            continue
        path, label = FIELD_OF_PARAMETER[option], _LABEL_OF_PARAMETER[option]
        if option in _FLAGS:
            value = _FLAGS[option]
        elif option in _LISTED:
            try:
                value = parse_values(value, numeric=option != "days")
            except ValueError as error:
                errors.append(f"{label} = {options[option]!r}: {error}")
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
        elif option in ("load_profile", "horizon"):
            value = {"file": str(value)}
        elif option in ("planes", "fold_angle"):
            try:
                value = parse_planes(value) if option == "planes" else one_fold_angle(value)
            except ValueError as error:
                errors.append(f"{label} = {options[option]!r}: {error}")
                continue
        if option == "load_voltage":
            # coupled directly: said as circuit.coupling, the field the option chose
            entries.append((label, {"circuit.coupling": "direct"}, False))
        entries.append((label, {path: value}))
    if errors:
        raise ConfigError(errors)
    return entries


def parse_planes(text: str) -> list[list[float]]:
    """``--planes``: two planes ``TILT/AZIMUTH,TILT/AZIMUTH`` [deg] as ``panel.planes`` takes them.

    Parameters
    ----------
    text : str
        ``9/14,9/194``.

    Returns
    -------
    list of list of float
        ``[[9.0, 14.0], [9.0, 194.0]]``; the ranges are the study's to check.

    Raises
    ------
    ValueError
        For anything but two pairs of numbers.
    """
    planes = [plane.split("/") for plane in str(text).split(",")]
    try:
        if len(planes) == 2 and all(len(plane) == 2 for plane in planes):
            return [[float(part) for part in plane] for plane in planes]
    except ValueError:
        pass  # not numbers: said below
    raise ValueError("expected two planes TILT/AZIMUTH,TILT/AZIMUTH [deg], e.g. 9/14,9/194")


def one_fold_angle(angle) -> dict:
    """``--fold-angle``: the fold-angle grid of that one angle [deg], as
    ``--set fold_angles={start: X, stop: X, step: 1}`` gives it.

    Raises
    ------
    ValueError
        For anything but a number in (0, 180].
    """
    number = isinstance(angle, (int, float)) and not isinstance(angle, bool)
    if not (number and 0.0 < angle <= FLAT_FOLD_ANGLE):
        raise ValueError("must be one fold angle in (0, 180] deg")
    return {"start": angle, "stop": angle, "step": 1}


def _map_entries(options: dict, data: dict) -> list[tuple]:
    """A map's options that set its study's fields, as entries."""
    entries = []
    for option, path in MAP_OPTIONS.items():
        if options.get(option) is not None:
            entries.append((f"--{option.replace('_', '-')}", {path: options[option]}))
    if options.get("p_load_fraction") is not None:
        if options.get("p_load") is not None:
            raise ConfigError(
                [
                    "--p-load / --p-load-fraction: give loads one way, in watts or as fractions "
                    "of each site's flat peak"
                ]
            )
        entries.append(("--p-load-fraction", {"p_load": options["p_load_fraction"]}))
    if options.get("angle_step") is not None:
        step = options["angle_step"]
        entries.append(
            (
                "--angle-step",
                {"fold_angles": {"start": step, "stop": FLAT_FOLD_ANGLE, "step": step}},
            )
        )
    searched = options.get("optimize")
    if options.get("fold_search") or searched:
        try:
            varied = vary_names(searched or [])
        except ValueError as error:
            raise ConfigError([f"--optimize = {searched!r}: {error}"]) from None
        if any(name not in OPTIMIZE_VARIABLES for name in varied):
            raise ConfigError(
                [f"--optimize = {searched!r}: must name some of {', '.join(OPTIMIZE_VARIABLES)}"]
            )
        extra = [name for name in varied if name != "fold_angle"]
        label = "--optimize" if searched else "--fold-search"
        entries.append((label, {"optimize.vary": ["fold_angle", *extra]}))
    return entries


def _plain(values):
    """A sequence (a list, a tuple, an array) as a list of plain values; text and scalars as they are."""
    if isinstance(values, (str, dict)) or not (
        isinstance(values, Sequence) or hasattr(values, "tolist")
    ):
        return values.item() if hasattr(values, "item") else values
    items = [item.item() if hasattr(item, "item") else item for item in values]
    return [item.isoformat() if hasattr(item, "isoformat") else item for item in items]


def _default_loads(data: dict) -> list[float]:
    panel = data.get("panel") or {}
    rating = float(panel.get("area", 0.1)) * 1000.0 * float(panel.get("efficiency", 0.2))
    return [
        round(rating * share / DEFAULT_LOAD_SHARES, 4)
        for share in range(1, DEFAULT_LOAD_SHARES + 1)
    ]


def _plan_request(command, study, data, lines, changes, labels, source, costs) -> Request:
    """Steps 2 to 4 of every request but a map's."""
    axis = command.partition(" ")[2] if command.startswith("sweep ") else None
    if isinstance(study, (Plan, Study)) and not changes:
        plan = study if isinstance(study, Plan) else _plan_of(study)
        taken = _taken(plan, set(), None, plan.data, []) if command != "run" else []
    else:
        given = set(changes)
        changes = {**changes, **_command_defaults(command, data, changes)}
        if axis is not None or command == "optimize":
            description = f"foldopt {command} from {source} (see command)"
            changes.setdefault("description", description)
        field = SWEEP_AXES.get(axis)
        flat = policy.flatten(changes)
        if field is not None and field in flat and policy.is_single(flat[field]):
            raise ConfigError([f"{field}: sweep {axis} needs a range start:stop:step or a list"])
        new, decided = policy.apply(data, flat, field)
        if field is not None and field not in flat:
            new = policy.set_path(
                new, field, _default_loads(new) if field == "p_load" else DEFAULT_RANGES[field]
            )
            labels[field] = f"sweep {axis}'s default range"  # not an option the user gave
        weather = new.get("weather")
        ensemble = isinstance(weather, dict) and weather.get("members") is not None
        if (
            axis == "angle"
            and weather is not None
            and "objective" not in new
            and (ensemble or not ("date" in flat and policy.is_single(flat["date"])))
        ):
            new["objective"] = {"statistic": "mean"}  # a year of weather at one fold angle
        study_year = _ISO_DATE.match(str(data.get("date", "")))
        if "year" not in new and study_year and not year_problem(int(study_year.group(1))):
            new["year"] = int(study_year.group(1))  # days of year are the study's year's
        if axis is not None or command == "optimize":
            new["name"] = command.replace(" ", "-")
        elif command == "size --storage" and "name" not in given:
            new["name"] = f"{data.get('name')}-buffer"
        plan = make_plan(new, _unchanged_lines(lines, data, new))
        taken = _taken(plan, given, field, new, decided) if command != "run" else decided
    run = _run_of(command, plan)
    _refuse_unhonoured(command, run, plan.base)
    pinned = labels.get("fold_angles")
    if pinned in ("--fold-angle", "fold_angle") and command == "optimize":
        raise ConfigError(
            [
                f"{pinned}: foldopt optimize searches the mounting over a grid of fold angles "
                "(--fold-range); one fold angle is evaluated by foldopt sweep angle --fold-angle"
            ]
        )
    _refuse_empty_season(plan)
    if _set_by_run(run, policy.flatten(changes)):
        raise ConfigError(_set_by_run(run, policy.flatten(changes)))
    if axis == "angle":
        varied = [
            path
            for path, _ in plan.axes
            if not (path == "date" and plan.base.objective is not None)
        ]
        if varied:
            raise ConfigError(
                [
                    f"sweep angle: one site, day and load; {', '.join(varied)} vary (use sweep "
                    "latitude, day or load)"
                ]
            )
    if command == "size":
        taken = _size_taken(plan, source, taken, costs or {})
    return Request(command, plan, source, tuple(taken), labels, run)


def _command_defaults(command: str, data: dict, changes: dict) -> dict:
    """What a command sets where neither the study nor the request does."""
    touched = set(policy.flatten(changes))
    defaults = {}
    if (
        command == "optimize"
        and data.get("optimize") is None
        and not policy.touched(touched, "optimize")
    ):
        defaults["optimize"] = {}  # the search's own defaults: every variable
    if command == "size --storage":
        if data.get("storage") is None and not policy.touched(touched, "storage.capacity_wh"):
            defaults["storage.capacity_wh"] = 0.0  # an ideal buffer, sized from nothing
        weather = changes.get("weather", data.get("weather"))
        if (
            weather is not None
            and data.get("objective") is None
            and not policy.touched(touched, "objective")
        ):
            defaults["objective"] = {"statistic": "mean"}  # a weather year: one angle for it
    return defaults


def _unchanged_lines(lines: dict, data: dict, new: dict) -> dict:
    """A study file's key lines less those whose values a request (or the policy) changed: a
    message about such a field must not point at the file's line."""
    missing = object()

    def at(tree, loc):
        for key in loc:
            if not isinstance(tree, dict) or key not in tree:
                return missing
            tree = tree[key]
        return tree

    return {loc: line for loc, line in lines.items() if at(data, loc) == at(new, loc)}


def _plan_of(study: Study) -> Plan:
    """A study as a plan of one case, its validated self kept."""
    from foldopt.inputs.study_file import with_files

    return Plan.of(with_files(study))


def _run_of(command: str, plan: Plan) -> str:
    """The kind of run a plan is (:data:`foldopt.capabilities.RUNS`)."""
    if command == "size":
        return "sizing"
    base = plan.base
    if base.optimize is not None:
        return "optimize"
    if base.weather is not None and base.weather.members is not None:
        return "ensemble"
    axes = dict(plan.axes)
    if base.objective is not None and "date" in axes:
        return "annual"
    return "cases" if axes else "day"


#: Each capability's test on a validated study: whether the study has it.
_HAS = {
    "storage": lambda study: study.storage is not None,
    "weather": lambda study: study.weather is not None,
    "weather.members": lambda study: (
        study.weather is not None and study.weather.members is not None
    ),
    "site.horizon": lambda study: study.site is not None and study.site.horizon is not None,
    "load_profile": lambda study: study.load_profile is not None,
    "optimize": lambda study: study.optimize is not None,
    "panel.planes": lambda study: study.panel.planes is not None,
    "costs": lambda study: study.costs is not None,
}


def _refuse_unhonoured(command: str, run: str, study) -> None:
    """Refuse, one line each, the capabilities a study has that its run does not honour."""
    from foldopt.capabilities import CAPABILITIES

    if run not in COMMAND_RUNS[command]:
        # A study's optimize section would make a sweep a joint search: refused, not followed.
        run = COMMAND_RUNS[command][0]
    errors = refusals(
        (
            capability.name
            for capability in CAPABILITIES
            if run not in capability.honoured and _HAS[capability.name](study)
        ),
        command,
        run,
    )
    if errors:
        raise ConfigError(errors)


def _refuse_empty_season(plan: Plan) -> None:
    """Refuse an objective whose months hold none of the plan's days: a statistic over no days
    has no value, so no fold angle can be chosen for it."""
    objective = plan.base.objective
    if objective is None or not objective.months:
        return
    dates = dict(plan.axes).get("date", (plan.base.date,))
    if not any(date.month in objective.months for date in dates):
        raise ConfigError(
            [
                f"objective.months = {list(objective.months)}: none of the {len(dates)} days "
                f"({dates[0]} to {dates[-1]}) is in these months; give days in them, or other "
                "months"
            ]
        )


def _set_by_run(run: str, changes: dict) -> list[str]:
    """The fields a request gives that its run sets itself or has no use for, one line each."""
    return [
        f"{path}: {why}"
        for prefix, why in SET_BY_RUN.get(run, {}).items()
        for path in changes
        if policy.touched([path], prefix)
    ]


def _taken(plan: Plan, given: set, field: str | None, data: dict, decided: list[str]) -> list[str]:
    """What a request took from its study and its defaults, for the answer's "from" line."""
    from foldopt.inputs.load_profile import load_text

    study = plan.base
    given = set(policy.flatten({path: None for path in given}))
    weather = policy.touched(given, "weather")
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
    source = study.weather is not None and study.weather.source is not None
    if not policy.touched(given, "site") and (source or not weather) and field != "site.latitude":
        taken.append(f"site {study.site.latitude:g}, {study.site.longitude:g}")
    if "date" not in given and not weather and field != "date":
        taken.append(f"date {study.date}")
    if not policy.touched(given, "panel.area") and not policy.touched(given, "panel"):
        taken.append(f"panel {study.panel.area:g} m^2")
    if "p_load" not in given and field != "p_load":
        taken.append(load_text(study))
    notes = [note for note in (policy.EXACT_NOTE, policy.MOUNTING_NOTE) if note in decided]
    if "mode" not in given:
        taken.append(notes[0] if notes else f"{study.mode} mode")
    if "pv_model" not in given:
        taken.append(study.pv_model_text())
    taken += [item for item in decided if item not in notes]
    return taken


def _size_taken(plan: Plan, source: str, taken: list[str], costs: Mapping) -> list[str]:
    """What a panel sizing took from its study: the site, day, load and efficiency where the
    request does not give them (every area's panel has the study's efficiency) and, where it gives
    no panel cost, the paper's."""
    from foldopt.inputs.costs import PAPER_COST_PER_M2

    if plan.axes:
        raise ConfigError(
            [f"config: {source} sweeps {', '.join(p for p, _ in plan.axes)}; size takes one case"]
        )
    study = plan.base
    # the areas are the sizing's own: the study's panel area is not taken
    taken = [item for item in taken if not item.startswith("panel ")]
    taken.append(f"efficiency {study.panel.efficiency:g}")
    if costs.get("cost_per_m2") is None and costs.get("cost_per_w") is None:
        taken.append(
            f"panel cost {PAPER_COST_PER_M2:g} $/m^2 (what Shin et al.'s 0.108 m^2 optimum implies; "
            "cost_per_m2 or cost_per_w)"
        )
    return taken


def _map_request(data, embedded, changes, labels, options, where, source) -> Request:
    """A map's request: its study (the study's panel and models, the map's options over them),
    sites and loads, checked once (:func:`foldopt.studies.map_request.map_request`), as a
    :class:`foldopt.studies.map_request.MapSpec`. Its messages name ``where``'s parameters by
    ``where["labels"]`` (the command line's options), later stages' too (:attr:`Request.labels`)."""
    from foldopt.studies.map_request import map_request, map_study

    where = dict(where or {})
    # a field's own label wins: --set weather.years is named so, not --years
    labels = {**(where.pop("labels", None) or {}), **labels}
    flat = policy.flatten(changes)
    errors = _set_by_run("map", flat)
    # The study's and the request's weather: a source is fetched at each site; a file is one site's.
    weather = copy.deepcopy(data.get("weather"))
    for path, value in flat.items():
        if policy.touched([path], "weather"):
            weather = policy.set_path({"weather": weather}, path, value)["weather"]
    errors += _where_problems(where, weather, set(flat), labels)
    if isinstance(weather, str) or (isinstance(weather, dict) and weather.get("path")):
        errors.append(
            "weather: a map's sites each bring their own weather: a folder of files "
            f"({_name('weather_dir', labels)}) or a source ({_name('weather.source', labels)} "
            f"{' | '.join(WEATHER_SOURCES)})"
        )
    elif isinstance(weather, dict) and weather.get("members") is not None:
        errors.append(refusal("weather.members", "map", "map"))
    site = data.get("site")
    horizon = site.get("horizon") if isinstance(site, dict) else None
    given = []
    for name, present in (
        ("storage", data.get("storage") is not None or policy.touched(flat, "storage")),
        ("costs", data.get("costs") is not None or policy.touched(flat, "costs")),
        ("load_profile", data.get("load_profile") is not None or "load_profile" in flat),
        ("site.horizon", horizon is not None),
        (
            "panel.planes",
            isinstance(data.get("panel"), dict)
            and data["panel"].get("planes") is not None
            or flat.get("panel.planes") is not None,
        ),
    ):
        if present and name == "site.horizon":
            errors.append(
                "site.horizon: a horizon is of one site; give each site its own in the "
                "--sites CSV's horizon column"
            )
        elif present:
            given.append(name)
    errors += refusals(given, "map", "map")
    if errors:
        raise ConfigError(list(dict.fromkeys(errors)))
    weather = {
        **(weather if isinstance(weather, dict) else {}),
        **(where.pop("weather", None) or {}),
    }
    if weather.get("source") is not None:
        where["weather"] = weather
    relative = options.get("p_load_fraction") is not None or bool(where.pop("relative", False))
    year = flat.pop("year", data.get("year", 2025))
    loads = flat.pop("p_load", None)
    study = {key: value for key, value in flat.items() if not policy.touched([key], "weather")}
    made, _ = policy.apply(map_study(data, embedded=embedded), study)
    # The study's load as its file gives it: a value, a list or a range text, checked like --p-load.
    try:
        spec = map_request(
            made,
            (data.get("p_load") or 1.0) if loads is None else loads,
            relative=relative,
            year=year,
            **where,
        )
    except ConfigError as error:
        raise ConfigError([rename_field(line, labels) for line in error.errors]) from None
    loads_taken = (
        f"P_load {spec.loads[0]:g} W"
        if len(spec.loads) == 1
        else f"P_load {len(spec.loads)} loads, {min(spec.loads):g} to {max(spec.loads):g} W"
    )
    taken = [
        f"panel {spec.study.panel.area:g} m^2" if "panel.area" not in flat else None,
        loads_taken if loads is None and not relative else None,
        spec.study.pv_model_text(),
        f"{spec.study.mode} mode",
        f"{spec.study.step_min:g}-min steps" if "step_min" not in flat else None,
    ]
    return Request("map", spec, source, tuple(item for item in taken if item), labels, "map")


def _name(parameter: str, labels: Mapping) -> str:
    """A map's parameter as the request names it (``latitudes``, or the command line's ``--lat``)."""
    return labels.get(parameter, parameter)


def _where_problems(where: Mapping, weather, changed: set, labels: Mapping) -> list[str]:
    """What a map's ``where`` cannot have together: one source of sites (a grid of latitudes and
    longitudes, a CSV of sites, a folder of weather files), ``land_only`` of a grid alone, and a
    weather source neither with a folder's files nor, for its years alone, missing.

    Parameters
    ----------
    where : mapping
        :func:`make_request`'s ``where``.
    weather : dict, str or None
        The study's weather section, the request's field changes made.
    changed : set of str
        The fields the request changes.
    labels : mapping
        How messages name ``where``'s parameters and the fields (``--lat``, ``--set weather.years``).

    Returns
    -------
    list of str
        One line per fault.
    """
    given = {key for key, value in where.items() if value is not None}
    grid = "/".join(_name(key, labels) for key in ("latitudes", "longitudes") if key in given)
    sources = [grid] if grid else []
    sources += [_name(key, labels) for key in ("sites", "weather_dir") if key in given]
    errors = []
    if len(sources) > 1:
        errors.append(
            f"{', '.join(sources)}: give one source of sites: a grid "
            f"({_name('latitudes', labels)}/{_name('longitudes', labels)}), a CSV of sites "
            f"({_name('sites', labels)}) or a folder of weather files ({_name('weather_dir', labels)})"
        )
    if where.get("land_only") and sources and not grid:
        errors.append(
            f"{_name('land_only', labels)}: only for a {_name('latitudes', labels)}/"
            f"{_name('longitudes', labels)} grid, not {sources[0]}"
        )
    asked = where.get("weather") or {}
    study = weather if isinstance(weather, dict) else {}
    # The source and its years each named as what gave it: the request, a field change, the study.
    by = {
        key: _name(f"weather.{key}", labels)
        if asked.get(key) is not None or f"weather.{key}" in changed
        else f"weather.{key} (the study's)"
        for key in ("source", "years")
    }
    merged = {**study, **asked}
    if merged.get("source") is not None and "weather_dir" in given:
        errors.append(
            f"{by['source']} / {_name('weather_dir', labels)}: a folder's files are its sites' "
            "weather; give one"
        )
    if merged.get("years") is not None and merged.get("source") is None:
        errors.append(
            f"{by['years']}: the years of a weather source; give one with "
            f"{_name('weather.source', labels)}"
        )
    return errors


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
        if value is None or (
            isinstance(value, (int, float)) and not isinstance(value, bool) and 0 < value <= largest
        ):
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


def request_engine(engine: str, plan) -> str:
    """The engine of every evaluation of one request (:data:`foldopt.names.ENGINES`), decided once
    where the request enters the API (:func:`foldopt.run`, :func:`foldopt.optimize`,
    :func:`foldopt.world_map`, :func:`foldopt.reproduce`): downstream every evaluation takes it,
    so one request's numbers come from one engine, the one its answer records.

    ``auto`` (:mod:`foldopt.engine.choice`) counts the request's clear-sky cases (its loads among
    them: the reference path's cost grows with them) at its fold angles and steps. A day's study
    takes the NumPy reference path; more takes the compiled kernel where numba's cache holds it
    (:func:`foldopt.engine.choice.kernel_cached`), and before its first compile only above
    :data:`foldopt.names.AUTO_NUMPY_ROW_STEPS` (a day's sweeps of the angle or the load, a few
    latitudes or days compile nothing). A weather file's or a cloud ensemble's days, a joint
    search over the tilt or the azimuth (some 10^4 designs), a study with a buffer (whose
    reference path walks the time steps in Python) and a map (``plan`` None: a year at every
    site) take the compiled kernel.

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
        # The buffer's reference path walks the time steps in Python, slow however few the curves,
        # and a periodic state takes 2 to 60 passes.
        return engine_for(engine, math.inf)
    if base.optimize is not None and set(base.optimize.vary) != {"fold_angle"}:
        # A joint search over the tilt or the azimuth evaluates some 10^4 designs of a day.
        return engine_for(engine, math.inf)
    return engine_for(engine, cases * base.fold_angles.count() * round(24 * 60 / base.step_min))
