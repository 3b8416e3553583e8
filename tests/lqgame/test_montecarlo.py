"""Monte Carlo: the closed loop's sample mean and covariance agree with the propagated ones
(eq. 4.18, 4.54) within sampling error, and a wrong prediction is caught."""

from __future__ import annotations

import numpy as np

from gamespec.lqgame.covariance import vector_to_gains
from gamespec.lqgame.game import Strategies
from gamespec.lqgame.montecarlo import agreement, simulate
from gamespec.lqgame.solution import GameModel
from tests.lqgame.conftest import random_game

Z_BOUND = 5.0
"""Largest z-score accepted among a few hundred compared entries (a 5σ miss has odds ~1e-6 each)."""


def _strategies(model: GameModel) -> Strategies:
    g = model.game
    U, V = model.mean.upper_game()
    kappa, ell = model.covariance.unconstrained_saddle()
    return Strategies(
        U.reshape(g.N, g.m),
        V.reshape(g.N, g.ell),
        vector_to_gains(kappa, g.m, g.n),
        vector_to_gains(ell, g.ell, g.n),
    )


def test_samples_match_propagated_statistics():
    model = GameModel.build(random_game(9, N=6))
    strategies = _strategies(model)
    samples = simulate(model.game, strategies, samples=4000, seed=1)
    means = model.mean.trajectory(strategies.U.ravel(), strategies.V.ravel())
    covs = model.covariance.state_covariances(strategies.K, strategies.L)
    fit = agreement(samples, means, covs)
    assert fit.mean_z < Z_BOUND
    assert fit.covariance_z < Z_BOUND


def test_agreement_catches_a_wrong_prediction():
    model = GameModel.build(random_game(10, N=6))
    strategies = _strategies(model)
    samples = simulate(model.game, strategies, samples=4000, seed=2)
    means = model.mean.trajectory(strategies.U.ravel(), strategies.V.ravel())
    covs = model.covariance.state_covariances(strategies.K, strategies.L)
    assert agreement(samples, means, 1.3 * covs).covariance_z > Z_BOUND
    assert agreement(samples, means + 0.1 * np.sqrt(covs[:, 0, 0])[:, None], covs).mean_z > Z_BOUND
