"""Open-loop equilibria of a ``differential_game`` by best responses on compiled OCP models.

:class:`GameModel` compiles every player's best-response problem of every game to solve
(:func:`~gamespec.games.problems.views`) ONCE through :func:`gamespec.solving.compile_spec`; a
:class:`BestResponder` re-solves its model with the opponents' latest controls as grid ``inputs``
(warm-started from its previous solution) and is a player of :func:`gamespec.best_response.iterate`
(Gauss–Seidel as Algorithm 4, or Jacobi). A strategy is the array of a player's controls at the
evaluation points (rows: its controls), compared in the Euclidean norm as in section 7.3.2.

Honest convergence. The engine's residual ``‖BR_p(s) − s_p‖`` is only as true as each response is
exact: a player's IPOPT that accepts its warm start (its KKT test passes at its own ``tol``) reads
as a zero change. Each player's NLP ``tol`` is therefore tied to the game's:
``min(configured tol, TOLERANCE_RATIO · game.tolerance)`` (not below ``SOLVER_TOL_FLOOR``).

What was found (:class:`Equilibrium`). From the returned point ``s`` (the engine's best iterate)
every player answers once more, ``b_p = J_p(BR_p(s_{-p}), s_{-p})``, and both ``b_p`` and its payoff
at ``s`` itself, ``J_p(s)``, are evaluated on its own transcription (:mod:`gamespec.games.evaluation`:
the collocation states of the controls, not IPOPT's states within its tolerance); the
improvement ``J_p(s) − b_p`` (minimizer) or ``b_p − J_p(s)`` (maximizer) is what a best response
gains, and the largest is the Nash gap (``metrics.saddle_gap``; for a zero-sum game the open-loop
saddle gap). ``b`` of a zero-sum game's minimizer and maximizer bracket its lower and upper values
(``metrics.value_bounds``). The Result's trajectory is the one of ``s`` (the collocation equations
solved for the returned controls), so states, controls and payoffs belong to one point.

``objective``: for a zero-sum game, the payoff ``J(s)`` every player shares (the game value at the
returned point); for a non-zero-sum game, where there is no single value, the payoff of the first
player the file lists, every player's being in ``metrics.payoffs``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from gamespec.best_response import BestResponseRun, Settings, VectorPlayer, iterate
from gamespec.errors import SpecError
from gamespec.games.evaluation import payoff_at, states_at
from gamespec.games.expressions import GameExpressions, game_expressions
from gamespec.games.lq_structure import LQForm, lq_form
from gamespec.games.problems import parameter_values, player_problem, views
from gamespec.games.simulate import Dynamics
from gamespec.loader import with_values
from gamespec.result import Result, Status
from gamespec.solving import Solver, compile_spec, get_backend
from gamespec.specs.differential_game import INITIAL_PREFIX, NOMINAL_PREFIX, START_TIME, DifferentialGameSpec
from gamespec.specs.ocp import OptimalControlSpec
from gamespec.transforms.base import with_parameter_values

if TYPE_CHECKING:
    from gamespec.games.joint import JointRun

STEP_VALUES = (INITIAL_PREFIX, START_TIME)
"""The prefixes of the runtime parameters each step of a run sets (the initial state, the
predicted sensitivities ``initial_S_...``, the start time)."""
TOLERANCE_RATIO = 1e-2
"""A player's NLP ``tol`` is at most this fraction of ``game.tolerance``: IPOPT's error in a response
(its KKT residual over the problem's curvature) then stays well inside the residual the game tests."""
SOLVER_TOL_FLOOR = 1e-14
"""The tightest NLP ``tol`` asked for (roundoff of IPOPT's own linear algebra lies near it)."""


def with_tied_tolerance(spec: OptimalControlSpec, tolerance: float) -> OptimalControlSpec:
    """``spec`` whose backend's ``tol`` is ``min(configured, TOLERANCE_RATIO · tolerance)``, floored at
    ``SOLVER_TOL_FLOOR`` (the configured one when it is tighter)."""
    backend = get_backend(spec.solver.backend or spec.default_backend)
    configured = float(backend.options(spec).tol)
    tol = min(configured, max(TOLERANCE_RATIO * tolerance, SOLVER_TOL_FLOOR))
    options = dict(spec.solver.options)
    options[backend.name] = {**options.get(backend.name, {}), "tol": tol}
    return spec.model_copy(update={"solver": spec.solver.model_copy(update={"options": options})})


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
    validated: dict[str, float] | None = None
    """The values other than the step's own (:data:`STEP_VALUES`) the spec was last validated with."""
    answered: tuple[OptimalControlSpec, dict[str, np.ndarray]] | None = None
    """The spec and grid inputs of the last response (what :meth:`response_at` compares)."""

    def set_values(self, values: Mapping[str, float]) -> None:
        """Runtime parameter values (the initial state, the start time, the game's parameters) for
        the next responses, re-solved on the same compiled model. They are validated as at load
        (the code path of ``--set``) when a value other than the step's own changes; the step's own
        (the initial state, the start time and the predicted sensitivities, which the run computes
        from the validated game) are set on the validated spec, checked to be finite numbers."""
        values = {n: float(v) for n, v in values.items()}
        steady = {n: v for n, v in values.items() if not n.startswith(STEP_VALUES)}
        if steady != self.validated:
            self.spec = with_values(self.solver.spec, values)
            self.validated = steady
            return
        for name, value in values.items():
            if not math.isfinite(value):
                raise SpecError(f"{value} is not a finite number", field=name, source=self.spec.source)
        self.spec = with_parameter_values(self.spec, values)

    def check_responses(self, on: bool) -> None:
        """Whether this player's responses carry the OCP solution checks (re-integration, constraint
        violation, control swings, Hamiltonian; :attr:`~gamespec.ocp.transcription.Transcription.checked`):
        a caller that reads none of them turns them off; a model whose mesh is refined keeps them
        (the refinement reads its defects)."""
        tr = getattr(self.solver.compiled, "tr", None)
        if tr is not None and tr.spec.method.refine is None:
            tr.checked = on

    def respond(self, others: Mapping[str, np.ndarray]) -> tuple[np.ndarray | None, Result]:
        inputs = self._inputs(others)
        result = self.solver.solve_spec(self.spec, inputs=inputs)
        self.solves += 1
        self.last, self.answered = result, (self.spec, inputs)
        return self._strategy(result), result

    def response_at(self, others: Mapping[str, np.ndarray]) -> tuple[np.ndarray | None, Result]:
        """The best response to ``others``: the last one when it answered exactly these strategies
        with the same values (the same problem: solving it again gives the same optimum within
        IPOPT's tolerance), else a new one (:meth:`respond`)."""
        inputs = self._inputs(others)
        if self.last is not None and self.answered is not None and self.answered[0] is self.spec:
            before = self.answered[1]
            same = before.keys() == inputs.keys()
            if same and all(np.array_equal(before[c], v) for c, v in inputs.items()):
                return self._strategy(self.last), self.last
        return self.respond(others)

    def _inputs(self, others: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        return {c: np.asarray(others[o])[row] for o, cs in self.opponents.items() for row, c in enumerate(cs)}

    def _strategy(self, result: Result) -> np.ndarray | None:
        return np.array([result.controls[c] for c in self.controls]) if result.ok else None

    @property
    def points(self) -> int:
        return len(self.solver.compiled.input_grid().tau)


@dataclass
class Equilibrium:
    """What the returned point ``s`` is (see module doc): each player's payoff ``J_p(s)``, its best
    response's value ``b_p`` and improvement, the largest improvement (``gap``), and the Result of
    ``s`` itself (``point``: its trajectory, every player's controls, ``objective`` as the module
    says); a value is None where it could not be computed, ``note`` says why."""

    concept: str
    payoffs: dict[str, float | None]
    best_values: dict[str, float | None]
    improvements: dict[str, float | None]
    point: Result | None
    note: str = ""

    @property
    def gap(self) -> float | None:
        values = list(self.improvements.values())
        return None if not values or any(v is None for v in values) else max(values)


@dataclass
class GameSolution:
    """One game's best-response run, each player's last Result and, when verified, what the
    returned point is (:class:`Equilibrium`; else the last responder's Result stands for it)."""

    view: str
    run: BestResponseRun | JointRun
    results: dict[str, Result]
    last_player: str
    equilibrium: Equilibrium | None = None

    @property
    def states(self) -> Result:
        """The Result of the returned point (its trajectory and every player's controls)."""
        if self.equilibrium is not None and self.equilibrium.point is not None:
            return self.equilibrium.point
        return self.results[self.last_player]

    def controls_of(self, player: str) -> dict[str, np.ndarray]:
        """``player``'s controls at the returned point (its last response's when not verified)."""
        if self.equilibrium is not None and self.equilibrium.point is not None:
            return self.equilibrium.point.controls
        return self.results[player].controls


@dataclass
class GameModel:
    """Every player's best-response problem of every game, compiled once (see module doc)."""

    game: DifferentialGameSpec
    responders: dict[tuple[str, str], BestResponder] = field(default_factory=dict)
    parameters: dict[str, float] = field(default_factory=dict)
    """The game's runtime parameter values (``problem.parameters``, updated by a re-solve)."""
    lq: LQForm | str = ""
    """The game's expressions for the Riccati existence test (:mod:`gamespec.games.existence`),
    parsed once, or why the test does not apply."""
    joint: dict = field(default_factory=dict)
    """Per game, the stacked KKT system of ``game.scheme: joint`` (:mod:`gamespec.games.joint`),
    built on first use."""
    expressions: GameExpressions | None = None
    """The game's expressions in SymPy (:mod:`gamespec.games.expressions`), parsed once here
    unless given (a receding horizon's shrinking models share their game's)."""

    def __post_init__(self) -> None:
        self.parameters = dict(self.game.problem.parameters) | self.parameters
        parsed = self.expressions = self.expressions or game_expressions(self.game)
        self.lq = lq_form(self.game, parsed)
        names = list(self.game.problem.players)
        for view in views(self.game, parsed):
            for player in names:
                problem = player_problem(self.game, player, view, parsed)
                spec = with_tied_tolerance(problem, self.game.game.tolerance)
                opponents = {o: list(self.game.problem.players[o].controls) for o in names if o != player}
                self.responders[(view, player)] = BestResponder(
                    player, view, compile_spec(spec), list(spec.problem.controls), opponents, spec
                )

    @property
    def views(self) -> list[str]:
        return list(dict.fromkeys(view for view, _ in self.responders))

    @cached_property
    def dynamics(self) -> Dynamics:
        """The game's dynamics compiled for the true system and the players' predictions
        (:mod:`gamespec.games.simulate`), built on first use."""
        assert self.expressions is not None, "a game model has its expressions"
        controls = [c for p in self.game.problem.players.values() for c in p.controls]
        return Dynamics(self.expressions, controls)

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
        """Iterate best responses of game ``view`` from ``state`` at ``time``; then one more best
        response per player at the returned point says what it is (see module doc)."""
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

        first = dict(start) if start is not None else self.start(view)
        if settings.scheme == "joint":
            from gamespec.games.joint import joint_run

            run = joint_run(self, view, order, first)
        else:
            run = iterate(
                [VectorPlayer(r.name, responder(r)) for r in order],
                first,
                Settings(settings.scheme, settings.tolerance, settings.max_iterations, settings.damping),
                payoff=lambda _: _objective(self.responders[(view, last[0])].last),
            )
        equilibrium = self._verify(order, run) if run.best is not None else None
        results = {r.name: r.last for r in order if r.last is not None}
        return GameSolution(view, run, results, last[0], equilibrium)

    def concept(self) -> str:
        """The solution concept the best responses seek: ``saddle`` (zero-sum, players of both
        senses), ``nash`` (one shared payoff, one sense: a team's person-by-person optimum) or
        ``open_loop_nash`` (players with payoffs of their own)."""
        players = self.game.problem.players.values()
        if any(p.payoff is not None for p in players):
            return "open_loop_nash"
        return "saddle" if len({p.objective for p in players}) > 1 else "nash"

    def _verify(self, order: list[BestResponder], run: BestResponseRun) -> Equilibrium:
        """Every player's payoff at the returned point and its best response's improvement there
        (none when a player's problem goes through transforms: its states and payoff are not the
        game's)."""
        point = run.strategies
        concept = self.concept() if run.converged else "none"
        if any(r.solver.steps or not hasattr(r.solver.compiled, "tr") for r in order):
            missing = dict.fromkeys((r.name for r in order), None)
            note = "a player's problem goes through transforms: no payoffs or gap at the returned point"
            return Equilibrium(concept, missing, dict(missing), dict(missing), None, note)
        responses = {r.name: r.response_at({o: point[o] for o in r.opponents})[1] for r in order}
        payoffs: dict[str, float | None] = {}
        best: dict[str, float | None] = {}
        improvements: dict[str, float | None] = {}
        trajectory: tuple[Result, np.ndarray] | None = None
        notes = []
        for r in order:
            result = responses[r.name]
            best[r.name] = self._response_value(r, result)
            states = self._states_at(r, result, point[r.name])
            if states is None:
                payoffs[r.name] = improvements[r.name] = None
                notes.append(f"{r.name}'s payoff at the returned point could not be evaluated")
                continue
            tr = r.solver.compiled.tr
            U = np.asarray(point[r.name], dtype=float)
            payoffs[r.name] = payoff_at(tr, result.parameters, states, U, _inputs(tr, result))
            trajectory = trajectory or (result, states)
            sense = 1.0 if self.game.problem.players[r.name].objective == "minimize" else -1.0
            b = best[r.name]
            improvements[r.name] = None if b is None else sense * (payoffs[r.name] - b)
        first = order[0].name
        return Equilibrium(
            concept=concept,
            payoffs=payoffs,
            best_values=best,
            improvements=improvements,
            point=self._point(trajectory, point, payoffs[first]) if trajectory else None,
            note="; ".join(notes),
        )

    def _response_value(self, r: BestResponder, result: Result) -> float | None:
        """The best response's payoff evaluated as the returned point's is (on the collocation
        states of its controls), so that the improvement compares like with like and not IPOPT's
        objective at states within its tolerance of the defects; IPOPT's when they are not met."""
        if not result.ok or result.objective is None:
            return None
        tr = r.solver.compiled.tr
        U = np.array([result.controls[c] for c in tr.ocp.controls])
        states = self._states_at(r, result, U)
        if states is None:
            return float(result.objective)
        return payoff_at(tr, result.parameters, states, U, _inputs(tr, result))

    @staticmethod
    def _states_at(r: BestResponder, result: Result, strategy: np.ndarray) -> np.ndarray | None:
        """The states of the returned point on ``r``'s model (None when its best response failed or
        the collocation equations were not met)."""
        if not result.ok:
            return None
        tr = r.solver.compiled.tr
        start = np.array([result.states[n] for n in tr.ocp.states])
        return states_at(tr, result.parameters, np.asarray(strategy, dtype=float), _inputs(tr, result), start)

    def _point(self, trajectory: tuple[Result, np.ndarray], point: dict, objective: float | None) -> Result:
        result, X = trajectory
        names = self.game.problem.players
        controls = {c: np.asarray(point[p])[row] for p in point for row, c in enumerate(names[p].controls)}
        states = {n: X[i] for i, n in enumerate(self.game.problem.states)}
        return result.model_copy(update={"states": states, "controls": controls, "objective": objective})


def _inputs(tr, result: Result) -> np.ndarray:
    """The grid inputs a response was solved with (n_w × evaluation points)."""
    rows = [np.asarray(result.arrays[f"input/{n}"], dtype=float) for n in tr.ocp.inputs]
    return np.array(rows) if rows else np.zeros((0, tr.grid.eval_tau.size))


def _objective(result: Result | None) -> float:
    return float(result.objective) if result is not None and result.objective is not None else float("nan")


def status_of(solutions: list[GameSolution]) -> Status:
    """The worst status among the games' runs (optimal < feasible < anything not ok)."""
    statuses = [s.run.status for s in solutions]
    bad = [s for s in statuses if not s.ok]
    if bad:
        return bad[0]
    return Status.FEASIBLE if Status.FEASIBLE in statuses else Status.OPTIMAL


@dataclass
class EquilibriumReport:
    """What the games of one solve found, for the Result: ``metrics`` (``solution_concept``,
    ``information``, ``payoffs``, ``saddle_gap``, ``value_bounds``; per game under ``equilibria``
    when each player solves its own), the ``saddle_gap`` check (value, verdict, tolerance in
    ``metrics.checks_passed`` and ``metrics.check_tolerances``) and a message when the gap exceeds
    the tolerance or could not be computed."""

    metrics: dict
    checks: dict[str, float | None]
    message: str


def _game_metrics(model: GameModel, e: Equilibrium) -> dict:
    out: dict = {
        "solution_concept": e.concept,
        "sought_concept": model.concept(),
        "information": "open_loop",
        "payoffs": e.payoffs,
        "best_response_values": e.best_values,
        "improvements": e.improvements,
        "saddle_gap": e.gap,
    }
    senses = {n: p.objective for n, p in model.game.problem.players.items()}
    if model.concept() == "saddle":
        lows = [e.best_values[n] for n, s in senses.items() if s == "minimize"]
        highs = [e.best_values[n] for n, s in senses.items() if s == "maximize"]
        if None not in lows + highs:
            out["value_bounds"] = {"lower": max(lows), "upper": min(highs)}
    return out


def equilibrium_report(model: GameModel, solutions: list[GameSolution]) -> EquilibriumReport:
    """The report of an open-loop solve's games (see :class:`EquilibriumReport`): each player's
    payoff is the one in the game it solves itself; the gap is the largest of the games'."""
    verified = [s for s in solutions if s.equilibrium is not None]
    if not verified:
        return EquilibriumReport({"solution_concept": "none", "sought_concept": model.concept()}, {}, "")
    games = {s.view: _game_metrics(model, s.equilibrium) for s in verified}
    own = {p: games.get(p, next(iter(games.values()))) for p in model.game.problem.players}
    gaps = [g["saddle_gap"] for g in games.values()]
    gap = None if None in gaps else max(gaps)
    first = next(iter(games.values()))
    metrics = {
        "solution_concept": first["solution_concept"],
        "sought_concept": first["sought_concept"],
        "information": "open_loop",
        "payoffs": {p: g["payoffs"].get(p) for p, g in own.items()},
        "saddle_gap": gap,
    }
    if len(games) == 1:
        metrics = first | metrics
    else:
        metrics["equilibria"] = games
    tolerance = model.game.game.tolerance
    notes = [s.equilibrium.note for s in verified if s.equilibrium.note]
    if gap is None:
        return EquilibriumReport(metrics, {}, "; ".join(notes or ["the saddle gap could not be computed"]))
    passed = bool(gap <= tolerance)
    metrics |= {"checks_passed": {"saddle_gap": passed}, "check_tolerances": {"saddle_gap": tolerance}}
    message = (
        ""
        if passed
        else (
            f"saddle gap {gap:.3g} exceeds the tolerance {tolerance:.3g}: a player gains that much by a "
            "best response at the returned point"
        )
    )
    return EquilibriumReport(metrics, {"saddle_gap": gap}, "; ".join([*notes, message] if message else notes))
