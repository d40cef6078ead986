"""foldopt: design-space optimiser for twofold photovoltaic panels powering storage-less loads.

The public interface (``foldopt.__all__``) loads on first use, so that ``import foldopt`` and the
command line's help stay fast; ``__version__`` too (:mod:`importlib.metadata`, which reads the
installed distributions, takes longer than the rest of this module).

>>> import foldopt
>>> result = foldopt.run(foldopt.default_study())
>>> ax = foldopt.plot_power_curves(result)
"""

import sys
from importlib import import_module
from importlib.abc import MetaPathFinder
from importlib.machinery import PathFinder
from importlib.util import LazyLoader

#: Public name -> the module that defines it.
_PUBLIC = {
    "Study": "foldopt.inputs.study",
    "Plan": "foldopt.inputs.plan",
    "ConfigError": "foldopt.errors",
    **{
        name: "foldopt.inputs.sections"
        for name in (
            "Site",
            "Panel",
            "Tracker",
            "Objective",
            "FoldAngles",
            "LoadProfile",
            "NearOptimal",
        )
    },
    "Weather": "foldopt.inputs.weather_section",
    "Horizon": "foldopt.inputs.horizon_section",
    "Circuit": "foldopt.inputs.circuit_section",
    "default_study": "foldopt.api",
    "load_study": "foldopt.api",
    "run": "foldopt.api",
    "sweep": "foldopt.api",
    "optimize": "foldopt.api",
    "write": "foldopt.api",
    "size": "foldopt.api",
    "reproduce": "foldopt.api",
    "world_map": "foldopt.api",
    "StudyResult": "foldopt.studies.day",
    "SweepResult": "foldopt.studies.sweeps",
    "MapSpec": "foldopt.studies.map_request",
    "MapRun": "foldopt.studies.cluster",
    "run_map": "foldopt.studies.cluster",
    "evaluate_sites": "foldopt.studies.worldmap",
    "map_study": "foldopt.studies.map_request",
    **{name: "foldopt.inputs.sites" for name in ("grid_sites", "read_sites", "weather_sites")},
    "annual_summary": "foldopt.studies.annual",
    "write_html": "foldopt.output.html",
    "save_plot": "foldopt.output.figures.canvas",
    **{
        name: "foldopt.output.figures.day"
        for name in (
            "plot_power_curves",
            "plot_switching",
            "plot_t_solar_vs_fold_angle",
            "plot_comparison",
            "plot_standby",
        )
    },
    **{
        name: "foldopt.output.figures.storage"
        for name in ("plot_state_of_charge", "plot_powered_vs_capacity")
    },
    **{name: "foldopt.output.figures.sweep" for name in ("plot_map", "plot_curves")},
    **{
        name: "foldopt.output.figures.annual"
        for name in (
            "plot_annual_fold_angles",
            "plot_monthly",
            "plot_distribution",
            "plot_day_hour",
            "plot_refold_value",
            "plot_powered_by_year",
        )
    },
    **{
        name: "foldopt.output.figures.weather"
        for name in ("plot_weather_minutes", "plot_member_t_solar")
    },
    **{name: "foldopt.output.figures.world" for name in ("plot_world_map", "plot_latitude_load")},
    "plot_sizing": "foldopt.output.figures.sizing",
    "plot_sun_paths": "foldopt.output.figures.horizon",
    "plot_landscape": "foldopt.output.figures.landscape",
    "plot_design_space": "foldopt.output.figures.least_cost",
    "Costs": "foldopt.inputs.costs_section",
    "OptimizeResult": "foldopt.studies.joint",
    "Optimize": "foldopt.inputs.optimize_section",
    "best_schedules": "foldopt.engine.schedule",
    "Answer": "foldopt.studies.answer",
    "make_request": "foldopt.studies.request",
    "Request": "foldopt.studies.request",
    "SizingResult": "foldopt.studies.sizing",
    "Reproduction": "foldopt.studies.reproduce",
    "twofold_arrays": "foldopt.physics.pvsystem",
}
__all__ = ["__version__", *_PUBLIC]


class _OnFirstUse(MetaPathFinder):
    """Loads pvlib's subpackages that a study does not use when first used rather than when pvlib
    is imported, which imports all of them: ``pvlib.iotools`` (requests and ssl), read only for a
    weather file, and ``pvlib.spectrum`` (scipy.integrate), used by none of foldopt's models.

    :class:`importlib.util.LazyLoader` is not thread-safe before Python 3.12: foldopt's readers
    first use ``pvlib.iotools`` under a lock (:func:`foldopt.inputs.weather.formats.read_with_pvlib`).
    """

    _NAMES = ("pvlib.iotools", "pvlib.spectrum")

    def find_spec(self, name, path=None, target=None):
        if name not in self._NAMES:
            return None
        spec = PathFinder.find_spec(name, path)
        if spec is not None and spec.loader is not None and hasattr(spec.loader, "exec_module"):
            spec.loader = LazyLoader(spec.loader)
        return spec


if "pvlib" not in sys.modules and not any(
    isinstance(finder, _OnFirstUse) for finder in sys.meta_path
):
    sys.meta_path.insert(0, _OnFirstUse())


def _version() -> str:
    from importlib import metadata

    try:
        return metadata.version("foldopt")
    except metadata.PackageNotFoundError:  # running from a source tree that is not installed
        return "0+unknown"


def __getattr__(name: str):
    if name == "__version__":
        globals()[name] = _version()
        return globals()[name]
    if name in _PUBLIC:
        value = getattr(import_module(_PUBLIC[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'foldopt' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
