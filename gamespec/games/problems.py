"""Each player's best-response problem as an ``optimal_control`` spec, generated symbolically.

In the game ``G^i`` that player ``i`` solves (section 7.2.2), player ``j``'s best response is the
optimal-control problem of its own controls with the other players' controls as grid inputs
(:mod:`gamespec.ocp.inputs`):

- parameters: the game's, each uncertain one at the value ``i`` assigns to ``j`` (``j``'s belief
  when ``j == i`` or ``i`` knows the others' beliefs, else ``i``'s own: the pursuer models the
  evader with ρ̂ in ``G^u``; the evader knows the pursuer uses ρ̂ in ``G^v``), the initial state as
  ``initial_<state>`` and the absolute start time as ``start_time`` — all runtime parameters, so a
  receding-horizon step re-solves the compiled model;
- the payoff (eq. 7.1) in ``j``'s sense, ``j``'s path constraints (eqs. 7.3–7.4), the terminal
  constraints (eq. 7.5), with ``t`` read as ``t + start_time`` (absolute time);
- ``j``'s requested ``transforms`` when ``j == i`` or ``i`` knows them (the evader does not know
  the pursuer's regularizer), so the solving chain applies them.

Every expression is printed back by :func:`~gamespec.symbolic.printer.to_text` from its SymPy form
parsed once when the game is compiled (:mod:`gamespec.games.expressions`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import sympy as sp

from gamespec.games.expressions import GameExpressions, game_expressions
from gamespec.specs.differential_game import (
    INITIAL_PREFIX,
    NOMINAL_PREFIX,
    START_TIME,
    DifferentialGameSpec,
    sensitivity_name,
)
from gamespec.specs.ocp import OptimalControlSpec, StateSpec
from gamespec.symbolic.grammar import Relation
from gamespec.symbolic.language import symbol
from gamespec.symbolic.printer import to_text


def _text(expr: sp.Expr, shift: dict) -> str:
    return to_text(expr.subs(shift))


def _relations(rel: Relation, shift: dict) -> list[str]:
    """A constraint of the file printed back (a two-sided one as two one-sided ones)."""
    expr = sp.sympify(rel.expr).subs(shift)
    if rel.lower == rel.upper:
        return [to_text(sp.Eq(expr, sp.Float(rel.lower)))]
    out = []
    if math.isfinite(rel.lower):
        out.append(to_text(sp.Ge(expr, sp.Float(rel.lower))))
    if math.isfinite(rel.upper):
        out.append(to_text(sp.Le(expr, sp.Float(rel.upper))))
    return out


def parameter_values(game: DifferentialGameSpec, player: str, view: str) -> dict[str, float]:
    """The uncertain parameters' values in ``player``'s problem of the game ``view`` solves."""
    owner = game.problem.players[view]
    holder = player if player == view or owner.knows_beliefs else view
    return {name: u.belief(holder) for name, u in game.problem.uncertain.items()}


def applies_transforms(game: DifferentialGameSpec, player: str, view: str) -> bool:
    return player == view or game.problem.players[view].knows_transforms


def initial_state(
    game: DifferentialGameSpec, parameters: Mapping[str, float] | None = None
) -> dict[str, float]:
    """The game's initial state (eq. 7.2's x_0; a free initial value starts at 0), evaluated at load
    (:attr:`~gamespec.specs.differential_game.GameProblem.values`), or again at the runtime
    ``parameters`` of a compiled game where they differ from the file's."""
    p = game.problem
    if parameters is None or all(parameters.get(n, v) == v for n, v in p.parameters.items()):
        return dict(p.values.initial)
    return p.evaluate(parameters).initial


def predicted_states(game: DifferentialGameSpec, view: str) -> list[str]:
    """The states the player ``view`` predicts, whose initial values in its game carry their
    accumulated sensitivity (``receding_horizon.sensitivity_time: absolute``)."""
    rh, observes = game.receding_horizon, game.problem.players[view].observes
    if rh is None or rh.sensitivity_time == "relative" or observes is None or not game.problem.uncertain:
        return []
    return [s for s in game.problem.states if s not in observes]


def _initial_value(name: str, predicted: bool, uncertain: list[str]) -> str:
    """``initial_<x>``, or for a predicted state the first-order expansion of eq. 7.14,
    ``initial_<x> + Σ_ρ initial_S_<x>_<ρ> (ρ − nominal_ρ)``, equal to ``initial_<x>`` at the problem's
    parameter values and with ``∂x0/∂ρ`` the predicted sensitivity."""
    value = symbol(f"{INITIAL_PREFIX}{name}")
    if predicted:
        value += sum(
            symbol(sensitivity_name(name, u)) * (symbol(u) - symbol(f"{NOMINAL_PREFIX}{u}"))
            for u in uncertain
        )
    return to_text(value)


def player_problem(
    game: DifferentialGameSpec, player: str, view: str, expressions: GameExpressions | None = None
) -> OptimalControlSpec:
    """``player``'s best-response problem in the game ``view`` solves (see module doc), printed
    from the game's parsed ``expressions`` (parsed here when not given)."""
    p = game.problem
    me = p.players[player]
    parsed = expressions or game_expressions(game)
    shift = parsed.symbols.shift
    x0 = initial_state(game)
    beliefs = parameter_values(game, player, view)
    predicted = predicted_states(game, view)
    parameters = (
        dict(p.parameters)
        | beliefs
        | {f"{INITIAL_PREFIX}{s}": v for s, v in x0.items()}
        | {START_TIME: float(game.problem.time.initial)}
        | {f"{NOMINAL_PREFIX}{u}": v for u, v in beliefs.items()}
        | {sensitivity_name(s, u): 0.0 for s in predicted for u in p.uncertain}
    )
    states = {
        name: StateSpec(
            initial=_initial_value(name, name in predicted, list(p.uncertain)),
            lower=s.lower,
            upper=s.upper,
            final=s.final,
        )
        for name, s in p.states.items()
    }
    others = {n: pl for n, pl in p.players.items() if n != player}
    inputs = {c: {"default": o.start.get(c, 0.0)} for o in others.values() for c in o.controls}
    payoff = parsed.payoffs.get(player, parsed.payoff)
    path = [r for c in parsed.path[player] for r in _relations(c, shift)]
    terminal = [r for c in parsed.terminal for r in _relations(c, shift)]
    horizon = parsed.final_time - p.time.initial
    problem = {
        "parameters": parameters,
        "states": {n: s.model_dump() for n, s in states.items()},
        "controls": {n: c.model_dump() for n, c in me.controls.items()},
        "inputs": inputs,
        "dynamics": {n: _text(parsed.dynamics[n], shift) for n in p.dynamics},
        "objective": {
            "sense": me.objective,
            "mayer": _text(payoff.mayer, shift),
            "lagrange": _text(payoff.lagrange, shift),
        },
        "time": {"initial": 0.0, "final": to_text(horizon)},
        "path_constraints": path,
        "boundary_constraints": terminal,
        "uncertain": {n: u.distribution.model_dump() for n, u in p.uncertain.items() if u.distribution},
    }
    return OptimalControlSpec.model_validate(
        {
            "name": f"{game.name}.{view}.{player}",
            "problem": problem,
            "method": game.method.model_dump(),
            "solver": {"backend": game.game.backend, "options": game.solver.options},
            "guess": {"controls": dict(me.start)},
            "transforms": list(me.transforms) if applies_transforms(game, player, view) else [],
        }
    )


def views(game: DifferentialGameSpec, expressions: GameExpressions | None = None) -> list[str]:
    """The games to solve: one per player (``G^i``), or one for all when every player's problems
    are the same in every player's game (no private beliefs or transforms)."""
    names = list(game.problem.players)
    parsed = expressions or game_expressions(game)
    games = [[player_problem(game, j, i, parsed).model_dump(exclude={"name"}) for j in names] for i in names]
    return names[:1] if all(g == games[0] for g in games) else names


def player_problems(game: DifferentialGameSpec) -> dict[str, dict[str, OptimalControlSpec]]:
    """Every best-response problem the game's players solve: per game solved (:func:`views`),
    each player's :func:`player_problem` (its requested ``transforms`` still to apply)."""
    names = list(game.problem.players)
    return {view: {player: player_problem(game, player, view) for player in names} for view in views(game)}
