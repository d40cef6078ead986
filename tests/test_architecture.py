"""The house's rules, read off the source: stages import only downward, no import cycle, no
module imports another's private name, every stage says what it owns. (A module holds one concept
and is split where the concept splits, not at a line count: issue 39 retired the 500-line test,
which made code denser rather than clearer.)

The order is the flow of a study (docs/architecture.rst): the leaves (errors, names, files, cache, tables),
then physics, inputs, engine, studies, output, the API and the command line. Every import counts,
those inside functions too: a lazy import that climbs is still a climb.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "foldopt"
#: Stage of each top-level name of the package, lowest first.
STAGES = {"errors": 0, "names": 0, "capabilities": 0, "files": 0, "cache": 0, "tables": 0, "columnar": 0, "threads": 0,
          "physics": 1, "inputs": 2, "engine": 3,
          "studies": 4, "output": 5, "api": 6, "cli": 7, "__main__": 7}


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def _resolve(name: str) -> str | None:
    """The foldopt module an imported dotted name lives in (a module, or the module of a name)."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


@functools.cache
def _tree(module: str) -> ast.Module:
    """The syntax tree of ``module``, parsed once for every test (none changes it)."""
    return ast.parse(MODULES[module].read_text())


@functools.cache
def _imports(module: str) -> tuple[tuple[str, list[str], int], ...]:
    """(imported module, names taken from it, line) for every import of ``module``."""
    tree = _tree(module)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(alias.name, [], node.lineno) for alias in node.names if alias.name.startswith("foldopt")]
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("foldopt"):
            assert node.level == 0, f"{module}:{node.lineno}: relative import"
            for alias in node.names:
                target = f"{node.module}.{alias.name}"
                if target in MODULES:  # `from foldopt.engine import kernel`: the module itself
                    found.append((target, [], node.lineno))
                else:
                    found.append((node.module, [alias.name], node.lineno))
    return tuple((target, names, line) for target, names, line in found if _resolve(target))


def _stage(module: str) -> int | None:
    parts = module.split(".")
    return STAGES.get(parts[1]) if len(parts) > 1 else None


def _graph() -> dict[str, set[str]]:
    return {module: {_resolve(target) for target, _, _ in _imports(module)} - {module} for module in MODULES}


def test_every_module_has_a_stage():
    assert [m for m in MODULES if m != "foldopt" and _stage(m) is None] == []


def test_imports_only_go_down():
    climbs = []
    for module in MODULES:
        for target, _, line in _imports(module):
            target = _resolve(target)
            if module != "foldopt" and target != "foldopt" and _stage(target) > _stage(module):
                climbs.append(f"{module}:{line} imports {target}")
    assert climbs == []


def test_no_module_imports_the_lazy_namespace_but_its_version():
    offenders = [f"{module}:{line} takes {names}" for module in MODULES if module != "foldopt"
                 for target, names, line in _imports(module) if _resolve(target) == "foldopt"
                 and set(names) - {"__version__"}]
    assert offenders == []


def test_no_import_cycle():
    graph, state, cycles = _graph(), {}, []

    def visit(module, path):
        state[module] = "open"
        for target in sorted(graph[module]):
            if state.get(target) == "open":
                cycles.append(" -> ".join(path[path.index(target):] + [target]))
            elif target not in state:
                visit(target, path + [target])
        state[module] = "done"

    for module in MODULES:
        if module not in state:
            visit(module, [module])
    assert cycles == []


def test_no_module_imports_a_private_name():
    private = [f"{module}:{line} takes {name} from {target}" for module in MODULES
               for target, names, line in _imports(module) for name in names
               if name.startswith("_") and not name.startswith("__")]
    assert private == []


@pytest.mark.parametrize("package", [m for m, p in MODULES.items() if p.name == "__init__.py"])
def test_every_package_says_what_it_owns(package):
    doc = ast.get_docstring(_tree(package)) or ""
    assert len(doc) > 200, f"{package}: a one-paragraph docstring of what it owns and may import"
    if package != "foldopt":
        assert "import" in doc, f"{package}: the docstring says what the stage may import"


def test_cycle_finder_sees_a_cycle():
    """The cycle test can fail: a made-up graph with a cycle is found."""
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}}
    state, cycles = {}, []

    def visit(module, path):
        state[module] = "open"
        for target in sorted(graph[module]):
            if state.get(target) == "open":
                cycles.append(path[path.index(target):] + [target])
            elif target not in state:
                visit(target, path + [target])
        state[module] = "done"

    visit("a", ["a"])
    assert cycles == [["a", "b", "c", "a"]]


#: The front door's modules: a Plan is made by make_plan (and Plan.of), a Request by make_request.
_MAKERS = {"Plan": {"foldopt.inputs.plan", "foldopt.studies.request"},
           "Request": {"foldopt.studies.request"}}


def _calls_of(module: str) -> list[tuple[str, int]]:
    """``(name, line)`` of every call of ``Plan(...)``, ``Plan.of(...)`` or ``Request(...)``."""
    found = []
    for node in ast.walk(_tree(module)):
        if not isinstance(node, ast.Call):
            continue
        func = node.func
        name = func.id if isinstance(func, ast.Name) else (
            func.value.id if isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name)
            and func.attr == "of" else None)
        if name in _MAKERS:
            found.append((name, node.lineno))
    return found


def test_only_the_front_door_makes_a_plan_or_a_request():
    """Issue 47: every entry (a YAML study, options, --set, keywords, a map) becomes a plan through
    foldopt.studies.request.make_request; nothing downstream builds one by hand."""
    elsewhere = [f"{module}:{line} makes a {name}" for module in MODULES
                 for name, line in _calls_of(module) if module not in _MAKERS[name]]
    assert elsewhere == []
    assert _calls_of("foldopt.studies.request"), "the finder sees the front door's own calls"


#: What changes ``os.environ``: a call of one of its methods, or of ``os``'s own.
_ENVIRONMENT_WRITERS = {"pop", "popitem", "clear", "update", "setdefault", "__setitem__", "__delitem__"}
#: The one place foldopt writes the environment, and why: matplotlib reads ``MPLCONFIGDIR`` once as
#: it is first imported, and has no other way to be given a folder; it is deleted at once after.
_SET_AND_UNDONE = {("foldopt.output.figures.canvas", "_matplotlib_imported"),
                   ("foldopt.studies.dask_client", "start_worker_server")}


def _environment_writes(module: str) -> list[tuple[int, str | None]]:
    """(line, enclosing function) of every write to the process's environment in ``module``:
    ``os.environ[...] =``, ``del os.environ[...]``, ``os.environ.pop(...)``..., ``os.putenv``,
    ``os.unsetenv``."""
    tree = _tree(module)

    def environ(node) -> bool:
        return (isinstance(node, ast.Attribute) and node.attr == "environ"
                and isinstance(node.value, ast.Name) and node.value.id == "os") or \
            (isinstance(node, ast.Name) and node.id == "environ")

    spans = [(node.lineno, node.end_lineno, node.name) for node in ast.walk(tree)
             if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))]
    found = []
    for node in ast.walk(tree):
        targets = node.targets if isinstance(node, (ast.Assign, ast.Delete)) else \
            [node.target] if isinstance(node, (ast.AugAssign, ast.AnnAssign)) else []
        writes = any(isinstance(target, ast.Subscript) and environ(target.value) for target in targets)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            writes |= (node.func.attr in _ENVIRONMENT_WRITERS and environ(node.func.value)) or (
                node.func.attr in ("putenv", "unsetenv") and isinstance(node.func.value, ast.Name)
                and node.func.value.id == "os")
        if writes:
            inside = [name for start, end, name in spans if start <= node.lineno <= end]
            found.append((node.lineno, inside[-1] if inside else None))
    return found


def test_foldopt_sets_no_environment_variable():
    """No state set behind the caller's back (issue 48): --quiet and --offline are context
    variables of foldopt.cache, and no module writes ``os.environ``, but the moment matplotlib is
    first imported (output.figures.canvas), which sets MPLCONFIGDIR and deletes it at once after
    (tests/test_faults_inputs.py: the environment is as it was), and the moment the embedded
    cluster's worker server starts with the environment Dask's nanny gives a worker, restored at
    once after (tests/test_cluster.py's hand-started cluster: the environment is as it was)."""
    writes = [(module, line, function) for module in MODULES for line, function in _environment_writes(module)]
    assert [f"{module}:{line}" for module, line, function in writes
            if (module, function) not in _SET_AND_UNDONE] == []
    assert {(module, function) for module, _, function in writes} == _SET_AND_UNDONE


def test_the_environment_finder_sees_every_kind_of_write(tmp_path, monkeypatch):
    """The finder can fail: a made-up module with each kind of write is caught, a read is not."""
    source = tmp_path / "made_up.py"
    source.write_text("import os\nfrom os import environ\nos.environ['A'] = '1'\ndel os.environ['A']\n"
                      "os.environ.pop('B', None)\nenviron.update(C='1')\nos.putenv('D', '1')\n"
                      "def f():\n    os.environ.setdefault('E', '1')\n    return os.environ.get('F')\n")
    monkeypatch.setitem(MODULES, "made_up", source)
    assert _environment_writes("made_up") == [(3, None), (4, None), (5, None), (6, None), (7, None), (9, "f")]


#: The most positional parameters a function of the engine or the studies takes (issue 48): past
#: it a call is a row of bare values whose meaning hangs on their order; the rest go keyword-only
#: or into a named record (foldopt.engine.records, foldopt.engine.options).
MAX_POSITIONAL = 8


def _positional_counts(tree: ast.AST) -> list[tuple[str, int, int]]:
    """``(name, line, positional parameters)`` of every function in ``tree`` (``self`` and
    ``cls`` not counted)."""
    return [(node.name, node.lineno,
             len([a for a in node.args.posonlyargs + node.args.args if a.arg not in ("self", "cls")]))
            for node in ast.walk(tree) if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))]


def test_no_function_of_the_engine_or_the_studies_takes_more_than_eight_positional_parameters():
    too_many = [f"{module}:{line} {name} takes {count}" for module in MODULES
                if module.startswith(("foldopt.engine", "foldopt.studies"))
                for name, line, count in _positional_counts(_tree(module))
                if count > MAX_POSITIONAL]
    assert too_many == []


def test_the_parameter_count_sees_positional_and_keyword_only_parameters():
    """The count can fail: nine positional parameters are seen, keyword-only ones and self are not."""
    tree = ast.parse("def f(a, b, c, d, e, f, g, h, i=1): pass\n"
                     "def g(a, /, b, *, c, d, e, f, g, h, i, j): pass\n"
                     "class C:\n    def m(self, a, b): pass\n")
    assert _positional_counts(tree) == [("f", 1, 9), ("g", 2, 2), ("m", 4, 2)]


def _format_calls(tree: ast.AST) -> list[int]:
    """Lines of every ``<something>.format(...)`` call in ``tree``."""
    return [node.lineno for node in ast.walk(tree) if isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute) and node.func.attr == "format"]


def test_no_answer_module_builds_a_key_with_format():
    """Issue 48: an answer's keys are written as they are read, so that a search finds them (a key
    built at run time, ``"{}_by_design_{}".format(...)``, is found by no search); the modules
    that say the answers use f-strings for their prose, never ``.format``."""
    answers = [module for module, path in MODULES.items()
               if module.startswith("foldopt.studies.") and "answer" in path.stem]
    assert "foldopt.studies.storage_answer" in answers
    built = [f"{module}:{line}" for module in answers
             for line in _format_calls(_tree(module))]
    assert built == []
    assert _format_calls(ast.parse('"{}_by_design_{}".format(*column.rsplit("_", 1))')) == [1]


def test_the_engine_never_sees_a_study():
    """Issue 48: the engine reads its options groups (foldopt.engine.options), made of a study once,
    outside it (foldopt.studies.engine_options); no engine module imports the study."""
    offenders = [f"{module}:{line} imports {target}" for module in MODULES if module.startswith("foldopt.engine")
                 for target, _, line in _imports(module) if _resolve(target) == "foldopt.inputs.study"]
    assert offenders == []
    assert _imports("foldopt.studies.engine_options"), "the finder sees the builder's imports"


def test_an_engine_option_is_the_study_field_of_its_name_unless_derived():
    """Issue 48: a field the engine comes to read is a field of the study and of its options group,
    named alike, and no line of the builder: every option not in DERIVED is a study field, and each
    option the builder makes is the study's value (the field's own, or its derivation's)."""
    import dataclasses

    from foldopt.inputs.study import Study
    from foldopt.studies.engine_options import DERIVED, engine_options
    from foldopt.studies.request import make_request

    for kind, derived in DERIVED.items():
        names = {field.name for field in dataclasses.fields(kind)}
        assert set(derived) <= names, f"{kind.__name__}: derived options it does not have"
        assert sorted(names - set(derived) - set(Study.model_fields)) == [], kind.__name__
        # Derived though named as a field: the value in force (the transposition a beam-only sky
        # drops, the circuit None when ideal), not the field as given.
        in_force = {"circuit", "transposition"}
        assert sorted(set(derived) & set(Study.model_fields) - in_force) == [], (
            f"{kind.__name__}: an option named as a study field takes that field")
    study = make_request("run", None, settings=["mode=exact", "panel.area=0.2"]).plan.base
    options = engine_options(study)
    assert options.electrical.area == 0.2 and options.sky.mode == "exact"
    assert options.sky.temp_air == study.temp_air and options.electrical.pv_model == study.pv_model
