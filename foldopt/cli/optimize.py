"""``foldopt optimize``: the fold angle, base tilt and base azimuth together
(:func:`foldopt.studies.joint.optimize_plan`), with every option of ``foldopt sweep`` for the
site, days, loads and models; the request is :func:`foldopt.studies.request.make_request`'s, the
search's own options making its ``optimize`` section (:func:`foldopt.studies.request.optimize_section`)."""

from __future__ import annotations

import inspect
from typing import Annotated

import typer

from foldopt import names
from foldopt.cli.options import RESULTS, check_choices
from foldopt.cli.output import Output, fail
from foldopt.cli.run import run_request
from foldopt.cli.sweep import signature
from foldopt.errors import ConfigError

#: The optimize section's fields by the parameters of :func:`_optimize_options` that set them.
_PARAMETER_OF_FIELD = {
    "vary": "vary",
    "fold_angle": "fold_range",
    "tilt": "tilt_range",
    "azimuth": "azimuth_range",
    "tolerance_h": "tolerance",
}


def _optimize_options(
    vary: Annotated[
        str | None,
        typer.Option(
            "--vary",
            help="What to optimise: any of "
            + ", ".join(names.OPTIMIZE_VARIABLES)
            + ", joined by commas [default: "
            "all three, or the study's optimize.vary].",
        ),
    ] = None,
    fold_range: Annotated[
        str | None,
        typer.Option(
            "--fold-range",
            help="Fold angles min:max:step [deg] [default: the study's fold_angles].",
        ),
    ] = None,
    tilt_range: Annotated[
        str | None,
        typer.Option("--tilt-range", help="Base tilts min:max:step [deg] [default: 0:90:1]."),
    ] = None,
    azimuth_range: Annotated[
        str | None,
        typer.Option(
            "--azimuth-range",
            help="Base azimuths min:max:step [deg "
            "from north; may cross north, -90:90:2] [default: the "
            "equator-facing one +-90 by 2].",
        ),
    ] = None,
    tolerance: Annotated[
        float | None,
        typer.Option(
            "--tolerance",
            help="What the search may miss of the best "
            "objective [h]; no finer than the objective counts (one day: "
            "the time step) [default: 0.01].",
        ),
    ] = None,
):
    """The options of the optimisation itself."""


def optimize(**options):
    output_format, engine = check_choices(options.pop("output_format"), options.pop("engine"))
    output = Output(options.pop("quiet"), output_format, options.pop("table"))
    out, overwrite = options.pop("out"), options.pop("overwrite")
    config, settings = options.pop("config"), options.pop("settings") or ()
    search = {field: options.pop(parameter) for field, parameter in _PARAMETER_OF_FIELD.items()}
    # The study's modules (yaml, pydantic, numpy) once a command runs: --help stays quick.
    from foldopt.studies.request import OPTIMIZE_OPTIONS, make_request

    search = {field: value for field, value in search.items() if value is not None}
    try:
        request = make_request(
            "optimize",
            config,
            options=options,
            settings=settings,
            optimize={**search, "labels": OPTIMIZE_OPTIONS},
        )
    except ConfigError as error:
        fail(list(dict.fromkeys(error.errors)))
    # The search's own limits (loads x designs) are checked as it starts, before any work.
    run_request(request, out or RESULTS / "optimize", overwrite, output, engine, "optimize")


_SIGNATURE = signature("optimize", "results/optimize")
_OWN = inspect.signature(_optimize_options, eval_str=True).parameters.values()
optimize.__signature__ = _SIGNATURE.replace(parameters=[*_OWN, *_SIGNATURE.parameters.values()])
optimize.__doc__ = """The best fold angle, base tilt and base azimuth together (any of them), maximising the study's
objective over its days: per load the optimum with its near-optimal region, the flat panel at its own best tilt and
azimuth, the default mounting and the tracker, what each variable adds, and landscape.png (tilt x fold angle).

\b
Examples:
  foldopt optimize --mode exact
  foldopt optimize --days year --objective worst-month --vary fold_angle,tilt --step-min 10
  foldopt optimize --lat -33.87 --lon 151.21 --timezone Australia/Sydney --days 1:365:7 --p-load 1,3"""

#: The commands of this module: name, function, and the line the command list shows.
COMMANDS = [
    (
        "optimize",
        optimize,
        "The best fold angle, tilt and azimuth together, and the flat panel's own best.",
    )
]
