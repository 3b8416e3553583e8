"""An ``optimal_control`` spec's expressions, built in any algebra of
:mod:`gamespec.symbolic.grammar`: SymPy (the form the transforms differentiate and the Pyomo
backend translates), a backend's own expressions straight from the text (the CasADi graph, NumPy
arrays for the checks) or the names each term depends on.

Everything is stated for minimization: ``J = sign * (Mayer + integral of Lagrange)``, with
``sign = -1`` when the file says ``maximize``. The Hamiltonian is ``H = sign*L + lambda^T f``.
"""

from __future__ import annotations

import ast
import dataclasses
import math
from collections.abc import Callable, Container, Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Generic, TypeVar

import numpy as np

from gamespec.errors import ExpressionError, SpecError
from gamespec.specs.ocp import INITIAL_TIME, NORMALIZED_TIME, EvaluatedValues, OptimalControlSpec
from gamespec.symbolic.grammar import (
    FLOATS,
    Algebra,
    Deferred,
    DeferredAlgebra,
    Relation,
    deferred_name,
    dependencies,
    expression,
    kept_expression,
    kept_relation,
    relation,
    unknowns,
)
from gamespec.symbolic.library import NUMPY, LibraryAlgebra
from gamespec.symbolic.tape import vectorized

HORIZON_FLOOR = 1e-6
"""The shortest horizon a free initial time allows, relative to the longest: ``T`` stays positive."""
EVALUATIONS_KEPT = 8
"""How many parameter values' bounds a :class:`SymbolicOcp` keeps."""
ALGEBRAS_KEPT = 8
"""For how many algebras a :class:`SymbolicOcp` keeps the walks of its terms (:meth:`SymbolicOcp._keep`)."""


@dataclass(frozen=True)
class RunningTerms:
    """The running terms in one algebra: the dynamics, the Lagrange integrand (``sign`` applied),
    the path constraints (then each bound that uses ``t`` as ``x - bound(t) >= 0`` (lower) or
    ``<= 0`` (upper)) and the integrands of the integral constraints (not signed)."""

    dynamics: list[Any]
    lagrange: Any
    path: list[Relation]
    integrands: list[Any]


@dataclass(frozen=True)
class EndTerms:
    """The end-point terms in one algebra: the Mayer term (``sign`` applied) and the boundary
    constraints (but those that name a state at a fixed time, ``x(t=5)``: interior points,
    :mod:`gamespec.ocp.events`), over ``<state>_0``, ``<state>_f``, ``<control>_0``,
    ``<control>_f``, ``t_f``, the parameters and the design variables."""

    mayer: Any
    boundary: list[Relation]


Terms = TypeVar("Terms", RunningTerms, EndTerms)


@dataclass(frozen=True)
class KeptTerms(Generic[Terms]):
    """Terms walked once over :class:`~gamespec.symbolic.grammar.Deferred` names: the ``steps``
    that compute named values first, in order (each a kept walk over the names and the steps
    before it), and the terms, each a kept walk over those (a relation's bounds as numbers)."""

    steps: tuple[tuple[str, Any], ...]
    terms: Terms

    def scope(self, values: Mapping[str, Any], only: Container[str] | None = None) -> dict[str, Any]:
        """``values`` (by name; the tables too) and each step's value (of the steps named in
        ``only``, when given) over them and the steps before it."""
        scope = dict(values)
        for name, step in self.steps:
            if only is None or name in only:
                scope[name] = _taken(step, scope)
        return scope

    def taken(self, values: Mapping[str, Any]) -> Terms:
        """The terms at ``values`` (by name; the tables too): what walking the texts over them
        builds, step for step in the same algebra."""
        scope = self.scope(values)
        found = {f.name: _taken(getattr(self.terms, f.name), scope) for f in dataclasses.fields(self.terms)}
        return dataclasses.replace(self.terms, **found)


def _taken(term: Any, scope: Mapping[str, Any]) -> Any:
    """A kept term (a walk, a relation of one, a list of them) at ``scope``."""
    if isinstance(term, list):
        return [_taken(t, scope) for t in term]
    if isinstance(term, Relation):
        return Relation(_taken(term.expr, scope), term.lower, term.upper)
    return term(scope) if type(term) is Deferred else term


@dataclass(frozen=True)
class SymbolicOcp:
    """The parsed problem: names, the running and end terms in any algebra, and the
    parameter-only values as floats. The SymPy forms (:attr:`dynamics`, :attr:`path`, ...) are
    built on first use only."""

    spec: OptimalControlSpec

    @property
    def states(self) -> list[str]:
        return list(self.spec.problem.states)

    @property
    def controls(self) -> list[str]:
        return list(self.spec.problem.controls)

    @property
    def parameters(self) -> list[str]:
        return list(self.spec.problem.parameters)

    @property
    def design(self) -> list[str]:
        """Names of the free static parameters (decision variables of the NLP), then ``t_0`` when
        the initial time is free."""
        free_initial = [INITIAL_TIME] if self.free_initial else []
        return [*self.spec.problem.design, *free_initial]

    @property
    def free_initial(self) -> bool:
        """Whether the initial time is free: the transcription's time ``t`` and final time ``t_f``
        are then counted from 0, and every term sees them shifted by the variable ``t_0``."""
        return self.spec.problem.time.free_initial

    @property
    def inputs(self) -> list[str]:
        """Names of the grid inputs (signals tabulated at the evaluation points)."""
        return list(self.spec.problem.inputs)

    @property
    def functions(self) -> dict[str, Any]:
        """The file's tables by name (:mod:`gamespec.symbolic.tables`), in every scope."""
        return self.spec.problem.functions

    @property
    def sign(self) -> float:
        return -1.0 if self.spec.problem.objective.sense == "maximize" else 1.0

    @property
    def running_names(self) -> list[str]:
        """The names a running expression may use, in the order of :attr:`running_function`."""
        return [*self.states, *self.controls, *self.inputs, *self.parameters, *self.design, "t"]

    @property
    def end_names(self) -> list[str]:
        """The names an end-point expression may use."""
        ends = [f"{n}_{e}" for e in "0f" for n in [*self.states, *self.controls]]
        return [*self.parameters, *self.design, *ends, "t_f"]

    def running_values(
        self, x: Sequence[Any], u: Sequence[Any], w: Sequence[Any], t: Any, others: Mapping[str, Any]
    ) -> dict[str, Any]:
        """The values of :attr:`running_names` by name: one per state, control and grid input,
        ``t``, and the parameters and design variables from ``others``."""
        values = dict(zip(self.states, x, strict=True)) | dict(zip(self.controls, u, strict=True))
        return values | dict(zip(self.inputs, w, strict=True)) | dict(others) | {"t": t}

    def end_values(
        self,
        x: tuple[Sequence[Any], Sequence[Any]],
        u: tuple[Sequence[Any], Sequence[Any]],
        t_final: Any,
        others: Mapping[str, Any],
    ) -> dict[str, Any]:
        """The values of :attr:`end_names` by name: the states ``x`` and controls ``u`` at the
        (first, last) point, the final time, and the parameters and design variables from
        ``others``."""
        values: dict[str, Any] = dict(others)
        for names, (first, last) in ((self.states, x), (self.controls, u)):
            values |= {f"{n}_0": v for n, v in zip(names, first, strict=True)}
            values |= {f"{n}_f": v for n, v in zip(names, last, strict=True)}
        return values | {"t_f": t_final}

    def _scope(self, values: Mapping[str, Any], algebra: Algebra) -> dict[str, Any]:
        """``values`` (by name) and each definition built over them and the earlier ones."""
        scope = dict(values) | self.functions
        for name, raw in self.spec.problem.definitions.items():
            scope[name] = expression(raw, scope, algebra)
        return scope

    def _shifted(self, values: Mapping[str, Any], name: str, algebra: Algebra) -> dict[str, Any]:
        """``values`` with the time ``name`` shifted by a free initial time (unchanged when fixed)."""
        if not self.free_initial:
            return dict(values)
        return {**values, name: algebra.binary(ast.Add, values[name], values[INITIAL_TIME])}

    def definitions(self, values: Mapping[str, Any], algebra: Algebra) -> dict[str, Any]:
        """Each definition by name, built over ``values`` and the earlier ones: the steps of the
        running terms' kept walk (:meth:`_keep`) but a free initial time's shift, so that a failed
        solve's diagnosis (:mod:`gamespec.ocp.diagnostics`) walks no text."""
        defined = self.spec.problem.definitions
        kept = self._kept_running(algebra)
        if kept is None:
            scope = self._scope(values, algebra)
        else:
            scope = kept.scope(dict(values) | self.functions, only=defined)
        return {name: scope[name] for name in defined}

    def running_terms(self, values: Mapping[str, Any], algebra: Algebra) -> RunningTerms:
        """The running terms over ``values`` (each of :attr:`running_names` by name): the file's
        texts walked once per algebra (:meth:`_keep`) and taken at ``values``."""
        kept = self._kept_running(algebra)
        if kept is None:
            scope = self._scope(self._shifted(values, "t", algebra), algebra)
            return self._running_over(scope, algebra)
        return kept.taken(dict(values) | self.functions)

    def _running_over(self, scope: Mapping[str, Any], algebra: Algebra) -> RunningTerms:
        """The running terms over ``scope`` (the names, the definitions and the tables)."""
        problem = self.spec.problem
        lagrange = expression(problem.objective.lagrange, scope, algebra)
        path = [relation(c, scope, algebra) for c in problem.path_constraints]
        for name, key, raw in problem.time_varying_bounds():
            gap = algebra.binary(ast.Sub, scope[name], expression(raw, scope, algebra))
            path.append(Relation(gap, 0.0, math.inf) if key == "lower" else Relation(gap, -math.inf, 0.0))
        return RunningTerms(
            dynamics=[expression(problem.dynamics[n], scope, algebra) for n in self.states],
            lagrange=algebra.binary(ast.Mult, algebra.number(self.sign), lagrange),
            path=path,
            integrands=[expression(c.integrand, scope, algebra) for c in problem.integral_constraints],
        )

    def end_terms(self, values: Mapping[str, Any], algebra: Algebra) -> EndTerms:
        """The end-point terms over ``values`` (each of :attr:`end_names` by name): the file's
        texts walked once per algebra (:meth:`_keep`) and taken at ``values``."""
        kept = self._kept_end(algebra)
        if kept is None:
            return self._end_over(self._shifted(values, "t_f", algebra) | self.functions, algebra)
        return kept.taken(dict(values) | self.functions)

    def _end_over(self, scope: Mapping[str, Any], algebra: Algebra) -> EndTerms:
        """The end-point terms over ``scope`` (the names and the tables)."""
        problem = self.spec.problem
        mayer = expression(problem.objective.mayer, scope, algebra)
        inline = problem.inline_points()
        boundary = [
            relation(c, scope, algebra) for i, c in enumerate(problem.boundary_constraints) if i not in inline
        ]
        if self.free_initial:
            lo, hi, _ = self.final_time(self.parameter_values())
            boundary.append(Relation(scope["t_f"], lo, hi))
        return EndTerms(mayer=algebra.binary(ast.Mult, algebra.number(self.sign), mayer), boundary=boundary)

    @cached_property
    def _kept_texts(self) -> dict[tuple[Any, ...], Any]:
        """The texts :meth:`kept_relation` and :meth:`kept_expression` walked, by text, names and
        algebra."""
        return {}

    def kept_relation(self, text: str, names: Sequence[str], algebra: Algebra = FLOATS) -> Relation | None:
        """The constraint ``text`` over ``names`` and the file's tables walked once per algebra
        (:func:`~gamespec.symbolic.grammar.kept_relation`: None where the walk refuses it), for
        every transcription of this problem (issue 27, item 3)."""
        key = (True, text, tuple(names), algebra)
        if key not in self._kept_texts:
            self._kept_texts[key] = kept_relation(text, names, algebra, self.functions)
        found: Relation | None = self._kept_texts[key]
        return found

    def kept_expression(self, text: str | float, names: Sequence[str], algebra: Algebra = FLOATS) -> Any:
        """The expression ``text`` over ``names`` and the file's tables walked once per algebra
        (:func:`~gamespec.symbolic.grammar.kept_expression`: None where the walk refuses it)."""
        key = (False, text, tuple(names), algebra)
        if key not in self._kept_texts:
            self._kept_texts[key] = kept_expression(text, names, algebra, self.functions)
        return self._kept_texts[key]

    @cached_property
    def profiles(self) -> dict[str, Any]:
        """The guess's expressions and the grid inputs' defaults over the parameters and ``tau``
        walked once in NumPy, by field (:func:`~gamespec.symbolic.grammar.kept_expression`; None
        where the walk refuses one; neither changes with the mesh)."""
        names = [*self.parameters, NORMALIZED_TIME]
        texts = {
            f"guess.{group}.{name}": raw
            for group in ("states", "controls")
            for name, raw in getattr(self.spec.guess, group).items()
        }
        texts |= {f"problem.inputs.{n}.default": i.default for n, i in self.spec.problem.inputs.items()}
        arrays = LibraryAlgebra(NUMPY)
        return {
            field: kept_expression(raw, names, arrays)
            for field, raw in texts.items()
            if isinstance(raw, str) and raw != "linear"
        }

    @cached_property
    def kept_boundary(self) -> list[Relation | None]:
        """Each boundary constraint walked once in floats over :attr:`end_names`
        (:meth:`kept_relation`; None for one that names a state at a fixed time)."""
        return [self.kept_relation(text, self.end_names) for text in self.spec.problem.boundary_constraints]

    @cached_property
    def _kept_terms(self) -> dict[tuple[Algebra, bool], Any]:
        """The last :data:`ALGEBRAS_KEPT` algebras' :class:`KeptTerms` (running ones and end ones)."""
        return {}

    def _kept_running(self, algebra: Algebra) -> KeptTerms[RunningTerms] | None:
        """The running terms walked once in ``algebra`` (:meth:`_keep`)."""
        found: KeptTerms[RunningTerms] | None = self._keep(algebra, True, self._running_over)
        return found

    def _kept_end(self, algebra: Algebra) -> KeptTerms[EndTerms] | None:
        """The end-point terms walked once in ``algebra`` (:meth:`_keep`)."""
        found: KeptTerms[EndTerms] | None = self._keep(algebra, False, self._end_over)
        return found

    def _keep(
        self, algebra: Algebra, running: bool, build: Callable[[Mapping[str, Any], Algebra], Terms]
    ) -> KeptTerms[Terms] | None:
        """The running (else the end-point) terms, ``build`` over their scope, walked once in
        ``algebra`` with each step kept (:class:`~gamespec.symbolic.grammar.DeferredAlgebra`), so
        that each call, and each model built on this problem (another mesh of
        :mod:`gamespec.compiling.refinement`), takes them again without walking text (issue 27,
        item 3). The time shifted by a free initial time and each definition are steps taken once
        per call, as the walk builds them once. None where the walk refuses a step it cannot keep
        (then the text is walked each time, which names the refusal)."""
        key = (algebra, running)
        if key in self._kept_terms:
            kept: KeptTerms[Terms] | None = self._kept_terms[key]
            return kept
        deferred = DeferredAlgebra(algebra)
        names = self.running_names if running else self.end_names
        scope: dict[str, Any] = {n: deferred_name(n) for n in names} | self.functions
        steps: list[tuple[str, Any]] = []
        time = "t" if running else "t_f"
        texts = self.spec.problem.definitions.items() if running else {}.items()
        try:
            if self.free_initial:
                steps.append((time, self._shifted(scope, time, deferred)[time]))
            for name, raw in texts:
                steps.append((name, expression(raw, scope, deferred)))
                scope[name] = deferred_name(name)
            found = KeptTerms(tuple(steps), build(scope, deferred))
        except ExpressionError:
            found = None
        if len(self._kept_terms) >= 2 * ALGEBRAS_KEPT:
            self._kept_terms.pop(next(iter(self._kept_terms)))
        self._kept_terms[key] = found
        return found

    @cached_property
    def running_structure(self) -> RunningTerms:
        """The running terms as :class:`~gamespec.symbolic.grammar.Dependent` values (the names each
        depends on: :func:`~gamespec.symbolic.grammar.dependencies`), with the constraints' bounds."""
        return self.running_terms(unknowns(self.running_names), FLOATS)

    @cached_property
    def _sympy(self) -> tuple[RunningTerms, EndTerms]:
        """The running and end terms in SymPy (imported here, at the first use: loading and
        solving on CasADi or Pyomo never need it)."""
        from gamespec.symbolic.language import SYMPY

        running = {n: self._symbols[n] for n in self.running_names}
        ends = {n: self._symbols[n] for n in self.end_names}
        return self.running_terms(running, SYMPY), self.end_terms(ends, SYMPY)

    @property
    def dynamics(self) -> list[Any]:
        """The dynamics in SymPy."""
        return self._sympy[0].dynamics

    @property
    def lagrange(self) -> Any:
        """The running cost in SymPy, in minimization form (``sign`` applied)."""
        return self._sympy[0].lagrange

    @property
    def path(self) -> list[Relation]:
        """The path constraints in SymPy (:class:`RunningTerms`)."""
        return self._sympy[0].path

    def integral_bounds(self, params: Mapping[str, float]) -> list[tuple[float, float]]:
        """Per integral constraint ``(lower, upper)`` for these parameter values."""
        return self._evaluated(params).integrals

    @property
    def mayer(self) -> Any:
        """The end cost in SymPy, in minimization form (``sign`` applied)."""
        return self._sympy[1].mayer

    def parsed(self) -> SymbolicOcp:
        """This problem with its SymPy forms (:attr:`dynamics`, :attr:`mayer`, ...,
        :attr:`initial_values`) built now, when it is compiled, so that what uses them later parses
        no text."""
        self._sympy  # noqa: B018 (a cached property, built here)
        self.initial_values  # noqa: B018
        return self

    def kept_for_solves(self) -> SymbolicOcp:
        """This problem with the walks a transcription's solves take (:attr:`profiles`,
        :attr:`kept_boundary`) kept now, when it is compiled, so that the first solve walks no text."""
        self.profiles  # noqa: B018 (a cached property, built here)
        self.kept_boundary  # noqa: B018
        return self

    @cached_property
    def initial_values(self) -> list[Any]:
        """Each state's initial value in SymPy, an expression of the parameters (None when free),
        parsed on first use only (a desensitized problem's Monte Carlo re-simulations use the
        compiled problem's)."""
        from gamespec.symbolic.language import SYMPY

        params = {n: self._symbols[n] for n in self.parameters}
        initial = [spec.initial for spec in self.spec.problem.states.values()]
        return [None if raw is None else expression(raw, params, SYMPY) for raw in initial]

    @cached_property
    def _symbols(self) -> dict[str, Any]:
        from gamespec.symbolic.language import symbol

        return {n: symbol(n) for n in [*self.running_names, *self.end_names]}

    @property
    def x(self) -> list[Any]:
        return [self._symbols[n] for n in self.states]

    @property
    def u(self) -> list[Any]:
        return [self._symbols[n] for n in self.controls]

    @property
    def p(self) -> list[Any]:
        return [self._symbols[n] for n in self.parameters]

    @property
    def w(self) -> list[Any]:
        return [self._symbols[n] for n in self.inputs]

    @property
    def t(self) -> Any:
        return self._symbols["t"]

    @property
    def x0(self) -> list[Any]:
        return [self._symbols[f"{n}_0"] for n in self.states]

    @property
    def xf(self) -> list[Any]:
        return [self._symbols[f"{n}_f"] for n in self.states]

    @property
    def autonomous(self) -> bool:
        """No explicit ``t`` in the dynamics and the running cost (grid inputs aside: see
        :meth:`inputs_in_hamiltonian`)."""
        return "t" not in self._hamiltonian_names

    @cached_property
    def _hamiltonian_names(self) -> frozenset[str]:
        terms = self.running_structure
        return frozenset().union(*map(dependencies, [*terms.dynamics, terms.lagrange]))

    @cached_property
    def running_function(self) -> Callable[..., np.ndarray]:
        """The dynamics, the Lagrange integrand and the integral constraints' integrands, recorded
        once: called with one array per :attr:`running_names` it returns ``(n_x + 1 + n_integrals,
        *shape)`` (the checks evaluate them often)."""
        names = self.running_names

        def build(slots: list[Any], library: Any) -> list[Any]:
            terms = self.running_terms(dict(zip(names, slots, strict=True)), LibraryAlgebra(library))
            return [*terms.dynamics, terms.lagrange, *terms.integrands]

        return vectorized(build, len(names), NUMPY)

    @cached_property
    def inputs_in_hamiltonian(self) -> list[int]:
        """Indices of the grid inputs that enter the dynamics or the running cost: a time-varying
        one makes H time-varying (``dH/dt = dH/dw * dw/dt`` on an optimal arc)."""
        return [i for i, n in enumerate(self.inputs) if n in self._hamiltonian_names]

    def parameter_values(self, overrides: Mapping[str, float] | None = None) -> dict[str, float]:
        """The file's parameter values with ``overrides`` applied, derived parameters recomputed
        from them (unknown names, and a derived parameter set on its own, are an error)."""
        problem = self.spec.problem
        values = {n: v for n, v in problem.parameters.items() if not isinstance(v, str)}
        for name, value in (overrides or {}).items():
            if name in problem.derived_parameters:
                raise SpecError(
                    f"parameter {name!r} is derived ({name}: {problem.parameters[name]}); set the "
                    "parameters it is computed from, or replace it by a number with --set at load",
                    field=f"problem.parameters.{name}",
                    source=self.spec.source,
                )
            if name not in values:
                raise SpecError(
                    f"unknown parameter {name!r} (declared: {', '.join(values) or 'none'})",
                    field="problem.parameters",
                    source=self.spec.source,
                )
            if not math.isfinite(float(value)):
                raise SpecError(f"parameter {name!r} must be finite, got {value}", source=self.spec.source)
            values[name] = float(value)
        try:
            return problem.parameter_values(values)
        except SpecError as err:
            raise SpecError(err.reason, field=err.field, source=self.spec.source) from None

    def state_bounds(
        self, params: Mapping[str, float]
    ) -> list[tuple[float, float, float | None, float | None]]:
        """Per state: ``(lower, upper, initial, final)`` as floats (initial/final None when free)."""
        return self._evaluated(params).states

    def control_bounds(self, params: Mapping[str, float]) -> list[tuple[float, float]]:
        return self._evaluated(params).controls

    def design_bounds(self, params: Mapping[str, float]) -> list[tuple[float, float, float]]:
        """Per design variable: ``(lower, upper, guess)`` (a free initial time's last)."""
        evaluated = self._evaluated(params)
        return evaluated.design + ([evaluated.t0_bounds] if evaluated.t0_bounds else [])

    def horizon(self, params: Mapping[str, float]) -> tuple[float, float, float]:
        """``(lower, upper, guess)`` of the horizon ``T = t_f - t_0``; with a free initial time
        its bounds are the widest the two times' bounds allow (their sum is a boundary constraint of
        :meth:`end_terms`), positive."""
        lo, hi, guess = self.final_time(params)
        t0 = self._evaluated(params).t0_bounds
        if t0 is None:
            origin = self.spec.problem.time.origin
            return lo - origin, hi - origin, guess - origin
        earliest, latest, start = t0
        shortest = max(lo - latest, HORIZON_FLOOR * (hi - earliest))
        return shortest, hi - earliest, max(guess - start, shortest)

    @cached_property
    def _evaluations(self) -> dict[tuple[tuple[str, float], ...], EvaluatedValues]:
        """The last :data:`EVALUATIONS_KEPT` values of :meth:`_evaluated` by parameter values: one
        solve and its checks ask for the bounds at the same values several times."""
        return {}

    def _evaluated(self, params: Mapping[str, float]) -> EvaluatedValues:
        key = tuple((n, float(v)) for n, v in params.items())
        found = self._evaluations.get(key)
        if found is not None:
            return found
        try:
            found = self.spec.problem.evaluate(params)
        except SpecError as err:
            raise SpecError(err.reason, field=err.field, source=self.spec.source) from None
        if len(self._evaluations) >= EVALUATIONS_KEPT:
            self._evaluations.pop(next(iter(self._evaluations)))
        self._evaluations[key] = found
        return found

    def final_time(self, params: Mapping[str, float]) -> tuple[float, float, float]:
        """``(lower, upper, guess)`` of the final time (lower == upper when it is fixed)."""
        time = self.spec.problem.time
        if time.free:
            lo, hi = self._evaluated(params).t_bounds
            guess = self.spec.guess.t_final or time.guess or 0.5 * (lo + hi)
            return lo, hi, guess
        tf = self._evaluated(params).t_final
        return tf, tf, tf
