"""DESIGN.md, "Layers": a lower layer never imports a higher one. Every module of the gamespec
package belongs to one layer below; an import of a higher layer fails the test, and so does a new
top-level module that nobody placed."""

from __future__ import annotations

import ast
from pathlib import Path

import gamespec

LAYERS = [
    {"errors", "result", "registry", "best_response", "limits", "reading", "terminal", "metrics", "npyfile"},
    {"symbolic"},
    {"specs", "loader", "analyses"},
    {"ocp", "lqgame", "pursuit", "flowfield", "desensitize", "rcs", "montecarlo", "obstacles", "plotting"},
    {"backend"},
    {"transforms"},
    {"solving"},
    {"studies", "games", "summaries"},
    {"cli", "commands"},
]
RANK = {name: i for i, layer in enumerate(LAYERS) for name in layer}

ROOT = Path(gamespec.__file__).parent


def _layer(path: Path) -> str | None:
    parts = path.relative_to(ROOT).parts
    if parts == ("__init__.py",):
        return None
    return parts[0].removesuffix(".py")


def _imported(tree: ast.AST) -> set[str]:
    found = set()
    for node in ast.walk(tree):
        names = [node.module] if isinstance(node, ast.ImportFrom) and node.module else []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        found |= {n.split(".")[1] for n in names if n.startswith("gamespec.") and n.count(".") >= 1}
    return found


def test_every_module_has_a_layer() -> None:
    unplaced = {_layer(p) for p in ROOT.rglob("*.py")} - set(RANK) - {None}
    assert not unplaced, f"place these in LAYERS: {sorted(unplaced)}"


def test_no_module_imports_a_higher_layer() -> None:
    upward = []
    for path in sorted(ROOT.rglob("*.py")):
        mine = _layer(path)
        if mine is None:
            continue
        for other in _imported(ast.parse(path.read_text())):
            relative = str(path.relative_to(ROOT))
            if other in RANK and RANK[other] > RANK[mine]:
                upward.append(f"{relative} ({mine}) imports gamespec.{other}")
    assert not upward, "\n".join(upward)
