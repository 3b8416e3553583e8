"""Which solution of the ``lq_stochastic_game`` a Result holds, each player's payoff and its gap.

The game is zero-sum, ``J = J_μ + J_Σ`` (eqs. 4.21, 4.56), the controller minimizing with
``(Ū, K)``, the stopper maximizing with ``(V̄, L)``; the mean and covariance parts separate, so a
player's best response to the other's returned strategies is the pair of its best responses in
each part, and its improvement the sum of the two:

- mean, stopper: eq. 4.39b, ``V̄ = −H_vv⁻¹(H_uvᵀŪ + f_v)``; controller: ``min_Ū J_μ(Ū, V̄)``, subject
  with a target ``μ_N`` to reaching it against the fixed ``V̄`` (the KKT system, least squares where
  the terminal map is deficient);
- covariance, stopper: eq. 4.59b; controller: ``κ = −H_KK⁻¹(g_K + H_KLℓ)`` without ``Σ_N``, with it
  the value of the backend's constrained step (eq. 4.62) at the returned ``ℓ`` (None: not computed).

Concepts: the mean part is a ``saddle`` (Prop. 9) without a target mean and the controller's
**upper value** with one (Prop. 10: the controller commits and the stopper answers, eq. 4.43); the
covariance part is a ``saddle`` (the UCSG closed form, eq. 4.59) or, under ``Σ_N``, the ``nash``
point of Algorithm 2. The Result's concept is ``upper_value`` when the mean part is one, else
``nash`` when the covariance part is, else ``saddle``. A saddle or Nash point is checked by its gap
(``checks.saddle_gap``); an upper value by the follower's improvement alone (``checks.follower_gap``),
the leader's improvement against a fixed follower being no defect of it (it is reported). Both
tolerances are ``method.tolerance · max(1, |J|)``. ``upper_value`` (and ``lower_value`` for a
saddle) is ``J`` where the covariance part is the UCSG saddle; under ``Σ_N`` neither is claimed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from gamespec.lqgame.solution import GameModel

CONTROLLER, STOPPER = "controller", "stopper"


@dataclass(frozen=True)
class Report:
    """Metrics, checks and a message for the Result (see module doc)."""

    metrics: dict
    checks: dict[str, float | None]
    message: str


def mean_improvements(model: GameModel, U: np.ndarray, V: np.ndarray) -> dict[str, float]:
    """Each player's gain in ``J_μ`` by a best response to the other's mean inputs."""
    mean, lifted, game = model.mean, model.lifted, model.game
    value = mean.payoff(U, V)
    rhs = -(mean.free_u + mean.H_uv @ V)
    if game.muN is None:
        U_best = np.linalg.solve(mean.H_uu, rhs)
    else:
        rows = ~np.isnan(game.muN)
        B_N = lifted.terminal(lifted.B)[rows]
        drift = lifted.terminal(lifted.A) @ game.mu0 + lifted.terminal(lifted.C) @ V
        k = B_N.shape[0]
        kkt = np.block([[mean.H_uu, B_N.T], [B_N, np.zeros((k, k))]])
        target = np.concatenate([rhs, game.muN[rows] - drift[rows]])
        U_best = np.linalg.lstsq(kkt, target, rcond=None)[0][: U.size]
    return {
        CONTROLLER: value - mean.payoff(U_best, V),
        STOPPER: mean.payoff(U, mean.stopper_response(U)) - value,
    }


def covariance_improvements(
    model: GameModel, kappa: np.ndarray, ell: np.ndarray, controller_value: float | None
) -> dict[str, float | None]:
    """Each player's gain in ``J_Σ`` by a best response to the other's gains; the controller's
    under ``Σ_N`` from ``controller_value`` (its constrained best response's ``J_Σ``, or None)."""
    cov = model.covariance
    value = cov.payoff(kappa, ell)
    if model.game.SigmaN is None:
        best = np.linalg.solve(cov.H_KK, -(cov.g_K + cov.H_KL @ ell))
        controller_value = cov.payoff(best, ell)
    return {
        CONTROLLER: None if controller_value is None else value - controller_value,
        STOPPER: cov.payoff(kappa, cov.stopper_response(kappa)) - value,
    }


def concepts(model: GameModel) -> dict[str, str]:
    """The concept of the mean part, of the covariance part and of the whole (module doc)."""
    mean = "upper_value" if model.game.muN is not None else "saddle"
    covariance = "nash" if model.game.SigmaN is not None else "saddle"
    whole = "upper_value" if mean == "upper_value" else covariance
    return {"mean": mean, "covariance": covariance, "game": whole}


def report(
    model: GameModel,
    parts: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    controller_value: float | None,
    tolerance: float,
    found: bool,
) -> Report:
    """The Result's concept, payoffs, improvements, gap and its check for the strategies
    ``parts = (Ū, V̄, κ, ℓ)`` (``found``: both parts' solves succeeded)."""
    U, V, kappa, ell = parts
    J = model.mean.payoff(U, V) + model.covariance.payoff(kappa, ell)
    mean = mean_improvements(model, U, V)
    cov = covariance_improvements(model, kappa, ell, controller_value)
    improvements = {p: None if cov[p] is None else float(mean[p] + cov[p]) for p in (CONTROLLER, STOPPER)}
    known = [v for v in improvements.values() if v is not None]
    gap = max(known) if len(known) == 2 else None
    kinds = concepts(model)
    bound = tolerance * max(1.0, abs(J))
    metrics: dict = {
        "solution_concept": kinds["game"] if found else "none",
        "sought_concept": kinds["game"],
        "solution_concepts": {"mean": kinds["mean"], "covariance": kinds["covariance"]},
        "information": "open_loop mean inputs with state-feedback gains (eq. 4.51)",
        "payoffs": {CONTROLLER: float(J), STOPPER: float(J)},
        "improvements": improvements,
        "improvements_by_part": {"mean": mean, "covariance": cov},
        "saddle_gap": gap,
    }
    if found and kinds["covariance"] == "saddle":
        metrics["upper_value"] = float(J)
        if kinds["mean"] == "saddle":
            metrics["lower_value"] = float(J)
    if kinds["game"] == "upper_value":
        name, value = "follower_gap", improvements[STOPPER]
    else:
        name, value = "saddle_gap", gap
    notes = []
    if value is None:
        notes.append(f"{name} not computed: the controller's constrained best response was not solved")
        return Report(metrics, {}, "; ".join(notes))
    passed = bool(value <= bound)
    metrics |= {"checks_passed": {name: passed}, "check_tolerances": {name: bound}}
    if not passed:
        notes.append(f"{name} {value:.3g} exceeds the tolerance {bound:.3g}: a best response gains that much")
    return Report(metrics, {name: value}, "; ".join(notes))
