"""The linear-quadratic structure of a ``differential_game``, where it has one.

A game is LQ when its dynamics are affine in the states and controls and every player's payoff is
quadratic in them (its Mayer term in the final states), with coefficients that are numbers once
the parameters are given — no ``t``, no bounds, path or terminal constraints, beliefs or
transforms, a fixed initial state. Appending the constant state ``1`` makes every term homogeneous:
``ẋ = A x + B u`` and, per player ``i`` (a maximizer's payoff negated, so that every player
minimizes), ``J_i = ½ x(T)ᵀ S_i x(T) + ½ ∫ (xᵀ Q_i x + 2 xᵀ N_i u + uᵀ R_i u) dt`` over the
controls of all players stacked in the file's order: an :class:`~gamespec.games.feedback.LQGame`.

:func:`lq_form` parses the file's expressions once (SymPy); :func:`lq_game` evaluates the matrices
at given parameter values. Both return the reason, as text, where the game is not LQ. The Riccati
existence test (:mod:`gamespec.games.existence`) and the feedback equilibria
(:mod:`gamespec.games.feedback`) read them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import sympy as sp

from gamespec.errors import SpecError
from gamespec.games.expressions import GameExpressions, game_expressions
from gamespec.games.feedback import LQGame, LQPlayer
from gamespec.games.problems import initial_state
from gamespec.limits import MAX_LQ_ENTRY
from gamespec.specs.differential_game import DifferentialGameSpec


def not_lq(game: DifferentialGameSpec) -> str:
    """Why the game cannot be LQ whatever its expressions are ('' when it may be)."""
    p = game.problem
    players = p.players.values()
    reasons = [
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


def quadratic(expr: sp.Expr, variables: list[sp.Symbol]) -> tuple[np.ndarray, np.ndarray, float] | None:
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
    """A game's expressions parsed once into SymPy (in the parameters' symbols): the dynamics, each
    player's Lagrange and Mayer terms in its minimized sense, the horizon, over ``z = (x, u)`` (the
    controls of every player in the file's order, player ``i``'s at ``controls[i]``, its sense at
    ``senses[i]``) and ``x_f``; ``zero_sum`` when every player takes the game's payoff; ``game`` the
    spec, whose initial state (an expression of the parameters) each :func:`lq_game` evaluates."""

    dynamics: list[sp.Expr]
    costs: list[tuple[sp.Expr, sp.Expr]]
    horizon: sp.Expr
    z: list[sp.Symbol]
    ends: list[sp.Symbol]
    parameters: dict[str, sp.Symbol]
    states: list[str]
    players: list[str]
    senses: list[str]
    controls: list[slice]
    zero_sum: bool
    game: DifferentialGameSpec


def lq_form(game: DifferentialGameSpec, expressions: GameExpressions | None = None) -> LQForm | str:
    """The game's expressions (its parsed ``expressions``, parsed here when not given), or the
    reason it cannot be LQ (:func:`not_lq`)."""
    why = not_lq(game)
    if why:
        return why
    p = game.problem
    parsed = expressions or game_expressions(game)
    sym = parsed.symbols
    controls, slices, costs = [], [], []
    for name, player in p.players.items():
        slices.append(slice(len(controls), len(controls) + len(player.controls)))
        controls += [sym.running[c] for c in player.controls]
        payoff = parsed.payoffs.get(name, parsed.payoff)
        sign = 1 if player.objective == "minimize" else -1
        costs.append((sign * payoff.lagrange, sign * payoff.mayer))
    return LQForm(
        dynamics=[parsed.dynamics[name] for name in p.states],
        costs=costs,
        horizon=parsed.final_time,
        z=[sym.running[n] for n in p.states] + controls,
        ends=[sym.ends[f"{s}_f"] for s in p.states],
        parameters={n: sym.running[n] for n in p.parameters},
        states=list(p.states),
        players=list(p.players),
        senses=[pl.objective for pl in p.players.values()],
        controls=slices,
        zero_sum=all(pl.payoff is None for pl in p.players.values()),
        game=game,
    )


def _homogeneous(H: np.ndarray, g: np.ndarray, c: float, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Q, N, R)`` of ``½ zᵀHz + gᵀz + c`` over ``z = (x, u)`` with ``x`` extended by 1."""
    Q = np.block([[H[:n, :n], g[:n, None]], [g[None, :n], np.array([[2 * c]])]])
    N = np.vstack([H[:n, n:], g[None, n:]])
    return Q, N, H[n:, n:]


def lq_game(form: LQForm, parameters: Mapping[str, float]) -> LQGame | str:
    """The game's LQ matrices at ``parameters``, or the reason the expressions are not LQ."""
    values = {form.parameters[n]: float(v) for n, v in parameters.items() if n in form.parameters}
    n = len(form.states)
    rows = []
    for name, f in zip(form.states, form.dynamics, strict=True):
        term = quadratic(f.subs(values), form.z)
        if term is None or np.any(term[0]):
            return f"the dynamics of {name} are not linear in the states and controls (or depend on t)"
        rows.append((term[1], term[2]))
    horizon = form.horizon.subs(values)
    if horizon.free_symbols:
        return "the final time depends on more than the parameters"
    G = np.array([g for g, _ in rows])
    c = np.array([k for _, k in rows])
    A = np.block([[G[:, :n], c[:, None]], [np.zeros((1, n + 1))]])
    B = np.vstack([G[:, n:], np.zeros((1, G.shape[1] - n))])
    players = []
    for name, columns, (lagrange, mayer) in zip(form.players, form.controls, form.costs, strict=True):
        running = quadratic(lagrange.subs(values), form.z)
        final = quadratic(mayer.subs(values), form.ends)
        if running is None or final is None:
            return f"{name}'s payoff is not quadratic in the states and controls (or depends on t or t_f)"
        Q, N, R = _homogeneous(*running, n)
        S, _, _ = _homogeneous(*final, n)
        players.append(LQPlayer(name, columns, Q, N, R, S))
    checked = [("the dynamics", "problem.dynamics", np.hstack([A, B]))]
    checked += [(f"{pl.name}'s payoff", "problem.payoff", np.hstack([pl.Q, pl.N, pl.S])) for pl in players]
    for name, field, M in checked:
        if not np.abs(M).max(initial=0.0) <= MAX_LQ_ENTRY:
            raise SpecError(
                f"{name} as an LQ game have an entry of {np.abs(M).max():.3g}, beyond MAX_LQ_ENTRY = "
                f"{MAX_LQ_ENTRY:g} (the Riccati equations of the existence test and the feedback "
                "equilibrium would overflow)",
                field=field,
                source=form.game.source,
            )
    start = initial_state(form.game, parameters)
    x0 = np.array([*(start[name] for name in form.states), 1.0])
    return LQGame(A, B, tuple(players), x0, float(form.game.problem.time.initial), float(horizon))
