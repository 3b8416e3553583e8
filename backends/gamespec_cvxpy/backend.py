"""The ``cvxpy`` backend for the ``lq_stochastic_game`` kind (chapter 4).

The mean steering upper game (eq. 4.43, Prop. 10) is a CVXPY QP; the constrained covariance game is
Algorithm 2 on the best-response engine with the stopper's best response (eq. 4.59b, closed form)
and the controller's best response under the relaxed terminal constraint eq. 4.61 normalized as in
eq. 4.62 (``W Wᵀ ⪯ I``, an SDP in whitened gains, :mod:`gamespec.lqgame.scaling`, with one small
cone per column of ``W``: :meth:`CovariancePlayers.terminal_cone`), built once with
``cp.Parameter``s and re-solved every iteration. A step the solver fails on numerically is retried
on ``fallback_solver`` when the options name one, and otherwise stops the run with the best iterate
and the status ``numerical_error``. When the controller's problem is infeasible, a second problem
on the same parameters, ``min γ`` subject to ``W Wᵀ ⪯ γ I``, gives the smallest achievable scaling
``γ* = σ_max(W)²`` of ``Σ_N``. Without a terminal covariance the covariance game is the UCSG closed
form (eq. 4.59). cvxpy is imported only when this backend is used.
"""

from __future__ import annotations

import time
import warnings
from typing import Any, ClassVar

import numpy as np
from pydantic import Field

from gamespec.best_response import Settings, StepReport
from gamespec.compiling.lq import LQBackend, LQCompiledModel, LQSolverOptions
from gamespec.errors import BackendError
from gamespec.lqgame.covariance import CONTROLLER, STOPPER, algorithm_2, gains_to_vector
from gamespec.lqgame.scaling import ControllerScaling, QPScaling
from gamespec.lqgame.solution import CovarianceOutcome, GameModel, MeanOutcome, fallback_mean
from gamespec.result import Result, Status

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


RETRY_SOLVER_OPTIONS: dict[str, dict[str, Any]] = {"CLARABEL": {"chordal_decomposition_enable": False}}
"""Settings of a second attempt at a step a solver fails on numerically (the same tolerances).
Clarabel's chordal decomposition is a heuristic whose interior point can stall: it did on eq. 4.62
posed as one (n + p)-square cone where the controller cannot steer some terminal states (the rows
of ``W`` it leaves constant, e.g. the target's acceleration in the missile endgame), and the whole
cone gave ``optimal`` or ``infeasible``. The column cones of :meth:`CovariancePlayers.terminal_cone`
are dense and leave it nothing to split; the second attempt stays for the problems it does split."""


class CvxpyOptions(LQSolverOptions):
    """Options of the ``cvxpy`` backend: the conic solver's name and its keyword arguments, how to
    retry a step it fails on numerically, and an optional second solver for such a step."""

    solver: str = Field("CLARABEL", description="The CVXPY solver's name (`CLARABEL`, `SCS`, ...).")
    retry_solver_options: dict[str, Any] | None = Field(
        None,
        description="solver_options added for a second attempt at a step the solver fails on "
        "numerically; default: RETRY_SOLVER_OPTIONS for the solver (none for most solvers), {} to disable.",
    )
    fallback_solver: str | None = Field(
        None,
        description="Solver (default settings) that takes a step both attempts failed on numerically; "
        "none by default, so a failure is reported rather than hidden.",
    )

    @property
    def retry(self) -> dict[str, Any]:
        """The solver options of the second attempt (empty: no second attempt)."""
        if self.retry_solver_options is not None:
            return self.retry_solver_options
        return RETRY_SOLVER_OPTIONS.get(self.solver.upper(), {})


class _Problem:
    """A CVXPY problem re-solved with new parameter values; returns our Status (an inaccurate
    solution is ``feasible``, so cvxpy's warning about it is not repeated). A numerical failure is
    retried with the options' ``retry`` settings, then on ``fallback_solver`` when the options name
    one; ``note`` says what was needed."""

    def __init__(self, problem: Any, options: CvxpyOptions) -> None:
        self.problem = problem
        self.options = options
        self.seconds = 0.0
        self.note = ""
        self.raised = ""
        """Why the last run raised (empty when it did not)."""

    def _run(self, solver: str, solver_options: dict[str, Any]) -> Status:
        import cvxpy as cp

        start = time.perf_counter()
        self.raised = ""
        try:
            with warnings.catch_warnings():
                warnings.filterwarnings("ignore", message="Solution may be inaccurate")
                self.problem.solve(solver=solver, warm_start=True, **solver_options)
        except cp.SolverError:
            self.raised = "a solver error"
            return Status.NUMERICAL_ERROR
        except ValueError as err:
            if "Problem data contains NaN" not in str(err):
                raise
            self.raised = "problem data with NaN or Inf (an input of extreme magnitude)"
            return Status.NUMERICAL_ERROR
        finally:
            self.seconds += time.perf_counter() - start
        return STATUS_MAP.get(self.problem.status, Status.ERROR)

    def solve(self) -> Status:
        options = self.options
        self.note = ""
        status = self._run(options.solver, options.solver_options)
        if status is Status.NUMERICAL_ERROR and options.retry:
            status = self._run(options.solver, {**options.solver_options, **options.retry})
            self.note = f"{options.solver} failed numerically, again with {options.retry}: {status.value}"
        if status is Status.NUMERICAL_ERROR and options.fallback_solver:
            status = self._run(options.fallback_solver, {})
            self.note += f"{'; ' if self.note else ''}{options.fallback_solver}: {status.value}"
        return status

    @property
    def reported(self) -> str:
        """What the solver reported last (cvxpy's status, or that it raised)."""
        return self.raised or self.problem.status


class MeanProblem:
    """The controller's upper game eq. 4.43 as a CVXPY QP in the scaled inputs ``ξ`` of
    :class:`~gamespec.lqgame.scaling.QPScaling` (``Ū = ρ s R⁻¹ ξ``)."""

    def __init__(self, model: GameModel, options: CvxpyOptions) -> None:
        import cvxpy as cp

        original = model.mean.upper_game_qp()
        self.scaling = QPScaling.of(original)
        qp = self.scaling.scaled(original)
        self.xi = cp.Variable(qp.q.size)
        constraints = [] if qp.A is None else [qp.A @ self.xi - qp.b == 0]
        objective = cp.Minimize(cp.sum_squares(self.xi) + qp.q @ self.xi)
        self.problem = _Problem(cp.Problem(objective, constraints), options)

    def solve(self, model: GameModel) -> MeanOutcome:
        start = self.problem.seconds
        status = self.problem.solve()
        reported = f"mean QP: solver reported {self.problem.reported}"
        if self.problem.note:
            reported += f" ({self.problem.note})"
        if self.xi.value is None or not status.ok:
            return fallback_mean(model, status, reported)
        U = self.scaling.unscale(np.asarray(self.xi.value))
        return MeanOutcome(
            U,
            model.mean.stopper_response(U),
            status,
            message=reported if status is Status.FEASIBLE or self.problem.note else "",
            iterations=self.problem.problem.solver_stats.num_iters,
            solve_time_s=self.problem.seconds - start,
        )


class CovariancePlayers:
    """Both players' best responses of Algorithm 2: the stopper's in closed form (eq. 4.59b, an
    unconstrained strictly concave QP, solved exactly by one linear solve rather than to a conic
    solver's tolerance) and the controller's SDP under eq. 4.61–4.62 (:meth:`terminal_cone`), built
    once on ``cp.Parameter``s in the whitened, normalized gains ``κ = s R_K⁻¹ ζ`` of
    :mod:`gamespec.lqgame.scaling`, so the solver sees a unit Hessian and a unit constraint map
    whatever the problem's magnitudes."""

    def __init__(self, model: GameModel, options: CvxpyOptions) -> None:
        import cvxpy as cp

        cov = model.covariance
        self.model = model
        self.w0, T_WK, self.T_WL = cov.terminal_map()
        self.gains = ControllerScaling.of(cov.H_KK, T_WK)
        n = model.game.n
        p = self.w0.size // n
        self.zeta = cp.Variable(cov.g_K.size)
        self.c = cp.Parameter(cov.g_K.size)
        self.offset = cp.Parameter(self.w0.size)
        W = cp.reshape(self.offset + self.gains.map(T_WK) @ self.zeta, (n, p), order="F")
        payoff = cp.sum_squares(self.zeta) + 2 * self.c @ self.zeta
        self.controller = _Problem(cp.Problem(cp.Minimize(payoff), self.terminal_cone(W, 1.0)), options)
        gamma = cp.Variable()
        self.scaling = _Problem(cp.Problem(cp.Minimize(gamma), self.terminal_cone(W, gamma)), options)
        self.steps = 0

    @staticmethod
    def terminal_cone(W: Any, bound: Any) -> list[Any]:
        """``W Wᵀ ⪯ bound · I`` for the n × p expression ``W``: eq. 4.61 normalized by ``Σ_N^{-1/2}``
        (with ``bound = 1`` the constraint eq. 4.62, ``‖W‖₂ ≤ 1``, squared), as
        ``Σ_j Z_j ⪯ bound · I`` and ``[[Z_j, w_j], [w_jᵀ, 1]] ⪰ 0`` (``Z_j ⪰ w_j w_jᵀ``) for each
        column ``w_j``. ``W Wᵀ = Σ_j w_j w_jᵀ``, so the two are equivalent; this is the chordal
        decomposition of the arrow-shaped ``[[bound · I, W], [Wᵀ, I]] ⪰ 0``: p cones of size n + 1
        instead of one of size n + p, whose scaling an interior-point solver holds as one dense block
        of side (n + p)(n + p + 1)/2. With no decomposition of its own to do, Clarabel also re-solves
        on new parameter values without a new setup."""
        import cvxpy as cp

        n, p = W.shape
        Y = [cp.Variable((n + 1, n + 1), PSD=True) for _ in range(p)]
        return [
            cp.vstack([Yj[:n, n] for Yj in Y]).T == W,
            cp.hstack([Yj[n, n] for Yj in Y]) == 1,
            bound * np.eye(n) - sum(Yj[:n, :n] for Yj in Y) >> 0,
        ]

    def stopper_step(self, kappa: np.ndarray) -> tuple[np.ndarray, StepReport]:
        """eq. 4.59b: ``ℓ = −H_LL⁻¹(g_L + H_LK κ)``."""
        return self.model.covariance.stopper_response(kappa), StepReport(Status.OPTIMAL)

    def controller_step(self, ell: np.ndarray) -> tuple[np.ndarray | None, StepReport]:
        """The controller's best response in ``𝒦(ℓ)`` (eq. 4.62), ``κ = s R_K⁻¹ ζ``; the report names
        the step when the solver was only inaccurate or needed the fallback."""
        self.c.value = self.gains.linear_term(self.model.covariance.controller_linear_term(ell))
        self.offset.value = self.w0 + self.T_WL @ ell
        status = self.controller.solve()
        self.steps += 1
        notes = [f"solver reported {self.controller.reported}"] if status is not Status.OPTIMAL else []
        notes += [self.controller.note] if self.controller.note else []
        report = StepReport(status, f"step {self.steps}: {'; '.join(notes)}" if notes else "")
        return (self.gains.unscale(np.asarray(self.zeta.value)) if status.ok else None), report

    def controller_value(self, ell: np.ndarray) -> float | None:
        """``J_Σ`` of the controller's constrained best response to ``ℓ`` (one more step, for the
        Nash gap), None when the step fails."""
        kappa, report = self.controller_step(ell)
        return self.model.covariance.payoff(kappa, ell) if kappa is not None and report.status.ok else None

    def smallest_scaling(self) -> float | None:
        """``min_K ‖W‖₂²`` for the current parameters: the least ``γ`` with ``Σ_N(K) ⪯ γ Σ_N``."""
        status = self.scaling.solve()
        value = self.scaling.problem.value
        return float(value) if status.ok and value is not None else None

    @property
    def seconds(self) -> float:
        return self.controller.seconds + self.scaling.seconds

    def solve(
        self, settings: Settings, start_gains: tuple[np.ndarray, np.ndarray] | None = None
    ) -> CovarianceOutcome:
        """Algorithm 2 from ``start_gains`` ``(K, L)`` (arrays (N, m, n), (N, ℓ, n)), or else from the
        UCSG saddle point (the thesis leaves ``K_0, L_0`` open)."""
        start = self.seconds
        self.steps = 0
        if start_gains is None:
            kappa0, ell0 = self.model.covariance.unconstrained_saddle()
        else:
            kappa0, ell0 = (gains_to_vector(G) for G in start_gains)
        run = algorithm_2(self.stopper_step, self.controller_step, kappa0, ell0, settings)
        accelerated = " + anderson" if settings.acceleration == "anderson" else ""
        outcome = CovarianceOutcome(
            run.strategies[CONTROLLER],
            run.strategies[STOPPER],
            run.status,
            f"{settings.scheme}{accelerated} (Algorithm 2, eq. 4.62)",
            message=run.message,
            iterations=run.iterations,
            history=list(zip(run.changes(CONTROLLER), run.changes(STOPPER), strict=True)),
            best_response=run.as_metrics(),
        )
        if run.status.ok:
            outcome.controller_value = self.controller_value(run.strategies[STOPPER])
        if run.status is Status.INFEASIBLE and run.failed_player == CONTROLLER:
            gamma = self.smallest_scaling()
            outcome.min_covariance_scaling = gamma
            scaling = (
                f"the smallest achievable scaling of Σ_N against the stopper's gains is γ* = {gamma:.4g}"
                if gamma is not None
                else "the smallest achievable scaling of Σ_N could not be computed"
            )
            outcome.message = (
                f"terminal covariance cannot be met at Jacobi iteration {run.iterations + 1}: {scaling}; "
                "gains shown are the best iterate (smallest residual)"
            )
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
        return self.players.solve(self.spec.method.settings(), self._start_gains(guess))


class CvxpyBackend(LQBackend[CvxpyOptions]):
    """CVXPY with a conic solver chosen by name (``solver: CLARABEL``, ``SCS``, ...)."""

    name: ClassVar[str] = "cvxpy"
    features: ClassVar[frozenset[str]] = frozenset({"mean_steering", "covariance_constraint"})
    options_model = CvxpyOptions
    library: ClassVar[str] = "cvxpy"
    model_class: ClassVar[type[LQCompiledModel]] = CvxpyModel

    @classmethod
    def installed_solvers(cls) -> list[str]:
        import cvxpy as cp

        return list(cp.installed_solvers())

    @classmethod
    def probe_options(cls, options: CvxpyOptions) -> None:
        """Solve ``min (x − 1)² s.t. x ≥ 0`` with the user's solver options; a fallback solver must be
        installed."""
        import cvxpy as cp

        fallback = options.fallback_solver
        if fallback is not None and fallback.upper() not in cls.installed_solvers():
            raise BackendError(f"fallback_solver {fallback!r} is not installed for cvxpy")
        x = cp.Variable()
        try:
            problem = cp.Problem(cp.Minimize(cp.square(x - 1)), [x >= 0])
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                problem.solve(solver=options.solver, **options.solver_options)
        except (TypeError, ValueError) as err:
            raise options.rejected(err) from None
        except cp.SolverError:
            return
