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
import sympy as sp
from scipy.integrate import solve_ivp

from gamespec.games.problems import symbols_of
from gamespec.specs.differential_game import DifferentialGameSpec
from gamespec.symbolic.language import parse

ESCAPE = 1e8
"""``‖P‖`` beyond this multiple of ``max(1, ‖P(T)‖, ‖Q‖)`` counts as a finite escape."""


@dataclass(frozen=True)
class LQData:
    """The homogeneous (constant state appended) matrices of a zero-sum LQ game."""

    A: np.ndarray
    B_u: np.ndarray
    B_v: np.ndarray
    Q: np.ndarray
    N_u: np.ndarray
    N_v: np.ndarray
    R: np.ndarray
    S: np.ndarray
    x0: np.ndarray
    t0: float
    T: float

    @property
    def m(self) -> int:
        return self.B_u.shape[1]


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


def _skip(game: DifferentialGameSpec) -> str:
    """Why the game is not one the test covers ('' when it is)."""
    p = game.problem
    players = p.players.values()
    reasons = [
        (any(pl.payoff is not None for pl in players), "a player has a payoff of its own (not zero-sum)"),
        (len({pl.objective for pl in players}) < 2, "every player has the same sense"),
        (bool(p.uncertain), "uncertain parameters (the players' games differ)"),
        (
            any(pl.transforms or pl.path_constraints for pl in players),
            "a player's transforms or path constraints",
        ),
        (bool(p.terminal_constraints), "terminal constraints"),
        (
            any(c.lower is not None or c.upper is not None for pl in players for c in pl.controls.values()),
            "control bounds",
        ),
        (
            any(s.lower is not None or s.upper is not None or s.final is not None for s in p.states.values()),
            "state bounds or fixed final states",
        ),
        (any(s.initial is None for s in p.states.values()), "a free initial state"),
    ]
    return next((why for hit, why in reasons if hit), "")


def _quadratic(expr: sp.Expr, variables: list[sp.Symbol]) -> tuple[np.ndarray, np.ndarray, float] | None:
    """``(H, g, c)`` with ``expr = ½ zᵀHz + gᵀz + c`` in ``variables``, or None when ``expr`` is not
    a polynomial of degree ≤ 2 with numeric coefficients."""
    expr = sp.expand(expr)
    if expr.free_symbols - set(variables) or not expr.is_polynomial(*variables):
        return None
    if variables and sp.Poly(expr, *variables).total_degree() > 2:
        return None
    zero = dict.fromkeys(variables, 0)
    H = np.array([[float(sp.diff(expr, a, b).subs(zero)) for b in variables] for a in variables], dtype=float)
    g = np.array([float(sp.diff(expr, a).subs(zero)) for a in variables], dtype=float)
    return H.reshape(len(variables), len(variables)), g, float(expr.subs(zero))


@dataclass(frozen=True)
class LQForm:
    """A zero-sum game's expressions parsed once into SymPy (in the parameters' symbols): the
    dynamics, the Lagrange and Mayer terms and the horizon, over ``z = (x, u, v)`` and ``x_f``."""

    dynamics: list[sp.Expr]
    lagrange: sp.Expr
    mayer: sp.Expr
    horizon: sp.Expr
    z: list[sp.Symbol]
    ends: list[sp.Symbol]
    parameters: dict[str, sp.Symbol]
    states: list[str]
    m: int
    x0: np.ndarray
    t0: float


def lq_form(game: DifferentialGameSpec) -> LQForm | str:
    """The game's expressions for the test, or the reason it is not a game the test covers."""
    why = _skip(game)
    if why:
        return why
    p = game.problem
    sym = symbols_of(game)
    senses = {c: pl.objective for pl in p.players.values() for c in pl.controls}
    u = [sym.running[c] for c, sense in senses.items() if sense == "minimize"]
    v = [sym.running[c] for c, sense in senses.items() if sense == "maximize"]
    return LQForm(
        dynamics=[sp.sympify(parse(p.dynamics[name], sym.running)) for name in p.states],
        lagrange=sp.sympify(parse(p.payoff.lagrange, sym.running)),
        mayer=sp.sympify(parse(p.payoff.mayer, sym.ends)),
        horizon=sp.sympify(parse(p.time.final, sym.running)),
        z=[sym.running[n] for n in p.states] + u + v,
        ends=[sym.ends[f"{s}_f"] for s in p.states],
        parameters={n: sym.running[n] for n in p.parameters},
        states=list(p.states),
        m=len(u),
        x0=np.array([*(float(s.initial) for s in p.states.values()), 1.0]),
        t0=float(p.time.initial),
    )


def lq_data(form: LQForm, parameters: Mapping[str, float]) -> LQData | str:
    """The game's LQ matrices at ``parameters``, or the reason the expressions are not LQ."""
    values = {form.parameters[n]: float(v) for n, v in parameters.items() if n in form.parameters}
    rows = []
    for name, f in zip(form.states, form.dynamics, strict=True):
        term = _quadratic(f.subs(values), form.z)
        if term is None or np.any(term[0]):
            return f"the dynamics of {name} are not linear in the states and controls (or depend on t)"
        rows.append((term[1], term[2]))
    running = _quadratic(form.lagrange.subs(values), form.z)
    mayer = _quadratic(form.mayer.subs(values), form.ends)
    if running is None or mayer is None:
        return "the payoff is not quadratic in the states and controls (or depends on t or t_f)"
    horizon = form.horizon.subs(values)
    if horizon.free_symbols:
        return "the final time depends on more than the parameters"
    n, nu = len(form.states), form.m
    G = np.array([g for g, _ in rows])
    c = np.array([k for _, k in rows])
    A = np.block([[G[:, :n], c[:, None]], [np.zeros((1, n + 1))]])
    B = np.vstack([G[:, n:], np.zeros((1, G.shape[1] - n))])
    H, g, k = running
    Q = np.block([[H[:n, :n], g[:n, None]], [g[None, :n], np.array([[2 * k]])]])
    N = np.vstack([H[:n, n:], g[None, n:]])
    Hf, gf, kf = mayer
    S = np.block([[Hf, gf[:, None]], [gf[None, :], np.array([[2 * kf]])]])
    return LQData(
        A, B[:, :nu], B[:, nu:], Q, N[:, :nu], N[:, nu:], H[n:, n:], S, form.x0, form.t0, float(horizon)
    )


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
        return bound - np.abs(flat).max()

    escaped.terminal = True
    sol = solve_ivp(rhs, (0.0, duration), S.ravel(), method="LSODA", rtol=1e-12, atol=1e-14, events=escaped)
    P = sol.y[:, -1].reshape(k, k)
    return (float(sol.t_events[0][0]) if sol.t_events[0].size else None), P


def existence(form: LQForm | str, parameters: Mapping[str, float]) -> Existence:
    """The Riccati test of the module docstring at ``parameters`` on the game's parsed ``form``
    (:func:`lq_form`; a string: why the test does not apply)."""
    data = form if isinstance(form, str) else lq_data(form, parameters)
    if isinstance(data, str):
        return Existence(False, f"existence test skipped: {data}")
    m = data.m
    R_uu, R_vv = data.R[:m, :m], data.R[m:, m:]
    if np.linalg.eigvalsh(R_uu).min() <= 0:
        return Existence(
            True, "no saddle: the payoff is not strictly convex in the minimizer's controls", "minimizer"
        )
    if np.linalg.eigvalsh(-R_vv).min() <= 0:
        return Existence(
            True, "no saddle: the payoff is not strictly concave in the maximizer's controls", "maximizer"
        )
    duration = data.T - data.t0
    players = {
        "minimizer": (data.B_u, data.Q, data.N_u, R_uu, data.S),
        "maximizer": (data.B_v, -data.Q, -data.N_v, -R_vv, -data.S),
        "game": (np.hstack([data.B_u, data.B_v]), data.Q, np.hstack([data.N_u, data.N_v]), data.R, data.S),
    }
    P = None
    for name, (B, Q, N, R, S) in players.items():
        backward, P = escape(data.A, B, Q, N, R, S, duration)
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
