"""The ``weather`` section of a study: an hourly typical year or a measured sub-hourly file, and
the options of each kind (:class:`Weather`). Like the other sections it validates and opens no
file (:mod:`foldopt.inputs.sections`).

The module may import pydantic, :mod:`foldopt.names` and :mod:`foldopt.inputs.sections`. It says
which addresses a weather source is asked at (:func:`address_problem`).
"""

from __future__ import annotations

import datetime as dt
import re
from typing import Annotated
from urllib.parse import urlsplit

from pydantic import AfterValidator, Field, ValidationInfo, field_validator, model_validator

from foldopt import names
from foldopt.inputs.fields import StrictModel, interval, named
from foldopt.inputs.sections import parse_timezone


def _check_offset(name: str | None) -> str | None:
    if name is not None and not isinstance(parse_timezone(name), dt.timezone):
        raise ValueError(
            f"{name!r}: a measured file's standard time is a fixed offset such as 'UTC-07:00'"
        )
    return name


def _check_years(years: str | None) -> str | None:
    if years is None:
        return None
    found = re.fullmatch(r"\s*(\d{4})\s*:\s*(\d{4})\s*", str(years))
    if found is None:
        raise ValueError("the first and last year as START:END, e.g. 2005:2020")
    start, end = int(found.group(1)), int(found.group(2))
    if start > end:
        raise ValueError("the first year comes after the last")
    return f"{start}:{end}"


def _check_database(name: str | None) -> str | None:
    if name is not None and not re.fullmatch(r"PVGIS-[A-Za-z0-9]+", name):
        raise ValueError("a PVGIS radiation database, e.g. PVGIS-SARAH3 or PVGIS-ERA5")
    return name


#: The schemes a weather source is asked over.
SCHEMES = ("http", "https")


def address_problem(url: str) -> str | None:
    """Why ``url`` is no base address a weather source can be asked at (a scheme of
    :data:`SCHEMES`, a host, a port that is a number, no space or control character), or None.

    Parameters
    ----------
    url : str

    Returns
    -------
    str or None
        One phrase, for a line that names where the address came from.
    """
    accepted = "give an http:// or https:// base address (a mirror's)"
    try:
        parts = urlsplit(url)
        parts.port  # noqa: B018 - read for its check: a port that is no number raises
    except ValueError as error:
        return f"not an address ({error}); {accepted}"
    if parts.scheme.lower() not in SCHEMES:
        scheme = f"the scheme {parts.scheme}://" if parts.scheme else "an address without a scheme"
        return f"{scheme} is not supported; {accepted}"
    if not parts.hostname:
        return f"names no host; {accepted}"
    if re.search(r"[\s\x00-\x1f\x7f]", url):
        return f"holds a space or a control character; {accepted}"
    return None


def _check_url(url: str | None) -> str | None:
    problem = None if url is None else address_problem(url)
    if problem is not None:
        raise ValueError(problem)
    return url


class Weather(StrictModel):
    """A weather file, read through pvlib.iotools (:mod:`foldopt.inputs.weather`): an hourly
    typical year (TMY3, EPW, PVGIS TMY), brought to the study's step, or a measured sub-hourly
    file (SURFRAD, MIDC, SRML, BSRN, SOLRAD, CRN, a CSV), evaluated at its own; or a weather
    source, a public service's answer for the study's site, fetched and cached
    (:mod:`foldopt.inputs.weather.sources`), then read as the file it is.

    Parameters
    ----------
    path : str, optional
        The file; a study file's relative path is relative to the study file. With a
        ``source``, the cached answer (filled in when the study is planned).
    format : str, optional
        One of :data:`foldopt.names.WEATHER_FORMATS`; default from the extension (hourly formats;
        a measured file names its format).
    label : str, optional
        What a timestamp marks, one of :data:`foldopt.names.INTERVAL_LABELS`; default the format's.
    timezone : str, optional
        A measured file's standard time, a fixed offset (``UTC-07:00``): default the file's, else
        the offset nearest longitude / 15 h; it also places a CSV's stamps that carry none.
    decomposition : str
        How a measured file's ``dni`` and ``dhi`` come from ``ghi`` alone, one of
        :data:`foldopt.names.DECOMPOSITIONS`; default ``erbs``.
    max_gap_min : float
        A measured file's longest daylight gap filled along the clear-sky index [min]; a day with
        a longer one is left out of the study's days (and refused where asked for). Default 60.
    members : int, optional
        An hourly file's cloud ensemble: this many synthetic minute series of each hour
        (:mod:`foldopt.inputs.weather.ensemble`), 2 to 200; default none (the smooth minutes).
    seed : int
        The ensemble's seed; the same seed gives the same members. Default 0.
    source : str, optional
        One of :data:`foldopt.names.WEATHER_SOURCES`: the site's weather from that service.
    years : str, optional
        A source's years ``START:END`` (PVGIS TMY: the years its months are chosen from, at
        least 10; PVGIS hourly: the series' years); default the service's whole record.
    usehorizon : bool
        A source's light with the terrain's horizon shading it (PVGIS's DEM); default True.
    raddatabase : str, optional
        ``pvgis-hourly``'s radiation database (``PVGIS-SARAH3``, ``PVGIS-ERA5``); default the
        service's for the site.
    url : str, optional
        A source's base address (a mirror, a proxy); default ``FOLDOPT_PVGIS_URL``, else the
        service's pinned versioned address.
    timeout_s : float
        Seconds a source's fetch waits at most for the service's whole answer (connecting, every
        read, every retry), in (0, 600]; default 30.
    """

    path: str | None = Field(None, description="the file; with a source, its cached answer")
    format: named(names.WEATHER_FORMATS) | None = Field(
        None,
        description="default from the extension (hourly formats); a measured file names its format",
    )
    label: named(names.INTERVAL_LABELS) | None = Field(
        None,
        description="what a timestamp marks; default the format's (TMY3 end, EPW and PVGIS start)",
    )
    timezone: Annotated[str | None, AfterValidator(_check_offset)] = Field(
        None, description="a measured file's standard time, e.g. UTC-07:00; default the file's"
    )
    decomposition: named(names.DECOMPOSITIONS) = Field(
        "erbs", description="a measured file's dni and dhi from ghi"
    )
    max_gap_min: interval(0, 1440, unit=" min") = 60.0
    members: Annotated[int, Field(ge=2, le=200)] | None = Field(
        None, description="an hourly file's cloud ensemble of this many members"
    )
    seed: Annotated[int, Field(ge=0)] = 0
    source: named(names.WEATHER_SOURCES) | None = Field(
        None, description="weather fetched for the site from a public service"
    )
    years: Annotated[str | None, AfterValidator(_check_years)] = Field(
        None, description="a source's years START:END; default the service's record"
    )
    usehorizon: bool = True
    raddatabase: Annotated[str | None, AfterValidator(_check_database)] = Field(
        None, description="pvgis-hourly's radiation database; default PVGIS's for the site"
    )
    url: Annotated[str | None, AfterValidator(_check_url)] = Field(
        None, description="a source's base address; default FOLDOPT_PVGIS_URL or the pinned one"
    )
    timeout_s: interval(0, 600, lo_open=True, unit=" s") = 30.0

    @property
    def measured(self) -> bool:
        """Whether the file is a measured one (its format is not an hourly one)."""
        return self.format is not None and self.format not in names.HOURLY_WEATHER_FORMATS

    @field_validator("timezone", "decomposition", "max_gap_min")
    @classmethod
    def _measured_only(cls, value, info: ValidationInfo):
        fmt = info.data.get("format")
        if value != cls.model_fields[info.field_name].default and (
            fmt is None or fmt in names.HOURLY_WEATHER_FORMATS
        ):
            measured = ", ".join(
                f for f in names.WEATHER_FORMATS if f not in names.HOURLY_WEATHER_FORMATS
            )
            raise ValueError(f"is only used by measured weather files (format {measured})")
        return value

    @field_validator("members")
    @classmethod
    def _hourly_only(cls, value, info: ValidationInfo):
        fmt = info.data.get("format")
        if value is not None and fmt is not None and fmt not in names.HOURLY_WEATHER_FORMATS:
            raise ValueError(
                "a cloud ensemble is drawn from an hourly file; a measured file's minutes are its own"
            )
        return value

    @field_validator("seed")
    @classmethod
    def _ensemble_only(cls, value, info: ValidationInfo):
        if value != 0 and info.data.get("members") is None:
            raise ValueError("is only used by a cloud ensemble (weather.members)")
        return value

    @model_validator(mode="after")
    def _file_or_source(self):
        if self.path is None and self.source is None:
            raise ValueError(
                "give a weather file (weather.path, --weather FILE) or a source (weather.source, "
                f"--weather NAME: {', '.join(names.WEATHER_SOURCES)})"
            )
        defaults = {
            "years": None,
            "usehorizon": True,
            "raddatabase": None,
            "url": None,
            "timeout_s": 30.0,
        }
        given = [key for key, value in defaults.items() if getattr(self, key) != value]
        if self.source is None and given:
            raise ValueError(
                f"weather.{given[0]} is only used by a weather source (weather.source: "
                f"{', '.join(names.WEATHER_SOURCES)})"
            )
        if self.raddatabase is not None and self.source not in (None, "pvgis-hourly"):
            raise ValueError("weather.raddatabase is only used by the pvgis-hourly source")
        return self
