"""Feedback (closed-loop) Nash equilibria of linear-quadratic games by coupled Riccati equations.

Players ``i = 1..N`` share the homogeneous linear dynamics ``ẋ = A x + Σ_j B_j u_j`` (``x`` with a
constant ``1`` appended, so affine terms are columns of ``A``) and each minimizes its own cost

    J_i = ½ x(T)ᵀ S_i x(T) + ½ ∫ (xᵀ Q_i x + 2 xᵀ N_i u + uᵀ R_i u) dt

over the stacked control ``u`` of all players (a maximizer minimizes the negated payoff). With
linear feedback laws ``u_j = −K_j(t) x`` and value functions ``V_i = ½ xᵀ P_i(t) x``, the
stationarity of each player's Hamiltonian in its own control (Başar & Olsder, *Dynamic
Noncooperative Game Theory*, Thm 6.16 and Corollary 6.5; Engwerda, *LQ Dynamic Optimization and
Differential Games*, ch. 8) gives the gains at each time as one linear system

    Σ_k R_i^{ik} K_k = B_iᵀ P_i + (N_i^i)ᵀ          (one block row per player i),

and the value matrices follow the coupled Riccati equations

    −Ṗ_i = A_clᵀ P_i + P_i A_cl + Q_i + Kᵀ R_i K − N_i K − Kᵀ N_iᵀ,   P_i(T) = S_i,

with ``A_cl = A − B K`` (``B``, ``K`` stacked over players). For two players with ``J_2 = −J_1``
these are the feedback saddle of a zero-sum game, whose ``P_1`` is the game's Riccati equation.
A finite escape of some ``P_i`` (a conjugate point) or a singular gain system means no feedback
equilibrium on the horizon; the time is reported.

:func:`best_response_improvements` checks a solution independently: each player's optimal
feedback reply to the others' laws is an LQR problem (its own Riccati equation along the others'
closed loop); at an equilibrium no player improves, so the improvement is the Nash gap.

The discrete-time counterpart (Başar & Olsder, Corollary 6.1) is :func:`discrete_feedback_nash`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np


def solve_ivp(*args: Any, **kwargs: Any) -> Any:
    """SciPy's ``solve_ivp`` (the same arguments), imported on first use: scipy.integrate costs a
    command's start-up ~0.3 s, and a game solved by best responses never integrates here."""
    from scipy.integrate import solve_ivp as scipy_solve_ivp

    return scipy_solve_ivp(*args, **kwargs)


ESCAPE = 1e8
"""``‖P_i‖`` beyond this multiple of ``max(1, ‖S_i‖, ‖Q_i‖)`` counts as a finite escape."""

RTOL, ATOL = 1e-11, 1e-13
"""Tolerances of the backward Riccati and forward closed-loop integrations."""


@dataclass(frozen=True)
class LQPlayer:
    """One player of an LQ game: its control columns ``controls`` in the stacked control, and its
    cost's weights (minimized; see the module doc)."""

    name: str
    controls: slice
    Q: np.ndarray
    N: np.ndarray
    R: np.ndarray
    S: np.ndarray


@dataclass(frozen=True)
class LQGame:
    """``ẋ = A x + B u`` on ``[t0, T]`` from ``x0`` (homogeneous coordinates), and its players."""

    A: np.ndarray
    B: np.ndarray
    players: tuple[LQPlayer, ...]
    x0: np.ndarray
    t0: float
    T: float

    @property
    def k(self) -> int:
        return self.A.shape[0]

    @property
    def m(self) -> int:
        return self.B.shape[1]


@dataclass(frozen=True)
class FeedbackNash:
    """A feedback Nash equilibrium: ``P_i`` on ``times`` (players × times × k × k), the stacked
    gains ``K`` (times × m × k), the closed-loop states ``x`` (times × k) and controls ``u``
    (times × m), each player's cost ``values`` (as minimized), or where it fails: ``escape_time``
    (absolute time of a finite escape or a singular gain system) and ``reason``."""

    times: np.ndarray
    P: np.ndarray
    K: np.ndarray
    x: np.ndarray
    u: np.ndarray
    values: tuple[float, ...]
    escape_time: float | None = None
    reason: str = ""
    gain: Callable[[float], np.ndarray] | None = field(default=None, compare=False, repr=False)
    """The stacked gains ``K(t)`` (m × k) at any time of the horizon, from the dense solution."""

    @property
    def exists(self) -> bool:
        return self.escape_time is None


def _gain_system(game: LQGame) -> tuple[np.ndarray, list[np.ndarray]]:
    """The matrix ``M`` (m × m) of the gains' linear system and each player's ``B_iᵀ`` rows."""
    M = np.zeros((game.m, game.m))
    for player in game.players:
        M[player.controls] = player.R[player.controls]
    return M, [game.B[:, p.controls].T for p in game.players]


def _gains(game: LQGame, M: np.ndarray, Bt: list[np.ndarray], P: np.ndarray) -> np.ndarray:
    """The stacked gains ``K`` (m × k) at value matrices ``P`` (players × k × k)."""
    rhs = np.zeros((game.m, game.k))
    for player, b, Pi in zip(game.players, Bt, P, strict=True):
        rhs[player.controls] = b @ Pi + player.N[:, player.controls].T
    return np.linalg.solve(M, rhs)


def _minus_pdot(game: LQGame, P: np.ndarray, K: np.ndarray) -> np.ndarray:
    """``−Ṗ_i`` of every player (players × k × k) at ``P`` and gains ``K``."""
    closed = game.A - game.B @ K
    out = np.empty_like(P)
    for i, (player, Pi) in enumerate(zip(game.players, P, strict=True)):
        cross = player.N @ K
        out[i] = closed.T @ Pi + Pi @ closed + player.Q + K.T @ player.R @ K - cross - cross.T
    return out


def _bound(game: LQGame) -> float:
    return ESCAPE * max(1.0, *(max(np.abs(p.S).max(), np.abs(p.Q).max()) for p in game.players))


def feedback_nash(game: LQGame, points: int = 201) -> FeedbackNash:
    """The feedback Nash equilibrium of ``game`` (see the module doc) on ``points`` times, or where
    its Riccati equations escape (or its gain system is singular) backward from ``T``."""
    n_players, k = len(game.players), game.k
    M, Bt = _gain_system(game)
    if np.linalg.matrix_rank(M) < game.m:
        empty = np.empty((0,))
        return FeedbackNash(empty, empty, empty, empty, empty, (), game.T, "the gain system is singular")
    bound = _bound(game)

    def rhs(_: float, flat: np.ndarray) -> np.ndarray:
        P = flat.reshape(n_players, k, k)
        return _minus_pdot(game, P, _gains(game, M, Bt, P)).ravel()

    def escaped(_: float, flat: np.ndarray) -> float:
        return bound - np.abs(flat).max()

    escaped.terminal = True
    terminal = np.stack([p.S for p in game.players])
    duration = game.T - game.t0
    backward = solve_ivp(
        rhs, (0.0, duration), terminal.ravel(), rtol=RTOL, atol=ATOL, events=escaped, dense_output=True
    )
    if backward.t_events[0].size or not backward.success:
        when = game.T - (float(backward.t_events[0][0]) if backward.t_events[0].size else backward.t[-1])
        empty = np.empty((0,))
        reason = f"a player's Riccati equation escapes at t = {when:.6g} (a conjugate point)"
        return FeedbackNash(empty, empty, empty, empty, empty, (), when, reason)
    times = np.linspace(game.t0, game.T, points)

    def P_at(t: float) -> np.ndarray:
        return backward.sol(game.T - t).reshape(n_players, k, k)

    def closed_loop(t: float, x: np.ndarray) -> np.ndarray:
        return (game.A - game.B @ _gains(game, M, Bt, P_at(t))) @ x

    forward = solve_ivp(closed_loop, (game.t0, game.T), game.x0, t_eval=times, rtol=RTOL, atol=ATOL)
    P = np.stack([P_at(t) for t in times], axis=1)
    K = np.stack([_gains(game, M, Bt, P[:, j]) for j in range(points)])
    x = forward.y.T
    u = -np.einsum("tmk,tk->tm", K, x)
    values = tuple(0.5 * float(game.x0 @ P[i, 0] @ game.x0) for i in range(n_players))
    return FeedbackNash(times, P, K, x, u, values, gain=lambda t: _gains(game, M, Bt, P_at(t)))


def profile_values(game: LQGame, gain: Callable[[float], np.ndarray]) -> tuple[float, ...]:
    """Each player's cost when every player follows its rows of the linear feedback ``gain(t)``:
    ``½ x0ᵀ P_i(t0) x0`` with ``−Ṗ_i = A_clᵀ P_i + P_i A_cl + Q_i + Kᵀ R_i K − N_i K − Kᵀ N_iᵀ``."""
    n_players, k = len(game.players), game.k

    def rhs(tau: float, flat: np.ndarray) -> np.ndarray:
        K = np.asarray(gain(game.T - tau), dtype=float)
        return _minus_pdot(game, flat.reshape(n_players, k, k), K).ravel()

    terminal = np.stack([p.S for p in game.players])
    run = solve_ivp(rhs, (0.0, game.T - game.t0), terminal.ravel(), rtol=RTOL, atol=ATOL)
    P0 = run.y[:, -1].reshape(n_players, k, k)
    return tuple(0.5 * float(game.x0 @ P0[i] @ game.x0) for i in range(n_players))


def best_response_improvements(game: LQGame, gain: Callable[[float], np.ndarray]) -> tuple[float, ...]:
    """Per player, how much its cost under the feedback profile ``gain(t)`` falls when it alone
    replies optimally (by its own LQR along the others' laws) instead: 0 at a feedback Nash
    equilibrium (up to the integration's accuracy), the Nash gap elsewhere."""
    following = profile_values(game, gain)
    return tuple(following[i] - _reply_value(game, gain, p) for i, p in enumerate(game.players))


def _reply_value(game: LQGame, gain: Callable[[float], np.ndarray], player: LQPlayer) -> float:
    """``player``'s optimal cost against the others' laws: with ``u = E v − F(t) x`` (``v`` its own
    control, ``F`` the others' gains), an LQR problem with time-varying weights."""
    k, m = game.k, game.m
    E = np.zeros((m, player.controls.stop - player.controls.start))
    E[player.controls] = np.eye(E.shape[1])
    R_v = E.T @ player.R @ E

    def rhs(tau: float, flat: np.ndarray) -> np.ndarray:
        F = np.array(gain(game.T - tau), dtype=float)
        F[player.controls] = 0.0
        A = game.A - game.B @ F
        B = game.B @ E
        Q = player.Q + F.T @ player.R @ F - player.N @ F - (player.N @ F).T
        N = player.N @ E - F.T @ player.R @ E
        P = flat.reshape(k, k)
        PB = P @ B + N
        return (A.T @ P + P @ A + Q - PB @ np.linalg.solve(R_v, PB.T)).ravel()

    reply = solve_ivp(rhs, (0.0, game.T - game.t0), player.S.ravel(), rtol=RTOL, atol=ATOL)
    P0 = reply.y[:, -1].reshape(k, k)
    return 0.5 * float(game.x0 @ P0 @ game.x0)


@dataclass(frozen=True)
class DiscreteFeedbackNash:
    """Per stage ``k``: the stacked gains ``K[k]`` (m × n), the value matrices ``Z[i, k]`` of each
    player (``Z[i, N] = S_i``), and each player's cost ``values`` from ``x0``."""

    K: np.ndarray
    Z: np.ndarray
    values: tuple[float, ...]


def discrete_feedback_nash(
    A: Sequence[np.ndarray],
    B: Sequence[np.ndarray],
    players: Sequence[LQPlayer],
    x0: np.ndarray,
) -> DiscreteFeedbackNash:
    """The feedback Nash equilibrium of ``x_{k+1} = A_k x_k + B_k u_k`` with costs
    ``½ x_Nᵀ S_i x_N + ½ Σ_k (x_kᵀ Q_i x_k + 2 x_kᵀ N_i u_k + u_kᵀ R_i u_k)`` (Başar & Olsder,
    Corollary 6.1, with cross terms): backward, the gains solve
    ``Σ_j (R_i^{ij} + B_iᵀ Z_i B_j) K_j = B_iᵀ Z_i A + (N_i^i)ᵀ`` and
    ``Z_i ← Fᵀ Z_i F + Kᵀ R_i K − N_i K − Kᵀ N_iᵀ + Q_i`` with ``F = A − B K``. A singular gain
    system raises ``numpy.linalg.LinAlgError``."""
    stages = len(A)
    n, m = A[0].shape[0], B[0].shape[1]
    Z = np.empty((len(players), stages + 1, n, n))
    Z[:, stages] = np.stack([p.S for p in players])
    K = np.empty((stages, m, n))
    for k in reversed(range(stages)):
        Ak, Bk = A[k], B[k]
        M = np.zeros((m, m))
        rhs = np.zeros((m, n))
        for i, player in enumerate(players):
            Bi, Zi = Bk[:, player.controls], Z[i, k + 1]
            M[player.controls] = player.R[player.controls] + Bi.T @ Zi @ Bk
            rhs[player.controls] = Bi.T @ Zi @ Ak + player.N[:, player.controls].T
        K[k] = np.linalg.solve(M, rhs)
        F = Ak - Bk @ K[k]
        for i, player in enumerate(players):
            cross = player.N @ K[k]
            Z[i, k] = F.T @ Z[i, k + 1] @ F + K[k].T @ player.R @ K[k] - cross - cross.T + player.Q
    values = tuple(0.5 * float(x0 @ Z[i, 0] @ x0) for i in range(len(players)))
    return DiscreteFeedbackNash(K, Z, values)
