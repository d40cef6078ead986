"""Sphinx extension: the manual's reference pages, written at build time from the installed foldopt
so that they cannot drift from the code.

Directives
----------
``.. foldopt-cli::``
    Every command of the command line, read off the Typer app's click tree: its usage, its help
    and every option with its type, default and help, as ``foldopt <command> --help`` prints them.
``.. foldopt-cli-shared::``
    The options several commands take, and which commands take each, off the same tree.
``.. foldopt-study::``
    Every field of a study file, read off the pydantic models of :class:`foldopt.Study`: its
    dotted path, type, default, what it accepts (the validator's own words) and description.
``.. foldopt-names::``
    Every registry of names (:data:`foldopt.names.REGISTRIES`): each member, its description and
    the other spellings accepted (:data:`foldopt.names.ALIASES`).
``.. foldopt-study-file:: NAME``
    A study file that ships with foldopt (``configs/NAME.yaml``), verbatim.
``.. foldopt-reproduction:: TABLE``
    One table of :func:`foldopt.reproduce`, computed at build time.
``.. foldopt-rst:: MODULE.FUNCTION``
    The reStructuredText a foldopt function writes (the table of figures).

It also keeps ``|latitude|`` in docstrings as the absolute value it means (autodoc would read a
substitution).
"""

from __future__ import annotations

import functools
import importlib
import inspect
import math
import re
import types
import typing

from docutils import nodes
from docutils.parsers.rst import Directive
from docutils.statemachine import StringList

#: A default as click's help text states it, ``[default: ...]``; it gets a column of its own.
_DEFAULT = re.compile(r"\s*\[default: ([^\]]*)\]")


# --- docutils helpers ----------------------------------------------------------------------------

def _cell(content) -> nodes.entry:
    entry = nodes.entry()
    if isinstance(content, nodes.Node):
        entry += content if isinstance(content, nodes.paragraph) else nodes.paragraph("", "", content)
    else:
        entry += nodes.paragraph(text=str(content))
    return entry


def _table(header: list[str], rows: list[list], widths: list[int]) -> nodes.table:
    """A docutils table: every cell a string (plain text) or an inline node."""
    table = nodes.table(classes=["longtable"])
    group = nodes.tgroup(cols=len(header))
    table += group
    group += [nodes.colspec(colwidth=width) for width in widths]
    head, body = nodes.thead(), nodes.tbody()
    head += nodes.row("", *(_cell(text) for text in header))
    body += [nodes.row("", *(_cell(cell) for cell in row)) for row in rows]
    group += [head, body]
    return table


def _literal(text: str) -> nodes.literal:
    return nodes.literal(text=text)


def _section(document, title: nodes.Node | str, ident: str) -> nodes.section:
    section = nodes.section(ids=[ident], names=[ident])
    section += nodes.title("", "", title) if isinstance(title, nodes.Node) else nodes.title(text=title)
    document.note_explicit_target(section)
    return section


def _paragraphs(text: str) -> list[nodes.Node]:
    """Click help text: paragraphs, and each ``\\b`` paragraph (kept as written) a literal block."""
    found = []
    for block in re.split(r"\n\s*\n", text.strip()):
        if block.startswith("\b"):
            found.append(nodes.literal_block(text=block.lstrip("\b").strip("\n")))
        elif block.strip():
            found.append(nodes.paragraph(text=" ".join(block.split())))
    return found


# --- the command line ----------------------------------------------------------------------------

def _option_row(param, ctx) -> list:
    """[names, type, default, help] of one option or argument, as ``--help`` prints it."""
    record = param.get_help_record(ctx) or (param.human_readable_name, "")
    spelled, text = record
    names = ", ".join(sorted([*param.opts, *param.secondary_opts], key=lambda name: len(name) - len(name.lstrip("-"))))
    kind = "flag" if getattr(param, "is_flag", False) else spelled[len(names):].strip().strip("<>") or "value"
    match = _DEFAULT.search(text)
    if match:
        default, text = match.group(1), (text[:match.start()] + text[match.end():]).strip()
    elif param.required:
        default = "required"
    elif getattr(param, "is_flag", False):
        default = "off"
    elif param.default not in (None, (), []):
        default = str(param.default)
    else:
        default = ""
    return [_literal(names), kind, default, text]


def _command_section(document, command, path: list[str], parent_ctx) -> nodes.section:
    ctx = command.context_class(command, info_name=path[-1], parent=parent_ctx)
    section = _section(document, _literal(" ".join(path)), "cli-" + "-".join(path))
    section += nodes.literal_block(text=" ".join([ctx.command_path, *command.collect_usage_pieces(ctx)]))
    section += _paragraphs(command.help or "")
    params = [param for param in command.params if not getattr(param, "hidden", False)]
    if params:
        section += _table(["option", "type", "default", "what it sets"],
                          [_option_row(param, ctx) for param in params], [22, 9, 19, 50])
    for name in getattr(command, "list_commands", lambda ctx: [])(ctx):
        sub = command.get_command(ctx, name)
        if sub is not None and not getattr(sub, "hidden", False):
            section += _command_section(document, sub, [*path, name], ctx)
    return section


class CliReference(Directive):
    """Every command, argument and option of ``foldopt``."""

    def run(self):
        import typer.main

        from foldopt.cli.app import app

        command = typer.main.get_command(app)
        return [_command_section(self.state.document, command, ["foldopt"], None)]


def _leaves(command, path: list[str]):
    """(path, command) of every command under ``command`` that is no group."""
    for name, sub in getattr(command, "commands", {}).items():
        if hasattr(sub, "commands"):
            yield from _leaves(sub, [*path, name])
        elif not getattr(sub, "hidden", False):
            yield [*path, name], sub


def shared_options(command, least: int = 3) -> dict[str, list[str]]:
    """Each option that several commands take -> the commands, a group named once where all its
    commands take the option (``sweep`` for its four).

    Parameters
    ----------
    command : click.Group
        The command line.
    least : int
        How many of its top-level commands (a group as one) must take an option; 3 leaves out
        those only ``sweep`` and ``optimize`` share (``optimize`` takes every sweep option).

    Returns
    -------
    dict
        The option's names (``-q, --quiet``) -> the commands, in the command line's order.
    """
    takers: dict[str, list[list[str]]] = {}
    groups: dict[str, int] = {}
    for path, leaf in _leaves(command, []):
        groups[path[0]] = groups.get(path[0], 0) + 1
        for param in leaf.params:
            if param.param_type_name == "option" and not param.hidden:
                names = ", ".join(sorted([*param.opts, *param.secondary_opts], key=len))
                takers.setdefault(names, []).append(path)
    shared = {}
    for names, paths in takers.items():
        tops = list(dict.fromkeys(path[0] for path in paths))
        if len(tops) >= least:
            whole = {top for top in tops if sum(path[0] == top for path in paths) == groups[top]}
            shared[names] = list(dict.fromkeys(path[0] if path[0] in whole else " ".join(path) for path in paths))
    return shared


class CliShared(Directive):
    """The options that several commands take, and which commands take each."""

    def run(self):
        import typer.main

        from foldopt.cli.app import app

        shared = shared_options(typer.main.get_command(app))
        rows = [[_literal(names), ", ".join(commands)] for names, commands in shared.items()]
        return [_table(["option", "taken by foldopt"], rows, [30, 70])]


# --- the study file ------------------------------------------------------------------------------

def _unwrap(annotation):
    """(the type without Annotated, its metadata), Annotated unwrapped at the outer level."""
    metadata = []
    while typing.get_origin(annotation) is typing.Annotated:
        annotation, *extra = typing.get_args(annotation)
        metadata += extra
    return annotation, metadata


def _arms(annotation) -> list:
    """The members of a union (``X | None``), or the type itself."""
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        return list(typing.get_args(annotation))
    return [annotation]


def _model(annotation):
    """The pydantic model a field holds (through ``| None``), or None."""
    from pydantic import BaseModel

    for arm in _arms(_unwrap(annotation)[0]):
        arm = _unwrap(arm)[0]
        if isinstance(arm, type) and issubclass(arm, BaseModel):
            return arm
    return None


def _type_text(annotation) -> str:
    from pydantic import BaseModel

    annotation = _unwrap(annotation)[0]
    arms = _arms(annotation)
    if len(arms) > 1:
        shown = [_type_text(arm) for arm in arms if arm is not type(None)]
        return " or ".join(shown) + (" or null" if type(None) in arms else "")
    origin = typing.get_origin(annotation)
    if origin is list:
        return f"list of {_type_text(typing.get_args(annotation)[0])}"
    if origin is dict:
        key, value = typing.get_args(annotation)
        return f"mapping of {_type_text(key)} to {_type_text(value)}"
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return "mapping"
    return {"float": "number", "int": "integer", "bool": "true | false", "str": "text", "dict": "mapping",
            "date": "date"}.get(getattr(annotation, "__name__", ""), str(annotation))


def _constraints(annotation, metadata=()) -> list[str]:
    """Constraints stated as metadata (pydantic's ``Field(ge=...)``, ``max_length``, ``pattern``)
    of a field, of each arm of a union and of a list's items."""
    from pydantic.fields import FieldInfo

    words = {"gt": "> {}", "ge": "≥ {}", "lt": "< {}", "le": "≤ {}", "multiple_of": "a multiple of {}",
             "max_length": "at most {} characters", "pattern": "matching {}"}
    inner, nested = _unwrap(annotation)
    found = []
    for item in [*metadata, *nested]:
        for item in (item.metadata if isinstance(item, FieldInfo) else [item]):
            found += [word.format(getattr(item, attribute)) for attribute, word in words.items()
                      if getattr(item, attribute, None) is not None]
    arms = _arms(inner)
    for arm in arms:
        if typing.get_origin(arm) is list:
            found += [f"each {text}" for text in _constraints(typing.get_args(arm)[0])]
        elif len(arms) > 1:
            found += _constraints(arm)
    return found


def _probe(annotation):
    """A value each validator refuses in its own words: NaN for a number, the empty name for a
    name, a list of such for a list; None where there is none."""
    annotation = _unwrap(annotation)[0]
    for arm in _arms(annotation):
        arm = _unwrap(arm)[0]
        if arm is float:
            return math.nan
        if arm is str:
            return ""
        if typing.get_origin(arm) is list:
            item = _probe(typing.get_args(arm)[0])
            if item is not None:
                return [item]
    return None


def _accepts(field) -> str:
    """What a field accepts: its stated constraints and its validators' "must be ..." messages."""
    from pydantic import TypeAdapter, ValidationError

    annotation = typing.Annotated[(field.annotation, *field.metadata)] if field.metadata else field.annotation
    stated = _constraints(field.annotation, field.metadata)
    value = _probe(field.annotation)
    if value is not None:
        try:
            TypeAdapter(annotation).validate_python(value)
        except ValidationError as error:
            for problem in error.errors():
                message = str(problem.get("ctx", {}).get("error", ""))
                if message.startswith("must be") and message not in stated:
                    stated.append(message)
    return "; ".join(stated)


def _default_text(field) -> str:
    from pydantic import BaseModel

    if field.is_required():
        return "required"
    value = field.default
    if isinstance(value, BaseModel):
        return "its fields'"
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if value == "":
        return '""'
    return f"{value:g}" if isinstance(value, float) else str(value)


def _documented(model) -> tuple[str, dict[str, str]]:
    """A model's numpydoc docstring: its summary, and each field's description from Parameters."""
    from numpydoc.docscrape import NumpyDocString

    doc = NumpyDocString(inspect.cleandoc(model.__doc__ or ""))
    summary = "\n".join(doc["Summary"]) + "\n\n" + "\n".join(doc["Extended Summary"])
    fields = {name.strip(): " ".join(parameter.desc)
              for parameter in doc["Parameters"] for name in parameter.name.split(",")}
    return summary.strip(), fields


def _literal_bars(text: str) -> str:
    """``|latitude|`` as the text means it, not a substitution reference."""
    return re.sub(r"\|(\w+)\|", r"\\|\1\\|", text)


class StudyReference(Directive):
    """Every field of a study file, one table per mapping (the study, site, panel, ...), each
    described by its model's docstring (or the field's own description)."""

    def _rst(self, text: str, inline: bool):
        text = _literal_bars(text)
        if inline:
            parsed, messages = self.state.inline_text(text, self.lineno)
            return nodes.paragraph("", "", *parsed, *messages)
        box = nodes.container()
        self.state.nested_parse(StringList(text.splitlines()), self.content_offset, box)
        return box.children

    def _mapping(self, path: str, model, pending: list) -> nodes.section:
        summary, described = _documented(model)
        ident = "study-fields" if path == "study" else "study-" + path.replace("_", "-")
        section = _section(self.state.document, _literal(path), ident)
        if path != "study":
            section += self._rst(summary, inline=False)
        rows = []
        for name, field in model.model_fields.items():
            dotted = name if path == "study" else f"{path}.{name}"
            nested = _model(field.annotation)
            if nested is not None:
                pending.append((dotted, nested))
            description = described.get(name) or field.description or ""
            rows.append([_literal(dotted), _type_text(field.annotation), _default_text(field), _accepts(field),
                         self._rst(description, inline=True)])
        section += _table(["field", "type", "default", "accepts", "what it sets"], rows, [18, 12, 12, 22, 36])
        return section

    def run(self):
        import foldopt

        pending, found = [("study", foldopt.Study)], []
        while pending:
            path, model = pending.pop(0)
            found.append(self._mapping(path, model, pending))
        return found


class NamesReference(Directive):
    """Every registry of names with its members' descriptions and their other spellings."""

    def run(self):
        from foldopt import names

        aliases: dict[str, list[str]] = {}
        for alias, name in names.ALIASES.items():
            aliases.setdefault(name, []).append(alias)
        rows = [[registry.kind, _literal(name), registry.describe(name), ", ".join(aliases.get(name, []))]
                for registry in names.REGISTRIES for name in registry]
        return [_table(["kind", "name", "what it is", "also accepted"], rows, [14, 16, 55, 15])]


class CapabilityMatrix(Directive):
    """The capability matrix (:mod:`foldopt.capabilities`): which run honours which section, and
    which runs each command makes."""

    def run(self):
        from foldopt import capabilities

        header, *rows = capabilities.matrix_rows()
        width = (100 - 40) // (len(header) - 2)
        matrix = _table(header, [[_literal(row[0]), *row[1:]] for row in rows],
                        [15, 25, *[width] * (len(header) - 2)])
        runs = [[_literal(command), ", ".join(runs)] for command, runs in capabilities.COMMAND_RUNS.items()]
        described = [[_literal(run), capabilities.RUNS.describe(run)] for run in capabilities.RUNS]
        set_by = [[_literal(run), _literal(field), why] for run, fields in capabilities.SET_BY_RUN.items()
                  for field, why in fields.items()]
        return [_table(["run", "what it evaluates"], described, [20, 80]), matrix,
                _table(["command", "its runs"], runs, [30, 70]),
                _table(["run", "field", "why a request may not give it"], set_by, [15, 20, 65])]


class StudyFile(Directive):
    """A study file shipped with foldopt, verbatim."""

    required_arguments = 1

    def run(self):
        from foldopt.inputs.study_file import default_study_path

        path = default_study_path(self.arguments[0])
        block = nodes.literal_block(text=path.read_text(encoding="utf-8"), language="yaml")
        return [nodes.paragraph("", "", _literal(f"configs/{path.name}")), block]


@functools.cache
def _reproduction():
    import foldopt

    return foldopt.reproduce()


def _number(value) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "–"
    return f"{value:.4g}" if isinstance(value, float) else str(value)


class ReproductionTable(Directive):
    """One table of :func:`foldopt.reproduce` (``reproduction`` or ``reproduction_single_diode``)."""

    required_arguments = 1

    def run(self):
        table = _reproduction().tables[self.arguments[0]]
        rows = [[_literal(str(row["quantity"])), row["unit"], *(_number(row[column])
                 for column in ("paper", "paper_mode", "exact_mode"))] for _, row in table.iterrows()]
        return [_table(["quantity", "unit", "paper", "paper mode", "exact mode"], rows, [34, 8, 14, 14, 14])]


class GeneratedRst(Directive):
    """reStructuredText written by a foldopt function, parsed in place."""

    required_arguments = 1

    def run(self):
        module, _, function = self.arguments[0].rpartition(".")
        text = getattr(importlib.import_module(module), function)()
        self.state_machine.insert_input(text.splitlines(), f"<{self.arguments[0]}>")
        return []


def _absolute_values(app, what, name, obj, options, lines):
    """autodoc: foldopt's docstrings write ``|latitude|`` for an absolute value; keep it text."""
    lines[:] = [_literal_bars(line) for line in lines]


def setup(app):
    app.connect("autodoc-process-docstring", _absolute_values)
    for name, directive in (("foldopt-cli", CliReference), ("foldopt-cli-shared", CliShared),
                            ("foldopt-study", StudyReference),
                            ("foldopt-names", NamesReference), ("foldopt-study-file", StudyFile),
                            ("foldopt-capabilities", CapabilityMatrix),
                            ("foldopt-reproduction", ReproductionTable), ("foldopt-rst", GeneratedRst)):
        app.add_directive(name, directive)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
