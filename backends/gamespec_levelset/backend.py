"""The ``levelset`` and ``extremals`` backends of the ``flow_field_game`` kind (chapter 5).

Both run the chapter's pipeline and differ only in the reachability stage: ``levelset`` solves
eq. 5.22 on the grid (:mod:`gamespec.flowfield.levelset`) and integrates the nominal paths backward
along ∇φ (eqs. 5.23–5.26); ``extremals`` shoots the characteristics (:mod:`gamespec.flowfield.
extremals`) and takes the extremals through ``x_f`` as the nominal paths. Then: ``N = round(T̂/step)``
steps, the zero-order hold of the linearized dynamics (eqs. 5.5–5.8), the lifting (eq. 5.10),
the game on the best-response engine with the players of :mod:`.players` (Gauss–Seidel,
Algorithm 3, or the ``minimax`` scheme), the capture probability (eq. 5.39) per step in open loop,
closed loop (the game's solution: the pursuer's strategy against the evader's, mixed for
``minimax``) and with the pursuer's strategy against the open-loop evader, and a Monte Carlo of
the nonlinear SDE in open and closed loop (the samples split among the evader's mixture). The
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
from gamespec.best_response import Settings, iterate
from gamespec.flowfield.capture_probability import capture_probabilities
from gamespec.flowfield.covariance_game import PLAYERS, CovarianceGame, Strategy
from gamespec.flowfield.extremals import capture_by_extremals
from gamespec.flowfield.hamiltonian import FlowHamiltonian
from gamespec.flowfield.levelset import LevelSetSolver, capture_by_level_sets
from gamespec.flowfield.linearize import DiscreteModel, lifted, zero_order_hold
from gamespec.flowfield.nominal import NominalPaths, from_extremals, from_level_sets
from gamespec.flowfield.problem import FlowGameData, evaluate
from gamespec.flowfield.simulation import simulate
from gamespec.montecarlo import proportion
from gamespec.result import Result, Status
from gamespec.specs.base import SpecBase, StrictModel
from gamespec.specs.flow_game import FlowGameSpec
from gamespec_levelset.players import (
    EvaderStep,
    GamePlayer,
    MinimaxEvader,
    MinimaxPursuerStep,
    PursuerStep,
)

DISPERSION_PATHS = 200
"""Sample paths kept in the Result for the dispersion figures (Figs. 5.3, 5.4b)."""


class FlowGameOptions(StrictModel):
    """The conic solver of the players' steps and its keyword arguments; ``cross_check`` also runs
    the other reachability method and reports the difference of ``T̂``."""

    solver: str = "CLARABEL"
    solver_options: dict[str, Any] = Field(default_factory=dict)
    cross_check: bool = True


@dataclass(frozen=True)
class Reachability:
    """Stage 1's outcome: ``T̂``, ``x_f`` and the nominal paths, or why there are none; the arrays
    and metrics it contributes to the Result."""

    capture_time: float | None
    capture_point: np.ndarray | None
    paths: NominalPaths | None
    message: str
    arrays: dict[str, np.ndarray]
    metrics: dict[str, Any]


def _level_set_reach(
    spec: FlowGameSpec, data: FlowGameData, nominal: bool = True, engine: str = "numpy"
) -> Reachability:
    m = spec.method
    speeds = data.nominal_speeds
    if engine == "jax":
        from gamespec_levelset.hj_solver import HJSolver

        solver = HJSolver(data.grid, data.field, speeds, m.cfl)
    else:
        solver = LevelSetSolver(
            data.grid, FlowHamiltonian(speeds, data.field.drift(data.grid.points)), m.scheme, m.cfl
        )
    reach = capture_by_level_sets(solver, data.origins, m.max_time, level_cells=m.level_cells)
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
    return Reachability(reach.capture_time, reach.capture_point, paths, "", arrays, metrics)


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
        return result.model_copy(
            update={
                "parameters": values,
                "checks": {**result.checks, **checks},
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
    """The two players of the file's scheme, their steps, and the engine's settings."""

    pursuer: PursuerStep | MinimaxPursuerStep
    evader: EvaderStep
    players: list[GamePlayer]
    settings: Settings
    scale: float


def game_players(spec: FlowGameSpec, options: FlowGameOptions, game: CovarianceGame) -> Players:
    """Gauss–Seidel's (Algorithm 3) or the minimax scheme's players, scaled by the open-loop payoff."""
    open_loop = game.nominal()
    scale = max(game.value(open_loop), 1e-300)
    m = spec.method
    if m.game.scheme == "minimax":
        pursuer = MinimaxPursuerStep(game, options.solver, options.solver_options, scale, m.game.tolerance)
    else:
        pursuer = PursuerStep(game, options.solver, options.solver_options, scale)
    evader = EvaderStep(
        game,
        options.solver,
        options.solver_options,
        scale,
        m.convex_concave.tolerance,
        m.convex_concave.max_iterations,
        open_loop[1],
    )
    answer = (
        MinimaxEvader(evader, pursuer, m.game.gap, open_loop[1])
        if isinstance(pursuer, MinimaxPursuerStep)
        else evader
    )
    players = [GamePlayer("pursuer", pursuer), GamePlayer("evader", answer)]
    settings = Settings(
        scheme="gauss_seidel", tolerance=m.game.tolerance, max_iterations=m.game.max_iterations
    )
    return Players(pursuer, evader, players, settings, scale)


def _game(spec: FlowGameSpec, options: FlowGameOptions, data: FlowGameData, reach: Reachability) -> Result:
    """Stages 2–4: linearization, the covariance game, capture probabilities and Monte Carlo."""
    T = reach.capture_time
    stage = linearized_game(data, reach)
    model, game, tau = stage.model, stage.game, stage.time
    open_loop = game.nominal()
    m = spec.method
    cast = game_players(spec, options, game)
    pursuer, evader, scale = cast.pursuer, cast.evader, cast.scale

    def payoff(strategies: dict[str, Strategy]) -> float:
        return game.value((strategies["pursuer"], strategies["evader"]))

    run = iterate(cast.players, dict(zip(PLAYERS, open_loop, strict=True)), cast.settings, payoff)
    p_star = run.strategies["pursuer"]
    mixture = _evader_mixture(pursuer, run.strategies["evader"])
    eps = data.capture_radius
    prob = {
        "open_loop": capture_probabilities(*game.relative(open_loop), eps),
        "closed_loop": sum(w * capture_probabilities(*game.relative((p_star, e)), eps) for w, e in mixture),
        "pursuer_feedback": capture_probabilities(*game.relative((p_star, open_loop[1])), eps),
    }
    closed = (p_star, max(mixture, key=lambda we: we[0])[1])
    metrics: dict[str, Any] = {
        "capture_time": T,
        "capture_point": [float(v) for v in reach.capture_point],
        **{f"capture_probability_{k}": float(v[-1]) for k, v in prob.items()},
        "game_converged": run.converged,
        "game_scheme": m.game.scheme,
        "best_response": run.as_metrics(),
        "evader_convex_concave": {"payoffs": evader.log.steps, "converged": evader.log.converged},
        "evader_alternation": evader.log.alternation(),
        "evader_mixture": {
            "weights": [w for w, _ in mixture],
            "payoffs": [game.value((p_star, e)) / scale for _, e in mixture],
        },
        "payoff": data.payoff,
        "feedforward": data.feedforward,
        "payoff_open_loop": scale,
        "payoff_closed_loop": sum(w * game.value((p_star, e)) for w, e in mixture),
        "payoff_pursuer_feedback": game.value((p_star, open_loop[1])),
        "steps": model.N,
        "step": model.step,
        "reachability": reach.metrics,
    }
    if m.game.scheme == "minimax":
        metrics["minimax_lower_bound"] = pursuer.bound * scale
    arrays = {
        **reach.arrays,
        "nominal_time": reach.paths.times,
        "nominal_positions": reach.paths.positions,
        **{f"capture_probability_{k}": v for k, v in prob.items()},
        "gains": game.controls(closed)[1],
        "evader_support_gains": np.stack([e.kappa for _, e in mixture]),
    }
    carlo = m.monte_carlo
    if carlo.samples:
        draws = np.random.default_rng(carlo.seed).multinomial(carlo.samples, [w for w, _ in mixture])
        estimates = {}
        for name, plays in (
            ("open_loop", [(carlo.samples, open_loop)]),
            ("closed_loop", [(n, (p_star, e)) for n, (_, e) in zip(draws, mixture, strict=True) if n]),
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
    X_bar = np.vstack([data.origins.reshape(1, 4), game.mean(closed)])
    V, _ = game.controls(closed)
    names = spec.problem.position
    states = {f"{p}_{n}": X_bar[:, 2 * i + j] for i, p in enumerate(PLAYERS) for j, n in enumerate(names)}
    controls = {f"{p}_v{j + 1}": V[:, 2 * i + j] for i, p in enumerate(PLAYERS) for j in range(2)}
    violations = game.violations(closed)
    return Result(
        status=run.status,
        message=run.message,
        objective=metrics["payoff_closed_loop"],
        t_final=T,
        iterations=run.iterations,
        time=tau,
        control_time=tau[:-1],
        states=states,
        controls=controls,
        arrays=arrays,
        metrics=metrics,
        checks={"max_constraint_violation": max(0.0, *violations.values())},
    )


def _evader_mixture(
    pursuer: PursuerStep | MinimaxPursuerStep, last: Strategy
) -> list[tuple[float, Strategy]]:
    """The evader's play against the pursuer's last strategy: its last response (Gauss–Seidel), or
    the mixed strategy over the support that the minimax pursuer's multipliers give."""
    if isinstance(pursuer, MinimaxPursuerStep) and pursuer.support:
        return [(float(w), e) for w, e in zip(pursuer.weights, pursuer.support, strict=True) if w > 1e-9]
    return [(1.0, last)]


class _FlowGameBackend(Backend):
    kinds: ClassVar[frozenset[str]] = frozenset({"flow_field_game"})
    options_model = FlowGameOptions
    method: ClassVar[str]

    def _compile(self, spec: SpecBase, options: StrictModel) -> CompiledModel:
        assert isinstance(spec, FlowGameSpec) and isinstance(options, FlowGameOptions)
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
