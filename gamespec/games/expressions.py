"""A game's expressions read from its file once, in SymPy, for everything built from them later.

The spec checks every expression at load (:meth:`~gamespec.specs.differential_game.GameProblem`);
:func:`game_expressions` parses them once more into SymPy when the game is compiled
(:class:`~gamespec.games.equilibrium.GameModel`), and from then on the players' problems
(:mod:`gamespec.games.problems`), the true system's integrator (:mod:`gamespec.games.simulate`) and
the receding horizon's stop rules (:mod:`gamespec.games.receding_horizon`) are built from these
SymPy forms: no text is parsed again at solve time (issue 27, item 3).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from gamespec.errors import SpecError
from gamespec.specs.differential_game import START_TIME, DifferentialGameSpec, PayoffSpec
from gamespec.symbolic.grammar import Relation
from gamespec.symbolic.language import parse, parse_relation, symbol


@dataclass(frozen=True)
class Symbols:
    """The symbol tables of a game's expressions: ``running`` (parameters, controls, states, ``t``),
    ``ends`` (parameters, ``<state>_f``, ``t_f``) and ``shift``, which reads ``t`` and ``t_f`` as
    absolute times (``t + start_time``) in a player's problem."""

    running: dict[str, sp.Symbol]
    ends: dict[str, sp.Symbol]
    shift: dict[sp.Symbol, sp.Expr]


def symbols_of(game: DifferentialGameSpec) -> Symbols:
    p = game.problem
    params = {n: symbol(n) for n in [*p.parameters, *p.uncertain]}
    controls = {c: symbol(c) for pl in p.players.values() for c in pl.controls}
    running = params | controls | {n: symbol(n) for n in [*p.states, "t"]}
    ends = params | {f"{s}_f": symbol(f"{s}_f") for s in p.states} | {"t_f": symbol("t_f")}
    start = symbol(START_TIME)
    return Symbols(running, ends, {symbol("t"): symbol("t") + start, symbol("t_f"): symbol("t_f") + start})


@dataclass(frozen=True)
class Payoff:
    """Eq. 7.1 in SymPy: the Mayer term over the ends, the Lagrange integrand over the running names."""

    mayer: sp.Expr
    lagrange: sp.Expr


@dataclass(frozen=True)
class StopRules:
    """The receding horizon's expressions over the states and parameters: the capture relation
    and the obstacle's centre and radius (None where the file has none)."""

    capture: Relation | None
    obstacle: dict[str, sp.Expr] | None


@dataclass(frozen=True)
class GameExpressions:
    """Every expression of a game in SymPy (see module doc): the dynamics by state, the shared
    payoff and each player's own, each player's path constraints and the terminal constraints as
    relations, the final time and the receding horizon's stop rules."""

    symbols: Symbols
    dynamics: dict[str, sp.Expr]
    payoff: Payoff
    payoffs: dict[str, Payoff]
    path: dict[str, list[Relation]]
    terminal: list[Relation]
    final_time: sp.Expr
    stop: StopRules
    parameters: list[str] = field(default_factory=list)
    """The game's parameter names, the uncertain ones last (the order of the compiled functions'
    parameter vector)."""
    control_bounds: dict[str, tuple[sp.Expr | None, sp.Expr | None]] = field(default_factory=dict)
    """Each control's lower and upper bound over the running names (None where it has none)."""


def _payoff(payoff: PayoffSpec, sym: Symbols) -> Payoff:
    return Payoff(sp.sympify(parse(payoff.mayer, sym.ends)), sp.sympify(parse(payoff.lagrange, sym.running)))


def _stop_rules(game: DifferentialGameSpec) -> StopRules:
    rh = game.receding_horizon
    p = game.problem
    table = {n: symbol(n) for n in [*p.parameters, *p.uncertain, *p.states]}

    def read(text: str | float, where: str, constraint: bool) -> Relation | sp.Expr:
        try:
            return parse_relation(str(text), table) if constraint else sp.sympify(parse(text, table))
        except SpecError as err:
            raise SpecError(err.reason, field=f"receding_horizon.{where}", source=game.source) from None

    if rh is None:
        return StopRules(None, None)
    capture = read(rh.capture.when, "capture.when", True) if rh.capture else None
    ob = rh.obstacle
    obstacle = {k: read(getattr(ob, k), f"obstacle.{k}", False) for k in ("x", "y", "radius")} if ob else None
    assert capture is None or isinstance(capture, Relation), "a capture rule is a relation"
    return StopRules(capture, obstacle)


def _bound(value: str | float | None, sym: Symbols) -> sp.Expr | None:
    return None if value is None else sp.sympify(parse(value, sym.running))


def game_expressions(game: DifferentialGameSpec) -> GameExpressions:
    """The game's expressions parsed into SymPy (see module doc)."""
    p = game.problem
    sym = symbols_of(game)
    controls = {c: spec for pl in p.players.values() for c, spec in pl.controls.items()}
    return GameExpressions(
        symbols=sym,
        dynamics={s: sp.sympify(parse(p.dynamics[s], sym.running)) for s in p.states},
        payoff=_payoff(p.payoff, sym),
        payoffs={n: _payoff(pl.payoff, sym) for n, pl in p.players.items() if pl.payoff is not None},
        path={n: [parse_relation(c, sym.running) for c in q.path_constraints] for n, q in p.players.items()},
        terminal=[parse_relation(c, sym.ends) for c in p.terminal_constraints],
        final_time=sp.sympify(parse(p.time.final, sym.running)),
        stop=_stop_rules(game),
        parameters=[*p.parameters, *p.uncertain],
        control_bounds={c: (_bound(b.lower, sym), _bound(b.upper, sym)) for c, b in controls.items()},
    )
