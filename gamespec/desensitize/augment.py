"""The states each desensitization method adds to an ``optimal_control`` problem, derived with SymPy.

Three methods, one shape (:class:`Augmentation`): new states with their dynamics and end values,
the dynamics of the original states (changed only by Seywald's method), and the *entries* a weight
may penalize, as expressions over the running symbols (trajectory term) and over the end symbols
(final-time term and fixed values).

- :func:`sensitivity_functions`: ``S = ∂x/∂ρ`` with ``Ṡ = f_x S + f_ρ`` (eq. 6.12), ``S(t0) = ∂x0/∂ρ``
  (zero for a fixed, parameter-free initial state as in eq. 6.12; the derivative of the initial value
  when it is an expression of ρ). n + nℓ states.
- :func:`seywald_matrix`: the parameters become states ``P_ρ`` (eq. 6.4) and the (n+ℓ)² entries of
  the sensitivity matrix are states (eq. 6.5): (n+ℓ)² + n + ℓ states in all, as the formula below
  eq. 6.7 says. Eq. 6.7 needs ``Λ(t_f) Λ(t)^{-1}`` inside the running cost; that is the transition
  matrix ``Φ(t_f, t)``, which obeys ``Φ̇ = -Φ ∂f̃/∂x̃`` with ``Φ(t_f, t_f) = I`` — the same number of
  states without an inverse or a final value inside the integrand, so we integrate Φ backward.
  (§6.3.1 reports 21 states for Zermelo, n = 2, ℓ = 1: that is 2(n+ℓ)² + n + ℓ, the count of
  §6.5.1, i.e. Λ and Λ⁻¹ both propagated; the formula below eq. 6.7 and this method give 12.)
  Its ``x``-row, ``ρ``-column block at time t is the sensitivity of the final state to the parameter
  from t on; at t0 (with the initial-state term) it equals ``S(t_f)``. The ρ rows are constant
  (0 and 1) but they are states of the method as published, and kept so the counts compare.
- :func:`costate_desensitization`: C-DOC's co-states λ (of x) and μ (of ρ) with ``λ̇ = -H_x``,
  ``μ̇ = -H_ρ`` (eq. 6.60), ``H = L + λᵀf`` (eq. 6.59), ``λ(t_f) = φ_x`` (eq. 6.58) and
  ``μ(t_f) = φ_ρ`` (eq. 6.63; zero when φ does not involve ρ). By Theorem 7 they are the gradients of
  the cost-to-go *for the given control*, so the terminal constraints add no multiplier here. The
  parameters stay parameters (``ρ̇ = 0`` needs no state): 2n + ℓ states, against the 2(n+ℓ) of the
  text below eq. 6.64, which counts ρ as states.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.symbolic.calculus import jacobian
from gamespec.symbolic.language import symbol


@dataclass(frozen=True)
class NewState:
    """An added state: its dynamics, and its initial and final values (None: free), expressions of
    the parameters (a final value may also involve the end symbols ``<state>_f``, ``t_f``)."""

    name: str
    rhs: sp.Expr
    initial: sp.Expr | None
    final: sp.Expr | None


@dataclass(frozen=True)
class Augmentation:
    """What a method adds: states, changed dynamics, and the entries weights refer to."""

    method: str
    states: list[NewState]
    running: dict[str, sp.Expr]
    """Entry name → its value at time t (for the trajectory term)."""
    final: dict[str, sp.Expr]
    """Entry name → its value at the final time, over the end symbols (final term, fixed values)."""
    dynamics: dict[str, sp.Expr] = field(default_factory=dict)
    """Replaced dynamics of original states (Seywald's method substitutes ``P_ρ`` for ρ)."""
    formula_states: int = 0
    """The state count the thesis's formula gives for this method."""


def sensitivity_name(state: str, parameter: str) -> str:
    return f"S_{state}_{parameter}"


def sensitivity_functions(ocp: SymbolicOcp, uncertain: list[str]) -> Augmentation:
    """Eqs. 6.11-6.15: the n·ℓ sensitivity functions ``S_<state>_<parameter>`` (column-major vec S)."""
    x, f = ocp.x, sp.Matrix(ocp.dynamics)
    rho = [symbol(p) for p in uncertain]
    S = sp.Matrix(len(x), len(rho), lambda i, j: symbol(sensitivity_name(ocp.states[i], uncertain[j])))
    rhs = jacobian(f, x) * S + jacobian(f, rho)
    x0 = ocp.initial_values
    states, running, final = [], {}, {}
    for j, p in enumerate(rho):
        for i, name in enumerate(ocp.states):
            entry = sensitivity_name(name, uncertain[j])
            start = sp.Integer(0) if x0[i] is None else sp.diff(x0[i], p)
            states.append(NewState(entry, sp.expand(rhs[i, j]), start, None))
            running[entry] = S[i, j]
            final[entry] = symbol(f"{entry}_f")
    n, ell = len(x), len(rho)
    return Augmentation("sensitivity", states, running, final, formula_states=n + n * ell)


def seywald_matrix(ocp: SymbolicOcp, uncertain: list[str]) -> Augmentation:
    """Eqs. 6.4-6.7 with ``Φ(t_f, t) = Λ(t_f) Λ(t)^{-1}`` integrated backward from the identity."""
    rho = [symbol(p) for p in uncertain]
    carriers = [f"P_{p}" for p in uncertain]
    lifted = dict(zip(rho, (symbol(c) for c in carriers), strict=True))
    f_tilde = sp.Matrix([*(e.xreplace(lifted) for e in ocp.dynamics), *([0] * len(rho))])
    x_tilde = [*ocp.x, *lifted.values()]
    names = [*ocp.states, *carriers]
    m = len(names)
    Phi = sp.Matrix(m, m, lambda r, c: symbol(f"Phi_{names[r]}_{names[c]}"))
    rhs = -Phi * jacobian(f_tilde, x_tilde)
    states = [NewState(c, sp.Integer(0), p, None) for c, p in zip(carriers, rho, strict=True)]
    for c in range(m):
        for r in range(m):
            states.append(NewState(str(Phi[r, c]), sp.expand(rhs[r, c]), None, sp.Integer(int(r == c))))
    x0 = ocp.initial_values
    running, final = {}, {}
    n = len(ocp.states)
    for j, p in enumerate(uncertain):
        for i, name in enumerate(ocp.states):
            entry = sensitivity_name(name, p)
            running[entry] = Phi[i, n + j]
            through_x0 = sum(
                (symbol(f"{Phi[i, k]}_0") * sp.diff(x0[k], rho[j]) for k in range(n) if x0[k] is not None),
                sp.Integer(0),
            )
            final[entry] = symbol(f"{Phi[i, n + j]}_0") + through_x0
    dynamics = {name: f_tilde[i] for i, name in enumerate(ocp.states)}
    return Augmentation("seywald", states, running, final, dynamics, formula_states=m * m + m)


def costate_desensitization(ocp: SymbolicOcp, uncertain: list[str]) -> Augmentation:
    """Eqs. 6.59-6.63: co-states ``lambda_<state>`` and ``mu_<parameter>`` of the file's cost."""
    lagrange, mayer = ocp.sign * ocp.lagrange, ocp.sign * ocp.mayer
    rho = [symbol(p) for p in uncertain]
    lam = [symbol(f"lambda_{n}") for n in ocp.states]
    H = lagrange + sum((lv * fv for lv, fv in zip(lam, ocp.dynamics, strict=True)), sp.Integer(0))
    states = []
    for xi, lv, xf in zip(ocp.x, lam, ocp.xf, strict=True):
        states.append(NewState(str(lv), sp.expand(-sp.diff(H, xi)), None, sp.diff(mayer, xf)))
    running = {}
    for p, r in zip(uncertain, rho, strict=True):
        states.append(NewState(f"mu_{p}", sp.expand(-sp.diff(H, r)), None, sp.diff(mayer, r)))
        running[f"mu_{p}"] = symbol(f"mu_{p}")
    n, ell = len(ocp.states), len(uncertain)
    return Augmentation("costate", states, running, {}, formula_states=2 * (n + ell))


METHODS = {
    "sensitivity": sensitivity_functions,
    "seywald": seywald_matrix,
    "costate": costate_desensitization,
}
