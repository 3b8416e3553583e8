"""An ``optimal_control`` spec as SymPy objects, the one form every OCP backend translates.

Everything is stated for minimization: ``J = sign * (Mayer + integral of Lagrange)``, with
``sign = -1`` when the file says ``maximize``. The Hamiltonian is ``H = sign*L + lambda^T f``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import sympy as sp

from gamespec.errors import SpecError
from gamespec.specs.ocp import EvaluatedValues, OptimalControlSpec
from gamespec.symbolic.calculus import numeric_function
from gamespec.symbolic.language import TIME, Relation, parse, parse_relation, symbol


@dataclass(frozen=True)
class SymbolicOcp:
    """The parsed problem: symbols, dynamics, objective, constraints and parameter-only values."""

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
        """Names of the free static parameters (decision variables of the NLP)."""
        return list(self.spec.problem.design)

    @property
    def inputs(self) -> list[str]:
        """Names of the grid inputs (signals tabulated at the evaluation points)."""
        return list(self.spec.problem.inputs)

    @cached_property
    def x(self) -> list[sp.Symbol]:
        return [symbol(n) for n in self.states]

    @cached_property
    def u(self) -> list[sp.Symbol]:
        return [symbol(n) for n in self.controls]

    @cached_property
    def p(self) -> list[sp.Symbol]:
        return [symbol(n) for n in self.parameters]

    @cached_property
    def d(self) -> list[sp.Symbol]:
        return [symbol(n) for n in self.design]

    @cached_property
    def w(self) -> list[sp.Symbol]:
        return [symbol(n) for n in self.inputs]

    @property
    def t(self) -> sp.Symbol:
        return TIME

    @cached_property
    def x0(self) -> list[sp.Symbol]:
        return [symbol(f"{n}_0") for n in self.states]

    @cached_property
    def xf(self) -> list[sp.Symbol]:
        return [symbol(f"{n}_f") for n in self.states]

    @cached_property
    def u0(self) -> list[sp.Symbol]:
        """The controls at the initial time (``<control>_0``, in Mayer and boundary terms)."""
        return [symbol(f"{n}_0") for n in self.controls]

    @cached_property
    def uf(self) -> list[sp.Symbol]:
        return [symbol(f"{n}_f") for n in self.controls]

    @cached_property
    def tf(self) -> sp.Symbol:
        return symbol("t_f")

    @cached_property
    def _running(self) -> dict[str, sp.Expr]:
        """Running symbols, and each definition by its expanded expression (substituted where named)."""
        names = [*self.parameters, *self.design, *self.inputs, *self.states, *self.controls]
        symbols = {n: symbol(n) for n in names} | {"t": TIME}
        for name, raw in self.spec.problem.definitions.items():
            symbols[name] = parse(raw, symbols)
        return symbols

    @cached_property
    def definitions(self) -> dict[str, sp.Expr]:
        """Each named expression with the earlier ones substituted (over running symbols only)."""
        return {n: self._running[n] for n in self.spec.problem.definitions}

    @cached_property
    def _ends(self) -> dict[str, sp.Expr]:
        ends = {str(s): s for s in [*self.x0, *self.xf, *self.u0, *self.uf, self.tf]}
        return {n: symbol(n) for n in [*self.parameters, *self.design]} | ends

    @cached_property
    def _params(self) -> dict[str, sp.Expr]:
        return {n: symbol(n) for n in self.parameters}

    @property
    def sign(self) -> float:
        return -1.0 if self.spec.problem.objective.sense == "maximize" else 1.0

    @cached_property
    def dynamics(self) -> list[sp.Expr]:
        dyn = self.spec.problem.dynamics
        return [parse(dyn[n], self._running) for n in self.states]

    @cached_property
    def lagrange(self) -> sp.Expr:
        """The running cost in minimization form (``sign`` applied)."""
        return self.sign * parse(self.spec.problem.objective.lagrange, self._running)

    @cached_property
    def mayer(self) -> sp.Expr:
        """The end cost in minimization form (``sign`` applied), over x0, xf, t_f, parameters."""
        return self.sign * parse(self.spec.problem.objective.mayer, self._ends)

    @cached_property
    def path(self) -> list[Relation]:
        """The path constraints, then each bound that uses ``t`` as ``x - bound(t) >= 0`` (lower)
        or ``<= 0`` (upper)."""
        problem = self.spec.problem
        relations = [parse_relation(c, self._running) for c in problem.path_constraints]
        for name, key, raw in problem.time_varying_bounds():
            gap = symbol(name) - parse(raw, self._running)
            relations.append(
                Relation(gap, 0.0, math.inf) if key == "lower" else Relation(gap, -math.inf, 0.0)
            )
        return relations

    @cached_property
    def integrals(self) -> list[Relation]:
        """Integral constraints: ``lower <= integral of expr dt <= upper`` (integrands not signed),
        the bounds at the file's parameter values (:meth:`integral_bounds` for others)."""
        bounds = self.integral_bounds(self.parameter_values())
        return [
            Relation(parse(c.integrand, self._running), lo, hi)
            for c, (lo, hi) in zip(self.spec.problem.integral_constraints, bounds, strict=True)
        ]

    def integral_bounds(self, params: Mapping[str, float]) -> list[tuple[float, float]]:
        """Per integral constraint ``(lower, upper)`` for these parameter values."""
        return self._evaluated(params).integrals

    @cached_property
    def boundary(self) -> list[Relation]:
        return [parse_relation(c, self._ends) for c in self.spec.problem.boundary_constraints]

    @cached_property
    def hamiltonian_end_value(self) -> sp.Expr:
        """``-dPhi/dt_f`` for the minimization form: the constant value of H on an autonomous,
        free-final-time problem (transversality, e.g. eq. 2.23)."""
        return -sp.diff(self.mayer, self.tf)

    @property
    def autonomous(self) -> bool:
        """No explicit ``t`` in the dynamics and the running cost (grid inputs aside: see
        :meth:`inputs_in_hamiltonian`)."""
        exprs = [*self.dynamics, self.lagrange]
        return not any(TIME in e.free_symbols for e in exprs)

    @cached_property
    def running_arguments(self) -> list[sp.Symbol]:
        """The symbols a running expression may use, in the order of :attr:`running_function`."""
        return [*self.x, *self.u, *self.w, *self.p, *self.d, self.t]

    @cached_property
    def running_function(self) -> Callable[..., np.ndarray]:
        """The dynamics and the Lagrange integrand, translated once: called with one array per
        :attr:`running_arguments` it returns ``(n_x + 1, *shape)`` (the checks evaluate them often)."""
        return numeric_function([*self.dynamics, self.lagrange], self.running_arguments)

    @cached_property
    def inputs_in_hamiltonian(self) -> list[int]:
        """Indices of the grid inputs that enter the dynamics or the running cost: a time-varying
        one makes H time-varying (``dH/dt = dH/dw * dw/dt`` on an optimal arc)."""
        used = set().union(*(e.free_symbols for e in [*self.dynamics, self.lagrange]))
        return [i for i, s in enumerate(self.w) if s in used]

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
        """Per design variable: ``(lower, upper, guess)``."""
        return self._evaluated(params).design

    def _evaluated(self, params: Mapping[str, float]) -> EvaluatedValues:
        try:
            return self.spec.problem.evaluate(params)
        except SpecError as err:
            raise SpecError(err.reason, field=err.field, source=self.spec.source) from None

    def final_time(self, params: Mapping[str, float]) -> tuple[float, float, float]:
        """``(lower, upper, guess)`` of the final time (lower == upper when it is fixed)."""
        time = self.spec.problem.time
        if time.free:
            lo, hi = self._evaluated(params).t_bounds
            guess = self.spec.guess.t_final or time.guess or 0.5 * (lo + hi)
            return lo, hi, guess
        tf = self._evaluated(params).t_final
        return tf, tf, tf
