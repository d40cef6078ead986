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
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "foldopt"
#: Stage of each top-level name of the package, lowest first.
STAGES = {"errors": 0, "names": 0, "capabilities": 0, "files": 0, "cache": 0, "tables": 0,
          "physics": 1, "inputs": 2, "engine": 3,
          "studies": 4, "output": 5, "api": 6, "cli": 7}


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def _resolve(name: str) -> str | None:
    """The foldopt module an imported dotted name lives in (a module, or the module of a name)."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def _imports(module: str) -> list[tuple[str, list[str], int]]:
    """(imported module, names taken from it, line) for every import of ``module``."""
    tree = ast.parse(MODULES[module].read_text())
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
    return [(target, names, line) for target, names, line in found if _resolve(target)]


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
    doc = ast.get_docstring(ast.parse(MODULES[package].read_text())) or ""
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
    for node in ast.walk(ast.parse(MODULES[module].read_text())):
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
