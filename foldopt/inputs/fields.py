"""The building blocks of a study's models: checked numbers and names, the strict base model, and
what a study's files hold (:class:`FilesRead`), which the models judge and never read themselves.
"""

from __future__ import annotations

import datetime as dt
import math
import types
import typing
from dataclasses import dataclass
from functools import partial
from typing import Annotated

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    ValidationInfo,
    field_validator,
)

from foldopt.names import canonical


#: Years of a study's days, checked alike for study files, sweeps, maps and a study's ``date``:
#: well inside Python's calendar (years 1 to 9999; a year 0 or 10000 was a traceback) and pvlib's
#: solar position.
YEARS = (1901, 2099)


def year_problem(year) -> str | None:
    """Why a value cannot be a study's year.

    Parameters
    ----------
    year : object

    Returns
    -------
    str or None
        The problem, or None for a whole year of :data:`YEARS`.
    """
    if isinstance(year, bool) or not isinstance(year, int) or not YEARS[0] <= year <= YEARS[1]:
        return f"must be a whole year in [{YEARS[0]}, {YEARS[1]}]"
    return None


def _in_years(day: dt.date) -> dt.date:
    if year_problem(day.year):
        raise ValueError(f"must be a date of a year in [{YEARS[0]}, {YEARS[1]}]")
    return day


#: A study's day: a date of :data:`YEARS`.
StudyDate = Annotated[dt.date, AfterValidator(_in_years)]


def interval(lo, hi, *, lo_open=False, hi_open=False, unit=""):
    """A float constrained to an interval, whose error message states the interval.

    Parameters
    ----------
    lo, hi : float
        The bounds, in the field's unit.
    lo_open, hi_open : bool
        Whether a bound itself is outside the interval.
    unit : str
        The unit the message gives after the interval (``" deg"``).

    Returns
    -------
    typing.Annotated
        ``float`` with a validator raising ``ValueError("must be in [lo, hi] unit")`` for a value
        outside the interval or not finite.
    """
    text = f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}{unit}"

    def check(value: float) -> float:
        below = value <= lo if lo_open else value < lo
        above = value >= hi if hi_open else value > hi
        if not math.isfinite(value) or below or above:
            raise ValueError(f"must be in {text}")
        return value

    return Annotated[float, AfterValidator(check)]


def named(choices):
    """A name among ``choices``, any spelling of :func:`foldopt.names.canonical` accepted.

    Parameters
    ----------
    choices : sequence of str
        The names (a registry of :mod:`foldopt.names`).

    Returns
    -------
    typing.Annotated
        ``str`` validated into foldopt's spelling of the name.
    """
    return Annotated[str, BeforeValidator(partial(canonical, names=choices))]


@dataclass(frozen=True)
class FilesRead:
    """What :func:`foldopt.inputs.study_file.resolve_files` read of the files a study names, handed to
    the study's validation as pydantic's context: the models judge it and open no files. A study
    validated without it (built in Python, or a :meth:`foldopt.inputs.study.Study.variant`) has
    its files unread until :func:`foldopt.inputs.study_file.with_files` reads them.

    Parameters
    ----------
    weather_site : dict, optional
        The site in the weather file's header (:func:`foldopt.inputs.weather.reader.weather_site`).
    weather_problem : str, optional
        Why the weather file cannot be used: one line naming the file (and the line, the field).
    weather_missing : bool
        Whether the weather file does not exist, or is no file foldopt reads (a folder, a device,
        a FIFO, one over the size limit).
    weather_step_min : float, optional
        A measured weather file's step [min].
    weather_dates : tuple of str, optional
        A measured weather file's whole days (ISO dates), less those with a daylight gap too long
        to fill.
    profile_daily : dict, optional
        The load profile file's day: clock times ``HH:MM`` to loads [W].
    profile_problem : str, optional
        Why the load profile file cannot be read: one line naming the file and the line.
    horizon_points : list, optional
        The site's horizon file's (azimuth, elevation) points [deg].
    horizon_problem : str, optional
        Why the horizon file cannot be read: one line naming the file.
    """

    weather_site: dict | None = None
    weather_problem: str | None = None
    weather_missing: bool = False
    weather_step_min: float | None = None
    weather_dates: tuple | None = None
    profile_daily: dict | None = None
    profile_problem: str | None = None
    horizon_points: list | None = None
    horizon_problem: str | None = None

    @staticmethod
    def given(info: ValidationInfo) -> FilesRead | None:
        """The files read for a validation, or None where it was given none.

        Parameters
        ----------
        info : pydantic.ValidationInfo

        Returns
        -------
        FilesRead or None
        """
        return info.context if isinstance(info.context, FilesRead) else None


class StrictModel(BaseModel):
    """A frozen model that refuses unknown fields, and ``true``/``false`` where a number is
    expected: the base of a study and its parts.

    pydantic's lax mode reads a boolean as 1 or 0 for a number field, so ``capacity_wh: true`` (a
    slip in YAML, ``--set storage.capacity_wh=true``) would run a 1 Wh buffer without a word.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    @field_validator("*", mode="before")
    @classmethod
    def _no_boolean_for_number(cls, value, info: ValidationInfo):
        if _holds_boolean(value) and _numeric(cls.model_fields[info.field_name].annotation):
            raise ValueError("must be a number, not true or false")
        return value


def _holds_boolean(value) -> bool:
    """Whether a value is a boolean, or a list (of lists) holding one."""
    if isinstance(value, (list, tuple)):
        return any(_holds_boolean(item) for item in value)
    return isinstance(value, bool)


def _numeric(annotation) -> bool:
    """Whether a field's type takes numbers (or lists of them) and no boolean."""
    members = _union(annotation)
    if bool in members:
        return False
    return any(
        member in (int, float)
        or (
            typing.get_origin(member) in (list, tuple)
            and any(_numeric(item) for item in typing.get_args(member) if item is not Ellipsis)
        )
        for member in members
    )


def _unwrapped(annotation):
    return (
        _unwrapped(typing.get_args(annotation)[0])
        if typing.get_origin(annotation) is Annotated
        else annotation
    )


def _union(annotation) -> tuple:
    annotation = _unwrapped(annotation)
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        return tuple(_unwrapped(member) for member in typing.get_args(annotation))
    return (annotation,)


def _list_depth(annotation) -> int:
    """How deep lists nest in a type: 2 for ``list[tuple[float, float]] | None``, 0 for a number."""
    depths = [
        1
        + max(
            (_list_depth(item) for item in typing.get_args(member) if item is not Ellipsis),
            default=0,
        )
        for member in _union(annotation)
        if typing.get_origin(member) in (list, tuple)
    ]
    return max(depths, default=0)


def _walk(model: type[BaseModel], prefix: str = ""):
    """Every field of a model and of its sections, parents first: ``(dotted path, field, the
    section models its type holds)``."""
    for name, field in model.model_fields.items():
        path = f"{prefix}{name}"
        sections = [
            member
            for member in _union(field.annotation)
            if isinstance(member, type) and issubclass(member, BaseModel)
        ]
        yield path, field, sections
        for section in sections:
            yield from _walk(section, f"{path}.")


def list_valued_fields(model: type[BaseModel], prefix: str = "") -> dict[str, int]:
    """The dotted paths of a model's fields whose value is itself a list, with the lists' depth.

    A study's list is a sweep axis (:mod:`foldopt.inputs.plan`) except in these fields, where a
    list as deep as the field's type is the value (``site.horizon: [[0, 10], [180, 20]]``,
    ``objective.months: [6, 7, 8]``) and only a list of such values is an axis. A model that takes
    a bare list as the shorthand of one of its fields names it in ``LIST_SHORTHAND``.

    Parameters
    ----------
    model : type of pydantic.BaseModel
    prefix : str
        The model's own path, with its trailing dot.

    Returns
    -------
    dict of str to int
    """
    walked = list(_walk(model, prefix))
    depths = {path: _list_depth(field.annotation) for path, field, _ in walked}
    depths = {path: depth for path, depth in depths.items() if depth}
    for path, _, sections in walked:
        for section in sections:
            shorthand = getattr(section, "LIST_SHORTHAND", None)
            if shorthand is not None:
                depths[path] = depths[f"{path}.{shorthand}"]
    return depths


def field_paths(model: type[BaseModel], prefix: str = "") -> tuple[str, ...]:
    """The dotted paths of a model's fields, its sections' fields included.

    Parameters
    ----------
    model : type of pydantic.BaseModel
    prefix : str
        The model's own path, with its trailing dot.

    Returns
    -------
    tuple of str
        In the order the models declare them (``site``, ``site.name``, ``site.latitude``...).
    """
    return tuple(dict.fromkeys(path for path, _, _ in _walk(model, prefix)))


def list_depth(value) -> int:
    """How deep lists nest in a value: 2 for ``[[0, 10], [180, 20]]``, 0 for a number."""
    return (
        1 + list_depth(value[0])
        if isinstance(value, list) and value
        else int(isinstance(value, list))
    )
