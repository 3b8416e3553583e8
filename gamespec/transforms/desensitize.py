"""``desensitize``: the requested ``optimal_control`` → ``optimal_control`` rewrite of chapter 6.

:meth:`Desensitize.apply` adds the states of the chosen method (:mod:`gamespec.desensitize.augment`)
and the weighted terms the file asks for — trajectory ``∫‖vec S‖²_Q`` (eq. 6.16; eq. 6.7 for
Seywald's method, ``∫ μᵀQμ`` of eq. 6.62 for C-DOC), final ``‖vec S(t_f)‖²_Q`` (eq. 6.17), fixed
``S(t_f)`` (eq. 6.18) — with every generated expression printed from SymPy. The weights stay
expressions of the file's parameters, so ``--set problem.parameters.alpha=75`` and sweeps re-solve the
compiled model. A ``maximize`` objective subtracts the penalty.

:meth:`Desensitize.invert` keeps the added states in the Result (``S_x1_rho``, ``Phi_*``,
``lambda_*``, ``mu_*``), splits the objective into ``metrics.nominal_objective`` and
``metrics.sensitivity_cost`` (the solver's own quadrature, so they add up to the objective), records
the state counts, and re-simulates the control under sampled parameters (``metrics.monte_carlo``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import sympy as sp

from gamespec.desensitize.augment import METHODS, Augmentation
from gamespec.desensitize.montecarlo import monte_carlo
from gamespec.desensitize.simulate import dense_integral, evaluate
from gamespec.errors import ExpressionError, SpecError
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.ocp.transcription import Transcription
from gamespec.result import Result
from gamespec.specs.base import SpecBase
from gamespec.specs.desensitize import DesensitizeOptions, Weights
from gamespec.specs.ocp import OptimalControlSpec
from gamespec.symbolic.language import TIME, parse, symbol
from gamespec.symbolic.printer import to_text
from gamespec.transforms.base import OcpRewrite

FIELD = "transforms.desensitize"


@dataclass(frozen=True)
class Penalty:
    """The added cost in the file's sense of optimization: running and final parts."""

    running: sp.Expr
    final: sp.Expr


@dataclass(frozen=True)
class InverseData:
    """What :func:`report` needs: the augmentation, the added cost, and the same terms with unit
    weights on the entries the file weights or fixes (the *sensitivity measure*, e.g. ∫S1² or
    S1(t_f)², defined at α = 0 too)."""

    augmentation: Augmentation
    penalty: Penalty
    measure: Penalty
    options: DesensitizeOptions
    original_states: int
    augmented_states: int


class Desensitize(OcpRewrite[DesensitizeOptions, InverseData]):
    """Desensitized optimal control (chapter 6) by sensitivity functions, Seywald's method or C-DOC."""

    name: ClassVar[str] = "desensitize"
    options_model = DesensitizeOptions

    def apply(
        self,
        spec: OptimalControlSpec,
        options: DesensitizeOptions | None = None,
        upstream: Result | None = None,
    ) -> tuple[OptimalControlSpec, InverseData]:
        options = options or DesensitizeOptions()
        return desensitize(spec, options)

    def invert(self, result: Result, spec: OptimalControlSpec, inverse_data: InverseData) -> Result:
        return report(result, spec, inverse_data)


def desensitize(
    spec: OptimalControlSpec, options: DesensitizeOptions
) -> tuple[OptimalControlSpec, InverseData]:
    """The augmented spec and what :func:`report` needs (pure)."""
    uncertain = list(spec.problem.uncertain)
    if not uncertain:
        raise SpecError(
            "desensitization needs uncertain parameters (problem.uncertain)", field=FIELD, source=spec.source
        )
    ocp = SymbolicOcp(spec)
    aug = METHODS[options.method](ocp, uncertain)
    _check_terms(spec, options, aug)
    params = {n: symbol(n) for n in spec.problem.parameters}
    running = _weighted(options.trajectory, aug.running, params, spec, "trajectory")
    final = _weighted(options.final, aug.final, params, spec, "final")
    penalty = Penalty(running, final)
    measure = Penalty(
        _weighted(_unit(options.trajectory, aug.running), aug.running, params, spec, "trajectory"),
        _weighted(
            _unit(options.final, aug.final) or _unit(options.fixed or None, aug.final),
            aug.final,
            params,
            spec,
            "final",
        ),
    )
    fixed = {key: _parse(raw, params, spec, f"fixed.{key}") for key, raw in options.fixed.items()}
    new = augmented_spec(spec, aug, penalty, fixed)
    inverse = InverseData(aug, penalty, measure, options, len(spec.problem.states), len(new.problem.states))
    return new, inverse


def augmented_spec(
    spec: OptimalControlSpec, aug: Augmentation, penalty: Penalty, fixed: dict[str, sp.Expr] | None = None
) -> OptimalControlSpec:
    """``spec`` with the augmentation's states and dynamics, the end values in ``fixed`` (entry name →
    value, eq. 6.18) and the penalty added to the objective in the file's sense (pure)."""
    ocp = SymbolicOcp(spec)
    params = {n: symbol(n) for n in spec.problem.parameters}
    data = spec.model_dump(exclude={"transforms"} & set(type(spec).model_fields))
    problem = data["problem"]
    taken = set(problem["states"]) | set(problem["parameters"]) | set(problem["controls"])
    clash = sorted(taken & {s.name for s in aug.states})
    if clash:
        raise SpecError(
            f"names needed by the {aug.method} method are taken: {clash}", field=FIELD, source=spec.source
        )
    for name, expr in aug.dynamics.items():
        problem["dynamics"][name] = to_text(expr)
    constraints = problem["boundary_constraints"]
    for state in aug.states:
        entry: dict[str, Any] = {}
        if state.initial is not None:
            entry["initial"] = to_text(state.initial)
        if state.final is not None:
            if state.final.free_symbols <= set(params.values()):
                entry["final"] = to_text(state.final)
            else:
                constraints.append(_equation(symbol(f"{state.name}_f") - state.final))
        problem["states"][state.name] = entry
        problem["dynamics"][state.name] = to_text(state.rhs)
    end_of = {
        symbol(f"{s}_{e}"): (s, key)
        for s in problem["states"]
        for e, key in (("0", "initial"), ("f", "final"))
    }
    for key, value in (fixed or {}).items():
        end = aug.final[key]
        if end in end_of:
            state, which = end_of[end]
            problem["states"][state][which] = to_text(value)
        else:
            constraints.append(_equation(end - value))
    sign = ocp.sign
    user_lagrange, user_mayer = sign * ocp.lagrange, sign * ocp.mayer
    problem["objective"]["lagrange"] = to_text(user_lagrange + sign * penalty.running)
    problem["objective"]["mayer"] = to_text(user_mayer + sign * penalty.final)
    new = OptimalControlSpec.model_validate(data)
    new.with_source(spec.source, spec.file_hash)
    return new


def _equation(residual: sp.Expr) -> str:
    """A boundary constraint ``residual == 0`` in the file language."""
    return to_text(sp.Eq(residual, 0, evaluate=False))


def _check_terms(spec: OptimalControlSpec, options: DesensitizeOptions, aug: Augmentation) -> None:
    if options.trajectory is None and options.final is None and not options.fixed:
        raise SpecError("ask for at least one of trajectory, final, fixed", field=FIELD, source=spec.source)
    if aug.method == "costate" and (options.final is not None or options.fixed):
        raise SpecError(
            "the costate method (C-DOC) penalizes ∫ μᵀQμ only: use trajectory (μ(t_f) is fixed, eq. 6.63)",
            field=FIELD,
            source=spec.source,
        )
    for key in options.fixed:
        if key not in aug.final:
            raise SpecError(
                f"unknown entry {key!r} (entries: {', '.join(aug.final)})",
                field=f"{FIELD}.fixed.{key}",
                source=spec.source,
            )


def _parse(raw: float | str, params: dict[str, sp.Symbol], spec: SpecBase, where: str) -> sp.Expr:
    try:
        return sp.sympify(parse(raw, params))
    except ExpressionError as err:
        raise SpecError(str(err), field=f"{FIELD}.{where}", source=spec.source) from None


def _unit(weights: Weights | None, entries: dict[str, sp.Expr]) -> Weights | None:
    """Weight 1 on the entries ``weights`` names (all of them for a single weight)."""
    if weights is None:
        return None
    return dict.fromkeys(weights if isinstance(weights, dict) else entries, 1.0)


def _weighted(
    weights: Weights | None,
    entries: dict[str, sp.Expr],
    params: dict[str, sp.Symbol],
    spec: SpecBase,
    term: str,
) -> sp.Expr:
    """``Σ w_e · e²`` over the entries (eq. 6.16/6.17 with a diagonal Q)."""
    if weights is None:
        return sp.Integer(0)
    if not isinstance(weights, dict):
        weights = dict.fromkeys(entries, weights)
    total = sp.Integer(0)
    for key, raw in weights.items():
        if key not in entries:
            raise SpecError(
                f"unknown entry {key!r} (entries: {', '.join(entries)})",
                field=f"{FIELD}.{term}.{key}",
                source=spec.source,
            )
        total += _parse(raw, params, spec, f"{term}.{key}") * entries[key] ** 2
    return total


def report(result: Result, spec: OptimalControlSpec, inverse: InverseData) -> Result:
    """The Result with the desensitization metrics and the Monte Carlo summary (pure: re-simulates only)."""
    metrics, arrays = dict(result.metrics), dict(result.arrays)
    metrics["desensitization"] = {
        "method": inverse.augmentation.method,
        "original_states": inverse.original_states,
        "augmented_states": inverse.augmented_states,
        "formula_states": inverse.augmentation.formula_states,
    }
    if result.ok and result.time is not None:
        ocp = SymbolicOcp(spec)
        sensitivity = _penalty_value(spec, result, inverse.penalty)
        metrics["sensitivity_cost"] = sensitivity
        metrics["sensitivity_measure"] = _penalty_value(spec, result, inverse.measure)
        ends = _end_values(result)
        metrics["final_sensitivity"] = {
            k: float(evaluate([e], ends, ())[0]) for k, e in inverse.augmentation.final.items()
        }
        metrics["nominal_objective"] = (
            None if result.objective is None else result.objective - ocp.sign * sensitivity
        )
        if inverse.options.monte_carlo.samples:
            metrics["monte_carlo"], bundle = monte_carlo(
                ocp, result, spec.problem.uncertain, inverse.options.monte_carlo
            )
            arrays |= bundle
    return result.model_copy(
        update={"metrics": metrics, "arrays": arrays, "kind": spec.kind, "problem": spec.name}
    )


def _penalty_value(spec: OptimalControlSpec, result: Result, penalty: Penalty) -> float:
    """The added cost on the solution, with the transcription's own quadrature (``T q·L``) on the
    file's mesh; on a refined mesh (``metrics.refinement``), whose points the Result does not
    describe, the running part is a dense trapezoid along the solution (refined to the file's
    tolerance, the two agree to it)."""
    final = float(evaluate([penalty.final], _end_values(result), ())[0])
    if penalty.running == 0:
        return final
    if len(result.metrics.get("refinement", ())) > 1:
        return dense_integral(result, SymbolicOcp(spec), penalty.running) + final
    grid = Transcription(spec).grid
    _, _, q = grid.triplets
    idx = grid.eval_index
    t = np.asarray(result.time)
    values: dict[sp.Symbol, Any] = {symbol(k): v for k, v in result.parameters.items()}
    values.update({symbol(k): np.asarray(v)[idx] for k, v in result.states.items()})
    values.update({symbol(k): np.asarray(v) for k, v in result.controls.items()})
    values[TIME] = t[idx]
    running = evaluate([penalty.running], values, (len(idx),))[0]
    return float((t[-1] - t[0]) * q @ running) + final


def _end_values(result: Result) -> dict[sp.Symbol, float]:
    """The end symbols (``<state>_0``, ``<state>_f``, ``t_f``) and the parameters of a Result."""
    ends: dict[sp.Symbol, float] = {symbol(k): v for k, v in result.parameters.items()}
    for k, v in result.states.items():
        ends[symbol(f"{k}_0")], ends[symbol(f"{k}_f")] = float(v[0]), float(v[-1])
    assert result.t_final is not None, "an optimal_control Result has a final time"
    ends[symbol("t_f")] = float(result.t_final)
    return ends
