"""The ``qp`` backend for the ``lq_stochastic_game`` kind: the mean steering game through qpsolvers.

The controller's upper game (eq. 4.43, Prop. 10) is handed to qpsolvers as
``min ½ Ūᵀ P Ū + qᵀŪ s.t. 𝒢 Ū = μ_N − drift`` (eq. 4.42; no equality without a terminal mean,
which gives the saddle point of Prop. 9). The covariance part is the UCSG closed form (eq. 4.59).
A QP solver cannot take the controller's terminal covariance constraint (an SDP, eq. 4.62), so the
backend does not declare the ``covariance_constraint`` feature and refuses a file that sets
``terminal.covariance`` (UnsupportedFeature); use the ``cvxpy`` backend for those.
"""

from __future__ import annotations

import time
from typing import ClassVar

import numpy as np
from scipy.sparse import csc_matrix

from gamespec.lqgame.backend import LQBackend, LQCompiledModel, LQSolverOptions
from gamespec.lqgame.solution import MeanOutcome, fallback_mean
from gamespec.result import Result, Status
from gamespec.specs.base import StrictModel


class QpOptions(LQSolverOptions):
    """Options of the ``qp`` backend: the qpsolvers solver's name and its keyword arguments."""

    solver: str = "proxqp"


class QpModel(LQCompiledModel):
    """The mean QP as a qpsolvers Problem (sparse for sparse-only solvers); the covariance gains
    in closed form. qpsolvers reports no common iteration count, so ``iterations`` is None."""

    def _build_solver(self) -> None:
        import qpsolvers

        qp = self.model.mean.upper_game_qp()
        P, A = qp.P, qp.A
        if self.options.solver not in qpsolvers.dense_solvers:
            P, A = csc_matrix(P), None if A is None else csc_matrix(A)
        self.problem = qpsolvers.Problem(P, qp.q, A=A, b=qp.b)

    def _initial_controls(self, guess: Result | None) -> np.ndarray | None:
        """``guess``'s controller inputs stacked as ``Ū``, when they fit this game."""
        game = self.model.game
        columns = [guess.controls.get(f"u{i + 1}") for i in range(game.m)] if guess is not None else []
        if not columns or any(c is None or c.shape != (game.N,) for c in columns):
            return None
        return np.column_stack(columns).ravel()

    def _solve_mean_qp(self, guess: Result | None) -> MeanOutcome:
        """The QP, warm-started from ``guess``'s controls."""
        import qpsolvers

        initvals = self._initial_controls(guess)
        start = time.perf_counter()
        solution = qpsolvers.solve_problem(
            self.problem, solver=self.options.solver, initvals=initvals, **self.options.solver_options
        )
        seconds = time.perf_counter() - start
        if not solution.found or solution.x is None:
            return fallback_mean(
                self.model, Status.NUMERICAL_ERROR, f"{self.options.solver} found no solution"
            )
        U = np.asarray(solution.x)
        return MeanOutcome(U, self.model.mean.stopper_response(U), Status.OPTIMAL, solve_time_s=seconds)


class QpBackend(LQBackend):
    """qpsolvers with a QP solver chosen by name (``solver: proxqp``, ``osqp``, ``clarabel``, ...)."""

    name: ClassVar[str] = "qp"
    features: ClassVar[frozenset[str]] = frozenset({"mean_steering"})
    options_model: ClassVar[type[StrictModel]] = QpOptions
    library: ClassVar[str] = "qpsolvers"
    model_class: ClassVar[type[LQCompiledModel]] = QpModel

    @classmethod
    def installed_solvers(cls) -> list[str]:
        import qpsolvers

        return list(qpsolvers.available_solvers)

    @classmethod
    def probe(cls, options: QpOptions) -> None:
        import qpsolvers

        P, G = np.eye(1), np.ones((1, 1))
        if options.solver not in qpsolvers.dense_solvers:
            P, G = csc_matrix(P), csc_matrix(G)
        problem = qpsolvers.Problem(P, -np.ones(1), G=G, h=np.full(1, 0.5))
        try:
            qpsolvers.solve_problem(problem, solver=options.solver, **options.solver_options)
        except qpsolvers.ParamError as err:
            raise ValueError(str(err)) from None
