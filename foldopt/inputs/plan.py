"""Plans: a study with sweep axes, and the values an axis takes.

Any field of a study may hold a list of values or a numeric range ``start:stop:step``
(:func:`parse_range`, :func:`parse_values`), and ``date`` a date range, ``year`` or
``equinoxes-solstices`` (:func:`parse_dates`); each is an axis of a :class:`Plan`, whose cases are
the product of its axes' values. :func:`make_plan` validates every value of every axis, collapses
the faults to one line per field and problem, and refuses a plan larger than the limits
(:data:`MAX_CASES`, :data:`MAX_EVALUATIONS`...) before any work.
"""

from __future__ import annotations

import datetime as dt
import functools
import itertools
import math
import re
import dataclasses
from dataclasses import dataclass
from pathlib import Path

from pydantic import ValidationError

from foldopt.errors import ConfigError
from foldopt.inputs.fields import field_paths, list_depth, list_valued_fields, year_problem
from foldopt.inputs.study_file import read_study, resolve_files
from foldopt.inputs.reading import MAX_AXIS_VALUES, size_limit
from foldopt.inputs.weather_files import (
    weather_defaults,
    with_fetched_horizon,
    with_fetched_weather,
)
from foldopt.inputs.policy import set_path
from foldopt.inputs.study import Study, format_error

DATE_KEYWORDS = ("year", "equinoxes-solstices")
#: Fields that label a study rather than design it: a list of them is no sweep.
UNSWEPT = ("name", "description")
#: Axes whose parser already made each value what the study's field holds (a date), and whose
#: value no other field's validation reads: the first case validates the rest of the study, so a
#: study per value would validate nothing more, and a measured file's days are thousands.
_PARSED_AXES = ("date",)
_LIST_VALUED = list_valued_fields(Study)
#: Every field of a study: a list under any other key is no axis (the validation names the key).
_FIELDS = frozenset(field_paths(Study))

#: Cases of a plan: one row of results.csv per case and design.
MAX_CASES = size_limit("MAX_CASES", 200_000)
#: Site-days x fold angles x time steps of a plan: the default is a few minutes of work at most
#: (docs/performance.rst gives what one costs).
MAX_EVALUATIONS = size_limit("MAX_EVALUATIONS", 20_000_000_000)
#: Days x fold angles x loads of one annual group (a fixed angle chosen over the days), held at
#: once: 8 bytes each.
MAX_ANNUAL_CELLS = size_limit("MAX_ANNUAL_CELLS", 100_000_000)
_RANGE = re.compile(r"^\s*([^:\s]+)\s*:\s*([^:\s]+)\s*:\s*([^:\s]+)\s*$")
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_NUMERIC_RANGE = re.compile(rf"^\s*{_NUMBER}\s*:\s*{_NUMBER}\s*:\s*{_NUMBER}\s*$")


def range_parts(text: str) -> tuple[float, float, float]:
    """The three numbers of ``"start:stop:step"``, unchecked; ValueError for any other text."""
    match = _RANGE.match(str(text))
    if not match:
        raise ValueError("expected start:stop:step")
    try:
        return tuple(float(part) for part in match.groups())
    except ValueError:
        raise ValueError("expected numbers in start:stop:step") from None


def parse_range(text: str) -> list[float]:
    """The values of a range.

    Parameters
    ----------
    text : str
        ``"start:stop:step"``, numbers with a positive step.

    Returns
    -------
    list of float
        From start to stop inclusive (stop kept if on the grid), rounded to 12 decimals.

    Raises
    ------
    ValueError
        For a malformed or empty range, or more than :data:`MAX_AXIS_VALUES` values.
    """
    start, stop, step = range_parts(text)
    if step <= 0 or not all(map(math.isfinite, (start, stop, step))):
        raise ValueError("step must be a positive number")
    if stop < start:
        raise ValueError("empty range: stop is below start")
    count = math.floor((stop - start) / step + 1e-9) + 1
    if count > MAX_AXIS_VALUES:
        raise ValueError(
            f"{count:,} values; at most {MAX_AXIS_VALUES:,} per axis "
            "(FOLDOPT_MAX_AXIS_VALUES raises it)"
        )
    return [round(start + i * step, 12) for i in range(count)]


def parse_values(text: str, numeric: bool = True):
    """The one parser of a value, a range or a list, as typed on the command line.

    ``"5"`` is a value, ``"0:60:10"`` a range (inclusive, :func:`parse_range`) and ``"0,30,60"`` a
    list; with ``numeric=False`` (dates) the items stay text and a range or keyword (``year``)
    is left to :func:`parse_dates`.

    Parameters
    ----------
    text : str
    numeric : bool
        Whether the items are numbers.

    Returns
    -------
    float, str or list
        A value, or a list for a range or a list.

    Raises
    ------
    ValueError
        For an empty text or item, a malformed range, a value that is not a number, or more than
        :data:`MAX_AXIS_VALUES` values.
    """
    text = str(text).strip()
    if not text:
        raise ValueError("no value; give a value, a range start:stop:step or a list a,b,c")
    items = [item.strip() for item in text.split(",")]
    if any(not item for item in items):
        raise ValueError("an empty item; a list is a,b,c")
    if len(items) > MAX_AXIS_VALUES:
        raise ValueError(
            f"a list of {len(items):,} values; at most {MAX_AXIS_VALUES:,} per axis "
            "(FOLDOPT_MAX_AXIS_VALUES raises it)"
        )
    if not numeric:
        return items if len(items) > 1 else items[0]
    if len(items) == 1 and ":" in text:
        return parse_range(text)
    try:
        values = [float(item) for item in items]
    except ValueError:
        raise ValueError("expected a number, a range start:stop:step or a list a,b,c") from None
    if not all(math.isfinite(value) for value in values):
        raise ValueError("values must be finite numbers")
    return values if len(values) > 1 else values[0]


def parse_dates(spec, year: int) -> list[dt.date]:
    """The dates of a study's ``date`` axis.

    Parameters
    ----------
    spec : object
        A date (or its text, or a day of ``year``), a list of them, ``"start:stop:step"`` (dates
        or days of ``year``, a step in days), ``year`` or ``equinoxes-solstices`` (20 March,
        21 June, 23 September, 21 December of ``year``).
    year : int
        The year of days of year and keywords.

    Returns
    -------
    list of datetime.date

    Raises
    ------
    ValueError
        For a value that is no date or day of ``year``, an empty list or an empty range.
    """

    def one(value):
        if isinstance(value, dt.date):
            return value
        if isinstance(value, int) and not isinstance(value, bool):
            if not 1 <= value <= (366 if _leap(year) else 365):
                raise ValueError(f"day of year {value} is outside {year}")
            return dt.date(year, 1, 1) + dt.timedelta(days=value - 1)
        try:
            return dt.date.fromisoformat(str(value))
        except ValueError:
            raise ValueError(f"{value!r} is not a date (YYYY-MM-DD) or a day of year") from None

    if isinstance(spec, list):
        if not spec:
            raise ValueError("empty list of dates")
        return [one(item) for item in spec]
    if spec == "year":
        days = 366 if _leap(year) else 365
        return [dt.date(year, 1, 1) + dt.timedelta(days=i) for i in range(days)]
    if spec == "equinoxes-solstices":
        return [
            dt.date(year, 3, 20),
            dt.date(year, 6, 21),
            dt.date(year, 9, 23),
            dt.date(year, 12, 21),
        ]
    match = _RANGE.match(str(spec)) if isinstance(spec, str) else None
    if match:
        start, stop, step = match.groups()
        if not step.isdigit() or int(step) < 1:
            raise ValueError(f"the step of a date range is a whole number of days, got {step!r}")
        first, last = (
            one(int(start) if start.isdigit() else start),
            one(int(stop) if stop.isdigit() else stop),
        )
        if last < first:
            raise ValueError("empty range: stop is before start")
        return [first + dt.timedelta(days=d) for d in range(0, (last - first).days + 1, int(step))]
    if isinstance(spec, str) and ":" in spec:
        parts = spec.split(":")
        example = ":".join([*parts[:2], "1"]) if len(parts) == 2 else "2025-12-25:2026-01-05:1"
        raise ValueError(f"a range of dates is start:stop:step, the step in days (e.g. {example})")
    return [one(spec)]


def _leap(year: int) -> bool:
    return year % 4 == 0 and (year % 100 != 0 or year % 400 == 0)


#: Validated studies a plan keeps (the first ones made; beyond, a case is validated when asked).
KEPT_STUDIES = 4096


@dataclass(frozen=True)
class Plan:
    """A study and its sweep axes; the cases are the product of the axes' values.

    A plan is made by :func:`make_plan` (the front door's validation,
    :func:`foldopt.studies.request.make_request`), which validates every axis value; the studies
    it validated are kept, so a case asked for again (the base above all) is not validated again,
    and the files the study names are read once for all its cases.

    Parameters
    ----------
    data : dict
        The study's fields, each axis at its listed values (as a study file holds it).
    axes : tuple
        ``(path, values)`` pairs: each dotted field path (``site.latitude``, ``p_load``,
        ``date``...) with the tuple of its values.
    """

    data: dict
    axes: tuple
    _studies: dict = dataclasses.field(default_factory=dict, repr=False, compare=False)
    _files: dict = dataclasses.field(default_factory=dict, repr=False, compare=False)

    @classmethod
    def of(cls, study: Study) -> Plan:
        """A validated study (its files read) as a plan of one case, kept as it is.

        Parameters
        ----------
        study : Study

        Returns
        -------
        Plan
        """
        plan = cls(study.data(), ())
        plan._studies[()] = study
        return plan

    @functools.cached_property
    def base(self) -> Study:
        """The study with every axis at its first value (:meth:`study`)."""
        return self.study({path: values[0] for path, values in self.axes})

    @property
    def n_cases(self) -> int:
        """The number of cases: the product of the axes' lengths."""
        return math.prod(len(values) for _, values in self.axes)

    def study(self, choice: dict) -> Study:
        """One case's study, its files read (:func:`foldopt.inputs.study_file.resolve_files`).

        Parameters
        ----------
        choice : dict
            Dotted field paths to their values in this case; an axis it leaves out is at its
            first value.

        Returns
        -------
        Study

        Raises
        ------
        pydantic.ValidationError
        """
        key = tuple(sorted((path, repr(value)) for path, value in choice.items()))
        if key in self._studies:
            return self._studies[key]
        data = self._skeleton
        for path, value in choice.items():
            data = set_path(data, path, value)
        study = Study.model_validate(data, context=self._read(data))
        if len(self._studies) < KEPT_STUDIES:
            self._studies[key] = study
        return study

    @functools.cached_property
    def _skeleton(self) -> dict:
        """The study's fields with every axis at its first value: what a case's data is copied
        from, so that a case copies one value of each axis, not every value (a measured file's
        days are thousands, and a copy of them per case made a plan quadratic in its days)."""
        data = self.data
        for path, values in self.axes:
            data = set_path(data, path, values[0])
        return data

    def _read(self, data: dict):
        """What the files a case names hold, read once for every case that names the same."""
        key = repr([data.get(name) for name in ("weather", "load_profile", "site")])
        if key not in self._files:
            self._files[key] = resolve_files(data)
        return self._files[key]

    def cases(self):
        """Every case of the plan.

        Yields
        ------
        choice : dict
            Each axis' path to its value in the case, first axis slowest.
        study : Study
        """
        paths = [path for path, _ in self.axes]
        for values in itertools.product(*(values for _, values in self.axes)):
            choice = dict(zip(paths, values, strict=True))
            yield choice, self.study(choice)


def _listed_leaves(data: dict, prefix: str = ""):
    """Dotted paths holding a list (not a list-valued field's own value,
    :func:`~foldopt.inputs.fields.list_valued_fields`), a numeric range or a date keyword."""
    for key, value in data.items():
        path = f"{prefix}{key}"
        if path == "date" and (
            isinstance(value, list)
            or value in DATE_KEYWORDS
            or (isinstance(value, str) and ":" in value)
        ):
            yield path, value
        elif isinstance(value, list) and list_depth(value) == _LIST_VALUED.get(path):
            continue
        elif path not in _FIELDS and path not in UNSWEPT:
            continue
        elif isinstance(value, list) or (isinstance(value, str) and _NUMERIC_RANGE.match(value)):
            yield path, value
        elif isinstance(value, dict):
            yield from _listed_leaves(value, f"{path}.")


def check_distinct(values, noun: str = "value", label=None) -> list:
    """``values`` as a list, refused where one is given twice: a case computed twice is work done
    twice, and rows with the same key break the tables that index by it (a map's ``map.nc``).

    Parameters
    ----------
    values : sequence
        An axis's values (numbers, dates, text or mappings such as sites).
    noun : str, default 'value'
        What the message calls a value.
    label : callable, optional
        ``label(value)``: how the message shows a value; default the value itself.

    Returns
    -------
    list

    Raises
    ------
    ValueError
        Naming the first value given twice and where.
    """
    values, first = list(values), {}
    for index, value in enumerate(values):
        key = repr(sorted(value.items())) if isinstance(value, dict) else value
        try:
            hash(key)
        except TypeError:  # a list as one value
            key = repr(key)
        if key in first:
            shown = (
                label(value)
                if label
                else f"{value:g}"
                if isinstance(value, float)
                else (f"the same {noun}" if isinstance(value, (dict, list)) else str(value))
            )
            raise ValueError(
                f"{shown} is given twice ({noun}s {first[key] + 1} and {index + 1}); give each "
                f"{noun} once"
            )
        first[key] = index
    return values


def _value_text(spec) -> str:
    """An axis's value as a message shows it: short, as typed."""
    text = repr(spec)
    return text if len(text) <= 60 else text[:57] + "..."


def _axis_values(path: str, spec, year: int) -> list:
    if path == "date":
        return check_distinct(parse_dates(spec, year))
    if isinstance(spec, list):
        if not spec:
            raise ValueError("empty list")
        if len(spec) > MAX_AXIS_VALUES:
            raise ValueError(
                f"a list of {len(spec):,} values; at most {MAX_AXIS_VALUES:,} per axis "
                "(FOLDOPT_MAX_AXIS_VALUES raises it)"
            )
        return check_distinct(spec)
    if isinstance(spec, str) and _RANGE.match(spec):
        return parse_range(spec)
    return [spec]


def make_plan(data, lines: dict | None = None) -> Plan:
    """Validate a study with optional sweep axes.

    Any field but :data:`UNSWEPT` may hold a list (``site``: a list of sites) or a numeric range
    ``"start:stop:step"``; ``date`` also takes a date range, ``year`` or ``equinoxes-solstices``
    (of ``year``, default 2025), and is the whole ``year`` by default with a weather file. The
    ``sweep:`` section maps dotted field paths to lists or ranges. Each becomes an axis.

    Parameters
    ----------
    data : dict
        The study's fields, as a study file holds them (``year`` and ``sweep`` included).
    lines : dict, optional
        Key paths (tuples of str) to YAML line numbers, added to the messages.

    Returns
    -------
    Plan

    Raises
    ------
    foldopt.ConfigError
        With every fault, one line per field and problem, or for a plan beyond the size limits.
    """
    lines = lines or {}
    if not isinstance(data, dict):
        raise ConfigError([f"study: expected a mapping of fields, got {type(data).__name__}"])
    # A weather or horizon source is fetched (or taken from the cache) once, here: then it is a
    # file.
    data = dict(with_fetched_horizon(with_fetched_weather(data)))
    if data.get("weather") is not None and ("date" not in data or "step_min" not in data):
        # An hourly file is a year; a measured file its own days at its own step.
        data = {**weather_defaults(data), **data}
    errors: list[str] = []
    year = data.pop("year", 2025)
    if year_problem(year):
        errors.append(_at(lines, ("year",), f"year = {year!r}: {year_problem(year)}"))
        year = 2025
    sweep = data.pop("sweep", None) or {}
    if not isinstance(sweep, dict):
        errors.append(
            _at(lines, ("sweep",), "sweep: expected a mapping of field paths to lists or ranges")
        )
        sweep = {}
    # Each axis: dotted field path -> (name in messages, key path in the YAML, its spec).
    specs = {path: (path, tuple(path.split(".")), value) for path, value in _listed_leaves(data)}
    for path, value in sweep.items():
        specs[str(path)] = (f"sweep.{path}", ("sweep", str(path)), value)
    axes = []
    for path, (source, yaml_path, spec) in specs.items():
        if path in UNSWEPT:
            errors.append(
                _at(
                    lines,
                    yaml_path,
                    f"{source}: the study's {path} labels its results, it is not "
                    f"sweepable; give one {path}",
                )
            )
            continue
        try:
            values = _axis_values(path, spec, year)
        except ValueError as error:
            errors.append(_at(lines, yaml_path, f"{source} = {_value_text(spec)}: {error}"))
            continue
        axes.append((path, tuple(values)))
    if errors:
        raise ConfigError(errors)

    plan = Plan(data, tuple(axes))
    weather = data.get("weather")
    ensemble = isinstance(weather, dict) and weather.get("members") is not None
    if data.get("objective") is not None and "date" not in dict(axes) and not ensemble:
        # Said beside the objective's own faults (a misspelt statistic), not instead of them.
        errors.append(
            _at(
                lines,
                ("objective",),
                "objective: one fold angle for several days needs several "
                "dates (a date range, 'year', or a weather file)",
            )
        )
    if plan.n_cases > MAX_CASES:
        raise ConfigError(
            [
                f"sweep: {plan.n_cases:,} cases; the limit is {MAX_CASES:,} (FOLDOPT_MAX_CASES raises it)"
            ]
        )
    first = {path: values[0] for path, values in axes}
    labels = {path: (f"{specs[path][0]}[0]", specs[path][1] + (0,)) for path in first}
    errors += _validation_errors(plan, first, lines, labels)
    for path, values in axes:
        if path in _PARSED_AXES:
            continue
        source, yaml_path, _ = specs[path]
        for index, value in enumerate(values[1:], start=1):
            where = {**labels, path: (f"{source}[{index}]", yaml_path + (index,))}
            errors += _validation_errors(plan, {**first, path: value}, lines, where)
    if errors:
        raise ConfigError(_collapse(list(dict.fromkeys(errors))))
    _check_size(plan)
    return plan


def _check_size(plan: Plan) -> None:
    """Refuse a plan whose work or memory would exceed the limits, before any work."""
    axes = dict(plan.axes)
    base = plan.base
    angles = base.fold_angles.count()
    steps = round(24 * 60 / base.step_min)
    loads = len(axes.get("p_load", (None,)))
    site_days = plan.n_cases // loads
    evaluations = site_days * angles * steps
    if evaluations > MAX_EVALUATIONS:
        raise ConfigError(
            [
                f"study: {site_days:,} site-days x {angles} fold angles x {steps:,} steps = "
                f"{evaluations:.2g} evaluations; the limit is {MAX_EVALUATIONS:.2g} (a coarser "
                "fold_angles or step_min, fewer cases, or FOLDOPT_MAX_EVALUATIONS)"
            ]
        )
    if base.objective is not None and "date" in axes:
        cells = len(axes["date"]) * angles * loads
        if cells > MAX_ANNUAL_CELLS:
            raise ConfigError(
                [
                    f"objective: {len(axes['date'])} days x {angles} fold angles x {loads} loads = "
                    f"{cells:.2g} values held at once; the limit is {MAX_ANNUAL_CELLS:.2g} (fewer loads "
                    "or angles, or FOLDOPT_MAX_ANNUAL_CELLS)"
                ]
            )


_INDEXED = re.compile(r"^(?P<field>[^\[\s]+)\[(?P<index>\d+)\] = (?P<value>.*?): (?P<problem>.*)$")


def _collapse(errors: list[str]) -> list[str]:
    """One line per field and problem: ``p_load[0,2] = -1.0, 0.0: must be ...`` (values cut at 5)."""
    groups: dict[tuple, list] = {}
    for error in errors:
        match = _INDEXED.match(error)
        key = (match["field"], match["problem"]) if match else (error, None)
        groups.setdefault(key, []).append(match)
    lines = []
    for (field, problem), matches in groups.items():
        if problem is None:
            lines.append(field)
            continue
        indices = ",".join(m["index"] for m in matches)
        values = ", ".join(m["value"] for m in matches[:5]) + (", ..." if len(matches) > 5 else "")
        lines.append(f"{field}[{indices}] = {values}: {problem}")
    return lines


def _validation_errors(plan: Plan, choice: dict, lines: dict, where: dict) -> list[str]:
    try:
        plan.study(choice)
    except ValidationError as error:
        messages = []
        for item in error.errors():
            for message in format_error(item):
                loc = tuple(str(part) for part in item["loc"])
                for path, (label, yaml_path) in where.items():
                    dotted = ".".join(loc)
                    if dotted == path or dotted.startswith(path + "."):
                        # circuit[1].switch_resistance: the case's value, then the field in it
                        message = message.replace(dotted, label + dotted[len(path) :], 1)
                        loc = tuple(str(part) for part in yaml_path) + loc[len(path.split(".")) :]
                        break
                messages.append(_at(lines, loc, message))
        return messages
    return []


def _at(lines: dict, loc: tuple, message: str) -> str:
    """Append the YAML line of the longest known prefix of ``loc``."""
    for end in range(len(loc), 0, -1):
        line = lines.get(tuple(str(part) for part in loc[:end]))
        if line is not None:
            return f"{message} (line {line})"
    return message


def load_plan(path: Path | str) -> Plan:
    """Read and validate a YAML study, with any sweep axes.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    Plan

    Raises
    ------
    foldopt.ConfigError
        With the YAML line of each fault.
    """
    return make_plan(*read_study(path))
