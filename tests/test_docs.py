"""The manual builds from the foldopt the suite tests, with warnings as errors, from a copy of docs/
outside the source tree; its references hold every command-line option and every study field;
the README stays a short front page whose tables and figures match the committed examples; the
example notebook runs and reproduces the paper's headline numbers."""

from __future__ import annotations

import csv
import filecmp
import html
import re
import shutil
import sys
import typing
from pathlib import Path

import pytest

#: One worker runs the tests of the built manual (it is built once, by one worker; pytest-xdist --dist
#: loadgroup); the others go to either. The build is session-scoped: the worker may run other
#: modules' tests between these, which would tear a module-scoped fixture down and build the manual
#: again (it was, 20 s each time).
BUILT = pytest.mark.xdist_group("docs")

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")
PAGES = ("index", "quickstart", "cli", "study-file", "outputs", "api", "reproduction", "physics", "performance",
         "reliability", "architecture", "examples/paper", "examples/weather_year", "examples/camera_profile",
         "examples/design_map", "examples/world_map", "examples/configs")


@pytest.fixture(scope="session")
def built(tmp_path_factory):
    """The HTML manual, built with warnings as errors from a copy of docs/ with the working folder
    outside the source tree, by the foldopt the suite tests. Sphinx runs in this process, as
    ``python -m sphinx -W -b html`` runs it: a process of its own imported again what the suite has
    imported. It leaves the working folder, ``sys.path`` (conf.py puts its extensions' folder first)
    and matplotlib's settings (its plot directive sets ``figure.autolayout``) as it found them. Its
    search index, which nothing here reads, is not built."""
    pytest.importorskip("sphinx")
    pytest.importorskip("numpydoc")
    import io

    import matplotlib
    from sphinx.application import Sphinx
    from sphinx.util.console import strip_colors
    from sphinx.util.docutils import docutils_namespace, patch_docutils

    work = tmp_path_factory.mktemp("docs")
    shutil.copytree(ROOT / "docs", work / "docs", ignore=shutil.ignore_patterns("_build", "generated"))
    log = io.StringIO()
    with pytest.MonkeyPatch.context() as patch, matplotlib.rc_context():
        patch.chdir(work)
        patch.setattr(sys, "path", list(sys.path))
        with patch_docutils(work / "docs"), docutils_namespace():
            app = Sphinx(work / "docs", work / "docs", work / "html", work / "doctrees", "html", status=None,
                         warning=log, warningiserror=True)
            app.builder.search = False
            app.build()
    assert app.statuscode == 0, strip_colors(log.getvalue())[-3000:]
    return work / "html"


def _first_cells(page: str) -> set[str]:
    """The text of the first cell of every table row of an HTML page (an option, a field)."""
    rows = re.findall(r"<tr[^>]*>\s*<td[^>]*>(.*?)</td>", page, flags=re.S)
    return {" ".join(html.unescape(re.sub(r"<[^>]+>", " ", cell)).split()) for cell in rows}


def _commands(command, path):
    """(path, click command) of the command line and every subcommand."""
    yield path, command
    for name, sub in getattr(command, "commands", {}).items():
        yield from _commands(sub, [*path, name])


def _fields(model, prefix=""):
    """Every dotted field path of a study, nested mappings included."""
    from pydantic import BaseModel

    for name, field in model.model_fields.items():
        yield prefix + name
        pending = [field.annotation]
        while pending:
            annotation = pending.pop()
            if isinstance(annotation, type) and issubclass(annotation, BaseModel):
                yield from _fields(annotation, f"{prefix}{name}.")
            else:
                pending += [arg for arg in typing.get_args(annotation) if not isinstance(arg, (str, int))]


@BUILT
def test_every_page_builds_and_the_examples_run(built):
    for page in PAGES:
        assert (built / f"{page}.html").exists(), page
    assert len(list((built / "_images").glob("*-1.png"))) == 3  # the three plot examples ran
    reproduction = (built / "reproduction.html").read_text(encoding="utf-8")
    assert "4.398" in reproduction and "4.693" in reproduction  # foldopt.reproduce() ran at build time


@BUILT
def test_the_cli_reference_holds_every_command_and_option(built):
    import typer.main

    from foldopt.cli.app import app

    page = (built / "cli.html").read_text(encoding="utf-8")
    starts = [match.start() for match in re.finditer(r'<section id="cli-', page)] + [len(page)]
    missing = []
    for path, command in _commands(typer.main.get_command(app), ["foldopt"]):
        ident = f'<section id="cli-{"-".join(path)}">'
        assert ident in page, " ".join(path)
        begin = page.index(ident)
        own = page[begin:min(start for start in starts if start > begin)]
        shown = {name for cell in _first_cells(own) for name in cell.split(", ")}
        missing += [f"{' '.join(path)} {name}" for param in command.params
                    for name in [*param.opts, *param.secondary_opts] if name not in shown]
    assert missing == []
    assert "taken by foldopt" in page  # the table of the options several commands share


def _rst_blocks(lines: list[str]) -> list[str]:
    """The lines of a reStructuredText page's literal blocks (after a line ending in ``::``)."""
    found, indent = [], None
    for line in lines:
        depth = len(line) - len(line.lstrip())
        if indent is not None and line.strip() and depth <= indent:
            indent = None
        if indent is not None:
            found.append(line)
        elif line.rstrip().endswith("::"):
            indent = depth
    return found


def command_lines(text: str) -> list[str]:
    """Every ``foldopt ...`` command line of a page: inline literals, and the lines of its bash
    blocks (Markdown) or literal blocks (reStructuredText), a trailing backslash joining the next;
    templates (``<command>``, ``[CONFIG]``, ``a | b``, ``...``) left out."""
    found = [" ".join(span.split()) for span in re.findall(r"(?<!`)``?(foldopt [^`]+?)``?(?!`)", text)]
    if "```" in text:
        lines = [line for block in re.findall(r"```bash\n(.*?)```", text, flags=re.S) for line in block.splitlines()]
    else:
        lines = _rst_blocks(text.splitlines())
    index = 0
    while index < len(lines):
        line = lines[index].strip().removeprefix("$ ")
        index += 1
        if not line.startswith("foldopt "):
            continue
        while line.endswith("\\") and index < len(lines):
            line = line[:-1] + " " + lines[index].strip()
            index += 1
        found.append(line)
    return [line for line in found if not re.search(r"[<\[|]|\.\.\.", line)]


def test_every_command_line_in_the_docs_parses():
    """Each command line the README and the manual show names a command and options it has, with
    values of their types (Click parses it; nothing runs, and no eager option such as
    --install-completion is reached: the line of a group is only looked up)."""
    import shlex

    import typer.main

    from foldopt.cli.app import app

    root = typer.main.get_command(app)
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.rst"))]
    lines = [(page.name, line) for page in pages for line in command_lines(page.read_text(encoding="utf-8"))]
    assert len(lines) > 50
    refused = []
    for page, line in lines:
        args, command, name = shlex.split(line, comments=True)[1:], root, "foldopt"
        while hasattr(command, "commands") and args and not args[0].startswith("-"):
            name = args.pop(0)
            command = command.commands.get(name)
            if command is None:
                refused.append(f"{page}: {line}: no command {name}")
                break
        if command is None or hasattr(command, "commands"):
            continue
        try:
            command.make_context(name, args)
        except Exception as error:  # click's UsageError and its kin, as the command line would refuse it
            refused.append(f"{page}: {line}: {error}")
    assert refused == []


def test_the_cli_page_and_the_readme_list_every_command():
    """The command tables of docs/cli.rst and the README name every command of the command line."""
    import typer.main

    from foldopt.cli.app import app

    root = typer.main.get_command(app)
    page = (ROOT / "docs" / "cli.rst").read_text(encoding="utf-8")
    table = page[:page.index("\n---")]  # the table before the page's first section
    listed = set(re.findall(r"\* - ``foldopt ([a-z ]+?)[ `\[]", table))
    leaves = {f"{group} {name}" if hasattr(command, "commands") else group
              for group, top in root.commands.items() for name, command in
              (getattr(top, "commands", None) or {group: top}).items()}
    assert leaves - listed == set()
    readme = set(re.findall(r"^\| `foldopt ([a-z]+)", README, flags=re.M))
    assert set(root.commands) - readme == set()


def test_the_api_page_lists_every_public_name():
    import foldopt

    page = (ROOT / "docs" / "api.rst").read_text(encoding="utf-8")
    shown = re.findall(r"^   foldopt\.(\w+)\s*$", page, flags=re.M)
    assert sorted(set(foldopt.__all__) - {"__version__"} - set(shown)) == []
    assert sorted(set(shown) - set(foldopt.__all__)) == []
    assert len(shown) == len(set(shown))


@BUILT
def test_the_study_file_reference_holds_every_field(built):
    import foldopt

    shown = _first_cells((built / "study-file.html").read_text(encoding="utf-8"))
    fields = list(_fields(foldopt.Study))
    assert len(fields) > 60
    assert [field for field in fields if field not in shown] == []


def test_the_docs_figures_are_the_committed_examples():
    copies = sorted((ROOT / "docs" / "_static" / "examples").rglob("*.png"))
    assert copies
    for copy in copies:
        committed = ROOT / "results" / "examples" / copy.relative_to(ROOT / "docs" / "_static" / "examples")
        assert filecmp.cmp(copy, committed, shallow=False), f"cp {committed} {copy}"


def test_the_readme_is_a_front_page():
    lines = README.splitlines()
    assert len(lines) <= 200
    commands = [line for line in lines if line and not line.startswith("#")][:4]
    assert commands == ["```bash", "pip install . && foldopt run --overwrite",
                        "pip install '.[test]' && python -m pytest", "```"]
    for target in re.findall(r"\]\(([^)#\s]+)", README) + re.findall(r'src="([^"]+)"', README):
        if "://" not in target:
            assert (ROOT / target).exists(), target
    assert len(re.findall(r"!\[[^\]]*\]\(", README)) == 1  # one figure


def test_the_readme_reproduction_table_is_the_committed_one():
    tables = {}
    for name in ("reproduction", "reproduction_single_diode"):
        with open(ROOT / "results" / "examples" / "reproduction" / f"{name}.csv", newline="") as file:
            tables[name] = {row["quantity"]: row for row in csv.DictReader(file)}
    rows = {cells[0].strip("` "): cells for cells in
            ([cell.strip() for cell in line.strip("|").split("|")] for line in README.splitlines()
             if line.startswith("| `"))}
    assert set(tables["reproduction"]) <= set(rows)
    for quantity, row in tables["reproduction"].items():
        shown = rows[quantity][2:7]
        committed = [row["paper"], row["paper_mode"], row["exact_mode"],
                     tables["reproduction_single_diode"][quantity]["paper_mode"],
                     tables["reproduction_single_diode"][quantity]["exact_mode"]]
        for text, value in zip(shown, committed):
            if text == "–":
                assert value == "", quantity
            else:
                digits = len(text.partition(".")[2])
                assert round(float(value), digits) == pytest.approx(float(text)), (quantity, text, value)


def test_example_notebook_runs():
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    notebook = nbformat.read(ROOT / "examples" / "paper_headline.ipynb", as_version=4)
    assert len(notebook.cells) < 10
    nbclient.NotebookClient(notebook, timeout=300, kernel_name="python3",
                            resources={"metadata": {"path": str(ROOT)}}).execute()
    printed = "".join(output.get("text", "") for cell in notebook.cells if cell.cell_type == "code"
                      for output in cell.get("outputs", []))
    assert "best fold angle: paper 29.8 deg, foldopt 28.5 deg" in printed
