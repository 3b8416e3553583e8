"""Constraint sensitivities (eq. 6.31) and the relevant constraint sensitivity (eqs. 6.33-6.36).

The state sensitivities ``S = ∂x/∂ρ`` are the desensitize transform's
(:func:`gamespec.desensitize.augment.sensitivity_functions`, eq. 6.12); :func:`nonzero` drops those
that are identically zero (zero initial value and a right-hand side that vanishes when the other
zero ones do — e.g. every agent state when only obstacles depend on ρ), so a problem with N
obstacles does not carry 2N states that stay 0.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import sympy as sp

from gamespec.desensitize.augment import Augmentation, sensitivity_name
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.rcs.relevance import relevance
from gamespec.symbolic.calculus import jacobian
from gamespec.symbolic.language import symbol


@dataclass(frozen=True)
class Inequality:
    """``g <= 0`` taken from path constraint ``index`` (its upper or lower bound)."""

    index: int
    label: str
    g: sp.Expr


def inequalities(ocp: SymbolicOcp) -> list[Inequality]:
    """Every bound of every inequality path constraint as ``g <= 0`` (``expr - upper``, ``lower - expr``)."""
    out = []
    for i, rel in enumerate(ocp.path):
        if rel.is_equality:
            continue
        bounds = [(b, s) for b, s in ((rel.upper, 1), (rel.lower, -1)) if abs(b) != float("inf")]
        for b, s in bounds:
            suffix = "" if len(bounds) == 1 else ("_upper" if s > 0 else "_lower")
            out.append(Inequality(i, f"g{i}{suffix}", s * (rel.expr - b)))
    return out


def nonzero(aug: Augmentation) -> Augmentation:
    """The augmentation without its identically zero sensitivities (see module doc)."""
    zero = {s.name for s in aug.states if s.initial == 0}
    while True:
        subs = {symbol(n): 0 for n in zero}
        stays = {s.name for s in aug.states if s.name in zero and sp.simplify(s.rhs.xreplace(subs)) == 0}
        if stays == zero:
            break
        zero = stays
    subs = {symbol(n): 0 for n in zero}
    states = [replace(s, rhs=s.rhs.xreplace(subs)) for s in aug.states if s.name not in zero]
    keep = {s.name for s in states}
    return replace(
        aug,
        states=states,
        running={k: v for k, v in aug.running.items() if k in keep},
        final={k: v for k, v in aug.final.items() if k in keep},
    )


def state_sensitivity(ocp: SymbolicOcp, uncertain: Sequence[str], aug: Augmentation) -> sp.Matrix:
    """``S`` (n × ℓ): the augmentation's sensitivity symbols, 0 where it dropped them."""
    kept = {s.name for s in aug.states}

    def entry(i: int, j: int) -> sp.Expr:
        name = sensitivity_name(ocp.states[i], uncertain[j])
        return symbol(name) if name in kept else sp.Integer(0)

    return sp.Matrix(len(ocp.states), len(uncertain), entry)


def constraint_sensitivity(
    ocp: SymbolicOcp, g: Sequence[sp.Expr], uncertain: Sequence[str], S: sp.Matrix
) -> sp.Matrix:
    """``S_g = g_x S + g_ρ`` (eq. 6.31), k × ℓ."""
    G = sp.Matrix(list(g))
    return jacobian(G, ocp.x) * S + jacobian(G, [symbol(p) for p in uncertain])


def relevant(S_g: sp.Matrix, g: Sequence[sp.Expr], choice: str) -> sp.Matrix:
    """``S_r = R S_g`` with ``R = diag(r(g_i))`` (eqs. 6.33-6.34)."""
    return sp.diag(*(relevance(choice, gi) for gi in g)) * S_g


def weighted_square(M: sp.Matrix, weights: Sequence[sp.Expr]) -> sp.Expr:
    """``‖vec M‖²_Q`` with ``Q`` diagonal, row i of M weighted by ``weights[i]`` (eqs. 6.32, 6.36)."""
    return sp.Add(*(w * sum(M[i, j] ** 2 for j in range(M.cols)) for i, w in enumerate(weights)))
