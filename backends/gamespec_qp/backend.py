"""The ``qp`` backend for the ``lq_stochastic_game`` kind: the mean steering game through qpsolvers.

The controller's upper game (eq. 4.43, Prop. 10) is handed to qpsolvers as
``min ½ Ūᵀ P Ū + qᵀŪ s.t. 𝒢 Ū = μ_N − drift`` (eq. 4.42; no equality without a terminal mean,
which gives the saddle point of Prop. 9). The covariance part is the UCSG closed form (eq. 4.59).
A QP solver cannot take the controller's terminal covariance constraint (an SDP, eq. 4.62), so the
backend does not declare the ``covariance_constraint`` feature and refuses a file that sets
``terminal.covariance`` (UnsupportedFeature); use the ``cvxpy`` backend for those.

A solve's status is qpsolvers' own verdict (``Solution.found`` and ``Solution.is_optimal`` at a
tolerance relative to the data's scale) through ``STATUS_MAP``; its primal and dual residuals and
duality gap go into the Result's checks. Solver options are tried on a one-variable QP at compile
time, so a rejected option is a one-line error and no exception is caught around a real solve.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, ClassVar

import numpy as np
from pydantic import Field
from scipy.sparse import csc_matrix

from gamespec.compiling.lq import LQBackend, LQCompiledModel, LQSolverOptions
from gamespec.lqgame.solution import MeanOutcome, fallback_mean
from gamespec.result import Result, Status

if TYPE_CHECKING:
    import qpsolvers


QP_TOLERANCE = 1e-7
"""Residuals (primal, dual, duality gap) allowed relative to the QP's data scale (see :func:`verdict`);
above the defaults of the solvers qpsolvers wraps (1e-8 to 1e-9 in their own scaled norms)."""

STATUS_MAP = {
    "optimal": Status.OPTIMAL,
    "primal_feasible": Status.FEASIBLE,
    "infeasible_point": Status.NUMERICAL_ERROR,
    "not_found": Status.NUMERICAL_ERROR,
}
"""qpsolvers' verdicts on a Solution (``found`` and ``is_optimal``) to our statuses. The mean QP is
feasible by Lemma 11 (checked before it is solved), so a solver that finds no point failed
numerically."""


_MESSAGES = {
    "optimal": "",
    "primal_feasible": "mean QP: {solver}'s point meets 𝒢Ū = h, but its dual residual or duality gap "
    "exceeds {eps:.2g} (qpsolvers' is_optimal)",
    "infeasible_point": "mean QP: {solver}'s point misses 𝒢Ū = h by more than {eps:.2g}",
    "not_found": "mean QP: {solver} found no solution",
}


def data_scale(solution: qpsolvers.Solution) -> float:
    """``max(1, ‖q‖∞, ‖b‖∞, ‖P x‖∞, |xᵀPx|)``: the size of the terms the residuals compare."""
    P, q, _, _, _, b, _, _ = solution.problem.unpack()
    x = solution.x
    terms = [1.0, float(np.abs(q).max(initial=0.0))]
    if b is not None:
        terms.append(float(np.abs(b).max(initial=0.0)))
    if x is not None:
        Px = P @ x
        terms += [float(np.abs(Px).max(initial=0.0)), abs(float(x @ Px))]
    return max(terms)


def verdict(solution: qpsolvers.Solution) -> str:
    """A key of STATUS_MAP: qpsolvers' own ``found`` and ``is_optimal(eps)`` with
    ``eps = QP_TOLERANCE · data_scale``; a found point whose primal residual alone is within eps is
    ``primal_feasible``."""
    if not solution.found or solution.x is None:
        return "not_found"
    eps = QP_TOLERANCE * data_scale(solution)
    if solution.is_optimal(eps):
        return "optimal"
    return "primal_feasible" if solution.primal_residual() < eps else "infeasible_point"


def residuals(solution: qpsolvers.Solution, scale: float) -> dict[str, float | None]:
    """qpsolvers' primal and dual residuals and duality gap (None where undefined), and the scale
    (:func:`data_scale`)."""

    def finite(value: float) -> float | None:
        return float(value) if np.isfinite(value) else None

    return {
        "qp_primal_residual": finite(solution.primal_residual()),
        "qp_dual_residual": finite(solution.dual_residual()),
        "qp_duality_gap": finite(solution.duality_gap()),
        "qp_data_scale": scale,
    }


class QpOptions(LQSolverOptions):
    """Options of the ``qp`` backend: the qpsolvers solver's name and its keyword arguments."""

    solver: str = Field("proxqp", description="The qpsolvers solver's name (`proxqp`, `osqp`, ...).")


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
        given = [guess.controls.get(f"u{i + 1}") for i in range(game.m)] if guess is not None else []
        columns = [c for c in given if c is not None and c.shape == (game.N,)]
        if not columns or len(columns) < len(given):
            return None
        return np.column_stack(columns).ravel()

    def _solve_mean_qp(self, guess: Result | None) -> MeanOutcome:
        """The QP, warm-started from ``guess``'s controls; its status from qpsolvers' residuals."""
        import qpsolvers

        start = time.perf_counter()
        solution = qpsolvers.solve_problem(
            self.problem,
            solver=self.options.solver,
            initvals=self._initial_controls(guess),
            **self.options.solver_options,
        )
        seconds = time.perf_counter() - start
        key = verdict(solution)
        scale = data_scale(solution)
        status, checks = STATUS_MAP[key], residuals(solution, scale)
        eps = QP_TOLERANCE * scale
        message = _MESSAGES[key].format(solver=self.options.solver, eps=eps)
        if not status.ok:
            outcome = fallback_mean(self.model, status, message)
            outcome.checks = checks
            return outcome
        U = np.asarray(solution.x)
        return MeanOutcome(
            U, self.model.mean.stopper_response(U), status, message, solve_time_s=seconds, checks=checks
        )


class QpBackend(LQBackend[QpOptions]):
    """qpsolvers with a QP solver chosen by name (``solver: proxqp``, ``osqp``, ``clarabel``, ...)."""

    name: ClassVar[str] = "qp"
    features: ClassVar[frozenset[str]] = frozenset({"mean_steering"})
    options_model = QpOptions
    library: ClassVar[str] = "qpsolvers"
    model_class: ClassVar[type[LQCompiledModel]] = QpModel

    @classmethod
    def installed_solvers(cls) -> list[str]:
        import qpsolvers

        return list(qpsolvers.available_solvers)

    @classmethod
    def probe_options(cls, options: QpOptions) -> None:
        """Solve ``min ½x² − x s.t. x ≤ ½`` with the user's solver options (constrained, so that
        qpsolvers hands it to the solver rather than to SciPy's least squares)."""
        import qpsolvers

        P, G = np.eye(1), np.ones((1, 1))
        if options.solver not in qpsolvers.dense_solvers:
            P, G = csc_matrix(P), csc_matrix(G)
        probe = qpsolvers.Problem(P, -np.ones(1), G=G, h=np.full(1, 0.5))
        try:
            qpsolvers.solve_problem(probe, solver=options.solver, **options.solver_options)
        except (TypeError, ValueError, qpsolvers.ParamError) as err:
            raise options.rejected(err) from None
