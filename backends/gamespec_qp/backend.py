"""The ``qp`` backend for the ``lq_stochastic_game`` kind: the mean steering game through qpsolvers.

The controller's upper game (eq. 4.43, Prop. 10) is handed to qpsolvers as
``min ½ Ūᵀ P Ū + qᵀŪ s.t. 𝒢 Ū = μ_N − drift`` (eq. 4.42; no equality without a terminal mean,
which gives the saddle point of Prop. 9). The covariance part is the UCSG closed form (eq. 4.59):
a QP solver cannot take the controller's terminal covariance constraint (an SDP, eq. 4.62). When
the file asks for a terminal covariance, the Result says so in its message and in
``metrics.covariance_game``, and ``checks.terminal_covariance_violation`` shows how far the
unconstrained gains miss it; use the ``cvxpy`` backend for the constrained covariance game.
"""

from __future__ import annotations

import time
from typing import Any, ClassVar

import numpy as np
from pydantic import Field
from scipy.sparse import csc_matrix

from gamespec.backend import Availability, Backend, CompiledModel
from gamespec.errors import BackendError
from gamespec.lqgame.solution import GameModel, MeanOutcome, assemble, fallback_mean, unconstrained_covariance
from gamespec.result import Result, Status
from gamespec.specs.base import SpecBase, StrictModel
from gamespec.specs.lq_game import LQGameSpec

UNENFORCED = "terminal covariance not enforced: the qp backend solves the unconstrained covariance game"


class QpOptions(StrictModel):
    """Options of the ``qp`` backend: the qpsolvers solver's name and its keyword arguments."""

    solver: str = "proxqp"
    solver_options: dict[str, Any] = Field(default_factory=dict)


class QpModel(CompiledModel):
    """The mean QP built once (rebuilt for new parameter values; sparse for sparse-only solvers),
    solved by qpsolvers."""

    def __init__(self, spec: LQGameSpec, options: QpOptions) -> None:
        self.spec = spec
        self.options = options
        self._build(None)

    def _build(self, parameters: dict[str, float] | None) -> None:
        import qpsolvers

        self.parameters = dict(parameters or {})
        self.model = GameModel.build(self.spec.game(parameters))
        qp = self.model.mean.upper_game_qp()
        P, A = qp.P, qp.A
        if self.options.solver not in qpsolvers.dense_solvers:
            P, A = csc_matrix(P), None if A is None else csc_matrix(A)
        self.problem = qpsolvers.Problem(P, qp.q, A=A, b=qp.b)

    def solve_mean(self, guess: Result | None = None) -> MeanOutcome:
        """The mean game alone: Lemma 11, then the QP (warm-started from ``guess``'s controls)."""
        import qpsolvers

        unreachable = self.model.unreachable_mean()
        if unreachable:
            return fallback_mean(self.model, Status.INFEASIBLE, unreachable)
        initvals = None
        if guess is not None and "u1" in guess.controls:
            initvals = np.column_stack(
                [guess.controls[f"u{i + 1}"] for i in range(self.model.game.m)]
            ).ravel()
        start = time.perf_counter()
        try:
            solution = qpsolvers.solve_problem(
                self.problem, solver=self.options.solver, initvals=initvals, **self.options.solver_options
            )
        except (TypeError, ValueError, qpsolvers.ParamError) as err:
            reason = str(err).splitlines()[0]
            raise BackendError(
                f"{self.options.solver} rejected solver_options {self.options.solver_options}: {reason}"
            ) from None
        seconds = time.perf_counter() - start
        if not solution.found or solution.x is None:
            return fallback_mean(
                self.model, Status.NUMERICAL_ERROR, f"{self.options.solver} found no solution"
            )
        U = np.asarray(solution.x)
        return MeanOutcome(U, self.model.mean.stopper_response(U), Status.OPTIMAL, solve_time_s=seconds)

    def solve(self, parameters: dict[str, float] | None = None, guess: Result | None = None) -> Result:
        if parameters and parameters != self.parameters:
            self._build(parameters)
        failure = self.model.assumption_failure()
        if failure:
            return Result(status=Status.ERROR, message=failure, metrics=self.model.assumptions.as_metrics())
        mean = self.solve_mean(guess)
        note = UNENFORCED if self.model.game.SigmaN is not None else ""
        cov = unconstrained_covariance(self.model, note)
        method = self.spec.method
        result = assemble(
            self.model, mean, cov, self.spec.state_names, method.monte_carlo.samples, method.monte_carlo.seed
        )
        values = {**self.spec.problem.parameters, **self.parameters}
        return result.model_copy(
            update={"parameters": values, "solver_stats": {"solver": self.options.solver}}
        )


class QpBackend(Backend):
    """qpsolvers with a QP solver chosen by name (``solver: proxqp``, ``osqp``, ``clarabel``, ...)."""

    name: ClassVar[str] = "qp"
    kinds: ClassVar[frozenset[str]] = frozenset({"lq_stochastic_game"})
    features: ClassVar[frozenset[str]] = frozenset({"mean_steering"})
    options_model: ClassVar[type[StrictModel]] = QpOptions

    @classmethod
    def available(cls) -> Availability:
        try:
            import qpsolvers
        except ImportError as err:
            return Availability(False, f"qpsolvers does not import: {err}")
        if not qpsolvers.available_solvers:
            return Availability(False, "qpsolvers finds no QP solver")
        return Availability(
            True, f"qpsolvers {qpsolvers.__version__}; solvers {', '.join(qpsolvers.available_solvers)}"
        )

    def _compile(self, spec: SpecBase, options: StrictModel) -> CompiledModel:
        import qpsolvers

        assert isinstance(spec, LQGameSpec) and isinstance(options, QpOptions)
        if options.solver not in qpsolvers.available_solvers:
            raise BackendError(
                f"QP solver {options.solver!r} is not installed for qpsolvers "
                f"(installed: {', '.join(qpsolvers.available_solvers)})"
            )
        return QpModel(spec, options)
