"""Does a zero-sum linear-quadratic differential game have an open-loop saddle? The Riccati test.

For dynamics ``ẋ = A x + B_u u + B_v v + c`` and the payoff ``J = Φ(x(T)) + ∫ L dt`` with ``Φ``
and ``L`` quadratic (``u`` minimizing, ``v`` maximizing; constant coefficients), the constant
state ``1`` appended to ``x`` makes every term homogeneous, and three Riccati equations

    −Ṗ = AᵀP + PA + Q − (PB + N) R⁻¹ (BᵀP + Nᵀ),   P(T) = S,

are integrated backward from ``T`` (SciPy):

- the **minimizer's** (``B_u`` and the weights of ``J``: ``J`` strictly convex in ``u`` iff it has
  no conjugate point, i.e. exists on ``[t0, T]``, with ``R_uu ≻ 0``);
- the **maximizer's** (``B_v`` and the weights of ``−J``: ``J`` strictly concave in ``v`` iff it
  exists on ``[t0, T]``, with ``R_vv ≺ 0``) — its finite escape is the usual reason a game has no
  open-loop saddle: the maximizer can drive ``J`` to ``+∞``;
- the **game's** (``B = [B_u B_v]``, the whole indefinite ``R``), whose ``½ x̃(t0)ᵀP(t0)x̃(t0)`` is
  the saddle value when the game has one (the open-loop and feedback saddles of a zero-sum LQ game
  share it, Başar & Olsder ch. 6).

A finite escape (``‖P‖`` past ``ESCAPE`` times its scale at ``T``) of any of them refuses the game
as ``unbounded`` with the escape time, before any best response is tried. The test applies only
where the structure is certain — zero-sum, two senses, no beliefs, transforms, constraints, bounds
or fixed final states, coefficients without ``t`` — and is otherwise skipped with the reason in
``metrics.existence``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from gamespec.games.feedback import LQGame, solve_ivp
from gamespec.games.lq_structure import LQForm, lq_game

ESCAPE = 1e8
"""``‖P‖`` beyond this multiple of ``max(1, ‖P(T)‖, ‖Q‖)`` counts as a finite escape."""


@dataclass(frozen=True)
class Existence:
    """The test's verdict: ``checked`` (False: skipped, ``reason`` says why), the Riccati equation
    that escaped and when (``escape_time``, absolute time), else the Riccati value."""

    checked: bool
    reason: str = ""
    riccati: str | None = None
    escape_time: float | None = None
    value: float | None = None

    @property
    def refused(self) -> bool:
        """A Riccati equation escaped or a player's problem is not strictly convex: no saddle."""
        return self.riccati is not None

    def as_metrics(self) -> dict:
        return {
            "checked": self.checked,
            "reason": self.reason,
            "riccati": self.riccati,
            "escape_time": self.escape_time,
            "riccati_value": self.value,
        }


def _not_zero_sum(form: LQForm) -> str:
    """Why the LQ game is not a zero-sum game of minimizers against maximizers ('' when it is)."""
    if not form.zero_sum:
        return "a player has a payoff of its own (not zero-sum)"
    if len(set(form.senses)) < 2:
        return "every player has the same sense"
    return ""


def _columns(form: LQForm, sense: str) -> np.ndarray:
    """The stacked-control columns of the players of ``sense``."""
    spans = [
        np.arange(s.start, s.stop) for s, pl in zip(form.controls, form.senses, strict=True) if pl == sense
    ]
    return np.concatenate(spans)


def escape(A, B, Q, N, R, S, duration: float) -> tuple[float | None, np.ndarray]:
    """Integrate ``−Ṗ = AᵀP + PA + Q − (PB + N)R⁻¹(BᵀP + Nᵀ)``, ``P(T) = S``, backward over
    ``duration``: the backward time of a finite escape (None when none) and the last ``P``."""
    k = A.shape[0]
    Rinv = np.linalg.inv(R)
    bound = ESCAPE * max(1.0, np.abs(S).max(), np.abs(Q).max())

    def rhs(_: float, flat: np.ndarray) -> np.ndarray:
        P = flat.reshape(k, k)
        PB = P @ B + N
        return (A.T @ P + P @ A + Q - PB @ Rinv @ PB.T).ravel()

    def escaped(_: float, flat: np.ndarray) -> float:
        largest = np.abs(flat).max()
        return float(bound - largest) if np.isfinite(largest) else -1.0

    escaped.terminal = True
    sol = solve_ivp(rhs, (0.0, duration), S.ravel(), method="LSODA", rtol=1e-12, atol=1e-14, events=escaped)
    P = sol.y[:, -1].reshape(k, k)
    return (float(sol.t_events[0][0]) if sol.t_events[0].size else None), P


def existence(form: LQForm | str, parameters: Mapping[str, float]) -> Existence:
    """The Riccati test of the module docstring at ``parameters`` on the game's parsed ``form``
    (:func:`~gamespec.games.lq_structure.lq_form`; a string: why the test does not apply)."""
    why = form if isinstance(form, str) else _not_zero_sum(form)
    data: LQGame | str = why or lq_game(form, parameters)
    if isinstance(data, str):
        return Existence(False, f"existence test skipped: {data}")
    u, v = _columns(form, "minimize"), _columns(form, "maximize")
    payoff = data.players[form.senses.index("minimize")]
    Q, N, R, S = payoff.Q, payoff.N, payoff.R, payoff.S
    R_uu, R_vv = R[np.ix_(u, u)], R[np.ix_(v, v)]
    if np.linalg.eigvalsh(R_uu).min() <= 0:
        return Existence(
            True, "no saddle: the payoff is not strictly convex in the minimizer's controls", "minimizer"
        )
    if np.linalg.eigvalsh(-R_vv).min() <= 0:
        return Existence(
            True, "no saddle: the payoff is not strictly concave in the maximizer's controls", "maximizer"
        )
    both = np.concatenate([u, v])
    duration = data.T - data.t0
    players = {
        "minimizer": (data.B[:, u], Q, N[:, u], R_uu, S),
        "maximizer": (data.B[:, v], -Q, -N[:, v], -R_vv, -S),
        "game": (data.B[:, both], Q, N[:, both], R[np.ix_(both, both)], S),
    }
    P = None
    for name, (B, Qi, Ni, Ri, Si) in players.items():
        backward, P = escape(data.A, B, Qi, Ni, Ri, Si, duration)
        if backward is not None:
            when = data.T - backward
            return Existence(
                True,
                f"no open-loop saddle: the {name}'s Riccati equation escapes at t = {when:.6g} "
                f"(integrated backward from T = {data.T:.6g}; a conjugate point, the payoff is unbounded)",
                name,
                when,
            )
    return Existence(
        True, "the Riccati equations exist on the horizon", None, None, 0.5 * float(data.x0 @ P @ data.x0)
    )
