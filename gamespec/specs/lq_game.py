"""The ``lq_stochastic_game`` kind: the discrete-time LQ stochastic game of eq. 4.1 (chapter 4).

A file gives the model either in discrete form (``A, B, C, D``, each constant or ``per_step``) or as
a continuous model (``A, B, C`` and the noise input) discretized with step ``step`` by a zero-order
hold (eq. 4.70); the weights ``Q, R, S`` (eq. 4.4, constant or per step); the initial Gaussian; and
optionally the controller's terminal mean and covariance (eq. 4.11). A ``null`` entry of the
terminal mean leaves that component free. A terminal covariance makes the file require the
``covariance_constraint`` feature (the constrained covariance game, eq. 4.62), which only backends
that solve that SDP declare. Every matrix entry is a number or an expression over
``parameters``; a matrix is a list of rows, ``{diag: [...]}`` or ``{identity: scale}`` (square:
n × n for ``A, B, C, D``, ``Q`` and the covariances, m × m for ``R``, ℓ × ℓ for ``S``).
:meth:`LQGameSpec.game` evaluates all of it into an :class:`~gamespec.specs.lq_model.LQGame`.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Discriminator, Field, Tag, field_validator, model_validator

from gamespec.best_response import Settings
from gamespec.errors import ExpressionError, SpecError
from gamespec.limits import MAX_INTERVALS, MAX_LQ_ENTRY, MAX_SAMPLE_VALUES, MAX_SAMPLES
from gamespec.registry import Kind
from gamespec.specs.base import Number, ProblemParameters, SpecBase, StrictModel, Value
from gamespec.specs.lq_model import LQGame, zero_order_hold
from gamespec.symbolic.grammar import RESERVED, numeric_value


class Diagonal(StrictModel):
    """A diagonal matrix."""

    diag: list[Value] = Field(min_length=1, description="The diagonal entries.")


class Identity(StrictModel):
    """``scale · I`` of the size the slot needs."""

    identity: Value = Field(1.0, description="The scale of the identity matrix.")


_KEYS = {"diag": "matrix-diag", "identity": "matrix-identity", "per_step": "matrix-per-step"}


def _form(value: Any) -> str | None:
    """Which form a matrix is written in (a list of rows, or the key of its mapping or model), so a
    bad entry's error names that form's field rather than every member of the union (the tags hold
    a ``-``, which the loader leaves out of locations)."""
    if isinstance(value, list):
        return "matrix-rows"
    keys = value if isinstance(value, dict) else getattr(type(value), "model_fields", {})
    return next((tag for key, tag in _KEYS.items() if key in keys), None)


_MATRIX_FORM = Discriminator(
    _form,
    custom_error_type="matrix_form",
    custom_error_message="a matrix is a list of rows, {diag: [...]}, {identity: scale} or {per_step: [...]}",
)
_Rows = Annotated[list[list[Value]], Tag("matrix-rows")]
_Diagonal = Annotated[Diagonal, Tag("matrix-diag")]
_Identity = Annotated[Identity, Tag("matrix-identity")]

MatrixValue = Annotated[_Rows | _Diagonal | _Identity, _MATRIX_FORM]


class PerStep(StrictModel):
    """One matrix per step k = 0 … N−1."""

    per_step: list[MatrixValue] = Field(min_length=1, description="One matrix per step k = 0 … N−1.")


_PerStep = Annotated[PerStep, Tag("matrix-per-step")]

StepMatrix = Annotated[_Rows | _Diagonal | _Identity | _PerStep, _MATRIX_FORM]


class DiscreteModel(StrictModel):
    """``x_{k+1} = A_k x_k + B_k u_k + C_k v_k + D_k w_k`` (eq. 4.1)."""

    A: StepMatrix = Field(description="The state matrices A_k.")
    B: StepMatrix = Field(description="The controller's input matrices B_k.")
    C: StepMatrix = Field(description="The stopper's input matrices C_k.")
    D: StepMatrix = Field(description="The noise matrices D_k.")


class ContinuousModel(StrictModel):
    """``ẋ = A x + B u + C v + noise · w`` held constant over each ``step`` (eq. 4.68–4.70)."""

    A: MatrixValue = Field(description="The state matrix A.")
    B: MatrixValue = Field(description="The controller's input matrix B.")
    C: MatrixValue = Field(description="The stopper's input matrix C.")
    noise: MatrixValue = Field(description="The noise matrix.")
    step: Value = Field(description="The sampling step the model is held constant over.")


class CostWeights(StrictModel):
    """Weights of the payoff eq. 4.4: state ``Q``, controller ``R`` and stopper ``S``."""

    Q: StepMatrix = Field(description="The state weight Q.")
    R: StepMatrix = Field(description="The controller's weight R.")
    S: StepMatrix = Field(description="The stopper's weight S.")


class InitialDistribution(StrictModel):
    """``x_0 ~ N(mean, covariance)``."""

    mean: list[Value] = Field(min_length=1, description="The initial mean.")
    covariance: MatrixValue = Field(description="The initial covariance.")


class TerminalTarget(StrictModel):
    """The controller's terminal target ``x_N ~ N(mean, covariance)`` (eq. 4.11); each part optional."""

    mean: list[Value | None] | None = Field(
        None, description="The target mean (None entries are free); omitted: none."
    )
    covariance: MatrixValue | None = Field(
        None, description="The target covariance (the relaxed constraint of eqs. 4.61–4.62); omitted: none."
    )


class LQGameProblem(StrictModel):
    """The mathematics of the game."""

    parameters: dict[str, Number] = Field(
        default_factory=dict, description="Named numbers the expressions may use (runtime parameters)."
    )
    horizon: int = Field(ge=1, le=MAX_INTERVALS, description="Number of steps N.")
    states: list[str] | None = Field(None, description="State names (default x1, x2, ...).")
    discrete: DiscreteModel | None = Field(
        None, description="A discrete-time model (eq. 4.1; give this or `continuous`)."
    )
    continuous: ContinuousModel | None = Field(
        None, description="A continuous-time model, sampled (give this or `discrete`)."
    )
    cost: CostWeights = Field(description="The payoff's weights (eq. 4.4).")
    initial: InitialDistribution = Field(description="The initial distribution.")
    terminal: TerminalTarget = Field(
        default_factory=TerminalTarget, description="The controller's terminal target (eq. 4.11)."
    )

    @field_validator("states")
    @classmethod
    def _distinct_states(cls, states: list[str] | None) -> list[str] | None:
        repeated = sorted(name for name, count in Counter(states or []).items() if count > 1)
        if repeated:
            raise ValueError(f"state names must be distinct; repeated: {', '.join(repeated)}")
        return states

    @model_validator(mode="after")
    def _one_model(self) -> LQGameProblem:
        if (self.discrete is None) == (self.continuous is None):
            raise ValueError("give exactly one of 'discrete' and 'continuous'")
        for name in self.parameters:
            if not name.isidentifier() or name in RESERVED:
                raise ValueError(f"{name!r} cannot be a parameter name (reserved or not an identifier)")
        if self.states is not None and len(self.states) != len(self.initial.mean):
            raise SpecError(
                f"expected {len(self.states)} entries (one per name in problem.states), "
                f"got {len(self.initial.mean)}",
                field="problem.initial.mean",
            )
        return self


class MonteCarloSpec(StrictModel):
    """Closed-loop samples drawn after the solve (0 to skip)."""

    samples: int = Field(
        100, ge=0, le=MAX_SAMPLES, description="Number of closed-loop samples (0 skips the check)."
    )
    seed: int = Field(0, ge=0, description="Seed of the random generator (a non-negative integer).")


class LQMethodSpec(StrictModel):
    """The best-response iteration of the covariance game (Algorithm 2: scheme, stopping rule,
    damping, acceleration; :mod:`gamespec.best_response`) and the Monte Carlo check."""

    tolerance: Number = Field(1e-5, gt=0, description="Bound on ε_k and ε_ℓ (section 4.5).")
    max_iterations: int = Field(100, ge=1, description="Iteration limit of the best responses.")
    scheme: Literal["jacobi", "gauss_seidel"] = Field(
        "jacobi", description="jacobi (Algorithm 2) or gauss_seidel (the controller answers L_{i+1})."
    )
    damping: float = Field(
        1.0, gt=0, le=1, description="Weight w of a new response: K_{i+1} = (1 − w) K_i + w BR (1: none)."
    )
    acceleration: Literal["none", "anderson"] = Field(
        "none",
        description="anderson: each sweep answers Anderson's extrapolation from the last `memory` sweeps "
        "(same best responses, same stopping rule; converges where the plain scheme spirals outwards).",
    )
    memory: int = Field(5, ge=1, description="Sweeps Anderson's extrapolation uses.")
    monte_carlo: MonteCarloSpec = Field(
        default_factory=MonteCarloSpec, description="The closed-loop Monte Carlo check."
    )

    def settings(self) -> Settings:
        """The best-response engine's settings of this method."""
        return Settings(
            scheme=self.scheme,
            tolerance=self.tolerance,
            max_iterations=self.max_iterations,
            damping=self.damping,
            acceleration=self.acceleration,
            memory=self.memory,
        )


class LQGameSpec(ProblemParameters, SpecBase):
    """An LQ stochastic game with one-sided terminal mean/covariance constraints (chapter 4)."""

    kind: Literal["lq_stochastic_game"] = Field(
        "lq_stochastic_game", description="The problem kind; selects the schema of the rest of the file."
    )
    problem: LQGameProblem = Field(
        description="The model, the payoff, the initial distribution and the target."
    )
    method: LQMethodSpec = Field(
        default_factory=LQMethodSpec, description="The best-response iteration and the Monte Carlo check."
    )

    @model_validator(mode="after")
    def _evaluates(self) -> LQGameSpec:
        self.game()
        return self

    @model_validator(mode="after")
    def _samples_fit(self) -> LQGameSpec:
        """Monte Carlo samples times (horizon + 1) times states within
        :data:`~gamespec.limits.MAX_SAMPLE_VALUES` (the memory the sampled trajectories take)."""
        values = self.method.monte_carlo.samples * (self.problem.horizon + 1) * len(self.problem.initial.mean)
        if values > MAX_SAMPLE_VALUES:
            raise SpecError(
                f"{values} sampled values exceed the limit of {MAX_SAMPLE_VALUES} (samples × (horizon + 1)"
                " × states): draw fewer samples",
                field="method.monte_carlo.samples",
            )
        return self

    def required_features(self) -> frozenset[str]:
        """``mean_steering`` always; ``covariance_constraint`` when the file sets a terminal
        covariance (the relaxed constraint eq. 4.61–4.62, an SDP), so a backend that cannot
        enforce it (``qp``) refuses the file instead of returning gains that miss ``Σ_N``."""
        if self.problem.terminal.covariance is not None:
            return frozenset({"mean_steering", "covariance_constraint"})
        return frozenset({"mean_steering"})

    @property
    def objective_sense(self) -> str:
        """``saddle``: the objective is the game's value (eq. 4.12), which the controller minimizes
        and the stopper maximizes."""
        return "saddle"

    def as_solved(self) -> LQGameSpec:
        """A continuous model as the discrete one the backends solve: the zero-order-hold matrices of
        eq. 4.70 for the file's parameter values (the step is named in the description)."""
        if self.problem.continuous is None:
            return self
        game = self.game()
        discrete = {name: getattr(game, name)[0].tolist() for name in ("A", "B", "C", "D")}
        problem = self.problem.model_dump(mode="json") | {"continuous": None, "discrete": discrete}
        note = f"continuous model discretized by zero-order hold with step {game.dt:g} (eq. 4.70)"
        data = self.model_dump(mode="json") | {"problem": problem}
        data["description"] = f"{self.description.strip()} [{note}]".strip()
        return LQGameSpec.model_validate(data)

    @property
    def state_names(self) -> list[str]:
        """The declared state names, or x1, x2, ..."""
        n = len(self.problem.initial.mean)
        return self.problem.states or [f"x{i + 1}" for i in range(n)]

    def game(self, parameters: Mapping[str, float] | None = None) -> LQGame:
        """The numeric game for the file's parameter values, updated by ``parameters``."""
        unknown = set(parameters or {}) - set(self.problem.parameters)
        if unknown:
            raise SpecError(f"unknown parameter(s) {sorted(unknown)}", field="problem.parameters")
        values = {**self.problem.parameters, **(parameters or {})}
        return _Evaluator(self.problem, values).game()


class _Evaluator:
    """Evaluates a problem's entries for given parameter values (the grammar's float walk; no eval)."""

    def __init__(self, problem: LQGameProblem, values: Mapping[str, float]) -> None:
        self.problem = problem
        self.values = {name: float(v) for name, v in values.items()}

    def scalar(self, value: Value, field: str) -> float:
        """The value of an entry: a number, or an expression of the parameters computed in floating
        point with the grammar's overflow checks (never by SymPy's exact arithmetic)."""
        if not isinstance(value, str):
            return float(value)
        try:
            return numeric_value(value, self.values)
        except ExpressionError as err:
            raise SpecError(str(err), field=f"problem.{field}") from None

    def vector(self, values: list[Value], field: str) -> np.ndarray:
        return np.array([self.scalar(v, f"{field}.{i}") for i, v in enumerate(values)])

    def matrix(self, value: MatrixValue, size: int, field: str) -> np.ndarray:
        if isinstance(value, Identity):
            return self.scalar(value.identity, f"{field}.identity") * np.eye(size)
        if isinstance(value, Diagonal):
            return np.diag(self.vector(value.diag, f"{field}.diag"))
        widths = {len(row) for row in value}
        if len(widths) != 1 or 0 in widths:
            raise SpecError("rows must be non-empty and of equal length", field=f"problem.{field}")
        return np.array(
            [[self.scalar(v, f"{field}.{i}.{j}") for j, v in enumerate(row)] for i, row in enumerate(value)]
        )

    def shaped(self, value: MatrixValue, rows: int, cols: int | None, field: str) -> np.ndarray:
        M = self.matrix(value, rows, field)
        if M.shape[0] != rows or (cols is not None and M.shape[1] != cols):
            want = f"{rows}×{cols}" if cols is not None else f"{rows} rows"
            raise SpecError(f"expected {want}, got {M.shape[0]}×{M.shape[1]}", field=f"problem.{field}")
        return M

    def steps(self, value: StepMatrix, rows: int, cols: int | None, field: str) -> np.ndarray:
        """(N, rows, cols): one matrix repeated, or the ``per_step`` list (of length N)."""
        N = self.problem.horizon
        if isinstance(value, PerStep):
            if len(value.per_step) != N:
                raise SpecError(
                    f"per_step needs {N} matrices (one per step), got {len(value.per_step)}",
                    field=f"problem.{field}.per_step",
                )
            first = self.shaped(value.per_step[0], rows, cols, f"{field}.per_step.0")
            rest = [
                self.shaped(m, rows, first.shape[1], f"{field}.per_step.{k}")
                for k, m in enumerate(value.per_step[1:], start=1)
            ]
            return np.stack([first, *rest])
        return np.repeat(self.shaped(value, rows, cols, field)[None], N, axis=0)

    def dynamics(self, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
        p = self.problem
        if p.discrete is not None:
            d = p.discrete
            return (
                self.steps(d.A, n, n, "discrete.A"),
                self.steps(d.B, n, None, "discrete.B"),
                self.steps(d.C, n, None, "discrete.C"),
                self.steps(d.D, n, None, "discrete.D"),
                1.0,
            )
        c = p.continuous
        dt = self.scalar(c.step, "continuous.step")
        if dt <= 0:
            raise SpecError("the step must be positive", field="problem.continuous.step")
        A, (B, C, D) = zero_order_hold(
            self.shaped(c.A, n, n, "continuous.A"),
            [
                self.shaped(m, n, None, f"continuous.{k}")
                for k, m in (("B", c.B), ("C", c.C), ("noise", c.noise))
            ],
            dt,
        )
        N = p.horizon
        A, B, C, D = (np.repeat(M[None], N, axis=0) for M in (A, B, C, D))
        return A, B, C, D, dt

    def covariance(self, value: MatrixValue, n: int, field: str) -> np.ndarray:
        M = self.shaped(value, n, n, field)
        if not np.allclose(M, M.T) or np.linalg.eigvalsh(M).min() < -1e-12 * max(1.0, np.abs(M).max()):
            raise SpecError("a covariance must be symmetric positive semidefinite", field=f"problem.{field}")
        return M

    def game(self) -> LQGame:
        p = self.problem
        mu0 = self.vector(p.initial.mean, "initial.mean")
        n = mu0.size
        A, B, C, D, dt = self.dynamics(n)
        m, ell = B.shape[2], C.shape[2]
        Q = self.steps(p.cost.Q, n, n, "cost.Q")
        R = self.steps(p.cost.R, m, m, "cost.R")
        S = self.steps(p.cost.S, ell, ell, "cost.S")
        for name, W, strict in (("Q", Q, False), ("R", R, True), ("S", S, True)):
            eig = min(np.linalg.eigvalsh((M + M.T) / 2).min() for M in W)
            if eig < 0 or (strict and eig == 0):
                need = "positive definite" if strict else "positive semidefinite"
                raise SpecError(f"{name}_k must be {need} (eq. 4.4)", field=f"problem.cost.{name}")
        muN = None
        if p.terminal.mean is not None:
            if len(p.terminal.mean) != n:
                raise SpecError(f"expected {n} entries", field="problem.terminal.mean")
            muN = np.array(
                [
                    np.nan if v is None else self.scalar(v, f"terminal.mean.{i}")
                    for i, v in enumerate(p.terminal.mean)
                ]
            )
        SigmaN = None
        if p.terminal.covariance is not None:
            SigmaN = self.covariance(p.terminal.covariance, n, "terminal.covariance")
            if np.linalg.eigvalsh(SigmaN).min() <= 0:
                raise SpecError(
                    "the terminal covariance must be positive definite (Lemma 13)",
                    field="problem.terminal.covariance",
                )
        Sigma0 = self.covariance(p.initial.covariance, n, "initial.covariance")
        for name, M in (
            ("dynamics", A),
            ("dynamics", B),
            ("dynamics", C),
            ("dynamics", D),
            ("cost", Q),
            ("cost", R),
            ("cost", S),
            ("initial", mu0),
            ("initial", Sigma0),
        ):
            if not np.abs(M).max(initial=0.0) <= MAX_LQ_ENTRY:
                raise SpecError(
                    f"an entry is beyond {MAX_LQ_ENTRY:g} in size (README, Limits)",
                    field=f"problem.{'continuous' if name == 'dynamics' and p.continuous else name}",
                )
        _open_loop_bounded(A, D, Sigma0)
        return LQGame(
            A=A,
            B=B,
            C=C,
            D=D,
            Q=Q,
            R=R,
            S=S,
            mu0=mu0,
            Sigma0=Sigma0,
            muN=muN,
            SigmaN=SigmaN,
            dt=dt,
        )


def _open_loop_bounded(A: np.ndarray, D: np.ndarray, Sigma0: np.ndarray) -> None:
    """The open-loop covariance ``Σ_{k+1} = A_k Σ_k A_kᵀ + D_k D_kᵀ`` (eq. 4.2 without controls)
    and the state transition ``A_k ⋯ A_0`` stay within :data:`~gamespec.limits.MAX_LQ_ENTRY` over
    the horizon, so the backends' products of them are finite; a SpecError otherwise."""
    Sigma, Phi = Sigma0, np.eye(A.shape[1])
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(A.shape[0]):
            Sigma = A[k] @ Sigma @ A[k].T + D[k] @ D[k].T
            Phi = A[k] @ Phi
            if not (np.abs(Sigma).max() <= MAX_LQ_ENTRY and np.abs(Phi).max() <= MAX_LQ_ENTRY):
                raise SpecError(
                    f"the open-loop state transition or covariance grows beyond {MAX_LQ_ENTRY:g} by step "
                    f"{k + 1}: the model is too unstable (or too noisy) for this horizon",
                    field="problem.horizon",
                )


KIND = Kind(
    LQGameSpec,
    default_backend="cvxpy",
    plot="gamespec.lqgame.plotting:plot",
    summary="gamespec.lqgame.report:lq_summary",
    metrics="gamespec.lqgame.metrics:LqGameMetrics",
    analyses="gamespec.lqgame.montecarlo:ANALYSES",
    columns=(
        "metrics.solution_concept",
        "metrics.mean_payoff",
        "metrics.covariance_payoff",
        "metrics.saddle_gap",
    ),
)
"""The ``LQGameSpec`` kind as one plugin (:class:`~gamespec.registry.Kind`)."""
