"""What every backend of the ``lq_stochastic_game`` kind shares: the game built once, and the Result.

A backend supplies the mean steering solution (a QP, section 4.3) and the covariance gains
(eq. 4.59 or Algorithm 2, section 4.4); :func:`assemble` joins them by Props. 7–8
(``U = Ū + K y``), recomputes the terminal statistics and the closed-form gap, and packs the
Result; the Monte Carlo check is the kind's ``monte_carlo`` analysis
(:data:`gamespec.lqgame.montecarlo.ANALYSES`). :mod:`gamespec.compiling.lq` drives these steps for
every backend.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gamespec.lqgame.checks import Assumptions, check_assumptions
from gamespec.lqgame.covariance import CovarianceGame, vector_to_gains
from gamespec.lqgame.equilibrium import report
from gamespec.lqgame.lifting import Lifted, lift
from gamespec.lqgame.mean_steering import MeanGame
from gamespec.result import Result, Status
from gamespec.specs.lq_model import LQGame, Strategies


@dataclass
class GameModel:
    """A game with its lifted matrices, mean and covariance games and assumption checks, built once."""

    game: LQGame
    lifted: Lifted
    mean: MeanGame
    covariance: CovarianceGame
    assumptions: Assumptions

    @classmethod
    def build(cls, game: LQGame) -> GameModel:
        lifted = lift(game)
        mean = MeanGame(game, lifted)
        covariance = CovarianceGame(game, lifted)
        return cls(game, lifted, mean, covariance, check_assumptions(mean, covariance))

    def assumption_failure(self) -> str | None:
        """Why the game violates the convexity–concavity assumptions of chapter 4, or None."""
        a = self.assumptions
        if not a.saddle_condition:
            return f"eq. 4.27 fails: λ_min(S̄ − 𝒞ᵀQ̄𝒞) = {a.stopper_concavity_min_eig:.3g} ≤ 0"
        if a.covariance_convexity_min_eig <= 0:
            return "J_Σ is not strictly convex in K (Σ_s ⊗ (ℬᵀQ̄ℬ + R̄) on the gain structure)"
        if a.covariance_concavity_max_eig >= 0:
            return "J_Σ is not strictly concave in L (Σ_s ⊗ (𝒞ᵀQ̄𝒞 − S̄) on the gain structure)"
        return None

    def unreachable_mean(self) -> str | None:
        """Lemma 11's verdict on the terminal mean as a message, or None when it can be reached."""
        reach = self.assumptions.reachability
        if reach is None or reach.reachable:
            return None
        return (
            f"terminal mean unreachable in the upper game (Lemma 11): rank 𝒢 = {reach.rank}, "
            f"state components {reach.unreachable_components} cannot be steered "
            f"(residual {reach.residual:.3g}); mean shown reaches the target's reachable part"
        )


@dataclass
class MeanOutcome:
    """Stacked mean inputs ``Ū``, ``V̄``, how the solve went and the solver's own residuals."""

    U: np.ndarray
    V: np.ndarray
    status: Status
    message: str = ""
    iterations: int | None = None
    solve_time_s: float = 0.0
    checks: dict[str, float | None] = field(default_factory=dict)


@dataclass
class CovarianceOutcome:
    """Vectorized gains ``κ``, ``ℓ`` (see :mod:`gamespec.lqgame.covariance`) and how they were found:
    ``history`` holds ``(ε_k, ε_ℓ)`` per iteration, ``best_response`` the engine's metrics
    (:meth:`~gamespec.best_response.BestResponseRun.as_metrics`) when Algorithm 2 ran."""

    kappa: np.ndarray
    ell: np.ndarray
    status: Status
    method: str
    message: str = ""
    iterations: int | None = None
    history: list[tuple[float, float]] = field(default_factory=list)
    min_covariance_scaling: float | None = None
    solve_time_s: float = 0.0
    best_response: dict[str, object] | None = None
    controller_value: float | None = None
    """``J_Σ`` of the controller's constrained best response (eq. 4.62) to the returned ``ℓ``, when
    the backend solved it (the saddle/Nash gap needs it under ``Σ_N``)."""


def unconstrained_covariance(model: GameModel, note: str = "") -> CovarianceOutcome:
    """The UCSG gains of eq. 4.59 (closed form)."""
    kappa, ell = model.covariance.unconstrained_saddle()
    return CovarianceOutcome(kappa, ell, Status.OPTIMAL, "unconstrained saddle (eq. 4.59)", note)


def fallback_mean(model: GameModel, status: Status, message: str) -> MeanOutcome:
    """Prop. 10's closed form (least squares where 𝒢 is deficient) with a failed status."""
    U, V = model.mean.upper_game()
    return MeanOutcome(U, V, status, message)


def _combined_status(mean: MeanOutcome, cov: CovarianceOutcome) -> Status:
    """The first failed part's status; else ``feasible`` if either part is, else ``optimal``."""
    for status in (mean.status, cov.status):
        if not status.ok:
            return status
    return Status.OPTIMAL if Status.FEASIBLE not in (mean.status, cov.status) else Status.FEASIBLE


def assemble(
    model: GameModel,
    mean: MeanOutcome,
    cov: CovarianceOutcome,
    state_names: list[str],
    tolerance: float = 1e-5,
) -> Result:
    """The Result of one solve, with checks recomputed from the strategies (not from the solver),
    and which solution it is (:mod:`gamespec.lqgame.equilibrium`, gap tolerance ``tolerance``
    relative to ``max(1, |J|)``).

    ``iterations`` is Algorithm 2's count when it ran, else the mean QP solver's count (None when
    the solver does not say); ``metrics.iterations`` is Algorithm 2's count alone.
    """
    game = model.game
    N, n = game.N, game.n
    K = vector_to_gains(cov.kappa, game.m, n)
    L = vector_to_gains(cov.ell, game.ell, n)
    strategies = Strategies(mean.U.reshape(N, game.m), mean.V.reshape(N, game.ell), K, L)
    means = model.mean.trajectory(mean.U, mean.V)
    covariances = model.covariance.state_covariances(K, L)
    closed_U, _ = model.mean.upper_game()
    checks: dict[str, float | None] = {
        **mean.checks,
        "mean_closed_form_gap": float(np.max(np.abs(mean.U - closed_U))),
        "stopper_response_gap": float(np.max(np.abs(cov.ell - model.covariance.stopper_response(cov.kappa)))),
    }
    metrics: dict[str, object] = {
        "terminal_mean": means[-1].tolist(),
        "terminal_covariance": covariances[-1].tolist(),
        "iterations": cov.iterations,
        "covariance_game": cov.method,
        "convergence_history": [list(h) for h in cov.history],
        "mean_payoff": model.mean.payoff(mean.U, mean.V),
        "covariance_payoff": model.covariance.payoff(cov.kappa, cov.ell),
        **model.assumptions.as_metrics(),
    }
    found = mean.status.ok and cov.status.ok
    solution = report(model, (mean.U, mean.V, cov.kappa, cov.ell), cov.controller_value, tolerance, found)
    metrics |= solution.metrics
    checks |= solution.checks
    arrays: dict[str, np.ndarray] = {"mean": means, "covariance": covariances, "K": K, "L": L}
    if game.muN is not None:
        given = ~np.isnan(game.muN)
        metrics["target_mean"] = [float(v) if ok else None for v, ok in zip(game.muN, given, strict=True)]
        checks["terminal_mean_error"] = float(np.max(np.abs(means[-1][given] - game.muN[given]), initial=0.0))
        arrays["target_mean"] = game.muN
    if game.SigmaN is not None:
        metrics["target_covariance"] = game.SigmaN.tolist()
        excess = np.linalg.eigvalsh(covariances[-1] - game.SigmaN).max()
        checks["terminal_covariance_violation"] = float(max(excess, 0.0))
        arrays["target_covariance"] = game.SigmaN
    violations = [checks[k] for k in ("terminal_mean_error", "terminal_covariance_violation") if k in checks]
    if violations:
        checks["max_constraint_violation"] = max(violations)
    if cov.best_response is not None:
        metrics["best_response"] = cov.best_response
    if cov.min_covariance_scaling is not None:
        metrics["min_covariance_scaling"] = cov.min_covariance_scaling
    if cov.history:
        arrays["convergence_history"] = np.array(cov.history)
    time = np.arange(N + 1) * game.dt
    controls = {f"u{i + 1}": strategies.U[:, i] for i in range(game.m)}
    controls |= {f"v{i + 1}": strategies.V[:, i] for i in range(game.ell)}
    return Result(
        status=_combined_status(mean, cov),
        message="; ".join(m for m in (mean.message, cov.message, solution.message) if m),
        objective=metrics["mean_payoff"] + metrics["covariance_payoff"],
        t_final=float(time[-1]),
        solve_time_s=mean.solve_time_s + cov.solve_time_s,
        iterations=cov.iterations if cov.iterations is not None else mean.iterations,
        time=time,
        control_time=time[:-1],
        states={name: means[:, i] for i, name in enumerate(state_names)},
        controls=controls,
        arrays=arrays,
        checks=checks,
        metrics=metrics,
    )
