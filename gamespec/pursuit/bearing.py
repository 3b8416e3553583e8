"""Line of sight and the pursuers' headings it fixes (eqs. 3.3 and 3.17), vectorized over pursuers.

Pure pursuit heads along the line of sight, θ_i = φ_i. Constant bearing keeps the line of sight's
direction fixed: the pursuer matches the evader's velocity across it, u_i sin(θ_i − φ_i) =
v sin(θ_E − φ_i), with cos(θ_i − φ_i) > 0 so that the distance decreases (eq. 3.3).
"""

from __future__ import annotations

import numpy as np


def line_of_sight_angles(pursuers: np.ndarray, evaders: np.ndarray) -> np.ndarray:
    """φ_i = atan2(y_E − y_i, x_E − x_i) (eq. 3.17): pursuers ``(n, 2)``, evaders ``(2,)`` or ``(n, 2)``."""
    sight = np.asarray(evaders, dtype=float) - np.asarray(pursuers, dtype=float)
    return np.arctan2(sight[..., 1], sight[..., 0])


def constant_bearing_headings(
    los: np.ndarray, pursuer_speeds: np.ndarray, evader_speeds: np.ndarray, evader_headings: np.ndarray
) -> np.ndarray:
    """θ_i = φ_i + asin(v sin(θ_E − φ_i) / u_i) (eq. 3.3); a pursuer at rest (u_i = 0) gets φ_i.
    All arguments broadcast together."""
    u = np.asarray(pursuer_speeds, dtype=float)
    across = np.asarray(evader_speeds, dtype=float) * np.sin(np.asarray(evader_headings) - los)
    ratio = np.divide(across, u, out=np.zeros(np.broadcast(across, u).shape), where=u > 0)
    return los + np.arcsin(np.clip(ratio, -1.0, 1.0))
