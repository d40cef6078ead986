"""``foldopt size``: Shin et al.'s panel sizing (Sec. IV-A) through :func:`foldopt.size`, whose
limits (:data:`foldopt.studies.request.SIZING_LIMITS`) are checked before the study is read."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from foldopt.cli.options import (
    RESULTS,
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
from foldopt.errors import ConfigError
from foldopt.files import check_output
from foldopt.inputs.costs import C_GRID, DAYS_PER_YEAR, LIFETIME_YEARS, PAPER_COST_PER_M2

#: The sizing's parameters as the command line names them, longest first.
_OPTION_OF_SIZING = {
    "cost_per_m2 / cost_per_w": "--cost-per-m2 / --cost-per-w",
    "c_grid_usd_per_kwh": "--c-grid",
    "days_per_year": "--days-per-year",
    "cost_per_m2": "--cost-per-m2",
    "cost_per_w": "--cost-per-w",
    "years": "--years",
    "areas": "--areas",
}


def _sizing_option(line: str) -> str:
    for field, option in _OPTION_OF_SIZING.items():
        if line.startswith(field):
            return option + line[len(field) :]
    return line


def size(
    config: Annotated[Path | None, study_argument(" (one case)")] = None,
    areas: Annotated[
        str, typer.Option("--areas", help="Panel areas [m^2], start:stop:step.")
    ] = "0.01:0.5:0.005",
    cost_per_m2: Annotated[
        float | None,
        typer.Option(
            "--cost-per-m2",
            help=f"Panel cost [$/m^2] [default: "
            f"{PAPER_COST_PER_M2:g}, the cost Shin et al.'s 0.108 m^2 "
            "optimum implies].",
        ),
    ] = None,
    cost_per_w: Annotated[
        float | None, typer.Option("--cost-per-w", help="Panel cost [$/W at STC], instead.")
    ] = None,
    c_grid: Annotated[
        float, typer.Option("--c-grid", help="Grid energy price [$/kWh] (Shin et al.: 0.22).")
    ] = C_GRID,
    years: Annotated[
        float, typer.Option("--years", help="Lifetime [years] (Shin et al.: 20).")
    ] = LIFETIME_YEARS,
    days_per_year: Annotated[
        float, typer.Option("--days-per-year", help="Days a year like the study's day.")
    ] = DAYS_PER_YEAR,
    out: Annotated[Path | None, out_option(shown="results/<study>-sizing")] = None,
    overwrite: Overwrite = False,
    quiet: Quiet = False,
    output_format: OutputFormat = "table",
    table: Table = False,
    settings: Settings = None,
    storage: Annotated[
        bool,
        typer.Option(
            "--storage",
            help="Size the study's buffer instead: each design's smallest capacity for the load "
            "to run --target-h hours a day (its storage section, else an ideal buffer).",
        ),
    ] = False,
    target_h: TargetH = None,
    weather: Annotated[
        Path | None,
        typer.Option(
            "--weather",
            help="With --storage: a weather file (TMY3, EPW...): the buffer for the target over "
            "its year's days, in sequence (its site; the study's objective, else mean).",
        ),
    ] = None,
):
    """Shin et al. Sec. IV-A panel sizing: the lifetime benefit C_grid x t_solar x P_load against the
    panel's cost, for flat and twofold panels of every area; with --storage, the buffer each design
    needs for a target.

    \b
    Examples:
      foldopt size
      foldopt size --cost-per-w 0.9 --areas 0.02:0.3:0.002
      foldopt size --storage --target-h 24 --set p_load=2 --set storage.preset=supercapacitor
      foldopt size --storage --target-h 24 --set storage.target.days_pct=95 --weather configs/weather/723170TYA.CSV
    """
    output_format, _ = check_choices(output_format, "numba")
    output = Output(quiet, output_format, table)
    # The study's modules (yaml, pydantic, numpy) once a command runs: --help stays quick.
    from foldopt.studies.request import make_request, sizing_problems

    if storage or target_h is not None or weather is not None:
        # The panel's costs size the panel, not its buffer: said, never ignored.
        given = {
            "--areas": areas != "0.01:0.5:0.005",
            "--cost-per-m2": cost_per_m2 is not None,
            "--cost-per-w": cost_per_w is not None,
            "--c-grid": c_grid != C_GRID,
            "--years": years != LIFETIME_YEARS,
            "--days-per-year": days_per_year != DAYS_PER_YEAR,
        }
        if storage and any(given.values()):
            option = next(name for name, set_ in given.items() if set_)
            fail([f"{option}: an option of the panel's sizing; --storage sizes the buffer"])
        _size_buffer(config, target_h, storage, settings, weather, out, overwrite, output)
        return

    costs = {
        "cost_per_m2": cost_per_m2,
        "cost_per_w": cost_per_w,
        "c_grid_usd_per_kwh": c_grid,
        "years": years,
        "days_per_year": days_per_year,
    }
    errors = sizing_problems(costs)
    if errors:
        fail([_sizing_option(line) for line in errors])
    try:
        request = make_request("size", config, settings=settings or (), costs=costs)
    except ConfigError as error:
        fail(list(dict.fromkeys(error.errors)))
    study = request.plan.base
    out = out or RESULTS / f"{study.name}-sizing"
    check_output(out, overwrite)
    from foldopt.api import size as size_panel, write

    try:
        with output.progress(f"sizing {study.name}"):
            result = size_panel(areas=areas, request=request, **_parameters(costs))
    except ConfigError as error:
        fail([_sizing_option(line) for line in error.errors])
    output.answer(
        "size",
        out,
        result.answer,
        result.table,
        [f"wrote {out}"],
        result.table,
        write=lambda: write(result, out, overwrite, INVOCATION),
    )


def _parameters(costs: dict) -> dict:
    """The sizing's parameters as :func:`foldopt.size` names them."""
    return {
        ("c_grid" if name == "c_grid_usd_per_kwh" else name): value for name, value in costs.items()
    }


def _size_buffer(config, target_h, storage, settings, weather, out, overwrite, output):
    """``foldopt size --storage --target-h H``: the study with its buffer sized for the load to
    run ``H`` hours a day (``storage.target``), an ideal 0 Wh buffer where the study has none;
    its answer is the day's, or over a weather file's year (``--weather`` or the study's, with
    its objective, else the mean) the annual one (:mod:`foldopt.studies.storage_days`)."""
    from foldopt.cli.run import run_request
    from foldopt.studies.request import make_request

    if not storage and weather is not None:
        fail(["--weather: sizes a buffer over the file's year; give --storage --target-h H"])
    if not storage or target_h is None:
        fail(["--storage and --target-h go together: --target-h is the hours a day, in (0, 24]"])
    try:
        request = make_request(
            "size --storage",
            config,
            options={"weather": weather},
            settings=settings or (),
            target_h=target_h,
        )
    except ConfigError as error:
        fail(list(dict.fromkeys(error.errors)))
    run_request(request, out or RESULTS / request.plan.base.name, overwrite, output, "auto", "size")


#: The commands of this module: name, function, and the line the command list shows.
COMMANDS = [("size", size, "Panel sizing: lifetime net benefit against area, flat and twofold.")]
