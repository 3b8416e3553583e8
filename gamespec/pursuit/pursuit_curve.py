"""Pure pursuit of a non-maneuvering evader in closed form: the classical pursuit curve (eq. 2.5).

With ``α`` the angle from a pure-pursuit pursuer's line of sight to the evader's (constant) velocity,
eq. 2.1 gives ``ṙ = v cos α − u`` and ``r α̇ = −v sin α``. Two integrals follow:

- ``d/dt [r (u + v cos α)] = v² − u²``, so ``r (u + v cos α) = r0 (u + v cos α0) − (u² − v²) t``
  (the invariant behind eq. 2.5, which is its value at ``r = 0``);
- ``d ln r / dα = (u − v cos α) / (v sin α)``, so with ``w = ln tan(|α| / 2)``:
  ``r = r0 sin|α0| e^{k (w − w0)} cosh w`` and ``u + v cos α = u − v tanh w``, ``k = u / v``.

``L(w) = r (u + v cos α)`` has ``d ln L / dw`` between ``k − 1`` and ``k + 1``, positive for
``u > v``, so the ``w`` of any time (and of ``r = ε``) is found by bisection in a bracket of known
width, to round-off; ``|α|`` falls monotonically to 0 (tail chase). At ``sin α0 = 0`` the chase is
along the line of sight: ``r = r0 + (v cos α0 − u) t``. Pursuers move independently of each other
against a constant heading, so the capture time of a team is the least of theirs.
"""

from __future__ import annotations

import numpy as np

from gamespec.errors import UnsupportedFeature
from gamespec.pursuit.simulation import Players, Trajectory

_BISECTIONS = 64


def _log_rate(w: np.ndarray, k: float, u: np.ndarray, v: float) -> np.ndarray:
    """``ln(u cosh w − v sinh w) − k w`` written to stay finite for large ``|w|``."""
    return np.logaddexp(np.log(u - v) + w, np.log(u + v) - w) - np.log(2.0) + k * w


def _solve_w(
    w0: np.ndarray, log_target: np.ndarray, k: np.ndarray, u: np.ndarray, v: float, shape: str
) -> np.ndarray:
    """The ``w <= w0`` at which ``ln L(w) - ln L(w0) = log_target`` (``<= 0``), by bisection.

    ``shape="rate"``: ``L = cosh w (u − v tanh w) e^{k w}``; ``shape="distance"``: ``L = cosh w e^{k w}``
    (``d ln L / dw`` is at least ``k − 1`` for both, which sets the bracket).
    """

    def log_l(w):
        if shape == "rate":
            return _log_rate(w, k, u, v)
        return np.logaddexp(w, -w) - np.log(2.0) + k * w

    base = log_l(w0)
    hi = np.broadcast_to(w0, np.shape(log_target)).astype(float)
    lo = hi + log_target / (k - 1) - 1.0
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        above = log_l(mid) - base > log_target
        hi = np.where(above, mid, hi)
        lo = np.where(above, lo, mid)
    return 0.5 * (lo + hi)


def constant_heading_pursuit(players: Players, heading: float, *, samples: int = 400) -> Trajectory:
    """Pure-pursuit pursuers against an evader on a constant heading, to capture: the trajectory that
    :func:`~gamespec.pursuit.simulation.simulate_to_capture` integrates, in closed form (module doc)."""
    if any(s != "pp" for s in players.strategies):
        raise UnsupportedFeature("the closed-form pursuit curve needs every pursuer on pp")
    u, v, eps = players.speeds, players.v, players.eps
    r0 = players.distances()
    phi0 = players.los_angles()
    alpha0 = np.angle(np.exp(1j * (heading - phi0)))
    side = np.where(alpha0 < 0, -1.0, 1.0)
    a0 = np.abs(alpha0)
    straight = np.sin(a0) == 0
    w0 = np.log(np.tan(np.where(straight, 1.0, a0) / 2))
    k = u / v

    w_capture = _solve_w(w0, np.log(eps / r0), k, u, v, "distance")
    cos_capture = -np.tanh(w_capture)
    invariant = r0 * (u + v * np.cos(a0))
    curved_time = (invariant - eps * (u + v * cos_capture)) / (u**2 - v**2)
    straight_time = (r0 - eps) / (u - v * np.cos(a0))
    times = np.where(straight, straight_time, curved_time)
    t_capture = float(np.min(times))

    time = np.linspace(0.0, t_capture, samples)
    left = invariant[None, :] - (u**2 - v**2)[None, :] * time[:, None]
    w = _solve_w(w0, np.log(left / invariant), k, u, v, "rate")
    rate = np.exp(_log_rate(w, k, u, v) - _log_rate(w0, k, u, v))
    curved_r = invariant * rate / (u - v * np.tanh(w))
    r = np.where(straight, r0 + (v * np.cos(a0) - u) * time[:, None], curved_r)
    alpha = np.where(straight, alpha0, side * 2 * np.arctan(np.exp(w)))
    evader = players.evader + v * time[:, None] * np.array([np.cos(heading), np.sin(heading)])
    los = heading - alpha
    pursuers = evader[:, None, :] - r[..., None] * np.stack([np.cos(los), np.sin(los)], axis=-1)
    return Trajectory(time, pursuers, evader, np.full(samples, float(heading)), captured=True)
