"""The vector reading of an ``optimal_control`` or ``multiphase_optimal_control`` problem
(:mod:`gamespec.specs.vectors` says what it means): SymPy over the vector language of
:mod:`gamespec.symbolic.vectors`, written back as the components' scalar expressions. The
tables are SymPy's opaque functions of :func:`gamespec.symbolic.tables.sympy_function`, printed
back as calls. Imported only for a file that has vectors or definitions at the ends (loading any
other file needs no SymPy)."""

from __future__ import annotations

import ast
import copy
from collections.abc import Mapping
from typing import Any

import sympy as sp

from gamespec.errors import ExpressionError, SpecError
from gamespec.symbolic.grammar import FileFunction, at_time, at_time_name, numeric_value, syntax_tree
from gamespec.symbolic.language import symbol
from gamespec.symbolic.printer import relation_texts, to_text
from gamespec.symbolic.vectors import VECTORS, Vector, is_vector, parse_vector, parse_vector_relation

VECTOR_FUNCTIONS = frozenset(VECTORS.functions)

COMPONENT = "__"
"""Joins a vector's name and a component's index (``r__0``)."""


def component(name: str, i: int) -> str:
    """The scalar name of component ``i`` of vector ``name``."""
    return f"{name}{COMPONENT}{i}"


def _vector(name: str, n: int, suffix: str = "") -> Vector:
    return Vector([symbol(component(name, i) + suffix) for i in range(n)])


class _Lowering:
    """The vector reading of one problem (module doc); each method's ``where`` is the field of the
    value it reads, named by a SpecError."""

    def __init__(
        self,
        problem: Mapping[str, Any],
        sizes: dict[str, int],
        phases: bool,
        tables: Mapping[str, FileFunction],
    ) -> None:
        self.sizes = sizes
        self.tables = dict(tables)
        self.end_definitions = not phases
        """Whether a definition's end values (``h_0``, ``h_f``) are made: in one phase only (a phase
        may replace a definition, so that a multi-phase file's end value would be ambiguous)."""
        scalars = [
            *problem.get("parameters", {}),
            *problem.get("design", {}),
            *problem.get("inputs", {}),
            *(n for n in problem.get("states", {}) if n not in sizes),
            *(n for n in problem.get("controls", {}) if n not in sizes),
        ]
        self.params = {n: symbol(n) for n in [*problem.get("parameters", {}), *problem.get("design", {})]}
        self.running: dict[str, Any] = {n: symbol(n) for n in [*scalars, "t"]} | self.tables
        self.running |= {n: _vector(n, k) for n, k in sizes.items()}
        variables = [*problem.get("states", {}), *problem.get("controls", {})]
        self.ends: dict[str, Any] = self.params | self.tables | {"t_f": symbol("t_f")}
        if _start(problem) == symbol("t_0"):
            self.ends["t_0"] = symbol("t_0")
        for name in variables:
            for end in ("_0", "_f"):
                k = sizes.get(name)
                self.ends[name + end] = symbol(name + end) if k is None else _vector(name, k, end)
        self.timed = self.params | self.tables | {"t": symbol("t"), "tau": symbol("tau")}
        states = problem.get("states", {})
        self.points: dict[str, Any] = self.params | self.tables
        """The symbols of a constraint at a point inside the horizon (``at:``, a measured key): the
        states then, the parameters, the design variables and the tables."""
        self.points |= {n: _vector(n, sizes[n]) if n in sizes else symbol(n) for n in states}
        if not phases:
            self.ends |= _timed_states(problem.get("boundary_constraints", []), states, sizes)
        self.defined_ends: set[str] = set()
        self.inputs = set(problem.get("inputs", {}))
        self.scalar_variables = [
            m
            for n in variables
            for m in ([n] if n not in sizes else [component(n, i) for i in range(sizes[n])])
        ]

    def fail(self, err: ExpressionError, where: str) -> SpecError:
        return SpecError(str(err), field=where)

    def value(self, text: Any, symbols: Mapping[str, Any], where: str) -> Any:
        """``text`` read over ``symbols``: a SymPy scalar or vector."""
        try:
            return parse_vector(text, symbols)
        except ExpressionError as err:
            raise self.fail(err, where) from None

    def scalar(self, text: Any, symbols: Mapping[str, Any], where: str) -> Any:
        """``text`` as the language's text of a scalar (numbers stay numbers; a text that names no
        vector and no definition's end value is kept as written, so that SymPy's simplification
        never changes its domain: ``x/x`` stays ``x/x``)."""
        if not isinstance(text, str):
            return text
        value = self.value(text, symbols, where)
        if is_vector(value):
            raise SpecError("is a vector where a scalar is needed", field=where)
        return to_text(value) if self._rewritten(text, symbols) else text

    def _rewritten(self, text: str, symbols: Mapping[str, Any]) -> bool:
        """Whether ``text`` must be written out again: it uses a vector (a name that stands for
        one, an index, a list, a vector function) or a definition's end value."""
        tree = syntax_tree(text)
        for node in ast.walk(tree):
            if isinstance(node, ast.Subscript | ast.List):
                return True
            if isinstance(node, ast.Name) and (
                is_vector(symbols.get(node.id)) or node.id in self.defined_ends or node.id in self.sizes
            ):
                return True
            if (
                isinstance(node, ast.Call)
                and isinstance(node.func, ast.Name)
                and node.func.id in VECTOR_FUNCTIONS
            ):
                return True
        return False

    def components(self, raw: Any, n: int, symbols: Mapping[str, Any], where: str) -> list[Any]:
        """``n`` component values of ``raw``: a list of ``n``, a vector expression of size ``n``, or
        one value for every component (a number, ``linear``, a scalar expression)."""
        if isinstance(raw, list):
            if len(raw) != n:
                raise SpecError(f"has {len(raw)} values for a vector of size {n}", field=where)
            return [self.scalar(v, symbols, f"{where}.{i}") for i, v in enumerate(raw)]
        if not isinstance(raw, str) or raw in ("linear", "auto", "none"):
            return [raw] * n
        value = self.value(raw, symbols, where)
        if not is_vector(value):
            return [to_text(value) if self._rewritten(raw, symbols) else raw] * n
        if value.shape[0] != n:
            raise SpecError(f"is a vector of size {value.shape[0]}, not {n}", field=where)
        return [to_text(c) for c in value]

    def relations(self, text: str, symbols: Mapping[str, Any], where: str) -> list[str]:
        """The scalar constraints of ``text`` (module doc)."""
        try:
            found = parse_vector_relation(text, symbols)
        except ExpressionError as err:
            raise self.fail(err, where) from None
        if not self._rewritten(text, symbols):
            return [text]
        return [t for r in found for t in relation_texts(r)]

    def variables(self, group: dict[str, Any], keys: tuple[str, ...], where: str) -> dict[str, Any]:
        """``group`` (states or controls) with each vector replaced by its components."""
        lowered: dict[str, Any] = {}
        for name, spec in group.items():
            n = self.sizes.get(name)
            if n is None:
                lowered[name] = spec
                continue
            spec = {k: v for k, v in spec.items() if k != "size"}
            values = {
                k: self.components(v, n, self.timed, f"{where}.{name}.{k}")
                for k, v in spec.items()
                if k in keys
            }
            other = {k: v for k, v in spec.items() if k not in keys}
            for i in range(n):
                self._new(component(name, i), group, lowered, where)
                lowered[component(name, i)] = other | {k: v[i] for k, v in values.items()}
        return lowered

    @staticmethod
    def _new(name: str, given: Mapping[str, Any], lowered: Mapping[str, Any], where: str) -> None:
        """Refuse a component whose name the file also gives (state ``r__0`` beside vector ``r``)."""
        if name in given or name in lowered:
            raise SpecError(f"names used twice: {name} is a vector's component", field=f"{where}.{name}")

    def definitions(self, raw: Mapping[str, Any], where: str, start: sp.Expr) -> dict[str, Any]:
        """Each definition as text, a vector one as one definition per component; the running
        symbols then know each definition (a vector one as the vector of its components), and the
        end symbols its values at the ends (``h_0``, ``h_f``: the definition over the states and
        controls at ``t_0 = start`` and ``t_f``, as GPOPS-II's end-point functions)."""
        lowered: dict[str, Any] = {}
        inlined = dict(self.running)
        for name, text in raw.items():
            inlined[name] = self.value(text, inlined, f"{where}.{name}")
            self._at_ends(name, inlined[name], start)
            value = self.value(text, self.running, f"{where}.{name}")
            if is_vector(value):
                n = value.shape[0]
                for i, c in enumerate(value):
                    self._new(component(name, i), raw, lowered, where)
                    lowered[component(name, i)] = to_text(c)
                self.running[name] = _vector(name, n)
            else:
                lowered[name] = self.scalar(text, self.running, f"{where}.{name}")
                self.running[name] = symbol(name)
        return lowered

    def _at_ends(self, name: str, value: Any, start: sp.Expr) -> None:
        """``name_0`` and ``name_f`` among the end symbols: ``value`` (a definition with the earlier
        ones substituted) over the end values at ``t_0 = start`` and ``t_f``; none for a definition
        of grid inputs, which have no end values."""
        if not self.end_definitions or {str(s) for s in sp.sympify(value).free_symbols} & self.inputs:
            return
        self.defined_ends |= {name + "_0", name + "_f"}
        for end, time in (("_0", start), ("_f", symbol("t_f"))):
            mapping = {symbol(v): symbol(v + end) for v in self.scalar_variables} | {symbol("t"): time}
            self.ends[name + end] = value.xreplace(mapping)

    def link_phases(self, names: list[Any]) -> None:
        """The end symbols of each phase by name (``phases.ascent.r_f``, a vector for a vector)."""
        for phase in (n for n in names if isinstance(n, str)):
            linked = {
                f"phases.{phase}.{n}": v
                for n, v in self.ends.items()
                if n not in self.params and n not in self.tables
            }
            for name, value in list(linked.items()):
                prefix = name.rsplit(".", 1)[0]
                if is_vector(value):
                    linked[name] = Vector([symbol(f"{prefix}.{c}") for c in value])
                else:
                    linked[name] = symbol(name)
            self.ends |= linked | {f"phases.{phase}.t_0": symbol(f"phases.{phase}.t_0")}

    def sections(self, raw: Mapping[str, Any], field: str, start: sp.Expr) -> dict[str, Any]:
        """The sections of a problem (or of a phase) that hold variables and expressions, lowered."""
        out = dict(raw)
        keys = ("initial", "final", "lower", "upper", "scale")
        if isinstance(raw.get("states"), Mapping):
            out["states"] = self.variables(raw["states"], keys, f"{field}.states")
        if isinstance(raw.get("controls"), Mapping):
            out["controls"] = self.variables(
                raw["controls"], ("lower", "upper", "scale"), f"{field}.controls"
            )
        if "definitions" in raw:
            out["definitions"] = self.definitions(raw["definitions"], f"{field}.definitions", start)
        if "dynamics" in raw:
            out["dynamics"] = self.dynamics(raw["dynamics"], f"{field}.dynamics")
        if isinstance(raw.get("objective"), Mapping):
            objective = dict(raw["objective"])
            for key, symbols in (("mayer", self.ends), ("lagrange", self.running)):
                if key in objective:
                    objective[key] = self.scalar(objective[key], symbols, f"{field}.objective.{key}")
            out["objective"] = objective
        if "lagrange" in raw:
            out["lagrange"] = self.scalar(raw["lagrange"], self.running, f"{field}.lagrange")
        for key, symbols in (("path_constraints", self.running), ("boundary_constraints", self.ends)):
            if isinstance(raw.get(key), list):
                out[key] = [
                    text
                    for i, c in enumerate(raw[key])
                    for text in self.relations(c, symbols, f"{field}.{key}.{i}")
                ]
        if isinstance(raw.get("integral_constraints"), list):
            out["integral_constraints"] = [
                {
                    **c,
                    "integrand": self.scalar(
                        c.get("integrand"), self.running, f"{field}.integral_constraints.{i}.integrand"
                    ),
                }
                for i, c in enumerate(raw["integral_constraints"])
            ]
        if isinstance(raw.get("jump"), Mapping):
            out["jump"] = self.dynamics(raw["jump"], f"{field}.jump", self.ends)
        if isinstance(raw.get("guess"), Mapping):
            out["guess"] = self.guess(raw["guess"], f"{field}.guess")
        if isinstance(raw.get("at"), list):
            out["at"] = [
                {**p, "constraints": self.at_point(p.get("constraints", []), self.points, f"{field}.at.{i}")}
                for i, p in enumerate(raw["at"])
            ]
        if isinstance(raw.get("measurements"), Mapping):
            out["measurements"] = self.measurements(raw["measurements"], f"{field}.measurements")
        return out

    def at_point(self, texts: Any, symbols: Mapping[str, Any], where: str) -> Any:
        """The constraints of one interior point (a list of texts), each vector one per component."""
        if not isinstance(texts, list):
            return texts
        return [
            t
            for j, c in enumerate(texts)
            for t in (self.relations(c, symbols, f"{where}.constraints.{j}") if isinstance(c, str) else [c])
        ]

    def event(self, texts: Any, where: str) -> Any:
        """A ``free_event``'s constraints: an interior point's, with ``t`` the event time."""
        return self.at_point(texts, self.points | {"t": symbol("t")}, where)

    def measurements(self, raw: Mapping[str, Any], where: str) -> dict[str, Any]:
        """The measured keys (and the weights' keys) as the scalar expressions they name; a vector
        cannot be a key (its components can), nor two keys one expression."""
        keys: dict[str, str] = {}
        for key in raw.get("values", {}):
            if is_vector(self.value(key, self.points, f"{where}.values.{key}")):
                reason = "a measured key is a scalar: measure a vector's components (r[0], r[1], ...)"
                raise SpecError(reason, field=f"{where}.values.{key}")
            keys[key] = self.scalar(key, self.points, f"{where}.values.{key}")
        twice = sorted(k for k in keys if list(keys.values()).count(keys[k]) > 1)
        if twice:
            raise SpecError(f"keys {twice} measure one expression", field=f"{where}.values")
        out = dict(raw)
        for section in ("values", "weights"):
            if isinstance(raw.get(section), Mapping):
                out[section] = {keys.get(k, k): v for k, v in raw[section].items()}
        return out

    def phase(self, raw: Any, field: str) -> Any:
        """One phase of a multi-phase problem, lowered with its own definitions."""
        if not isinstance(raw, Mapping):
            return raw
        own = copy.copy(self)
        own.running = dict(self.running)
        own.ends = self.ends | {"t_0": symbol("t_0")}
        return own.sections(raw, field, sp.Integer(0))

    def guess(self, raw: dict[str, Any], where: str) -> dict[str, Any]:
        """A guess's ``states`` and ``controls`` with each vector's value given per component."""
        lowered = dict(raw)
        for group in ("states", "controls"):
            if not isinstance(raw.get(group), Mapping):
                continue
            values = dict(raw[group])
            for name in [n for n in values if n in self.sizes]:
                parts = self.components(
                    values.pop(name), self.sizes[name], self.timed, f"{where}.{group}.{name}"
                )
                values |= {component(name, i): v for i, v in enumerate(parts)}
            lowered[group] = values
        return lowered

    def dynamics(
        self, raw: Mapping[str, Any], where: str, symbols: Mapping[str, Any] | None = None
    ) -> dict[str, Any]:
        """Per state, its equation over the running symbols (or ``symbols``: a jump over the
        previous phase's end), a vector state's as one per component."""
        symbols = self.running if symbols is None else symbols
        lowered: dict[str, Any] = {}
        for name, text in raw.items():
            n = self.sizes.get(name)
            if n is None:
                lowered[name] = self.scalar(text, symbols, f"{where}.{name}")
                continue
            values = self.components(text, n, symbols, f"{where}.{name}")
            for i, v in enumerate(values):
                self._new(component(name, i), raw, lowered, where)
                lowered[component(name, i)] = v
        return lowered


def _timed_states(texts: Any, states: Mapping[str, Any], sizes: Mapping[str, int]) -> dict[str, Any]:
    """The end symbols of the states at fixed times in the boundary constraints (``x(t=5)``, as
    :func:`~gamespec.symbolic.grammar.at_time_name` spells it): a vector state's the vector of its
    components' (``r(t=5)``: ``r__0(t=5.0)``, ...). A time that is not a number is left to the
    parse, which refuses it and names the field."""
    found: dict[str, Any] = {}
    for text in texts if isinstance(texts, list) else []:
        try:
            calls = at_time(syntax_tree(text)) if isinstance(text, str) else []
        except ExpressionError:
            continue
        for name, node in calls:
            try:
                time = numeric_value(ast.unparse(node), {})
            except ExpressionError:
                continue
            if name not in states:
                continue
            n = sizes.get(name)
            found[at_time_name(name, time)] = (
                symbol(at_time_name(name, time))
                if n is None
                else Vector([symbol(at_time_name(component(name, i), time)) for i in range(n)])
            )
    return found


def _start(problem: Mapping[str, Any]) -> sp.Expr:
    """The initial time as SymPy: the file's number, or the symbol ``t_0`` when it is free."""
    initial = (problem.get("time") or {}).get("initial", 0.0)
    if initial == "free":
        return symbol("t_0")
    return (
        _number(float(initial))
        if isinstance(initial, int | float) and not isinstance(initial, bool)
        else sp.Integer(0)
    )


def _number(value: float) -> sp.Expr:
    return sp.Integer(int(value)) if value == int(value) else sp.Float(value)


def lowered(
    problem: dict[str, Any],
    sizes: dict[str, int],
    field: str,
    phases: bool,
    tables: Mapping[str, FileFunction],
) -> tuple[dict[str, Any], _Lowering]:
    """:func:`gamespec.specs.vectors.lower_problem` once it is known to have work to do (``tables``:
    the file's, as functions of the expressions)."""
    low = _Lowering(problem, sizes, phases, tables)
    if phases:
        low.link_phases([ph.get("name") for ph in problem.get("phases", []) if isinstance(ph, Mapping)])
    out = low.sections(problem, field, _start(problem))
    if phases and isinstance(problem.get("phases"), list):
        out["phases"] = [low.phase(ph, f"{field}.phases.{k}") for k, ph in enumerate(problem["phases"])]
    return out, low
