"""The README's commands, run in the order it shows them as a newcomer would on a fresh clone, and
what it quotes of their answers: each line of an output block is a line the commands print, and
each figure (``9.44 h``, ``+8.5 %``, ``28.5°``, ``6.6 min``) of the paragraphs that lead to a
block of commands and follow it, or that name a command, is a number they print, at the README's
rounding.

The commands run in-process (typer's CliRunner) in a folder of their own that holds the clone's
``configs/`` and ``tests/data``; their results folders are made but not filled (foldopt.api.write
is tested on its own, and the figures cost some seconds a command), so that one writing a folder
another already wrote fails as it would: "already exists".

Three of the README's commands are left to ``FOLDOPT_README_ALL=1`` (the test then takes 83 s, not
8 s): the maps, which start a Dask cluster (the second on a scheduler and workers the README starts
by hand, here a local cluster of the test's own at another address), and the 20-member cloud
ensemble of single-diode panels (160 s from the shell, 40 s here without its figures). Without it
their lines are still parsed by tests/test_docs.py::test_every_command_line_in_the_docs_parses, and
the folders they name are still checked to be their own.
"""

from __future__ import annotations

import os
import re
import shlex
from pathlib import Path

import pytest
from typer.testing import CliRunner

from foldopt.cli.app import app

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")
#: A figure the README quotes: a number and its unit.
FIGURE = re.compile(r"([+-]?\d+(?:\.\d+)?)\s?(?:h|%|°|deg|min)(?![\w/])")
#: Commands too slow for the suite (see the module's docstring), by a part of their line.
SLOW = ("foldopt map ", "--members 20")


def _paragraph_after(lines: list[str], start: int) -> str:
    """The paragraph from ``start`` (blank lines skipped) to a blank line, a block or a heading."""
    while start < len(lines) and not lines[start].strip():
        start += 1
    end = start
    while end < len(lines) and lines[end].strip() and not lines[end].startswith(("```", "#", "**")):
        end += 1
    return " ".join(lines[start:end])


def _paragraph_before(lines: list[str], end: int) -> str:
    """The paragraph that ends just before line ``end`` (blank lines skipped), or ``""``."""
    while end > 0 and not lines[end - 1].strip():
        end -= 1
    start = end
    while start > 0 and lines[start - 1].strip() and not lines[start - 1].startswith(("```", "#", "|")):
        start -= 1
    return " ".join(lines[start:end]) if end and not lines[end - 1].startswith("```") else ""


def readme_steps(text: str = README) -> list[dict]:
    """The README in order: each bash block's foldopt commands with the output block that follows
    it and the paragraphs before and after them, and each paragraph that names a command inline.

    Returns
    -------
    list of dict
        ``{"commands": [...], "output": [...], "prose": str}``; an inline command without arguments
        (``foldopt run`` in a caption) is ``{"mention": line, "prose": str}``.
    """
    lines, steps, index = text.splitlines(), [], 0
    while index < len(lines):
        line = lines[index]
        if line.startswith("```bash"):
            lead, end = _paragraph_before(lines, index), lines.index("```", index + 1)
            block = " \n".join(lines[index + 1:end]).replace("\\ \n", " ").split(" \n")
            commands = [" ".join(part.split("&&")[-1].split()) for part in block
                        if part.split("&&")[-1].strip().startswith("foldopt ")]
            index = end + 1
            output = []
            if index < len(lines) and lines[index] == "```":
                end = lines.index("```", index + 1)
                output, index = lines[index + 1:end], end + 1
            steps.append({"commands": commands, "output": output, "prose": lead + " " + _paragraph_after(lines, index),
                          "install": any("pip install" in part for part in block)})
            continue
        if line.startswith("```"):
            index = lines.index("```", index + 1) + 1  # a python block, an output block of no command
            continue
        if line.strip() and not line.startswith(("#", "|", "![")):
            end = index
            while end < len(lines) and lines[end].strip() and not lines[end].startswith(("```", "#")):
                end += 1
            prose, index = " ".join(lines[index:end]), end
            named = [command for command in re.findall(r"`(foldopt [^`]+)`", prose)
                     if not re.search(r"[<\[|]|\.\.\.", command)] if FIGURE.search(prose) else []
            run = [command for command in named if len(command.split()) > 2]
            if run:  # the paragraph's commands, its figures what they print together
                steps.append({"commands": run, "output": [], "prose": prose})
            steps += [{"mention": command, "output": [], "prose": prose} for command in named if command not in run]
            continue
        index += 1
    return steps


def _numbers(text: str) -> list[float]:
    return [abs(float(number)) for number in re.findall(r"[+-]?\d+(?:\.\d+)?", text.replace(",", ""))]


def _figures_missing(prose: str, printed: str) -> list[str]:
    """The figures of ``prose`` that no number of ``printed`` rounds to."""
    numbers = _numbers(printed)
    missing = []
    for match in FIGURE.finditer(prose):
        text = match.group(1)
        value, places = abs(float(text)), len(text.partition(".")[2])
        if not any(abs(number - value) <= 0.5 * 10 ** -places + 1e-9 for number in numbers):
            missing.append(match.group(0))
    return missing


def test_the_steps_are_the_readmes():
    """The parsing itself: the README's bash blocks, output blocks and quoted figures are all seen."""
    steps = readme_steps()
    commands = [command for step in steps for command in step.get("commands", [])]
    assert commands[0] == "foldopt run --overwrite"
    assert len(commands) >= 10 and any("foldopt optimize" in command for command in commands)
    assert sum(len(step["output"]) for step in steps) >= 8
    assert sum(len(FIGURE.findall(step["prose"])) for step in steps) >= 15


def test_every_readme_command_runs_in_order_and_prints_what_the_readme_quotes(tmp_path, monkeypatch,
                                                                             folders_written_elsewhere):
    every = os.environ.get("FOLDOPT_README_ALL") == "1"
    for name in ("configs", "tests"):
        (tmp_path / name).symlink_to(ROOT / name)
    monkeypatch.chdir(tmp_path)
    with folders_written_elsewhere():
        _run_the_readme(every)


def _run_the_readme(every: bool) -> None:
    """Run the README's commands in order (every one with ``every``, else all but :data:`SLOW`'s)
    in the working folder, and assert that they print what it quotes."""
    runner, printed, folders, wrong = CliRunner(), {}, {}, []
    for step in readme_steps():
        if "mention" in step:  # a caption's `foldopt run`: what the command run before printed
            shown = [text for command, text in printed.items() if command.startswith(step["mention"])]
            if not shown:  # `foldopt reproduce`: its table is test_docs' (the committed reproduction)
                continue
            wrong += [f"{step['mention']}: {figure}" for figure in _figures_missing(step["prose"], shown[0])]
            continue
        texts, skipped = [], False
        for command in step["commands"]:
            args = shlex.split(command, comments=True)[1:]
            out = args[args.index("--out") + 1] if "--out" in args else None
            if out is not None:  # each folder a command writes is its own, slow command or not
                assert out not in folders or "--overwrite" in args, f"{command}: {out} also {folders.get(out)}"
                folders[out] = command
            if any(part in command for part in SLOW) and not every:
                skipped = True
                continue
            if "--scheduler" in args:  # the README starts one by hand: here a cluster of the test's own
                from distributed import LocalCluster

                cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None)
                args[args.index("--scheduler") + 1] = cluster.scheduler_address
            result = runner.invoke(app, args, prog_name="foldopt")
            if "--scheduler" in args:
                cluster.close()
            assert result.exit_code == 0, f"{command}: {result.stderr}"
            printed[command] = result.stdout
            texts.append(result.stdout)
        if skipped:
            continue
        lines = "\n".join(texts).splitlines()
        for quoted in step["output"]:
            shown = quoted.removesuffix(" ...").removesuffix("...")
            if not any(line == quoted or (shown != quoted and line.startswith(shown)) for line in lines):
                wrong.append(f"{step['commands'][-1]}: {quoted}")
        if not step.get("install"):  # the install's paragraph gives its times, not an answer's
            missing = _figures_missing(step["prose"], "\n".join(texts))
            wrong += [f"{step['commands'][-1]}: {figure}" for figure in missing]
    assert wrong == [], "\n".join(wrong)


@pytest.mark.parametrize("prose,printed,missing", [
    ("folds to 28.5° and runs 9.44 h (+22.1 %)", "fold 28.50 deg: t_solar 9.438 h, +22.09 %", []),
    ("the smooth minutes (7.53 h at 108°)", "mean t_solar 7.90 h at 102 deg", ["7.53 h", "108°"]),
    ("within 6.6 min; 3 W load", "within 6.6 min", []),
])
def test_a_figure_is_a_printed_number_at_its_rounding(prose, printed, missing):
    assert _figures_missing(prose, printed) == missing
