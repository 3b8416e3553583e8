"""Small builders shared by the pursuit tests."""

from __future__ import annotations

import numpy as np

from gamespec.pursuit.simulation import Players


def two_pursuers(p2, strategy: str, *, u2: float = 1.0, v: float = 0.5, eps: float = 1e-3) -> Players:
    """The §2.3 setting: P1 at the origin, E at (1, 0), u1 = 1."""
    return Players(
        names=("P1", "P2"),
        positions=np.array([[0.0, 0.0], p2], dtype=float),
        speeds=np.array([1.0, u2]),
        strategies=(strategy, strategy),
        evader=np.array([1.0, 0.0]),
        v=v,
        eps=eps,
    )
