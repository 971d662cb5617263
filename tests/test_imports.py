"""Every module of urdsl imports, and none imports one that imports it back (issue 15).

The import graph is read from the source with ``ast``: ``import`` and ``from … import``
statements anywhere in a module (also inside functions: a lazy import is still a dependency),
except under ``if TYPE_CHECKING:``, plus dynamic imports named by a string literal that is a
module's full name (``urdsl.cli`` loads its command modules so). Importing a package's
submodule implicitly runs the package's ``__init__``; that is not counted as an edge.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent / "urdsl"


def _modules() -> dict[str, tuple[Path, bool]]:
    found = {}
    for path in sorted(ROOT.rglob("*.py")):
        parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
        package = parts[-1] == "__init__"
        found[".".join(parts[:-1] if package else parts)] = (path, package)
    return found


MODULES = _modules()


def _type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _imports(name: str) -> set[str]:
    path, package = MODULES[name]
    here = name if package else name.rpartition(".")[0]
    found: set[str] = set()

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and _type_checking(node):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here.split(".")[: len(here.split(".")) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            for alias in node.names:
                child = f"{module}.{alias.name}"
                found.add(child if child in MODULES else module)
        elif isinstance(node, ast.Constant) and node.value in MODULES:
            found.add(node.value)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(ast.parse(path.read_text(encoding="utf-8")))
    return {module for module in found if module in MODULES and module != name}


GRAPH = {name: _imports(name) for name in MODULES}


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for target in sorted(graph[node]):
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in on_stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return found


def _describe(cycle: list[str]) -> str:
    return "; ".join(f"{m} -> {', '.join(sorted(GRAPH[m] & set(cycle)))}" for m in cycle)


def test_the_graph_sees_lazy_and_dynamic_imports():
    assert "urdsl._cli" in GRAPH["urdsl.lint.command"]  # inside a function
    assert "urdsl.verify.command" in GRAPH["urdsl.cli"]  # loaded by name
    assert "urdsl.lint.context" not in GRAPH["urdsl.lint.registry"]  # TYPE_CHECKING only
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_no_module_outside_the_sim_imports_one_that_imports_it_back():
    cycles = [c for c in _cycles(GRAPH)
              if not all(m == "urdsl.sim" or m.startswith("urdsl.sim.") for m in c)]
    assert cycles == [], "\n".join(_describe(c) for c in cycles)


def test_no_import_cycle_in_the_sim():
    cycles = [c for c in _cycles(GRAPH) if any(m.startswith("urdsl.sim") for m in c)]
    assert cycles == [], "\n".join(_describe(c) for c in cycles)


def test_command_modules_import_downwards():
    commands = [m for m in MODULES if m.endswith(".command")]
    assert "urdsl.kinematics.command" in commands and "urdsl.kinematics.cli" not in MODULES
    for module in commands:
        assert "urdsl.cli" not in GRAPH[module], module


@pytest.mark.parametrize("name", sorted(MODULES))
def test_every_module_imports(name):
    importlib.import_module(name)
