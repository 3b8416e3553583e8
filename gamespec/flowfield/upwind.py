"""One-sided (upwind) approximations of ∂φ/∂x_i on a uniform grid: first order, ENO2 and WENO5.

After hj_reachability's ``finite_differences/upwind_first.py``: each scheme maps a block of node
values with :data:`GHOSTS` ghost nodes on each side of one axis to the pair ``(D⁻φ, D⁺φ)`` of left-
and right-biased derivatives at the block's inner nodes. At the grid's edges the ghosts are filled by
linear extrapolation (:func:`extrapolate_ghosts`; a front leaving the box is reported by the solver,
not fixed here); inside the grid they are the neighbouring nodes, so a block may be any rectangle
of the grid. ENO2 and WENO5 follow Osher & Fedkiw, *Level Set Methods*, §3.3–3.4; WENO5 is written
in the equivalent form of Jiang & Peng (2000, eqs. 2.9–2.11), which needs only the second
differences, and evaluated in place in :class:`~gamespec.flowfield.scratch.Scratch` buffers.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from gamespec.flowfield.scratch import Scratch

GHOSTS = 3
WENO_EPSILON = 1e-6
"""ε of the WENO weights relative to the largest squared difference of the stencil (O&F eq. 3.38)."""


def extrapolate_ghosts(padded: np.ndarray) -> None:
    """Fill the :data:`GHOSTS`-wide border of ``padded`` (m + 6, k + 6) by linear extrapolation of
    its inner nodes, in place: along the columns first, then along the rows over the whole width
    (so the corners too)."""
    g = GHOSTS
    steps = np.arange(1, g + 1, dtype=float)[:, None]
    for v in (padded[g:-g].T, padded):  # the stencil axis first
        v[g - 1 :: -1] = v[g] - steps * (v[g + 1] - v[g])
        v[-g:] = v[-g - 1] + steps * (v[-g - 1] - v[-g - 2])


Pair = tuple[np.ndarray, np.ndarray]


def _first_order(v: np.ndarray, dx: float, scratch: Scratch, tag: str, transposed: bool) -> Pair:
    g, n = GHOSTS, v.shape[0] - 2 * GHOSTS
    d = np.diff(v, axis=0) / dx
    return d[g - 1 : g - 1 + n], d[g : g + n].copy()  # not overlapping: the caller writes in place


def _smaller(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.where(np.abs(a) <= np.abs(b), a, b)


def _eno2(v: np.ndarray, dx: float, scratch: Scratch, tag: str, transposed: bool) -> Pair:
    """ENO2: the first difference plus half the smaller (in magnitude) second difference."""
    g, n = GHOSTS, v.shape[0] - 2 * GHOSTS
    d = np.diff(v, axis=0) / dx
    dd = np.diff(d, axis=0)  # dd[q − 1]: the change of d across padded node q
    left = d[g - 1 : g - 1 + n] + 0.5 * _smaller(dd[g - 2 : g - 2 + n], dd[g - 1 : g - 1 + n])
    right = d[g : g + n] - 0.5 * _smaller(dd[g - 1 : g - 1 + n], dd[g : g + n])
    return left, right


_WENO_ROWS = {
    **dict.fromkeys(("d", "square"), 5),
    **dict.fromkeys(("s", "pairs"), 4),
    **dict.fromkeys(("jump", "common", "rising", "middle", "falling"), 3),
    **dict.fromkeys(("third", "fours"), 2),
    "eps": 1,
    **dict.fromkeys(("central", "a0", "a1", "a2", "total", "left", "right"), 0),
}
"""The scratch arrays of :func:`_weno5` and their rows beyond the block's inner nodes."""


def _weno5(v: np.ndarray, dx: float, scratch: Scratch, tag: str, transposed: bool) -> Pair:
    """Jiang–Peng WENO5 for both sides at once, in place.

    With the differences ``d_k = φ_{k+1} − φ_k`` and second differences ``s_k = d_{k+1} − d_k`` of
    the padded block, ``D∓φ_i = c_i ∓ Φ(a, b, c, d)`` where ``c_i`` is the fourth-order central
    difference (−d_{i−2} + 7d_{i−1} + 7d_i − d_{i+1})/12 (shared by both sides), ``(a, b, c, d)`` are
    the second differences ``s`` at nodes i−2 … i+1 for D⁻ and i+2 … i−1 for D⁺, and
    ``Φ = ω₀(a − 2b + c)/3 + (ω₂ − 1/2)(b − 2c + d)/6`` with the weights of the smoothness indicators
    ``IS₀ = 13(a − b)² + 3(a − 3b)²``, ``IS₁ = 13(b − c)² + 3(b + c)²``, ``IS₂ = 13(c − d)² +
    3(3c − d)²``. Every indicator is a function of one adjacent pair of second differences, so each
    is computed once per pair and read by both sides; they are kept divided by 3 (the weights are
    unchanged with ε scaled alike).
    """
    n = v.shape[0] - 2 * GHOSTS
    w = scratch.arrays(tag, _WENO_ROWS, n, v.shape[1], transposed)

    d = np.subtract(v[1:], v[:-1], out=w["d"])
    s = np.subtract(d[1:], d[:-1], out=w["s"])
    jump = np.subtract(s[1:], s[:-1], out=w["jump"])  # s_{k+1} − s_k, one per pair
    third = np.subtract(jump[1:], jump[:-1], out=w["third"])  # s_k − 2s_{k+1} + s_{k+2}
    x, y = s[:-1], s[1:]
    common = np.multiply(jump, jump, out=w["common"])
    common *= 13 / 3
    rising = np.multiply(y, 2.0, out=w["rising"])  # (x − 3y)² = (jump + 2y)²
    rising += jump
    np.square(rising, out=rising)
    rising += common
    middle = np.add(x, y, out=w["middle"])
    np.square(middle, out=middle)
    middle += common
    falling = np.multiply(x, 2.0, out=w["falling"])  # (3x − y)² = (2x − jump)²
    falling -= jump
    np.square(falling, out=falling)
    falling += common
    square = np.multiply(d, d, out=w["square"])
    pairs = np.maximum(square[:-1], square[1:], out=w["pairs"])
    fours = np.maximum(pairs[:-2], pairs[2:], out=w["fours"])
    eps = np.maximum(fours[:-1], square[4:], out=w["eps"])
    eps *= WENO_EPSILON
    eps += 1e-99 * dx * dx  # O&F's ε in units of the undivided differences …
    eps *= 4  # … and scaled like the indicators (IS/3 = 12 S/3 in O&F's S)
    scale = 1 / (12 * dx)
    central = np.add(d[2 : n + 2], d[3 : n + 3], out=w["central"])
    central *= 7
    central -= d[1 : n + 1]
    central -= d[4 : n + 4]
    central *= scale
    a0, a1, a2, total = w["a0"], w["a1"], w["a2"], w["total"]

    def side(*args: np.ndarray) -> np.ndarray:
        """``Φ/dx`` from the indicators, ε and the two third differences, into the last argument:
        ``12Φ = (4α₀ T₀ + (2α₂ − Σα) T₁) / Σα``."""
        is0, is1, is2, e, t0, t1, out = args
        for alpha, indicator, weight in ((a0, is0, 1.0), (a1, is1, 6.0), (a2, is2, 3.0)):
            np.add(indicator, e, out=alpha)
            np.square(alpha, out=alpha)
            np.divide(weight, alpha, out=alpha)
        np.add(a0, a1, out=total)
        np.add(total, a2, out=total)
        np.multiply(a2, 2.0, out=out)
        out -= total
        out *= t1
        np.multiply(a0, t0, out=a0)
        np.multiply(a0, 4.0, out=a0)
        out += a0
        out /= total
        out *= scale
        return out

    left = side(
        rising[:n],
        middle[1 : n + 1],
        falling[2 : n + 2],
        eps[:n],
        third[:n],
        third[1 : n + 1],
        w["left"],
    )
    np.subtract(central, left, out=left)
    right = side(
        falling[3 : n + 3],
        middle[2 : n + 2],
        rising[1 : n + 1],
        eps[1:],
        third[2 : n + 2],
        third[1 : n + 1],
        w["right"],
    )
    right += central
    return left, right


Scheme = Callable[[np.ndarray, float, Scratch, str, bool], Pair]
SCHEMES: dict[str, Scheme] = {"first_order": _first_order, "eno2": _eno2, "weno5": _weno5}


def upwind_pair(block: np.ndarray, axis: int, dx: float, scheme: str, scratch: Scratch) -> Pair:
    """``(D⁻φ, D⁺φ)`` along ``axis`` at the inner nodes of a 2-D ``block`` that has :data:`GHOSTS`
    ghost nodes on each side of ``axis``, by ``scheme`` (a key of :data:`SCHEMES`). The arrays may
    be ``scratch`` buffers (tagged by the axis): use them before the next call for the same axis."""
    transposed = axis == 1
    v = block.T if transposed else block
    left, right = SCHEMES[scheme](v, dx, scratch, f"{axis}:", transposed)
    return (left.T, right.T) if transposed else (left, right)
