"""Monte Carlo: the closed loop's sample mean and covariance agree with the propagated ones
(eq. 4.18, 4.54) within sampling error, and a wrong prediction is caught."""

from __future__ import annotations

import numpy as np

from gamespec.lqgame.covariance import vector_to_gains
from gamespec.lqgame.montecarlo import agreement, simulate
from gamespec.lqgame.solution import GameModel
from gamespec.specs.lq_model import Strategies
from tests.lqgame.conftest import random_game

Z_BOUND = 5.0
"""Largest z-score accepted among a few hundred compared entries (a 5σ miss has odds ~1e-6 each)."""


def _sampled(game_seed: int, sample_seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """4000 closed-loop samples of a random game under its saddle-point strategies, with the
    propagated means (eq. 4.18) and covariances (eq. 4.54)."""
    model = GameModel.build(random_game(game_seed, N=6))
    g = model.game
    U, V = model.mean.upper_game()
    kappa, ell = model.covariance.unconstrained_saddle()
    K, L = vector_to_gains(kappa, g.m, g.n), vector_to_gains(ell, g.ell, g.n)
    samples = simulate(g, Strategies(U.reshape(g.N, g.m), V.reshape(g.N, g.ell), K, L), 4000, sample_seed)
    return samples, model.mean.trajectory(U, V), model.covariance.state_covariances(K, L)


def test_samples_match_propagated_statistics():
    fit = agreement(*_sampled(9, 1))
    assert fit.mean_z < Z_BOUND
    assert fit.covariance_z < Z_BOUND


def test_agreement_catches_a_wrong_prediction():
    samples, means, covs = _sampled(10, 2)
    assert agreement(samples, means, 1.3 * covs).covariance_z > Z_BOUND
    assert agreement(samples, means + 0.1 * np.sqrt(covs[:, 0, 0])[:, None], covs).mean_z > Z_BOUND
