"""Apollonius circles of pursuers against one evader (§2.3.1, §2.4.4 Fig. 2.7, §3.3), vectorized.

The Apollonius circle of pursuer ``i`` on constant bearing is the locus of capture points of a
non-maneuvering evader: ``|X - e| / v = |X - p_i| / u_i``; its disk holds the evader. With
``rho = v / u_i`` its centre is ``(e - rho**2 p_i) / (1 - rho**2)`` and its radius
``rho |p_i - e| / (1 - rho**2)``. §2.3.1 gives it with P1 at the origin and E at (d, 0): centre
``u1**2 d / (u1**2 - v**2)``, radius ``u1 v d / (u1**2 - v**2)``, the same circle. §3.3 prints the
centre as ``(e - rho p_i) / (1 - rho**2)``, a misprint: only ``rho**2`` puts the circle through its
closest point to the evader, ``T_i = (e + rho p_i) / (1 + rho)`` (§3.3, Lemma 3's proof), at
distance ``v |p_i - e| / (u_i + v)`` from it.

Positions are ``(n, 2)`` arrays, the evader a ``(2,)`` array, pursuer speeds ``(n,)`` (heterogeneous
teams, §3.5) and the evader speed a scalar.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ApolloniusCircles:
    """The Apollonius circles of ``n`` pursuers against one evader: centres ``(n, 2)``, radii
    ``(n,)`` and the points ``T_i`` closest to the evader ``(n, 2)``."""

    centers: np.ndarray
    radii: np.ndarray
    closest_points: np.ndarray


def apollonius_circles(
    pursuers: np.ndarray, evader: np.ndarray, pursuer_speeds: np.ndarray, evader_speed: float
) -> ApolloniusCircles:
    """Centre, radius and closest point ``T_i`` of every pursuer's Apollonius circle (module doc)."""
    pursuers = np.asarray(pursuers, dtype=float)
    evader = np.asarray(evader, dtype=float)
    rho = evader_speed / np.asarray(pursuer_speeds, dtype=float)[:, None]
    distance = np.linalg.norm(pursuers - evader, axis=1)
    centers = (evader - rho**2 * pursuers) / (1.0 - rho**2)
    radii = rho[:, 0] * distance / (1.0 - rho[:, 0] ** 2)
    closest = (evader + rho * pursuers) / (1.0 + rho)
    return ApolloniusCircles(centers, radii, closest)
