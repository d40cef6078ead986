"""A study: one validated, typed description of what foldopt evaluates (:class:`Study`).

A study is written in YAML (see ``configs/``) or assembled from command-line options; both paths
go through :class:`Study`, so a bad value gets the same message either way: the field's path, the
value and the allowed range (:func:`format_errors`). Its parts are the models of
:mod:`foldopt.inputs.sections`. The models open no files: a weather file's site and a load profile
file's day are read by :func:`foldopt.inputs.study_file.resolve_files` and handed to the validation as a
:class:`~foldopt.inputs.sections.FilesRead`.
"""

from __future__ import annotations

import math
from typing import Annotated

from pydantic import (
    AfterValidator,
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from foldopt import names
from foldopt.errors import ConfigError
from foldopt.inputs import policy
from foldopt.inputs.circuit_section import Circuit
from foldopt.inputs.fields import FilesRead, StrictModel, StudyDate, interval, named
from foldopt.inputs.optimize_section import Optimize
from foldopt.inputs.pvwatts_section import PVWatts
from foldopt.inputs.sections import (
    FoldAngles,
    LoadProfile,
    NearOptimal,
    Objective,
    Panel,
    Site,
    Tracker,
    default_orientation,
    planes_panel,
)
from foldopt.inputs.costs_section import Costs, costs_problem
from foldopt.inputs.storage_section import Storage
from foldopt.inputs.weather_section import Weather

#: Each mode's default clear sky: pvlib's Ineichen (with diffuse light, Perez transposition at the
#: site's Linke turbidity) in exact mode, the paper's beam-only Meinel sky in paper mode.
MODE_SKIES = {"exact": "ineichen", "paper": "meinel"}
#: What each mode decides where a study gives none: its sky, geometry, PV model and temperature
#: model. Exact mode's PV model is PVWatts' with SAPM cells and a small panel's system losses: the
#: power a real panel gives (docs/validation.rst); paper mode's the paper's ideal one.
MODE_DEFAULTS = {
    "sky": MODE_SKIES,
    "geometry": {"paper": "azimuth-split", "exact": "hinge"},
    "pv_model": {"paper": "ideal", "exact": "pvwatts"},
    "temperature_model": {"paper": "fixed", "exact": "sapm"},
}
SITE_TOLERANCE_KM = 5.0  # [km] a study's site may lie this far from its weather file's
EARTH_RADIUS_KM = 6371.0
#: The site of a study whose weather file is not read yet (built in Python): None until
#: :func:`foldopt.inputs.study_file.with_files` reads it.
_UNREAD = object()


def _as_tuple(value) -> tuple:
    """A default as a tuple of its accepted values."""
    return value if isinstance(value, tuple) else (value,)


def great_circle_km(latitude_1, longitude_1, latitude_2, longitude_2) -> float:
    """Distance between two points on a spherical Earth (haversine).

    Parameters
    ----------
    latitude_1, longitude_1, latitude_2, longitude_2 : float
        The two points [deg].

    Returns
    -------
    float
        The great-circle distance [km] on a sphere of :data:`EARTH_RADIUS_KM`.
    """
    phi_1, phi_2 = math.radians(latitude_1), math.radians(latitude_2)
    half_dphi = (phi_2 - phi_1) / 2
    half_dlambda = math.radians(longitude_2 - longitude_1) / 2
    a = math.sin(half_dphi) ** 2 + math.cos(phi_1) * math.cos(phi_2) * math.sin(half_dlambda) ** 2
    return 2 * EARTH_RADIUS_KM * math.asin(min(1.0, math.sqrt(a)))


def _file_site(data: dict, info: ValidationInfo) -> dict | None:
    """The site a study's weather file holds, as read for this validation; None where no file is
    named or read, or where it holds none."""
    weather = data.get("weather")
    path = weather if isinstance(weather, str) else (weather or {}).get("path")
    files = FilesRead.given(info) if isinstance(path, str) else None
    return files.weather_site if files is not None else None


def _near(site: dict, read: dict) -> bool:
    """Whether a given site is the file's place: within :data:`SITE_TOLERANCE_KM` of it."""
    try:
        return (
            great_circle_km(
                float(site["latitude"]),
                float(site["longitude"]),
                float(read["latitude"]),
                float(read["longitude"]),
            )
            <= SITE_TOLERANCE_KM
        )
    except (KeyError, TypeError, ValueError):
        return False  # the site's own validation names what is wrong with it


def _check_step_min(value: float) -> float:
    if not math.isclose(1440 / value, round(1440 / value)):
        raise ValueError("must divide the 1440 min of a day (e.g. 0.5, 1, 2, 5, 10, 15, 30, 60)")
    return value


class Study(StrictModel):
    """One study: a panel at a site on a day (or the days of a weather file), its load, and the
    physics and designs it is evaluated with.

    A study is resolved when it is validated: every default that depends on other fields (the
    panel's tilt and azimuth and the site's time zone from the site, the geometry, temperature
    model and sky from the mode) is decided then, once, and nothing downstream decides it again.
    What was decided is no setting of the user's: :meth:`data` leaves it out, so a variant (another
    latitude, another mode) decides its own. A study whose weather file is unread (built in
    Python) has no site yet, so its panel's orientation waits for :func:`foldopt.inputs.study_file.with_files`.

    Parameters
    ----------
    name : str
        Letters, digits, ``.``, ``_`` and ``-``, at most 100 characters: it names the results.
    description : str
    mode : {'exact', 'paper'}
        pvlib's physics, or Shin et al.'s formulas (beam only, Eq. 1-6).
    site : Site
        Default with a weather file: the file's own site; ``None`` while that file is unread.
    force_site : bool
        Keep a site more than :data:`SITE_TOLERANCE_KM` [km] from the weather file's.
    date : datetime.date
        The local day.
    panel : Panel
    p_load : float
        The load [W] in (0, 1e6]; with a ``load_profile``, the profile's scale [-] (default 1).
    load_profile : LoadProfile, optional
    storage : Storage, optional
        A buffer behind a charge controller; default none: the storage-less study, its answers
        ``t_solar``'s.
    costs : Costs, optional
        Prices [USD] of panel, buffer, hinge and tracker drive: the cheapest panel and buffer of
        each kind meeting ``storage.target`` (:mod:`foldopt.studies.least_cost`); default none.
    geometry : str, optional
        One of :data:`foldopt.names.GEOMETRIES`; default azimuth-split in paper mode, hinge in exact.
    fold_angles : FoldAngles
    near_optimal : NearOptimal
    sky : str, optional
        One of :data:`foldopt.names.SKIES` (no use with a weather file); default ``ineichen`` in
        exact mode (with Perez transposition at the site's Linke turbidity), ``meinel`` (the
        paper's beam-only sky) in paper mode.
    linke_turbidity : float, optional
        [-] in (0, 10] for ``ineichen``; default pvlib's climatology.
    transposition : str, optional
        One of :data:`foldopt.names.TRANSPOSITIONS`; default none for beam-only skies, perez otherwise.
    albedo : float
        [-] in [0, 1]; default 0.2.
    iam : str
        One of :data:`foldopt.names.IAMS`; default ``none``.
    weather : Weather, optional
        A weather file (or its path): its site, year and light.
    objective : Objective, optional
        One fold angle for all of the study's days, chosen for this statistic.
    pv_model : str, optional
        One of :data:`foldopt.names.PV_MODELS`; default ``pvwatts`` in exact mode, ``ideal`` (the
        paper's) in paper mode.
    module : str, optional
        ``single-diode``: a CEC module name; default the A-300 cell.
    pvwatts : PVWatts
        ``pvwatts``: the rating, temperature coefficient and system losses; default PVWatts'
        losses for one small panel (:data:`foldopt.inputs.pvwatts_section.LOSSES`).
    connection : str
        One of :data:`foldopt.names.CONNECTIONS`; default ``switching``.
    switch_series, bypass_diodes, exact_electrical : bool
        Switching may select series; the series string has bypass diodes; every step's I-V
        curves are solved rather than tabled.
    converter_efficiency : float
        ``independent`` with ideal converters: [-] in (0, 1]; default 1.
    circuit : Circuit
        Diodes, converter, coupling to the load and switch as built; default Shin et al.'s ideal parts.
    temperature_model : str, optional
        One of :data:`foldopt.names.TEMPERATURE_MODELS`; default fixed in paper mode, sapm in exact.
    temp_air : float
        [C] in [-60, 60]; default 25 (a weather file brings its own).
    wind_speed : float
        [m/s] in [0, 60]; default 1.
    tracker : Tracker
    climate : str
        Hottel sky only: one of :data:`foldopt.names.HOTTEL_CLIMATES`.
    step_min : float
        The time step [min] in (0, 60], dividing a day (and an hour, with a weather file); default 1.

    Raises
    ------
    pydantic.ValidationError
        For every fault (:func:`make_study` turns them into a :class:`foldopt.ConfigError`).
    """

    name: Annotated[str, Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9._-]*$", max_length=100)]
    description: str = ""
    mode: named(names.MODES) = "exact"
    # None: unread
    site: Site = Field(description="default with a weather file: the file's own site")
    force_site: bool = Field(
        False, description="keep a site more than SITE_TOLERANCE_KM from the weather file's"
    )
    date: StudyDate
    panel: Panel
    p_load: interval(0, 1e6, lo_open=True, unit=" W") = Field(
        description="the load [W]; with a load_profile, the profile's scale [-]"
    )
    load_profile: LoadProfile | None = None
    storage: Storage | None = Field(
        None, description="a buffer behind a charge controller; default none (storage-less)"
    )
    costs: Costs | None = Field(
        None, description="prices [USD] for the least-cost panel and buffer; default none"
    )
    geometry: named(names.GEOMETRIES) | None = Field(
        None,
        validate_default=True,
        description="twofold parametrisation; default azimuth-split in paper mode, hinge in exact",
    )
    fold_angles: FoldAngles = FoldAngles()
    near_optimal: NearOptimal = NearOptimal()
    sky: named(names.SKIES) | None = Field(
        None,
        validate_default=True,
        description="clear sky; default ineichen in exact mode, meinel (the paper's beam-only) in paper",
    )
    linke_turbidity: interval(0, 10, lo_open=True) | None = Field(
        None, description="ineichen; default pvlib's climatology"
    )
    transposition: named(names.TRANSPOSITIONS) | None = Field(
        None, description="diffuse model; default none for beam-only skies, perez otherwise"
    )
    albedo: interval(0, 1) = 0.2
    iam: named(names.IAMS) = "none"
    weather: Weather | None = None
    objective: Objective | None = None
    pv_model: named(names.PV_MODELS) | None = Field(
        None, validate_default=True, description="default pvwatts in exact mode, ideal in paper"
    )
    module: str | None = Field(
        None, description="single-diode: CEC module name; default the A-300 cell"
    )
    pvwatts: PVWatts = Field(
        PVWatts(), description="pvwatts: rating, temperature coefficient and system losses"
    )
    connection: named(names.CONNECTIONS) = "switching"
    switch_series: bool = Field(False, description="switching may also select series")
    bypass_diodes: bool = True
    converter_efficiency: interval(0, 1, lo_open=True) = 1.0
    circuit: Circuit = Field(
        Circuit(), description="diodes, converter, coupling and switch as built; default ideal"
    )
    optimize: Optimize | None = Field(
        None, description="the fold angle, tilt and azimuth optimised together (foldopt optimize)"
    )
    temperature_model: named(names.TEMPERATURE_MODELS) | None = Field(
        None,
        validate_default=True,
        description="default fixed (cells at temp_air) in paper mode, sapm in exact",
    )
    temp_air: interval(-60, 60, unit=" C") = 25.0
    wind_speed: interval(0, 60, unit=" m/s") = 1.0
    exact_electrical: bool = Field(False, description="solve every step's I-V curves, not tables")
    tracker: Tracker = Tracker()
    climate: named(names.HOTTEL_CLIMATES) = Field(
        "midlatitude-summer", description="Hottel sky only"
    )
    step_min: Annotated[
        interval(0, 60, lo_open=True, unit=" min"), AfterValidator(_check_step_min)
    ] = 1.0

    @model_validator(mode="before")
    @classmethod
    def _profile_scale(cls, data):
        """A load profile is in watts: its scale defaults to 1."""
        if (
            isinstance(data, dict)
            and data.get("load_profile") is not None
            and data.get("p_load") is None
        ):
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
    def _site_from_weather(cls, data, info: ValidationInfo):
        """A weather file brings its site, as its loader read it, and completes a site given in
        part: the fields given win, the rest (the station's name, its altitude, its time zone) are
        the file's. A site moved beyond :data:`SITE_TOLERANCE_KM` from the file's is another place,
        none of whose fields the file knows (it is refused there, unless ``force_site``)."""
        site = data.get("site") if isinstance(data, dict) else None
        partial = isinstance(site, dict) and not {"latitude", "longitude"} & set(site)
        if isinstance(data, dict) and isinstance(site, dict) and not partial:
            read = _file_site(data, info)
            if read is not None and _near(site, read):
                data = {**data, "site": {**read, **site}}
        if isinstance(data, dict) and (site is None or partial) and data.get("weather") is not None:
            weather = data["weather"]
            path = (
                weather
                if isinstance(weather, str)
                else weather.get("path")
                if isinstance(weather, dict)
                else None
            )
            if isinstance(path, str):
                files = FilesRead.given(info)
                if files is not None and files.weather_problem is not None:
                    raise ValueError(files.weather_problem)
                read = files.weather_site if files is not None else None
                if partial and read is not None:
                    data = {**data, "site": {**read, **site}}
                elif not partial:
                    data = {**data, "site": read if read is not None else _UNREAD}
        return data

    @field_validator("site", mode="wrap")
    @classmethod
    def _unread_site(cls, value, handler):
        """None for a weather file's site not read yet; a missing or null site is still refused."""
        return None if value is _UNREAD else handler(value)

    @field_validator("geometry", "sky", "pv_model", "temperature_model", mode="after")
    @classmethod
    def _mode_default(cls, value, info: ValidationInfo):
        """The mode's own geometry, sky, PV model and temperature model where the study gives
        none."""
        mode = info.data.get("mode")
        return value if value is not None or mode is None else MODE_DEFAULTS[info.field_name][mode]

    @field_validator("panel", mode="after")
    @classmethod
    def _facing_the_equator(cls, panel, info: ValidationInfo):
        """The panel at ``|latitude|`` toward the equator where the study gives no tilt or azimuth:
        decided from the site (validated before the panel), not given (its fields set say so)."""
        site = info.data.get("site")
        if site is None or panel.planes is not None:
            # a weather file's site not read yet: decided when it is; planes make their own
            return panel
        facing = dict(zip(("tilt", "azimuth"), default_orientation(site.latitude), strict=True))
        missing = {key: value for key, value in facing.items() if getattr(panel, key) is None}
        if not missing:
            return panel
        return Panel.model_construct(panel.model_fields_set, **{**dict(panel), **missing})

    @model_validator(mode="after")
    def _base_from_planes(self):
        """The base orientation the panel's planes make under the study's geometry, decided, not
        given (the panel's fields set say so); a tilt or azimuth given beside them must make the
        planes too (:func:`foldopt.inputs.sections.planes_panel`)."""
        panel = self.panel
        if panel.planes is None:
            return self
        given = {key: getattr(panel, key) for key in ("tilt", "azimuth")}
        tilt, azimuth, _, _ = planes_panel(panel.planes, self.geometry, **given)
        base = Panel.model_construct(
            panel.model_fields_set, **{**dict(panel), "tilt": tilt, "azimuth": azimuth}
        )
        object.__setattr__(self, "panel", base)  # frozen: the validation decides it once
        return self

    def planes_design(self) -> dict | None:
        """The twofold design the panel's planes are, as it stands; None without planes.

        Returns
        -------
        dict or None
            ``fold_angle`` [deg] and ``first_east`` (the first plane is the east half), at the
            panel's base orientation (:func:`foldopt.inputs.sections.planes_panel`).
        """
        panel = self.panel
        if panel.planes is None:
            return None
        _, _, fold_angle, first_east = planes_panel(
            panel.planes, self.geometry, panel.tilt, panel.azimuth
        )
        return {"fold_angle": fold_angle, "first_east": first_east}

    @property
    def decided(self) -> tuple[str, ...]:
        """The dotted paths of the fields the validation decided, not given: :meth:`data` leaves
        them out, so a variant (another latitude, another mode) decides its own."""
        paths = [name for name in MODE_DEFAULTS if name not in self.model_fields_set]
        if self.site is not None:
            paths += [
                f"panel.{key}"
                for key in ("tilt", "azimuth")
                if key not in self.panel.model_fields_set
            ]
            paths += ["site.timezone"] * ("timezone" not in self.site.model_fields_set)
        if self.storage is not None:
            paths += [f"storage.{name}" for name in self.storage.decided]
        return tuple(paths)

    @model_validator(mode="after")
    def _consistent(self, info: ValidationInfo):
        if self.mode == "paper" and self.transposition not in (None, "none"):
            raise ValueError(
                "transposition: paper mode is beam-only (Shin et al. Eq. 5): transposition must be none"
            )
        problem = costs_problem(self.costs, self.storage, self.pv_model, names.IV_MODELS)
        if problem:
            raise ValueError(problem)
        idle = self.idle_settings()
        if idle:
            raise ValueError("\n".join(idle))  # one error line each
        too_large = (
            self.optimize.size_problem(self.fold_angles) if self.optimize is not None else None
        )
        if too_large:
            raise ValueError(too_large)
        files = FilesRead.given(info) if self.weather is not None else None
        if files is not None and files.weather_missing:
            raise ValueError(files.weather_problem)
        if self.weather is not None and self.weather.members is not None:
            if self.objective is None:
                raise ValueError(
                    "weather.members: a cloud ensemble chooses one fold angle over its members; give an "
                    "objective (e.g. objective: mean)"
                )
            if self.objective.visits is not None:
                raise ValueError(
                    "objective.visits: re-fold schedules are not drawn over a cloud ensemble; leave out "
                    "weather.members or objective.visits"
                )
        measured = self.weather is not None and self.weather.measured
        if (
            self.weather is not None
            and not measured
            and not math.isclose(60 / self.step_min, round(60 / self.step_min))
        ):
            raise ValueError(
                f"step_min = {self.step_min:g}: must divide the weather file's 60-min intervals"
            )
        if (
            measured
            and files is not None
            and files.weather_step_min is not None
            and not math.isclose(self.step_min, files.weather_step_min)
        ):
            raise ValueError(
                f"step_min = {self.step_min:g}: a measured weather file is evaluated at its own step, "
                f"{files.weather_step_min:g} min; leave step_min out or set it to that"
            )
        checked = files is not None and not self.force_site
        if checked and files.weather_problem is not None:
            raise ValueError(files.weather_problem)
        file_site = files.weather_site if checked else None
        if file_site is not None and self.site is not None:
            distance = great_circle_km(
                self.site.latitude,
                self.site.longitude,
                file_site["latitude"],
                file_site["longitude"],
            )
            if distance > SITE_TOLERANCE_KM:
                name = f"{file_site['name']} " if file_site["name"] else ""
                raise ValueError(
                    f"site ({self.site.latitude:g}, {self.site.longitude:g}) is {distance:,.0f} km from the weather "
                    f"file's site {name}({file_site['latitude']:g}, {file_site['longitude']:g}); leave the site out "
                    f"to use the file's, or set force_site to keep it"
                )
        return self

    def idle_settings(self) -> list[str]:
        """Settings given a value that nothing in the study uses.

        Returns
        -------
        list of str
            ``field = value: why`` for each (the tracker's from :meth:`Tracker.idle_settings`).
        """
        defaults = {name: field.default for name, field in Study.model_fields.items()}
        # What a resolved study fills in is no setting of the user's.
        for name, by_mode in MODE_DEFAULTS.items():
            defaults[name] = (None, by_mode[self.mode])
        iv_model = self.pv_model in names.IV_MODELS
        warm_cells = self.pv_model != "ideal"
        cells = ", ".join(name for name in names.PV_MODELS if name != "ideal")
        series_used = self.connection == "series" or (
            self.connection == "switching" and self.switch_series
        )
        rules = [
            ("climate", self.sky == "hottel", "is only used by sky hottel"),
            (
                "linke_turbidity",
                self.sky == "ineichen" or self.weather is not None,
                "is only used by sky ineichen and weather files",
            ),
            (
                "sky",
                self.weather is None,
                "has no use with a weather file (its light shapes the minutes)",
            ),
            (
                "albedo",
                self.sky_transposition() != "none",
                "is only used with a transposition (diffuse light)",
            ),
            (
                "switch_series",
                self.connection == "switching",
                "is only used by connection switching",
            ),
            (
                "bypass_diodes",
                series_used,
                "is only used where series is (connection series, or switching with switch_series)",
            ),
            (
                "converter_efficiency",
                self.connection == "independent",
                "is only used by connection independent",
            ),
            (
                "converter_efficiency",
                self.circuit.converter.model == "ideal",
                "is the ideal converters' efficiency; circuit.converter sets every converter's",
            ),
            ("temperature_model", warm_cells, f"is only used by pv_model {cells}"),
            (
                "temp_air",
                warm_cells and self.weather is None,
                f"is only used by pv_model {cells}, without a weather file (which brings its own)",
            ),
            ("wind_speed", warm_cells, f"is only used by pv_model {cells}"),
            ("exact_electrical", iv_model, "is only used by pv_model single-diode or b-model"),
        ]
        idle = [
            f"{name} = {getattr(self, name)!r}: {why}"
            for name, used, why in rules
            if not used and getattr(self, name) not in _as_tuple(defaults[name])
        ]
        if self.pv_model != "pvwatts":
            idle += [
                f"pvwatts.{name} = {value!r}: is only used by pv_model pvwatts"
                for name, value in self.pvwatts.model_dump(exclude_defaults=True).items()
            ]
        circuit = self.circuit.idle_settings(
            self.connection, series_used and self.bypass_diodes, iv_model
        )
        optimize = self.optimize.idle_settings() if self.optimize is not None else []
        return idle + circuit + self.tracker.idle_settings() + optimize

    def pv_model_text(self) -> str:
        """The PV model as an answer's question names it: PVWatts' with its cells, temperature
        coefficient and losses (``pvwatts PV model (SAPM cells, -0.37 %/C, 8.7 % losses)``).

        Returns
        -------
        str
        """
        if self.pv_model != "pvwatts":
            return f"{self.pv_model} PV model"
        cells = (
            "SAPM cells" if self.temperature_model == "sapm" else "cells at the air's temperature"
        )
        pvwatts = self.pvwatts
        rating = "" if pvwatts.pdc0 is None else f"{pvwatts.pdc0:g} W, "
        return (
            f"pvwatts PV model ({rating}{cells}, {100 * pvwatts.gamma_pdc:.3g} %/C, "
            f"{pvwatts.losses:.2g} % losses)"
        )

    def sky_transposition(self) -> str:
        """The diffuse model in force.

        Returns
        -------
        str
            ``transposition``, or by default none for beam-only skies (and paper mode) unless a
            weather file gives diffuse light, perez otherwise.
        """
        if self.transposition is not None:
            return self.transposition
        return (
            "none"
            if self.mode == "paper" or (self.weather is None and self.sky in names.BEAM_SKIES)
            else "perez"
        )

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
            mode takes its own geometry and sky and a new latitude tilts the panel at
            ``|latitude|``, unless those fields are given; what the study decided itself (its
            temperature model, its time zone...) is decided again (:meth:`data` leaves it out).

        Returns
        -------
        Study
            Resolved, its files unread (:class:`~foldopt.inputs.sections.FilesRead`): the API
            reads them when it runs the study.

        Raises
        ------
        foldopt.ConfigError
            One ``field = value: problem`` line per fault.

        Examples
        --------
        >>> import foldopt
        >>> study = foldopt.default_study().variant(site={"latitude": 10.0})
        >>> study.mode, study.geometry, study.sky, study.panel.tilt, study.panel.efficiency
        ('exact', 'hinge', 'ineichen', 10.0, 0.1905)
        """
        data, _ = policy.apply(self.data(), changes)
        return make_study(data)

    def data(self) -> dict:
        """The study's fields as plain data that validate back into it.

        Returns
        -------
        dict
            ``date`` as text, no unset field and no decided default; a profile or a horizon read
            from a file keeps its file, not what was read from it.
        """
        data = self.model_dump(mode="json", exclude_none=True)
        for path in self.decided:
            section, _, name = path.rpartition(".")
            (data[section] if section else data).pop(name, None)
        if self.load_profile is not None and self.load_profile.read_daily:
            data["load_profile"].pop("daily", None)
        if (
            self.site is not None
            and self.site.horizon is not None
            and self.site.horizon.file is not None
        ):
            data["site"]["horizon"].pop("points", None)
        return data

    def require_files(self) -> None:
        """Refuse to run a study whose files are unread.

        Raises
        ------
        foldopt.ConfigError
            ``weather: the file is not read yet; ...`` (and for ``load_profile``):
            :func:`foldopt.inputs.study_file.with_files` reads them, as the API does.
        """
        unread = [
            f"{name}: the file is not read yet; foldopt.run, foldopt.sweep and foldopt.size read it"
            for name, missing in (
                ("weather", self.site is None),
                ("load_profile", self.load_profile is not None and self.load_profile.daily is None),
            )
            if missing
        ]
        if unread:
            raise ConfigError(unread)


def format_error(item: dict) -> list[str]:
    """The lines of one pydantic error.

    Parameters
    ----------
    item : dict
        One of :meth:`pydantic.ValidationError.errors`.

    Returns
    -------
    list of str
        ``field = value: problem`` (``field: problem`` for a section, a missing or an unknown
        field); the study's own checks, which name their fields themselves, one line each.
    """
    field = ".".join(str(part) for part in item["loc"])
    message = item["msg"].removeprefix("Value error, ")
    if not field:
        # The study's own checks name their fields themselves.
        return message.splitlines() if item["type"] == "value_error" else [f"study: {message}"]
    if item["type"] == "missing":
        return [f"{field}: required field is missing"]
    if item["type"] == "extra_forbidden":
        return [f"{field}: unknown field{_where_it_belongs(field)}"]
    if isinstance(item["input"], dict):
        return [f"{field}: {message}"]
    return [f"{field} = {_shown(item['input'])}: {message}"]


def _where_it_belongs(field: str) -> str:
    """For an unknown field, the known fields of that name elsewhere in a study
    (``hourconsumption`` is ``load_profile.hourconsumption``), else the close names beside it."""
    from foldopt.inputs.fields import field_paths

    paths = field_paths(Study)
    section, _, name = field.rpartition(".")
    elsewhere = [path for path in paths if path.rpartition(".")[2] == name and path != field]
    if elsewhere:
        return f"; did you mean {' or '.join(elsewhere)}?"
    siblings = [path.rpartition(".")[2] for path in paths if path.rpartition(".")[0] == section]
    return names.did_you_mean(name, siblings)


def _shown(value) -> str:
    """A value as a study file writes it: YAML's ``true``/``false``, not Python's."""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_shown(item) for item in value) + "]"
    return repr(value)


def format_errors(error: ValidationError) -> list[str]:
    """Every line of a pydantic error (:func:`format_error`).

    Parameters
    ----------
    error : pydantic.ValidationError

    Returns
    -------
    list of str
    """
    return [line for item in error.errors() for line in format_error(item)]


def make_study(data: dict, files: FilesRead | None = None) -> Study:
    """Validate one study from plain data.

    Parameters
    ----------
    data : dict
        The study's fields, as a YAML study holds them.
    files : FilesRead, optional
        What :func:`foldopt.inputs.study_file.resolve_files` read of the files ``data`` names; without
        it they stay unread (:class:`~foldopt.inputs.sections.FilesRead`).

    Returns
    -------
    Study

    Raises
    ------
    foldopt.ConfigError
        Listing every fault, one ``field = value: problem`` line each.
    """
    if not isinstance(data, dict):
        raise ConfigError([f"study: expected a mapping of fields, got {type(data).__name__}"])
    try:
        return Study.model_validate(data, context=files)
    except ValidationError as error:
        raise ConfigError(format_errors(error)) from None
