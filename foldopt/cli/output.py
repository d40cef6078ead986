"""What the command line writes to the terminal: error lines, progress while a command works, and
the answer it returns, as its lines or as one JSON document.

The view decides nothing: every number and word of an answer is the
:class:`foldopt.studies.answer.Answer`'s; this module only chooses the stream and the format.
"""

from __future__ import annotations

import json
from contextlib import contextmanager
from pathlib import Path
from typing import NoReturn

import typer

from foldopt.errors import printable, redacted

#: The command line as typed, for run.json (``sys.argv`` holds the script's path, or pytest's); set
#: by the app for each command.
INVOCATION: list[str] = []


def as_text(text: str) -> str:
    """Text from the command line (an argument, a path in a message) as it was typed.

    Under a C locale without Python's UTF-8 mode its bytes arrive as surrogates (PEP 383), which no
    UTF-8 file can hold and a terminal shows as ``?``; they are read as the UTF-8 they are, and
    bytes that are no UTF-8 as backslash escapes.

    Parameters
    ----------
    text : str

    Returns
    -------
    str
    """
    return text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")


def echo(text: str, err: bool = False) -> None:
    """Print a line of text from the command line (:func:`as_text`), on stderr with ``err``; a
    control character (text a message took from a binary file) as a ``\\xNN`` escape.

    Parameters
    ----------
    text : str
    err : bool
    """
    typer.echo(printable(as_text(text), breaks=True), err=err)


def fail(lines: list[str]) -> NoReturn:
    """End the command on bad input: one ``error:`` line per fault on stderr, exit code 2.

    Parameters
    ----------
    lines : list of str
        The faults, each naming the option or field.
    """
    for line in lines:
        echo(f"error: {redacted(line)}", err=True)  # an address's password is never shown
    raise typer.Exit(2)


class Output:
    """What a command prints: progress on stderr while it works, then the answer.

    Parameters
    ----------
    quiet : bool
        Print nothing but errors (and, with JSON, the document): the command's ``--quiet``, which
        the command itself turns into silent notices for its run (:func:`foldopt.cache.quiet_mode`).
    output_format : {'table', 'json'}
    table : bool
        Also print the full table.
    """

    def __init__(self, quiet: bool, output_format: str, table: bool = False):
        self.quiet, self.json, self.table = quiet, output_format == "json", table

    @contextmanager
    def progress(self, label: str, total: float | None = None, unit: str = "days"):
        """A rich progress bar from the first moment of the work, removed when done.

        Parameters
        ----------
        label : str
        total : float, optional
            The work's size in ``unit``; without it a spinner.
        unit : str

        Yields
        ------
        callable
            ``progress(done, total)``, counting ``unit``.
        """
        if self.quiet:  # rich (0.05 s of imports) only where a bar may show
            yield lambda done, total: None
            return
        from rich.console import Console

        console = Console(stderr=True)
        if not console.is_terminal:  # a bar in a log or a pipe is noise
            yield lambda done, total: None
            return
        from rich.progress import (
            BarColumn,
            Progress,
            ProgressColumn,
            SpinnerColumn,
            TaskProgressColumn,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )
        from rich.text import Text

        class Rate(ProgressColumn):
            def render(self, task):
                return Text(f"{task.speed:,.0f} {unit}/s" if task.speed else "")

        columns = [SpinnerColumn(), TextColumn("{task.description}")]
        if total is not None:
            columns += [BarColumn(), TaskProgressColumn(), Rate(), TimeRemainingColumn()]
        with Progress(*columns, TimeElapsedColumn(), console=console, transient=True) as bar:
            task = bar.add_task(label, total=total)
            yield lambda done, total: bar.update(task, completed=done, total=total)

    def answer(
        self, command: str, out: Path, answer, rows=None, lines_after=(), table=None, write=None
    ) -> None:
        """Render an answer: its lines (``--table`` adds ``table``), or one JSON document holding it
        and the rows; and write its folder.

        The lines come before the folder is written (its figures and report take most of a warm
        run), ``lines_after`` once it is; a folder that fails is then an ``error:`` line after the
        answer. The JSON document comes after: a program reading it gets it only with its folder.

        Parameters
        ----------
        command : str
            The command's name, for the JSON document.
        out : pathlib.Path
            The results folder written.
        answer : foldopt.studies.answer.Answer
        rows : pandas.DataFrame or foldopt.columnar.Columns, optional
            The rows the JSON document holds.
        lines_after : sequence of str
            Lines printed after the answer's (``wrote <folder>``).
        table : pandas.DataFrame or foldopt.columnar.Columns, optional
            The table ``--table`` prints.
        write : callable, optional
            Writes the folder ``out``, with no argument.
        """
        if self.json:
            from foldopt.studies.answer import records

            if write is not None:
                write()
            document = {
                "command": command,
                "out": as_text(str(out)),
                "answer": answer.to_dict(),
                "rows": records(rows),
            }
            typer.echo(json.dumps(document, indent=1))
            return
        if not self.quiet:
            for line in answer.lines():
                echo(line)
        if write is not None:
            with self.progress(f"writing {as_text(str(out))}"):
                write()
        if self.quiet:
            return
        for line in lines_after:
            echo(line)
        if table is not None and self.table:
            from foldopt.columnar import as_frame

            typer.echo(
                as_frame(table).to_string(
                    index=False, float_format=lambda v: f"{v:.3f}", na_rep="-"
                )
            )
        elif table is not None:
            typer.echo("(--table prints the full table)")
