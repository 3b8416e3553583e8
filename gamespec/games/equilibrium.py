"""Open-loop equilibria of a ``differential_game`` by best responses on compiled OCP models.

:class:`GameModel` compiles every player's best-response problem of every game to solve
(:func:`~gamespec.games.problems.views`) ONCE through :func:`gamespec.solving.compile_spec`; a
:class:`BestResponder` re-solves its model with the opponents' latest controls as grid ``inputs``
(warm-started from its previous solution) and is a player of :func:`gamespec.best_response.iterate`
(Gauss–Seidel as Algorithm 4, or Jacobi). A strategy is the array of a player's controls at the
evaluation points (rows: its controls), compared in the Euclidean norm as in section 7.3.2.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from gamespec.best_response import BestResponseRun, Settings, VectorPlayer, iterate
from gamespec.games.problems import parameter_values, player_problem, views
from gamespec.loader import with_values
from gamespec.result import Result, Status
from gamespec.solving import Solver, compile_spec
from gamespec.specs.differential_game import INITIAL_PREFIX, NOMINAL_PREFIX, START_TIME, DifferentialGameSpec
from gamespec.specs.ocp import OptimalControlSpec


@dataclass
class BestResponder:
    """One player's compiled best-response problem in one game (see module doc)."""

    name: str
    view: str
    solver: Solver
    controls: list[str]
    opponents: dict[str, list[str]]
    spec: OptimalControlSpec
    solves: int = 0
    last: Result | None = None

    def set_values(self, values: Mapping[str, float]) -> None:
        """Runtime parameter values (the initial state, the start time, the game's parameters) for
        the next responses: validated once, re-solved on the same compiled model."""
        self.spec = with_values(self.solver.spec, dict(values))

    def respond(self, others: Mapping[str, np.ndarray]) -> tuple[np.ndarray | None, Result]:
        inputs = {c: others[o][row] for o, cs in self.opponents.items() for row, c in enumerate(cs)}
        result = self.solver.solve_spec(self.spec, inputs=inputs)
        self.solves += 1
        self.last = result
        if not result.ok:
            return None, result
        return np.array([result.controls[c] for c in self.controls]), result

    @property
    def points(self) -> int:
        return len(self.solver.compiled.input_grid().tau)


@dataclass
class GameSolution:
    """One game's best-response run and each player's last Result (the last responder's states are
    consistent with every player's final strategy)."""

    view: str
    run: BestResponseRun
    results: dict[str, Result]
    last_player: str

    @property
    def states(self) -> Result:
        return self.results[self.last_player]


@dataclass
class GameModel:
    """Every player's best-response problem of every game, compiled once (see module doc)."""

    game: DifferentialGameSpec
    responders: dict[tuple[str, str], BestResponder] = field(default_factory=dict)
    parameters: dict[str, float] = field(default_factory=dict)
    """The game's runtime parameter values (``problem.parameters``, updated by a re-solve)."""

    def __post_init__(self) -> None:
        self.parameters = dict(self.game.problem.parameters) | self.parameters
        names = list(self.game.problem.players)
        for view in views(self.game):
            for player in names:
                spec = player_problem(self.game, player, view)
                opponents = {o: list(self.game.problem.players[o].controls) for o in names if o != player}
                self.responders[(view, player)] = BestResponder(
                    player, view, compile_spec(spec), list(spec.problem.controls), opponents, spec
                )

    @property
    def views(self) -> list[str]:
        return list(dict.fromkeys(view for view, _ in self.responders))

    @property
    def builds(self) -> int:
        """How many models were compiled (each responder's once)."""
        return len(self.responders)

    def start(self, view: str) -> dict[str, np.ndarray]:
        """Each player's starting strategy: its ``start`` values held along the horizon."""
        out = {}
        for (v, name), r in self.responders.items():
            if v == view:
                start = self.game.problem.players[name].start
                out[name] = np.array([np.full(r.points, start.get(c, 0.0)) for c in r.controls])
        return out

    def values(
        self,
        view: str,
        player: str,
        state: Mapping[str, float],
        time: float,
        sensitivities: Mapping[str, float] | None = None,
    ) -> dict[str, float]:
        """The runtime parameters of ``player``'s problem in game ``view`` starting at ``state`` and
        absolute ``time``, with the predicted ``sensitivities`` (by generated parameter name)."""
        beliefs = parameter_values(self.game, player, view)
        return (
            dict(self.parameters)
            | beliefs
            | {f"{INITIAL_PREFIX}{s}": float(v) for s, v in state.items()}
            | {START_TIME: float(time)}
            | {f"{NOMINAL_PREFIX}{u}": v for u, v in beliefs.items()}
            | dict(sensitivities or {})
        )

    def solve(
        self,
        view: str,
        state: Mapping[str, float],
        time: float,
        start: Mapping[str, np.ndarray] | None = None,
        sensitivities: Mapping[str, float] | None = None,
    ) -> GameSolution:
        """Iterate best responses of game ``view`` from ``state`` at ``time`` (see module doc)."""
        settings = self.game.game
        order = [r for (v, _), r in self.responders.items() if v == view]
        for r in order:
            r.set_values(self.values(view, r.name, state, time, sensitivities))
        last: list[str] = [order[-1].name]

        def responder(r: BestResponder):
            def response(others):
                strategy, result = r.respond(others)
                last[0] = r.name
                return strategy, result

            return response

        players = [VectorPlayer(r.name, responder(r)) for r in order]
        run = iterate(
            players,
            dict(start) if start is not None else self.start(view),
            Settings(settings.scheme, settings.tolerance, settings.max_iterations, settings.damping),
            payoff=lambda _: _objective(self.responders[(view, last[0])].last),
        )
        results = {r.name: r.last for r in order if r.last is not None}
        return GameSolution(view, run, results, last[0])


def _objective(result: Result | None) -> float:
    return float(result.objective) if result is not None and result.objective is not None else float("nan")


def status_of(solutions: list[GameSolution]) -> Status:
    """The worst status among the games' runs (optimal < feasible < anything not ok)."""
    statuses = [s.run.status for s in solutions]
    bad = [s for s in statuses if not s.ok]
    if bad:
        return bad[0]
    return Status.FEASIBLE if Status.FEASIBLE in statuses else Status.OPTIMAL
