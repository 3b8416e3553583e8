"""``moving_obstacles`` and ``rcs``: the requested ``optimal_control`` rewrites of thesis §6.4.

``moving_obstacles`` appends one avoidance path constraint ``g <= 0`` per declared obstacle
(:mod:`gamespec.rcs.obstacles`: eqs. 6.39, 6.41, 6.43-6.44) and, on the way back, puts the
obstacles' positions along the solution in the Result (``obstacle_<name>_x``/``_y``) for plots,
the time of the agent's closest approach to each nominal obstacle centre and, for an obstacle off
a track, the clearance there (centre distance less r_o: ``metrics.obstacle_samples``, typed by
:class:`gamespec.rcs.metrics.ObstacleSamples`). When a Monte Carlo ran upstream (the ``rcs``
transform's ``monte_carlo``, whose kept draws are ``monte_carlo_draw_<name>``), it adds each
obstacle's centre for those draws at that time (``obstacle_<name>_sampled_x``/``_y``): where the
uncertainty is, in the plane.

``rcs`` adds the state sensitivities the desensitize transform builds (eq. 6.12, the identically
zero ones left out) and the cost ``∫‖vec S_r‖²_Q`` with ``S_r = R S_g`` (eqs. 6.31-6.36), or
``∫‖vec S_g‖²_Q`` (eq. 6.32) with ``relevant: false``. On the way back it reports through the
desensitize transform's report (``metrics.sensitivity_cost`` is the RCS cost,
``metrics.nominal_objective`` the rest) and adds ``S_g<i>_<ρ>`` and ``S_r<i>_<ρ>`` along the
solution. Its ``monte_carlo`` analysis (:meth:`Rcs.analyses`) adds
``metrics.monte_carlo.collision_probability``: the share of sampled speeds for which the
open-loop re-simulation (RK4, ``monte_carlo.steps`` steps, agent and obstacles together) breaks a
path constraint somewhere on that fine grid, with its Wilson interval (``gamespec.montecarlo.proportion``);
``lqr_tracking`` is the desensitize transform's.

With ``cost_state: true`` the cost is integrated as a state ``rcs_cost`` (its end value in the
objective), so the defect check re-integrates it between the collocation points and
``method.refine`` refines where a steep integrand is under-resolved (the super-Gaussian of
eq. 6.44); ``metrics.sensitivity_measure`` is then a dense trapezoid along the solution.
:meth:`Rcs.verify` rejects a Result that fails any check, and :meth:`Rcs.restarts` offers the
file's ``restarts`` (guess sections, e.g. other homotopy classes) for the solving layer's
multi-start.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Any, ClassVar

import numpy as np
import sympy as sp

from gamespec.analyses import Analysis, Outputs
from gamespec.desensitize.augment import NewState, sensitivity_functions
from gamespec.desensitize.penalized import (
    InverseData,
    Penalty,
    augmented_spec,
    lqr_tracking,
    open_loop_monte_carlo,
    report,
)
from gamespec.desensitize.simulate import dense_integral, evaluate, values_at
from gamespec.desensitize.spec import DesensitizeOptions
from gamespec.errors import ExpressionError, SpecError
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.ocp.transcription import Transcription
from gamespec.rcs import obstacles as geometry
from gamespec.rcs.sensitivity import (
    Inequality,
    constraint_sensitivity,
    inequalities,
    nonzero,
    relevant,
    state_sensitivity,
    weighted_square,
)
from gamespec.rcs.spec import MovingObstaclesOptions, RcsOptions
from gamespec.result import Result, Status
from gamespec.specs.ocp import GuessSpec, OptimalControlSpec
from gamespec.symbolic.language import TIME, parse, symbol
from gamespec.symbolic.printer import to_text
from gamespec.transforms.base import KeepsParameters, OcpRewrite, with_parameter_values


def _parser(spec: OptimalControlSpec, field: str, running: bool = False) -> Callable[[float | str], sp.Expr]:
    names = [*spec.problem.parameters, *(spec.problem.states if running else ())]
    symbols = {n: symbol(n) for n in names}

    def read(raw: float | str) -> sp.Expr:
        try:
            return sp.sympify(parse(raw, symbols))
        except ExpressionError as err:
            raise SpecError(str(err), field=field, source=spec.source) from None

    return read


@dataclass(frozen=True)
class ObstacleData:
    """The obstacles' positions as expressions of the parameters and ``t``."""

    positions: dict[str, tuple[sp.Expr, sp.Expr]]
    radii: dict[str, sp.Expr]
    power: sp.Expr
    agent: tuple[sp.Expr, sp.Expr]
    on_track: frozenset[str]
    """The obstacles moving along a track (eqs. 6.43-6.44), whose clearance is not a distance."""


class MovingObstacles(
    KeepsParameters[OptimalControlSpec, "ObstacleData"], OcpRewrite[MovingObstaclesOptions, "ObstacleData"]
):
    """Avoidance constraints of declared moving obstacles (§6.4.1-6.4.3); the obstacles are
    expressions of the parameters and ``t``, so every parameter maps to itself."""

    name: ClassVar[str] = "moving_obstacles"
    options_model = MovingObstaclesOptions

    def apply(
        self, spec: OptimalControlSpec, options: MovingObstaclesOptions, upstream: Result | None = None
    ) -> tuple[OptimalControlSpec, ObstacleData]:
        field = "transforms.moving_obstacles"
        read = _parser(spec, field)
        agent = tuple(_parser(spec, f"{field}.agent", running=True)(a) for a in options.agent)
        t0 = float(spec.problem.time.initial)
        power = read(options.power)
        g = geometry.constraints(options.obstacles, agent, power, read, t0)
        data = spec.model_dump(exclude={"transforms"} & set(type(spec).model_fields))
        data["problem"]["path_constraints"] += [to_text(sp.Le(e, 0, evaluate=False)) for e in g.values()]
        new = OptimalControlSpec.model_validate(data)
        new.with_source(spec.source, spec.file_hash)
        positions = {n: geometry.position(o, read, t0) for n, o in options.obstacles.items()}
        radii = {n: read(o.radius) for n, o in options.obstacles.items()}
        tracks = frozenset(n for n, o in options.obstacles.items() if o.track is not None)
        return new, ObstacleData(positions, radii, power, agent, tracks)

    def invert(self, result: Result, spec: OptimalControlSpec, inverse_data: ObstacleData) -> Result:
        arrays, metrics = dict(result.arrays), dict(result.metrics)
        if result.time is not None:
            params = {symbol(k): v for k, v in result.parameters.items()}
            t = np.asarray(result.time)
            values: dict[sp.Symbol, np.ndarray | float] = {**params, TIME: t}
            for name, (px, py) in inverse_data.positions.items():
                xy = evaluate([px, py], values, t.shape)
                arrays[f"obstacle_{name}_x"], arrays[f"obstacle_{name}_y"] = xy[0], xy[1]
            metrics["obstacle_power"] = float(evaluate([inverse_data.power], params, ())[0])
            metrics["obstacles"] = {
                n: float(evaluate([r], params, ())[0]) for n, r in inverse_data.radii.items()
            }
            values |= {symbol(k): v for k, v in result.states.items()}
            agent = evaluate(list(inverse_data.agent), values, t.shape)
            samples = _sampled(result, inverse_data, agent, arrays, metrics["obstacles"])
            metrics["obstacle_samples"], sampled = samples
            arrays |= sampled
        return result.model_copy(
            update={"arrays": arrays, "metrics": metrics, "kind": spec.kind, "problem": spec.name}
        )


def _sampled(
    result: Result,
    data: ObstacleData,
    agent: np.ndarray,
    positions: dict[str, np.ndarray],
    radii: dict[str, float],
) -> tuple[dict[str, dict[str, float]], dict[str, np.ndarray]]:
    """Per obstacle: the time of the agent's closest approach to its nominal centre (the first
    when several tie), the clearance there (off a track), and its centre at that time for each
    kept Monte Carlo draw (the draws of ``monte_carlo_draw_<name>``, the other parameters at their
    values)."""
    t = np.asarray(result.time)
    prefix = "monte_carlo_draw_"
    drawn = {k.removeprefix(prefix): v for k, v in result.arrays.items() if k.startswith(prefix)}
    drawn = {k: v for k, v in drawn.items() if k in result.parameters}
    count = min((len(v) for v in drawn.values()), default=0)
    params: dict[sp.Symbol, np.ndarray | float] = {
        symbol(k): drawn[k][:count] if k in drawn else v for k, v in result.parameters.items()
    }
    metrics: dict[str, dict[str, float]] = {}
    arrays: dict[str, np.ndarray] = {}
    for name, (px, py) in data.positions.items():
        ox, oy = positions[f"obstacle_{name}_x"], positions[f"obstacle_{name}_y"]
        gap = np.hypot(agent[0] - ox, agent[1] - oy)
        k = int(np.argmin(gap))
        metrics[name] = {"time": float(t[k])}
        if name not in data.on_track:
            metrics[name]["clearance"] = float(gap[k] - radii[name])
        if count:
            xy = evaluate([px, py], {**params, TIME: float(t[k])}, (count,))
            arrays[f"obstacle_{name}_sampled_x"], arrays[f"obstacle_{name}_sampled_y"] = xy[0], xy[1]
    return metrics, arrays


@dataclass(frozen=True)
class RcsData:
    """The desensitize report's data, and S_g, S_r (k × ℓ) with their row labels."""

    report: InverseData
    labels: list[str]
    uncertain: list[str]
    S_g: sp.Matrix
    S_r: sp.Matrix
    options: RcsOptions
    target: OptimalControlSpec
    unit: sp.Expr
    """The integrand of the sensitivity measure (unit weights)."""

    @cached_property
    def starting_points(self) -> list[Result]:
        """The ``restarts`` on the target's mesh (:func:`starting_point`), built once, at compile
        (:func:`regularized`): no solve parses a guess's text (issue 27, item 3)."""
        return [starting_point(self.target, g) for g in self.options.restarts]


class Rcs(KeepsParameters[OptimalControlSpec, "RcsData"], OcpRewrite[RcsOptions, "RcsData"]):
    """Relevant constraint sensitivity (eqs. 6.31-6.36), or eq. 6.32 with ``relevant: false``;
    every parameter maps to itself, the target kept for :meth:`restarts` taking the new values."""

    name: ClassVar[str] = "rcs"
    plot: ClassVar[str] = "gamespec.rcs.plotting:plot_rcs"
    summary: ClassVar[str] = "gamespec.rcs.report:rcs_summary"
    options_model = RcsOptions

    def apply(
        self, spec: OptimalControlSpec, options: RcsOptions | None = None, upstream: Result | None = None
    ) -> tuple[OptimalControlSpec, RcsData]:
        return regularized(spec, options or RcsOptions())

    def parameter_map(
        self, spec: OptimalControlSpec, inverse_data: RcsData
    ) -> tuple[dict[str, float], RcsData]:
        values = spec.runtime_parameters()
        return values, replace(inverse_data, target=with_parameter_values(inverse_data.target, values))

    def invert(self, result: Result, spec: OptimalControlSpec, inverse_data: RcsData) -> Result:
        return rcs_report(result, spec, inverse_data)

    def analyses(self) -> list[Analysis]:
        return list(ANALYSES)

    def verify(self, result: Result, spec: OptimalControlSpec, inverse_data: RcsData) -> str | None:
        """The first check of the Result that fails its tolerance (``metrics.checks_passed``; with
        ``cost_state`` an under-resolved risk integral fails ``max_defect_relative``), or None."""
        failed = [name for name, passed in result.metrics.get("checks_passed", {}).items() if not passed]
        if not failed:
            return None
        value = result.checks.get(failed[0])
        return f"check {failed[0]} failed ({value:.3g})" if value is not None else f"check {failed[0]} failed"

    def restarts(self, spec: OptimalControlSpec, inverse_data: RcsData) -> list[Result]:
        """The starting points of ``restarts`` (each a ``guess`` section of the file's problem) on
        the target's mesh, in the file's order."""
        return inverse_data.starting_points


FIELD = "transforms.rcs"


def regularized(spec: OptimalControlSpec, options: RcsOptions) -> tuple[OptimalControlSpec, RcsData]:
    """The spec with the sensitivity states and the (relevant) constraint-sensitivity cost (pure)."""
    uncertain = list(spec.problem.uncertain)
    if not uncertain:
        raise SpecError("rcs needs uncertain parameters (problem.uncertain)", field=FIELD, source=spec.source)
    ocp = SymbolicOcp(spec).parsed()
    chosen = _chosen(spec, ocp, options)
    aug = nonzero(sensitivity_functions(ocp, uncertain))
    g = [q.g for q in chosen]
    S_g = constraint_sensitivity(ocp, g, uncertain, state_sensitivity(ocp, uncertain, aug))
    try:
        S_r = relevant(S_g, g, options.relevance)
    except ExpressionError as err:
        raise SpecError(str(err), field=f"{FIELD}.relevance", source=spec.source) from None
    penalized = S_r if options.relevant else S_g
    weights = _weights(spec, options, len(chosen))
    cost = weighted_square(penalized, weights)
    unit = weighted_square(penalized, [sp.Integer(1)] * len(chosen))
    if options.cost_state:
        aug = replace(aug, states=[*aug.states, NewState(COST_STATE, cost, sp.Integer(0), None)])
        cost = symbol(f"{COST_STATE}_f")
        penalty = measure = Penalty(sp.Integer(0), cost)  # the measure: see rcs_report
    else:
        penalty, measure = Penalty(cost, sp.Integer(0)), Penalty(unit, sp.Integer(0))
    new = augmented_spec(spec, aug, penalty)
    data = InverseData(
        aug,
        penalty,
        measure,
        DesensitizeOptions(monte_carlo=options.monte_carlo),
        len(spec.problem.states),
        len(new.problem.states),
        ocp,
    )
    rcs = RcsData(data, [q.label for q in chosen], uncertain, S_g, S_r, options, new, unit)
    rcs.starting_points  # noqa: B018 (built now, at compile: no solve parses a guess's text)
    return new, rcs


def starting_point(target: OptimalControlSpec, guess: GuessSpec) -> Result:
    """``guess`` (a ``guess`` section in the names of the file's problem; the added states start
    from their default) evaluated on ``target``'s mesh as a Result of ``target``."""
    tr = Transcription(target.model_copy(update={"guess": guess}))
    start = tr.guess(target.runtime_parameters())
    t = tr.t0 + start.T * tr.grid.nodes
    return Result(
        status=Status.FEASIBLE,
        message="starting point",
        t_final=float(t[-1]),
        time=t,
        control_time=tr.t0 + start.T * tr.grid.eval_tau,
        states={n: start.X[i] for i, n in enumerate(tr.ocp.states)},
        controls={n: start.U[j] for j, n in enumerate(tr.ocp.controls)},
        parameters=target.runtime_parameters(),
    )


COST_STATE = "rcs_cost"
"""The state that integrates ``‖vec S_r‖²_Q`` (``cost_state: true``: ``q' = ‖vec S_r‖²_Q``,
``q(t0) = 0``, free end, ``q(t_f)`` added to the objective)."""


def _chosen(spec: OptimalControlSpec, ocp: SymbolicOcp, options: RcsOptions) -> list[Inequality]:
    found = inequalities(ocp)
    if options.constraints is not None:
        indices = {q.index for q in found}
        unknown = sorted(set(options.constraints) - indices)
        if unknown:
            raise SpecError(
                f"no inequality path constraint at {unknown} (there are: {sorted(indices)})",
                field=f"{FIELD}.constraints",
                source=spec.source,
            )
        found = [q for q in found if q.index in options.constraints]
    if not found:
        raise SpecError("rcs needs inequality path constraints g <= 0", field=FIELD, source=spec.source)
    return found


def _weights(spec: OptimalControlSpec, options: RcsOptions, k: int) -> list[sp.Expr]:
    raw = options.weight if isinstance(options.weight, list) else [options.weight] * k
    if len(raw) != k:
        raise SpecError(
            f"{len(raw)} weights for {k} constraints", field=f"{FIELD}.weight", source=spec.source
        )
    read = _parser(spec, f"{FIELD}.weight")
    return [read(w) for w in raw]


def rcs_report(result: Result, spec: OptimalControlSpec, data: RcsData) -> Result:
    """The desensitize report, ``metrics.rcs``, S_g and S_r along the solution, and the collision
    probability (see module doc)."""
    result = report(result, spec, data.report)
    metrics, arrays = dict(result.metrics), dict(result.arrays)
    metrics["rcs"] = {
        "constraints": data.labels,
        "relevance": data.options.relevance,
        "relevant": data.options.relevant,
    }
    if result.ok and result.time is not None:
        arrays |= along(result, spec, data)
        if data.options.cost_state:
            metrics["sensitivity_measure"] = dense_integral(result, SymbolicOcp(spec), data.unit)
    return result.model_copy(update={"metrics": metrics, "arrays": arrays})


def collision_monte_carlo(result: Result, spec: OptimalControlSpec, data: RcsData) -> Outputs:
    """The ``monte_carlo`` analysis of rcs: the desensitize transform's, with the violation
    probability read as the collision probability (see module doc)."""
    out = open_loop_monte_carlo(result, spec, data.report)
    mc = out.metrics.get("monte_carlo")
    if mc is None or "violation_probability" not in mc:
        return out
    mc = mc | {
        "collision_probability": mc["violation_probability"],
        "collision_probability_ci": mc["violation_probability_ci"],
    }
    return Outputs(metrics={"monte_carlo": mc}, arrays=out.arrays)


ANALYSES = (
    Analysis(
        "monte_carlo",
        collision_monte_carlo,
        "re-simulates the open-loop control under sampled uncertain parameters; the collision probability",
    ),
    Analysis(
        "lqr_tracking",
        lambda result, spec, data: lqr_tracking(result, spec, data.report),
        "the LQR-tracking closed loop for the same samples (eqs. 6.27-6.29)",
        needs=("monte_carlo",),
    ),
)
"""The rcs transform's analyses (neither decides a check of the status)."""


def along(result: Result, spec: OptimalControlSpec, data: RcsData) -> dict[str, Any]:
    """``S_g<i>_<ρ>`` and ``S_r<i>_<ρ>`` at the Result's time points."""
    t = np.asarray(result.time)
    values = values_at(result, SymbolicOcp(spec), t)
    out = {}
    for prefix, M in (("S_g", data.S_g), ("S_r", data.S_r)):
        flat = [M[i, j] for i in range(M.rows) for j in range(M.cols)]
        rows = evaluate(flat, values, t.shape)
        for (i, j), row in zip(np.ndindex(M.rows, M.cols), rows, strict=True):
            out[f"{prefix}{data.labels[i][1:]}_{data.uncertain[j]}"] = np.array(row)
    return out
