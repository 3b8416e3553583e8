"""Monte Carlo check of a solution: sample ``x_0`` and the noise, run the closed loop, and compare the
sample mean and covariance with the propagated ones (eq. 4.18 and 4.54). It is the
``lq_stochastic_game`` kind's ``monte_carlo`` analysis (:data:`ANALYSES`, in the
``gamespec.analyses`` entry-point group), run on the Result after the solve.

The players use ``u_k = ū_k + K_k y_k``, ``v_k = v̄_k + L_k y_k`` with ``y`` the noise-only state of
eq. 4.52, simulated alongside ``x`` with the same draws. The draws come from the Monte Carlo engine
(:mod:`gamespec.montecarlo`): ``x_0 ~ N(μ_0, Σ_0)`` and standard normal noise per step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gamespec.analyses import Analysis, Outputs
from gamespec.montecarlo import MultivariateNormal, Normal, sample
from gamespec.result import Result
from gamespec.specs.lq_game import LQGameSpec
from gamespec.specs.lq_model import LQGame, Strategies


def simulate(game: LQGame, strategies: Strategies, samples: int, seed: int = 0) -> np.ndarray:
    """Closed-loop trajectories of eq. 4.1 for ``samples`` draws, as an array (samples, N+1, n)."""
    draws = sample(
        {"x0": MultivariateNormal(game.mu0, game.Sigma0), "noise": Normal(0.0, 1.0, shape=(game.N, game.r))},
        samples,
        seed,
    )
    x = draws["x0"]
    y = x - game.mu0
    out = np.empty((samples, game.N + 1, game.n))
    out[:, 0] = x
    for k in range(game.N):
        u = strategies.U[k] + y @ strategies.K[k].T
        v = strategies.V[k] + y @ strategies.L[k].T
        noise = draws["noise"][:, k] @ game.D[k].T
        x = x @ game.A[k].T + u @ game.B[k].T + v @ game.C[k].T + noise
        y = y @ game.A[k].T + noise
        out[:, k + 1] = x
    return out


@dataclass(frozen=True)
class SampleAgreement:
    """Largest deviations of sample statistics from the predicted ones, in standard errors."""

    mean_z: float
    covariance_z: float


def agreement(trajectories: np.ndarray, mean: np.ndarray, covariance: np.ndarray) -> SampleAgreement:
    """Largest ``|sample − predicted| / standard error`` over steps and entries.

    Standard errors for ``M`` Gaussian samples: ``sqrt(Σ_ii / M)`` for a mean, and
    ``sqrt((Σ_ii Σ_jj + Σ_ij²) / M)`` for a covariance entry. Entries with zero predicted spread
    (e.g. a deterministic start) are compared on an absolute floor of 1e-12.
    """
    M = trajectories.shape[0]
    sample_mean = trajectories.mean(axis=0)
    centred = trajectories - sample_mean
    sample_cov = np.einsum("sti,stj->tij", centred, centred) / (M - 1)
    var = np.einsum("tii->ti", covariance)
    mean_se = np.sqrt(np.maximum(var, 1e-24) / M)
    cov_se = np.sqrt((var[:, :, None] * var[:, None, :] + covariance**2 + 1e-24) / M)
    return SampleAgreement(
        mean_z=float(np.max(np.abs(sample_mean - mean) / mean_se)),
        covariance_z=float(np.max(np.abs(sample_cov - covariance) / cov_se)),
    )


def closed_loop_check(result: Result, spec: LQGameSpec, inverse: None = None) -> Outputs:
    """The ``monte_carlo`` analysis: ``method.monte_carlo.samples`` closed-loop trajectories under
    the Result's strategies (``u{i}``, ``v{j}``, ``arrays.K``, ``arrays.L``) for the game at its
    parameters, and their agreement with ``arrays.mean`` and ``arrays.covariance`` in standard
    errors (``checks.monte_carlo_mean_z``, ``checks.monte_carlo_covariance_z``); nothing for
    fewer than two samples."""
    carlo = spec.method.monte_carlo
    if carlo.samples <= 1 or "K" not in result.arrays:
        return Outputs()
    game = spec.game(result.parameters)
    U = np.column_stack([result.controls[f"u{i + 1}"] for i in range(game.m)])
    V = np.column_stack([result.controls[f"v{j + 1}"] for j in range(game.ell)])
    trajectories = simulate(
        game, Strategies(U, V, result.arrays["K"], result.arrays["L"]), carlo.samples, carlo.seed
    )
    fit = agreement(trajectories, result.arrays["mean"], result.arrays["covariance"])
    return Outputs(
        metrics={"monte_carlo": {"samples": carlo.samples, "seed": carlo.seed}},
        checks={"monte_carlo_mean_z": fit.mean_z, "monte_carlo_covariance_z": fit.covariance_z},
        arrays={"samples": trajectories},
    )


ANALYSES = (
    Analysis(
        "monte_carlo",
        closed_loop_check,
        "closed-loop samples against the propagated mean and covariance (eqs. 4.18, 4.54)",
    ),
)
"""The ``lq_stochastic_game`` kind's analyses (the z-scores have no tolerance: no check of the status)."""
