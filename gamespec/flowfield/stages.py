"""Chapter 5 as two stages: what :mod:`gamespec.flowfield.transform` writes and reads.

Stage 1, reachability (section 5.2): the ``flow_field_game`` without its diffusion (the
disturbance term is ignored, so the flow is the drift alone) and without a Monte Carlo, as a
``flow_reachability`` spec; a reachability backend returns ``T̂``, ``x_f`` (Theorem 6), the nominal
paths (eqs. 5.23–5.26, arrays ``nominal_time``, ``nominal_positions``, ``nominal_directions``) and
the checks of that stage (closure errors, the cross-check, the grid-error estimate).

Stage 2, the covariance game (section 5.3): the flow, the players and the game's method of the
``flow_field_game`` with ``N = round(T̂ / step)`` (eq. 5.7) and the nominal paths written out, as a
``flow_covariance_game`` spec. Its runtime parameters are the flow game's, so a new value of one
that enters only the diffusion (α) re-solves the game about the same nominal paths.

:func:`flow_game_result` maps the game's Result back to the ``flow_field_game``'s names: the
stage-1 metrics, arrays and checks joined to the game's.
"""

from __future__ import annotations

from typing import Any

from gamespec.flowfield.problem import FlowGameData, evaluate
from gamespec.flowfield.spec import FlowCovarianceGameSpec, FlowGameSpec, FlowReachabilitySpec
from gamespec.result import Result

NOMINAL_ARRAYS = ("nominal_time", "nominal_positions", "nominal_directions")
"""The arrays of the nominal paths in a reachability Result (the directions only feed the game)."""
GAME_NOTE = "the covariance game of section 5.3 about the nominal paths of the reachability stage"
REACHABILITY_METRICS = ("capture_time", "capture_point", "reachability", "grid_error_estimate")
"""The metrics of a reachability Result that the ``flow_field_game``'s Result carries."""


def reachability_key(data: FlowGameData) -> tuple[Any, ...]:
    """The values stage 1 depends on: the drift, the starts, the nominal speeds and the step (the
    grid-error check's tolerance is 5 % of it); the rest of the method is structure."""
    return (
        str(data.field.drift_exprs),
        data.origins.tobytes(),
        data.nominal_speeds.tobytes(),
        data.step,
    )


def reachability_spec(spec: FlowGameSpec) -> FlowReachabilitySpec:
    """Stage 1's spec: ``spec`` with a zero diffusion and no Monte Carlo, same solver section."""
    data = spec.model_dump()
    data["kind"] = "flow_reachability"
    data["problem"]["flow"]["diffusion"] = {"identity": 0.0}
    data["method"]["monte_carlo"]["samples"] = 0
    return FlowReachabilitySpec.model_validate(data).with_source(spec.source, spec.file_hash)


def covariance_game_spec(spec: FlowGameSpec, reach: Result) -> FlowCovarianceGameSpec:
    """Stage 2's spec from the flow game and its reachability Result: ``N = max(1, round(T̂ /
    step))`` and the nominal paths; without a capture, neither (the game has nothing to play)."""
    p, m = spec.problem, spec.method
    steps, nominal = None, None
    if "capture_time" in reach.metrics:
        data = evaluate(spec)
        steps = max(1, round(reach.metrics["capture_time"] / data.step))
        times, positions, directions = (reach.arrays[name] for name in NOMINAL_ARRAYS)
        nominal = {
            "times": times.tolist(),
            "speeds": data.nominal_speeds.tolist(),
            "wall_time": reach.solve_time_s or 0.0,
            **{
                player: {"positions": positions[i].tolist(), "directions": directions[i].tolist()}
                for i, player in enumerate(("pursuer", "evader"))
            },
        }
    problem = {
        "parameters": p.parameters,
        "position": p.position,
        "flow": p.flow.model_dump(),
        "pursuer": p.pursuer.model_dump(),
        "evader": p.evader.model_dump(),
        "capture_radius": p.capture_radius,
        "payoff": p.payoff,
        "feedforward": p.feedforward,
        "steps": steps,
        "nominal": nominal,
    }
    method = {name: getattr(m, name).model_dump() for name in ("game", "convex_concave", "monte_carlo")}
    game = FlowCovarianceGameSpec.model_validate(
        {
            "name": spec.name,
            "description": f"{spec.description.strip()} [{GAME_NOTE}]".strip(),
            "solver": spec.solver.model_dump(),
            "problem": problem,
            "method": method,
        }
    )
    return game.with_source(spec.source, spec.file_hash)


def flow_game_result(game: Result, reach: Result) -> Result:
    """The game's Result with stage 1's metrics, arrays (but the directions), checks and verdicts;
    without a capture, stage 1's status (``infeasible``, or ``time_limit`` when its time limit
    stopped it), message, arrays and reachability metrics."""
    if "capture_time" not in reach.metrics:
        return game.model_copy(
            update={
                "status": reach.status,
                "message": reach.message,
                "arrays": reach.arrays,
                "metrics": {"reachability": reach.metrics["reachability"], "game_converged": False},
            }
        )
    metrics = {key: reach.metrics[key] for key in REACHABILITY_METRICS if key in reach.metrics}
    metrics |= game.metrics
    for key in ("checks_passed", "check_tolerances"):
        metrics[key] = {**reach.metrics.get(key, {}), **game.metrics.get(key, {})}
    arrays = {name: a for name, a in reach.arrays.items() if name != "nominal_directions"}
    return game.model_copy(
        update={
            "metrics": metrics,
            "arrays": {**arrays, **game.arrays},
            "checks": {**reach.checks, **game.checks},
        }
    )
