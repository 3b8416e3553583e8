"""The layers of ``docs/architecture.md`` ("Layers"), read from that table: every module of
``gamespec/`` and of the plugin distributions in ``backends/`` is in one layer (by its role, else by
its folder, as the page says); none imports a module of a higher layer (lazy imports included); the
modules of one layer import each other without a circle (imports under ``TYPE_CHECKING`` run no
code and are left out of the circles)."""

from __future__ import annotations

import ast
import re
from functools import cache
from pathlib import Path

import pytest

from tests.conftest import ROOT

DOC = ROOT / "docs" / "architecture.md"
SOURCES = (ROOT / "gamespec", *sorted((ROOT / "backends").glob("gamespec_*")))
ROLES = {"spec", "lowering", "transform", "study"}
"""The roles a file's stem names (``spec.py``) ..."""
SUFFIX_ROLES = {"spec", "transform", "study"}
"""... and those its last ``_`` word names (``study_spec.py``)."""


@cache
def table() -> tuple[list[str], dict[str, int]]:
    """The layers, top first, and each unit's rank in them (0 = top): a top-level folder or module
    of ``gamespec`` (``rcs``), ``role NAME``, or ``backends/*``."""
    text = DOC.read_text().split("\n## Layers\n", 1)[1]
    layers, rank = [], {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if not line.startswith("|") or len(cells) != 3 or set(cells[0]) <= {"-"} or cells[0] == "layer":
            continue
        for unit in re.findall(r"(role `\w+`|`[\w/*]+`)", cells[2]):
            name = unit.replace("`", "")
            assert name not in rank, f"{name} is in two rows of {DOC.name}"
            rank[name] = len(layers)
        layers.append(cells[0])
    return layers, rank


def _role(path: Path) -> str | None:
    if path.stem in ROLES:
        return path.stem
    last = path.stem.rsplit("_", 1)[-1]
    return last if last in SUFFIX_ROLES else None


def unit_of(path: Path) -> str:
    """The table's unit that places the module at ``path`` (see the page's rule)."""
    role = _role(path)
    if role is not None:
        return f"role {role}"
    if path.is_relative_to(ROOT / "backends"):
        return "backends/*"
    return path.relative_to(ROOT / "gamespec").parts[0].removesuffix(".py")


def _modules() -> dict[str, Path]:
    """Every module by dotted name (``gamespec.rcs.spec``, ``gamespec_casadi.backend``), the facade
    ``gamespec/__init__.py`` (the public API, above every layer) left out."""
    found = {}
    for source in SOURCES:
        for path in sorted(source.rglob("*.py")):
            parts = path.relative_to(source.parent).with_suffix("").parts
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            if name != "gamespec":
                found[name] = path
    return found


MODULES = _modules()


def _target(name: str, imported: str | None = None) -> str | None:
    """The module ``from name import imported`` (or ``import name``) loads, None outside the house."""
    if imported is not None and f"{name}.{imported}" in MODULES:
        return f"{name}.{imported}"
    return name if name in MODULES else None


def _is_type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def imports(path: Path) -> tuple[set[str], set[str]]:
    """The house's modules ``path`` imports: (all of them, those imported when it runs)."""
    every, running = set(), set()

    def visit(node: ast.AST, runs: bool) -> None:
        targets = []
        if isinstance(node, ast.Import):
            targets = [_target(a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            targets = [_target(node.module, a.name) for a in node.names]
        for t in filter(None, targets):
            every.add(t)
            if runs:
                running.add(t)
        for child in ast.iter_child_nodes(node):
            visit(child, runs and not (isinstance(node, ast.If) and _is_type_checking(node)))

    visit(ast.parse(path.read_text()), True)
    return every, running


def _rank(name: str) -> int:
    return table()[1][unit_of(MODULES[name])]


def test_the_table_has_the_layers_of_the_design() -> None:
    layers, rank = table()
    assert layers[0] == "entry points" and layers[-1] == "foundation"
    assert rank["cli"] < rank["role study"] < rank["solving"] < rank["role transform"] < rank["compiling"]
    assert rank["compiling"] == rank["backends/*"] < rank["rcs"] < rank["role spec"] < rank["symbolic"]


def test_every_module_has_a_layer() -> None:
    _, rank = table()
    unplaced = sorted({unit_of(p) for p in MODULES.values()} - set(rank))
    assert not unplaced, f"place these in the layer table of {DOC.relative_to(ROOT)}: {unplaced}"


@pytest.mark.parametrize(
    "path", [ROOT / "gamespec/rcs/spec.py", ROOT / "backends/gamespec_geometric/spec.py"]
)
def test_a_role_places_a_module_wherever_its_folder(path: Path) -> None:
    assert unit_of(path) == "role spec"
    assert unit_of(ROOT / "gamespec/rcs/multi_obstacle_study.py") == "role study"
    assert unit_of(ROOT / "gamespec/multiphase/lowering.py") == "role lowering"
    assert unit_of(ROOT / "gamespec/rcs/study_points.py") == "rcs"
    assert unit_of(ROOT / "backends/gamespec_casadi/nlp.py") == "backends/*"


def test_no_module_imports_a_higher_layer() -> None:
    layers, _ = table()
    upward = []
    for name, path in MODULES.items():
        for other in sorted(imports(path)[0]):
            if _rank(other) < _rank(name):
                upward.append(f"{name} ({layers[_rank(name)]}) imports {other} ({layers[_rank(other)]})")
    assert not upward, "\n".join(upward)


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of ``graph`` with more than one node (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found = []

    def connect(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph.get(v, ()):
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            connect(v)
    return found


def test_circles_are_found() -> None:
    assert circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert circles({"a": {"b"}, "b": set()}) == []


def test_no_circle_inside_a_layer() -> None:
    graph = {
        name: {other for other in imports(path)[1] if _rank(other) == _rank(name) and other != name}
        for name, path in MODULES.items()
    }
    found = circles(graph)
    assert not found, "\n".join(" → ".join(c) for c in found)
