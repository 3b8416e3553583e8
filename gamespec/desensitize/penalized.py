"""An ``optimal_control`` spec augmented with sensitivity states and a penalty on them, and the report
that maps its Result back: what chapter 6's two requested rewrites share (the ``desensitize``
transform's eqs. 6.16–6.18 and the ``rcs`` transform's eqs. 6.31–6.36 both add states and a penalty,
then split the objective and sample the parameters the same way).

:func:`augmented_spec` builds the new spec (pure, every expression printed from SymPy);
:func:`report` keeps the added states in the Result and splits the objective into
``metrics.nominal_objective`` and ``metrics.sensitivity_cost`` (the solver's own quadrature, so they
add up to the objective). The analyses both rewrites declare (:data:`ANALYSES`) re-simulate the
control under sampled parameters: ``monte_carlo`` (``metrics.monte_carlo``, open loop) and
``lqr_tracking`` (``metrics.monte_carlo.tracking``, eqs. 6.27-6.29), each when the file's
``monte_carlo`` options ask for it.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import sympy as sp

from gamespec.analyses import Analysis, Outputs
from gamespec.desensitize.augment import Augmentation
from gamespec.desensitize.montecarlo import monte_carlo, tracking
from gamespec.desensitize.simulate import dense_integral, evaluate
from gamespec.desensitize.spec import DesensitizeOptions
from gamespec.errors import SpecError
from gamespec.ocp.collocation import Grid
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.ocp.transcription import Transcription
from gamespec.result import Result
from gamespec.specs.ocp import OptimalControlSpec
from gamespec.symbolic.language import TIME, symbol
from gamespec.symbolic.printer import to_text

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
    ocp: SymbolicOcp
    """The source problem's expressions, parsed when it was compiled (their SymPy forms built
    there): the Monte Carlo analyses re-simulate from them, so no solve parses text (issue 27, item
    3; a re-solve changes parameter values and distributions only, never an expression)."""


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


def report(result: Result, spec: OptimalControlSpec, inverse: InverseData) -> Result:
    """The Result with the desensitization metrics (pure: evaluates the penalty terms only)."""
    metrics = dict(result.metrics)
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
    return result.model_copy(update={"metrics": metrics, "kind": spec.kind, "problem": spec.name})


def open_loop_monte_carlo(result: Result, spec: OptimalControlSpec, inverse: InverseData) -> Outputs:
    """The ``monte_carlo`` analysis: :func:`gamespec.desensitize.montecarlo.monte_carlo` with the
    file's ``monte_carlo`` options (nothing when it asks for no samples)."""
    carlo = inverse.options.monte_carlo
    if not carlo.samples or result.time is None:
        return Outputs()
    metrics, arrays = monte_carlo(inverse.ocp, result, spec.problem.uncertain, carlo)
    return Outputs(metrics={"monte_carlo": metrics}, arrays=arrays)


def lqr_tracking(result: Result, spec: OptimalControlSpec, inverse: InverseData) -> Outputs:
    """The ``lqr_tracking`` analysis: :func:`gamespec.desensitize.montecarlo.tracking` into
    ``metrics.monte_carlo.tracking`` (nothing unless ``monte_carlo.tracking`` asks for it)."""
    carlo = inverse.options.monte_carlo
    if not (carlo.samples and carlo.tracking) or "monte_carlo" not in result.metrics:
        return Outputs()
    metrics, arrays = tracking(inverse.ocp, result, spec.problem.uncertain, carlo)
    return Outputs(
        metrics={"monte_carlo": {**result.metrics["monte_carlo"], "tracking": metrics}}, arrays=arrays
    )


ANALYSES = (
    Analysis(
        "monte_carlo",
        open_loop_monte_carlo,
        "re-simulates the open-loop control under sampled uncertain parameters (§6.3.1)",
    ),
    Analysis(
        "lqr_tracking",
        lqr_tracking,
        "the LQR-tracking closed loop for the same samples (eqs. 6.27-6.29)",
        needs=("monte_carlo",),
    ),
)
"""The desensitize transform's analyses (neither decides a check of the status)."""


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
    q, idx = _quadrature(Transcription(spec).grid)
    t = np.asarray(result.time)
    values: dict[sp.Symbol, Any] = {symbol(k): v for k, v in result.parameters.items()}
    values.update({symbol(k): np.asarray(v)[idx] for k, v in result.states.items()})
    values.update({symbol(k): np.asarray(v) for k, v in result.controls.items()})
    values[TIME] = t[idx]
    running = evaluate([penalty.running], values, (len(idx),))[0]
    return float((t[-1] - t[0]) * q @ running) + final


@lru_cache(maxsize=64)
def _quadrature(grid: Grid) -> tuple[np.ndarray, np.ndarray]:
    """The grid's quadrature weights and evaluation points, computed once per grid (a frozen value:
    every re-solve of a compiled chain reports on the same one)."""
    return grid.triplets[2], grid.eval_index


def _end_values(result: Result) -> dict[sp.Symbol, float]:
    """The end symbols (``<state>_0``, ``<state>_f``, ``t_f``) and the parameters of a Result."""
    ends: dict[sp.Symbol, float] = {symbol(k): v for k, v in result.parameters.items()}
    for k, v in result.states.items():
        ends[symbol(f"{k}_0")], ends[symbol(f"{k}_f")] = float(v[0]), float(v[-1])
    assert result.t_final is not None, "an optimal_control Result has a final time"
    ends[symbol("t_f")] = float(result.t_final)
    return ends
