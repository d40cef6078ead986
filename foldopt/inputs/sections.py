"""The parts of a study, as pydantic models: its site, panel, tracker, weather file, objective, load
profile, fold-angle grid and near-optimal tolerance (:class:`foldopt.inputs.study.Study` holds them).

Every number is checked against its interval, and the message states the interval and its unit
(:func:`interval`); every name is checked against its registry in :mod:`foldopt.names`, any
spelling of :func:`foldopt.names.canonical` accepted (:func:`named`). The models open no files:
what a study's files hold comes from :func:`foldopt.inputs.study_file.resolve_files`, as a
:class:`FilesRead` handed to the validation.
"""

from __future__ import annotations

import datetime as dt
import math
import re
import zoneinfo
from typing import Annotated

from pydantic import AfterValidator, Field, ValidationInfo, field_validator, model_validator

from foldopt import names
from foldopt.inputs.fields import FilesRead, StrictModel, interval, named
from foldopt.inputs.horizon_section import Horizon
from foldopt.inputs.load_profile import hourly_steps, profile_steps
from foldopt.inputs.optimize_section import grid_points
from foldopt.inputs.reading import MAX_AXIS_VALUES
from foldopt.names import ALEXANDRU_STEP_OFFSETS_H, FLAT_FOLD_ANGLE

_OFFSET = re.compile(r"^(?:UTC)?([+-])(\d{1,2})(?::?(\d{2}))?$")


def parse_timezone(name: str) -> dt.tzinfo:
    """A time zone from its IANA name or a fixed offset.

    Parameters
    ----------
    name : str
        An IANA name (``America/Los_Angeles``) or an offset (``UTC-08:00``, ``+5:30``).

    Returns
    -------
    datetime.tzinfo

    Raises
    ------
    ValueError
        For an unknown name or an offset beyond +/-14:00.
    """
    match = _OFFSET.match(name.strip())
    if match:
        sign, hours, minutes = match.groups()
        offset = dt.timedelta(hours=int(hours), minutes=int(minutes or 0))
        if offset > dt.timedelta(hours=14):
            raise ValueError(f"offset {name!r} is beyond +/-14:00")
        return dt.timezone(offset if sign == "+" else -offset)
    try:
        return zoneinfo.ZoneInfo(name)
    except (zoneinfo.ZoneInfoNotFoundError, ValueError):
        raise ValueError(
            f"unknown time zone {name!r}; use an IANA name such as 'Europe/Berlin' or an offset such as 'UTC-08:00'"
        ) from None


def _check_timezone(name: str | None) -> str | None:
    if name is not None:
        parse_timezone(name)
    return name


class Site(StrictModel):
    """Where a study's panel stands.

    Parameters
    ----------
    name : str, optional
    latitude : float
        [deg] in [-90, 90], north positive.
    longitude : float
        [deg] in [-180, 180], east positive.
    altitude : float
        [m] in [-500, 9000]; default 0.
    timezone : str, optional
        An IANA name or a UTC offset (:func:`parse_timezone`); default the longitude's standard
        offset (:func:`standard_timezone`, decided by the study).
    horizon : Horizon, optional
        The horizon line around the panel; default none (an open plain).
    """

    name: str | None = None
    latitude: interval(-90, 90, unit=" deg")
    longitude: interval(-180, 180, unit=" deg")
    altitude: interval(-500, 9000, unit=" m") = 0.0
    timezone: Annotated[str | None, AfterValidator(_check_timezone)] = Field(
        None,
        validate_default=True,
        description="IANA name or UTC offset; default: the longitude's standard offset",
    )
    horizon: Horizon | None = Field(
        None, description="(azimuth, elevation) points or a file; default an open plain"
    )

    @field_validator("timezone", mode="after")
    @classmethod
    def _standard_by_default(cls, timezone, info: ValidationInfo):
        """The longitude's standard offset where none is given: decided, not given (the site's
        fields set say so, and a study's data leave it out)."""
        longitude = info.data.get("longitude")
        return (
            standard_timezone(longitude) if timezone is None and longitude is not None else timezone
        )


def standard_timezone(longitude: float) -> str:
    """The standard offset of a longitude: a site's time zone where none is given.

    Parameters
    ----------
    longitude : float
        [deg], east positive.

    Returns
    -------
    str
        ``UTC+hh:00`` or ``UTC-hh:00``, the nearest whole hour to ``longitude / 15``.
    """
    hours = round(longitude / 15.0)
    return f"UTC{'+' if hours >= 0 else '-'}{abs(hours):02d}:00"


class Panel(StrictModel):
    """The panel: its size, its efficiency and its orientation when flat (the twofold panel's base).

    Parameters
    ----------
    area : float
        [m^2] in (0, 1000].
    efficiency : float
        [-] in (0, 1]; default 0.2.
    tilt : float, optional
        [deg] in [0, 90]; default |latitude|.
    azimuth : float, optional
        [deg] in [0, 360), clockwise from north; default facing the equator.
    planes : tuple of two (surface_tilt, surface_azimuth) pairs, optional
        [deg]: the two halves of an existing array as they stand, each tilt in [0, 90] and
        azimuth in [0, 360); the study finds the base orientation and fold angle that make them
        (:func:`planes_panel`) and evaluates that design beside the best fold.
    """

    area: interval(0, 1000, lo_open=True, unit=" m^2")
    efficiency: interval(0, 1, lo_open=True) = 0.2
    tilt: interval(0, 90, unit=" deg") | None = Field(None, description="default |latitude|")
    azimuth: interval(0, 360, hi_open=True, unit=" deg") | None = Field(
        None, description="default: facing the equator"
    )
    planes: tuple[tuple[float, float], tuple[float, float]] | None = Field(
        None, description="the two halves' [surface_tilt, surface_azimuth] as built [deg]"
    )

    @field_validator("planes", mode="before")
    @classmethod
    def _two_planes(cls, planes):
        """Two [tilt, azimuth] pairs of numbers, each in its range: one line for any fault."""
        if planes is None:
            return planes
        pairs = planes if isinstance(planes, (list, tuple)) else ()
        numbers = [
            pair
            for pair in pairs
            if isinstance(pair, (list, tuple))
            and len(pair) == 2
            and all(
                isinstance(value, (int, float))
                and not isinstance(value, bool)
                and math.isfinite(value)
                for value in pair
            )
        ]
        if len(pairs) != 2 or len(numbers) != 2:
            raise ValueError(
                "expected two [surface_tilt, surface_azimuth] pairs [deg], e.g. [[9, 14], [9, 194]]"
            )
        for index, (tilt, azimuth) in enumerate(numbers, start=1):
            if not 0.0 <= tilt <= 90.0:
                raise ValueError(f"plane {index}'s tilt {tilt:g} must be in [0, 90] deg")
            if not 0.0 <= azimuth < 360.0:
                raise ValueError(f"plane {index}'s azimuth {azimuth:g} must be in [0, 360) deg")
        return tuple((float(tilt), float(azimuth)) for tilt, azimuth in numbers)


#: How near [deg] a twofold panel must make the given planes (:func:`planes_panel`): the angle
#: between each given plane's normal and the half made for it.
PLANES_TOLERANCE_DEG = 0.1


def planes_panel(
    planes, geometry: str, tilt=None, azimuth=None
) -> tuple[float, float, float, bool]:
    """The twofold panel of a geometry that makes two given planes
    (:func:`foldopt.physics.geometry.fold_from_planes`), within :data:`PLANES_TOLERANCE_DEG`.

    Parameters
    ----------
    planes : tuple of two (surface_tilt, surface_azimuth) pairs
        [deg].
    geometry : str
        One of :data:`foldopt.names.GEOMETRIES`.
    tilt, azimuth : float, optional
        A base orientation given beside the planes [deg]: kept where the panel it makes at the
        planes' fold angle makes them too (a ridge tent's two ends), refused otherwise.

    Returns
    -------
    surface_tilt, surface_azimuth, fold_angle : float
        The flat panel's orientation and the fold angle [deg].
    first_east : bool
        Whether the first plane is the east half.

    Raises
    ------
    ValueError
        One line naming ``panel.planes``: no twofold panel of the geometry makes the planes (and
        which geometry would), or the given tilt or azimuth is not the planes' base.
    """
    from foldopt.physics.geometry import fold_from_planes, planes_residual

    flat = [value for plane in planes for value in plane]
    found = {name: fold_from_planes(*flat, geometry=name) for name in names.GEOMETRIES}
    panel = {key: float(value) for key, value in found[geometry].items()}
    made = panel["residual"] <= PLANES_TOLERANCE_DEG
    if not made:
        tilts = f"tilts {flat[0]:g} and {flat[2]:g} deg"
        other = next(
            (
                name
                for name, other in found.items()
                if name != geometry and float(other["residual"]) <= PLANES_TOLERANCE_DEG
            ),
            None,
        )
        if abs(flat[0] - flat[2]) > PLANES_TOLERANCE_DEG:
            why = f"{tilts} differ: both halves of a twofold panel have one tilt"
        elif panel["fold_angle"] == 0.0 and geometry == "azimuth-split":
            why = "azimuths 180 deg apart would be an azimuth-split panel folded shut (0 deg)"
        else:
            why = "the halves face opposite ways, a panel folded shut (0 deg)"
        hint = ""
        if other is not None:
            by = {key: float(value) for key, value in found[other].items()}
            hint = (
                f"; the {other} geometry makes them (base tilt {by['surface_tilt']:.4g}, azimuth "
                f"{by['surface_azimuth']:.4g}, fold {by['fold_angle']:.4g} deg)"
            )
        raise ValueError(
            f"panel.planes: no {geometry} panel makes them within {PLANES_TOLERANCE_DEG:g} deg: "
            f"{why}{hint}"
        )

    def made(orientation: dict):
        """(residual [deg], first_east) of the planes' fold at a base orientation."""
        return planes_residual(
            flat, panel["fold_angle"], orientation["tilt"], orientation["azimuth"], geometry
        )

    base = {"tilt": panel["surface_tilt"], "azimuth": panel["surface_azimuth"]}
    keys = {
        key: value for key, value in (("tilt", tilt), ("azimuth", azimuth)) if value is not None
    }
    given = {**base, **keys}
    residual, first_east = made(given)
    if not float(residual) <= PLANES_TOLERANCE_DEG:
        # Name the one that misses alone, where one does (a tent's level tilt given is no fault).
        alone = {
            key: value
            for key, value in keys.items()
            if len(keys) == 2 and not float(made({**base, key: value})[0]) <= PLANES_TOLERANCE_DEG
        }
        keys = alone or keys
        named = " and ".join(f"{key} {value:g} deg" for key, value in keys.items())
        raise ValueError(
            f"panel.planes: the planes are a {geometry} panel of base tilt "
            f"{panel['surface_tilt']:.4g}, azimuth {panel['surface_azimuth']:.4g} deg folded to "
            f"{panel['fold_angle']:.4g} deg, not of the given {named}; leave the "
            f"{' and '.join(keys)} out"
        )
    return float(given["tilt"]), float(given["azimuth"]), panel["fold_angle"], bool(first_east)


def default_orientation(latitude: float) -> tuple[float, float]:
    """The panel's orientation where a study gives none: facing the equator, tilted by |latitude|.

    Parameters
    ----------
    latitude : float
        Site latitude [deg north].

    Returns
    -------
    surface_tilt, surface_azimuth : float
        [deg]; azimuth 180 on the northern hemisphere (and the equator), 0 on the southern.

    Examples
    --------
    >>> default_orientation(-33.9)
    (33.9, 0.0)
    """
    return abs(latitude), 180.0 if latitude >= 0 else 0.0


class Tracker(StrictModel):
    """The tracker compared against, and the energy it spends (see :mod:`foldopt.physics.trackers`).

    Each model reads some of the options (:data:`foldopt.physics.trackers.TRACKER_MODELS`); an
    option of another model given a value is refused by the study (:meth:`idle_settings`).

    Parameters
    ----------
    model : str
        One of :data:`foldopt.names.TRACKERS`; default ``dual-axis``.
    steps : int
        Moves a day of ``dual-axis-steps``, even, in [2, 200]; default 12.
    angular_field : float
        Swing of its daily axis [deg] in (0, 360]; default 90.
    step_offsets_h : list of float, optional
        Its afternoon moves from solar noon [h], each in (0, 12), ``steps / 2`` of them; default
        Alexandru's 12-step law.
    axis_tilt : float
        ``single-axis``: the axis' tilt [deg] in [0, 90]; default 0.
    axis_azimuth : float, optional
        Its azimuth [deg] in [0, 360); default toward the equator.
    max_angle : float
        Its largest rotation [deg] in (0, 90]; default 90.
    backtrack : bool
        Whether it backtracks against the next row; default False.
    gcr : float
        Its ground coverage ratio [-] in (0, 1]; default 0.35.
    standby_w : float
        The controller's draw while the sun is up [W] in [0, 1000]; default 0.
    drive : str
        One of :data:`foldopt.names.DRIVES`; default ``motor``.
    wh_per_degree : float
        ``wh-per-degree`` drive's energy [Wh/deg] in [0, 10]; default 0.
    """

    model: named(names.TRACKERS) = "dual-axis"
    steps: Annotated[int, Field(ge=2, le=200, multiple_of=2)] = 12
    angular_field: interval(0, 360, lo_open=True, unit=" deg") = 90.0
    step_offsets_h: list[interval(0, 12, lo_open=True, hi_open=True, unit=" h")] | None = Field(
        None, description="afternoon move times from solar noon; default Alexandru's 12-step law"
    )
    axis_tilt: interval(0, 90, unit=" deg") = 0.0
    axis_azimuth: interval(0, 360, hi_open=True, unit=" deg") | None = None
    max_angle: interval(0, 90, lo_open=True, unit=" deg") = 90.0
    backtrack: bool = False
    gcr: interval(0, 1, lo_open=True) = 0.35
    standby_w: interval(0, 1000, unit=" W") = 0.0
    drive: named(names.DRIVES) = "motor"
    wh_per_degree: interval(0, 10, unit=" Wh/deg") = 0.0

    @model_validator(mode="after")
    def _offsets_match_steps(self):
        offsets = (
            self.step_offsets_h if self.step_offsets_h is not None else ALEXANDRU_STEP_OFFSETS_H
        )
        # A model that does not step leaves both idle: the study refuses them as such.
        if len(offsets) * 2 != self.steps and self.model in self.models_using("steps"):
            raise ValueError(
                f"steps ({self.steps}) must be twice the number of step_offsets_h ({len(offsets)})"
            )
        return self

    @staticmethod
    def models_using(option: str) -> tuple[str, ...]:
        """The tracker models that read an option.

        Parameters
        ----------
        option : str
            A field of the tracker (``gcr``).

        Returns
        -------
        tuple of str
            The models of :data:`foldopt.physics.trackers.TRACKER_MODELS` that read it; none for
            the model itself and the drive's fields, which every model reads.
        """
        # numpy with the registry: only for a tracker given options, whose study then runs.
        from foldopt.physics.trackers import TRACKER_MODELS

        return tuple(model for model, entry in TRACKER_MODELS.items() if option in entry.options)

    def idle_settings(self) -> list[str]:
        """Options given a value that the tracker does not use.

        Returns
        -------
        list of str
            ``tracker.<option> = value: why`` for each option of another tracker model given a
            value other than its default, and for ``wh_per_degree`` without its drive.
        """
        idle = []
        for name, field in Tracker.model_fields.items():
            value = getattr(self, name)
            users = self.models_using(name) if name != "model" and value != field.default else ()
            if users and self.model not in users:
                idle.append(
                    f"tracker.{name} = {value!r}: is only used by tracker.model {' or '.join(users)}"
                )
        if self.drive != "wh-per-degree" and self.wh_per_degree:
            idle.append(
                f"tracker.wh_per_degree = {self.wh_per_degree!r}: is only used by tracker.drive "
                "wh-per-degree"
            )
        return idle


_STATISTIC = re.compile(r"^(mean|min|worst-month|p(\d{1,2}))$")


class Objective(StrictModel):
    """What a fixed fold angle should maximise over the days of a study.

    Parameters
    ----------
    statistic : str
        Of the daily t_solar [h]: ``mean``, ``min``, ``worst-month`` or a percentile ``pNN``.
    months : list of int, optional
        The season, months 1 to 12; default all.
    visits : int, optional
        Also the best re-fold schedule of 1 to ``visits`` (at most 12) settings a year
        (:mod:`foldopt.engine.schedule`).
    """

    statistic: str = Field(
        "mean", description="mean | min | worst-month | pNN (a percentile, e.g. p10)"
    )
    months: list[Annotated[int, Field(ge=1, le=12)]] | None = Field(
        None, description="the season; default all"
    )
    visits: Annotated[int, Field(ge=1, le=12)] | None = Field(
        None,
        description="also the best re-fold schedule of 1..visits settings a year (foldopt.engine.schedule)",
    )

    @field_validator("statistic")
    @classmethod
    def _known(cls, value):
        if not _STATISTIC.match(value):
            hint = names.did_you_mean(value, ("mean", "min", "worst-month"))
            raise ValueError(f"must be mean, min, worst-month or a percentile pNN (e.g. p10){hint}")
        return value

    @model_validator(mode="after")
    def _schedulable(self):
        if self.visits is not None and self.statistic not in ("mean", "worst-month"):
            raise ValueError(
                f"visits: a re-fold schedule maximises mean or worst-month, not {self.statistic}"
            )
        if self.visits is not None and self.months:
            raise ValueError("visits: a re-fold schedule covers the whole year; leave months out")
        return self


_ProfileSteps = Annotated[dict, AfterValidator(profile_steps)]


class LoadProfile(StrictModel):
    """P_load(t) for a scale (``p_load``) of 1: loads [W] at clock times of the local day, held
    until the next time (``step``) or interpolated between them (``linear``), and the last carried
    over midnight to the first (:mod:`foldopt.inputs.load_profile`).

    Parameters
    ----------
    daily : dict, optional
        Clock times ``HH:MM`` to loads [W] (:func:`foldopt.inputs.load_profile.profile_steps`).
    file : str, optional
        A CSV of ``time,watts`` rows instead of ``daily``; its day becomes ``daily`` where its
        loader read it (:class:`FilesRead`).
    hourconsumption : list of float, optional
        Instead of ``daily``, PVGIS's off-grid form: 24 fractions of ``consumptionday``, one an
        hour from 00:00, summing to 1; they become ``daily``
        (:func:`foldopt.inputs.load_profile.hourly_steps`).
    consumptionday : float, optional
        With ``hourconsumption``: the day's energy [Wh] in (0, 1e7].
    interpolation : {'step', 'linear'}
    weekend : dict, optional
        The day of Saturdays and Sundays, as ``daily``.
    months : dict, optional
        Month numbers 1 to 12 to a day, as ``daily``.
    """

    # What gives the day comes first: the day is read from it where not given (:meth:`_read_day`).
    file: str | None = None
    hourconsumption: list[float] | None = Field(
        None, description="PVGIS's form: 24 fractions of consumptionday, hour by hour from 00:00"
    )
    consumptionday: interval(0, 1e7, lo_open=True, unit=" Wh") | None = Field(
        None, description="with hourconsumption: the day's energy"
    )
    interpolation: named(("step", "linear")) = "step"
    daily: _ProfileSteps | None = Field(None, validate_default=True)
    weekend: _ProfileSteps | None = None
    months: dict[Annotated[int, Field(ge=1, le=12)], _ProfileSteps] | None = None

    @field_validator("daily", mode="after")
    @classmethod
    def _read_day(cls, daily, info: ValidationInfo):
        """The day a file (as its loader read it) or PVGIS's fractions give, where ``daily`` is not
        given: read, not given (the fields set say so); where they cannot give one,
        :meth:`_one_day` says why."""
        if daily is not None:
            return daily
        files = FilesRead.given(info)
        if info.data.get("file") is not None and files is not None:
            return files.profile_daily
        fractions, energy = info.data.get("hourconsumption"), info.data.get("consumptionday")
        if fractions is None or energy is None:
            return None
        try:
            return hourly_steps(fractions, energy)
        except ValueError:
            return None

    @model_validator(mode="after")
    def _one_day(self, info: ValidationInfo):
        given = [
            name
            for name in ("daily", "file", "hourconsumption")
            if (
                name in self.model_fields_set
                if name == "daily"
                else getattr(self, name) is not None
            )
        ]
        if len(given) != 1:
            raise ValueError(
                "give the day's loads as one of daily (a mapping HH:MM: watts), file (a CSV) or "
                "hourconsumption (PVGIS's 24 fractions of consumptionday)"
                + (f", not {' and '.join(given)}" if given else "")
            )
        if (self.hourconsumption is None) != (self.consumptionday is None):
            raise ValueError(
                "hourconsumption and consumptionday [Wh] go together: PVGIS's fractions of the "
                "day's energy, and that energy"
            )
        if self.hourconsumption is not None:
            if self.interpolation != "step":
                raise ValueError(
                    "interpolation: hourconsumption gives each hour's energy, held over the hour "
                    "(step); linear would move energy between hours"
                )
            hourly_steps(self.hourconsumption, self.consumptionday)  # ValueError: what is wrong
        files = FilesRead.given(info)
        if self.file is not None and files is not None and files.profile_problem is not None:
            raise ValueError(files.profile_problem)
        return self

    @property
    def read_daily(self) -> bool:
        """Whether ``daily`` was worked out from ``file`` or ``hourconsumption``, not given."""
        return self.file is not None or self.hourconsumption is not None


class FoldAngles(StrictModel):
    """The grid of fold angles a study sweeps.

    Parameters
    ----------
    start, stop, step : float
        [deg], each in (0, 180]; default 1 to 180 by 1.
    """

    start: interval(0, FLAT_FOLD_ANGLE, lo_open=True, unit=" deg") = 1.0
    stop: interval(0, FLAT_FOLD_ANGLE, lo_open=True, unit=" deg") = FLAT_FOLD_ANGLE
    step: interval(0, FLAT_FOLD_ANGLE, lo_open=True, unit=" deg") = 1.0

    @model_validator(mode="after")
    def _ordered(self):
        if self.start > self.stop:
            raise ValueError(f"start ({self.start:g}) must not exceed stop ({self.stop:g})")
        return self

    @field_validator("step")
    @classmethod
    def _bounded(cls, step: float, info: ValidationInfo):
        # Counted, not listed: a step of 1e-9 deg would list 1.8e11 angles before any limit looked.
        start, stop = info.data.get("start"), info.data.get("stop")
        count = (
            grid_points(start, stop, step)
            if start is not None and stop is not None and start <= stop
            else 0
        )
        if count > MAX_AXIS_VALUES:
            raise ValueError(
                f"{count:,} fold angles from {start:g} to {stop:g}; the limit is {MAX_AXIS_VALUES:,} "
                "values a range (a coarser step, or FOLDOPT_MAX_AXIS_VALUES)"
            )
        return step

    def count(self) -> int:
        """The number of fold angles of :meth:`grid`, worked out without listing them."""
        return grid_points(self.start, self.stop, self.step)

    def grid(self):
        """The sweep's fold angles.

        Returns
        -------
        list of float
            [deg]: ``start`` by ``step``, always ending on ``stop``.
        """
        count = int(math.floor((self.stop - self.start) / self.step + 1e-9)) + 1
        angles = [self.start + i * self.step for i in range(count)]
        return angles if math.isclose(angles[-1], self.stop) else [*angles, self.stop]


class NearOptimal(StrictModel):
    """How close to the best a fold angle must come to count as near-optimal: within ``fraction``
    of the best t_solar (or objective) or within ``minutes``, whichever is larger. The optimum of a
    fold angle is a plateau; the near-optimal range is every grid angle on the best one's plateau
    and the recommended angle its centre, robust to how precisely an installer sets a hinge.

    Parameters
    ----------
    fraction : float
        [-] in [0, 1]; default 0.01.
    minutes : float
        [min] in [0, 1440]; default 1.
    """

    fraction: interval(0, 1) = 0.01
    minutes: interval(0, 1440, unit=" min") = 1.0

    def tolerance_h(self, best_h):
        """The tolerance around a best value.

        Parameters
        ----------
        best_h : array_like
            The best t_solar or objective [h].

        Returns
        -------
        numpy.ndarray
            [h], broadcast with ``best_h``.
        """
        import numpy as np

        return np.maximum(self.fraction * np.asarray(best_h, dtype=float), self.minutes / 60.0)
