"""foldopt command line: thin wrappers over the library.

Every bad input ends the same way: one ``error: <field> ...`` line per fault on stderr, exit code
2, no traceback and nothing written. Input is checked before numpy, pandas, pvlib or matplotlib
load, so that help and errors come at once. Work shows a progress bar on stderr that is removed when
done; the terminal then gets a short answer (``--table`` adds the full table, always in the CSV
files), ``--format json`` one JSON document, and ``--quiet`` nothing but errors.

This module is the app: its error path, its global options and the commands of
:mod:`foldopt.cli.run`, :mod:`foldopt.cli.sweep`, :mod:`foldopt.cli.map` and :mod:`foldopt.cli.size`.
"""

from __future__ import annotations

import codecs
import signal
import sys
import threading
import traceback
from typing import Annotated

import typer
from typer.core import TyperCommand, TyperGroup

from foldopt.cli import map as map_command, optimize, process, run, size, sweep, weather
from foldopt.cli.output import INVOCATION, as_text, echo
from foldopt.errors import ConfigError, OutputError, OutputExistsError
from foldopt.names import close_names

# click's UsageError, whose kin are every refusal of the command line's words. Typer >= 0.26 vendors
# click (typer._click, not public), so the click distribution's click.exceptions.UsageError is another
# class, one Typer never raises; Typer's public BadParameter is a UsageError with either click.
_USAGE_ERROR = next(cls for cls in typer.BadParameter.__mro__ if cls.__name__ == "UsageError")

HELP = """Design-space optimiser for twofold PV panels powering storage-less loads.

Every command runs from its defaults: the embedded study (configs/shin2015.yaml, Shin et al.'s
pole camera in Los Angeles on the 2014 autumn equinox) or the one --config names.

\b
Examples:
  foldopt run                                  the embedded study: best fold angle, flat, tracker
  foldopt run configs/design-map.yaml          a YAML study, one case or a sweep
  foldopt reproduce                            Shin et al.'s numbers beside foldopt's
  foldopt sweep latitude                       the embedded study from 60 S to 60 N
  foldopt sweep angle --weather FILE.csv       a real year from a TMY3 / EPW / PVGIS file
  foldopt sweep angle --lat 45.8 --lon 8.6 --weather pvgis-tmy   the site's year from PVGIS
  foldopt size --cost-per-w 0.9                panel sizing (Shin et al. Sec. IV-A)
  foldopt map --p-load 2 --area 0.108          many sites on Dask: where folding pays, worldwide

Shell completion: foldopt --install-completion.
"""


def _option_hint(given: str, ctx) -> str:
    """What an unknown option most likely meant: the command's options it begins or is close to
    (:func:`foldopt.names.close_names`, without their dashes: Click compares them with theirs, and
    the ``--`` that every option shares made ``--bogus`` look like ``--out``), or where it belongs to
    other commands, which; else where the command's options are listed.

    Parameters
    ----------
    given : str
        The option as typed, ``--name`` or ``--name=value``.
    ctx : click.Context
        The command's context.

    Returns
    -------
    str
        The end of the error line.
    """
    name = given.split("=", 1)[0]
    own = {
        opt.lstrip("-"): opt
        for param in ctx.command.get_params(ctx)
        for opt in (*param.opts, *param.secondary_opts)
        if opt.startswith("-")
    }
    close = [own[bare] for bare in close_names(name.lstrip("-"), list(own))]
    if close:
        return f"; did you mean {' or '.join(close)}?"
    takers = [
        top
        for top, command in _commands(ctx.find_root().command)
        if any(name in (*param.opts, *param.secondary_opts) for param in command.params)
    ]
    if takers:
        return (
            f" ({name} is an option of foldopt {', '.join(dict.fromkeys(takers))}; {ctx.command_path} --help "
            "lists its own)"
        )
    return f" ({ctx.command_path} --help lists its options)"


def _commands(group, top: str | None = None):
    """(top-level name, command) of every command under ``group`` that is no group itself."""
    for name, command in getattr(group, "commands", {}).items():
        if hasattr(command, "commands"):
            yield from _commands(command, top or name)
        else:
            yield top or name, command


#: Set by ``foldopt --debug``: an internal error shows its traceback.
_DEBUG = {"on": False}


def _terminate(signum, frame):
    raise SystemExit(128 + signum)  # unwinds like an error: a staging folder is removed


class _Interrupted(Exception):
    """Ctrl-C, carried past typer, which would end the command with code 130 and not a word."""


def _exit_code(error: BaseException) -> int:
    """Say what ended a command, as the command line says it, and the exit code it ends with: bad
    input (usage, study, weather file, results folder) is one ``error:`` line per fault and code 2;
    Ctrl-C is ``interrupted``, code 130; anything else is an internal error: one line naming it,
    code 1, and the traceback only with ``--debug``."""
    if isinstance(error, ConfigError):
        for line in dict.fromkeys(error.errors):
            echo(f"error: {line}", err=True)
        return 2
    if isinstance(error, (OutputError, OutputExistsError)):
        echo(f"error: {error}", err=True)
        return 2
    if isinstance(error, _USAGE_ERROR):
        message = error.format_message()
        if type(error).__name__ == "NoArgsIsHelpError":  # a bare `foldopt` or `foldopt sweep`
            typer.echo(message)
            return 0
        if message:
            where = f"{error.ctx.command_path}: " if error.ctx is not None else ""
            if type(error).__name__ == "NoSuchOption" and error.ctx is not None:
                message = error.message + _option_hint(error.option_name, error.ctx)
            elif message.startswith("No such command") and error.ctx is not None:
                message += (
                    f" Choose one of {', '.join(error.ctx.command.list_commands(error.ctx))}."
                )
            echo(f"error: {where}{message}", err=True)
        return 2
    # Ctrl-C; typer's Abort: end of input at a prompt
    if isinstance(error, (_Interrupted, typer.Abort)):
        typer.echo("interrupted", err=True)
        return 130
    if _DEBUG["on"]:
        traceback.print_exception(error)
    else:
        reason = str(error).splitlines()[0][:300] if str(error) else ""
        echo(
            f"error: internal error ({type(error).__name__}{': ' + reason if reason else ''}); "
            "run again as foldopt --debug ... for the traceback, and please report it",
            err=True,
        )
    return 1


class _OneLineErrors(TyperGroup):
    """The command line's group: one error path (:func:`_exit_code`) for every way it is called."""

    def main(self, args=None, *rest, **kwargs):
        # The one override of a method click runs itself: the console script calls the app, and
        # typer.testing.CliRunner calls this main directly, so only here do both take the one error
        # path. The rest is click's documented standalone_mode=False: exceptions come to the caller.
        INVOCATION[:] = ["foldopt", *map(as_text, sys.argv[1:] if args is None else args)]
        if args is None:  # the process's own command line (the script, python -m): its alone
            process.own_process()
        for stream in (sys.stdout, sys.stderr):
            # A terminal that cannot show a character (a site's name under LANG=C) gets an escape, not an error.
            if codecs.lookup(
                getattr(stream, "encoding", None) or "utf-8"
            ).name != "utf-8" and hasattr(stream, "reconfigure"):
                stream.reconfigure(errors="backslashreplace")
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGTERM, _terminate)
        try:
            code = super().main(args, *rest, **{**kwargs, "standalone_mode": False})
        except Exception as error:
            sys.exit(_exit_code(error))
        finally:
            process.ending()
        sys.exit(code if isinstance(code, int) else 0)

    def invoke(self, ctx):
        # click's documented hook: Typer would end a Ctrl-C with code 130 and not a word.
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            raise _Interrupted() from None


class _OnceEach(TyperCommand):
    """A command whose options are each given at most once: a repeated option (``--days a --days
    b``) is an error, not a silent last-wins. Options that collect values (``--set``) repeat.
    Its ``--quiet`` silences foldopt's notices (:func:`foldopt.cache.quiet_mode`) while it runs."""

    def invoke(self, ctx):
        # click's documented hook, where the options are parsed: the command's run, and no longer
        # (an in-process caller's later work is as loud as it was).
        from foldopt.cache import quiet_mode

        with quiet_mode(bool(ctx.params.get("quiet"))):
            return super().invoke(ctx)

    def parse_args(self, ctx, args):
        # No documented hook sees a repeat: click's parser keeps the last value, a parameter's
        # callback gets that one value, and ctx.get_parameter_source says only "command line". So
        # the arguments are looked at here, before click parses them (as click's own parse_args).
        seen: dict[str, str] = {}
        for arg in args:
            if arg == "--":
                break
            flag = arg.split("=", 1)[0]
            for param in self.params:
                if getattr(param, "multiple", False) or flag not in tuple(
                    getattr(param, "opts", ())
                ) + tuple(getattr(param, "secondary_opts", ())):
                    continue
                if param.name in seen:
                    raise _USAGE_ERROR(
                        f"{flag}: given twice (first as {seen[param.name]}); give each option once",
                        ctx=ctx,
                    )
                seen[param.name] = flag
        return super().parse_args(ctx, args)


app = typer.Typer(
    cls=_OneLineErrors,
    add_completion=True,
    pretty_exceptions_enable=False,
    no_args_is_help=True,
    rich_markup_mode=None,
    help=HELP,
)
sweep_app = typer.Typer(rich_markup_mode=None, no_args_is_help=True, help=sweep.HELP)
weather_app = typer.Typer(rich_markup_mode=None, no_args_is_help=True, help=weather.HELP)


def _print_version(value: bool) -> None:
    if value:
        from foldopt import __version__

        typer.echo(f"foldopt {__version__}")
        raise typer.Exit()


@app.callback()
def _options(
    debug: Annotated[
        bool, typer.Option("--debug", help="Show the traceback of an internal error.")
    ] = False,
    version: Annotated[
        bool,
        typer.Option(
            "--version",
            callback=_print_version,
            is_eager=True,
            help="Print foldopt's version and exit.",
        ),
    ] = False,
):
    _DEBUG["on"] = debug
    # A yes-or-no variable that is neither is refused before any command works, not only where a
    # fetch or a notice would read it.
    from foldopt.cache import YES_OR_NO_VARIABLES, env_flag

    for name in YES_OR_NO_VARIABLES:
        env_flag(name)


app.add_typer(sweep_app, name="sweep", short_help=sweep.SHORT_HELP)
app.add_typer(weather_app, name="weather", short_help=weather.SHORT_HELP)
for group, commands in (
    (app, run.COMMANDS),
    (sweep_app, sweep.COMMANDS),
    (app, map_command.COMMANDS),
    (app, size.COMMANDS),
    (app, optimize.COMMANDS),
    (weather_app, weather.COMMANDS),
):
    for name, command, short_help in commands:
        group.command(name, cls=_OnceEach, short_help=short_help)(command)


def main():  # pragma: no cover - console-script entry point
    """The ``foldopt`` console script: run the app on ``sys.argv``."""
    app()


if __name__ == "__main__":  # pragma: no cover
    main()
