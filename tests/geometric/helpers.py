"""Random pursuit configurations shared by the geometric tests."""

from __future__ import annotations

import numpy as np


def random_team(seed: int, n: int, heterogeneous: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """``n`` pursuers around an evader, with speeds that satisfy eq. 3.29."""
    rng = np.random.default_rng(seed)
    pursuers = rng.uniform(-10, 10, (n, 2))
    evader = rng.uniform(-3, 3, 2)
    speeds = rng.uniform(1.0, 2.0, n) if heterogeneous else np.ones(n)
    return pursuers, evader, speeds, float(rng.uniform(0.1, 0.95))
