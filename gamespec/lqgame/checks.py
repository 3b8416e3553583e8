"""Checks of the assumptions of chapter 4, computed (never assumed) for each game.

- eq. 4.27: ``S̄ − 𝒞ᵀQ̄𝒞 ≻ 0`` (the mean game is concave in the stopper's input);
- Lemma 10: ``rank B̄_N = n`` (controllable without the stopper and the noise);
- eq. 4.40/4.41 and Lemma 11: the relative controllability matrix ``𝒢``, its rank and singular
  values, and whether ``μ_N`` can be reached in the upper game; when not, the directions of the
  state space (and the state components) it cannot reach;
- section 4.4: ``Σ_s ⊗ (ℬᵀQ̄ℬ + R̄) ≻ 0`` and ``Σ_s ⊗ (𝒞ᵀQ̄𝒞 − S̄) ≺ 0`` on the gain structure.

Extreme eigenvalues within roundoff of zero are reported as zero, so a singular matrix (the
boundary case of a strict inequality) fails its check rather than passing on a rounding error.

A numerical rank is decided against numpy's tolerance ``τ = σ_max · max(shape) · eps``, an estimate
of the rounding error on the singular values; ``rank_margin = min(σ_r / τ, τ / σ_{r+1})`` says how
far the decision is from that threshold. By Weyl's inequality another machine's rounding moves each
σ by at most ``‖ΔG‖₂``, of the order of ``τ``, so a decision with a margin above 10 is the same on
any machine and one below it is the rounding's (the missile endgame's rank 3 of 𝒢 has a margin
above 10⁵: ``σ_4 ≈ 10⁻²⁰`` against ``τ ≈ 1.6·10⁻¹⁵``, ``σ_3 ≈ 0.04``).
Without eq. 4.27 the stopper has no best response (eq. 4.39b), so ``𝒢`` and Lemma 11 are not
computed.
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
    rank_margin: float
    unreachable_directions: list[list[float]] = field(default_factory=list)
    unreachable_components: list[int] = field(default_factory=list)


@dataclass(frozen=True)
class Assumptions:
    """The computed assumption checks of one game."""

    stopper_concavity_min_eig: float
    controllability_rank: int
    reachability: Reachability | None
    covariance_convexity_min_eig: float
    covariance_concavity_max_eig: float

    @property
    def saddle_condition(self) -> bool:
        """eq. 4.27 holds."""
        return self.stopper_concavity_min_eig > 0

    def as_metrics(self) -> dict[str, object]:
        """The checks as JSON-able metrics (without Lemma 11's when eq. 4.27 fails)."""
        metrics: dict[str, object] = {
            "assumption_4_27_min_eig": self.stopper_concavity_min_eig,
            "controllability_rank": self.controllability_rank,
            "covariance_convexity_min_eig": self.covariance_convexity_min_eig,
            "covariance_concavity_max_eig": self.covariance_concavity_max_eig,
        }
        reach = self.reachability
        if reach is not None:
            metrics |= {
                "relative_controllability_rank": reach.rank,
                "relative_controllability_singular_values": reach.singular_values,
                "relative_controllability_rank_margin": reach.rank_margin,
                "mean_target_reachable": reach.reachable,
                "mean_target_residual": reach.residual,
                "unreachable_directions": reach.unreachable_directions,
                "unreachable_components": reach.unreachable_components,
            }
        return metrics


def _rank_tolerance(singular_values: np.ndarray, shape: tuple[int, int]) -> float:
    """numpy's default rank tolerance: ``σ_max · max(shape) · eps``."""
    top = singular_values.max() if singular_values.size else 0.0
    return top * max(shape) * np.finfo(float).eps


def numerical_rank(singular_values: np.ndarray, shape: tuple[int, int]) -> tuple[int, float]:
    """The rank at numpy's tolerance ``τ`` and its margin ``min(σ_r / τ, τ / σ_{r+1})`` (infinite
    for a zero matrix or where no σ lies on that side)."""
    tolerance = _rank_tolerance(singular_values, shape)
    kept = singular_values[singular_values > tolerance]
    dropped = singular_values[singular_values <= tolerance]
    above = kept.min() / tolerance if kept.size else np.inf
    below = tolerance / dropped.max() if dropped.size and dropped.max() > 0 else np.inf
    return int(kept.size), float(min(above, below))


def extreme_eigenvalue(M: np.ndarray, largest: bool = False) -> float:
    """The smallest (or largest) eigenvalue of the symmetric ``M``; zero when within roundoff of
    it (``|λ| ≤ size · eps · max|λ|``, numpy's rank tolerance)."""
    eigenvalues = np.linalg.eigvalsh(M)
    value = float(eigenvalues[-1] if largest else eigenvalues[0])
    return 0.0 if abs(value) <= _rank_tolerance(np.abs(eigenvalues), M.shape) else value


def reachability(mean: MeanGame) -> Reachability:
    """Lemma 11 (eq. 4.41): is ``μ_N − drift`` in the range of ``𝒢``? (always, without a target).

    ``rank`` and the singular values are those of the full ``𝒢`` (eq. 4.44); reachability is tested
    on the rows of ``μ_N`` that are given, and unreachable components are state indices.
    ``rank_margin`` is the smaller of the two rank decisions' margins (:func:`numerical_rank`).
    """
    G_full, _ = mean.relative_controllability
    sv = np.linalg.svd(G_full, compute_uv=False)
    rank, margin = numerical_rank(sv, G_full.shape)
    if mean.game.muN is None:
        return Reachability(rank, sv.tolist(), True, 0.0, margin)
    G, target = mean.target_equation()
    rows = np.flatnonzero(~np.isnan(mean.game.muN))
    U_, sv_rows, _ = np.linalg.svd(G)
    row_rank, row_margin = numerical_rank(sv_rows, G.shape)
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
        rank_margin=min(margin, row_margin),
        unreachable_directions=directions.T.tolist(),
        unreachable_components=components,
    )


def check_assumptions(mean: MeanGame, covariance: CovarianceGame) -> Assumptions:
    """All assumption checks of chapter 4 for one game."""
    BN = mean.lifted.terminal(mean.lifted.B)
    stopper_concavity = extreme_eigenvalue(-mean.H_vv)
    return Assumptions(
        stopper_concavity_min_eig=stopper_concavity,
        controllability_rank=int(np.linalg.matrix_rank(BN)),
        reachability=reachability(mean) if stopper_concavity > 0 else None,
        covariance_convexity_min_eig=extreme_eigenvalue(covariance.H_KK),
        covariance_concavity_max_eig=extreme_eigenvalue(covariance.H_LL, largest=True),
    )
