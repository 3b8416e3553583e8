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


def _weno5_combination(
    v1: np.ndarray, v2: np.ndarray, v3: np.ndarray, v4: np.ndarray, v5: np.ndarray
) -> np.ndarray:
    """Jiang–Peng WENO5 weights on the three ENO3 candidates (Osher & Fedkiw eq. 3.28–3.39)."""
    p1 = v1 / 3 - 7 * v2 / 6 + 11 * v3 / 6
    p2 = -v2 / 6 + 5 * v3 / 6 + v4 / 3
    p3 = v3 / 3 + 5 * v4 / 6 - v5 / 6
    s1 = 13 / 12 * (v1 - 2 * v2 + v3) ** 2 + 0.25 * (v1 - 4 * v2 + 3 * v3) ** 2
    s2 = 13 / 12 * (v2 - 2 * v3 + v4) ** 2 + 0.25 * (v2 - v4) ** 2
    s3 = 13 / 12 * (v3 - 2 * v4 + v5) ** 2 + 0.25 * (3 * v3 - 4 * v4 + v5) ** 2
    eps = 1e-6 * np.maximum.reduce([v1**2, v2**2, v3**2, v4**2, v5**2]) + 1e-99
    a1, a2, a3 = 0.1 / (s1 + eps) ** 2, 0.6 / (s2 + eps) ** 2, 0.3 / (s3 + eps) ** 2
    return (a1 * p1 + a2 * p2 + a3 * p3) / (a1 + a2 + a3)


def _weno5(d: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    g = GHOSTS

    def shifted(k: int) -> np.ndarray:
        """``d`` at ``i + k − 1/2`` for every node i (k = 0: the difference left of the node)."""
        return d[g - 1 + k : g - 1 + k + n]

    left = _weno5_combination(shifted(-2), shifted(-1), shifted(0), shifted(1), shifted(2))
    right = _weno5_combination(shifted(3), shifted(2), shifted(1), shifted(0), shifted(-1))
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
