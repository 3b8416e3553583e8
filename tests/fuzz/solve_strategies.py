"""Hypothesis strategies for the solve path: a shipped file made tiny (few intervals, samples, steps,
iterations: :data:`TINY`), then one of its own fields set (``--set``) to an expression generated from
the names the file declares, the functions of the language and numbers at the edges of the range."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import yaml
from hypothesis import strategies as st

from gamespec.symbolic.grammar import FUNCTION_ARITY
from tests.fuzz.strategies import NASTY_NUMBERS, SHIPPED

TINY: dict[str, dict[str, Any]] = {
    "optimal_control": {"method.intervals": 4},
    "multiphase_optimal_control": {},
    "engagement": {"method.intervals": 4},
    "differential_game": {"game.max_iterations": 2},
    "flow_field_game": {
        "method.grid.nodes": [15, 15],
        "method.max_time": 1.0,
        "method.monte_carlo.samples": 20,
        "method.game.max_iterations": 1,
    },
    "lq_stochastic_game": {"monte_carlo.samples": 20},
    "pursuit_scenario": {},
    "pursuit_suboptimal_study": {
        "speeds": [0.5],
        "grid": {"angles": 1, "fractions": 1},
        "refinements": [],
        "method.intervals": 6,
    },
    "rcs_multi_obstacle_study": {
        "obstacles": [2],
        "alphas": [0.0],
        "guesses": [4.0],
        "samples": 10,
        "steps": 20,
        "method.intervals": 6,
    },
}
"""Per kind, the values (by dotted path, set only where the file has the path) that make a solve of
a shipped file take about a second: its numerics are then exercised, not its size."""

SOLVER_BUDGETS: dict[str, dict[str, Any]] = {
    "hji": {"solver.options.hji.max_wall_time": 1.0},
    "levelset": {"solver.options.levelset.max_wall_time": 1.0},
    "casadi": {"solver.options.casadi.max_iter": 100},
}
"""Per backend, the options that bound the work of one tiny solve: a mutant may legitimately ask
for much work (dynamics fast on an HJI grid: many CFL steps; a parameter of 1e300: IPOPT's 3000
iterations), and must then stop at the limit with an honest status (``time_limit``,
``iteration_limit``)."""

CASADI_KINDS = frozenset({"optimal_control", "multiphase_optimal_control", "engagement", "differential_game"})
"""The kinds whose default backend is ``casadi`` (when the file names none)."""

REFINEMENTS = 3
"""``method.refine.max_iterations`` of a tiny solve whose file refines its mesh."""

STORE_KINDS = frozenset({"pursuit_suboptimal_study", "rcs_multi_obstacle_study"})
"""The kinds whose file names a store folder (redirected into the test's own folder)."""


def _document(path: Path) -> dict[str, Any]:
    return yaml.safe_load(path.read_text())


def _has(document: Any, dotted: str) -> bool:
    node = document
    for part in dotted.split("."):
        if isinstance(node, dict) and part in node:
            node = node[part]
        else:
            return False
    return True


def leaves(node: Any, prefix: str = "") -> list[str]:
    """The dotted paths of a document's scalar values (numbers and texts; names and kinds left
    out: changing them is the loader's surface, fuzzed in :mod:`tests.fuzz.test_fuzz`)."""
    if isinstance(node, dict):
        items = [(str(k), v) for k, v in node.items() if k not in ("kind", "name", "description", "store")]
    elif isinstance(node, list):
        items = [(str(i), v) for i, v in enumerate(node)]
    else:
        return [prefix] if isinstance(node, int | float | str) and not isinstance(node, bool) else []
    return [p for k, v in items for p in leaves(v, f"{prefix}.{k}" if prefix else k)]


def names(node: Any) -> list[str]:
    """The symbol names a document declares: the keys of its ``parameters``, ``states``,
    ``controls`` and ``uncertain`` mappings, wherever they are."""
    found: list[str] = []
    if isinstance(node, dict):
        for key, value in node.items():
            if key in ("parameters", "states", "controls", "uncertain") and isinstance(value, dict):
                found += [str(k) for k in value]
            found += names(value)
    elif isinstance(node, list):
        for value in node:
            found += names(value)
    return sorted(set(found))


def _monte_carlo_blocks(node: Any, prefix: str = "") -> list[str]:
    """The dotted paths of the ``monte_carlo`` blocks that give a ``samples`` count (analyses of
    requested transforms, studies)."""
    found = []
    if isinstance(node, dict | list):
        items = node.items() if isinstance(node, dict) else enumerate(node)
        for key, value in items:
            at = f"{prefix}.{key}" if prefix else str(key)
            if key == "monte_carlo" and isinstance(value, dict) and "samples" in value:
                found.append(at)
            found += _monte_carlo_blocks(value, at)
    return found


def tiny_overrides(path: Path, store: Path) -> list[str]:
    """``--set`` assignments that make the shipped file ``path`` tiny (see :data:`TINY`)."""
    values = _tiny_values(_document(path), store)
    return [f"{k}={json.dumps(v)}" for k, v in values.items()]


def _tiny_values(document: dict[str, Any], store: Path) -> dict[str, Any]:
    """The values of :func:`tiny_overrides` by dotted path."""
    kind = document["kind"]
    values = {k: v for k, v in TINY.get(kind, {}).items() if _has(document, k.split(".")[0])}
    values |= {f"{at}.samples": 20 for at in _monte_carlo_blocks(document)}
    rh = document.get("receding_horizon")
    if rh is not None:
        values["receding_horizon.time_limit"] = rh["step"]
    backend = document.get("solver", {}).get("backend", "casadi" if kind in CASADI_KINDS else None)
    values |= SOLVER_BUDGETS.get(backend, {})
    if _has(document, "method.refine"):
        values["method.refine.max_iterations"] = REFINEMENTS
    if kind in STORE_KINDS:
        values["store"] = str(store)
    return values


def expressions(symbols: list[str]) -> st.SearchStrategy[str]:
    """Expression texts over ``symbols``: numbers at the edges, the names, and sums, products,
    powers and whitelisted functions of them, nested a few levels."""
    numbers = st.sampled_from([n for n in NASTY_NUMBERS if isinstance(n, int | float)]).map(repr)
    atoms = st.one_of(numbers, st.sampled_from(symbols or ["pi"]), st.sampled_from(["1e+300", "710", "-0.0"]))
    unary = [name for name, arity in FUNCTION_ARITY.items() if arity == 1]
    binary = [name for name, arity in FUNCTION_ARITY.items() if arity == 2]

    def extend(inner: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
        return st.one_of(
            st.tuples(inner, st.sampled_from(["+", "-", "*", "/", "**"]), inner).map(
                lambda t: f"({t[0]} {t[1]} {t[2]})"
            ),
            st.tuples(st.sampled_from(unary), inner).map(lambda t: f"{t[0]}({t[1]})"),
            st.tuples(st.sampled_from(binary), inner, inner).map(lambda t: f"{t[0]}({t[1]}, {t[2]})"),
            inner.map(lambda e: f"-{e}"),
        )

    return st.recursive(atoms, extend, max_leaves=6)


def text_values() -> st.SearchStrategy[str]:
    """Texts that are not expressions but look like numbers or code to a careless reader."""
    return st.sampled_from(
        ["\t", "0x10", "not x", "1_0", "''", "2.5", "[1, 2]", "{}", "null", "x if x else 0"]
    )


@st.composite
def solve_mutants(draw: st.DrawFn, files: list[Path] | None = None) -> tuple[Path, list[str]]:
    """A shipped file and a ``--set`` of one of its fields to a generated expression (or a text
    that only looks like one), JSON-encoded; not a field the tiny overrides set (the solve's size:
    ``grid.angles = 1_0`` asks for a study ten times as large, not bad input)."""
    path = draw(st.sampled_from(files or SHIPPED))
    document = _document(path)
    sized = _tiny_values(document, Path("store"))
    fields = [f for f in leaves(document) if not any(f == k or f.startswith(f"{k}.") for k in sized)]
    field = draw(st.sampled_from(fields))
    value = draw(st.one_of(expressions(names(document)), text_values()))
    return path, [f"{field}={json.dumps(value)}"]


def kinds_of(files: list[Path]) -> dict[str, list[Path]]:
    """The shipped files by kind."""
    out: dict[str, list[Path]] = {}
    for path in files:
        out.setdefault(_document(path)["kind"], []).append(path)
    return out
