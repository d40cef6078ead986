"""The command line's help and option plumbing, read off the app itself so that no command or
option is left out: a misspelt option or name gets what it most likely meant, an option whose help
says it takes a range or a list takes one (and one that does not say so takes one value), help
names the folder each command writes, and ``--set`` works where the docs say it does."""

import json
import re
from pathlib import Path

import pytest
import typer.main
from typer.testing import CliRunner

from foldopt.cli.app import app

runner = CliRunner()
ROOT = typer.main.get_command(app)


def _leaves(command=ROOT, path=()):
    for name, sub in command.commands.items():
        if hasattr(sub, "commands"):
            yield from _leaves(sub, (*path, name))
        else:
            yield (*path, name), sub


LEAVES = dict(_leaves())


def help_text(command, name: str) -> str:
    """The help of an option, its line wrapping undone."""
    param = next(param for param in command.params if name in param.opts)
    return " ".join((param.help or "").split())


def typo(word: str) -> str:
    """A word with its middle letter dropped (a letter, so that ``dual-axis`` does not become a
    spelling of itself)."""
    middle = len(word) // 2
    index = next(i for i in [*range(middle, len(word)), *range(middle, -1, -1)] if word[i].isalpha())
    return word[:index] + word[index + 1:]


def invoke(*args):
    return runner.invoke(app, [str(arg) for arg in args], prog_name="foldopt")


def refusal(capsys, *args) -> str:
    """The error line of a command line refused while its arguments are parsed, from the click
    command built once (CliRunner builds it again for each call: 50 ms); were it accepted, the
    command would run."""
    with pytest.raises(SystemExit) as end:
        ROOT.main([str(arg) for arg in args], prog_name="foldopt")
    printed = capsys.readouterr()
    assert end.value.code == 2 and printed.out == "", printed.out
    return printed.err.strip()


def test_a_misspelt_option_gets_that_option_among_all_the_commands_options(capsys):
    """Click compares the option as typed with every option, dashes and all: the ``--`` they share
    made ``--bogus`` close to ``--out`` and to nothing else, and a word a letter short was often
    matched with none."""
    missed = []
    for path, command in LEAVES.items():
        for param in command.params:
            for name in param.opts:
                if not name.startswith("--") or name == "--help":
                    continue
                wrong = "--" + typo(name[2:])
                line = refusal(capsys, *path, wrong)
                if not re.search(rf"did you mean [-\w ]*{re.escape(name)}\b", line):
                    missed.append(f"{' '.join(path)} {wrong}: {line}")
    assert missed == []


@pytest.mark.parametrize("path,args,end", [
    ("run", ["--bogus"], "No such option: --bogus (foldopt run --help lists its options)"),
    ("run", ["--lat", "3"], "No such option: --lat (--lat is an option of foldopt map, optimize, sweep, weather; "
                            "foldopt run --help lists its own)"),
    ("sweep angle", ["--p-laod", "3"], "No such option: --p-laod; did you mean --p-load?"),
    ("size", ["--cost", "3"], "No such option: --cost; did you mean --cost-per-m2 or --cost-per-w?"),
])
def test_an_unknown_option_is_one_line_that_suggests_only_what_is_close(path, args, end, capsys):
    assert refusal(capsys, *path.split(), *args) == f"error: foldopt {path}: {end}"


#: What the option choices are validated against needs: a range of days for an objective.
_CONTEXT = ["--days", "2025-03-20,2025-06-21"]
#: What an option needs beside it to be read at all.
_NEEDS = {"--weather-format": ["--weather", Path(__file__).resolve().parent.parent / "configs" / "weather"
                               / "723170TYA.CSV"]}


def _choices(text: str) -> list[str]:
    """The names an option's help lists as ``a | b (what b is) | c``; ``pNN`` is a pattern."""
    pieces = text.split(" | ")
    if len(pieces) < 2:
        return []
    names = [re.findall(r"[\w.-]+", re.sub(r"\([^)]*\)", "", pieces[0]))[-1]]
    names += [re.match(r"[\w.-]+", piece).group() for piece in pieces[1:]]
    return [name.rstrip(".") for name in names if name.rstrip(".") != "pNN"]


def test_every_choice_of_every_option_is_suggested_for_its_misspelling(tmp_path, monkeypatch, capsys):
    """Each option whose help lists its names (``--sky``, ``--objective``, ``--format``,
    ``--engine``, ``--show-period`` ...) answers a misspelt name with that name: the registries'
    names (foldopt.names.canonical), the objective's and the map's periods alike."""
    monkeypatch.chdir(tmp_path)  # nothing is written; were a misspelling accepted, not in the tree
    seen, missed, count = set(), [], 0
    for path, command in LEAVES.items():
        for param in command.params:
            text = " ".join((param.help or "").split())
            key = (param.opts[0], text)
            if key in seen or not param.opts[0].startswith("--"):
                continue
            seen.add(key)
            context = _CONTEXT if any("--days" in other.opts for other in command.params) else []
            for name in _choices(text):
                count += 1
                out = ["--out", tmp_path / "never"] if any("--out" in p.opts for p in command.params) else []
                line = refusal(capsys, *path, param.opts[0], typo(name), *context, *_NEEDS.get(param.opts[0], ()),
                               *out)
                if not re.search(rf"did you mean [^\n]*'{re.escape(name)}'", line):
                    missed.append(f"{' '.join(path)} {param.opts[0]} {typo(name)}: {line}")
    assert count > 60
    assert missed == []


#: A list for each option that can take several values, and what it needs beside it.
_SEVERAL = {"--lat": ["0,10"], "--lon": ["0,10"], "--days": ["2025-03-20,2025-06-21"], "--p-load": ["1,2"],
            "--tilt": ["10,20"], "--p-load-scale": ["1,2", "--load-profile", "profile.csv"]}
#: Each command's own axis at a small size, where the option tested does not give it.
_OWN = {("sweep", "latitude"): ["--lat", "0,10"], ("sweep", "day"): ["--days", "2025-03-20,2025-06-21"],
        ("sweep", "load"): ["--p-load", "1,2"], ("sweep", "angle"): ["--days", "2025-03-20"],
        ("optimize",): ["--days", "2025-03-20,2025-06-21", "--vary", "fold_angle"]}
#: How help says that an option takes several values.
_SAYS_SEVERAL = re.compile(r"a range\b.*\bor a list")
#: What a condition in an option's help (``with --objective``) takes to hold.
_CONDITIONS = {"--objective": ["--objective", "mean"]}


@pytest.mark.parametrize("path", list(_OWN), ids=" ".join)
def test_an_option_takes_a_list_exactly_where_its_help_says_so(path, tmp_path, monkeypatch):
    """``optimize --help`` said "or a range" of --lat and --tilt, which optimize refuses; each
    option's help now says what the command takes. Runs at 60-min steps and 30-deg angles, the
    folder not written (foldopt.api.write is what --out's other tests check); the folder the
    answer names is the one --out's help gives as its default."""
    import foldopt.api

    monkeypatch.setattr(foldopt.api, "write", lambda *args, **kwargs: None)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "profile.csv").write_text("time,watts\n00:00,1\n07:00,3\n19:00,1\n")
    command = LEAVES[path]
    default = re.search(r"\[default: ([^\]]+)\]", help_text(command, "--out")).group(1)
    checked = []
    for option, values in _SEVERAL.items():
        text = help_text(command, option)
        several = _SAYS_SEVERAL.search(text) is not None
        own = [] if option in _OWN[path] or (option == "--p-load-scale" and "--p-load" in _OWN[path]) else _OWN[path]
        condition = [arg for name, args in _CONDITIONS.items() if f"with {name}" in text for arg in args]
        result = invoke(*path, option, *values, *own, *condition, "--step-min", 60, "--angle-step", 30,
                        "--format", "json")
        if several:
            assert result.exit_code == 0, (option, result.stderr)
            assert json.loads(result.stdout)["out"] == default
        else:
            assert result.exit_code == 2 and result.stderr.startswith("error: "), (option, result.stdout)
        checked.append(several)
    assert any(checked)


class _Reached(Exception):
    """Raised by a stand-in for the map's run: the command accepted its options."""


def test_the_maps_options_take_a_list_exactly_where_their_help_says_so(monkeypatch):
    """As for the sweeps, with the map's run (a Dask cluster) replaced by one that ends the command
    where the work would start: the options were accepted once it is reached (exit 1, an internal
    error naming it), refused with exit 2."""
    import foldopt.api

    def reached(*args, **kwargs):
        raise _Reached()

    monkeypatch.setattr(foldopt.api, "world_map", reached)
    command = LEAVES[("map",)]
    lists = {"--lat": "0,10", "--lon": "0,10", "--p-load": "1,2", "--p-load-fraction": "0.2,0.4"}
    for option, value in lists.items():
        result = invoke("map", option, value, "--quiet")
        several = _SAYS_SEVERAL.search(help_text(command, option)) is not None
        assert (result.exit_code, "_Reached" in result.stderr) == ((1, True) if several else (2, False)), (
            option, result.stderr)


def test_help_names_no_other_command():
    """``optimize --help`` said "foldopt map: 5" of --step-min: each command's help speaks of itself."""
    wrong = []
    for path, command in LEAVES.items():
        text = invoke(*path, "--help").stdout
        named = {match for match in re.findall(r"foldopt ((?:sweep )?[a-z]+)", text)}
        wrong += [f"{' '.join(path)}: foldopt {name}" for name in named - {" ".join(path), path[0]}]
    assert wrong == []


def test_run_and_size_take_set(tmp_path, monkeypatch):
    """``foldopt run --set p_load=3`` was refused though the docs listed --set for every command;
    it runs the embedded study with that change, as a line of the study file would (the folders
    not written: foldopt.api.write is tested on its own)."""
    import foldopt.api

    monkeypatch.setattr(foldopt.api, "write", lambda *args, **kwargs: None)
    monkeypatch.chdir(tmp_path)
    result = invoke("run", "--set", "p_load=3", "--set", "step_min=10", "--format", "json")
    assert result.exit_code == 0, result.stderr
    document = json.loads(result.stdout)
    assert document["out"] == "results/shin2015" and "P_load 3 W" in document["answer"]["lines"][0]
    bad = invoke("run", "--set", "p_load=-3", "--set", "panel")
    assert bad.exit_code == 2
    assert bad.stderr.splitlines() == ["error: --set = 'panel': expected KEY=VALUE, e.g. panel.efficiency=0.21"]
    bad = invoke("run", "--set", "p_load=-3")
    assert bad.stderr.splitlines() == ["error: p_load = -3: must be in (0, 1e+06] W"]  # no line of the file
    sized = invoke("size", "--set", "p_load=3", "--areas", "0.1:0.3:0.1", "--format", "json")
    assert sized.exit_code == 0, sized.stderr
    assert "3 W" in " ".join(json.loads(sized.stdout)["answer"]["lines"])


def test_help_loads_none_of_the_studys_modules():
    """The command line's modules read no study at import: --help and the option checks Typer makes
    load neither numpy, pandas, pvlib, matplotlib nor yaml and pydantic (the study's readers, which
    brought numpy in and made 0.18 s of `foldopt --help`'s 0.30 s)."""
    import subprocess
    import sys

    heavy = ("numpy", "pandas", "pvlib", "matplotlib", "numba", "yaml", "pydantic")
    code = f"import sys, foldopt.cli.app; print(sorted(m for m in {heavy!r} if m in sys.modules))"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout.strip() == "[]"


#: The options of every sweep, as --help lists them; ``*`` marks those whose help says they take a
#: range or a list. Recorded from main (7ff6a51) before each command became a function of its own;
#: --planes and --fold-angle added with issue 51.
_SWEEP = ("--config --lat{o} --lon{o} --altitude --timezone --days/--date* --year --p-load{v} --load-profile "
          "--p-load-scale{v} --area --efficiency --tilt{o} --azimuth --planes --mode --geometry --sky --climate "
          "--weather "
          "--years --offline --weather-format --members --seed --force-site --transposition --albedo --iam "
          "--objective --visits --tracker --tracker-standby --pv-model --module --connection --switch-series "
          "--no-bypass --converter-efficiency --horizon --blocking-diode --bypass-diode --converter --load-voltage "
          "--switch-resistance --temp-air --exact-electrical --step-min --angle-step --fold-angle --storage-wh "
          "--min-soc --set "
          "--out --overwrite --quiet/-q --format --engine --table")
#: Every command's options (``/`` joins an option's spellings; an argument in capitals), recorded so.
RECORDED = {
    "map": "--lat* --lon* --land-only --sites --weather-dir --weather --years --offline --p-load* "
           "--p-load-fraction* --area --efficiency --objective --year --step-min --angle-step --fold-search "
           "--optimize --config --set --scheduler --workers --chunk-sites --show-load --show-period --resume "
           "--out --overwrite --quiet/-q --format --engine",
    "optimize": "--vary --fold-range --tilt-range --azimuth-range --tolerance "
                + _SWEEP.format(o="", v="*"),
    "reproduce": "--out --overwrite --quiet/-q --format --engine",
    "run": "CONFIG --out --overwrite --quiet/-q --format --engine --table --set --target-h",
    "size": "CONFIG --areas --cost-per-m2 --cost-per-w --c-grid --years --days-per-year --out --overwrite "
            "--quiet/-q --format --table --set --storage --target-h --weather",
    "sweep angle": _SWEEP.format(o="", v=""),
    "sweep day": _SWEEP.format(o="*", v="*"),
    "sweep latitude": _SWEEP.format(o="*", v="*"),
    "sweep load": _SWEEP.format(o="*", v="*"),
    "weather fetch": "SOURCE --lat --lon --years --no-horizon --raddatabase --url --timeout --quiet/-q --format",
    "weather list": "--quiet/-q --format",
    "weather path": "SOURCE --lat --lon --years --no-horizon --raddatabase --url --out --overwrite --quiet/-q "
                    "--format",
}


def test_every_command_takes_the_options_it_took_before_its_options_were_shared():
    """Each command is a function of its own whose options are the shared types of cli/options.py
    (one value, or several where the command sweeps the field): the same options, spellings and
    order as the generated signature gave, and a range or a list said of the same ones."""
    found = {}
    for path, command in LEAVES.items():
        ctx = command.make_context(" ".join(path), [], resilient_parsing=True)
        words = []
        for param in command.get_params(ctx):
            if param.name == "help":
                continue
            word = "/".join([*param.opts, *param.secondary_opts]) if param.param_type_name == "option" else \
                param.name.upper()
            words.append(word + ("*" if _SAYS_SEVERAL.search(" ".join((param.help or "").split())) else ""))
        found[" ".join(path)] = " ".join(words)
    assert found == RECORDED


def test_no_command_rewrites_a_signature_or_a_docstring():
    """Typer reads each command's own signature and docstring: nothing in foldopt/cli assigns a
    function's ``__signature__`` or ``__doc__`` (nor through setattr)."""
    import ast

    rewrites, modules = [], sorted((Path(__file__).resolve().parent.parent / "foldopt" / "cli").glob("*.py"))
    assert len(modules) > 5
    for path in modules:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            targets = node.targets if isinstance(node, ast.Assign) else \
                [node.target] if isinstance(node, (ast.AugAssign, ast.AnnAssign)) else []
            names = [target.attr for target in targets if isinstance(target, ast.Attribute)]
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "setattr" and len(node.args) > 1:
                names.append(getattr(node.args[1], "value", None))
            rewrites += [f"{path.name}:{node.lineno} {name}" for name in names
                         if name in ("__signature__", "__doc__")]
    assert rewrites == []


def test_python_m_foldopt_runs_the_command_line(tmp_path):
    """``python -m foldopt`` is the ``foldopt`` command: its help, its version, and a refusal as
    one line with exit code 2, nothing written."""
    import subprocess
    import sys

    def run(*args):
        return subprocess.run([sys.executable, "-m", "foldopt", *args], capture_output=True, text=True,
                              cwd=tmp_path, timeout=120)

    shown = run("--help")
    assert shown.returncode == 0 and "sweep" in shown.stdout and "Usage: python -m foldopt" in shown.stdout
    import foldopt

    assert run("--version").stdout.strip() == f"foldopt {foldopt.__version__}"
    refused = run("sweep", "angle", "--lat", "95")
    assert (refused.returncode, refused.stdout) == (2, "")
    assert refused.stderr.splitlines() == ["error: --lat = 95.0: must be in [-90, 90] deg"]
    assert list(tmp_path.iterdir()) == []
