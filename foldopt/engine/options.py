"""What the engine reads of a study, grouped by concept: the sky's settings (:class:`SkyOptions`)
and the cells' electrical model (:class:`ElectricalOptions`), together an :class:`EngineOptions`.

The engine never sees a :class:`foldopt.inputs.study.Study`: a study becomes its options once, by
:func:`foldopt.studies.engine_options.engine_options`, and the engine's entry points take them
beside the arrays (:func:`foldopt.engine.sky.build_sky` the sky's,
:func:`foldopt.engine.evaluation.row_metrics` and the other passes over a sky the electrical
model's). Each group holds plain values and the few input sections the engine reads whole (the
weather file, the load profile, the circuit as built), validated where the study was.

The module may import :mod:`foldopt.inputs` sections (never the study).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

from foldopt.inputs.circuit_section import Circuit
from foldopt.inputs.sections import LoadProfile, Site
from foldopt.inputs.weather_section import Weather
from foldopt.physics.pvmodel import PVModel


@dataclass(frozen=True)
class SkyOptions:
    """The settings of a sky's light (:func:`foldopt.engine.sky.build_sky`).

    Attributes
    ----------
    mode : {'paper', 'exact'}
        Shin et al.'s sun and Eq. 5 incidence, or pvlib's (:data:`foldopt.names.MODES`).
    model : str
        The clear sky (:data:`foldopt.names.SKIES`), without a weather file.
    linke_turbidity : float or None
        Ineichen's Linke turbidity [-]; None: the climatology's at each site.
    climate : str
        Hottel's climate (:data:`foldopt.names.HOTTEL_CLIMATES`).
    transposition : str
        The diffuse model in force (:data:`foldopt.names.TRANSPOSITIONS`; ``'none'``: beam only).
    albedo : float
        Ground reflectance [-].
    iam : str
        The beam's incidence-angle modifier (:data:`foldopt.names.IAMS`).
    step_min : float
        Time step [min], a divisor of a day.
    temp_air : float
        Air temperature of the cells without a weather file [C].
    wind_speed : float
        Wind speed without a weather file [m/s] (a weather file's dark days too).
    temperature_model : str
        The cells' temperature model (:data:`foldopt.names.TEMPERATURE_MODELS`), which folds a
        weather file's wind into an equivalent air temperature.
    weather : foldopt.inputs.weather_section.Weather or None
        The weather file, read (its site known); None for a clear sky.
    weather_site : foldopt.inputs.sections.Site or None
        The site a measured weather file that names none is taken at.
    load_profile : foldopt.inputs.sections.LoadProfile or None
        A day's load shape, read; None for a constant load.
    """

    mode: str
    model: str
    linke_turbidity: float | None
    climate: str
    transposition: str
    albedo: float
    iam: str
    step_min: float
    temp_air: float
    wind_speed: float
    temperature_model: str
    weather: Weather | None
    weather_site: Site | None
    load_profile: LoadProfile | None


@dataclass(frozen=True)
class ElectricalOptions:
    """The cells' electrical model and the circuit of the two sub-panels
    (:func:`foldopt.engine.cell_tables.electrical_for`).

    Attributes
    ----------
    pv_model : str
        One of :data:`foldopt.names.PV_MODELS`.
    efficiency : float
        The ideal and the PVWatts model's efficiency [-] (PVWatts': its rating per area / 1000
        W/m^2).
    module : str or None
        The single-diode model's module of pvlib's CEC database; None: the paper's A-300 cells.
    gamma_pdc : float
        The PVWatts model's temperature coefficient of power [1/C].
    losses : float
        The PVWatts model's system losses [-] (a fraction of its DC power).
    area : float
        The flat panel's area [m^2] (each sub-panel half of it).
    temperature_model : str
        The cells' temperature model (:data:`foldopt.names.TEMPERATURE_MODELS`).
    wind_speed : float
        Wind speed of the tables where the sky gives none [m/s].
    bypass : bool
        Bypass diodes across the sub-panels in series.
    switch_series : bool
        Switching may also select series.
    converter_efficiency : float
        Efficiency of each of the independent connection's converters [-].
    exact : bool
        Solve every step's I-V curves instead of the tables (the NumPy path).
    circuit : foldopt.inputs.circuit_section.Circuit or None
        The circuit as built; None for Shin et al.'s ideal parts.
    """

    pv_model: str
    efficiency: float
    module: str | None
    gamma_pdc: float
    losses: float
    area: float
    temperature_model: str
    wind_speed: float
    bypass: bool
    switch_series: bool
    converter_efficiency: float
    exact: bool
    circuit: Circuit | None

    def pv(self) -> PVModel:
        """The PV model these options name, with its settings."""
        return PVModel(self.pv_model, self.efficiency, self.module, self.gamma_pdc, self.losses)


class EngineOptions(NamedTuple):
    """Everything the engine reads of one study: its sky's and its electrical model's settings."""

    sky: SkyOptions
    electrical: ElectricalOptions
