"""Vector states and controls of an ``optimal_control`` file, lowered to their components at load.

A state or control with ``size: N`` (``r: {size: 3, initial: [1, 0, 0]}``) stands for ``N``
scalar components ``r__0 ... r__{N-1}``; every expression of the file is read in the vector
language of :mod:`gamespec.symbolic.vectors` (``r[0]``, ``dot(r, v)``, ``cross(r, v)``,
``norm(r)``, ``-mu*r/norm(r)**3``, ``[a, b, c]``) and written back as the scalar expressions of the
components through SymPy's printer, so that everything after loading (the checks at load, every
backend, the Result's arrays) sees an ordinary scalar problem and the vector problem equals its
scalar form by construction:

- ``initial``, ``final``, ``lower``, ``upper``, ``scale`` and a guess are a list of ``N`` values or
  one value for every component (an expression may give a vector: ``initial: "[r0, 0, 0]"``);
- the dynamics of a vector state is a vector expression of its size (or a list of ``N``);
- a definition may be a vector (``g: -mu*r/norm(r)**3``: definitions ``g__0 ... g__2``);
- end values are vectors too (``r_f``, ``v_0``: ``norm(r_f) == 1``), and a vector constraint is one
  constraint per component (``r_f == [1, 0, 0]``, ``-1 <= u <= 1``); a chained one becomes two
  one-sided constraints.

A file without ``size:`` is returned unchanged (its expressions are not re-printed). A file with
vectors cannot have ``tables:`` yet (refused with the reason).
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable, Mapping
from typing import Any

from gamespec.errors import ExpressionError, SpecError
from gamespec.limits import MAX_VECTOR_SIZE
from gamespec.symbolic.grammar import syntax_tree


def _sizes(group: Any, where: str) -> dict[str, int]:
    """The vectors of ``group`` (states or controls) by name and size."""
    sizes: dict[str, int] = {}
    if not isinstance(group, Mapping):
        return sizes
    for name, spec in group.items():
        if isinstance(spec, Mapping) and spec.get("size") is not None:
            n = spec["size"]
            if type(n) is not int or not 1 <= n <= MAX_VECTOR_SIZE:
                raise SpecError(
                    f"size must be an integer from 1 to {MAX_VECTOR_SIZE}", field=f"{where}.{name}.size"
                )
            sizes[name] = n
    return sizes


def _end_texts(problem: Mapping[str, Any]) -> list[str]:
    """The Mayer term and the boundary constraints, as texts."""
    objective = problem.get("objective")
    texts = [objective.get("mayer") if isinstance(objective, Mapping) else None]
    boundary = problem.get("boundary_constraints")
    texts += list(boundary) if isinstance(boundary, list) else []
    return [t for t in texts if isinstance(t, str)]


def _names_in(text: str) -> list[ast.AST]:
    try:
        return list(ast.walk(syntax_tree(text)))
    except ExpressionError:
        return []


def _uses_times(problem: Mapping[str, Any]) -> bool:
    """Whether an end term has a value at a fixed time (``x(t=5)``)."""
    return any(
        isinstance(n, ast.Call) and any(k.arg == "t" for k in n.keywords)
        for text in _end_texts(problem)
        for n in _names_in(text)
    )


def _uses_end_definitions(problem: Mapping[str, Any]) -> bool:
    """Whether the Mayer term or a boundary constraint names a definition at an end (``h_f``)."""
    definitions = problem.get("definitions")
    if not isinstance(definitions, Mapping) or not definitions:
        return False
    wanted = {f"{d}{end}" for d in definitions for end in ("_0", "_f")}
    return any(
        isinstance(n, ast.Name) and n.id in wanted for text in _end_texts(problem) for n in _names_in(text)
    )


_EXPRESSION = (str, int, float)
_MAPS = ("parameters", "definitions", "states", "controls", "inputs", "design", "dynamics")
_LISTS = ("path_constraints", "boundary_constraints")


def _expression(value: Any) -> bool:
    return isinstance(value, _EXPRESSION) and not isinstance(value, bool)


def _well_formed(problem: Mapping[str, Any], phases: bool) -> bool:
    """Whether the sections the lowering reads have the shapes it reads (mappings with string keys,
    lists of constraint texts, expressions as texts or numbers, a numeric or free initial time);
    anything else is left to the schema, which names the field in one line."""

    def section_ok(raw: Mapping[str, Any]) -> bool:
        for key in _MAPS:
            value = raw.get(key, {})
            if value is None and key == "controls" and phases:
                continue
            if not isinstance(value, Mapping) or not all(isinstance(k, str) for k in value):
                return False
        for key in ("definitions", "dynamics", "jump"):
            values = raw.get(key, {})
            if not isinstance(values, Mapping) or not all(
                _expression(v) or (key != "definitions" and isinstance(v, list) and all(map(_expression, v)))
                for v in values.values()
            ):
                return False
        for key in _LISTS:
            if not isinstance(raw.get(key, []), list) or not all(
                isinstance(c, str) for c in raw.get(key, [])
            ):
                return False
        integrals = raw.get("integral_constraints", [])
        return isinstance(integrals, list) and all(isinstance(c, Mapping) for c in integrals)

    time = problem.get("time", {})
    if not isinstance(time, Mapping):
        return False
    initial = time.get("initial", 0.0)
    if initial != "free" and not (
        isinstance(initial, int | float) and not isinstance(initial, bool) and math.isfinite(initial)
    ):
        return False
    phase_list = problem.get("phases", []) if phases else []
    if not isinstance(phase_list, list) or not all(isinstance(p, Mapping) for p in phase_list):
        return False
    return section_ok(problem) and all(section_ok(p) for p in phase_list)


def lower_problem(
    problem: dict[str, Any], field: str = "problem", *, phases: bool = False
) -> tuple[dict[str, Any], Callable[[dict[str, Any], str], dict[str, Any]]]:
    """``problem`` (an ``optimal_control`` problem mapping, or a ``multiphase_optimal_control``
    one when ``phases``) with its vectors lowered (module doc), and the lowering of a guess mapping
    (``states``/``controls`` values) of the same problem. The definitions at the ends are for a
    single phase (a phase may replace a definition, so that its end value would be ambiguous)."""
    sizes = _sizes(problem.get("states", {}), f"{field}.states") | _sizes(
        problem.get("controls", {}), f"{field}.controls"
    )
    if not sizes and (phases or not _uses_end_definitions(problem)):
        return problem, lambda guess, where: guess
    if not _well_formed(problem, phases):
        return problem, lambda guess, where: guess
    for key, what in (("tables", "tables"), ("at", "interior-point constraints (at:)")):
        if problem.get(key):
            raise SpecError(
                f"{what} in a file with vector states or end-point definitions are not supported yet: "
                "write the components as scalar states and the definitions out",
                field=f"{field}.{key}",
            )
    if _uses_times(problem):
        raise SpecError(
            "x(t=...) in a file with vector states or end-point definitions is not supported yet: "
            "use at: in a file of scalar states",
            field=f"{field}.boundary_constraints",
        )
    from gamespec.specs.vector_lowering import lowered

    return lowered(problem, sizes, field, phases)
