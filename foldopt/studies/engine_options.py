"""A study's engine options: the one place a :class:`foldopt.inputs.study.Study` becomes what the
engine reads of it (:class:`foldopt.engine.options.EngineOptions`). A field the engine comes to
read is a field of its options group and a line here.

The module may import :mod:`foldopt.engine` and :mod:`foldopt.inputs`.
"""

from __future__ import annotations

from foldopt.engine.options import ElectricalOptions, EngineOptions, SkyOptions
from foldopt.inputs.study import Study


def engine_options(study: Study) -> EngineOptions:
    """The sky's and the electrical model's settings of a study, its files read.

    Parameters
    ----------
    study : Study
        Resolved (its defaults decided).

    Returns
    -------
    EngineOptions

    Raises
    ------
    foldopt.ConfigError
        If the study's files are unread (:meth:`foldopt.inputs.study.Study.require_files`).
    """
    study.require_files()
    return EngineOptions(
        sky=SkyOptions(
            mode=study.mode,
            model=study.sky,
            linke_turbidity=study.linke_turbidity,
            climate=study.climate,
            transposition=study.sky_transposition(),
            albedo=study.albedo,
            iam=study.iam,
            step_min=study.step_min,
            temp_air=study.temp_air,
            wind_speed=study.wind_speed,
            temperature_model=study.temperature_model,
            weather=study.weather,
            weather_site=study.site,
            load_profile=study.load_profile,
        ),
        electrical=ElectricalOptions(
            pv_model=study.pv_model,
            efficiency=study.panel.efficiency,
            module=study.module,
            area=study.panel.area,
            temperature_model=study.temperature_model,
            wind_speed=study.wind_speed,
            bypass=study.bypass_diodes,
            switch_series=study.switch_series,
            converter_efficiency=study.converter_efficiency,
            exact=study.exact_electrical,
            circuit=None if study.circuit.ideal else study.circuit,
        ),
    )
