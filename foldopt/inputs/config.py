"""Study configuration: a validated, typed description of one foldopt study.

A study is written in YAML (see ``configs/``) or assembled from command-line options; both paths
go through :class:`Study`, so a bad value gets the same message either way: the field's path, the
value and the allowed range.
"""

from __future__ import annotations

import datetime as dt
import itertools
import math
import os
import re
import stat
import zoneinfo
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Annotated

import yaml
from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from foldopt import names
from foldopt.errors import ConfigError
from foldopt.inputs import policy
from foldopt.names import ALEXANDRU_STEP_OFFSETS_H, canonical
from foldopt.inputs.policy import set_path

DEFAULT_STUDY = "shin2015"
SITE_TOLERANCE_KM = 5.0  # [km] a study's site may lie this far from its weather file's
EARTH_RADIUS_KM = 6371.0
_OFFSET = re.compile(r"^(?:UTC)?([+-])(\d{1,2})(?::?(\d{2}))?$")


def _interval(lo, hi, *, lo_open=False, hi_open=False, unit=""):
    """A float constrained to an interval, whose error message states the interval."""
    text = f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}{unit}"

    def check(value: float) -> float:
        below = value <= lo if lo_open else value < lo
        above = value >= hi if hi_open else value > hi
        if not math.isfinite(value) or below or above:
            raise ValueError(f"must be in {text}")
        return value

    return Annotated[float, AfterValidator(check)]


def _as_tuple(value) -> tuple:
    """A default as a tuple of its accepted values."""
    return value if isinstance(value, tuple) else (value,)


def _named(choices):
    """A name among ``choices``, any spelling of :func:`foldopt.names.canonical` accepted."""
    return Annotated[str, BeforeValidator(partial(canonical, names=choices))]


def _weather_site(path: str, fmt: str | None) -> dict:
    from foldopt.inputs.weather import (
        weather_site,  # pvlib's readers, only when a file is given
    )

    return weather_site(path, fmt)


def great_circle_km(latitude_1, longitude_1, latitude_2, longitude_2) -> float:
    """Distance between two points on a spherical Earth [km] (haversine)."""
    phi_1, phi_2 = math.radians(latitude_1), math.radians(latitude_2)
    half_dphi = (phi_2 - phi_1) / 2
    half_dlambda = math.radians(longitude_2 - longitude_1) / 2
    a = math.sin(half_dphi) ** 2 + math.cos(phi_1) * math.cos(phi_2) * math.sin(half_dlambda) ** 2
    return 2 * EARTH_RADIUS_KM * math.asin(min(1.0, math.sqrt(a)))


def parse_timezone(name: str) -> dt.tzinfo:
    """An IANA time zone (``America/Los_Angeles``) or a fixed offset (``UTC-08:00``, ``+5:30``)."""
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


def _check_step_min(value: float) -> float:
    if not math.isclose(1440 / value, round(1440 / value)):
        raise ValueError("must divide the 1440 min of a day (e.g. 0.5, 1, 2, 5, 10, 15, 30, 60)")
    return value


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Site(_Strict):
    name: str | None = None
    latitude: _interval(-90, 90, unit=" deg")
    longitude: _interval(-180, 180, unit=" deg")
    altitude: _interval(-500, 9000, unit=" m") = 0.0
    timezone: Annotated[str | None, AfterValidator(_check_timezone)] = Field(
        None, description="IANA name or UTC offset; default: the longitude's standard offset"
    )


    def resolved(self) -> Site:
        """The site with its time zone filled in: the longitude's standard offset by default."""
        if self.timezone is not None:
            return self
        hours = round(self.longitude / 15.0)
        return self.model_copy(update={"timezone": f"UTC{'+' if hours >= 0 else '-'}{abs(hours):02d}:00"})


class Panel(_Strict):
    area: _interval(0, 1000, lo_open=True, unit=" m^2")
    efficiency: _interval(0, 1, lo_open=True) = 0.2
    tilt: _interval(0, 90, unit=" deg") | None = Field(None, description="default |latitude|")
    azimuth: _interval(0, 360, hi_open=True, unit=" deg") | None = Field(
        None, description="default: facing the equator"
    )


class Tracker(_Strict):
    """The tracker compared against, and the energy it spends (see :mod:`foldopt.physics.trackers`)."""

    model: _named(names.TRACKERS) = "dual-axis"
    steps: Annotated[int, Field(ge=2, le=200, multiple_of=2)] = 12
    angular_field: _interval(0, 360, lo_open=True, unit=" deg") = 90.0
    step_offsets_h: list[_interval(0, 12, lo_open=True, hi_open=True, unit=" h")] | None = Field(
        None, description="afternoon move times from solar noon; default Alexandru's 12-step law"
    )
    axis_tilt: _interval(0, 90, unit=" deg") = 0.0
    axis_azimuth: _interval(0, 360, hi_open=True, unit=" deg") | None = None
    max_angle: _interval(0, 90, lo_open=True, unit=" deg") = 90.0
    backtrack: bool = False
    gcr: _interval(0, 1, lo_open=True) = 0.35
    standby_w: _interval(0, 1000, unit=" W") = 0.0
    drive: _named(names.DRIVES) = "motor"
    wh_per_degree: _interval(0, 10, unit=" Wh/deg") = 0.0

    @model_validator(mode="after")
    def _offsets_match_steps(self):
        offsets = self.step_offsets_h if self.step_offsets_h is not None else ALEXANDRU_STEP_OFFSETS_H
        if len(offsets) * 2 != self.steps:
            raise ValueError(f"steps ({self.steps}) must be twice the number of step_offsets_h ({len(offsets)})")
        return self


class Weather(_Strict):
    """A weather file: TMY3, EPW or PVGIS TMY, read through pvlib.iotools."""

    path: str
    format: _named(names.WEATHER_FORMATS) | None = Field(None, description="default from the extension")
    label: _named(names.INTERVAL_LABELS) | None = Field(
        None, description="what a timestamp marks; default the format's (TMY3 end, EPW and PVGIS start)"
    )


_STATISTIC = re.compile(r"^(mean|min|worst-month|p(\d{1,2}))$")


class Objective(_Strict):
    """What a fixed fold angle should maximise over the days of a study."""

    statistic: str = Field("mean", description="mean | min | worst-month | pNN (a percentile, e.g. p10)")
    months: list[Annotated[int, Field(ge=1, le=12)]] | None = Field(None, description="the season; default all")
    visits: Annotated[int, Field(ge=1, le=12)] | None = Field(
        None, description="also the best re-fold schedule of 1..visits settings a year (foldopt.engine.schedule)")

    @field_validator("statistic")
    @classmethod
    def _known(cls, value):
        if not _STATISTIC.match(value):
            raise ValueError("must be mean, min, worst-month or a percentile pNN (e.g. p10)")
        return value

    @model_validator(mode="after")
    def _schedulable(self):
        if self.visits is not None and self.statistic not in ("mean", "worst-month"):
            raise ValueError(f"visits: a re-fold schedule maximises mean or worst-month, not {self.statistic}")
        if self.visits is not None and self.months:
            raise ValueError("visits: a re-fold schedule covers the whole year; leave months out")
        return self


_CLOCK = re.compile(r"^([01]?\d|2[0-3]):([0-5]\d)$")


def _profile_steps(value: dict) -> dict:
    """``{"HH:MM": watts}``: clock times of a day, each load at least 0 W."""
    if not isinstance(value, dict) or not value:
        raise ValueError("expected a mapping of clock times HH:MM to watts, e.g. {'07:00': 6, '19:00': 1.5}")
    steps, given = {}, {}
    for time, watts in value.items():
        match = _CLOCK.match(str(time).strip())
        if not match:
            raise ValueError(f"{time!r} is not a clock time HH:MM in [00:00, 23:59]")
        if isinstance(watts, bool) or not isinstance(watts, (int, float)) or not math.isfinite(watts) or watts < 0:
            raise ValueError(f"{time}: {watts!r} is not a load in watts >= 0")
        clock = f"{int(match.group(1)):02d}:{match.group(2)}"
        if clock in given:  # 7:00 beside 07:00: one of the two loads would be dropped unseen
            raise ValueError(f"{time!r} is the time {given[clock]!r} again; give each time once")
        given[clock] = time
        steps[clock] = float(watts)
    return dict(sorted(steps.items()))


_ProfileSteps = Annotated[dict, AfterValidator(_profile_steps)]


class LoadProfile(_Strict):
    """P_load(t) for a scale (``p_load``) of 1: loads [W] at clock times of the local day, held
    until the next time (``step``) or interpolated between them (``linear``), and the last carried
    over midnight to the first. ``weekend`` (Saturday and Sunday) and ``months`` (month number to
    a day) replace the ``daily`` day where they apply. ``file``: a CSV of ``time,watts`` rows
    instead of ``daily``."""

    daily: _ProfileSteps | None = None
    file: str | None = None
    interpolation: _named(("step", "linear")) = "step"
    weekend: _ProfileSteps | None = None
    months: dict[Annotated[int, Field(ge=1, le=12)], _ProfileSteps] | None = None

    @model_validator(mode="after")
    def _one_day(self):
        if (self.daily is None) == (self.file is None):
            raise ValueError("give the day's loads as daily (a mapping HH:MM: watts) or as file (a CSV), not both")
        if self.file is not None:
            from foldopt.inputs.loads import read_profile  # only when a file is named

            object.__setattr__(self, "daily", read_profile(self.file))
        return self


class FoldAngles(_Strict):
    start: _interval(0, 180, lo_open=True, unit=" deg") = 1.0
    stop: _interval(0, 180, lo_open=True, unit=" deg") = 180.0
    step: _interval(0, 180, lo_open=True, unit=" deg") = 1.0

    @model_validator(mode="after")
    def _ordered(self):
        if self.start > self.stop:
            raise ValueError(f"start ({self.start:g}) must not exceed stop ({self.stop:g})")
        return self

    def grid(self):
        """The sweep's fold angles [deg]: ``start`` by ``step``, always ending on ``stop``."""
        count = int(math.floor((self.stop - self.start) / self.step + 1e-9)) + 1
        angles = [self.start + i * self.step for i in range(count)]
        return angles if math.isclose(angles[-1], self.stop) else [*angles, self.stop]


class NearOptimal(_Strict):
    """How close to the best a fold angle must come to count as near-optimal: within ``fraction``
    of the best t_solar (or objective) or within ``minutes``, whichever is larger. The optimum of a
    fold angle is a plateau; the near-optimal range is every grid angle on the best one's plateau
    and the recommended angle its centre, robust to how precisely an installer sets a hinge."""

    fraction: _interval(0, 1) = 0.01
    minutes: _interval(0, 1440, unit=" min") = 1.0

    def tolerance_h(self, best_h):
        """The tolerance [h] around a best value ``best_h`` [h] (broadcast)."""
        import numpy as np

        return np.maximum(self.fraction * np.asarray(best_h, dtype=float), self.minutes / 60.0)


class Study(_Strict):
    name: Annotated[str, Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9._-]*$", max_length=100)]
    description: str = ""
    mode: _named(names.MODES) = "exact"
    site: Site = Field(description="default with a weather file: the file's own site")
    force_site: bool = Field(False, description="keep a site more than SITE_TOLERANCE_KM from the weather file's")
    date: dt.date
    panel: Panel
    p_load: _interval(0, 1e6, lo_open=True, unit=" W") = Field(
        description="the load [W]; with a load_profile, the profile's scale [-]")
    load_profile: LoadProfile | None = None
    geometry: _named(names.GEOMETRIES) | None = Field(
        None, description="twofold parametrisation; default azimuth-split in paper mode, hinge in exact"
    )
    fold_angles: FoldAngles = FoldAngles()
    near_optimal: NearOptimal = NearOptimal()
    sky: _named(names.SKIES) = "meinel"
    linke_turbidity: _interval(0, 10, lo_open=True) | None = Field(None, description="ineichen; default pvlib's climatology")
    transposition: _named(names.TRANSPOSITIONS) | None = Field(
        None, description="diffuse model; default none for beam-only skies, perez otherwise"
    )
    albedo: _interval(0, 1) = 0.2
    iam: _named(names.IAMS) = "none"
    weather: Weather | None = None
    objective: Objective | None = None
    pv_model: _named(names.PV_MODELS) = "ideal"
    module: str | None = Field(None, description="single-diode: CEC module name; default the A-300 cell")
    connection: _named(names.CONNECTIONS) = "switching"
    switch_series: bool = Field(False, description="switching may also select series")
    bypass_diodes: bool = True
    converter_efficiency: _interval(0, 1, lo_open=True) = 1.0
    temperature_model: _named(names.TEMPERATURE_MODELS) | None = Field(
        None, description="default fixed (cells at temp_air) in paper mode, sapm in exact"
    )
    temp_air: _interval(-60, 60, unit=" C") = 25.0
    wind_speed: _interval(0, 60, unit=" m/s") = 1.0
    exact_electrical: bool = Field(False, description="solve every step's I-V curves, not tables")
    tracker: Tracker = Tracker()
    climate: _named(names.HOTTEL_CLIMATES) = Field("midlatitude-summer", description="Hottel sky only")
    step_min: Annotated[_interval(0, 60, lo_open=True, unit=" min"), AfterValidator(_check_step_min)] = 1.0

    @model_validator(mode="before")
    @classmethod
    def _profile_scale(cls, data):
        """A load profile is in watts: its scale defaults to 1."""
        if isinstance(data, dict) and data.get("load_profile") is not None and data.get("p_load") is None:
            data = {**data, "p_load": 1.0}
        return data

    @field_validator("weather", mode="before")
    @classmethod
    def _weather_by_path(cls, value):
        return {"path": value} if isinstance(value, str) else value

    @field_validator("objective", mode="before")
    @classmethod
    def _objective_by_statistic(cls, value):
        """``objective: worst-month`` is ``objective: {statistic: worst-month}``."""
        return {"statistic": value} if isinstance(value, str) else value

    @model_validator(mode="before")
    @classmethod
    def _site_from_weather(cls, data):
        """A weather file brings its site: the study's unless one is given."""
        if isinstance(data, dict) and data.get("site") is None and data.get("weather") is not None:
            weather = data["weather"]
            path, fmt = (weather, None) if isinstance(weather, str) else (weather.get("path"), weather.get("format"))
            if isinstance(path, str):
                if not Path(path).is_file():
                    raise ValueError(f"weather: file not found: {path}")
                try:
                    data = {**data, "site": _weather_site(path, fmt)}
                except ConfigError as error:  # foldopt.errors.WeatherError: the file, the line, the reason
                    raise ValueError(str(error)) from None
                except (ValueError, KeyError, OSError) as error:
                    raise ValueError(f"weather: cannot read a site from {path} ({error.__class__.__name__})") from None
        return data

    @model_validator(mode="after")
    def _consistent(self):
        if self.mode == "paper" and self.transposition not in (None, "none"):
            raise ValueError("transposition: paper mode is beam-only (Shin et al. Eq. 5): transposition must be none")
        idle = self.idle_settings()
        if idle:
            raise ValueError("\n".join(idle))  # one error line each
        if self.weather is not None and not Path(self.weather.path).is_file():
            raise ValueError(f"weather: file not found: {self.weather.path}")
        if self.weather is not None and not math.isclose(60 / self.step_min, round(60 / self.step_min)):
            raise ValueError(f"step_min = {self.step_min:g}: must divide the weather file's 60-min intervals")
        if self.weather is not None and not self.force_site:
            file_site = _weather_site(self.weather.path, self.weather.format)
            distance = great_circle_km(self.site.latitude, self.site.longitude, file_site["latitude"],
                                       file_site["longitude"])
            if distance > SITE_TOLERANCE_KM:
                name = f"{file_site['name']} " if file_site["name"] else ""
                raise ValueError(
                    f"site ({self.site.latitude:g}, {self.site.longitude:g}) is {distance:,.0f} km from the weather "
                    f"file's site {name}({file_site['latitude']:g}, {file_site['longitude']:g}); leave the site out "
                    f"to use the file's, or set force_site to keep it"
                )
        return self

    def idle_settings(self) -> list[str]:
        """Settings given a value that nothing in the study uses, each as ``field = value: why``."""
        defaults = {name: field.default for name, field in Study.model_fields.items()}
        # What a resolved study fills in is no setting of the user's.
        defaults["temperature_model"] = (None, "fixed" if self.mode == "paper" else "sapm")
        iv_model = self.pv_model != "ideal"
        series_used = self.connection == "series" or (self.connection == "switching" and self.switch_series)
        rules = [
            ("climate", self.sky == "hottel", "is only used by sky hottel"),
            ("linke_turbidity", self.sky == "ineichen" or self.weather is not None,
             "is only used by sky ineichen and weather files"),
            ("sky", self.weather is None, "has no use with a weather file (its light shapes the minutes)"),
            ("albedo", self.sky_transposition() != "none", "is only used with a transposition (diffuse light)"),
            ("switch_series", self.connection == "switching", "is only used by connection switching"),
            ("bypass_diodes", series_used, "is only used where series is (connection series, or switching "
                                           "with switch_series)"),
            ("converter_efficiency", self.connection == "independent", "is only used by connection independent"),
            ("temperature_model", iv_model, "is only used by pv_model single-diode or b-model"),
            ("temp_air", iv_model and self.weather is None,
             "is only used by pv_model single-diode or b-model, without a weather file (which brings its own)"),
            ("wind_speed", iv_model, "is only used by pv_model single-diode or b-model"),
            ("exact_electrical", iv_model, "is only used by pv_model single-diode or b-model"),
        ]
        idle = [f"{name} = {getattr(self, name)!r}: {why}" for name, used, why in rules
                if not used and getattr(self, name) not in _as_tuple(defaults[name])]
        if self.tracker.drive != "wh-per-degree" and self.tracker.wh_per_degree:
            idle.append(f"tracker.wh_per_degree = {self.tracker.wh_per_degree!r}: is only used by tracker.drive "
                        "wh-per-degree")
        return idle

    def sky_transposition(self) -> str:
        """The diffuse model in force: none for beam-only skies unless a weather file gives diffuse."""
        if self.transposition is not None:
            return self.transposition
        return "none" if self.mode == "paper" or (self.weather is None and self.sky in names.BEAM_SKIES) else "perez"

    @field_validator("tracker", mode="before")
    @classmethod
    def _tracker_by_name(cls, value):
        return {"model": value} if isinstance(value, str) else value

    @field_validator("module")
    @classmethod
    def _module_is_known(cls, module, info: ValidationInfo):
        if module is not None:
            if info.data.get("pv_model") != "single-diode":
                raise ValueError("module is only used with pv_model single-diode")
            from foldopt.physics.pvmodel import (
                cec_module_name,  # pvlib's CEC database, only when a module is named
            )

            return cec_module_name(module)
        return module

    def variant(self, **changes) -> Study:
        """A validated copy with ``changes``, made by the study policy (:func:`foldopt.inputs.policy.apply`).

        Parameters
        ----------
        **changes
            Field names to new values. A mapping for a section (``site``, ``panel``, ``tracker``,
            ``objective``, ``fold_angles``, ``near_optimal``) changes only the fields it names:
            ``variant(panel={"area": 0.1})`` keeps the efficiency, tilt and azimuth. As for the
            command line, a paper-mode study given another site or day runs in exact mode, a new
            mode takes its own geometry and a new latitude tilts the panel at ``|latitude|``,
            unless those fields are given too.

        Returns
        -------
        Study

        Raises
        ------
        foldopt.ConfigError
            One ``field = value: problem`` line per fault.

        Examples
        --------
        >>> import foldopt
        >>> study = foldopt.default_study().variant(site={"latitude": 10.0})
        >>> study.mode, study.geometry, study.panel.tilt, study.panel.efficiency
        ('exact', None, None, 0.1905)
        """
        data, _ = policy.apply(self.data(), changes)
        return make_study(data)

    def data(self) -> dict:
        """The study's fields as plain data that validate back into it (``date`` as text, no
        unset field; a profile read from a file keeps its file, not the steps read from it)."""
        data = self.model_dump(mode="json", exclude_none=True)
        if self.load_profile is not None and self.load_profile.file is not None:
            data["load_profile"].pop("daily", None)
        return data

    def resolved(self) -> Study:
        """The study with every default that depends on other fields (site, mode) filled in.

        Studies are kept unresolved so that a variant (another mode, another latitude) gets its
        own defaults; :class:`foldopt.studies.day.Day` resolves the study it runs.
        """
        from foldopt.physics.geometry import default_orientation

        tilt, azimuth = default_orientation(self.site.latitude)
        panel = self.panel.model_copy(
            update={
                "tilt": tilt if self.panel.tilt is None else self.panel.tilt,
                "azimuth": azimuth if self.panel.azimuth is None else self.panel.azimuth,
            }
        )
        geometry = self.geometry or ("azimuth-split" if self.mode == "paper" else "hinge")
        temperature = self.temperature_model or ("fixed" if self.mode == "paper" else "sapm")
        return self.model_copy(
            update={
                "panel": panel,
                "site": self.site.resolved(),
                "geometry": geometry,
                "temperature_model": temperature,
            }
        )


def _format_error(item: dict) -> list[str]:
    """The lines of one pydantic error: ``field = value: problem``."""
    field = ".".join(str(part) for part in item["loc"])
    message = item["msg"].removeprefix("Value error, ")
    if not field:
        # The study's own checks name their fields themselves.
        return message.splitlines() if item["type"] == "value_error" else [f"study: {message}"]
    if item["type"] == "missing":
        return [f"{field}: required field is missing"]
    if item["type"] == "extra_forbidden":
        return [f"{field}: unknown field"]
    if isinstance(item["input"], dict):
        return [f"{field}: {message}"]
    return [f"{field} = {item['input']!r}: {message}"]


def _format_errors(error: ValidationError) -> list[str]:
    return [line for item in error.errors() for line in _format_error(item)]


def make_study(data: dict) -> Study:
    """Validate one study from plain data; raises :class:`ConfigError` listing every fault."""
    if not isinstance(data, dict):
        raise ConfigError([f"study: expected a mapping of fields, got {type(data).__name__}"])
    try:
        return Study.model_validate(data)
    except ValidationError as error:
        raise ConfigError(_format_errors(error)) from None


# --- Plans: a study with sweep axes ------------------------------------------------------------

DATE_KEYWORDS = ("year", "equinoxes-solstices")
#: Fields that label a study rather than design it: a list of them is no sweep.
UNSWEPT = ("name", "description")

def _limit(name: str, default: int) -> int:
    """A size limit, raised by the environment variable ``FOLDOPT_<NAME>``."""
    text = os.environ.get(f"FOLDOPT_{name}")
    try:
        return int(float(text)) if text else default
    except ValueError:
        return default


#: Values of one sweep axis (a range or a list).
MAX_AXIS_VALUES = _limit("MAX_AXIS_VALUES", 10_000)
#: Cases of a plan: one row of results.csv per case and design.
MAX_CASES = _limit("MAX_CASES", 200_000)
#: Site-days x fold angles x time steps of a plan: about 6 ns each on one core (README,
#: "Performance"), so the default is a few minutes of work at most.
MAX_EVALUATIONS = _limit("MAX_EVALUATIONS", 20_000_000_000)
#: Days x fold angles x loads of one annual group (a fixed angle chosen over the days), held at
#: once: 8 bytes each.
MAX_ANNUAL_CELLS = _limit("MAX_ANNUAL_CELLS", 100_000_000)
#: Bytes of a study file.
MAX_STUDY_BYTES = _limit("MAX_STUDY_BYTES", 1_000_000)
#: Bytes of a CSV input (a table of sites, a load profile): MAX_CASES sites at 100 bytes a row.
MAX_CSV_BYTES = _limit("MAX_CSV_BYTES", 20_000_000)
#: Years of a study's days, checked alike for study files, sweeps and maps: well inside Python's
#: calendar (years 1 to 9999; a year 0 or 10000 was a traceback) and pvlib's solar position.
YEARS = (1901, 2099)


def year_problem(year) -> str | None:
    """Why ``year`` cannot be a study's year, or None: a whole year of :data:`YEARS`."""
    if isinstance(year, bool) or not isinstance(year, int) or not YEARS[0] <= year <= YEARS[1]:
        return f"must be a whole year in [{YEARS[0]}, {YEARS[1]}]"
    return None


#: What :func:`read_input` calls a file that is no regular file, by its type.
_SPECIAL_FILES = ((stat.S_ISCHR, "character device"), (stat.S_ISBLK, "block device"), (stat.S_ISFIFO, "FIFO"),
                  (stat.S_ISSOCK, "socket"))


def read_input(path: Path | str, field: str, limit: int, limit_name: str) -> str:
    """The text of an input file (a study, a table of sites, a load profile), read as UTF-8
    whatever the locale, a byte-order mark (a spreadsheet's "CSV UTF-8") dropped.

    Parameters
    ----------
    path : str or pathlib.Path
    field : str
        What messages name the file by (``config``, ``--sites``...).
    limit : int
        Its largest size [bytes].
    limit_name : str
        The limit's name: ``FOLDOPT_<limit_name>`` raises it.

    Raises
    ------
    ConfigError
        One line naming ``field`` and the file: missing, a folder, no regular file (a device or a
        FIFO never ends, or never starts), larger than ``limit``, unreadable or not UTF-8 text.
    """
    path = Path(path)
    try:
        # Opened without blocking and checked by the open descriptor, so that a FIFO cannot hold
        # the command and no file swapped in after a check is read.
        descriptor = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(descriptor, "rb") as handle:
            info = os.fstat(handle.fileno())
            mode = info.st_mode
            if stat.S_ISDIR(mode):
                raise ConfigError([f"{field}: {path} is a folder; give a file"])
            kind = next((name for test, name in _SPECIAL_FILES if test(mode)), None)
            if kind is not None:
                raise ConfigError([f"{field}: {path} is a {kind}, not a regular file; give a file"])
            # A file that says it is too large is not read; one that grows while it is read is cut.
            data = b"" if info.st_size > limit else handle.read(limit + 1)
    except FileNotFoundError:
        raise ConfigError([f"{field}: file not found: {path}"]) from None
    except OSError as error:
        raise ConfigError([f"{field}: cannot read {path}: {error.__class__.__name__}"]) from None
    if info.st_size > limit or len(data) > limit:
        size = f"{info.st_size:,} bytes" if info.st_size > limit else f"over {limit:,} bytes"
        raise ConfigError([f"{field}: {path} is {size}; at most {limit:,} (FOLDOPT_{limit_name} raises it)"])
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise ConfigError([f"{field}: cannot read {path}: not UTF-8 text (byte {error.start + 1:,})"]) from None


class StudyLoader(yaml.SafeLoader):
    """YAML for studies: PyYAML's safe loader, less what a study never needs and an attacker or a
    slip would use. Aliases (``*name``) are refused, so no "billion laughs" expansion; a key given
    twice in one mapping is an error rather than silently the last; dates stay text, so that the
    schema validates them (``2025-02-30`` is a field error, not a crash in the parser)."""

    yaml_implicit_resolvers = {
        first: [(tag, regexp) for tag, regexp in resolvers if tag != "tag:yaml.org,2002:timestamp"]
        for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
    }

    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            raise yaml.composer.ComposerError(None, None, "aliases (*name) are not accepted in a study; write the "
                                              "value out", self.peek_event().start_mark)
        return super().compose_node(parent, index)

    def construct_mapping(self, node, deep=False):
        first: dict = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            try:
                if key in first:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"key {key!r} appears twice (first at line {first[key]})", key_node.start_mark)
                first[key] = key_node.start_mark.line + 1
            except TypeError:  # an unhashable key: the base class says so
                break
        return super().construct_mapping(node, deep)

    def construct_yaml_int(self, node):
        self._not_sexagesimal(node, "construct_yaml_int")
        return super().construct_yaml_int(node)

    def construct_yaml_float(self, node):
        self._not_sexagesimal(node, "construct_yaml_float")
        return super().construct_yaml_float(node)

    def _not_sexagesimal(self, node, constructor: str):
        """YAML 1.1 reads ``19:00`` as the base-60 number 1140 and ``1:9:4`` as 4144: a clock time
        or a range written without quotes would be a wrong number, silently."""
        text = self.construct_scalar(node)
        if ":" in text:
            value = getattr(super(), constructor)(node)
            raise yaml.constructor.ConstructorError(
                None, None, f"{text} is read by YAML as the number {value:g} (base 60); write '{text}' in quotes",
                node.start_mark)


StudyLoader.add_constructor("tag:yaml.org,2002:int", StudyLoader.construct_yaml_int)
StudyLoader.add_constructor("tag:yaml.org,2002:float", StudyLoader.construct_yaml_float)

_RANGE = re.compile(r"^\s*([^:\s]+)\s*:\s*([^:\s]+)\s*:\s*([^:\s]+)\s*$")
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_NUMERIC_RANGE = re.compile(rf"^\s*{_NUMBER}\s*:\s*{_NUMBER}\s*:\s*{_NUMBER}\s*$")


def parse_range(text: str) -> list[float]:
    """``"start:stop:step"`` -> the values from start to stop inclusive (stop kept if on the grid)."""
    match = _RANGE.match(str(text))
    if not match:
        raise ValueError(f"expected start:stop:step, got {text!r}")
    try:
        start, stop, step = (float(part) for part in match.groups())
    except ValueError:
        raise ValueError(f"expected numbers in start:stop:step, got {text!r}") from None
    if step <= 0 or not all(map(math.isfinite, (start, stop, step))):
        raise ValueError(f"step must be a positive number, got {text!r}")
    if stop < start:
        raise ValueError(f"empty range {text!r}: stop is below start")
    count = math.floor((stop - start) / step + 1e-9) + 1
    if count > MAX_AXIS_VALUES:
        raise ValueError(f"{text!r} has {count:,} values; at most {MAX_AXIS_VALUES:,} per axis "
                         "(FOLDOPT_MAX_AXIS_VALUES raises it)")
    return [round(start + i * step, 12) for i in range(count)]


def parse_values(text: str, numeric: bool = True):
    """The one parser of a value, a range or a list, as typed on the command line.

    ``"5"`` is a value, ``"0:60:10"`` a range (inclusive, :func:`parse_range`) and ``"0,30,60"`` a
    list; with ``numeric=False`` (dates) the items stay text and a range or keyword (``year``)
    is left to :func:`parse_dates`.

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
        raise ValueError(f"{text!r} has an empty item; a list is a,b,c")
    if len(items) > MAX_AXIS_VALUES:
        raise ValueError(f"a list of {len(items):,} values; at most {MAX_AXIS_VALUES:,} per axis "
                         "(FOLDOPT_MAX_AXIS_VALUES raises it)")
    if not numeric:
        return items if len(items) > 1 else items[0]
    if len(items) == 1 and ":" in text:
        return parse_range(text)
    try:
        values = [float(item) for item in items]
    except ValueError:
        raise ValueError(f"{text!r}: expected a number, a range start:stop:step or a list a,b,c") from None
    if not all(math.isfinite(value) for value in values):
        raise ValueError(f"{text!r}: values must be finite numbers")
    return values if len(values) > 1 else values[0]


def parse_dates(spec, year: int) -> list[dt.date]:
    """Dates from a date, a list, ``"start:stop:step"`` (dates, or days of ``year``), ``year`` or
    ``equinoxes-solstices`` (20 March, 21 June, 23 September, 21 December of ``year``)."""

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
        return [dt.date(year, 3, 20), dt.date(year, 6, 21), dt.date(year, 9, 23), dt.date(year, 12, 21)]
    match = _RANGE.match(str(spec)) if isinstance(spec, str) else None
    if match:
        start, stop, step = match.groups()
        if not step.isdigit() or int(step) < 1:
            raise ValueError(f"the step of a date range is a whole number of days, got {step!r}")
        first, last = one(int(start) if start.isdigit() else start), one(int(stop) if stop.isdigit() else stop)
        if last < first:
            raise ValueError(f"empty range {spec!r}: stop is before start")
        return [first + dt.timedelta(days=d) for d in range(0, (last - first).days + 1, int(step))]
    return [one(spec)]


def _leap(year: int) -> bool:
    return year % 4 == 0 and (year % 100 != 0 or year % 400 == 0)


@dataclass(frozen=True)
class Plan:
    """A study and its sweep axes; the cases are the product of the axes' values.

    ``axes`` pairs each dotted field path (``site.latitude``, ``p_load``, ``date``...) with its values.
    """

    data: dict
    axes: tuple

    @property
    def base(self) -> Study:
        """The study with every axis at its first value."""
        return self.study({path: values[0] for path, values in self.axes})

    @property
    def n_cases(self) -> int:
        return math.prod(len(values) for _, values in self.axes)

    def study(self, choice: dict) -> Study:
        data = self.data
        for path, value in choice.items():
            data = set_path(data, path, value)
        return Study.model_validate(data)

    def cases(self):
        """``(choice, study)`` for every combination of the axes' values, first axis slowest."""
        paths = [path for path, _ in self.axes]
        for values in itertools.product(*(values for _, values in self.axes)):
            choice = dict(zip(paths, values, strict=True))
            yield choice, self.study(choice)


def _listed_leaves(data: dict, prefix: str = ""):
    """Dotted paths holding a list, a numeric ``start:stop:step`` range or a date keyword."""
    for key, value in data.items():
        path = f"{prefix}{key}"
        if path == "date" and (isinstance(value, list) or value in DATE_KEYWORDS or (
            isinstance(value, str) and _RANGE.match(value)
        )):
            yield path, value
        elif isinstance(value, list) or (isinstance(value, str) and _NUMERIC_RANGE.match(value)):
            yield path, value
        elif isinstance(value, dict):
            yield from _listed_leaves(value, f"{path}.")


def _axis_values(path: str, spec, year: int) -> list:
    if path == "date":
        return parse_dates(spec, year)
    if isinstance(spec, list):
        if not spec:
            raise ValueError("empty list")
        if len(spec) > MAX_AXIS_VALUES:
            raise ValueError(f"a list of {len(spec):,} values; at most {MAX_AXIS_VALUES:,} per axis "
                             "(FOLDOPT_MAX_AXIS_VALUES raises it)")
        return list(spec)
    if isinstance(spec, str) and _RANGE.match(spec):
        return parse_range(spec)
    return [spec]


def make_plan(data, lines: dict | None = None) -> Plan:
    """Validate a study with optional sweep axes; raises :class:`ConfigError` with every fault.

    Any field but :data:`UNSWEPT` may hold a list (``site``: a list of sites) or a numeric range
    ``"start:stop:step"``; ``date`` also takes a date range, ``year`` or ``equinoxes-solstices`` (of ``year``, default
    2025), and is the whole ``year`` by default with a weather file. The ``sweep:`` section maps dotted field paths to lists or ranges. Each becomes an axis.
    ``lines`` maps key paths to YAML line numbers, added to the messages.
    """
    lines = lines or {}
    if not isinstance(data, dict):
        raise ConfigError([f"study: expected a mapping of fields, got {type(data).__name__}"])
    data = dict(data)
    if data.get("weather") is not None and "date" not in data:
        data["date"] = "year"  # a weather file is a year
    errors: list[str] = []
    year = data.pop("year", 2025)
    if year_problem(year):
        errors.append(_at(lines, ("year",), f"year = {year!r}: {year_problem(year)}"))
        year = 2025
    sweep = data.pop("sweep", None) or {}
    if not isinstance(sweep, dict):
        errors.append(_at(lines, ("sweep",), "sweep: expected a mapping of field paths to lists or ranges"))
        sweep = {}
    # Each axis: dotted field path -> (name in messages, key path in the YAML, its spec).
    specs = {path: (path, tuple(path.split(".")), value) for path, value in _listed_leaves(data)}
    for path, value in sweep.items():
        specs[str(path)] = (f"sweep.{path}", ("sweep", str(path)), value)
    axes = []
    for path, (source, yaml_path, spec) in specs.items():
        if path in UNSWEPT:
            errors.append(_at(lines, yaml_path, f"{source}: the study's {path} labels its results, it is not "
                                                f"sweepable; give one {path}"))
            continue
        try:
            values = _axis_values(path, spec, year)
        except ValueError as error:
            errors.append(_at(lines, yaml_path, f"{source}: {error}"))
            continue
        axes.append((path, tuple(values)))
    if errors:
        raise ConfigError(errors)

    plan = Plan(data, tuple(axes))
    if data.get("objective") is not None and "date" not in dict(axes):
        raise ConfigError([_at(lines, ("objective",), "objective: one fold angle for several days needs several "
                                                      "dates (a date range, 'year', or a weather file)")])
    if plan.n_cases > MAX_CASES:
        raise ConfigError([f"sweep: {plan.n_cases:,} cases; the limit is {MAX_CASES:,} (FOLDOPT_MAX_CASES raises it)"])
    first = {path: values[0] for path, values in axes}
    labels = {path: (f"{specs[path][0]}[0]", specs[path][1] + (0,)) for path in first}
    errors += _validation_errors(plan, first, lines, labels)
    for path, values in axes:
        source, yaml_path, _ = specs[path]
        for index, value in enumerate(values[1:], start=1):
            where = {path: (f"{source}[{index}]", yaml_path + (index,))}
            errors += _validation_errors(plan, {**first, path: value}, lines, where)
    if errors:
        raise ConfigError(_collapse(list(dict.fromkeys(errors))))
    _check_size(plan)
    return plan


def _check_size(plan: Plan) -> None:
    """Refuse a plan whose work or memory would exceed the limits, before any work."""
    axes = dict(plan.axes)
    base = plan.base
    angles = len(base.fold_angles.grid())
    steps = round(24 * 60 / base.step_min)
    loads = len(axes.get("p_load", (None,)))
    site_days = plan.n_cases // loads
    evaluations = site_days * angles * steps
    if evaluations > MAX_EVALUATIONS:
        raise ConfigError([f"study: {site_days:,} site-days x {angles} fold angles x {steps:,} steps = "
                           f"{evaluations:.2g} evaluations; the limit is {MAX_EVALUATIONS:.2g} (a coarser "
                           "fold_angles or step_min, fewer cases, or FOLDOPT_MAX_EVALUATIONS)"])
    if base.objective is not None and "date" in axes:
        cells = len(axes["date"]) * angles * loads
        if cells > MAX_ANNUAL_CELLS:
            raise ConfigError([f"objective: {len(axes['date'])} days x {angles} fold angles x {loads} loads = "
                               f"{cells:.2g} values held at once; the limit is {MAX_ANNUAL_CELLS:.2g} (fewer loads "
                               "or angles, or FOLDOPT_MAX_ANNUAL_CELLS)"])


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
            for message in _format_error(item):
                loc = tuple(str(part) for part in item["loc"])
                for path, (label, yaml_path) in where.items():
                    if ".".join(loc).startswith(path):
                        message = message.replace(".".join(loc), label, 1)
                        loc = yaml_path
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


def _yaml_lines(node, path=(), out=None) -> dict:
    """Map every key path of a composed YAML node to its 1-based line."""
    out = {} if out is None else out
    if isinstance(node, yaml.MappingNode):
        for key, value in node.value:
            child = path + (str(key.value),)
            out[child] = key.start_mark.line + 1
            _yaml_lines(value, child, out)
    elif isinstance(node, yaml.SequenceNode):
        for index, item in enumerate(node.value):
            out[path + (str(index),)] = item.start_mark.line + 1
            _yaml_lines(item, path + (str(index),), out)
    return out


def load_plan(path: Path | str) -> Plan:
    """Read and validate a YAML study (with any sweep axes); raises :class:`ConfigError`."""
    return make_plan(*read_study(path))


def read_study(path: Path | str) -> tuple:
    """The data of a YAML study file and the line of each of its keys; a relative weather path is
    made relative to the file. Raises :class:`ConfigError` for a file that :func:`read_input`
    refuses (larger than :data:`MAX_STUDY_BYTES`...) or that is not a plain YAML study
    (:class:`StudyLoader`)."""
    path = Path(path)
    data, lines = parse_study_text(read_input(path, "config", MAX_STUDY_BYTES, "MAX_STUDY_BYTES"), str(path))
    if isinstance(data, dict):
        data = _resolve_weather_path(data, path.parent)
    return data, lines


def parse_study_text(text: str, source: str = "config") -> tuple:
    """YAML text of a study (or one ``--set`` value) -> ``(data, lines)``; :class:`ConfigError` with
    the line for anything :class:`StudyLoader` refuses."""
    loader = StudyLoader(text)
    try:
        node = loader.get_single_node()
        data = loader.construct_document(node) if node is not None else None
    except yaml.YAMLError as error:
        where = getattr(error, "problem_mark", None)
        line = f" at line {where.line + 1}" if where is not None else ""
        problem = getattr(error, "problem", None) or "malformed YAML"
        raise ConfigError([f"config: {source}{line}: {problem}"]) from None
    except RecursionError:
        raise ConfigError([f"config: {source}: nested too deeply"]) from None
    finally:
        loader.dispose()
    return data, (_yaml_lines(node) if node is not None else {})


def _resolve_weather_path(data: dict, folder: Path) -> dict:
    """A study file's relative weather path is relative to the file, not to the working folder."""
    weather = data.get("weather")
    spec = weather.get("path") if isinstance(weather, dict) else weather
    if isinstance(spec, str) and not Path(spec).is_absolute() and (folder / spec).is_file():
        resolved = str(folder / spec)
        data = {**data, "weather": {**weather, "path": resolved} if isinstance(weather, dict) else resolved}
    return data


def load_study(path: Path | str) -> Study:
    """Read a YAML study that has no sweep axes; raises :class:`ConfigError`."""
    plan = load_plan(path)
    if plan.axes:
        raise ConfigError([f"config: {path} sweeps {', '.join(p for p, _ in plan.axes)}; run it with `foldopt run`"])
    return plan.base


def default_study_path(name: str = DEFAULT_STUDY) -> Path:
    """Path of a study shipped with foldopt (``configs/`` of the checkout or of the wheel)."""
    packaged = Path(__file__).with_name("configs") / f"{name}.yaml"
    if packaged.exists():
        return packaged
    return Path(__file__).resolve().parent.parent / "configs" / f"{name}.yaml"
