"""The ``cvxpy`` backend for the ``lq_stochastic_game`` kind (chapter 4).

The mean steering upper game (eq. 4.43, Prop. 10) is a CVXPY QP; the constrained covariance game is
Algorithm 2 (Jacobi) with the stopper's best response (concave QP, eq. 4.59b) and the controller's
best response under the relaxed terminal constraint eq. 4.61 in the form eq. 4.62
(``σ_max(W) ≤ 1``, an SDP). Each player's problem is built once with ``cp.Parameter``s and
re-solved every iteration. When the controller's problem is infeasible, a third problem on the same
parameters, ``min σ_max(W)``, gives the smallest achievable scaling ``γ* = σ²`` of ``Σ_N``. Without
a terminal covariance the covariance game is the UCSG closed form (eq. 4.59). cvxpy is imported
only when this backend is used.
"""

from __future__ import annotations

import time
import warnings
from typing import Any, ClassVar

import numpy as np

from gamespec.lqgame.backend import LQBackend, LQCompiledModel, LQSolverOptions
from gamespec.lqgame.covariance import gains_to_vector, jacobi
from gamespec.lqgame.solution import CovarianceOutcome, GameModel, MeanOutcome, fallback_mean
from gamespec.result import Result, Status
from gamespec.specs.base import StrictModel

STATUS_MAP = {
    "optimal": Status.OPTIMAL,
    "optimal_inaccurate": Status.FEASIBLE,
    "infeasible": Status.INFEASIBLE,
    "infeasible_inaccurate": Status.INFEASIBLE,
    "unbounded": Status.UNBOUNDED,
    "unbounded_inaccurate": Status.UNBOUNDED,
    "user_limit": Status.ITERATION_LIMIT,
    "solver_error": Status.NUMERICAL_ERROR,
}


class CvxpyOptions(LQSolverOptions):
    """Options of the ``cvxpy`` backend: the conic solver's name and its keyword arguments."""

    solver: str = "CLARABEL"


class _Problem:
    """A CVXPY problem re-solved with new parameter values; returns our Status (an inaccurate
    solution is ``feasible``, so cvxpy's warning about it is not repeated)."""

    def __init__(self, problem: Any, options: CvxpyOptions) -> None:
        self.problem = problem
        self.options = options
        self.seconds = 0.0

    def solve(self) -> Status:
        import cvxpy as cp

        start = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.filterwarnings("ignore", message="Solution may be inaccurate")
                self.problem.solve(solver=self.options.solver, warm_start=True, **self.options.solver_options)
        except cp.SolverError:
            return Status.NUMERICAL_ERROR
        finally:
            self.seconds += time.perf_counter() - start
        return STATUS_MAP.get(self.problem.status, Status.ERROR)


class MeanProblem:
    """The controller's upper game eq. 4.43 as a CVXPY QP in ``Ū``."""

    def __init__(self, model: GameModel, options: CvxpyOptions) -> None:
        import cvxpy as cp

        qp = model.mean.upper_game_qp()
        self.U = cp.Variable(qp.q.size)
        root = np.linalg.cholesky(qp.P / 2).T
        constraints = [] if qp.A is None else [qp.A @ self.U - qp.b == 0]
        objective = cp.Minimize(cp.sum_squares(root @ self.U) + qp.q @ self.U)
        self.problem = _Problem(cp.Problem(objective, constraints), options)

    def solve(self, model: GameModel) -> MeanOutcome:
        start = self.problem.seconds
        status = self.problem.solve()
        reported = f"mean QP: solver reported {self.problem.problem.status}"
        if self.U.value is None or not status.ok:
            return fallback_mean(model, status, reported)
        U = np.asarray(self.U.value)
        return MeanOutcome(
            U,
            model.mean.stopper_response(U),
            status,
            message=reported if status is Status.FEASIBLE else "",
            iterations=self.problem.problem.solver_stats.num_iters,
            solve_time_s=self.problem.seconds - start,
        )


class CovariancePlayers:
    """Both players' best-response problems of Algorithm 2, built once on ``cp.Parameter``s."""

    def __init__(self, model: GameModel, options: CvxpyOptions) -> None:
        import cvxpy as cp

        cov = model.covariance
        self.model = model
        self.w0, self.T_WK, self.T_WL = cov.terminal_map()
        n = model.game.n
        p = self.w0.size // n
        self.kappa = cp.Variable(cov.g_K.size)
        self.ell = cp.Variable(cov.g_L.size)
        self.c_K = cp.Parameter(cov.g_K.size)
        self.c_L = cp.Parameter(cov.g_L.size)
        self.offset = cp.Parameter(self.w0.size)
        W = cp.reshape(self.offset + self.T_WK @ self.kappa, (n, p), order="F")
        root_K = np.linalg.cholesky(cov.H_KK).T
        root_L = np.linalg.cholesky(-cov.H_LL).T
        self.controller = _Problem(
            cp.Problem(
                cp.Minimize(cp.sum_squares(root_K @ self.kappa) + 2 * self.c_K @ self.kappa),
                [cp.sigma_max(W) <= 1],
            ),
            options,
        )
        self.stopper = _Problem(
            cp.Problem(cp.Maximize(-cp.sum_squares(root_L @ self.ell) + 2 * self.c_L @ self.ell)),
            options,
        )
        self.scaling = _Problem(cp.Problem(cp.Minimize(cp.sigma_max(W))), options)
        self.steps = {"stopper": 0, "controller": 0}
        self.inaccurate = {"stopper": "", "controller": ""}

    def _step(self, player: str, problem: _Problem, variable: Any) -> tuple[Status, np.ndarray | None]:
        """Solve one player's problem; remember the step when the solver was only inaccurate."""
        status = problem.solve()
        self.steps[player] += 1
        self.inaccurate[player] = (
            f"{player} step {self.steps[player]}: solver reported {problem.problem.status}"
            if status is Status.FEASIBLE
            else ""
        )
        return status, (np.asarray(variable.value) if status.ok else None)

    def stopper_step(self, kappa: np.ndarray) -> tuple[Status, np.ndarray | None]:
        self.c_L.value = self.model.covariance.stopper_linear_term(kappa)
        return self._step("stopper", self.stopper, self.ell)

    def controller_step(self, ell: np.ndarray) -> tuple[Status, np.ndarray | None]:
        self.c_K.value = self.model.covariance.controller_linear_term(ell)
        self.offset.value = self.w0 + self.T_WL @ ell
        return self._step("controller", self.controller, self.kappa)

    def smallest_scaling(self) -> float | None:
        """``min_K ‖W‖₂²`` for the current parameters: the least ``γ`` with ``Σ_N(K) ⪯ γ Σ_N``."""
        status = self.scaling.solve()
        value = self.scaling.problem.value
        return float(value) ** 2 if status.ok and value is not None else None

    @property
    def seconds(self) -> float:
        return self.controller.seconds + self.stopper.seconds + self.scaling.seconds

    def solve(
        self, tolerance: float, max_iterations: int, start_gains: tuple[np.ndarray, np.ndarray] | None = None
    ) -> CovarianceOutcome:
        """Algorithm 2 from ``start_gains`` ``(K, L)`` (arrays (N, m, n), (N, ℓ, n)), or else from the
        UCSG saddle point (the thesis leaves ``K_0, L_0`` open)."""
        start = self.seconds
        self.steps = dict.fromkeys(self.steps, 0)
        if start_gains is None:
            kappa0, ell0 = self.model.covariance.unconstrained_saddle()
        else:
            kappa0, ell0 = (gains_to_vector(G) for G in start_gains)
        run = jacobi(self.stopper_step, self.controller_step, kappa0, ell0, tolerance, max_iterations)
        outcome = CovarianceOutcome(
            run.kappa,
            run.ell,
            run.status,
            "jacobi (Algorithm 2, eq. 4.62)",
            iterations=run.iterations,
            history=run.history,
        )
        if run.status is Status.INFEASIBLE and run.failed_step == "controller":
            gamma = self.smallest_scaling()
            outcome.min_covariance_scaling = gamma
            scaling = (
                f"the smallest achievable scaling of Σ_N against the stopper's gains is γ* = {gamma:.4g}"
                if gamma is not None
                else "the smallest achievable scaling of Σ_N could not be computed"
            )
            outcome.message = (
                f"terminal covariance cannot be met at Jacobi iteration {run.iterations + 1}: {scaling}; "
                "gains shown are the last iterate"
            )
        elif not run.status.ok:
            outcome.message = f"Jacobi stopped: {run.failed_step or 'iteration limit'} ({run.status.value})"
        elif run.status is Status.FEASIBLE:
            outcome.message = "; ".join(note for note in self.inaccurate.values() if note)
        outcome.solve_time_s = self.seconds - start
        return outcome


class CvxpyModel(LQCompiledModel):
    """The mean QP and, with a terminal covariance, both players' problems of Algorithm 2."""

    options: CvxpyOptions

    def _build_solver(self) -> None:
        self.mean = MeanProblem(self.model, self.options)
        self.players = (
            CovariancePlayers(self.model, self.options) if self.model.game.SigmaN is not None else None
        )

    def _solve_mean_qp(self, guess: Result | None) -> MeanOutcome:
        return self.mean.solve(self.model)

    def _start_gains(self, guess: Result | None) -> tuple[np.ndarray, np.ndarray] | None:
        """A previous Result's gains as Algorithm 2's start, when they fit this game."""
        if guess is None or "K" not in guess.arrays or "L" not in guess.arrays:
            return None
        g = self.model.game
        K, L = guess.arrays["K"], guess.arrays["L"]
        fits = K.shape == (g.N, g.m, g.n) and L.shape == (g.N, g.ell, g.n)
        return (K, L) if fits else None

    def _solve_covariance(self, guess: Result | None) -> CovarianceOutcome:
        """Algorithm 2 (warm-started from ``guess``'s gains) or, without Σ_N, the UCSG closed form."""
        if self.players is None:
            return super()._solve_covariance(guess)
        method = self.spec.method
        return self.players.solve(method.tolerance, method.max_iterations, self._start_gains(guess))


class CvxpyBackend(LQBackend):
    """CVXPY with a conic solver chosen by name (``solver: CLARABEL``, ``SCS``, ...)."""

    name: ClassVar[str] = "cvxpy"
    features: ClassVar[frozenset[str]] = frozenset({"mean_steering", "covariance_constraint"})
    options_model: ClassVar[type[StrictModel]] = CvxpyOptions
    library: ClassVar[str] = "cvxpy"
    model_class: ClassVar[type[LQCompiledModel]] = CvxpyModel

    @classmethod
    def installed_solvers(cls) -> list[str]:
        import cvxpy as cp

        return list(cp.installed_solvers())

    @classmethod
    def probe(cls, options: CvxpyOptions) -> None:
        import cvxpy as cp

        x = cp.Variable()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cp.Problem(cp.Minimize(cp.square(x - 1))).solve(solver=options.solver, **options.solver_options)
