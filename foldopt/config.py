"""Study configuration: a validated, typed description of one foldopt study.

A study is written in YAML (see ``configs/``) or assembled from command-line options; both paths
go through :class:`Study`, so a bad value gets the same message either way: the field's path, the
value and the allowed range.
"""

from __future__ import annotations

import datetime as dt
import math
import re
import zoneinfo
from pathlib import Path
from typing import Annotated, Literal

import yaml
from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from foldopt.aggregation import CONNECTIONS
from foldopt.atmosphere import SKY_MODELS
from foldopt.geometry import GEOMETRIES, default_orientation
from foldopt.pvmodel import PV_MODELS, TEMPERATURE_MODELS, cec_module
from foldopt.solarposition import MODES
from foldopt.tracker import TRACKERS

DEFAULT_STUDY = "shin2015"
_OFFSET = re.compile(r"^(?:UTC)?([+-])(\d{1,2})(?::?(\d{2}))?$")


class ConfigError(ValueError):
    """A study that cannot be run; ``errors`` holds one ``field: problem`` line per fault."""

    def __init__(self, errors: list[str]):
        super().__init__("; ".join(errors))
        self.errors = errors


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
    latitude: _interval(-90, 90, unit=" deg")
    longitude: _interval(-180, 180, unit=" deg")
    altitude: _interval(-500, 9000, unit=" m") = 0.0
    timezone: Annotated[str | None, AfterValidator(_check_timezone)] = Field(
        None, description="IANA name or UTC offset; default: the longitude's standard offset"
    )


class Panel(_Strict):
    area: _interval(0, 1000, lo_open=True, unit=" m^2")
    efficiency: _interval(0, 1, lo_open=True) = 0.2
    tilt: _interval(0, 90, unit=" deg") | None = Field(None, description="default |latitude|")
    azimuth: _interval(0, 360, hi_open=True, unit=" deg") | None = Field(
        None, description="default: facing the equator"
    )


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


class Study(_Strict):
    name: Annotated[str, Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9._-]*$", max_length=100)]
    description: str = ""
    mode: Literal[MODES] = "exact"
    site: Site
    date: dt.date
    panel: Panel
    p_load: _interval(0, 1e6, lo_open=True, unit=" W")
    geometry: Literal[GEOMETRIES] | None = Field(
        None, description="twofold parametrisation; default azimuth-split in paper mode, hinge in exact"
    )
    fold_angles: FoldAngles = FoldAngles()
    sky: Literal[SKY_MODELS] = "meinel"
    pv_model: Literal[PV_MODELS] = "ideal"
    module: str | None = Field(None, description="single-diode: CEC module name; default the A-300 cell")
    connection: Literal[CONNECTIONS] = "switching"
    switch_series: bool = Field(False, description="switching may also select series")
    bypass_diodes: bool = True
    converter_efficiency: _interval(0, 1, lo_open=True) = 1.0
    temperature_model: Literal[TEMPERATURE_MODELS] | None = Field(
        None, description="default fixed (cells at temp_air) in paper mode, sapm in exact"
    )
    temp_air: _interval(-60, 60, unit=" C") = 25.0
    wind_speed: _interval(0, 60, unit=" m/s") = 1.0
    exact_electrical: bool = Field(False, description="solve every step's I-V curves, not tables")
    tracker: Literal[TRACKERS] = "dual-axis"
    step_min: Annotated[_interval(0, 60, lo_open=True, unit=" min"), AfterValidator(_check_step_min)] = 1.0

    @field_validator("module")
    @classmethod
    def _module_is_known(cls, module, info: ValidationInfo):
        if module is not None:
            if info.data.get("pv_model") != "single-diode":
                raise ValueError("module is only used with pv_model single-diode")
            cec_module(module)
        return module

    def resolved(self) -> Study:
        """The study with every default that depends on other fields (site, mode) filled in.

        Studies are kept unresolved so that a variant (another mode, another latitude) gets its
        own defaults; :class:`foldopt.study.Day` resolves the study it runs.
        """
        tilt, azimuth = default_orientation(self.site.latitude)
        panel = self.panel.model_copy(
            update={
                "tilt": tilt if self.panel.tilt is None else self.panel.tilt,
                "azimuth": azimuth if self.panel.azimuth is None else self.panel.azimuth,
            }
        )
        timezone = self.site.timezone
        if timezone is None:
            hours = round(self.site.longitude / 15.0)
            timezone = f"UTC{'+' if hours >= 0 else '-'}{abs(hours):02d}:00"
        geometry = self.geometry or ("azimuth-split" if self.mode == "paper" else "hinge")
        temperature = self.temperature_model or ("fixed" if self.mode == "paper" else "sapm")
        return self.model_copy(
            update={
                "panel": panel,
                "site": self.site.model_copy(update={"timezone": timezone}),
                "geometry": geometry,
                "temperature_model": temperature,
            }
        )


def _format_errors(error: ValidationError) -> list[str]:
    lines = []
    for item in error.errors():
        field = ".".join(str(part) for part in item["loc"]) or "study"
        message = item["msg"].removeprefix("Value error, ")
        if item["type"] == "missing":
            lines.append(f"{field}: required field is missing")
        elif item["type"] == "extra_forbidden":
            lines.append(f"{field}: unknown field")
        elif isinstance(item["input"], dict):
            lines.append(f"{field}: {message}")
        else:
            lines.append(f"{field} = {item['input']!r}: {message}")
    return lines


def make_study(data: dict) -> Study:
    """Validate a study from plain data; raises :class:`ConfigError` listing every fault."""
    if not isinstance(data, dict):
        raise ConfigError([f"study: expected a mapping of fields, got {type(data).__name__}"])
    try:
        return Study.model_validate(data)
    except ValidationError as error:
        raise ConfigError(_format_errors(error)) from None


def load_study(path: Path | str) -> Study:
    """Read and validate a YAML study; raises :class:`ConfigError` with a one-line reason."""
    path = Path(path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise ConfigError([f"config: file not found: {path}"]) from None
    except (IsADirectoryError, PermissionError, UnicodeDecodeError) as error:
        raise ConfigError([f"config: cannot read {path}: {error.__class__.__name__}"]) from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as error:
        where = getattr(error, "problem_mark", None)
        line = f" at line {where.line + 1}" if where is not None else ""
        problem = getattr(error, "problem", None) or "malformed YAML"
        raise ConfigError([f"config: {path}{line}: {problem}"]) from None
    return make_study(data)


def default_study_path(name: str = DEFAULT_STUDY) -> Path:
    """Path of a study shipped with foldopt (``configs/`` of the checkout or of the wheel)."""
    packaged = Path(__file__).with_name("configs") / f"{name}.yaml"
    if packaged.exists():
        return packaged
    return Path(__file__).resolve().parent.parent / "configs" / f"{name}.yaml"
