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
from collections.abc import Callable, Mapping
from typing import Any

from gamespec.errors import ExpressionError, SpecError
from gamespec.limits import MAX_VECTOR_SIZE
from gamespec.symbolic.grammar import syntax_tree


def _sizes(group: Mapping[str, Any], where: str) -> dict[str, int]:
    sizes = {}
    for name, spec in group.items():
        if isinstance(spec, Mapping) and spec.get("size") is not None:
            n = spec["size"]
            if type(n) is not int or not 1 <= n <= MAX_VECTOR_SIZE:
                raise SpecError(
                    f"size must be an integer from 1 to {MAX_VECTOR_SIZE}", field=f"{where}.{name}.size"
                )
            sizes[name] = n
    return sizes


def _uses_end_definitions(problem: Mapping[str, Any]) -> bool:
    """Whether the Mayer term or a boundary constraint names a definition at an end (``h_f``)."""
    definitions = problem.get("definitions")
    if not isinstance(definitions, Mapping) or not definitions:
        return False
    wanted = {f"{d}{end}" for d in definitions for end in ("_0", "_f")}
    objective = problem.get("objective")
    texts = [objective.get("mayer") if isinstance(objective, Mapping) else None]
    boundary = problem.get("boundary_constraints")
    texts += list(boundary) if isinstance(boundary, list) else []
    for text in texts:
        if isinstance(text, str):
            try:
                tree = syntax_tree(text)
            except ExpressionError:
                continue
            if any(isinstance(n, ast.Name) and n.id in wanted for n in ast.walk(tree)):
                return True
    return False


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
    if sizes and problem.get("tables"):
        raise SpecError(
            "tables in a file with vector states or controls are not supported yet: write the "
            "vectors' components as scalar states",
            field=f"{field}.tables",
        )
    from gamespec.specs.vector_lowering import lowered

    return lowered(problem, sizes, field, phases)
