"""Relevance functions of eq. 6.33: ``r(w) = r̃(w)`` for ``w ≤ 0`` and ``r̃(0)`` for ``w > 0``.

Built as ``r̃(min(w, 0))``, which is exactly eq. 6.33 and uses only ``min`` (pyomo and casadi both
take it; ``sign``/``heaviside`` are casadi-only). Smoothness in ``w`` (what IPOPT sees):

- ``logistic_derivative`` (eq. 6.35, the default), ``gaussian`` ``e^{-w²}``, ``inverse_quadratic``
  ``1/(1+w²)``: r̃'(0) = 0, so r is continuously differentiable (the second derivative jumps at 0);
- ``logistic`` ``s(w)`` and ``inverse_abs_square`` ``1/(1+|w|)²``: r̃'(0) ≠ 0, so r has a kink at 0;
- ``hat`` ``max(0, 1-|w|)``: kinks at w = 0 and w = -1 (and zero gradient below -1).

Any other text is an expression of ``w`` in the file language, checked on a grid of (-∞, 0] to be
non-negative and non-decreasing (the conditions below eq. 6.33).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from gamespec.errors import ExpressionError
from gamespec.symbolic.calculus import numeric_function
from gamespec.symbolic.language import parse, symbol

W = symbol("w")
_E = sp.exp(W)

NAMED: dict[str, sp.Expr] = {
    "logistic_derivative": _E / (1 + _E) ** 2,
    "gaussian": sp.exp(-(W**2)),
    "hat": sp.Max(0, 1 - sp.Abs(W)),
    "logistic": _E / (1 + _E),
    "inverse_quadratic": 1 / (1 + W**2),
    "inverse_abs_square": 1 / (1 + sp.Abs(W)) ** 2,
}
"""The r̃ of §6.4 by name (eq. 6.35 and the five of §6.4.1). The logistic s(w) = 1/(1+e^{-w}) and
s(1-s) are written with e^{w}, equal forms that cannot overflow at the w = min(g, 0) <= 0 they see
(g_β of eq. 6.41 with β = 4 reaches -10⁴ far from the obstacle)."""

CHECK_GRID = np.concatenate([-np.logspace(2, -3, 400), [0.0]])
"""Where a user's r̃ is checked: increasing points of (-100, 0]."""


def profile(choice: str) -> sp.Expr:
    """r̃(w) of a named relevance function, or the parsed expression of ``w`` (checked)."""
    if choice in NAMED:
        return NAMED[choice]
    expr = sp.sympify(parse(choice, {"w": W}))
    values = np.broadcast_to(numeric_function([expr], [W])(CHECK_GRID), (1, CHECK_GRID.size))[0]
    if not np.all(np.isfinite(values)) or np.any(values < 0):
        raise ExpressionError(choice, "a relevance function must be finite and non-negative on (-inf, 0]")
    if np.any(np.diff(values) < -1e-12 * max(1.0, float(np.abs(values).max()))):
        raise ExpressionError(choice, "a relevance function must be non-decreasing on (-inf, 0] (eq. 6.33)")
    return expr


def relevance(choice: str, g: sp.Expr) -> sp.Expr:
    """``r(g)`` of eq. 6.33: r̃ at ``min(g, 0)``."""
    return profile(choice).xreplace({W: sp.Min(g, 0)})
