"""The options the commands share, each declared once, and the words of their errors.

A command takes a shared option by annotating a parameter with it, the default after it
(``overwrite: Overwrite = False``); an option whose help differs by command (``--out``, ``--step-min``,
the study argument) is made by one function here, which the command annotates with
(``out: Annotated[Path | None, out_option(shown="results/<study name>")] = None``). Errors from the
library name study fields; :func:`rename_fields` says them as the options that set them.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated

import typer

from foldopt import names
from foldopt.names import OPTION_OF_FIELD
from foldopt.cli.output import fail

#: Where results folders go unless ``--out`` says otherwise.
RESULTS = Path("results")
#: The embedded study, as help texts and answers name it.
EMBEDDED = "configs/shin2015.yaml"

Overwrite = Annotated[bool, typer.Option("--overwrite", help="Replace an existing results folder.")]
Quiet = Annotated[
    bool,
    typer.Option(
        "--quiet", "-q", help="Print nothing but errors (with --format json: the JSON only)."
    ),
]
OutputFormat = Annotated[
    str,
    typer.Option(
        "--format",
        help=f"{' | '.join(names.OUTPUT_FORMATS)}: a short answer, or "
        "one JSON document on stdout for scripts.",
    ),
]
Engine = Annotated[
    str,
    typer.Option(
        "--engine",
        help=" | ".join(f"{name} ({names.ENGINES.describe(name)})" for name in names.ENGINES) + ".",
    ),
]
Table = Annotated[
    bool, typer.Option("--table", help="Also print the full table (it is always in the CSV files).")
]
Area = Annotated[float | None, typer.Option("--area", help="Flat panel area [m^2].")]
Efficiency = Annotated[
    float | None,
    typer.Option(
        "--efficiency", help="PV efficiency [-] (ideal model; sets the b-model panel's area)."
    ),
]
AngleStep = Annotated[
    float | None,
    typer.Option("--angle-step", help="Fold-angle grid step [deg] [default: the study's]."),
]
StepMin = Annotated[
    float | None,
    typer.Option("--step-min", help="Time step [min], a divisor of 1440 [default: the study's]."),
]
StorageWh = Annotated[
    float | None,
    typer.Option(
        "--storage-wh",
        help="A buffer behind a charge controller: its usable energy [Wh] (0: storage-less); "
        "--set storage.<field> for the rest [default: none].",
    ),
]
MinSoc = Annotated[
    float | None,
    typer.Option(
        "--min-soc",
        help="The charge controller's cut-off: the state of charge [-] at which it disconnects "
        "the load [default: the storage preset's, else 0].",
    ),
]
Settings = Annotated[
    list[str] | None,
    typer.Option(
        "--set",
        metavar="KEY=VALUE",
        help="Any study field (a dotted "
        "key, a YAML value), e.g. --set pv_model=single-diode; "
        "repeatable.",
    ),
]


def out_option(shown: str | None = None) -> typer.models.OptionInfo:
    """The ``--out`` option: the results folder.

    Parameters
    ----------
    shown : str, optional
        The default as the help text gives it where the command names the folder from the study
        (``results/<study name>``); without it the help shows the parameter's default.

    Returns
    -------
    typer.models.OptionInfo
    """
    return typer.Option("--out", help=f"Results folder{f' [default: {shown}]' if shown else ''}.")


def study_argument(kind: str = "") -> typer.models.ArgumentInfo:
    """The optional study argument of ``run`` and ``size``.

    Parameters
    ----------
    kind : str
        What study the command takes, after ``YAML study`` (e.g. `` (one case)``).

    Returns
    -------
    typer.models.ArgumentInfo
    """
    return typer.Argument(help=f"YAML study{kind} [default: the embedded {EMBEDDED}].")


def check_choices(output_format: str, engine: str) -> tuple[str, str]:
    """``--format`` and ``--engine`` as their registries name them; bad ones end the command.

    Parameters
    ----------
    output_format, engine : str
        As given, in any of the names :mod:`foldopt.names` knows.

    Returns
    -------
    tuple of str
        The canonical format and engine.
    """
    errors, chosen = [], []
    for option, value, choices in (
        ("--format", output_format, names.OUTPUT_FORMATS),
        ("--engine", engine, names.ENGINES),
    ):
        try:
            chosen.append(names.canonical(value, choices))
        except ValueError as error:
            errors.append(f"{option} = {value!r}: {error}")
    if errors:
        fail(errors)
    return tuple(chosen)


_FIELD = re.compile(r"^([A-Za-z_.]+)(\[\d+\])?")


def rename_fields(line: str, options: dict = OPTION_OF_FIELD) -> str:
    """A message's leading field path as the option that set it.

    Parameters
    ----------
    line : str
        ``field: problem`` or ``field = value: problem``.
    options : dict
        Field path -> option.

    Returns
    -------
    str
        The line with its field renamed, or as it was where ``options`` has no such field.
    """
    match = _FIELD.match(line)
    if match and match.group(1) in options:
        return options[match.group(1)] + line[match.end(1) :]
    return line
