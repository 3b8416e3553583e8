"""Small random games that meet the assumptions of chapter 4 (eq. 4.27, R, S ≻ 0)."""

from __future__ import annotations

import numpy as np
import pytest

from gamespec.lqgame.solution import GameModel
from gamespec.specs.lq_model import LQGame


def random_game(seed: int, N: int = 4, n: int = 3, m: int = 2, ell: int = 1, r: int = 2) -> LQGame:
    """A time-varying game with a terminal mean and a loose terminal covariance."""
    rng = np.random.default_rng(seed)
    A = np.eye(n) + 0.3 * rng.standard_normal((N, n, n))
    B = rng.standard_normal((N, n, m))
    C = 0.5 * rng.standard_normal((N, n, ell))
    D = 0.1 * rng.standard_normal((N, n, r))
    root0 = 0.3 * rng.standard_normal((n, n))
    return LQGame(
        A=A,
        B=B,
        C=C,
        D=D,
        Q=np.repeat(np.eye(n)[None], N, axis=0),
        R=np.repeat(np.eye(m)[None], N, axis=0),
        S=np.repeat(200 * np.eye(ell)[None], N, axis=0),
        mu0=rng.standard_normal(n),
        Sigma0=root0 @ root0.T + 0.01 * np.eye(n),
        muN=np.zeros(n),
        SigmaN=np.eye(n),
    )


@pytest.fixture(params=[0, 1, 2])
def model(request) -> GameModel:
    return GameModel.build(random_game(request.param))
