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

- a table of the file takes scalars (``CL(norm(v), r[2])``) and stays a call of the table: SymPy
  sees it as an opaque function (:func:`gamespec.symbolic.tables.sympy_function`), printed back by
  name (the tables are read here, with the file's folder, and handed on read);
- an interior point (``at:``) and a measured key (``measurements:``) are read over the states (a
  vector as its components), the parameters, the design variables and the tables: ``r == [1, 0]``
  at a time is one constraint per component, ``norm(r)`` or ``r[0]`` a measured key (a vector
  cannot be one: its components can);
- ``r(t=1)`` in a boundary constraint is the vector state at that time (``r(t=1)[0] == 1``,
  ``norm(r(t=1)) == 1``, ``r(t=1) == [1, 0]``), written back as its components' values then
  (``r__0(t=1.0)``);
- the constraints of a requested ``free_event`` (``transforms:``) are read as an interior point's,
  with ``t`` the event time.

A file without ``size:`` is returned unchanged (its expressions are not re-printed).
"""

from __future__ import annotations

import ast
import math
from collections.abc import Mapping
from typing import Any, Protocol

from pydantic import ValidationError

from gamespec.errors import ExpressionError, SpecError
from gamespec.limits import MAX_VECTOR_SIZE
from gamespec.specs.tables import TableSpec
from gamespec.symbolic.grammar import FileFunction, syntax_tree


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


def _texts(value: Any) -> bool:
    return isinstance(value, list) and all(isinstance(v, str) for v in value)


def _well_formed(problem: Mapping[str, Any], phases: bool) -> bool:
    """Whether the sections the lowering reads have the shapes it reads (mappings with string keys,
    lists of constraint texts, measured keys as texts, expressions as texts or numbers, a numeric
    or free initial time); anything else is left to the schema, which names the field in one line."""

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
        if not isinstance(integrals, list) or not all(isinstance(c, Mapping) for c in integrals):
            return False
        points = raw.get("at", [])
        if not isinstance(points, list) or not all(
            isinstance(p, Mapping) and _texts(p.get("constraints", [])) for p in points
        ):
            return False
        measured = raw.get("measurements") or {}
        return isinstance(measured, Mapping) and all(
            isinstance(measured.get(k, {}), Mapping) and _texts(list(measured.get(k, {})))
            for k in ("values", "weights")
        )

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


class Lowering(Protocol):
    """What else of a file a problem's lowering reads: its guess and a ``free_event``'s constraints."""

    def guess(self, raw: dict[str, Any], where: str) -> dict[str, Any]:
        """A guess mapping (``states``/``controls`` values) with each vector given per component."""

    def event(self, texts: Any, where: str) -> Any:
        """The constraints at a free event time, each vector constraint one per component."""


class _Unchanged:
    """The lowering of a file that has nothing to lower: everything as written."""

    def guess(self, raw: dict[str, Any], where: str) -> dict[str, Any]:
        return raw

    def event(self, texts: Any, where: str) -> Any:
        return texts


UNCHANGED: Lowering = _Unchanged()


def lower_problem(
    problem: dict[str, Any],
    field: str = "problem",
    *,
    phases: bool = False,
    context: Mapping[str, Any] | None = None,
) -> tuple[dict[str, Any], Lowering]:
    """``problem`` (an ``optimal_control`` problem mapping, or a ``multiphase_optimal_control``
    one when ``phases``) with its vectors lowered (module doc), and the lowering of the rest of the
    file (:class:`Lowering`). The definitions at the ends are for a single phase (a phase may
    replace a definition, so that its end value would be ambiguous). ``context`` is the validation's
    (the folder of a table's file)."""
    sizes = _sizes(problem.get("states", {}), f"{field}.states") | _sizes(
        problem.get("controls", {}), f"{field}.controls"
    )
    if not sizes and (phases or not _uses_end_definitions(problem)):
        return problem, UNCHANGED
    if not _well_formed(problem, phases):
        return problem, UNCHANGED
    read = _read_tables(problem.get("tables", {}), context)
    if read is None:
        return problem, UNCHANGED
    from gamespec.specs.vector_lowering import lowered

    return lowered({**problem, "tables": read[0]} if read[0] else problem, sizes, field, phases, read[1])


def _read_tables(
    raw: Any, context: Mapping[str, Any] | None
) -> tuple[dict[str, Any], dict[str, FileFunction]] | None:
    """The tables as data (a file's read in, :class:`~gamespec.specs.tables.TableSpec`) and as the
    functions of the expressions; None where one is malformed (left to the schema, which names it)."""
    if not isinstance(raw, Mapping) or not all(isinstance(k, str) for k in raw):
        return None
    try:
        specs = {name: TableSpec.model_validate(spec, context=context) for name, spec in raw.items()}
        return {n: t.model_dump() for n, t in specs.items()}, {n: t.named(n) for n, t in specs.items()}
    except (ValidationError, ValueError):
        return None
