"""Derivatives of expression maps and their numeric evaluation, for generated problems (sensitivity
equations, chapter 5's linearization about a nominal trajectory).

:func:`jacobian` and :func:`gradient` are SymPy's derivatives of an expression map;
:func:`numeric_function` evaluates expressions over arrays through a tape recorded once by
:func:`~gamespec.symbolic.tape.vectorized` (no ``lambdify``, no code generation);
:func:`linearize` gives ``A(t) = ∂f/∂x`` (eq. 5.6) and ``B(t) = ∂f/∂u`` along a trajectory, the
matrices of the linearized dynamics ``dx ≈ (B u + r + A x) dt`` (eq. 5.5).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np
import sympy as sp

from gamespec.errors import ExpressionError
from gamespec.symbolic.library import NUMPY, Library
from gamespec.symbolic.tape import vectorized
from gamespec.symbolic.translate import translate


def jacobian(exprs: Sequence[sp.Expr] | sp.Matrix, wrt: Sequence[sp.Symbol]) -> sp.Matrix:
    """``J[i, j] = ∂ exprs[i] / ∂ wrt[j]``, a ``len(exprs) × len(wrt)`` matrix."""
    return sp.Matrix(list(exprs)).jacobian(sp.Matrix(list(wrt)))


def gradient(expr: sp.Expr, wrt: Sequence[sp.Symbol]) -> list[sp.Expr]:
    """``[∂ expr / ∂ w for w in wrt]``."""
    return [sp.diff(expr, w) for w in wrt]


def numeric_function(
    exprs: Sequence[sp.Expr] | sp.Matrix, args: Sequence[sp.Symbol], library: Library = NUMPY
) -> Callable[..., np.ndarray]:
    """A vectorized function of ``args``: called with one array (or number) per symbol, broadcast
    together to a shape ``s``, it returns the values of ``exprs`` as an array ``(len(exprs), *s)``.

    Every free symbol of ``exprs`` must be among ``args`` (an ExpressionError names the others).
    """
    exprs = [sp.sympify(e) for e in exprs]
    args = list(args)
    free = set().union(*(e.free_symbols for e in exprs)) - set(args)
    if free:
        names = ", ".join(sorted(map(str, free)))
        raise ExpressionError(", ".join(map(str, exprs)), f"symbols {names} are not arguments")

    def build(slots: list, lib: Library) -> list:
        values = dict(zip(args, slots, strict=True))
        return [translate(e, values, lib) for e in exprs]

    return vectorized(build, len(args), library)


def linearize(
    exprs: Sequence[sp.Expr],
    x: Sequence[sp.Symbol],
    u: Sequence[sp.Symbol],
    states: np.ndarray,
    controls: np.ndarray,
    parameters: Mapping[sp.Symbol, float] | None = None,
    time: tuple[sp.Symbol, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """``(A, B)`` of the dynamics ``ẋ = f(x, u)`` along a nominal trajectory (eqs. 5.5–5.6):
    ``A[k] = ∂f/∂x`` and ``B[k] = ∂f/∂u`` at ``(states[k], controls[k])``.

    ``states`` is ``(N, len(x))``, ``controls`` ``(N, len(u))``; ``parameters`` gives the other
    symbols their values and ``time = (t, grid)`` the time symbol its ``N`` values when ``f``
    depends on it. Returns arrays ``(N, n, n)`` and ``(N, n, len(u))``.
    """
    n, m = len(x), len(u)
    states = np.asarray(states, dtype=float).reshape(-1, n)
    controls = np.asarray(controls, dtype=float).reshape(-1, m)
    if states.shape[0] != controls.shape[0]:
        raise ValueError(f"{states.shape[0]} states but {controls.shape[0]} controls along the trajectory")
    fixed = dict(parameters or {})
    symbols = [*x, *u, *fixed]
    columns = [*states.T, *controls.T, *(np.full(states.shape[0], float(v)) for v in fixed.values())]
    if time is not None:
        symbols.append(time[0])
        columns.append(np.asarray(time[1], dtype=float))
    evaluate = numeric_function(jacobian(exprs, [*x, *u]), symbols)
    values = evaluate(*columns).reshape(len(exprs), n + m, -1).transpose(2, 0, 1)
    return values[:, :, :n], values[:, :, n:]
