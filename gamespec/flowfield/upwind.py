"""One-sided (upwind) approximations of ∂φ/∂x_i on a uniform grid: first order, ENO2 and WENO5.

After hj_reachability's ``finite_differences/upwind_first.py``: each scheme maps the node values and
an axis to the pair ``(D⁻φ, D⁺φ)`` of left- and right-biased derivatives at every node. The grid is
padded with ghost nodes by linear extrapolation (a front leaving the box is reported by the solver,
not fixed here). ENO2 and WENO5 follow Osher & Fedkiw, *Level Set Methods*, §3.3–3.4.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

GHOSTS = 3


def _padded_differences(phi: np.ndarray, axis: int, dx: float) -> np.ndarray:
    """First differences ``d_j = (φ_{j+1} − φ_j)/dx`` along ``axis`` (moved to the front) of the
    array padded with ``GHOSTS`` linearly extrapolated nodes on each side: ``d[j + GHOSTS]`` is the
    difference at ``j + 1/2``, ``d`` has ``n + 2·GHOSTS − 1`` entries."""
    v = np.moveaxis(phi, axis, 0)
    steps = np.arange(1, GHOSTS + 1).reshape((-1,) + (1,) * (v.ndim - 1))
    low = v[0] - steps[::-1] * (v[1] - v[0])
    high = v[-1] + steps * (v[-1] - v[-2])
    return np.diff(np.concatenate([low, v, high]), axis=0) / dx


def _first_order(d: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    g = GHOSTS
    return d[g - 1 : g - 1 + n], d[g : g + n]


def _smaller(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.where(np.abs(a) <= np.abs(b), a, b)


def _eno2(d: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """ENO2: the first difference plus half the smaller (in magnitude) second difference."""
    g = GHOSTS
    dd = np.diff(d, axis=0)  # dd[q − 1]: the change of d across padded node q
    left = d[g - 1 : g - 1 + n] + 0.5 * _smaller(dd[g - 2 : g - 2 + n], dd[g - 1 : g - 1 + n])
    right = d[g : g + n] - 0.5 * _smaller(dd[g - 1 : g - 1 + n], dd[g : g + n])
    return left, right


def _weno5(d: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Jiang–Peng WENO5 (Osher & Fedkiw eq. 3.28–3.39) for both sides at once.

    Every quantity of a stencil of three consecutive differences ``(d_j, d_{j+1}, d_{j+2})`` is
    computed once per ``j`` and shared: the right-biased derivative at node i uses the left-biased
    stencils of nodes i+1 … i+3 read backwards, whose smoothness indicators are the same numbers.
    """
    g = GHOSTS
    a, b, c = d[:-2], d[1:-1], d[2:]
    curvature = 13 / 12 * (a - 2 * b + c) ** 2
    rising = curvature + 0.25 * (a - 4 * b + 3 * c) ** 2
    falling = curvature + 0.25 * (3 * a - 4 * b + c) ** 2
    middle = curvature + 0.25 * (a - c) ** 2
    forward = a / 3 - 7 * b / 6 + 11 * c / 6
    backward = 11 * a / 6 - 7 * b / 6 + c / 3
    centre_left = -a / 6 + 5 * b / 6 + c / 3
    centre_right = a / 3 + 5 * b / 6 - c / 6
    square = d * d
    widest = np.maximum(
        np.maximum(np.maximum(square[:-4], square[1:-3]), np.maximum(square[2:-2], square[3:-1])), square[4:]
    )
    eps = 1e-6 * widest + 1e-99

    def combine(
        s1: np.ndarray,
        s2: np.ndarray,
        s3: np.ndarray,
        p1: np.ndarray,
        p2: np.ndarray,
        p3: np.ndarray,
        e: np.ndarray,
    ) -> np.ndarray:
        w1, w2, w3 = 0.1 / (s1 + e) ** 2, 0.6 / (s2 + e) ** 2, 0.3 / (s3 + e) ** 2
        return (w1 * p1 + w2 * p2 + w3 * p3) / (w1 + w2 + w3)

    def at(q: np.ndarray, j: int) -> np.ndarray:
        """``q`` of the stencil starting at padded difference ``j + i`` for every node i."""
        return q[j : j + n]

    left = combine(
        at(rising, g - 3),
        at(middle, g - 2),
        at(falling, g - 1),
        at(forward, g - 3),
        at(centre_left, g - 2),
        at(centre_right, g - 1),
        at(eps, g - 3),
    )
    right = combine(
        at(falling, g),
        at(middle, g - 1),
        at(rising, g - 2),
        at(backward, g),
        at(centre_right, g - 1),
        at(centre_left, g - 2),
        at(eps, g - 2),
    )
    return left, right


SCHEMES: dict[str, Callable[[np.ndarray, int], tuple[np.ndarray, np.ndarray]]] = {
    "first_order": _first_order,
    "eno2": _eno2,
    "weno5": _weno5,
}


def derivatives(phi: np.ndarray, axis: int, dx: float, scheme: str) -> tuple[np.ndarray, np.ndarray]:
    """``(D⁻φ, D⁺φ)`` along ``axis`` at every node, by ``scheme`` (a key of :data:`SCHEMES`)."""
    n = phi.shape[axis]
    left, right = SCHEMES[scheme](_padded_differences(phi, axis, dx), n)
    return np.moveaxis(left, 0, axis), np.moveaxis(right, 0, axis)
