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

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar, Literal

from pydantic import Field, PrivateAttr, model_validator

from gamespec.errors import ExpressionError, SpecError
from gamespec.limits import MAX_BEST_RESPONSES, MAX_GAME_STATE, MAX_RECEDING_STEPS
from gamespec.registry import Kind
from gamespec.specs.base import Number, ProblemParameters, RequestedTransforms, SpecBase, StrictModel, Value
from gamespec.specs.ocp import ControlSpec, FreeOrFixed, MethodSpec, StateSpec, _ordered, is_time_varying
from gamespec.specs.plot import PlotHint
from gamespec.specs.uncertainty import UncertainParameter
from gamespec.symbolic.canonical import check
from gamespec.symbolic.grammar import RESERVED, numeric_value

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


@dataclass(frozen=True)
class GameValues:
    """What :meth:`GameProblem.evaluate` gives: the initial state x_0 of eq. 7.2 (a free value at 0)
    and the horizon ``t_f - t_0`` (with a free final time: its upper bound less ``t_0``)."""

    initial: dict[str, float]
    horizon: float


def checked_expression(
    text: float | str, names: list[str], values: Mapping[str, float], field: str, constraint: bool = False
) -> float | None:
    """Check ``text`` over ``names`` and the parameters' ``values`` (numbers;
    :func:`~gamespec.symbolic.canonical.check`); its value when it uses no name, else None. A
    SpecError naming ``field`` when it is outside the language, or it is undefined, not real or out
    of range there (:func:`~gamespec.symbolic.canonical.check`)."""
    try:
        check(text, names, values, constraint=constraint)
        return None if constraint or names else numeric_value(text, values)
    except ExpressionError as err:
        raise SpecError(str(err), field=field) from None


class PayoffSpec(StrictModel):
    """Eq. 7.1: ``mayer`` over ``<state>_f``, ``t_f`` and the parameters, plus the ``lagrange``
    integrand over states, every player's controls, ``t`` and the parameters."""

    mayer: Value = Field(0.0, description="The terminal payoff over `<state>_f`, `t_f` and the parameters.")
    lagrange: Value = Field(
        0.0, description="The running payoff over states, every player's controls, t and the parameters."
    )


class BelievedParameter(StrictModel):
    """A parameter some players do not know (eq. 7.2): its ``actual`` (true) value (what moves the true
    system) and each player's belief; a player not in ``beliefs`` knows the true value. An optional
    ``distribution`` about a player's belief (as chapter 6's ``problem.uncertain``) is passed to
    every player's problem, where the sensitivity transforms (``desensitize``, ``rcs``) read it."""

    actual: Number = Field(description="The true value: what moves the true system.")
    beliefs: dict[str, Number] = Field(
        default_factory=dict,
        description="Each player's belief, by player; a player not listed knows the true value.",
    )
    distribution: UncertainParameter | None = Field(
        None,
        description="A distribution about a belief, read by the sensitivity transforms (desensitize, rcs).",
    )

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

    objective: Literal["minimize", "maximize"] = Field(
        description="Whether the player minimizes or maximizes the payoff."
    )
    controls: dict[str, ControlSpec] = Field(description="The player's controls, with their bounds.")
    path_constraints: list[str] = Field(
        default_factory=list, description="The player's own path constraints (eqs. 7.3–7.4)."
    )
    payoff: PayoffSpec | None = Field(
        None, description="The player's own payoff (a non-zero-sum game); omitted: the game's."
    )
    transforms: RequestedTransforms = Field(
        default_factory=list,
        description="Requested transforms of the player's own problem, [{name: {options}}] (rcs: eq. 7.20)",
    )
    observes: list[str] | None = Field(
        None,
        description="The states the player observes (omitted: all); the others it predicts with its beliefs.",
    )
    knows_beliefs: bool = Field(
        False, description="Whether the player knows the others' beliefs (else it models them with its own)."
    )
    knows_transforms: bool = Field(
        False, description="Whether the player knows the others' requested transforms (their regularizers)."
    )
    start: dict[str, Number] = Field(
        default_factory=dict,
        description="The starting strategy: a number per control, held along the horizon.",
    )


class GameTime(FreeOrFixed):
    """The horizon of the game: ``final`` is a number or an expression of the parameters (a fixed
    horizon), or ``free`` within ``bounds`` (a game of degree, Isaacs: it ends at capture, the
    ``problem.capture`` set reached, and its payoff is the capture time ``t_f``, minimized by the
    pursuers and maximized by the evaders; the upper bound is the longest game considered)."""

    initial: Number = Field(0.0, description="The initial time.")
    final: Value | Literal["free"] = Field(
        1.0,
        description="The final time (a number or an expression of the parameters), or free: the game "
        "ends at capture (problem.capture) and its payoff is the capture time t_f.",
    )

    fixed_field: ClassVar[str] = "final"
    what: ClassVar[str] = "final time"


class GameProblem(StrictModel):
    """The mathematics of a differential game (section 7.1.1)."""

    parameters: dict[str, Number] = Field(
        default_factory=dict, description="Named numbers the expressions may use (runtime parameters)."
    )
    uncertain: dict[str, BelievedParameter] = Field(
        default_factory=dict,
        description="Parameters some players do not know, with each player's belief (eq. 7.2).",
    )
    states: dict[str, StateSpec] = Field(
        description="The shared states, with bounds and initial and final values."
    )
    dynamics: dict[str, Value] = Field(
        description="Each state's ODE right-hand side: states, every player's controls, t, parameters."
    )
    players: dict[str, PlayerSpec] = Field(description="The players, by name.")
    payoff: PayoffSpec = Field(default_factory=PayoffSpec, description="The zero-sum payoff (eq. 7.1).")
    terminal_constraints: list[str] = Field(
        default_factory=list, description="Relations over the final state (eq. 7.5)."
    )
    time: GameTime = Field(default_factory=GameTime, description="The horizon.")
    capture: str | None = Field(
        None,
        description="The target set of a game of kind (capture), a relation over the states and "
        "parameters such as 'x**2 + y**2 <= l**2': the minimizing players reach it, the maximizing "
        "ones avoid it (read by the hji backend; the best-response schemes ignore it). With "
        "time.final: free, the terminal condition that ends the game.",
    )
    avoid: str | None = Field(
        None,
        description="A set the minimizing players must not enter on their way to the capture set, a "
        "relation over the states and parameters such as '(x - 1)**2 + y**2 <= 0.25' (reach-avoid, "
        "as hj_reachability: a state that enters it is lost for them; read by the hji backend).",
    )

    _values: GameValues = PrivateAttr()

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
            _check_transforms(name, player, self)
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

    def value_sets(self, parameters: Mapping[str, float] | None = None) -> list[dict[str, float]]:
        """The parameter values some problem of the game is built with: ``parameters`` (else the
        file's) with the uncertain ones at their true values, then at each player's beliefs."""
        given = parameters or {}
        base = {n: float(given.get(n, v)) for n, v in self.parameters.items()}
        holders = [None, *self.players]
        sets = [
            base | {n: u.actual if h is None else u.belief(h) for n, u in self.uncertain.items()}
            for h in holders
        ]
        return [dict(v) for v in {tuple(v.items()): v for v in sets}.values()]

    def _check_expressions(self) -> None:
        """Every expression over the names its field may use, at each of :meth:`value_sets`: the
        parameters are numbers there, so what is undefined, not real or out of range at the file's
        values (``sqrt(-w2)``, ``exp(ve)*exp(ve)``) is refused here, never at solve time."""
        controls = [c for p in self.players.values() for c in p.controls]
        running = [*self.states, *controls, "t"]
        ends = [*(f"{s}_f" for s in self.states), "t_f"]
        checks: list[tuple[str, Value, list[str], bool]] = [
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
        for field in ("capture", "avoid"):
            relation = getattr(self, field)
            if relation is not None:
                checks += [(field, relation, list(self.states), True)]
        if self.time.free:
            self._check_degree()
        for values in self.value_sets():
            for field, text, names, constraint in checks:
                checked_expression(text, names, values, f"problem.{field}", constraint)
        self._values = self.evaluate()

    def _check_degree(self) -> None:
        """A game of degree (``time.final: free``) ends at ``capture`` and pays the capture time: it
        needs ``problem.capture``, and its payoff is ``t_f`` (the default payoff, or ``mayer: t_f``
        with no Lagrange term); a player's own payoff is refused."""
        if self.capture is None:
            raise SpecError(
                "a free final time ends at capture: give problem.capture (e.g. x**2 + y**2 <= l**2)",
                field="problem.time.final",
            )
        own = [n for n, p in self.players.items() if p.payoff is not None]
        if own:
            raise SpecError(
                "a game of degree pays the capture time to every player (zero-sum)",
                field=f"problem.players.{own[0]}.payoff",
            )
        if self.payoff.mayer not in (0.0, "t_f") or self.payoff.lagrange != 0.0:
            raise SpecError(
                "with time.final: free the payoff is the capture time: leave payoff out or write mayer: t_f",
                field="problem.payoff",
            )

    @property
    def values(self) -> GameValues:
        """:meth:`evaluate` at the file's parameter values, computed once at load."""
        return self._values

    def evaluate(self, parameters: Mapping[str, float] | None = None) -> GameValues:
        """The numbers the file's values stand for at ``parameters`` (else the file's), checked at
        each of :meth:`value_sets`: every state's and control's bounds (ordered), the initial and
        final values (within the bounds and :data:`~gamespec.limits.MAX_GAME_STATE`; a free
        initial value starts at 0) and the horizon; a SpecError naming the field otherwise. Their
        values at the true parameters are returned."""
        found = [self._evaluated(values) for values in self.value_sets(parameters)]
        return found[0]

    def _evaluated(self, values: Mapping[str, float]) -> GameValues:
        def number(raw: float | str | None, default: float, field: str) -> float:
            if raw is not None and default in (-math.inf, math.inf) and is_time_varying(raw):
                checked_expression(raw, ["t"], values, f"problem.{field}")
                return default
            if raw is None:
                return default
            value = checked_expression(raw, [], values, f"problem.{field}")
            if default == 0.0 and not abs(value) <= MAX_GAME_STATE:
                raise SpecError(f"{value:g} is beyond {MAX_GAME_STATE:g} in size", field=f"problem.{field}")
            return value

        initial = {}
        for name, st in self.states.items():
            lo = number(st.lower, -math.inf, f"states.{name}.lower")
            hi = number(st.upper, math.inf, f"states.{name}.upper")
            _ordered(lo, hi, f"states.{name}")
            for key in ("initial", "final"):
                raw = getattr(st, key)
                value = None if raw is None else number(raw, 0.0, f"states.{name}.{key}")
                if value is not None and not lo <= value <= hi:
                    raise SpecError(
                        f"{value:g} lies outside [{lo:g}, {hi:g}]", field=f"problem.states.{name}.{key}"
                    )
                if key == "initial":
                    initial[name] = 0.0 if value is None else value
        for player, p in self.players.items():
            for name, c in p.controls.items():
                lo = number(c.lower, -math.inf, f"players.{player}.controls.{name}.lower")
                hi = number(c.upper, math.inf, f"players.{player}.controls.{name}.upper")
                _ordered(lo, hi, f"players.{player}.controls.{name}")
        if self.time.bounds is not None:
            found = [
                checked_expression(b, [], values, f"problem.time.bounds.{i}")
                for i, b in enumerate(self.time.bounds)
            ]
            lower, upper = (math.nan if v is None else v for v in found)
            if not self.time.initial <= lower < upper:
                raise SpecError(
                    "the bounds on a free final time are ordered and not before the initial time",
                    field="problem.time.bounds",
                )
            return GameValues(initial, upper - self.time.initial)
        final = checked_expression(self.time.final, [], values, "problem.time.final")
        if not final > self.time.initial:
            raise SpecError("the final time must be after the initial time", field="problem.time.final")
        return GameValues(initial, final - self.time.initial)


def _check_transforms(name: str, player: PlayerSpec, problem: GameProblem) -> None:
    """Each of the player's transforms is a requested ``optimal_control`` transform with valid
    options, their expressions checked at each of the game's parameter values
    (:meth:`GameProblem.value_sets`); a SpecError naming ``problem.players.<name>.transforms.<i>``
    otherwise."""
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
            checked = validated_options(cls, tname, options, index)
            if hasattr(checked, "check_against"):
                running = [*problem.states, *(c for p in problem.players.values() for c in p.controls), "t"]
                for values in problem.value_sets():
                    checked.check_against(values, running, f"transforms.{index}.{tname}")
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
        "linear-quadratic game by coupled Riccati equations, of another game by iterative LQ games.",
    )
    scheme: Literal["gauss_seidel", "jacobi", "joint"] = Field(
        "gauss_seidel",
        description="gauss_seidel (Algorithm 4) or jacobi: best responses; joint: every player's "
        "first-order conditions stacked and solved as one system (gamespec.games.joint; casadi only), "
        "its point verified by one best response per player.",
    )
    iterative_lq: Literal["second_order", "gauss_newton"] = Field(
        "second_order",
        description="information: feedback on a nonlinear game (iterative LQ games, "
        "gamespec.games.iterative_lq): second_order adds each player's value gradient times the "
        "dynamics' Hessian to its LQ game (needed where a control enters its owner's cost only through "
        "the dynamics); gauss_newton is iLQGames' own linearization.",
    )
    tolerance: float = Field(
        1e-6, gt=0, description="Stop when every player's change between iterations is below this."
    )
    max_iterations: int = Field(100, ge=1, description="Iteration limit of the best responses.")
    damping: float = Field(1.0, gt=0, le=1, description="Damping of the best-response update (1: none).")
    backend: Literal["casadi", "pyomo"] = Field(
        "casadi", description="The OCP backend that solves each best response."
    )
    """The OCP backend each player's best response is compiled on."""

    @model_validator(mode="after")
    def _joint_on_casadi(self) -> GameSettings:
        if self.scheme == "joint" and self.backend != "casadi":
            raise ValueError("scheme: joint stacks the players' CasADi transcriptions: use backend: casadi")
        return self


class StopRule(StrictModel):
    """A condition on the true state that ends a receding-horizon run (``<=``/``>=`` relation)."""

    when: str = Field(description="A relation (`<=`/`>=`) over the true state and the parameters.")


class ObstacleSpec(StrictModel):
    """A circular obstacle for reports and figures: centre (expressions of states and parameters) and
    radius; ``avoided_by`` maps a player to the pair of its position states, so the run reports that
    player's smallest distance to the obstacle's edge and whether it collided."""

    x: Value = Field(description="The centre's x: an expression of states and parameters.")
    y: Value = Field(description="The centre's y: an expression of states and parameters.")
    radius: Value = Field(description="The obstacle's radius.")
    avoided_by: dict[str, tuple[str, str]] = Field(
        default_factory=dict,
        description="Per player, the pair of its position states (its distance to the obstacle, collision).",
    )


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

    step: float = Field(
        gt=0, description="Time between re-solves: the first controls are applied for this long."
    )
    time_limit: float = Field(gt=0, description="The run's last time (the game's time, not wall-clock).")
    max_wall_time: Number | None = Field(
        None,
        gt=0,
        description="Seconds of wall time after which the run stops at the end of a step, with the "
        "status time_limit and what it has so far (none: no limit).",
    )
    capture: StopRule | None = Field(None, description="The capture condition that ends the run.")
    obstacle: ObstacleSpec | None = Field(
        None, description="The obstacle reported on and drawn (distances, collisions)."
    )
    stop_at_collision: bool = Field(True, description="Whether a collision with the obstacle ends the run.")
    horizon: Literal["receding", "shrinking"] = Field(
        "receding",
        description="`receding` (N Δt ahead at every step) or `shrinking` (to the game's final time).",
    )
    on_not_converged: Literal["last_iterate", "previous_plan"] = Field(
        "last_iterate",
        description="What a player applies when its game fails: `last_iterate` or `previous_plan`.",
    )
    positions: dict[str, tuple[str, str]] = Field(
        default_factory=dict,
        description="Per player, the pair of its position states (the figures draw its path).",
    )
    """Each player's position states, for the figures."""
    sensitivity_time: Literal["absolute", "relative"] = Field(
        "absolute",
        description="The t of eq. 7.26: `absolute` (from the run's start) or `relative` (the step's).",
    )
    """The sensitivity to the uncertain parameters a player's problem starts with, for a state the
    player predicts (does not observe): ``absolute`` — the sensitivity its prediction has
    accumulated since the start of the run (eq. 7.26 with t the absolute time; the prediction's
    first-order expansion of eq. 7.14 is the state's initial value, so ``S(t_k) = ∂x_k/∂ρ``), or
    ``relative`` — none (``S(t_k) = 0``: t counted from the step's start)."""


class DifferentialGameSpec(ProblemParameters, SpecBase):
    """A differential game (kind ``differential_game``); its runtime parameters are
    ``problem.parameters``."""

    kind: Literal["differential_game"] = Field(
        "differential_game", description="The problem kind; selects the schema of the rest of the file."
    )
    problem: GameProblem = Field(description="The mathematics: states, dynamics, players, payoff, horizon.")
    method: MethodSpec = Field(
        default_factory=MethodSpec,
        description="The collocation of each player's problem (Radau degree 1 is eqs. 7.27–7.29).",
    )
    game: GameSettings = Field(
        default_factory=GameSettings, description="The best-response iteration (or the feedback equilibrium)."
    )
    receding_horizon: RecedingHorizonSpec | None = Field(
        None,
        description="Run Algorithm 4 (receding horizon on the true system); omitted: one open-loop game.",
    )
    plot: PlotHint = Field(
        default_factory=PlotHint, description="Figure hints: planar position pairs, angles, units."
    )

    @model_validator(mode="after")
    def _plot_names(self) -> DifferentialGameSpec:
        controls = [c for p in self.problem.players.values() for c in p.controls]
        self.plot.check_names(list(self.problem.states), controls)
        return self

    @model_validator(mode="after")
    def _receding_horizon(self) -> DifferentialGameSpec:
        """The receding-horizon section against the problem: names of players and states, its
        expressions at the parameters' values, a step of whole collocation intervals and the work
        it implies (:data:`~gamespec.limits.MAX_RECEDING_STEPS`,
        :data:`~gamespec.limits.MAX_BEST_RESPONSES`)."""
        rh = self.receding_horizon
        if rh is None:
            return self
        if self.game.information == "feedback":
            raise ValueError("game.information: feedback solves the whole horizon; drop receding_horizon")
        players = self.problem.players
        steps = 1
        if rh is not None:
            self._check_receding(rh)
            steps = math.ceil(rh.time_limit / rh.step - 1e-9)
            if steps > MAX_RECEDING_STEPS:
                raise SpecError(
                    f"time_limit / step = {steps} steps is more than {MAX_RECEDING_STEPS}",
                    field="receding_horizon.step",
                )
        solves = steps * len(players) ** 2 * self.game.max_iterations
        if solves > MAX_BEST_RESPONSES:
            raise SpecError(
                f"up to {solves} best responses (steps x players^2 x max_iterations) is more than "
                f"{MAX_BEST_RESPONSES}",
                field="game.max_iterations",
            )
        return self

    def _check_receding(self, rh: RecedingHorizonSpec) -> None:
        players = self.problem.players
        states = list(self.problem.states)
        groups = [("positions", rh.positions)]
        if rh.obstacle is not None:
            groups.append(("obstacle.avoided_by", rh.obstacle.avoided_by))
        for group, pairs in groups:
            for player, pair in pairs.items():
                field = f"receding_horizon.{group}.{player}"
                if player not in players:
                    raise SpecError(f"names unknown player {player!r}", field=field)
                unknown = [n for n in pair if n not in states]
                if unknown:
                    raise SpecError(f"{', '.join(map(repr, unknown))} is not a state", field=field)
        checks = [("capture.when", rh.capture.when, True)] if rh.capture else []
        if rh.obstacle is not None:
            checks += [(f"obstacle.{k}", getattr(rh.obstacle, k), False) for k in ("x", "y", "radius")]
        for values in self.problem.value_sets():
            for field, text, constraint in checks:
                checked_expression(text, states, values, f"receding_horizon.{field}", constraint)
        intervals_per_step(rh.step, self.problem.values.horizon, self.method.intervals)


def intervals_per_step(step: float, horizon: float, intervals: int) -> int:
    """How many collocation intervals (``horizon / intervals`` long) a receding-horizon ``step``
    spans; a SpecError naming ``receding_horizon.step`` when it is not a whole number of them."""
    interval = horizon / intervals
    per_step = step / interval
    if abs(per_step - round(per_step)) > 1e-9 or round(per_step) < 1:
        raise SpecError(
            f"the step ({step:g}) must be a whole number of collocation intervals "
            f"(horizon / intervals = {interval:g})",
            field="receding_horizon.step",
        )
    return round(per_step)


KIND = Kind(
    DifferentialGameSpec,
    default_backend="best_response",
    plot="gamespec.games.plotting:plot_game",
    summary="gamespec.games.report:game_summary",
    metrics="gamespec.games.metrics:GameMetrics",
    columns=(
        "metrics.solution_concept",
        "metrics.saddle_gap",
        "metrics.captured",
        "metrics.capture_time",
    ),
)
"""The ``DifferentialGameSpec`` kind as one plugin (:class:`~gamespec.registry.Kind`)."""
