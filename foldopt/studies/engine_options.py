"""A study's engine options: the one place a :class:`foldopt.inputs.study.Study` becomes what the
engine reads of it (:class:`foldopt.engine.options.EngineOptions`).

An option of a group takes the study's field of the same name, unless :data:`DERIVED` says how it
is made of the study. A field the engine comes to read is so a field of the study and a field of
its options group, named alike, and nothing here (``tests/test_architecture.py`` holds the rule).

The module may import :mod:`foldopt.engine` and :mod:`foldopt.inputs`.
"""

from __future__ import annotations

import dataclasses

from foldopt.engine.options import ElectricalOptions, EngineOptions, SkyOptions
from foldopt.inputs.study import Study

#: The options that are not the study's field of their name: how each is made of the study.
DERIVED = {
    SkyOptions: {
        "model": lambda study: study.sky,
        "transposition": Study.sky_transposition,
        "weather_site": lambda study: study.site,
    },
    ElectricalOptions: {
        "efficiency": lambda study: (
            study.pvwatts.efficiency(study.panel.area, study.panel.efficiency)
            if study.pv_model == "pvwatts"
            else study.panel.efficiency
        ),
        "gamma_pdc": lambda study: study.pvwatts.gamma_pdc,
        "losses": lambda study: (
            study.pvwatts.losses / 100.0 if study.pv_model == "pvwatts" else 0.0
        ),
        "area": lambda study: study.panel.area,
        "bypass": lambda study: study.bypass_diodes,
        "exact": lambda study: study.exact_electrical,
        "circuit": lambda study: None if study.circuit.ideal else study.circuit,
    },
}


def _group(kind, study: Study):
    """The options group ``kind`` of ``study``: each field the study's of its name, or derived."""
    derived = DERIVED[kind]
    return kind(
        **{
            field.name: derived[field.name](study)
            if field.name in derived
            else getattr(study, field.name)
            for field in dataclasses.fields(kind)
        }
    )


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
    return EngineOptions(sky=_group(SkyOptions, study), electrical=_group(ElectricalOptions, study))
