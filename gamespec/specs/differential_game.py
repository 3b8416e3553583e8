"""The ``differential_game`` kind: n players sharing dynamics, each with its own controls, payoff
sense, path constraints, beliefs and payoff modifications (section 7.1.1).

The payoff (eq. 7.1, a Mayer term over ``<state>_f`` plus a Lagrange integrand) is minimized by the
players whose ``objective`` is ``minimize`` and maximized by the others (zero-sum); a player with its
own ``payoff`` plays a non-zero-sum game. The dynamics (eq. 7.2) take the parameters; an
``uncertain`` parameter has a true value and what each player believes (section 7.1.1: the pursuer
knows ρ̂, the evader ρ̄). Each player's ``path_constraints`` are its own (eqs. 7.3–7.4); the
``terminal_constraints`` (eq. 7.5) bind every player's problem. Each player's ``transforms`` are
requested ``optimal_control`` transforms applied to its own best-response problem (the pursuer's RCS
regularizer of eq. 7.20), so the chain applies them, not the game.

The game is solved by best responses (:mod:`gamespec.games`): each player's problem is generated as
an ``optimal_control`` spec in which the other players' controls are grid inputs. ``method`` is that
spec's transcription (Radau collocation of degree 1 on N intervals of Δt is the discrete model of
eqs. 7.27–7.29 for dynamics that do not depend on the state), ``game`` the iteration, and an optional
``receding_horizon`` section runs Algorithm 4.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from gamespec.errors import ExpressionError, SpecError
from gamespec.specs.base import Number, ProblemParameters, RequestedTransforms, SpecBase, StrictModel, Value
from gamespec.specs.ocp import ControlSpec, MethodSpec, StateSpec
from gamespec.specs.uncertainty import UncertainParameter
from gamespec.symbolic.language import RESERVED, parse, parse_relation, symbol

INITIAL_PREFIX = "initial_"
"""A generated player problem takes the initial state ``<state>`` as the parameter ``initial_<state>``."""
START_TIME = "start_time"
"""The generated parameter holding the absolute time at which a player's problem starts."""
NOMINAL_PREFIX = "nominal_"
"""``nominal_<parameter>``: the value an uncertain parameter has in a generated player problem."""


def sensitivity_name(state: str, parameter: str) -> str:
    """``initial_S_<state>_<parameter>``: the predicted sensitivity of an unobserved state at the
    start of a player's problem."""
    return f"{INITIAL_PREFIX}S_{state}_{parameter}"


class PayoffSpec(StrictModel):
    """Eq. 7.1: ``mayer`` over ``<state>_f``, ``t_f`` and the parameters, plus the ``lagrange``
    integrand over states, every player's controls, ``t`` and the parameters."""

    mayer: Value = 0.0
    lagrange: Value = 0.0


class BelievedParameter(StrictModel):
    """A parameter some players do not know (eq. 7.2): its ``actual`` (true) value (what moves the true
    system) and each player's belief; a player not in ``beliefs`` knows the true value. An optional
    ``distribution`` about a player's belief (as chapter 6's ``problem.uncertain``) is passed to
    every player's problem, where the sensitivity transforms (``desensitize``, ``rcs``) read it."""

    actual: Number
    beliefs: dict[str, Number] = Field(default_factory=dict)
    distribution: UncertainParameter | None = None

    def belief(self, player: str) -> float:
        return self.beliefs.get(player, self.actual)


class PlayerSpec(StrictModel):
    """One player: its controls (bounds), whether it minimizes or maximizes the payoff, its own path
    constraints, optionally its own payoff (non-zero-sum) and requested transforms.

    What it knows (section 7.1.1): the states it ``observes`` (None: all; the others it predicts with
    its beliefs from their initial values, as the pursuer predicts the obstacle it cannot see),
    whether it ``knows_beliefs`` of the others (the evader knows the pursuer believes ρ̂; a player
    that does not models the others with its own beliefs) and whether it ``knows_transforms`` of the
    others (the evader does not know the pursuer's regularizer). ``start`` is its starting strategy
    (a number per control, held along the horizon).
    """

    objective: Literal["minimize", "maximize"]
    controls: dict[str, ControlSpec]
    path_constraints: list[str] = Field(default_factory=list)
    payoff: PayoffSpec | None = None
    transforms: RequestedTransforms = Field(default_factory=list)
    observes: list[str] | None = None
    knows_beliefs: bool = False
    knows_transforms: bool = False
    start: dict[str, Number] = Field(default_factory=dict)


class GameTime(StrictModel):
    """The fixed horizon of the game: ``final`` is a number or an expression of the parameters."""

    initial: Number = 0.0
    final: Value = 1.0


class GameProblem(StrictModel):
    """The mathematics of a differential game (section 7.1.1)."""

    parameters: dict[str, Number] = Field(default_factory=dict)
    uncertain: dict[str, BelievedParameter] = Field(default_factory=dict)
    states: dict[str, StateSpec]
    dynamics: dict[str, Value]
    players: dict[str, PlayerSpec]
    payoff: PayoffSpec = Field(default_factory=PayoffSpec)
    terminal_constraints: list[str] = Field(default_factory=list)
    time: GameTime = Field(default_factory=GameTime)

    @model_validator(mode="after")
    def _consistent(self) -> GameProblem:
        if len(self.players) < 2:
            raise ValueError("a game needs at least two players")
        controls = [c for p in self.players.values() for c in p.controls]
        generated = [f"{INITIAL_PREFIX}{s}" for s in self.states] + [START_TIME]
        generated += [f"{NOMINAL_PREFIX}{u}" for u in self.uncertain]
        generated += [sensitivity_name(s, u) for s in self.states for u in self.uncertain]
        names = [*self.parameters, *self.uncertain, *self.states, *controls, *generated]
        for name in names:
            if not name.isidentifier() or name in RESERVED or name == "tau":
                raise ValueError(f"{name!r} cannot be a symbol name (reserved or not an identifier)")
        clashes = sorted({n for n in names if names.count(n) > 1})
        if clashes:
            raise ValueError(f"names used twice (or clashing with generated ones): {', '.join(clashes)}")
        if set(self.dynamics) != set(self.states):
            raise ValueError("dynamics must give one equation per state")
        for name, player in self.players.items():
            self._check_player(name, player)
        for pname, parameter in self.uncertain.items():
            unknown = set(parameter.beliefs) - set(self.players)
            if unknown:
                raise SpecError(
                    f"names unknown players {sorted(unknown)}", field=f"problem.uncertain.{pname}.beliefs"
                )
        self._check_expressions()
        for name, player in self.players.items():
            _check_transforms(name, player)
        return self

    def _check_player(self, name: str, player: PlayerSpec) -> None:
        if not player.controls:
            raise ValueError(f"player {name!r} has no controls")
        unknown = set(player.observes or []) - set(self.states)
        if unknown:
            raise ValueError(f"players.{name}.observes names unknown states {sorted(unknown)}")
        unknown = set(player.start) - set(player.controls)
        if unknown:
            raise ValueError(f"players.{name}.start names controls it does not have: {sorted(unknown)}")

    def _check_expressions(self) -> None:
        params = {n: symbol(n) for n in [*self.parameters, *self.uncertain]}
        controls = {c: symbol(c) for p in self.players.values() for c in p.controls}
        running = params | controls | {n: symbol(n) for n in [*self.states, "t"]}
        ends = params | {f"{s}_f": symbol(f"{s}_f") for s in self.states} | {"t_f": symbol("t_f")}
        checks: list[tuple[str, Value, dict, bool]] = [
            (f"dynamics.{k}", v, running, False) for k, v in self.dynamics.items()
        ]
        payoffs = [("payoff", self.payoff)] + [
            (f"players.{n}.payoff", p.payoff) for n, p in self.players.items() if p.payoff is not None
        ]
        for field, payoff in payoffs:
            checks += [(f"{field}.mayer", payoff.mayer, ends, False)]
            checks += [(f"{field}.lagrange", payoff.lagrange, running, False)]
        for n, p in self.players.items():
            checks += [
                (f"players.{n}.path_constraints.{i}", c, running, True)
                for i, c in enumerate(p.path_constraints)
            ]
        checks += [
            (f"terminal_constraints.{i}", c, ends, True) for i, c in enumerate(self.terminal_constraints)
        ]
        checks += [("time.final", self.time.final, params, False)]
        for field, text, symbols, relation in checks:
            try:
                (parse_relation if relation else parse)(text, symbols)
            except ExpressionError as err:
                raise ValueError(f"{field}: {err}") from None


def _check_transforms(name: str, player: PlayerSpec) -> None:
    """Each of the player's transforms is a requested ``optimal_control`` transform with valid
    options (a SpecError naming ``problem.players.<name>.transforms.<i>`` otherwise)."""
    from gamespec.specs.requested import entry, transform_class, validated_options

    for index, item in enumerate(player.transforms):
        try:
            tname, options = entry(item, index)
            cls = transform_class(tname, field=f"transforms.{index}")
            if not cls.requested or cls.source_kind != "optimal_control":
                raise SpecError(
                    f"transform {tname!r} is not a requested optimal_control transform",
                    field=f"transforms.{index}",
                )
            validated_options(cls, tname, options, index)
        except SpecError as err:
            raise SpecError(err.reason, field=f"problem.players.{name}.{err.field}") from None


class GameSettings(StrictModel):
    """The best-response iteration (:mod:`gamespec.best_response`): Gauss–Seidel (Algorithm 4) or
    Jacobi, the tolerance on each player's change ‖[ǔ]_i − [ǔ]_{i−1}‖ (section 7.3.2), the
    iteration limit and the damping; or, with ``information: feedback``, the feedback (closed-loop)
    equilibrium of a linear-quadratic game by coupled Riccati equations
    (:mod:`gamespec.games.feedback_game`)."""

    information: Literal["open_loop", "feedback"] = Field(
        "open_loop",
        description="open_loop: each player's strategy is a control signal of time (best responses); "
        "feedback: a law of the state, the feedback Nash (saddle, zero-sum) equilibrium of a "
        "linear-quadratic game by coupled Riccati equations.",
    )
    scheme: Literal["gauss_seidel", "jacobi"] = "gauss_seidel"
    tolerance: float = Field(1e-6, gt=0)
    max_iterations: int = Field(100, ge=1)
    damping: float = Field(1.0, gt=0, le=1)
    backend: Literal["casadi", "pyomo"] = "casadi"
    """The OCP backend each player's best response is compiled on."""


class StopRule(StrictModel):
    """A condition on the true state that ends a receding-horizon run (``<=``/``>=`` relation)."""

    when: str


class ObstacleSpec(StrictModel):
    """A circular obstacle for reports and figures: centre (expressions of states and parameters) and
    radius; ``avoided_by`` maps a player to the pair of its position states, so the run reports that
    player's smallest distance to the obstacle's edge and whether it collided."""

    x: Value
    y: Value
    radius: Value
    avoided_by: dict[str, tuple[str, str]] = Field(default_factory=dict)


class RecedingHorizonSpec(StrictModel):
    """Algorithm 4: every ``step`` the games are solved over the ``method``'s horizon, each player's
    first control is applied and the true system (true parameter values) advances; the run stops
    at ``capture``, at a collision with the ``obstacle`` (when ``stop_at_collision``) or at
    ``time_limit``.

    ``horizon``: ``receding`` (N Δt ahead at every step, as the thesis) or ``shrinking`` (to the
    game's final time: the open-loop game re-solved from where the true system is).
    ``on_not_converged``: what a player applies when its game does not converge —
    ``last_iterate`` (the first control of the last iterate, the default) or ``previous_plan`` (the
    next control of the plan of the step before, from the last game that converged).
    """

    step: float = Field(gt=0)
    time_limit: float = Field(gt=0)
    capture: StopRule | None = None
    obstacle: ObstacleSpec | None = None
    stop_at_collision: bool = True
    horizon: Literal["receding", "shrinking"] = "receding"
    on_not_converged: Literal["last_iterate", "previous_plan"] = "last_iterate"
    positions: dict[str, tuple[str, str]] = Field(default_factory=dict)
    """Each player's position states, for the figures."""
    sensitivity_time: Literal["absolute", "relative"] = "absolute"
    """The sensitivity to the uncertain parameters a player's problem starts with, for a state the
    player predicts (does not observe): ``absolute`` — the sensitivity its prediction has
    accumulated since the start of the run (eq. 7.26 with t the absolute time; the prediction's
    first-order expansion of eq. 7.14 is the state's initial value, so ``S(t_k) = ∂x_k/∂ρ``), or
    ``relative`` — none (``S(t_k) = 0``: t counted from the step's start)."""


class DifferentialGameSpec(ProblemParameters, SpecBase):
    """A differential game (kind ``differential_game``); its runtime parameters are
    ``problem.parameters``."""

    kind: Literal["differential_game"] = "differential_game"
    problem: GameProblem
    method: MethodSpec = Field(default_factory=MethodSpec)
    game: GameSettings = Field(default_factory=GameSettings)
    receding_horizon: RecedingHorizonSpec | None = None

    default_backend = "best_response"

    @model_validator(mode="after")
    def _receding_names(self) -> DifferentialGameSpec:
        rh = self.receding_horizon
        if rh is None:
            return self
        if self.game.information == "feedback":
            raise ValueError("game.information: feedback solves the whole horizon; drop receding_horizon")
        players = self.problem.players
        states = set(self.problem.states)
        pairs = dict(rh.positions) | (dict(rh.obstacle.avoided_by) if rh.obstacle else {})
        for player, pair in pairs.items():
            if player not in players:
                raise ValueError(f"receding_horizon names unknown player {player!r}")
            if not set(pair) <= states:
                raise ValueError(f"receding_horizon: positions of {player!r} must be states, got {pair}")
        return self
