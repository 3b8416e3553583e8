"""Stage 2 of chapter 5 (section 5.3): the ``flow_covariance_game`` model of the ``levelset``,
``extremals`` and ``hj_reachability`` backends (the same for all three).

About the nominal paths of its spec: ``N`` steps of ``T̂/N``, the zero-order hold of the linearized
dynamics (eqs. 5.5–5.8), the lifting (eq. 5.10), the game on the best-response engine with the
players of :mod:`.players` (the mixed minimax, or Gauss–Seidel, Algorithm 3, for
``gauss_seidel``) and the lower value (the evader commits, the pursuer answers;
:mod:`gamespec.flowfield.concepts`), the capture probability (eq. 5.39) per step in open loop and
under each solution, the closed loop being the one of ``method.game.scheme``, and a Monte Carlo of
the nonlinear SDE in open and closed loop (the samples split among the evader's mixture for the
minimax). The spec's diffusion is evaluated at each solve, so a new α re-solves the game about the
same nominal paths. Without nominal paths (no capture in stage 1) the Result is ``infeasible``.

The stage takes what is left of the backend's ``max_wall_time`` after the reachability stage
(``problem.nominal.wall_time``), checked after each best-response iteration, each step of the lower
value's ascent and each control step of the Monte Carlo (:class:`~gamespec.flowfield.budget.Budget`), with a
progress line on stderr: past it, what is left is skipped and the Result is ``time_limit``, its
message naming the part the limit cut short (the point reached so far is still reported).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from gamespec.best_response import Outcome, Settings, StepReport, iterate
from gamespec.compiling import CompiledModel, Inputs, refuse_inputs
from gamespec.flowfield.budget import Budget
from gamespec.flowfield.capture_probability import capture_probabilities
from gamespec.flowfield.concepts import saddle_gap, solution_concept
from gamespec.flowfield.covariance_game import PLAYERS, CovarianceGame, Strategy
from gamespec.flowfield.linearize import DiscreteModel, lifted, zero_order_hold
from gamespec.flowfield.problem import CovarianceGameData, evaluate_game
from gamespec.flowfield.simulation import simulate
from gamespec.flowfield.spec import FlowCovarianceGameSpec
from gamespec.montecarlo import proportion
from gamespec.result import Result, Status
from gamespec.terminal import progress
from gamespec_levelset.options import FlowGameOptions
from gamespec_levelset.players import (
    EvaderStep,
    GamePlayer,
    LowerValue,
    MinimaxEvader,
    MinimaxPursuerStep,
    PursuerStep,
    lower_value,
)
from gamespec_levelset.verdicts import verdicts

DISPERSION_PATHS = 200
"""Sample paths kept in the Result for the dispersion figures (Figs. 5.3, 5.4b)."""


def _stack(per_agent: np.ndarray) -> np.ndarray:
    """(2, N, 2) → (N, 4): pursuer then evader at each step."""
    return np.concatenate([per_agent[0], per_agent[1]], axis=1)


@dataclass(frozen=True)
class Linearized:
    """Stage 2: the discrete model along the nominal paths, the game about them, the step times."""

    model: DiscreteModel
    game: CovarianceGame
    time: np.ndarray


def linearized_game(data: CovarianceGameData) -> Linearized:
    """``N`` steps, the zero-order hold (eqs. 5.5–5.8), the lifting (eq. 5.10) and the covariance
    game about the sampled nominal paths."""
    N = data.steps
    model = zero_order_hold(data.field, data.paths, N)
    lift = lifted(model, data.origins.reshape(-1))
    tau, x_hat, u_hat = data.paths.sampled(N)
    game = CovarianceGame(
        lift, _stack(x_hat[:, 1:]), _stack(u_hat), data.bounds, data.payoff, data.feedforward
    )
    return Linearized(model, game, tau)


@dataclass(frozen=True)
class Players:
    """The two players of the file's iteration (Gauss–Seidel's, Algorithm 3, or the mixed minimax's),
    their steps, the pursuer's plain best response (for the lower value) and the engine's settings."""

    pursuer: PursuerStep | MinimaxPursuerStep
    evader: EvaderStep
    answer: PursuerStep
    players: list[GamePlayer]
    settings: Settings
    scale: float


def game_players(spec: FlowCovarianceGameSpec, options: FlowGameOptions, game: CovarianceGame) -> Players:
    """The players of the scheme's iteration, scaled by the open-loop payoff: Gauss–Seidel's for
    ``gauss_seidel``, the mixed minimax's otherwise (``lower_value`` reports it as the other figure)."""
    open_loop = game.nominal()
    scale = max(game.value(open_loop), 1e-300)
    m = spec.method
    answer = PursuerStep(game, options.solver, options.solver_options, scale)
    if m.game.scheme == "gauss_seidel":
        pursuer: PursuerStep | MinimaxPursuerStep = answer
    else:
        pursuer = MinimaxPursuerStep(game, options.solver, options.solver_options, scale, m.game.tolerance)
    evader = EvaderStep(
        game,
        options.solver,
        options.solver_options,
        scale,
        m.convex_concave.tolerance,
        m.convex_concave.max_iterations,
        open_loop[1],
    )
    respond = (
        MinimaxEvader(evader, pursuer, m.game.gap, open_loop[1])
        if isinstance(pursuer, MinimaxPursuerStep)
        else evader
    )
    players = [GamePlayer("pursuer", pursuer), GamePlayer("evader", respond)]
    settings = Settings(
        scheme="gauss_seidel", tolerance=m.game.tolerance, max_iterations=m.game.max_iterations
    )
    return Players(pursuer, evader, answer, players, settings, scale)


Plays = list[tuple[float, tuple[Strategy, Strategy]]]
"""A closed loop as weighted plays (pursuer's, evader's strategy): one for a pure point, the
evader's mixed strategy for the minimax."""


@dataclass(frozen=True)
class Concepts:
    """Both closed-loop solutions (:mod:`gamespec.flowfield.concepts`): the plays of each, keyed
    ``lower_value`` and the iteration's ``minimax_mixed`` or ``gauss_seidel``; the values ``v₋`` and
    ``v₊`` (None where not computed); the metrics, checks with tolerances, status and message of the
    chosen one."""

    plays: dict[str, Plays]
    chosen: str
    lower: float | None
    upper: float | None
    metrics: dict[str, Any]
    checks: dict[str, tuple[float | None, float]]
    status: Status
    message: str


def _concepts(
    spec: FlowCovarianceGameSpec, game: CovarianceGame, cast: Players, budget: Budget, cut: list[str]
) -> tuple[Concepts, Any]:
    """The iteration of the scheme and the lower value (eqs. 5.34–5.36 and
    :mod:`gamespec.flowfield.concepts`), the values and the solution concept; the run is returned
    for its metrics. What the ``budget`` cut short is appended to ``cut``."""
    m = spec.method.game
    open_loop = game.nominal()
    scale = cast.scale

    def payoff(strategies: dict[str, Strategy]) -> float:
        return game.value((strategies["pursuer"], strategies["evader"]))

    def stop() -> bool:
        budget.advance("covariance game, best responses")
        return budget.expired()

    run = iterate(cast.players, dict(zip(PLAYERS, open_loop, strict=True)), cast.settings, payoff, stop)
    if run.outcome is Outcome.TIME_LIMIT:
        cut.append(f"covariance game, best responses after {len(run.history)} iterations")
    p_star = run.strategies["pursuer"]
    iteration = "gauss_seidel" if m.scheme == "gauss_seidel" else "minimax_mixed"
    plays: dict[str, Plays] = {
        iteration: [(w, (p_star, e)) for w, e in _evader_mixture(cast.pursuer, run.strategies["evader"])]
    }
    answered = cast.evader.log.responses  # the last answered the run's last pursuer unless a step failed
    failed = run.outcome is Outcome.PLAYER_FAILED
    upper = game.value((p_star, answered[-1])) if answered and not failed else None
    if budget.expired():
        lower_point: LowerValue | StepReport = StepReport(Status.TIME_LIMIT, "not computed (time limit)")
        cut.append("covariance game, the lower value not computed")
    else:
        lower_point = lower_value(cast.answer, cast.evader, open_loop[1], m.gap, m.max_iterations, budget)
        if isinstance(lower_point, LowerValue) and not lower_point.converged and budget.expired():
            cut.append(f"covariance game, the lower value's ascent after {len(lower_point.values)} steps")
    lower = None
    metrics: dict[str, Any] = {"best_response": run.as_metrics(), "minimax_lower_bound": None}
    checks: dict[str, tuple[float | None, float]] = {}
    if isinstance(cast.pursuer, MinimaxPursuerStep):
        metrics["minimax_lower_bound"] = cast.pursuer.bound * scale
        if m.scheme == "minimax_mixed":
            excess = None if upper is None else (upper / scale - cast.pursuer.bound) / cast.pursuer.bound
            checks["minimax_certificate"] = (excess, m.gap)
    if isinstance(lower_point, LowerValue):
        lower = lower_point.values[-1] * scale
        plays["lower_value"] = [(1.0, (lower_point.pursuer, lower_point.evader))]
        metrics["lower_value_ascent"] = {
            "payoffs": lower_point.values,
            "converged": lower_point.converged,
            "residual": lower_point.residual,
            "copy_room": lower_point.room,
            "copy_defect": lower_point.defect,
            "bound": None if lower_point.bound is None else lower_point.bound * scale,
        }
        if m.scheme == "lower_value":
            width = None if lower_point.bound is None else lower_point.bound / lower_point.values[-1] - 1
            checks["lower_value_bracket"] = (width, m.gap)
    concept = solution_concept(lower, upper, m.gap, m.scheme)
    gap = None if lower is None or upper is None else saddle_gap(lower, upper)
    if m.scheme == "gauss_seidel":
        checks["saddle_gap"] = (None if gap is None else gap / max(upper, 1e-300), m.gap)
    metrics |= {
        "solution_concept": concept,
        "lower_value": lower,
        "upper_value": upper,
        "saddle_gap": gap,
    }
    if m.scheme == "lower_value":
        if isinstance(lower_point, LowerValue):
            status = Status.OPTIMAL if lower_point.converged else Status.ITERATION_LIMIT
            message = "" if lower_point.converged else "lower value: the evader's ascent hit max_iterations"
        else:
            status, message = lower_point.status, f"lower value: {lower_point.message}"
        converged = isinstance(lower_point, LowerValue) and lower_point.converged
        if not run.status.ok:
            message = f"{message}; " * bool(message) + f"minimax_mixed (the other figure): {run.message}"
    else:
        status, message, converged = run.status, run.message, run.converged
    if gap is not None and concept != "saddle":
        message = (
            f"{message}; " * bool(message)
            + f"{m.scheme}: no pure saddle point (v₊ − v₋ = {gap:.4g}, {gap / upper:.1%} of v₊): the "
            + "lower value (the pursuer answers) and a worst-case evader give different closed loops"
        )
    metrics["game_converged"] = converged
    chosen = "lower_value" if m.scheme == "lower_value" and "lower_value" in plays else iteration
    return Concepts(plays, chosen, lower, upper, metrics, checks, status, message), run


def _game(
    spec: FlowCovarianceGameSpec, options: FlowGameOptions, data: CovarianceGameData, budget: Budget
) -> Result:
    """Linearization, the covariance game (both solution concepts), capture probabilities and
    Monte Carlo, within the ``budget`` (module doc)."""
    T = data.paths.final_time
    stage = linearized_game(data)
    model, game, tau = stage.model, stage.game, stage.time
    open_loop = game.nominal()
    m = spec.method
    cast = game_players(spec, options, game)
    evader, scale = cast.evader, cast.scale
    cut: list[str] = []
    found, run = _concepts(spec, game, cast, budget, cut)
    eps = data.capture_radius

    def probability(plays: Plays) -> np.ndarray:
        return sum(w * capture_probabilities(*game.relative(s), eps) for w, s in plays)

    chosen = found.chosen
    closed = found.plays[chosen]
    prob = {"open_loop": capture_probabilities(*game.relative(open_loop), eps)}
    prob |= {key: probability(plays) for key, plays in found.plays.items()}
    prob["closed_loop"] = prob[chosen]
    heaviest = max(closed, key=lambda play: play[0])[1]
    objective = sum(w * game.value(s) for w, s in closed)
    mixture = found.plays.get("minimax_mixed", [])
    metrics: dict[str, Any] = {
        **{f"capture_probability_{k}": float(v[-1]) for k, v in prob.items()},
        **found.metrics,
        "payoffs": {"pursuer": objective, "evader": -objective},
        "game_scheme": m.game.scheme,
        "evader_convex_concave": {"payoffs": evader.log.steps, "converged": evader.log.converged},
        "evader_alternation": evader.log.alternation(),
        "evader_mixture": {
            "weights": [w for w, _ in mixture],
            "payoffs": [game.value(s) / scale for _, s in mixture],
        },
        "payoff": data.payoff,
        "feedforward": data.feedforward,
        "payoff_open_loop": scale,
        "payoff_closed_loop": objective,
        "steps": model.N,
        "step": model.step,
    }
    arrays = {
        **{f"capture_probability_{k}": v for k, v in prob.items()},
        "gains": game.controls(heaviest)[1],
        "evader_support_gains": np.stack([s[1].kappa for _, s in closed]),
    }
    carlo = m.monte_carlo
    if carlo.samples:
        draws = np.random.default_rng(carlo.seed).multinomial(carlo.samples, [w for w, _ in closed])
        estimates = {}
        for name, plays in (
            ("open_loop", [(carlo.samples, open_loop)]),
            ("closed_loop", [(n, s) for n, (_, s) in zip(draws, closed, strict=True) if n]),
        ):
            x0 = data.origins.reshape(-1)
            ensembles = []
            for j, (n, s) in enumerate(plays):
                controls = game.controls(s)
                ensemble = (
                    None
                    if budget.expired()
                    else simulate(data.field, model, x0, *controls, n, carlo.seed + j, carlo.substeps, budget)
                )
                if ensemble is None:
                    break
                ensembles.append(ensemble)
            if len(ensembles) < len(plays):
                cut.append(f"Monte Carlo, {name} not finished")
                continue
            hit = proportion(np.concatenate([e.separation()[:, -1] <= eps for e in ensembles]))
            estimates[name] = {"estimate": hit.estimate, "low": hit.low, "high": hit.high, "samples": hit.n}
            kept = [-(-DISPERSION_PATHS * len(e.positions) // carlo.samples) for e in ensembles]
            paths = np.concatenate([e.positions[:n] for e, n in zip(ensembles, kept, strict=True)])
            arrays[f"monte_carlo_{name}"] = paths[:DISPERSION_PATHS]  # each support point in its share
        metrics["monte_carlo_capture_probability"] = estimates
    X_bar = np.vstack([data.origins.reshape(1, 4), game.mean(heaviest)])
    V, _ = game.controls(heaviest)
    names = spec.problem.position
    states = {f"{p}_{n}": X_bar[:, 2 * i + j] for i, p in enumerate(PLAYERS) for j, n in enumerate(names)}
    controls = {f"{p}_v{j + 1}": V[:, 2 * i + j] for i, p in enumerate(PLAYERS) for j in range(2)}
    checks = {"max_constraint_violation": (max(0.0, *game.violations(heaviest).values()), 1e-6)}
    checks |= found.checks
    status, message = found.status, found.message
    if cut:
        status = Status.TIME_LIMIT
        message = "; ".join([budget.message("; ".join(cut)), *([message] if message else [])])
    return Result(
        status=status,
        message=message,
        objective=objective,
        t_final=T,
        iterations=run.iterations,
        time=tau,
        control_time=tau[:-1],
        states=states,
        controls=controls,
        arrays=arrays,
        metrics=metrics,
        checks={name: value for name, (value, _) in checks.items()},
    ).model_copy(update={"metrics": metrics | verdicts(checks)})


def _evader_mixture(
    pursuer: PursuerStep | MinimaxPursuerStep, last: Strategy
) -> list[tuple[float, Strategy]]:
    """The evader's play against the pursuer's last strategy: its last response (Gauss–Seidel), or
    the mixed strategy over the support that the minimax pursuer's multipliers give."""
    if isinstance(pursuer, MinimaxPursuerStep) and pursuer.support:
        return [(float(w), e) for w, e in zip(pursuer.weights, pursuer.support, strict=True) if w > 1e-9]
    return [(1.0, last)]


class CovarianceGameModel(CompiledModel):
    """The covariance game of one ``flow_covariance_game`` spec (see module doc)."""

    def __init__(self, spec: FlowCovarianceGameSpec, options: FlowGameOptions) -> None:
        self.spec, self.options = spec, options

    def solve(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        refuse_inputs(inputs, self.spec.kind)
        start = time.perf_counter()
        values = {**self.spec.problem.parameters, **(parameters or {})}
        data = evaluate_game(self.spec, values)
        if data.paths is None:
            return Result(
                status=Status.INFEASIBLE,
                message="no nominal paths: the reachability stage found no capture",
                parameters=values,
                metrics={"game_converged": False},
                solve_time_s=time.perf_counter() - start,
            )
        assert self.spec.problem.nominal is not None, "nominal paths come with the steps"
        limit = self.options.max_wall_time
        left = None if limit is None else max(0.0, limit - self.spec.problem.nominal.wall_time)
        with progress(f"{self.spec.name} (covariance game)") as tracker:
            result = _game(self.spec, self.options, data, Budget(left, tracker))
        return result.model_copy(update={"parameters": values, "solve_time_s": time.perf_counter() - start})
