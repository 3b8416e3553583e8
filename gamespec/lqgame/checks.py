"""Checks of the assumptions of chapter 4, computed (never assumed) for each game.

- eq. 4.27: ``S̄ − 𝒞ᵀQ̄𝒞 ≻ 0`` (the mean game is concave in the stopper's input);
- Lemma 10: ``rank B̄_N = n`` (controllable without the stopper and the noise);
- eq. 4.40/4.41 and Lemma 11: the relative controllability matrix ``𝒢``, its rank and singular
  values, and whether ``μ_N`` can be reached in the upper game; when not, the directions of the
  state space (and the state components) it cannot reach;
- section 4.4: ``Σ_s ⊗ (ℬᵀQ̄ℬ + R̄) ≻ 0`` and ``Σ_s ⊗ (𝒞ᵀQ̄𝒞 − S̄) ≺ 0`` on the gain structure.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gamespec.lqgame.covariance import CovarianceGame
from gamespec.lqgame.mean_steering import MeanGame


@dataclass(frozen=True)
class Reachability:
    """Lemma 11 for the mean target: ``rank 𝒢``, its singular values, and what cannot be reached."""

    rank: int
    singular_values: list[float]
    reachable: bool
    residual: float
    unreachable_directions: list[list[float]] = field(default_factory=list)
    unreachable_components: list[int] = field(default_factory=list)


@dataclass(frozen=True)
class Assumptions:
    """The computed assumption checks of one game."""

    stopper_concavity_min_eig: float
    controllability_rank: int
    reachability: Reachability
    covariance_convexity_min_eig: float
    covariance_concavity_max_eig: float

    @property
    def saddle_condition(self) -> bool:
        """eq. 4.27 holds."""
        return self.stopper_concavity_min_eig > 0

    def as_metrics(self) -> dict[str, object]:
        """The checks as JSON-able metrics."""
        reach = self.reachability
        return {
            "assumption_4_27_min_eig": self.stopper_concavity_min_eig,
            "controllability_rank": self.controllability_rank,
            "relative_controllability_rank": reach.rank,
            "relative_controllability_singular_values": reach.singular_values,
            "mean_target_reachable": reach.reachable,
            "mean_target_residual": reach.residual,
            "unreachable_directions": reach.unreachable_directions,
            "unreachable_components": reach.unreachable_components,
            "covariance_convexity_min_eig": self.covariance_convexity_min_eig,
            "covariance_concavity_max_eig": self.covariance_concavity_max_eig,
        }


def _rank_tolerance(singular_values: np.ndarray, shape: tuple[int, int]) -> float:
    """numpy's default rank tolerance: ``σ_max · max(shape) · eps``."""
    top = singular_values.max() if singular_values.size else 0.0
    return top * max(shape) * np.finfo(float).eps


def reachability(mean: MeanGame) -> Reachability:
    """Lemma 11 (eq. 4.41): is ``μ_N − drift`` in the range of ``𝒢``? (always, without a target).

    ``rank`` and the singular values are those of the full ``𝒢`` (eq. 4.44); reachability is tested
    on the rows of ``μ_N`` that are given, and unreachable components are state indices.
    """
    G_full, _ = mean.relative_controllability
    sv = np.linalg.svd(G_full, compute_uv=False)
    rank = int((sv > _rank_tolerance(sv, G_full.shape)).sum())
    if mean.game.muN is None:
        return Reachability(rank, sv.tolist(), True, 0.0)
    G, target = mean.target_equation()
    rows = np.flatnonzero(~np.isnan(mean.game.muN))
    U_, sv_rows, _ = np.linalg.svd(G)
    row_rank = int((sv_rows > _rank_tolerance(sv_rows, G.shape)).sum())
    left_null = U_[:, row_rank:]
    missed = left_null.T @ target
    scale = max(np.linalg.norm(target), 1.0)
    significant = np.abs(missed) > 1e-9 * scale
    directions = np.zeros((mean.game.n, int(significant.sum())))
    directions[rows] = left_null[:, significant]
    residual = float(np.linalg.norm(missed))
    components = sorted({int(i) for col in directions.T for i in np.flatnonzero(np.abs(col) > 1e-6)})
    return Reachability(
        rank=rank,
        singular_values=sv.tolist(),
        reachable=not significant.any(),
        residual=residual,
        unreachable_directions=directions.T.tolist(),
        unreachable_components=components,
    )


def check_assumptions(mean: MeanGame, covariance: CovarianceGame) -> Assumptions:
    """All assumption checks of chapter 4 for one game."""
    BN = mean.lifted.terminal(mean.lifted.B)
    return Assumptions(
        stopper_concavity_min_eig=float(np.linalg.eigvalsh(-mean.H_vv).min()),
        controllability_rank=int(np.linalg.matrix_rank(BN)),
        reachability=reachability(mean),
        covariance_convexity_min_eig=float(np.linalg.eigvalsh(covariance.H_KK).min()),
        covariance_concavity_max_eig=float(np.linalg.eigvalsh(covariance.H_LL).max()),
    )
