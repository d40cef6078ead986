"""``foldopt run`` and ``foldopt reproduce``, and the running of a request that ``sweep`` and
``optimize`` share."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

from foldopt.cli.options import (
    RESULTS,
    Engine,
    OutputFormat,
    Overwrite,
    Quiet,
    Settings,
    Table,
    TargetH,
    check_choices,
    out_option,
    study_argument,
)
from foldopt.cli.output import INVOCATION, Output, fail
from foldopt.cli.process import drawing_aside, loading
from foldopt.errors import ConfigError
from foldopt.files import check_output
from foldopt.names import DEFAULT_ENGINE

if TYPE_CHECKING:
    from foldopt.studies.request import Request


def run_request(
    request: Request, out: Path, overwrite: bool, output: Output, engine: str, command: str
) -> None:
    """Evaluate a request's plan (one case or many) through the API, print its answer, write its folder
    (:meth:`Output.answer`: the lines before the figures are drawn).

        Parameters
        ----------
        request : foldopt.studies.request.Request
        out : pathlib.Path
            The results folder.
        overwrite : bool
        output : Output
        engine : {'auto', 'numba', 'numpy'}
        command : str
            The command's name, for the JSON document.
    """
    check_output(out, overwrite)
    plan, base = request.plan, request.plan.base
    if not plan.axes:
        label, total, unit = (
            f"{base.name}: one day, {len(base.fold_angles.grid())} fold angles",
            None,
            "days",
        )
    else:
        days = plan.n_cases // max(len(dict(plan.axes).get("p_load", (1,))), 1)
        unit = "site-days" if any(path.startswith("site") for path, _ in plan.axes) else "days"
        label, total = f"{base.name}: {days} {unit}", days
    # The studies' modules (pvlib, pandas, numba) only once there is work: help and a bad value stay
    # quick. The figure workers fork then, with those modules and before the progress bar's thread.
    with loading():
        from foldopt.api import run
        from foldopt.studies.day import StudyResult
    drawing_aside()
    with output.progress(label, total=total, unit=unit) as progress:
        try:
            result = run(engine=engine, progress=progress, request=request)
        except (
            ConfigError
        ) as error:  # a limit found as the work starts, said as the request gave it
            fail(list(dict.fromkeys(request.rename(line) for line in error.errors)))
    # A day's rows as the study holds them: its answer is printed before pandas loads.
    rows = result.summary_columns if isinstance(result, StudyResult) else result.table
    output.answer(
        command,
        out,
        result.answer,
        rows,
        [f"wrote {out}"],
        rows,
        write=lambda: write_folder(result, out, overwrite),
    )


def write_folder(result, out: Path, overwrite: bool) -> None:
    """Write a result's folder (:func:`foldopt.api.write`), its writers' modules (jinja2, and
    matplotlib where the figures are drawn in this process) loaded first
    (:func:`foldopt.cli.process.loading`).

    Parameters
    ----------
    result : object
        What :func:`foldopt.api.run` or :func:`~foldopt.api.reproduce` returned.
    out : pathlib.Path
    overwrite : bool
    """
    with loading():
        from foldopt.api import write
        from foldopt.output import drawing, folders  # noqa: F401 - what write imports

        drawing.prepare()
    write(result, out, overwrite, INVOCATION)


def run_options(command: str, options: dict, folder: str, **request) -> None:
    """Run a command whose parameters are the options of every sweep (:mod:`foldopt.cli.sweep`,
    ``optimize``): its request made of them (:func:`foldopt.studies.request.make_request`), run
    and printed (:func:`run_request`).

    Parameters
    ----------
    command : str
        ``sweep angle``, ``sweep latitude``, ``sweep day``, ``sweep load`` or ``optimize``.
    options : dict
        The command's parameters by name: those that set study fields, and ``config``,
        ``settings``, ``out``, ``overwrite``, ``quiet``, ``output_format``, ``engine``, ``table``.
    folder : str
        The results folder under ``results/`` where ``out`` is None.
    **request
        More of :func:`~foldopt.studies.request.make_request`'s keywords (``optimize``).
    """
    options = dict(options)
    output_format, engine = check_choices(options.pop("output_format"), options.pop("engine"))
    output = Output(options.pop("quiet"), output_format, options.pop("table"))
    out, overwrite = options.pop("out"), options.pop("overwrite")
    config, settings = options.pop("config"), options.pop("settings") or ()
    # The study's modules (yaml, pydantic, numpy) once a command runs: --help stays quick.
    with loading():
        from foldopt.studies.request import make_request

    try:
        request = make_request(command, config, options=options, settings=settings, **request)
    except ConfigError as error:
        fail(list(dict.fromkeys(error.errors)))
    run_request(request, out or RESULTS / folder, overwrite, output, engine, command)


def run(
    config: Annotated[Path | None, study_argument()] = None,
    out: Annotated[Path | None, out_option(shown="results/<study name>")] = None,
    overwrite: Overwrite = False,
    quiet: Quiet = False,
    output_format: OutputFormat = "table",
    engine: Engine = DEFAULT_ENGINE,
    table: Table = False,
    settings: Settings = None,
    target_h: TargetH = None,
):
    """Run a YAML study: one case (fold-angle sweep, the paper's heuristic, flat and trackers
    compared) or a sweep of cases (a row per case x design).

    \b
    Examples:
      foldopt run
      foldopt run configs/annual-weather.yaml --out results/greensboro
      foldopt run --set p_load=3 --out results/shin2015-3w
    """
    output_format, engine = check_choices(output_format, engine)
    # The study's modules (yaml, pydantic, numpy) once a command runs: --help stays quick.
    with loading():
        from foldopt.studies.request import make_request

    request = make_request("run", config, settings=settings or (), target_h=target_h)
    run_request(
        request,
        out or RESULTS / request.plan.base.name,
        overwrite,
        Output(quiet, output_format, table),
        engine,
        "run",
    )


def reproduce(
    out: Annotated[Path, out_option()] = RESULTS / "reproduction",
    overwrite: Overwrite = False,
    quiet: Quiet = False,
    output_format: OutputFormat = "table",
    engine: Engine = DEFAULT_ENGINE,
):
    """Reproduce Shin et al.'s study in paper and exact modes: their published values beside foldopt's.

    Writes reproduction.csv (the embedded study: ideal PV model) and reproduction_single_diode.csv
    (A-300 single-diode sub-panels with switching).
    """
    output_format, engine = check_choices(output_format, engine)
    output = Output(quiet, output_format)
    check_output(out, overwrite)
    with output.progress("reproducing Shin et al. (two PV models x two modes)"):
        with loading():
            from foldopt.api import reproduce as reproduce_paper

        result = reproduce_paper(engine)
    output.answer(
        "reproduce",
        out,
        result.answer,
        None,
        [f"wrote {out}"],
        write=lambda: write_folder(result, out, overwrite),
    )


#: The commands of this module: name, function, and the line the command list shows.
COMMANDS = [
    ("run", run, "Run a YAML study, one case or a sweep [default: the embedded study]."),
    (
        "reproduce",
        reproduce,
        "Shin et al.'s published values beside foldopt's, paper and exact modes.",
    ),
]
