"""The ``best_response`` backend: a ``differential_game`` solved by best responses on OCP backends.

Compiling builds a :class:`~gamespec.games.equilibrium.GameModel` (each player's problem of each game
compiled once on ``game.backend``); solving runs the receding horizon of Algorithm 4 when the file
has a ``receding_horizon`` section (:mod:`gamespec.games.receding_horizon`), else the open-loop game
over the whole horizon. With ``game.information: feedback`` it parses the linear-quadratic game
instead and solves its coupled Riccati equations (:mod:`gamespec.games.feedback_game`), or runs
iterative LQ games on a game that is not LQ (:mod:`gamespec.games.iterative_lq`); ``game.scheme:
joint`` solves the players' stacked optimality conditions (:mod:`gamespec.games.joint`). Runtime
parameters are the game's ``problem.parameters``.
"""

from __future__ import annotations

from functools import cached_property
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from gamespec.compiling import Backend, CompiledModel, Inputs, NoOptions, refuse_inputs
from gamespec.games.equilibrium import GameModel, GameSolution, equilibrium_report, status_of
from gamespec.games.existence import existence
from gamespec.games.expressions import game_expressions
from gamespec.games.feedback import LQGame
from gamespec.games.feedback_game import feedback_equilibrium
from gamespec.games.lq_structure import LQForm, lq_form, lq_game
from gamespec.games.problems import initial_state
from gamespec.games.simulate import ControlPlan, TrueSystem, grid_of, true_parameters
from gamespec.result import Result, Status
from gamespec.specs.base import SpecBase
from gamespec.specs.differential_game import DifferentialGameSpec

if TYPE_CHECKING:
    from gamespec.games.iterative_lq import DiscreteGame


def open_loop(model: GameModel) -> Result:
    """The open-loop game over the whole horizon from the initial state.

    One game (no private beliefs or transforms): its trajectories. Several (``G^i`` per player):
    each player applies the controls of its own game and the true system is integrated with them;
    each game's own trajectories are in ``arrays["game/<player>/<state>"]``. A zero-sum LQ game
    whose Riccati test (:mod:`gamespec.games.existence`) finds no saddle is refused as ``unbounded``.
    """
    game = model.game
    exists = existence(model.lq, model.parameters)
    if exists.refused:
        metrics: dict[str, Any] = {
            "existence": exists.as_metrics(),
            "solution_concept": "none",
            "sought_concept": model.concept(),
        }
        return Result(status=Status.UNBOUNDED, message=exists.reason, metrics=metrics)
    x0, t0 = initial_state(game, model.parameters), game.problem.time.initial
    solutions = [model.solve(view, x0, t0) for view in model.views]
    own = {name: _own(solutions, name) for name in game.problem.players}
    message = "; ".join(s.run.message for s in solutions if s.run.message)
    unanswered = [p for p in game.problem.players if p not in own[p].results]
    if unanswered:
        status = status_of(solutions)
        return Result(
            status=status if not status.ok else Status.ERROR,
            message=f"{message}; no best response of {', '.join(unanswered)} was computed".lstrip("; "),
            iterations=sum(s.run.iterations for s in solutions),
            metrics={"best_response": _runs(solutions), "builds": model.builds},
        )
    first = solutions[0].states
    assert first.time is not None and first.control_time is not None, "a best response has its grids"
    tc = first.control_time + t0
    controls = {c: own[p].controls_of(p)[c] for p, pl in game.problem.players.items() for c in pl.controls}
    arrays: dict[str, np.ndarray] = {}
    if "control_mesh" in first.arrays:
        arrays["control_mesh"] = first.arrays["control_mesh"] + t0
    if len(solutions) == 1:
        time, states = first.time + t0, dict(first.states)
    else:
        for s in solutions:
            arrays |= {f"game/{s.view}/{k}": v for k, v in s.states.states.items()}
        time, states = _simulated(model, first, controls, t0)
    report = equilibrium_report(model, solutions)
    metrics = {"best_response": _runs(solutions), "builds": model.builds, "existence": exists.as_metrics()}
    metrics |= report.metrics
    return Result(
        status=status_of(solutions),
        message="; ".join(m for m in [message, report.message] if m),
        objective=first.objective,
        t_final=float(time[-1]),
        time=time,
        control_time=tc,
        states=states,
        controls=controls,
        arrays=arrays,
        iterations=sum(s.run.iterations for s in solutions),
        checks=report.checks,
        metrics=metrics,
    )


def _own(solutions: list[GameSolution], player: str) -> GameSolution:
    """The game ``player`` solves (the only one when there is one)."""
    return next((s for s in solutions if s.view == player), solutions[0])


def _runs(solutions: list[GameSolution]) -> dict[str, Any]:
    return {s.view: s.run.as_metrics() for s in solutions}


def _simulated(
    model: GameModel, reference: Result, controls: dict[str, np.ndarray], t0: float
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    game = model.game
    grid = grid_of(game.method)
    assert reference.time is not None, "a best response has its time grid"
    horizon = float(reference.time[-1] - reference.time[0])
    plan = ControlPlan.on_grid(grid, controls, t0, horizon)
    system = TrueSystem(model.dynamics, true_parameters(model))
    times, rows = system.advance(
        initial_state(game, model.parameters), plan, t0, horizon, t0 + horizon * grid.nodes
    )
    return times, dict(zip(system.states, rows.T, strict=True))


class GameCompiled(CompiledModel):
    """A compiled game: re-solved with new values of the game's parameters without a rebuild."""

    def __init__(self, game: DifferentialGameSpec) -> None:
        self.game = game
        feedback = game.game.information == "feedback"
        self.expressions = game_expressions(game) if feedback else None
        form = lq_form(game, self.expressions) if feedback else None
        self.feedback = form if isinstance(form, LQForm) else None
        self.iterative = feedback
        self.model = GameModel(game) if not feedback else None
        self.parameters = dict(game.problem.parameters)

    @cached_property
    def discrete_game(self) -> DiscreteGame:
        """The discrete game of iterative LQ games (a feedback game that is not LQ), its functions
        built on first use from the expressions parsed at compile."""
        from gamespec.games.iterative_lq import DiscreteGame

        assert self.expressions is not None, "a feedback game has its expressions"
        return DiscreteGame(self.game, self.expressions, self.game.game.iterative_lq == "second_order")

    def solve(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        """The game's Result, with the file's ``plot`` section in ``metrics["plot"]`` (what its
        figures draw: :mod:`gamespec.games.plotting`)."""
        result = self._solve(parameters, inputs)
        plot = self.game.plot.as_metrics() | {"path_constraints": []}
        return result.model_copy(update={"metrics": result.metrics | {"plot": plot}})

    def _solve(self, parameters: dict[str, float] | None, inputs: Inputs) -> Result:
        refuse_inputs(inputs, self.game.kind)
        if self.iterative:
            self.parameters |= parameters or {}
            if self.feedback is not None and isinstance(lq_game(self.feedback, self.parameters), LQGame):
                return feedback_equilibrium(self.game, self.feedback, self.parameters)
            from gamespec.games.iterative_lq import feedback_nash_nonlinear

            return feedback_nash_nonlinear(self.discrete_game, self.parameters)
        assert self.model is not None, "an open-loop game has its model"
        if parameters:
            self.model.parameters = {**self.model.parameters, **parameters}
        if self.game.receding_horizon is not None:
            from gamespec.games.receding_horizon import receding_horizon

            return receding_horizon(self.model)
        return open_loop(self.model)


class BestResponseBackend(Backend[DifferentialGameSpec, NoOptions]):
    """Best responses of the players of a ``differential_game``, each an ``optimal_control`` problem
    compiled once on casadi or pyomo."""

    name: ClassVar[str] = "best_response"
    kinds: ClassVar[frozenset[str]] = frozenset({"differential_game"})

    def unsupported(self, spec: SpecBase) -> str | None:
        """Refuses a game of degree (``time.final: free``): an open-loop strategy is a committed path,
        which a feedback pursuer always catches, and both players running straight is a stationary
        point of the open-loop game, so neither best responses nor the joint scheme can decide
        capture against escape (the homicidal chauffeur below Isaacs' barrier); its value function
        can (the ``hji`` backend). Refuses ``problem.avoid`` too, which only the ``hji`` backend reads."""
        reason = super().unsupported(spec)
        if reason or not isinstance(spec, DifferentialGameSpec):
            return reason
        if spec.problem.avoid is not None:
            return "problem.avoid (a reach-avoid game) is read by the hji backend only: use --backend hji"
        if not spec.problem.time.free:
            return None
        return (
            "time.final: free (a game of degree, the capture time as payoff) is decided by its value "
            "function: open-loop best responses and the joint scheme cannot tell capture from escape "
            "(a committed evader path is always caught); solve it with --backend hji"
        )

    def _compile(self, spec: DifferentialGameSpec, options: NoOptions) -> GameCompiled:
        return GameCompiled(spec)
