"""Which solution of the covariance game (section 5.3) a Result reports, and when the game has a
pure saddle point.

The pursuer minimizes the payoff ``𝒥(V, K)`` (eq. 5.34, or eq. 5.17) by its part
``p = (EᵖV, EᵖK) ∈ 𝒫``, the evader maximizes it by ``e = (EᵉV, EᵉK) ∈ ℰ``, the sets of section 5.3
cut out by eqs. 5.35–5.36 for each player; write ``J(p, e)``. Two values bracket every solution:

- the **lower value** ``v₋ = max_{e∈ℰ} min_{p∈𝒫} J(p, e)``: the evader commits to its gains and the
  pursuer's feedback answers them. This is the thesis' reading: Algorithm 3 lets the pursuer answer
  the evader's last strategy (line 3), and Fig. 5.2 and section 5.4 compare the open loop with the
  pursuer's optimized feedback ("the proposed closed-loop control strategy for the pursuer is
  effective in maximizing the capture probability");
- the **upper value** ``v₊ = min_{p∈𝒫} max_{e∈ℰ} J(p, e)``: the pursuer commits and a worst-case
  evader answers. ``J`` is convex in the pursuer's gains, so in the mixed extension the pursuer has a
  pure optimal strategy and ``v₊`` is also the value of the mixed game (Bohnenblust, Karlin and
  Shapley 1950): the robust **mixed minimax**.

``v₋ ≤ v₊`` always; a pure saddle point exists iff they are equal (``saddle_gap = v₊ − v₋``).

**No pure saddle here, and why (the feasibility condition).** The evader's set is symmetric in its
gains (``K → −K``) and, for the trace payoff, ``J(p, e) + J(p, ẽ) = 2‖c(p)‖² + 2‖Tᵉκᵉ‖²`` for the
mirror ``ẽ``, with ``vec G = c(p) + Tᵉκᵉ``; so ``v₊ ≥ min_p ‖c(p)‖² + max_e ‖Tᵉκᵉ‖²`` whatever else
holds. That alone does not rule out a saddle: ``J = (5 + p − e)²``, ``p ∈ [−3, 3]``, ``e ∈ [−1, 1]``
has both properties (``Tᵉ = −Tᵖ``, ``ℰ`` symmetric) and a pure saddle at ``(−3, −1)``, value 9 —
there the pursuer's best answer to the passive evader, ``p₀ = −3``, sits on the edge of ``𝒫`` and
cannot follow the evader. What makes ``v₋`` small is that the pursuer's best answer ``p₀`` to the
open-loop evader (``e = 0``) leaves room to copy any evader gain: ``p₀ + ℰ ⊆ 𝒫`` (``p₀ ∈ 𝒫 ⊖ ℰ``,
:func:`copy_room` ≤ 1). Then, in a linear flow (``Tᵖ = −Tᵉ``), ``J(p₀ + κᵉ, e) = J(p₀, 0)`` for every
``e``, so ``v₋ = J(p₀, 0) = min_p ‖c(p)‖²`` and ``v₊ − v₋ ≥ max_e ‖Tᵉκᵉ‖² > 0``. In a nonlinear flow
``Tᵖ + Tᵉ`` is small but not zero, and the copy gives the bracket of :func:`lower_value_bound`.

With ``V = Û`` (``feedforward: nominal``) both players' gains range over per-step balls of one
shape, ``‖S_k κ_k‖ ≤ ρⁱ_k`` with ``ρⁱ_k = (vⁱ_max − ‖ûⁱ_k‖)/√(2 log 1/βⁱ)`` (eq. 5.36 in its SOC form;
``S_k`` from the noise ``y_k`` both players observe), so ``p₀ + ℰ ⊆ 𝒫`` iff
``‖S_k κᵖ_k‖ + ρᵉ_k ≤ ρᵖ_k`` at every step; with ``free`` feedforward the condition is not checked.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

Scheme = Literal["lower_value", "minimax_mixed", "gauss_seidel"]
SCHEME_CONCEPT = {"lower_value": "lower_value", "minimax_mixed": "minimax_mixed", "gauss_seidel": "saddle"}
"""The solution concept each ``method.game.scheme`` computes when the game has no pure saddle."""


def copy_room(used: np.ndarray, pursuer_radii: np.ndarray, evader_radii: np.ndarray) -> float:
    """``max_k (‖S_k κᵖ_k‖ + ρᵉ_k) / ρᵖ_k`` for the pursuer's used spread ``used[k] = ‖S_k κᵖ_k‖``:
    at most 1 iff ``κᵖ + ℰ ⊆ 𝒫``, the pursuer can add any evader gain to its own."""
    used, rp, re = (np.asarray(a, dtype=float) for a in (used, pursuer_radii, evader_radii))
    return float(np.max((used + re) / rp))


def lower_value_bound(factor: np.ndarray, defect: float, payoff: str) -> float:
    """An upper bound of ``v₋`` when the pursuer can copy (:func:`copy_room` ≤ 1): ``J(p₀ + κᵉ, e)``
    has the relative factor ``G₀ + H`` with ``G₀`` the factor at ``(p₀, 0)`` and
    ``‖H‖_F = ‖(Tᵖ + Tᵉ)κᵉ‖ ≤ defect``; so ``J ≤ (‖G₀‖_F + defect)²`` (trace, eq. 5.34) or
    ``J ≤ (‖G₀G₀ᵀ‖_F + 2‖G₀‖₂ defect + defect²)²`` (Frobenius, eq. 5.17). ``defect = 0`` (a linear
    flow) gives ``J(p₀, 0)`` itself."""
    if payoff == "trace":
        return float((np.linalg.norm(factor) + defect) ** 2)
    spread = np.linalg.norm(factor @ factor.T) + 2 * np.linalg.norm(factor, 2) * defect + defect**2
    return float(spread**2)


def saddle_gap(lower: float, upper: float) -> float:
    """``v₊ − v₋`` (0 at a pure saddle point; a negative difference of estimates counts as 0)."""
    return max(float(upper) - float(lower), 0.0)


def solution_concept(lower: float | None, upper: float | None, tolerance: float, scheme: Scheme) -> str:
    """``saddle`` when both values are known and ``v₊ − v₋ ≤ tolerance · |v₊|`` (a pure saddle point:
    every concept gives it), else the concept of ``scheme`` (:data:`SCHEME_CONCEPT`; for
    ``gauss_seidel`` the saddle it seeks, its ``checks.saddle_gap`` failing)."""
    if lower is not None and upper is not None and saddle_gap(lower, upper) <= tolerance * abs(upper):
        return "saddle"
    return SCHEME_CONCEPT[scheme]
