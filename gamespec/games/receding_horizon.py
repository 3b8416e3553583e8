"""Algorithm 4: receding-horizon control of both players, the true system advancing between steps.

At every step each player's game is solved from where the players are (``G^u`` under ρ̂ with the
pursuer's transforms, ``G^v`` under ρ̄; one game when the views coincide), by best responses on the
compiled models of :class:`~gamespec.games.equilibrium.GameModel`, warm-started from the previous
step's strategies shifted by one step. Each player applies the first ``step`` of the controls of its
own game (or, when that game did not converge and ``on_not_converged: previous_plan``, the next step
of its last converged plan); the true system (true parameter values) is integrated over the step
(:class:`~gamespec.games.simulate.TrueSystem`). A state a player does not observe (the pursuer's
obstacle) it predicts with its own beliefs from the controls applied. The run stops at capture, at a
collision with the obstacle (when ``stop_at_collision``) or at the time limit; after
``max_wall_time`` seconds it stops at the end of a step with the status ``time_limit`` (the
progress bar on a terminal shows each step). The players' best responses are solved without the
OCP solution checks (each is ``feasible``, its ``checks_skipped`` saying why): the run reports none
of them, its figures (capture, clearances, convergence) being measured on the true system.

The horizon is ``N Δt`` ahead at every step (``receding``), or reaches the game's final time
(``shrinking``: each remaining length has its own compiled models); with a shrinking horizon and a
time-consistent open-loop equilibrium the run reproduces the open-loop solution.

The Result's ``solution_concept`` is ``receding_horizon_<concept>`` (each step's open-loop game's
concept, :meth:`~gamespec.games.equilibrium.GameModel.concept`; ``none`` when a step's game did not
converge) and ``saddle_gap`` the largest of the step games' gaps at their returned points (a check
against ``game.tolerance``; not computed when a player's problem has transforms). No payoff of the
realized trajectory is computed: the run's figure is the capture time.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from gamespec import terminal
from gamespec.errors import SpecError
from gamespec.games.equilibrium import GameModel, GameSolution
from gamespec.games.problems import initial_state, predicted_states
from gamespec.games.simulate import ControlPlan, TrueSystem, grid_of, true_parameters
from gamespec.result import Result, Status
from gamespec.specs.differential_game import DifferentialGameSpec, intervals_per_step, sensitivity_name
from gamespec.symbolic.calculus import numeric_function
from gamespec.symbolic.grammar import Relation
from gamespec.symbolic.language import symbol

SAMPLES_PER_STEP = 10
"""Points of the true trajectory per step at which capture and collisions are checked."""
DIFFERENCE_STEP = 1e-4
"""Relative step of the central differences of a prediction in an uncertain parameter (the
integration's relative tolerance 1e-11 leaves an error near 1e-7 in the quotient)."""


def believed_parameters(model: GameModel, player: str) -> dict[str, float]:
    """The game's parameter values with every uncertain one at ``player``'s belief."""
    return dict(model.parameters) | {n: u.belief(player) for n, u in model.game.problem.uncertain.items()}


class StateFunction:
    """An expression of the states and parameters (parsed once, :mod:`gamespec.games.expressions`),
    evaluated along sampled trajectories by vectorized NumPy; a relation's bounds in ``lower`` and
    ``upper``."""

    def __init__(self, game: DifferentialGameSpec, parsed: Relation | sp.Expr) -> None:
        p = game.problem
        self.names = [*p.parameters, *p.uncertain, *p.states]
        relation = isinstance(parsed, Relation)
        self.lower, self.upper = (parsed.lower, parsed.upper) if relation else (-np.inf, np.inf)
        expr = parsed.expr if relation else parsed
        self._f = numeric_function([expr], [symbol(n) for n in self.names])

    def __call__(self, states: Mapping[str, np.ndarray], params: Mapping[str, float]) -> np.ndarray:
        return self._f(*(states[n] if n in states else params[n] for n in self.names))[0]


class Predictor:
    """What a player that does not observe every state predicts of them: its model of the true
    system at its beliefs, from the observed states reset at every step, and the sensitivity of its
    predictions to each uncertain parameter by central differences of the same integration."""

    def __init__(self, model: GameModel, player: str, x0: Mapping[str, float]) -> None:
        game = model.game
        self.player = player
        self.observes = game.problem.players[player].observes
        believed = believed_parameters(model, player)
        self.system = TrueSystem(model.dynamics, believed)
        self.state = dict(x0)
        self.predicted = predicted_states(game, player)
        self.perturbed: dict[str, list[tuple[TrueSystem, dict[str, float], float]]] = {}
        for u in game.problem.uncertain if self.predicted else ():
            h = DIFFERENCE_STEP * max(1.0, abs(believed[u]))
            self.perturbed[u] = [
                (TrueSystem(model.dynamics, believed | {u: believed[u] + sign * h}), dict(x0), sign * h)
                for sign in (1, -1)
            ]

    def _merged(self, x: Mapping[str, float], own: Mapping[str, float]) -> dict[str, float]:
        return {s: x[s] if s in self.observes else own[s] for s in x}

    def start(self, x: Mapping[str, float]) -> dict[str, float]:
        """The state the player's game starts from: observed from ``x``, the rest predicted."""
        return self._merged(x, self.state)

    def sensitivities(self) -> dict[str, float]:
        """The predicted states' sensitivities, by their generated parameter names."""
        out = {}
        for u, ((_, plus, hp), (_, minus, hm)) in self.perturbed.items():
            for s in self.predicted:
                out[sensitivity_name(s, u)] = (plus[s] - minus[s]) / (hp - hm)
        return out

    def advance(
        self, x: Mapping[str, float], plan: ControlPlan, t: float, step: float, times: np.ndarray
    ) -> np.ndarray:
        """Advance the predictions over the step; the nominal prediction's rows at ``times``."""
        _, rows = self.system.advance(self.start(x), plan, t, step, times)
        self.state = dict(zip(self.system.states, rows[-1], strict=True))
        for u, runs in self.perturbed.items():
            updated = []
            for system, state, h in runs:
                _, prow = system.advance(self._merged(x, state), plan, t, step, times)
                updated.append((system, dict(zip(system.states, prow[-1], strict=True)), h))
            self.perturbed[u] = updated
        return rows


@dataclass
class Record:
    """What the run keeps: true samples, applied controls, look-ahead trajectories, per-step games."""

    times: list[float] = field(default_factory=list)
    states: list[np.ndarray] = field(default_factory=list)
    control_time: list[float] = field(default_factory=list)
    controls: dict[str, list[float]] = field(default_factory=dict)
    lookahead: dict[str, list[dict[str, np.ndarray]]] = field(default_factory=dict)
    predicted: dict[str, list[np.ndarray]] = field(default_factory=dict)
    steps: list[dict] = field(default_factory=list)


def _shifted(strategy: np.ndarray, points: int, keep_length: bool) -> np.ndarray:
    tail = strategy[:, points:]
    return (
        np.concatenate([tail, np.repeat(strategy[:, -1:], points, axis=1)], axis=1) if keep_length else tail
    )


class RecedingHorizon:
    """One run of Algorithm 4 (see module doc)."""

    def __init__(self, model: GameModel) -> None:
        self.model = model
        self.game = game = model.game
        self.rh = rh = game.receding_horizon
        self.players = list(game.problem.players)
        self.truth = TrueSystem(model.dynamics, true_parameters(model))
        self.predicting = [n for n, pl in game.problem.players.items() if pl.observes is not None]
        self.horizon = game.problem.evaluate(model.parameters).horizon
        intervals = game.method.intervals
        self.interval = self.horizon / intervals
        try:
            self.intervals_per_step = intervals_per_step(rh.step, self.horizon, intervals)
        except SpecError as err:
            raise SpecError(err.reason, field=err.field, source=game.source) from None
        self.points_per_step = self.intervals_per_step * grid_of(game.method).points_per_interval
        self.models: dict[int, GameModel] = {intervals: _unchecked(model)}
        assert model.expressions is not None, "a game model has its expressions"
        stop = model.expressions.stop
        self.capture = StateFunction(game, stop.capture) if stop.capture is not None else None
        self.obstacle = (
            {k: StateFunction(game, e) for k, e in stop.obstacle.items()}
            if stop.obstacle is not None
            else None
        )

    def _model(self, intervals: int, start: float) -> GameModel:
        """The compiled game with ``intervals`` left (shrinking horizon), compiled on first use."""
        if intervals not in self.models:
            data = self.game.model_dump(mode="json")
            data["method"]["intervals"] = intervals
            data["problem"]["time"] = {"initial": start, "final": self.game.problem.time.final}
            game = DifferentialGameSpec.model_validate(data)
            parsed = self.model.expressions
            self.models[intervals] = _unchecked(
                GameModel(game, parameters=dict(self.model.parameters), expressions=parsed)
            )
        return self.models[intervals]

    def _observed(
        self, view: str, x: Mapping[str, float], predicted: Mapping[str, float]
    ) -> dict[str, float]:
        observes = self.game.problem.players[view].observes
        return {s: x[s] if observes is None or s in observes else predicted[s] for s in x}

    def run(self, progress: bool = True) -> Result:
        rh, game = self.rh, self.game
        t = game.problem.time.initial
        end = t + rh.time_limit
        if rh.horizon == "shrinking":
            end = min(end, t + self.horizon)
        x = initial_state(game, self.model.parameters)
        predictors = {n: Predictor(self.model, n, x) for n in self.predicting}
        record = Record(times=[t], states=[np.array([x[s] for s in self.truth.states])])
        record.predicted = {n: [record.states[0]] for n in self.predicting}
        previous: dict[str, dict[str, np.ndarray]] = {}
        plans: dict[str, np.ndarray] = {}
        intervals = game.method.intervals
        stop, captured_at = "time_limit", None
        total = round((end - t) / rh.step)
        started = time.perf_counter()
        with terminal.progress(f"{game.name} (receding horizon)", total, enabled=progress) as tracker:
            for _ in range(total):
                model = self._model(intervals, t) if rh.horizon == "shrinking" else self.model
                solutions = {}
                for view in model.views:
                    predictor = predictors.get(view)
                    state = predictor.start(x) if predictor else x
                    sensitivities = predictor.sensitivities() if predictor else None
                    solutions[view] = model.solve(view, state, t, previous.get(view), sensitivities)
                keep = rh.horizon == "receding"
                previous = {
                    v: {n: _shifted(a, self.points_per_step, keep) for n, a in s.run.strategies.items()}
                    for v, s in solutions.items()
                }
                applied = self._applied(solutions, plans, keep)
                record.steps.append(self._step_record(t, solutions))
                self._lookahead(record, solutions, t)
                horizon = self.horizon if keep else intervals * self.interval
                values = {
                    c: strategy[row]
                    for player, strategy in applied.items()
                    for row, c in enumerate(game.problem.players[player].controls)
                }
                plan = ControlPlan.on_grid(grid_of(model.game.method), values, t, horizon)
                for c, value in plan.at(t + 1e-9 * rh.step).items():
                    record.controls.setdefault(c, []).append(value)
                record.control_time.append(t)
                times, rows = self.truth.advance(
                    x, plan, t, rh.step, np.linspace(t, t + rh.step, SAMPLES_PER_STEP + 1)
                )
                for n, predictor in predictors.items():
                    record.predicted[n].extend(predictor.advance(x, plan, t, rh.step, times)[1:])
                record.times.extend(times[1:])
                record.states.extend(rows[1:])
                x = dict(zip(self.truth.states, rows[-1], strict=True))
                t = float(times[-1])
                if rh.horizon == "shrinking":
                    intervals -= self.intervals_per_step
                iterations = ", ".join(f"{v}: {s.run.iterations}" for v, s in solutions.items())
                tracker.advance(info=f"t = {t:.2f}, iterations {iterations}")
                captured_at = self._captured(record)
                if captured_at is not None:
                    stop = "captured"
                    break
                if rh.stop_at_collision and self._collided(record):
                    stop = "collision"
                    break
                if rh.max_wall_time is not None and time.perf_counter() - started > rh.max_wall_time:
                    stop = "max_wall_time"
                    break
        return self._result(record, stop, captured_at)

    def _applied(
        self, solutions: dict[str, GameSolution], plans: dict[str, np.ndarray], keep: bool
    ) -> dict[str, np.ndarray]:
        """Each player's strategy to apply now (see module doc), and its plan kept for later."""
        applied = {}
        for player in self.players:
            own = solutions.get(player) or next(iter(solutions.values()))
            strategy = own.run.strategies[player]
            if own.run.converged or self.rh.on_not_converged == "last_iterate" or player not in plans:
                plans[player] = strategy
            else:
                strategy = plans[player] = _shifted(plans[player], self.points_per_step, keep)
            applied[player] = strategy
        return applied

    @staticmethod
    def _step_record(t: float, solutions: dict[str, GameSolution]) -> dict:
        return {
            "time": t,
            "games": {
                v: {
                    "iterations": s.run.iterations,
                    "converged": s.run.converged,
                    "outcome": s.run.outcome.value,
                    "saddle_gap": s.equilibrium.gap if s.equilibrium is not None else None,
                }
                for v, s in solutions.items()
            },
        }

    def _lookahead(self, record: Record, solutions: dict[str, GameSolution], t: float) -> None:
        """Each game's look-ahead trajectories (NaN when its last solve failed: no solution)."""
        for view, s in solutions.items():
            r = s.states
            blank = {k: np.full_like(v, np.nan, dtype=float) for k, v in r.states.items()}
            states = r.states if r.ok else blank
            record.lookahead.setdefault(view, []).append({"time": r.time + t, **states})

    def _samples(self, record: Record) -> dict[str, np.ndarray]:
        rows = np.array(record.states)
        return dict(zip(self.truth.states, rows.T, strict=True))

    def _captured(self, record: Record) -> float | None:
        """The first time the capture condition holds along the true trajectory (linear between
        samples), None if it has not."""
        if self.capture is None:
            return None
        g = self.capture(self._samples(record), true_parameters(self.model))
        lo, hi = self.capture.lower, self.capture.upper
        gap = np.maximum(lo - g, g - hi)
        inside = np.flatnonzero(gap <= 0)
        if inside.size == 0:
            return None
        k = int(inside[0])
        if k == 0:
            return record.times[0]
        t0, t1 = record.times[k - 1], record.times[k]
        return float(t0 + (t1 - t0) * gap[k - 1] / (gap[k - 1] - gap[k]))

    def _distances(self, record: Record) -> dict[str, np.ndarray]:
        """Each avoiding player's distance to the obstacle's edge along the true trajectory."""
        if self.obstacle is None:
            return {}
        samples = self._samples(record)
        params = true_parameters(self.model)
        ox, oy, radius = (self.obstacle[k](samples, params) for k in ("x", "y", "radius"))
        return {
            player: np.hypot(samples[px] - ox, samples[py] - oy) - radius
            for player, (px, py) in self.rh.obstacle.avoided_by.items()
        }

    def _collided(self, record: Record) -> bool:
        return any(float(d.min()) < 0 for d in self._distances(record).values())

    def _result(self, record: Record, stop: str, captured_at: float | None) -> Result:
        samples = self._samples(record)
        params = true_parameters(self.model)
        arrays: dict[str, np.ndarray] = {}
        if self.obstacle is not None:
            arrays |= {f"obstacle/true/{k}": self.obstacle[k](samples, params) for k in ("x", "y")}
            for n in self.predicting:
                believed = dict(zip(self.truth.states, np.array(record.predicted[n]).T, strict=True))
                bparams = believed_parameters(self.model, n)
                arrays |= {f"obstacle/{n}/{k}": self.obstacle[k](believed, bparams) for k in ("x", "y")}
        for view, steps in record.lookahead.items():
            for name in steps[0]:
                arrays[f"lookahead/{view}/{name}"] = _padded([s[name] for s in steps])
        metrics: dict = {"captured": captured_at is not None, "capture_time": captured_at, "stop": stop}
        for player, d in self._distances(record).items():
            metrics[f"{player}_min_obstacle_distance"] = float(d.min())
            metrics[f"{player}_collided"] = bool(d.min() < 0)
        converged = all(g["converged"] for s in record.steps for g in s["games"].values())
        models = list(self.models.values())
        metrics |= {
            "steps": len(record.steps),
            "per_step": record.steps,
            "all_converged": converged,
            "builds": sum(m.builds for m in models),
            "solves": sum(r.solves for m in models for r in m.responders.values()),
            "figure": {
                "positions": {p: list(v) for p, v in self.rh.positions.items()},
                "obstacle_radius": float(self.obstacle["radius"](samples, params)[0])
                if self.obstacle
                else None,
                "lookahead_players": {v: list(self.rh.positions) for v in record.lookahead},
            },
        }
        gaps = [g["saddle_gap"] for s in record.steps for g in s["games"].values()]
        gap = None if not gaps or None in gaps else max(gaps)
        concept = self.model.concept()
        metrics |= {
            "solution_concept": f"receding_horizon_{concept}" if converged else "none",
            "sought_concept": f"receding_horizon_{concept}",
            "information": "receding_horizon (each step's open-loop game, its first step applied)",
            "saddle_gap": gap,
        }
        checks: dict[str, float | None] = {}
        tolerance = self.model.game.game.tolerance
        if gap is not None:
            checks["saddle_gap"] = gap
            metrics["checks_passed"] = {"saddle_gap": bool(gap <= tolerance)}
            metrics["check_tolerances"] = {"saddle_gap": tolerance}
        failed = sum(not g["converged"] for s in record.steps for g in s["games"].values())
        message = f"stopped: {stop}" + (f"; {failed} game(s) did not converge" if failed else "")
        if gap is not None and gap > tolerance:
            message += f"; saddle gap {gap:.3g} of a step's game exceeds the tolerance {tolerance:.3g}"
        status = Status.OPTIMAL if converged else Status.FEASIBLE
        return Result(
            status=Status.TIME_LIMIT if stop == "max_wall_time" else status,
            message=message,
            objective=captured_at,
            t_final=record.times[-1],
            time=np.array(record.times),
            control_time=np.array(record.control_time),
            states=samples,
            controls={c: np.array(v) for c, v in record.controls.items()},
            arrays=arrays,
            iterations=sum(g["iterations"] for s in record.steps for g in s["games"].values()),
            checks=checks,
            metrics=metrics,
        )


def _unchecked(model: GameModel) -> GameModel:
    """``model`` with its players' responses solved without the OCP solution checks
    (:meth:`~gamespec.games.equilibrium.BestResponder.check_responses`): the run reports none of
    them (its figures are measured on the true system), and on a game of ~1300 small NLPs they
    were a fifth of the run's time."""
    for responder in model.responders.values():
        responder.check_responses(False)
    return model


def _padded(rows: list[np.ndarray]) -> np.ndarray:
    """Rows of different lengths (a shrinking horizon) as one array padded with NaN."""
    width = max(len(r) for r in rows)
    out = np.full((len(rows), width), np.nan)
    for i, r in enumerate(rows):
        out[i, : len(r)] = r
    return out


def receding_horizon(model: GameModel, progress: bool = True) -> Result:
    """Run Algorithm 4 on a compiled game (see module doc)."""
    return RecedingHorizon(model).run(progress)
