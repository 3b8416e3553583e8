"""The ``flow_field_game`` kind: pursuit-evasion of two agents in a stochastic flow field (chapter 5).

``problem`` gives the flow field of eq. 5.3 — the drift ``f(x)`` (two expressions of the position
names, e.g. eq. 5.37 or eq. 5.40) and the diffusion ``g(x)`` (a 2 × 2 matrix of expressions, or
``{identity: s}``) — both players' starts, speed limits and the bounds of eqs. 5.35–5.36
(``delta_x``, ``delta_u``, ``beta``), the nominal speed fraction ``v̂/v_max``, the capture radius ε,
the step ``T̂/N``, the payoff (``trace``: eq. 5.34; ``frobenius``: eq. 5.17) and the feedforward
(``free``: ``V`` within eq. 5.35; ``nominal``: ``V = Û``, the means on the nominal paths). Any
number may be an expression over ``parameters``; the flow's expressions may use the position names
as well. ``method`` sets the reachability grid, scheme and the levels read, the game's solution
concept (``lower_value``, the thesis' reading; ``minimax_mixed``, the robust value; or
``gauss_seidel``, Algorithm 3 as written) and its stopping rule, the evader's convex–concave
procedure and the Monte Carlo.

Validation at load evaluates every entry through the symbolic layer only (SymPy and
:func:`gamespec.symbolic.calculus.numeric_function` at a probe point) into
:class:`FlowGameValues`; the numerics build their objects from those values
(:func:`gamespec.flowfield.problem.evaluate`).

The chapter's two stages have specs of their own, which the staged transform
:mod:`gamespec.flowfield.transform` writes: ``flow_reachability`` (:class:`FlowReachabilitySpec`,
section 5.2: the game without its diffusion, solved for ``T̂``, ``x_f`` and the nominal paths; the
solving layer's upstream stage, not a kind of file) and the kind ``flow_covariance_game``
(:class:`FlowCovarianceGameSpec`, section 5.3: the chance-constrained covariance game about those
nominal paths, what ``gamespec show --transformed`` prints and a file may hold).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Literal

import numpy as np
import sympy as sp
from pydantic import Field, FiniteFloat, PositiveFloat, model_validator

from gamespec.errors import ExpressionError, SpecError
from gamespec.limits import MAX_EXTREMAL_VALUES, MAX_GRID_CELL_STEPS, MAX_SAMPLE_STEPS
from gamespec.registry import Kind
from gamespec.specs.base import ProblemParameters, SpecBase, StrictModel, Value
from gamespec.symbolic.calculus import jacobian, numeric_function
from gamespec.symbolic.language import RESERVED, parse, symbol

LEVEL_FRACTIONS = (0.06, 0.12)
"""The default levels read by the capture search, as fractions of the grid box's longer side."""


class Identity(StrictModel):
    """``scale · I₂``."""

    identity: Value = Field(1.0, description="The scale of the identity matrix (a number or an expression).")


class FlowSpec(StrictModel):
    """Drift ``f(x)`` (two expressions) and diffusion ``g(x)`` (2 × 2) of eq. 5.3."""

    drift: tuple[Value, Value] = Field(
        description="The drift f(x): two expressions of the position and the parameters."
    )
    diffusion: tuple[tuple[Value, Value], tuple[Value, Value]] | Identity = Field(
        Identity(identity=0.0),
        description="The diffusion g(x): a 2 × 2 matrix of expressions, or `{identity: scale}`.",
    )


class PlayerSpec(StrictModel):
    """One agent: start ``x₀ⁱ``, speed limit ``vⁱ_max`` (eq. 5.2) and the bounds of eqs. 5.35–5.36."""

    initial: tuple[Value, Value] = Field(description="The start x₀ (two numbers or expressions).")
    max_speed: Value = Field(description="The speed limit v_max (eq. 5.2).")
    delta_x: Value = Field(0.1, description="δ_x: distance of the mean from the nominal path (eq. 5.35a).")
    delta_u: Value = Field(
        description="δ_u: distance of the feedforward from the nominal control (eq. 5.35b)."
    )
    beta: Value = Field(0.01, description="β: the chance constraint's risk (eq. 5.36).")


class FlowGameProblem(StrictModel):
    """The mathematics of the game."""

    parameters: dict[str, FiniteFloat] = Field(
        default_factory=dict,
        description="Named numbers the expressions may use (runtime parameters: `--set`, `sweep --param`).",
    )
    position: tuple[str, str] = Field(
        ("x1", "x2"), description="The names of the two position coordinates the expressions use."
    )
    flow: FlowSpec = Field(description="The flow field: drift and diffusion (eq. 5.3).")
    pursuer: PlayerSpec = Field(description="The pursuer: start, speed limit and covariance bounds.")
    evader: PlayerSpec = Field(description="The evader: start, speed limit and covariance bounds.")
    nominal_speed_fraction: Value = Field(0.8, description="v̂/v_max of eq. 5.24, 5.26.")
    capture_radius: Value = Field(description="ε of eq. 5.4.")
    step: Value = Field(description="T̂/N of eq. 5.7; N = round(T̂/step).")
    payoff: Literal["trace", "frobenius"] = Field(
        "trace",
        description="The payoff: `trace` of eq. 5.34, or `frobenius` (squared Frobenius norm, eq. 5.17).",
    )
    feedforward: Literal["nominal", "free"] = Field(
        "free",
        description="free: each player's V moves within eq. 5.35; nominal: V = Û, the means stay on the "
        "nominal paths (section 5.3: the mean is driven by the nominal controls).",
    )

    @model_validator(mode="after")
    def _names(self) -> FlowGameProblem:
        names = [*self.position, *self.parameters]
        for name in names:
            if not name.isidentifier() or name in RESERVED:
                raise ValueError(f"{name!r} cannot be a name (reserved or not an identifier)")
        if len(set(names)) != len(names):
            raise ValueError("the position names and parameter names must all differ")
        return self


class GridSpec(StrictModel):
    """The reachability grid: the box and the number of nodes per axis."""

    lower: tuple[FiniteFloat, FiniteFloat] = Field(description="The box's lower corner.")
    upper: tuple[FiniteFloat, FiniteFloat] = Field(description="The box's upper corner.")
    nodes: tuple[int, int] = Field((101, 101), description="Grid nodes per axis.")

    @model_validator(mode="after")
    def _box(self) -> GridSpec:
        if any(lo >= hi for lo, hi in zip(self.lower, self.upper, strict=True)):
            raise ValueError("each lower bound must be below its upper bound")
        if any(n < 11 or n > 2001 for n in self.nodes):
            raise ValueError("nodes must lie in [11, 2001] per axis")
        return self


class GameMethod(StrictModel):
    """The solution concept of the covariance game and its iteration's stopping rule
    ``max(‖ΔV‖, ‖ΔK‖) ≤ tolerance`` (ε_v = ε_k, section 5.4); :mod:`gamespec.flowfield.concepts`."""

    scheme: Literal["lower_value", "minimax_mixed", "gauss_seidel"] = Field(
        "lower_value",
        description="lower_value (the thesis' reading, Algorithm 3 and Fig. 5.2): the evader commits to "
        "its gains and the pursuer's feedback answers them, v₋ = max_e min_p J; minimax_mixed: the "
        "robust value v₊ = min_p max_e J, the pursuer's security strategy against the evader's mixed "
        "strategy (what a worst-case evader achieves); gauss_seidel: Algorithm 3 as written, which "
        "converges only to a pure saddle point (this game has none when the pursuer can copy the "
        "evader's gains). Every scheme also reports the other closed-loop figure, both values and "
        "the saddle gap v₊ − v₋.",
    )
    gap: float = Field(
        1e-3,
        gt=0,
        description="Relative tolerance of the values: minimax_mixed counts an evader answer as new when "
        "it raises J above the pursuer's restricted value t by more than gap·t, and stops when "
        "J(p, BR_e(p)) ≤ (1 + gap) t; lower_value stops when a step of the evader's commitment raises "
        "min_p J by at most gap; a saddle gap v₊ − v₋ ≤ gap·v₊ is a pure saddle point.",
    )
    tolerance: float = Field(5e-3, gt=0, description="ε_v = ε_k of the iteration's stopping rule.")
    max_iterations: int = Field(30, ge=1, le=1000, description="Iteration limit of the best responses.")


class ConvexConcaveMethod(StrictModel):
    """The evader's convex–concave procedure: stop when ``J`` rises by less than ``tolerance · J``."""

    tolerance: float = Field(
        1e-6, gt=0, description="Stop when the payoff J rises by less than tolerance · J."
    )
    max_iterations: int = Field(
        500, ge=1, le=10_000, description="Iteration limit of the evader's convex–concave procedure."
    )


class MonteCarloMethod(StrictModel):
    """Euler–Maruyama samples of the nonlinear SDE (0 to skip), ``substeps`` per control step."""

    samples: int = Field(
        20_000, ge=0, le=1_000_000, description="Number of sample paths (0 skips the Monte Carlo)."
    )
    seed: int = Field(0, ge=0, description="Seed of the random generator (a non-negative integer).")
    substeps: int = Field(5, ge=1, le=100, description="Euler–Maruyama steps per control step.")


class ExtremalMethod(StrictModel):
    """Extremal shooting: initial directions and the RK4 step."""

    directions: int = Field(
        720, ge=16, le=20_000, description="Number of initial directions the extremals are shot from."
    )
    step: float = Field(2e-3, gt=0, description="The RK4 step of the extremals.")


class FlowGameMethod(StrictModel):
    """Reachability (grid, scheme, CFL, levels), the game's iterations and the Monte Carlo."""

    grid: GridSpec = Field(description="The reachability grid.")
    scheme: Literal["weno5", "eno2", "first_order"] = Field(
        "weno5",
        description="The spatial scheme of the level-set equation 5.22: `weno5`, `eno2` or `first_order`.",
    )
    cfl: float = Field(0.5, gt=0, le=1, description="The CFL number of the level-set time steps.")
    max_time: float = Field(
        20.0,
        gt=0,
        description="The longest time the reachable sets are grown to before giving up on capture.",
    )
    levels: tuple[PositiveFloat, PositiveFloat] | None = Field(
        None,
        description="The two levels c₁ < c₂ the capture search reads, as lengths (the sets reached from "
        "the disks of radius c about the starts; T̂ and x_f are extrapolated to c = 0): fixed under grid "
        "refinement, and clear of the smeared edge of φ's flat zero region (on linear_flow.yaml at dx = "
        "0.2 the level 4 cells out was 5e-4 off in T̂, 6 cells out 5e-5). Default: 6 % and 12 % of the "
        "box's longer side (6 and 12 cells of a 101-node axis).",
    )
    extremals: ExtremalMethod = Field(
        default_factory=ExtremalMethod,
        description="The extremal shooting (the grid-free cross-check of the capture time).",
    )
    game: GameMethod = Field(
        default_factory=GameMethod,
        description="The solution concept and the best-response iteration of the covariance game.",
    )
    convex_concave: ConvexConcaveMethod = Field(
        default_factory=ConvexConcaveMethod, description="The evader's convex–concave procedure."
    )
    monte_carlo: MonteCarloMethod = Field(
        default_factory=MonteCarloMethod,
        description="The Monte Carlo of the nonlinear SDE with the feedback applied.",
    )

    @model_validator(mode="after")
    def _levels(self) -> FlowGameMethod:
        if self.levels is not None and not self.levels[0] < self.levels[1]:
            raise ValueError("levels must be two increasing positive lengths")
        return self

    @property
    def read_levels(self) -> tuple[float, float]:
        """``levels``, or its default from the box (fixed under refinement of ``grid.nodes``)."""
        if self.levels is not None:
            return self.levels
        side = max(hi - lo for lo, hi in zip(self.grid.lower, self.grid.upper, strict=True))
        return (LEVEL_FRACTIONS[0] * side, LEVEL_FRACTIONS[1] * side)

    def check_work(self, max_speed: float, step: float) -> None:
        """The work the method implies, before anything runs (README, "Limits"): the level sets'
        cells times their fewest time steps (``max_time`` over the CFL step ``cfl·dx/max_speed`` at
        the fastest agent's speed, the flow only shortening it) within
        :data:`~gamespec.limits.MAX_GRID_CELL_STEPS`; the extremals' directions times RK4 steps
        within :data:`~gamespec.limits.MAX_EXTREMAL_VALUES`; the Monte Carlo's samples times its
        steps (``substeps`` per control step ``step`` over ``max_time``) within
        :data:`~gamespec.limits.MAX_SAMPLE_STEPS`. A SpecError naming the field otherwise."""
        nx, ny = self.grid.nodes
        spacing = min(
            (hi - lo) / (n - 1)
            for lo, hi, n in zip(self.grid.lower, self.grid.upper, self.grid.nodes, strict=True)
        )
        cells = nx * ny
        steps = self.max_time * max_speed / (self.cfl * spacing)
        if cells * steps > MAX_GRID_CELL_STEPS:
            raise SpecError(
                f"{cells} cells times at least {steps:.3g} CFL steps (max_time · max_speed / (cfl · dx)) "
                f"exceed the limit of {MAX_GRID_CELL_STEPS:g} cell steps",
                field="method.grid.nodes",
            )
        extremal = self.extremals.directions * self.max_time / self.extremals.step
        if extremal > MAX_EXTREMAL_VALUES:
            raise SpecError(
                f"{extremal:.3g} front points (directions · max_time / step) exceed the limit of "
                f"{MAX_EXTREMAL_VALUES:g}",
                field="method.extremals.step",
            )
        mc = self.monte_carlo
        sampled = mc.samples * mc.substeps * self.max_time / step
        if sampled > MAX_SAMPLE_STEPS:
            raise SpecError(
                f"{sampled:.3g} sample steps (samples · substeps · max_time / step) exceed the limit of "
                f"{MAX_SAMPLE_STEPS:g}",
                field="method.monte_carlo.samples",
            )


class FlowGameSpec(ProblemParameters, SpecBase):
    """Two agents in a stochastic flow field: reachability, nominal paths, covariance game (ch. 5);
    its runtime parameters are ``problem.parameters`` (``gamespec sweep --param alpha=…``)."""

    kind: Literal["flow_field_game"] = Field(
        "flow_field_game", description="The problem kind; selects the schema of the rest of the file."
    )
    problem: FlowGameProblem = Field(description="The flow field, the players and the payoff.")
    method: FlowGameMethod = Field(
        description="Reachability grid and scheme, the game's iteration and the Monte Carlo."
    )

    @property
    def objective_sense(self) -> str:
        """``saddle``: the objective is the game's value, which the pursuer minimizes and the
        evader maximizes."""
        return "saddle"

    @model_validator(mode="after")
    def _evaluates(self) -> FlowGameSpec:
        self.values()
        return self

    def values(self, parameters: Mapping[str, float] | None = None) -> FlowGameValues:
        """The evaluated game for the file's parameter values, updated by ``parameters``; the
        numerics build their objects from it (:func:`gamespec.flowfield.problem.evaluate`)."""
        unknown = set(parameters or {}) - set(self.problem.parameters)
        if unknown:
            raise SpecError(f"unknown parameter(s) {sorted(unknown)}", field="problem.parameters")
        return _Evaluator(self, {**self.problem.parameters, **(parameters or {})}).values()


class FlowReachabilitySpec(FlowGameSpec):
    """The reachability stage of a ``flow_field_game`` (section 5.2): the same file with its
    diffusion removed ("we ignore the disturbance term", the flow is the drift alone) and no Monte
    Carlo; a reachability backend (``levelset``, ``extremals``, ``hj_reachability``) solves it for
    ``T̂``, ``x_f`` (Theorem 6) and the nominal paths (eqs. 5.23–5.26). Written by
    :func:`gamespec.flowfield.stages.reachability_spec` for the solving layer (not registered as a
    kind of file); the game's fields it keeps are unused."""

    kind: Literal["flow_reachability"] = "flow_reachability"  # type: ignore[assignment]

    @property
    def default_backend(self) -> str:
        """``levelset``: a stage spec has no :class:`~gamespec.registry.Kind` entry of its own."""
        return "levelset"


class NominalPath(StrictModel):
    """One agent's nominal path (eqs. 5.23–5.26) at the nodes ``nominal.times``: the positions
    ``x̂`` and the unit directions ``n`` of the nominal control ``û = v̂ n``."""

    positions: list[tuple[FiniteFloat, FiniteFloat]] = Field(
        min_length=2, description="The nominal positions x̂, one per node."
    )
    directions: list[tuple[FiniteFloat, FiniteFloat]] = Field(
        min_length=2, description="The unit directions n of the nominal control û = v̂ n, one per node."
    )


class NominalSpec(StrictModel):
    """Both agents' nominal paths from the reachability stage, ``0 = t_0 < … < t_M = T̂``, and their
    nominal speeds ``v̂`` (eq. 5.24, 5.26)."""

    times: list[FiniteFloat] = Field(min_length=2, description="The nodes 0 = t_0 < … < t_M = T̂.")
    speeds: tuple[PositiveFloat, PositiveFloat] = Field(
        description="The nominal speeds v̂ of pursuer and evader."
    )
    pursuer: NominalPath = Field(description="The pursuer's nominal path.")
    evader: NominalPath = Field(description="The evader's nominal path.")
    wall_time: float = Field(
        0.0,
        ge=0,
        description="Wall seconds the reachability stage took: the covariance game may take what is left "
        "of the backend's max_wall_time.",
    )

    @model_validator(mode="after")
    def _nodes(self) -> NominalSpec:
        times = np.asarray(self.times)
        if times[0] != 0 or np.any(np.diff(times) <= 0):
            raise ValueError("times must increase from 0")
        for path in (self.pursuer, self.evader):
            if not len(path.positions) == len(path.directions) == len(times):
                raise ValueError("each path needs one position and one direction per time")
        return self


class CovarianceGameProblem(StrictModel):
    """The covariance game of section 5.3 about the nominal paths: the flow and players of the
    ``flow_field_game`` it came from, the number of steps ``N`` and the nominal paths (both None
    when the reachability stage found no capture: there is no game to play)."""

    parameters: dict[str, FiniteFloat] = Field(
        default_factory=dict, description="Named numbers the expressions may use (runtime parameters)."
    )
    position: tuple[str, str] = Field(
        ("x1", "x2"), description="The names of the two position coordinates the expressions use."
    )
    flow: FlowSpec = Field(description="The flow field: drift and diffusion (eq. 5.3).")
    pursuer: PlayerSpec = Field(description="The pursuer: start, speed limit and covariance bounds.")
    evader: PlayerSpec = Field(description="The evader: start, speed limit and covariance bounds.")
    capture_radius: Value = Field(description="ε of eq. 5.4.")
    payoff: Literal["trace", "frobenius"] = Field(
        "trace",
        description="The payoff: `trace` of eq. 5.34, or `frobenius` (squared Frobenius norm, eq. 5.17).",
    )
    feedforward: Literal["nominal", "free"] = Field(
        "free",
        description="The feedforward: `nominal` (the nominal path's) or `free` (a decision of the game).",
    )
    steps: int | None = Field(description="N of eq. 5.7, round(T̂ / step) of the flow_field_game.", ge=1)
    nominal: NominalSpec | None = Field(description="The paths of eq. 5.5's linearization.")

    @model_validator(mode="after")
    def _game(self) -> CovarianceGameProblem:
        if (self.steps is None) != (self.nominal is None):
            raise ValueError("steps and nominal are given together (or neither: no capture)")
        return self


class CovarianceGameMethod(StrictModel):
    """The game's solution concept and iteration, the evader's procedure and the Monte Carlo (as in
    ``flow_field_game``'s ``method``)."""

    game: GameMethod = Field(
        default_factory=GameMethod, description="The solution concept and the best-response iteration."
    )
    convex_concave: ConvexConcaveMethod = Field(
        default_factory=ConvexConcaveMethod, description="The evader's convex–concave procedure."
    )
    monte_carlo: MonteCarloMethod = Field(
        default_factory=MonteCarloMethod,
        description="The Monte Carlo of the nonlinear SDE with the feedback applied.",
    )


class FlowCovarianceGameSpec(ProblemParameters, SpecBase):
    """The chance-constrained covariance game of section 5.3 (eqs. 5.27–5.36) about given nominal
    paths: the backend linearizes the flow along them (eqs. 5.5–5.8), lifts the model (eq. 5.10)
    and solves the game; what :mod:`gamespec.flowfield.transform` makes of a ``flow_field_game``
    once its reachability stage is solved. Its runtime parameters are the flow game's."""

    kind: Literal["flow_covariance_game"] = Field(
        "flow_covariance_game", description="The problem kind; selects the schema of the rest of the file."
    )
    problem: CovarianceGameProblem = Field(description="The covariance game about the nominal paths.")
    method: CovarianceGameMethod = Field(
        default_factory=CovarianceGameMethod,
        description="The game's solution concept, iteration and Monte Carlo.",
    )

    @property
    def objective_sense(self) -> str:
        """``saddle``, as the ``flow_field_game``'s."""
        return "saddle"

    def structure(self, with_guess: bool = False) -> dict[str, Any]:
        """:meth:`SpecBase.structure` without ``problem.nominal.wall_time``: the reachability
        stage's time is a record of one run (a re-solve of a compiled chain keeps the compile's,
        the covariance game's time limit erring on the short side), not what the game is."""
        data = super().structure(with_guess)
        if data["problem"]["nominal"] is not None:
            data["problem"]["nominal"]["wall_time"] = None
        return data

    @model_validator(mode="after")
    def _evaluates(self) -> FlowCovarianceGameSpec:
        self.values()
        mc = self.method.monte_carlo
        sampled = mc.samples * mc.substeps * (self.problem.steps or 0)
        if sampled > MAX_SAMPLE_STEPS:
            raise SpecError(
                f"{sampled:.3g} sample steps (samples · substeps · steps) exceed the limit of "
                f"{MAX_SAMPLE_STEPS:g}",
                field="method.monte_carlo.samples",
            )
        return self

    def values(self, parameters: Mapping[str, float] | None = None) -> CovarianceGameValues:
        """The evaluated flow, players and capture radius for the file's parameter values updated
        by ``parameters`` (:func:`gamespec.flowfield.problem.evaluate_game` builds on it)."""
        unknown = set(parameters or {}) - set(self.problem.parameters)
        if unknown:
            raise SpecError(f"unknown parameter(s) {sorted(unknown)}", field="problem.parameters")
        evaluator = _Evaluator(self, {**self.problem.parameters, **(parameters or {})})
        drift, diffusion = evaluator.flow()
        return CovarianceGameValues(
            position=evaluator.position,
            drift=drift,
            diffusion=diffusion,
            players=(evaluator.player("pursuer"), evaluator.player("evader")),
            capture_radius=evaluator.number(self.problem.capture_radius, "capture_radius", positive=True),
        )


@dataclass(frozen=True)
class PlayerValues:
    """One agent's evaluated start, speed limit and bounds (eqs. 5.2, 5.35–5.36)."""

    initial: tuple[float, float]
    max_speed: float
    delta_x: float
    delta_u: float
    beta: float


@dataclass(frozen=True)
class FlowGameValues:
    """Every entry of a flow-field game evaluated: the drift (2 × 1) and diffusion (2 × 2) as SymPy
    matrices of the ``position`` symbols only, numbers for the rest, and the grid's box."""

    position: tuple[sp.Symbol, sp.Symbol]
    drift: sp.Matrix
    diffusion: sp.Matrix
    players: tuple[PlayerValues, PlayerValues]
    speed_fraction: float
    capture_radius: float
    step: float
    payoff: str
    feedforward: str
    grid_lower: tuple[float, float]
    grid_upper: tuple[float, float]
    grid_nodes: tuple[int, int]


@dataclass(frozen=True)
class CovarianceGameValues:
    """A covariance game's flow (SymPy matrices of the ``position`` symbols), players and ε."""

    position: tuple[sp.Symbol, sp.Symbol]
    drift: sp.Matrix
    diffusion: sp.Matrix
    players: tuple[PlayerValues, PlayerValues]
    capture_radius: float


@lru_cache(maxsize=4096, typed=True)
def _parsed(value: Value, names: tuple[str, ...]) -> sp.Expr:
    """``value`` in SymPy over the symbols ``names``, parsed once per process (at load, where the
    spec's validator evaluates it): a solve substitutes new parameter values into the same
    expression and parses no text again (issue 27, item 3)."""
    return sp.sympify(parse(value, {name: symbol(name) for name in names}))


class _Evaluator:
    """Substitutes the parameter values into every entry, each parsed once (:func:`_parsed`)."""

    def __init__(self, spec: FlowGameSpec | FlowCovarianceGameSpec, values: Mapping[str, float]) -> None:
        self.spec = spec
        self.position = tuple(symbol(n) for n in spec.problem.position)
        self.symbols = {name: symbol(name) for name in values}
        self.substitution = {symbol(name): sp.Float(v) for name, v in values.items()}

    def expression(self, value: Value, field: str, position: bool) -> sp.Expr:
        names = [*self.symbols, *(self.spec.problem.position if position else ())]
        try:
            return _parsed(value, tuple(dict.fromkeys(names))).xreplace(self.substitution)
        except ExpressionError as err:
            raise SpecError(str(err), field=f"problem.{field}") from None

    def number(self, value: Value, field: str, positive: bool = False) -> float:
        expr = self.expression(value, field, position=False)
        try:
            result = complex(expr)
        except (TypeError, ValueError):
            raise SpecError(f"{value!r} does not evaluate to a number", field=f"problem.{field}") from None
        if result.imag != 0 or not np.isfinite(result.real) or (positive and result.real <= 0):
            need = "a positive number" if positive else "a finite real number"
            raise SpecError(f"{value!r} evaluates to {result.real:g}; need {need}", field=f"problem.{field}")
        return result.real

    def player(self, name: str) -> PlayerValues:
        p: PlayerSpec = getattr(self.spec.problem, name)
        beta = self.number(p.beta, f"{name}.beta", positive=True)
        if beta >= 1:
            raise SpecError("β must lie in (0, 1)", field=f"problem.{name}.beta")
        return PlayerValues(
            initial=tuple(self.number(v, f"{name}.initial.{i}") for i, v in enumerate(p.initial)),
            max_speed=self.number(p.max_speed, f"{name}.max_speed", positive=True),
            delta_x=self.number(p.delta_x, f"{name}.delta_x", positive=True),
            delta_u=self.number(p.delta_u, f"{name}.delta_u", positive=True),
            beta=beta,
        )

    def flow(self) -> tuple[sp.Matrix, sp.Matrix]:
        """Drift and diffusion, checked to evaluate (with the drift's Jacobian) at a probe point."""
        flow = self.spec.problem.flow
        drift = sp.Matrix([self.expression(v, f"flow.drift.{i}", True) for i, v in enumerate(flow.drift)])
        if isinstance(flow.diffusion, Identity):
            diffusion = sp.eye(2) * self.expression(flow.diffusion.identity, "flow.diffusion.identity", True)
        else:
            diffusion = sp.Matrix(
                [
                    [self.expression(v, f"flow.diffusion.{i}.{j}", True) for j, v in enumerate(row)]
                    for i, row in enumerate(flow.diffusion)
                ]
            )
        for label, exprs in (
            ("drift", list(drift)),
            ("diffusion", list(diffusion)),
            ("drift", list(jacobian(drift, self.position))),
        ):
            try:
                numeric_function(exprs, self.position)(np.zeros(1), np.zeros(1))
            except ExpressionError as err:
                raise SpecError(str(err), field=f"problem.flow.{label}") from None
        return drift, diffusion

    def values(self) -> FlowGameValues:
        p, m = self.spec.problem, self.spec.method
        pursuer, evader = self.player("pursuer"), self.player("evader")
        fraction = self.number(p.nominal_speed_fraction, "nominal_speed_fraction", positive=True)
        if fraction > 1:
            raise SpecError("v̂/v_max must not exceed 1 (eq. 5.24)", field="problem.nominal_speed_fraction")
        if pursuer.max_speed <= evader.max_speed:
            raise SpecError(
                "the pursuer must be faster than the evader (section 5.1)", field="problem.pursuer.max_speed"
            )
        origins = np.array([pursuer.initial, evader.initial])
        if not np.all((origins >= m.grid.lower) & (origins <= m.grid.upper)):
            raise SpecError("both starting points must lie inside the grid", field="method.grid")
        drift, diffusion = self.flow()
        step = self.number(p.step, "step", positive=True)
        m.check_work(max(pursuer.max_speed, evader.max_speed), step)
        return FlowGameValues(
            position=self.position,
            drift=drift,
            diffusion=diffusion,
            players=(pursuer, evader),
            speed_fraction=fraction,
            capture_radius=self.number(p.capture_radius, "capture_radius", positive=True),
            step=step,
            payoff=p.payoff,
            feedforward=p.feedforward,
            grid_lower=m.grid.lower,
            grid_upper=m.grid.upper,
            grid_nodes=m.grid.nodes,
        )


KIND = Kind(
    FlowGameSpec,
    default_backend="levelset",
    plot="gamespec.flowfield.plotting:plot",
    summary="gamespec.flowfield.report:flow_game_summary",
    metrics="gamespec.flowfield.metrics:FlowGameMetrics",
    columns=(
        "metrics.capture_time",
        "metrics.capture_probability_open_loop",
        "metrics.capture_probability_closed_loop",
        "metrics.monte_carlo_capture_probability.open_loop.estimate",
        "metrics.monte_carlo_capture_probability.closed_loop.estimate",
        "metrics.solution_concept",
        "metrics.saddle_gap",
    ),
)
"""The ``FlowGameSpec`` kind as one plugin (:class:`~gamespec.registry.Kind`)."""

COVARIANCE_GAME_KIND = Kind(
    FlowCovarianceGameSpec,
    default_backend="levelset",
    plot="gamespec.plotting:plot_trajectories",
    summary="gamespec.flowfield.report:flow_game_summary",
)
"""The ``FlowCovarianceGameSpec`` kind (what the staged lowering writes): its trajectories, and the rows
of the flow game's summary its metrics hold."""
