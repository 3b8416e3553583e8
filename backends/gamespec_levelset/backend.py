"""The ``levelset`` and ``extremals`` backends of the ``flow_field_game`` kind (chapter 5).

Both run the chapter's pipeline and differ only in the reachability stage: ``levelset`` solves
eq. 5.22 on the grid (:mod:`gamespec.flowfield.levelset`) and integrates the nominal paths backward
along ∇φ (eqs. 5.23–5.26); ``extremals`` shoots the characteristics (:mod:`gamespec.flowfield.
extremals`) and takes the extremals through ``x_f`` as the nominal paths. Then: ``N = round(T̂/step)``
steps, the zero-order hold of the linearized dynamics (eqs. 5.5–5.8), the lifting (eq. 5.10),
the game on the best-response engine with the players of :mod:`.players` (the mixed minimax, or
Gauss–Seidel, Algorithm 3, for ``gauss_seidel``) and the lower value (the evader commits, the
pursuer answers; :mod:`gamespec.flowfield.concepts`), the capture probability (eq. 5.39) per step
in open loop and under each solution, the closed loop being the one of ``method.game.scheme``,
and a Monte Carlo of the nonlinear SDE in open and closed loop (the samples split among the
evader's mixture for the minimax). The
reachability and nominal paths depend on the drift only, so a re-solve with new values of
parameters that enter only the diffusion (α) reuses them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from pydantic import Field

from gamespec.backend import Availability, Backend, CompiledModel, Inputs, refuse_inputs
from gamespec.best_response import Outcome, Settings, iterate
from gamespec.flowfield.capture_probability import capture_probabilities
from gamespec.flowfield.concepts import saddle_gap, solution_concept
from gamespec.flowfield.covariance_game import PLAYERS, CovarianceGame, Strategy
from gamespec.flowfield.extremals import capture_by_extremals
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.hamiltonian import FlowHamiltonian
from gamespec.flowfield.levelset import (
    LevelSetSolver,
    capture_by_level_sets,
    coarser_grid,
    grid_error_estimate,
)
from gamespec.flowfield.linearize import DiscreteModel, lifted, zero_order_hold
from gamespec.flowfield.nominal import NominalPaths, from_extremals, from_level_sets
from gamespec.flowfield.problem import FlowGameData, evaluate
from gamespec.flowfield.simulation import simulate
from gamespec.montecarlo import proportion
from gamespec.result import Result, Status
from gamespec.specs.base import StrictModel
from gamespec.specs.flow_game import FlowGameSpec
from gamespec_levelset.players import (
    EvaderStep,
    GamePlayer,
    LowerValue,
    MinimaxEvader,
    MinimaxPursuerStep,
    PursuerStep,
    lower_value,
)

DISPERSION_PATHS = 200
"""Sample paths kept in the Result for the dispersion figures (Figs. 5.3, 5.4b)."""
GRID_ERROR_STEPS = 0.05
"""The tolerance of ``checks.capture_time_grid_error``, in game steps ``T̂/N``: the level-set grid
may move the game's time grid by at most 5 % of a step."""


class FlowGameOptions(StrictModel):
    """The conic solver of the players' steps and its keyword arguments; ``cross_check`` also runs
    the other reachability method and reports the difference of ``T̂``."""

    solver: str = "CLARABEL"
    solver_options: dict[str, Any] = Field(default_factory=dict)
    cross_check: bool = True


@dataclass(frozen=True)
class Reachability:
    """Stage 1's outcome: ``T̂``, ``x_f`` and the nominal paths, or why there are none; the arrays
    and metrics it contributes to the Result; the grid-error estimate where one was made (None
    inside: the coarser grid found no capture)."""

    capture_time: float | None
    capture_point: np.ndarray | None
    paths: NominalPaths | None
    message: str
    arrays: dict[str, np.ndarray]
    metrics: dict[str, Any]
    grid_error: dict[str, Any] | None = None


def _level_set_reach(
    spec: FlowGameSpec, data: FlowGameData, nominal: bool = True, engine: str = "numpy"
) -> Reachability:
    """Stage 1 by level sets; with ``nominal`` (not a cross-check) also the nominal paths and, for
    the NumPy engine, the grid-error estimate from the same levels on a coarser grid
    (:func:`~gamespec.flowfield.levelset.grid_error_estimate`, about 1/8 of the work)."""
    m = spec.method
    speeds = data.nominal_speeds

    def numpy_solver(grid: Grid) -> LevelSetSolver:
        return LevelSetSolver(grid, FlowHamiltonian(speeds, data.field.drift(grid.points)), m.scheme, m.cfl)

    if engine == "jax":
        from gamespec_levelset.hj_solver import HJSolver

        solver = HJSolver(data.grid, data.field, speeds, m.cfl)
    else:
        solver = numpy_solver(data.grid)
    reach = capture_by_level_sets(solver, data.origins, m.max_time, levels=m.read_levels)
    metrics = {
        "method": "levelset",
        "engine": "hj_reachability (jax)" if engine == "jax" else "numpy",
        "scheme": "weno5" if engine == "jax" else m.scheme,
        "nodes": list(data.grid.shape),
        "time_steps": reach.steps,
        "band_level": reach.band,
    }
    arrays = {"reach_margin_time": reach.times, "reach_margin": reach.margins}
    if reach.capture_time is None:
        return Reachability(None, None, None, reach.message, arrays, metrics)
    paths = from_level_sets(reach, data.field, speeds, data.origins) if nominal else None
    grid_error = None
    if nominal and engine == "numpy":
        coarse_solver = numpy_solver(coarser_grid(data.grid))
        coarse = capture_by_level_sets(coarse_solver, data.origins, m.max_time, levels=m.read_levels)
        grid_error = {"estimate": grid_error_estimate(reach, coarse)}
    metrics |= {
        "levels": reach.levels.tolist(),
        "level_capture_times": reach.level_times.tolist(),
        "level_offset": float(reach.level_times[1] - reach.level_times[0]),
    }
    arrays |= {
        "grid_x": data.grid.axes[0],
        "grid_y": data.grid.axes[1],
        "phi_final": reach.snapshots[-1].astype(float),
    }
    return Reachability(reach.capture_time, reach.capture_point, paths, "", arrays, metrics, grid_error)


def _extremal_reach(spec: FlowGameSpec, data: FlowGameData, nominal: bool = True) -> Reachability:
    e = spec.method.extremals
    speeds = data.nominal_speeds
    reach = capture_by_extremals(
        data.field, data.origins, speeds, spec.method.max_time, directions=e.directions, dt=e.step
    )
    metrics = {"method": "extremals", "directions": e.directions, "time_step": e.step}
    if reach.capture_time is None:
        return Reachability(
            None, None, None, f"no capture before t_max = {spec.method.max_time:g}", {}, metrics
        )
    paths = (
        from_extremals(data.field, data.origins, speeds, reach.capture_time, reach.capture_point)
        if nominal
        else None
    )
    arrays = {"front_final": reach.fronts[-1]}
    return Reachability(reach.capture_time, reach.capture_point, paths, "", arrays, metrics)


REACHABILITY = {
    "levelset": _level_set_reach,
    "extremals": _extremal_reach,
    "hj_reachability": lambda spec, data: _level_set_reach(spec, data, engine="jax"),
}


def _stack(per_agent: np.ndarray) -> np.ndarray:
    """(2, N, 2) → (N, 4): pursuer then evader at each step."""
    return np.concatenate([per_agent[0], per_agent[1]], axis=1)


class FlowGameModel(CompiledModel):
    """The pipeline for one spec; stage 1 is cached on the values that determine it."""

    def __init__(self, spec: FlowGameSpec, options: FlowGameOptions, method: str) -> None:
        self.spec, self.options, self.method = spec, options, method
        self._reach: tuple[tuple, Reachability] | None = None

    def reachability(self, data: FlowGameData) -> Reachability:
        key = (str(data.field.drift_exprs), data.origins.tobytes(), data.nominal_speeds.tobytes())
        if self._reach is None or self._reach[0] != key:
            self._reach = key, REACHABILITY[self.method](self.spec, data)
        return self._reach[1]

    def cross_check(self, data: FlowGameData, reach: Reachability) -> dict[str, float]:
        if not self.options.cross_check or reach.capture_time is None:
            return {}
        if self.method != "extremals":
            other = _extremal_reach(self.spec, data, nominal=False)
        else:
            other = _level_set_reach(self.spec, data, nominal=False)
        if other.capture_time is None:
            return {"capture_time_other_method": None}
        return {
            "capture_time_other_method": other.capture_time,
            "capture_time_difference": abs(other.capture_time - reach.capture_time),
            "capture_point_difference": float(np.linalg.norm(other.capture_point - reach.capture_point)),
        }

    def solve(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        refuse_inputs(inputs, self.spec.kind)
        start = time.perf_counter()
        values = {**self.spec.problem.parameters, **(parameters or {})}
        data = evaluate(self.spec, values)
        reach = self.reachability(data)
        if reach.capture_time is None:
            return Result(
                status=Status.INFEASIBLE,
                message=reach.message,
                parameters=values,
                arrays=reach.arrays,
                metrics={"reachability": reach.metrics, "game_converged": False},
                solve_time_s=time.perf_counter() - start,
            )
        checks = self.cross_check(data, reach)
        result = _game(self.spec, self.options, data, reach)
        checks |= {
            f"closure_error_{n}": float(e) for n, e in zip(PLAYERS, reach.paths.closure_error, strict=True)
        }
        metrics = result.metrics
        if reach.grid_error is not None:
            estimate = reach.grid_error["estimate"]
            graded = {
                "capture_time_grid_error": (
                    None if estimate is None else estimate["capture_time"],
                    GRID_ERROR_STEPS * data.step,
                )
            }
            checks |= {name: value for name, (value, _) in graded.items()}
            verdicts = _verdicts(graded)
            metrics = metrics | {key: metrics[key] | verdicts[key] for key in verdicts}
            metrics["grid_error_estimate"] = estimate
        return result.model_copy(
            update={
                "parameters": values,
                "checks": {**result.checks, **checks},
                "metrics": metrics,
                "solve_time_s": time.perf_counter() - start,
            }
        )


@dataclass(frozen=True)
class Linearized:
    """Stage 2: the discrete model along the nominal paths, the game about them, the step times."""

    model: DiscreteModel
    game: CovarianceGame
    time: np.ndarray


def linearized_game(data: FlowGameData, reach: Reachability) -> Linearized:
    """``N = round(T̂/step)`` steps, the zero-order hold (eqs. 5.5–5.8), the lifting (eq. 5.10) and
    the covariance game about the sampled nominal paths."""
    N = max(1, round(reach.capture_time / data.step))
    model = zero_order_hold(data.field, reach.paths, N)
    lift = lifted(model, data.origins.reshape(-1))
    tau, x_hat, u_hat = reach.paths.sampled(N)
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


def game_players(spec: FlowGameSpec, options: FlowGameOptions, game: CovarianceGame) -> Players:
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


def _concepts(spec: FlowGameSpec, game: CovarianceGame, cast: Players) -> tuple[Concepts, Any]:
    """The iteration of the scheme and the lower value (eqs. 5.34–5.36 and
    :mod:`gamespec.flowfield.concepts`), the values and the solution concept; the run is returned
    for its metrics."""
    m = spec.method.game
    open_loop = game.nominal()
    scale = cast.scale

    def payoff(strategies: dict[str, Strategy]) -> float:
        return game.value((strategies["pursuer"], strategies["evader"]))

    run = iterate(cast.players, dict(zip(PLAYERS, open_loop, strict=True)), cast.settings, payoff)
    p_star = run.strategies["pursuer"]
    iteration = "gauss_seidel" if m.scheme == "gauss_seidel" else "minimax_mixed"
    plays: dict[str, Plays] = {
        iteration: [(w, (p_star, e)) for w, e in _evader_mixture(cast.pursuer, run.strategies["evader"])]
    }
    answered = cast.evader.log.responses  # the last answered the run's last pursuer unless a step failed
    failed = run.outcome is Outcome.PLAYER_FAILED
    upper = game.value((p_star, answered[-1])) if answered and not failed else None
    lower_point = lower_value(cast.answer, cast.evader, open_loop[1], m.gap, m.max_iterations)
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


def _game(spec: FlowGameSpec, options: FlowGameOptions, data: FlowGameData, reach: Reachability) -> Result:
    """Stages 2–4: linearization, the covariance game (both solution concepts), capture
    probabilities and Monte Carlo."""
    T = reach.capture_time
    stage = linearized_game(data, reach)
    model, game, tau = stage.model, stage.game, stage.time
    open_loop = game.nominal()
    m = spec.method
    cast = game_players(spec, options, game)
    evader, scale = cast.evader, cast.scale
    found, run = _concepts(spec, game, cast)
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
        "capture_time": T,
        "capture_point": [float(v) for v in reach.capture_point],
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
        "reachability": reach.metrics,
    }
    arrays = {
        **reach.arrays,
        "nominal_time": reach.paths.times,
        "nominal_positions": reach.paths.positions,
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
            ensembles = [
                simulate(data.field, model, x0, *game.controls(s), n, carlo.seed + j, carlo.substeps)
                for j, (n, s) in enumerate(plays)
            ]
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
    return Result(
        status=found.status,
        message=found.message,
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
    ).model_copy(update={"metrics": metrics | _verdicts(checks)})


def _verdicts(checks: dict[str, tuple[float | None, float]]) -> dict[str, dict[str, Any]]:
    """``checks_passed`` (a value that is a finite number at most its tolerance) and
    ``check_tolerances`` for the checks that have a tolerance (the status policy reads them)."""
    passed = {
        name: value is not None and bool(np.isfinite(value)) and value <= tolerance
        for name, (value, tolerance) in checks.items()
    }
    return {"checks_passed": passed, "check_tolerances": {n: t for n, (_, t) in checks.items()}}


def _evader_mixture(
    pursuer: PursuerStep | MinimaxPursuerStep, last: Strategy
) -> list[tuple[float, Strategy]]:
    """The evader's play against the pursuer's last strategy: its last response (Gauss–Seidel), or
    the mixed strategy over the support that the minimax pursuer's multipliers give."""
    if isinstance(pursuer, MinimaxPursuerStep) and pursuer.support:
        return [(float(w), e) for w, e in zip(pursuer.weights, pursuer.support, strict=True) if w > 1e-9]
    return [(1.0, last)]


class _FlowGameBackend(Backend[FlowGameSpec, FlowGameOptions]):
    kinds: ClassVar[frozenset[str]] = frozenset({"flow_field_game"})
    options_model = FlowGameOptions
    method: ClassVar[str]

    def _compile(self, spec: FlowGameSpec, options: FlowGameOptions) -> FlowGameModel:
        return FlowGameModel(spec, options, self.method)


class LevelSetBackend(_FlowGameBackend):
    """Reachability by the level-set equation 5.22 on the file's grid, in NumPy: each step updates
    only the box around the levels the capture search reads (:mod:`gamespec.flowfield.band`).
    Nothing to compile, so the fastest for one solve; see ``hj_reachability`` for repeated solves on
    one grid in one process."""

    name = "levelset"
    method = "levelset"


class ExtremalBackend(_FlowGameBackend):
    """Reachability by extremal shooting (no grid)."""

    name = "extremals"
    method = "extremals"


class HJReachabilityBackend(_FlowGameBackend):
    """Reachability by hj_reachability (JAX) on the file's grid (WENO5, TVD-RK3; the scheme of
    ``method.scheme`` is not used), single precision, the whole grid each step, one XLA program for
    both agents' step compiled on the first solve for a grid, field and speeds (seconds) and reused
    by later solves in the process. The fast option for many solves on one grid in one process
    (per step about twice as fast as NumPy on the whole grid); for one solve, ``levelset`` is
    faster. Optional: needs ``pip install hj-reachability jax``."""

    name = "hj_reachability"
    method = "hj_reachability"

    @classmethod
    def available(cls) -> Availability:
        try:
            import hj_reachability
            import jax
        except ImportError as err:
            return Availability(False, f"optional; pip install hj-reachability jax ({err})")
        return Availability(
            True, f"hj_reachability {hj_reachability.__version__}, jax {jax.__version__} (CPU)"
        )
