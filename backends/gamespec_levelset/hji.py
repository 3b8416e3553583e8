"""The ``hji`` backend: the capture region of a two-state ``differential_game`` as the zero sublevel set
of a Hamilton–Jacobi–Isaacs value function on a grid (a game of kind, Isaacs; as hj_reachability's
backward reachable tube).

With the target ``l(x) ≤ 0`` (the file's ``problem.capture``, ``g ≤ c`` read as ``l = g − c`` and
``g ≥ c`` as ``l = c − g``), the value ``φ(x, τ) = min_pursuers max_evaders min_{s ≤ τ} l(x(s))``
solves ``∂φ/∂τ = min(0, H(x, ∇φ))`` from ``φ(x, 0) = l(x)``, with the Isaacs Hamiltonian
``H(x, p) = min_u max_d p · f(x, u, d)`` (u: the minimizing players' controls, d: the maximizing
ones'); a node is captured within the horizon T when ``φ(x, T) ≤ 0``. The scheme is the project's
level-set numerics (:mod:`gamespec.flowfield.upwind`: one-sided derivatives with ghost nodes by
linear extrapolation; :mod:`gamespec.flowfield.tvd_rk`: TVD-RK3) with a numerical Hamiltonian
``Ĥ(p⁻, p⁺)`` (``flux``) and the reach clamp ``φ ← min(φ, φ_before)`` after each step. ``upwind``
(the default): ``Ĥ = min_u max_d Σ_i [max(f_i, 0) p⁺_i + min(f_i, 0) p⁻_i]``, f = f(x, u, d) over
the control samples: every sample's Hamiltonian is linear in p, ``∂φ/∂τ = f · ∇φ`` carries φ
against f, and each is upwinded exactly (its own ``α_i = |f_i|``); the min and max of monotone
fluxes are monotone (nondecreasing in p⁺, nonincreasing in p⁻), consistent (``Ĥ(p, p) = H(p)``), and
add no dissipation beyond each sample's upwinding. ``lax_friedrichs``: the local Lax–Friedrichs flux
``Ĥ = H(x, (p⁻ + p⁺)/2) + Σ_i α_i (p⁺_i − p⁻_i)/2`` with ``α_i = max |f_i|`` over every sample at the
node (Osher & Shu 1991; Osher & Fedkiw §5.3.1's LLF, as ToolboxLS's ``artificialDissipationLLF``:
for dynamics linear in p per sample, the bound over all costates is the bound over the samples).
Its dissipation is that of the fastest sample, wherever the optimal one is slow: it fills in the
chauffeur's narrow neck between the barrier's arcs, and the study over ℓ's switch lies above
Isaacs' threshold by an error that falls as h^0.6 against the upwind flux's h^1
(``benchmarks/chauffeur_threshold.py``; ``docs/feedback-equilibria.md``). The upwind flux costs
1.7 to 2.5 times the CPU per solve (41 to 81 nodes: its sums run over every pair of samples, not
over the two players' apart).
The ghost nodes extrapolate linearly, so what lies outside the box is guessed: the box must hold the
manoeuvres that capture (a region too small for them stops growing early).

The min and max over the control boxes are taken over samples: a control that enters the dynamics
affinely (zero second derivative) is sampled at its two bounds (exact: a linear function's optimum
over an interval is at a bound), any other at ``control_samples`` equally spaced values including the
bounds (the optimum within the spacing). Where no component of the dynamics mixes a minimizer's and
a maximizer's control (zero cross derivatives), the min and the max are taken separately (the
samples add); otherwise over every pair (the samples multiply). The payoff is not used: this is the
game of kind.

Reach–avoid (``problem.avoid``, a set the minimizing players must not enter, ``g`` its level
negated, positive inside): ``φ ← max(min(φ_step, φ), g)`` from ``max(l, g)``, as hj_reachability's
``static_obstacle`` value postprocessor (Fisac et al.'s reach–avoid value). The maximizing players
are the disturbance.

A game of degree (``time.final: free`` within ``bounds``; the payoff the capture time): the node's
time to reach, ``T(x) = min{τ : φ(x, τ) ≤ 0}`` (linear in τ between steps), is the minimum time to
capture (``arrays.capture_time``, +∞ where not reached within the upper bound), and the game from
the initial state (φ interpolated bilinearly there) is decided: ``capture`` at ``T(x₀)``,
``escape`` (the capture time +∞) when it is not reached and the captured set has converged (its
part connected to the target the same at the bound as at half of it, clear of the grid's edge:
:func:`converged`), else ``undecided`` (``iteration_limit``). The bound must exceed twice the time
the set takes to settle: a set still creeping into a narrow neck at T/2 reads as growing (the
chauffeur's study over ℓ, ``benchmarks/chauffeur_threshold.py``, switched 0.005 lower at T = 4
than at T = 8 or 16 at spacing 0.05 by the Lax–Friedrichs flux; by the upwind flux the same at all
three). The concept is ``saddle`` when the min and max separate
(Isaacs' minimax condition, under which the upper and lower values of eqs. 4.9–4.10 agree), else
``upper_value`` (eq. 4.9's order: the maximizer answers the minimizer's control); the information
pattern is feedback. The value generalizes the reachability front of eq. 5.22 (the level of the
target starts as eq. 5.21's signed distance to first order) to two players.

``engine: hj_reachability`` computes the same value by hj_reachability (:mod:`gamespec_levelset.hji_jax`,
the optional ``hj`` extra).

Status: ``optimal`` when the grid-refinement check passes — the captured set's edge on the file's
grid and on one with half the nodes per axis (the same box, every other node) are on average at most
``refinement_tolerance`` coarse cells apart (:func:`boundary_shift`,
``checks.capture_region_refinement``). ``metrics.capture_region`` holds the captured area, its share
of the grid, and the area captured within half the horizon (equal when the region has stopped
growing: every capture from it happens within T/2), whether it has :func:`converged`, and
``detached_nodes``, the captured nodes not connected to the target (:func:`attached`: the edge's
guess, left out of the convergence test); a game of
degree also checks that the half-resolution grid decides the same, with a capture time within
``capture_time_tolerance`` of it (``checks.capture_time_refinement``).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass
from typing import Any, ClassVar, Literal

import numpy as np
import sympy as sp
from pydantic import Field, model_validator
from scipy import ndimage

from gamespec.compiling import Backend, CompiledModel, Inputs, refuse_inputs
from gamespec.errors import ExpressionError, SpecError, UnsupportedFeature
from gamespec.flowfield.budget import UNLIMITED, Budget
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.scratch import Scratch
from gamespec.flowfield.tvd_rk import tvd_rk3_step
from gamespec.flowfield.upwind import GHOSTS, extrapolate_ghosts, upwind_pair
from gamespec.limits import MAX_GAME_STATE, MAX_HJI_NODE_STEPS
from gamespec.result import Result, Status
from gamespec.specs.base import StrictModel
from gamespec.specs.differential_game import DifferentialGameSpec
from gamespec.symbolic.calculus import numeric_function
from gamespec.symbolic.grammar import Relation
from gamespec.symbolic.language import parse, parse_relation, symbol
from gamespec.terminal import progress

ONE_SIDED = "a set is one one-sided relation (g <= c or g >= c)"
Flux = Literal["upwind", "lax_friedrichs"]


class HJIOptions(StrictModel):
    """The grid, horizon and scheme of the ``hji`` backend (``solver.options.hji``)."""

    lower: tuple[float, float] | None = Field(
        None, description="The grid's lower corner (default: the states' lower bounds)."
    )
    upper: tuple[float, float] | None = Field(
        None, description="The grid's upper corner (default: the states' upper bounds)."
    )
    nodes: int = Field(
        101,
        ge=9,
        le=801,
        description="Nodes per axis (odd: the refinement check's grid takes every other node).",
    )
    horizon: float | None = Field(
        None, gt=0, description="How long the pursuers have to capture (default: the game's horizon)."
    )
    scheme: Literal["first_order", "eno2", "weno5"] = Field("eno2", description="The upwind scheme.")
    flux: Flux = Field(
        "upwind",
        description="The numerical Hamiltonian: upwind (each control sample's p·f upwinded exactly, then "
        "the min and max over the samples) or lax_friedrichs (H at the mean costate plus the dissipation "
        "of the fastest sample per axis and node); engine: hj_reachability uses its own Lax–Friedrichs.",
    )
    engine: Literal["gamespec", "hj_reachability"] = Field(
        "gamespec",
        description="gamespec: the project's level-set numerics; hj_reachability: the same value by "
        "hj_reachability on JAX (the optional hj extra; gamespec_levelset.hji_jax).",
    )
    hj_outputs: int = Field(
        100,
        ge=2,
        le=5000,
        description="engine: hj_reachability: the stored times per half horizon (capture times are "
        "linear between them).",
    )
    cfl: float = Field(0.5, gt=0, le=1, description="The CFL number of the time step.")
    max_wall_time: float | None = Field(
        300.0,
        gt=0,
        description="Seconds of wall time the two value functions (the grid's and the half-resolution "
        "one's) may take, checked after every step: past it the run stops with the status time_limit "
        "(null: no limit; the hj_reachability engine is not stopped).",
    )
    control_samples: int = Field(
        33, ge=3, le=257, description="Samples of a control that does not enter the dynamics affinely."
    )
    capture_time_tolerance: float = Field(
        0.1,
        gt=0,
        description="time.final: free: how much the capture time from the initial state may change "
        "between the grid and the half-resolution one, as a fraction of it.",
    )
    refinement_tolerance: float = Field(
        1.0,
        gt=0,
        description="How far (in cells of the half-resolution grid) the captured set's edge may move "
        "between the grid and the half-resolution one.",
    )

    @model_validator(mode="after")
    def _ordered(self) -> HJIOptions:
        if self.nodes % 2 == 0:
            raise ValueError("nodes must be odd")
        box = self.lower, self.upper
        if None not in box and not all(lo < hi for lo, hi in zip(*box, strict=True)):  # type: ignore[arg-type]
            raise ValueError("every lower corner coordinate must be below the upper one")
        return self


@dataclass(frozen=True)
class SampledHamiltonian:
    """The dynamics at every node for each sample of the controls: ``base`` f(x, u₀, d₀) (2, nx, ny);
    separable: ``pursuer`` f(x, u_k, d₀) − base (K, 2, nx, ny) and ``evader`` f(x, u₀, d_m) − base
    (M, 2, nx, ny); otherwise ``joint`` f(x, u_k, d_m) − base (K, M, 2, nx, ny). ``speed`` (2, nx, ny)
    is ``max |f_i|`` over the samples (the Lax–Friedrichs α, and the CFL condition's speed);
    ``magnitude`` (2, K, M, nx, ny) is ``|f_i(x, u_k, d_m)|`` per axis and sample pair, for the
    upwind flux (:meth:`numerical`; None when the Lax–Friedrichs flux is used); ``work`` holds that
    flux's buffers."""

    base: np.ndarray
    pursuer: np.ndarray | None
    evader: np.ndarray | None
    joint: np.ndarray | None
    speed: np.ndarray
    magnitude: np.ndarray | None = None
    work: dict[str, np.ndarray] = dataclasses.field(default_factory=dict, repr=False, compare=False)

    def __call__(self, p: np.ndarray) -> np.ndarray:
        """``min_u max_d p · f`` at every node for the costate ``p`` (2, nx, ny)."""
        value: np.ndarray = np.einsum("i...,i...->...", p, self.base)
        if self.joint is not None:
            value += np.einsum("i...,kmi...->km...", p, self.joint).max(axis=1).min(axis=0)
            return value
        assert self.pursuer is not None and self.evader is not None, "a separable game has both"
        value += np.einsum("i...,ki...->k...", p, self.pursuer).min(axis=0)
        value += np.einsum("i...,ki...->k...", p, self.evader).max(axis=0)
        return value

    def numerical(self, minus: np.ndarray, plus: np.ndarray) -> np.ndarray:
        """The numerical Hamiltonian ``Ĥ(p⁻, p⁺)`` (2, nx, ny each; module doc): Lax–Friedrichs
        ``H(p̄) + Σ_i α_i (p⁺_i − p⁻_i)/2`` with ``p̄ = (p⁻ + p⁺)/2`` and α = ``speed`` when
        ``magnitude`` is None; else upwind, ``min_k max_m Σ_i [f_i p̄_i + |f_i| (p⁺_i − p⁻_i)/2]``
        with ``f = f(x, u_k, d_m)``, which is ``Σ_i max(f_i, 0) p⁺_i + min(f_i, 0) p⁻_i``: each
        sample's linear Hamiltonian upwinded exactly (``∂φ/∂τ = f · ∇φ`` carries φ against f, so
        its information comes from the side f points to), then the min and max over the samples.
        The sums over the sample pairs are formed in buffers kept from call to call."""
        mean, jump = (minus + plus) / 2, (plus - minus) / 2
        if self.magnitude is None:
            lax_friedrichs: np.ndarray = self(mean) + self.speed[0] * jump[0] + self.speed[1] * jump[1]
            return lax_friedrichs
        work = self.work
        if not work:
            shape = self.magnitude.shape[1:]
            work.update(pairs=np.empty(shape), term=np.empty(shape))
            if self.evader is not None:
                work.update(evader=np.empty(self.evader[:, 0].shape), part=np.empty(self.evader[:, 0].shape))
        pairs, term = work["pairs"], work["term"]
        np.multiply(self.magnitude[0], jump[0], out=pairs)
        pairs += np.multiply(self.magnitude[1], jump[1], out=term)
        if self.joint is not None:
            pairs += np.multiply(self.joint[:, :, 0], mean[0], out=term)
            pairs += np.multiply(self.joint[:, :, 1], mean[1], out=term)
            best = pairs.max(axis=1).min(axis=0)
        else:
            assert self.pursuer is not None and self.evader is not None, "a separable game has both"
            evader = np.multiply(self.evader[:, 0], mean[0], out=work["evader"])
            evader += np.multiply(self.evader[:, 1], mean[1], out=work["part"])
            pairs += evader
            best = (pairs.max(axis=1) + self.pursuer[:, 0] * mean[0] + self.pursuer[:, 1] * mean[1]).min(0)
        upwind: np.ndarray = self.base[0] * mean[0] + self.base[1] * mean[1] + best
        return upwind


def _samples(
    exprs: list[sp.Expr], names: list[str], bounds: dict[str, tuple[float, float]], n: int
) -> list[dict[str, float]]:
    """Every combination of the controls' samples (two bounds for an affine control)."""
    per: list[tuple[float, ...]] = []
    for name in names:
        lo, hi = bounds[name]
        affine = all(sp.diff(e, symbol(name), 2) == 0 for e in exprs)
        per.append((lo, hi) if affine else tuple(float(v) for v in np.linspace(lo, hi, n)))
    return [dict(zip(names, combo, strict=True)) for combo in itertools.product(*per)]


@dataclass(frozen=True)
class ParsedGame:
    """The game's expressions parsed once, when the model is compiled, over the parameters as
    symbols (issue 27, item 3): the dynamics, the control bounds (None: none) and the sets
    (``problem.capture``, ``problem.avoid``) by field; a solve substitutes the parameter values."""

    states: list[str]
    dynamics: list[sp.Expr]
    minimizers: list[str]
    maximizers: list[str]
    bounds: dict[str, tuple[sp.Expr | None, sp.Expr | None]]
    sets: dict[str, Relation]


def parsed_game(game: DifferentialGameSpec) -> ParsedGame:
    """:class:`ParsedGame` of ``game`` (a set that is not one one-sided relation is refused)."""
    p = game.problem
    controls = [c for pl in p.players.values() for c in pl.controls]
    table = {n: symbol(n) for n in [*p.parameters, *p.states, *controls]}
    sets = {}
    for field, text in (("problem.capture", p.capture), ("problem.avoid", p.avoid)):
        if text is None:
            continue
        try:
            sets[field] = parse_relation(text, table)
        except ExpressionError:
            raise SpecError(ONE_SIDED, field=field) from None
    return ParsedGame(
        states=list(p.states),
        dynamics=[sp.sympify(parse(p.dynamics[s], table)) for s in p.states],
        minimizers=[c for pl in p.players.values() if pl.objective == "minimize" for c in pl.controls],
        maximizers=[c for pl in p.players.values() if pl.objective == "maximize" for c in pl.controls],
        bounds={
            c: (_parsed(ctl.lower, table), _parsed(ctl.upper, table))
            for pl in p.players.values()
            for c, ctl in pl.controls.items()
        },
        sets=sets,
    )


def _parsed(raw: float | str | None, table: dict[str, Any]) -> sp.Expr | None:
    return None if raw is None else sp.sympify(parse(raw, table))


def _at(expr: sp.Expr, parameters: dict[str, float]) -> sp.Expr:
    """``expr`` at these parameter values."""
    return expr.xreplace({symbol(n): sp.Float(v) for n, v in parameters.items()})


@dataclass(frozen=True)
class ControlSamples:
    """The game's dynamics as SymPy expressions over the states and controls (the parameters
    substituted), and the samples of the minimizers' (``us``) and maximizers' (``ds``) controls
    (module doc); ``separable`` when no component mixes a minimizer's and a maximizer's control."""

    exprs: list[sp.Expr]
    states: list[str]
    controls: list[str]
    us: list[dict[str, float]]
    ds: list[dict[str, float]]
    separable: bool


def control_samples(game: ParsedGame, samples: int, parameters: dict[str, float]) -> ControlSamples:
    """The dynamics and the samples of the players' control boxes (:class:`ControlSamples`)."""
    states = game.states
    exprs = [_at(e, parameters) for e in game.dynamics]
    minimizers, maximizers = game.minimizers, game.maximizers
    bounds = {c: (_bound(lo, parameters), _bound(hi, parameters)) for c, (lo, hi) in game.bounds.items()}
    us, ds = _samples(exprs, minimizers, bounds, samples), _samples(exprs, maximizers, bounds, samples)
    separable = all(
        sp.diff(e, symbol(u), symbol(d)) == 0 for e in exprs for u in minimizers for d in maximizers
    )
    return ControlSamples(exprs, states, [*minimizers, *maximizers], us, ds, separable)


def sampled_hamiltonian(
    game: ParsedGame, grid: Grid, samples: int, parameters: dict[str, float], flux: Flux
) -> SampledHamiltonian:
    """The dynamics of ``game`` sampled at ``grid``'s nodes over the players' control boxes (module
    doc), with the magnitudes per sample pair when the ``flux`` is ``upwind``."""
    sampled = control_samples(game, samples, parameters)
    controls, us, ds, separable = sampled.controls, sampled.us, sampled.ds, sampled.separable
    f = numeric_function(sampled.exprs, [symbol(s) for s in sampled.states] + [symbol(c) for c in controls])
    x, y = grid.points[..., 0], grid.points[..., 1]

    def at(u: dict[str, float]) -> np.ndarray:
        return np.broadcast_to(f(x, y, *(u[c] for c in controls)), (2, *x.shape)).astype(float)

    u0, d0 = us[0], ds[0]
    base = at(u0 | d0)
    if separable:
        pursuer = np.stack([at(u | d0) - base for u in us])
        evader = np.stack([at(u0 | d) - base for d in ds])
        highest = base + pursuer.max(axis=0) + evader.max(axis=0)
        speed = np.maximum(highest, -(base + pursuer.min(axis=0) + evader.min(axis=0)))
        magnitude = None
        if flux == "upwind":
            magnitude = np.ascontiguousarray(
                np.abs(np.moveaxis(base + pursuer[:, None] + evader[None], 2, 0))
            )
        return SampledHamiltonian(base, pursuer, evader, None, speed, magnitude)
    joint = np.stack([np.stack([at(u | d) - base for d in ds]) for u in us])
    magnitude = np.ascontiguousarray(np.abs(np.moveaxis(joint + base, 2, 0)))
    speed = magnitude.max(axis=(1, 2))
    return SampledHamiltonian(base, None, None, joint, speed, magnitude if flux == "upwind" else None)


def _number(
    raw: float | str | None,
    parameters: dict[str, float],
    field: str = "problem.players",
    what: str = "finite bounds on every control",
) -> float:
    """The finite number ``raw`` stands for; a SpecError naming ``field`` when there is none."""
    value = (
        math.inf
        if raw is None
        else float(sp.sympify(parse(raw, {n: sp.Float(v) for n, v in parameters.items()})))
    )
    if not math.isfinite(value):
        raise SpecError(f"the hji backend needs {what}", field=field)
    return value


def _bound(expr: sp.Expr | None, parameters: dict[str, float]) -> float:
    """A control bound parsed once (:class:`ParsedGame`) at these parameter values; finite."""
    value = math.inf if expr is None else float(_at(expr, parameters))
    if not math.isfinite(value):
        raise SpecError("the hji backend needs finite bounds on every control", field="problem.players")
    return value


def target(game: ParsedGame, grid: Grid, parameters: dict[str, float]) -> np.ndarray:
    """``l / |∇l|`` of ``problem.capture`` at the nodes (:func:`relation_level`)."""
    return relation_level(game, "problem.capture", grid, parameters)


def relation_level(game: ParsedGame, field: str, grid: Grid, parameters: dict[str, float]) -> np.ndarray:
    """``l / |∇l|`` at the nodes for the set ``relation`` (``g ≤ c``: ``l = g − c``; ``g ≥ c``:
    ``l = c − g``): negative inside the set, the signed distance to its edge to first order there
    (module doc), so the level set's slope is about one at the front."""
    rel = game.sets[field]
    expr, names = _at(sp.sympify(rel.expr), parameters), [symbol(s) for s in game.states]
    if math.isfinite(rel.upper) and not math.isfinite(rel.lower):
        level = expr - rel.upper
    elif math.isfinite(rel.lower) and not math.isfinite(rel.upper):
        level = rel.lower - expr
    else:
        raise SpecError(ONE_SIDED, field=field)
    gradient = sp.sqrt(sum(sp.diff(level, n) ** 2 for n in names))
    f = numeric_function([level, gradient], names)
    values = np.broadcast_to(f(grid.points[..., 0], grid.points[..., 1]), (2, *grid.shape)).astype(float)
    floor = 1e-3 * float(np.abs(values[1]).max() or 1.0)
    distance: np.ndarray = values[0] / np.maximum(values[1], floor)
    return distance


@dataclass(frozen=True)
class ReachRun:
    """What :func:`reach_value` computes: ``value`` φ(·, T) and ``half`` φ(·, T/2); ``arrival`` the
    first τ at which each node's φ reaches zero (the minimum time to capture, ``inf`` where it does
    not within T; linear in τ between steps); ``probe_arrival`` the same for the bilinear
    interpolation of φ at one point (the initial state), and the ``steps`` taken; ``timed_out`` when
    the budget stopped the run before the horizon."""

    value: np.ndarray
    half: np.ndarray
    arrival: np.ndarray
    probe_arrival: float
    steps: int
    timed_out: bool = False


def reach_value(
    hamiltonian: SampledHamiltonian,
    grid: Grid,
    initial: np.ndarray,
    horizon: float,
    scheme: str,
    cfl: float,
    avoid: np.ndarray | None = None,
    probe: tuple[float, float] | None = None,
    budget: Budget = UNLIMITED,
) -> ReachRun:
    """φ of ``∂φ/∂τ = min(0, H)`` from ``initial`` up to ``horizon`` (module doc); with ``avoid``
    (``g``, positive inside the avoid set) the reach–avoid value ``φ ← max(min(φ_step, φ), g)``
    from ``max(initial, g)``. Each step is counted on ``budget``'s progress line, and the run stops
    when it expires; :func:`time_steps` bounds their number first."""
    g = GHOSTS
    nx, ny = grid.shape
    dx = grid.spacing
    steps = time_steps(hamiltonian, grid, horizon, cfl)
    dt = horizon / steps
    padded = [np.zeros((nx + 2 * g, ny + 2 * g)) for _ in range(3)]
    inner = [a[g:-g, g:-g] for a in padded]
    inner[0][...] = initial if avoid is None else np.maximum(initial, avoid)
    scratch = Scratch((nx + 2 * g) * (ny + 2 * g))
    arrival = np.where(inner[0] <= 0, 0.0, np.inf)
    weights = bilinear(grid, probe)
    probe_value = at_point(inner[0], weights)
    probe_arrival = 0.0 if probe_value <= 0 else math.inf

    def rate(k: int) -> np.ndarray:
        extrapolate_ghosts(padded[k])
        lx, rx = upwind_pair(padded[k][:, g:-g], 0, dx[0], scheme, scratch)
        ly, ry = upwind_pair(padded[k][g:-g, :], 1, dx[1], scheme, scratch)  # the other axis' buffers
        return hamiltonian.numerical(np.stack([lx, ly]), np.stack([rx, ry]))

    half = inner[0].copy()
    for step in range(steps):
        if budget.expired():
            return ReachRun(inner[0].copy(), half, arrival, probe_arrival, step, timed_out=True)
        budget.advance(f"tau = {step * dt:.3g} of {horizon:g}")
        before = inner[0].copy()
        tvd_rk3_step(inner[0], inner[1], inner[2], dt, rate)
        np.minimum(inner[0], before, out=inner[0])
        if avoid is not None:
            np.maximum(inner[0], avoid, out=inner[0])
        reached = (inner[0] <= 0) & np.isinf(arrival)
        arrival[reached] = (step + before[reached] / (before[reached] - inner[0][reached])) * dt
        now = at_point(inner[0], weights)
        if math.isinf(probe_arrival) and now <= 0:
            probe_arrival = (step + probe_value / (probe_value - now)) * dt
        probe_value = now
        if step + 1 == steps // 2:
            half = inner[0].copy()
    return ReachRun(inner[0].copy(), half, arrival, probe_arrival, steps)


def time_steps(hamiltonian: SampledHamiltonian, grid: Grid, horizon: float, cfl: float) -> int:
    """The even number of TVD-RK3 steps to ``horizon`` that the CFL condition ``dt·Σ_i α_i/Δx_i ≤ cfl``
    asks for; a SpecError when the dynamics' speed on the grid is not finite or the node updates
    (nodes times steps) would exceed :data:`~gamespec.limits.MAX_HJI_NODE_STEPS`."""
    dx = grid.spacing
    rate_bound = float((hamiltonian.speed[0] / dx[0] + hamiltonian.speed[1] / dx[1]).max())
    if not math.isfinite(rate_bound):
        raise SpecError("the dynamics' speed on the hji grid is not finite", field="problem.dynamics")
    fewest = horizon * rate_bound / cfl
    work = fewest * grid.shape[0] * grid.shape[1]
    if work > MAX_HJI_NODE_STEPS:
        raise SpecError(
            f"{grid.shape[0]}x{grid.shape[1]} nodes over the {fewest:.3g} CFL steps to tau = {horizon:g} "
            f"are {work:.3g} node updates, more than MAX_HJI_NODE_STEPS = {MAX_HJI_NODE_STEPS:.0e} "
            "(fewer nodes, a shorter horizon, or a box where the dynamics are slower)",
            field="solver.options.hji",
        )
    return 2 * max(1, math.ceil(fewest / 2))


def bilinear(grid: Grid, point: tuple[float, float] | None) -> list[tuple[int, int, float]]:
    """The nodes and weights of the bilinear interpolation at ``point`` (none without a point)."""
    if point is None:
        return []
    scaled = (np.asarray(point) - np.asarray(grid.lower)) / grid.spacing
    base = np.clip(np.floor(scaled).astype(int), 0, np.asarray(grid.shape) - 2)
    fx, fy = scaled - base
    i, j = int(base[0]), int(base[1])
    return [
        (i, j, (1 - fx) * (1 - fy)),
        (i + 1, j, fx * (1 - fy)),
        (i, j + 1, (1 - fx) * fy),
        (i + 1, j + 1, fx * fy),
    ]


def at_point(values: np.ndarray, weights: list[tuple[int, int, float]]) -> float:
    """``values`` interpolated with ``weights`` (:func:`bilinear`; +inf without a point)."""
    return float(sum(w * values[i, j] for i, j, w in weights)) if weights else math.inf


def stored_run(
    values: np.ndarray, taus: np.ndarray, grid: Grid, probe: tuple[float, float] | None
) -> ReachRun:
    """The :class:`ReachRun` of the values ``values[k]`` stored at the times ``taus[k]`` (an even
    number of intervals; first zero crossings linear between the stored times)."""
    arrival = np.where(values[0] <= 0, 0.0, np.inf)
    weights = bilinear(grid, probe)
    along = [at_point(v, weights) for v in values]
    probe_arrival = 0.0 if along[0] <= 0 else math.inf
    for k in range(1, len(values)):
        before, now = values[k - 1], values[k]
        reached = (now <= 0) & np.isinf(arrival)
        share = before[reached] / (before[reached] - now[reached])
        arrival[reached] = taus[k - 1] + share * (taus[k] - taus[k - 1])
        if math.isinf(probe_arrival) and along[k] <= 0:
            probe_arrival = taus[k - 1] + along[k - 1] / (along[k - 1] - along[k]) * (taus[k] - taus[k - 1])
    half = len(values) // 2
    return ReachRun(values[-1].copy(), values[half].copy(), arrival, float(probe_arrival), len(values) - 1)


class HJIModel(CompiledModel):
    """A compiled ``hji`` game: re-solved with new parameter values (the samples are recomputed)."""

    def __init__(self, game: DifferentialGameSpec, options: HJIOptions) -> None:
        self.game, self.options = game, options
        self.parsed = parsed_game(game)
        self.parameters = dict(game.problem.parameters)
        p = game.problem

        def corner(end: Literal["lower", "upper"]) -> tuple[float, float]:
            given = getattr(options, end)
            if given is not None:
                return given  # type: ignore[no-any-return]
            what = "finite state bounds or solver.options.hji.lower and upper"
            x, y = (
                _number(getattr(st, end), self.parameters, "problem.states", what) for st in p.states.values()
            )
            return x, y

        self.box = (corner("lower"), corner("upper"))
        if any(abs(v) > MAX_GAME_STATE for v in (*self.box[0], *self.box[1])):
            raise SpecError(
                f"the grid {self.box} reaches beyond MAX_GAME_STATE = {MAX_GAME_STATE:.0e}",
                field="solver.options.hji",
            )

    def _region(
        self,
        nodes: int,
        parameters: dict[str, float],
        horizon: float,
        probe: tuple[float, float] | None,
        budget: Budget,
    ) -> tuple[Grid, ReachRun, bool]:
        """The grid, the reach (–avoid) run on it (stopped when ``budget`` expires) and whether the
        min and max were taken separately (Isaacs' condition holds for the sampled controls)."""
        grid = Grid(self.box[0], self.box[1], (nodes, nodes))
        o = self.options
        ham = sampled_hamiltonian(self.parsed, grid, o.control_samples, parameters, o.flux)
        start = target(self.parsed, grid, parameters)
        avoid = self.game.problem.avoid
        barrier = None if avoid is None else -relation_level(self.parsed, "problem.avoid", grid, parameters)
        if o.engine == "hj_reachability":
            time_steps(ham, grid, horizon, o.cfl)  # the same work bound; its own steps are not stopped
            run = self._hj_reachability(grid, start, horizon, parameters, barrier, probe)
        else:
            run = reach_value(ham, grid, start, horizon, o.scheme, o.cfl, barrier, probe, budget)
        return grid, run, ham.joint is None

    def _hj_reachability(
        self,
        grid: Grid,
        start: np.ndarray,
        horizon: float,
        parameters: dict[str, float],
        avoid: np.ndarray | None,
        probe: tuple[float, float] | None,
    ) -> ReachRun:
        """:func:`reach_value`'s run by hj_reachability (:mod:`gamespec_levelset.hji_jax`)."""
        from gamespec_levelset.hji_jax import reach_values_hj

        sampled = control_samples(self.parsed, self.options.control_samples, parameters)
        pairs = [[[(u | d)[c] for c in sampled.controls] for d in sampled.ds] for u in sampled.us]
        taus = np.linspace(0.0, horizon, 2 * self.options.hj_outputs + 1)
        box = (grid.lower, grid.upper, grid.shape)
        o = self.options
        names = [*sampled.states, *sampled.controls]
        values = reach_values_hj(sampled.exprs, names, pairs, box, start, -taus, o.scheme, o.cfl, avoid)
        return stored_run(values, taus, grid, probe)

    def solve(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        refuse_inputs(inputs, self.game.kind)
        values = self.parameters | (parameters or {})
        evaluated = self.game.problem.evaluate(values)
        horizon = self.options.horizon or evaluated.horizon
        probe = None
        if self.game.problem.time.free:
            x0, y0 = evaluated.initial.values()
            probe = (x0, y0)
            if not all(lo <= v <= hi for lo, v, hi in zip(self.box[0], probe, self.box[1], strict=True)):
                raise SpecError(
                    f"the initial state {probe} lies outside the grid {self.box}", field="solver.options.hji"
                )
        n = self.options.nodes
        with progress(f"{self.game.name} (hji value, {n}x{n} and the half-resolution grid)") as tracker:
            budget = Budget(self.options.max_wall_time, tracker)
            grid, run, separable = self._region(n, values, horizon, probe, budget)
            coarse_grid, coarse, _ = self._region((n + 1) // 2, values, horizon, probe, budget)
        stopped = next((r for r in (run, coarse) if r.timed_out), None)
        if stopped is not None:
            which = "the grid's" if stopped is run else "the half-resolution grid's"
            return Result(
                status=Status.TIME_LIMIT,
                message=budget.message(f"{which} value function after {stopped.steps} steps"),
                iterations=run.steps,
                parameters=values,
                metrics={"solution_concept": "value_function", "information": "feedback"},
            )
        captured = run.value <= 0
        shift = boundary_shift(captured, coarse.value <= 0, grid)
        cell = float(np.prod(grid.spacing))
        region: dict[str, Any] = {
            "area": float(captured.sum()) * cell,
            "fraction": float(captured.mean()),
            "area_at_half_horizon": float((run.half <= 0).sum()) * cell,
            "horizon": horizon,
            "nodes": n,
            "lower": list(grid.lower),
            "upper": list(grid.upper),
            "states": list(self.game.problem.states),
            "avoid": self.game.problem.avoid is not None,
            "converged": converged(run),
            "detached_nodes": int((captured & ~attached(captured, run.arrival == 0)).sum()),
        }
        tolerance = self.options.refinement_tolerance
        result = Result(
            status=Status.OPTIMAL,
            message=f"captured {region['fraction']:.1%} of the grid within T = {horizon:g} "
            f"({region['area_at_half_horizon'] / max(region['area'], cell):.0%} of it within T/2)",
            iterations=run.steps,
            parameters=values,
            arrays={
                "value": run.value,
                "capture_time": run.arrival,
                "grid_x": grid.axes[0],
                "grid_y": grid.axes[1],
            },
            checks={"capture_region_refinement": shift},
            metrics={
                "capture_region": region,
                "solution_concept": "value_function",
                "information": "feedback",
                "checks_passed": {"capture_region_refinement": shift <= tolerance},
                "check_tolerances": {"capture_region_refinement": tolerance},
            },
        )
        if probe is None:
            return result
        outcomes = outcome(run, grid), outcome(coarse, coarse_grid)
        return game_of_degree(self.game, result, run, outcomes, coarse, separable, self.options)


def outcome(run: ReachRun, grid: Grid) -> Literal["capture", "escape", "undecided"]:
    """What the value says from the initial state: ``capture`` when φ there reaches zero within the
    time bound; ``escape`` when it does not and the captured set has :func:`converged`, so the
    minimum time to capture is +∞ there; otherwise ``undecided``."""
    if math.isfinite(run.probe_arrival):
        return "capture"
    return "escape" if converged(run) else "undecided"


def attached(captured: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The nodes of ``captured`` connected to ``target`` (through captured nodes, diagonal
    neighbours included). The set captured within τ is the union of the paths that end in the
    target, so it is connected to it; a piece apart from it is the ghost nodes' guess at the grid's
    edge (on [−3, 3]² with 81 nodes the chauffeur's far corners are captured so between τ = 7 and 14)."""
    labels, _ = ndimage.label(captured, structure=np.ones((3, 3), dtype=bool))
    keep = np.unique(labels[target & captured])
    joined: np.ndarray = np.isin(labels, keep[keep > 0])
    return joined


def converged(run: ReachRun) -> bool:
    """Whether the captured set has stopped growing: its part connected to the target
    (:func:`attached`) is the same at the horizon as at half of it, and clear of the grid's two
    outer rings of nodes (where the ghost nodes' extrapolation guesses what lies outside). Below
    Isaacs' barrier threshold the barrier closes it off and the rest escapes; above it the set
    leaks through the gap between the barrier's arcs and keeps growing
    (``metrics.capture_region.converged``)."""
    target = run.arrival == 0
    captured = attached(run.value <= 0, target)
    ring = np.ones_like(captured)
    ring[2:-2, 2:-2] = False
    same = np.array_equal(captured, attached(run.half <= 0, target))
    return bool(same) and not bool(np.any(captured & ring))


def game_of_degree(
    game: DifferentialGameSpec,
    result: Result,
    run: ReachRun,
    outcomes: tuple[str, str],
    coarse: ReachRun,
    separable: bool,
    options: HJIOptions,
) -> Result:
    """``result`` (the capture region) completed for a game of degree (``time.final: free``): the
    minimum time to capture from the initial state (the payoff, +∞ on escape), the outcome, and the
    check that the half-resolution grid decides the same with a capture time within
    ``capture_time_tolerance`` of it, relatively (``checks.capture_time_refinement``)."""
    decided, other = outcomes
    bound = result.metrics["capture_region"]["horizon"]
    if decided == "capture" and other == "capture":
        change: float | None = abs(run.probe_arrival - coarse.probe_arrival) / max(run.probe_arrival, 1e-12)
    else:
        change = 0.0 if decided == other == "escape" else None
    tolerance = options.capture_time_tolerance
    time = run.probe_arrival
    players = game.problem.players
    metrics = result.metrics | {
        "outcome": decided,
        "captured": decided == "capture",
        "capture_time": time if decided == "capture" else None,
        "solution_concept": "saddle" if separable else "upper_value",
        "value_function": "minimum time to capture (HJI, time-to-reach)",
        "payoffs": {name: time if decided == "capture" else math.inf for name in players},
        "checks_passed": result.metrics["checks_passed"]
        | {"capture_time_refinement": change is not None and change <= tolerance},
        "check_tolerances": result.metrics["check_tolerances"] | {"capture_time_refinement": tolerance},
    }
    checks = result.checks | {"capture_time_refinement": change}
    if decided == "undecided":
        return result.model_copy(
            update={
                "status": Status.ITERATION_LIMIT,
                "message": f"undecided: not captured within t_f <= {bound:g}, and the captured set still "
                "grows there or reaches the grid's edge (raise problem.time.bounds or widen "
                "solver.options.hji.lower/upper)",
                "metrics": metrics,
                "checks": checks,
            }
        )
    said = f"captured at t_f = {time:.4g}" if decided == "capture" else "escape (the capture time is +inf)"
    return result.model_copy(
        update={
            "message": f"{said}; {result.message}",
            "objective": time if decided == "capture" else math.inf,
            "t_final": time if decided == "capture" else None,
            "metrics": metrics,
            "checks": checks,
        }
    )


def boundary_shift(fine: np.ndarray, coarse: np.ndarray, grid: Grid) -> float:
    """How far the captured set's edge moves between ``grid`` and the grid of every other node, in
    units of the coarse spacing: the area where the two disagree (at their common nodes) over the
    fine set's perimeter (its cell edges between captured and free nodes)."""
    dx, dy = grid.spacing
    perimeter = np.sum(fine[1:] != fine[:-1]) * dy + np.sum(fine[:, 1:] != fine[:, :-1]) * dx
    disagreement = np.sum(fine[::2, ::2] != coarse) * 4 * dx * dy
    return float(disagreement / max(perimeter, 2 * dx) / (2 * max(dx, dy)))


class HJIBackend(Backend[DifferentialGameSpec, HJIOptions]):
    """The capture region of a two-state ``differential_game`` with a ``problem.capture`` set as the
    zero sublevel set of its HJI value function on a grid (:mod:`gamespec_levelset.hji`)."""

    name: ClassVar[str] = "hji"
    kinds: ClassVar[frozenset[str]] = frozenset({"differential_game"})
    options_model = HJIOptions

    def unsupported(self, spec: object) -> str | None:
        reason = super().unsupported(spec)  # type: ignore[arg-type]
        if reason or not isinstance(spec, DifferentialGameSpec):
            return reason
        p = spec.problem
        if len(p.states) != 2:
            return "the hji backend solves games of two states (reduced coordinates)"
        if p.capture is None:
            return "the hji backend needs problem.capture (the target set)"
        names = [*p.parameters, *p.uncertain, *p.states, "t"]
        names += [c for pl in p.players.values() for c in pl.controls]
        table = {n: symbol(n) for n in names}
        if any(symbol("t") in sp.sympify(parse(text, table)).free_symbols for text in p.dynamics.values()):
            return "the hji backend solves autonomous games (dynamics free of t)"
        if spec.receding_horizon is not None:
            return "the hji backend computes a value function, not a receding-horizon run"
        bounds = p.time.bounds
        if bounds is not None and _number(bounds[0], dict(p.parameters)) != p.time.initial:
            return "the hji backend computes the capture time from t_0: make the lower bound on t_f equal t_0"
        return None

    def _compile(self, spec: DifferentialGameSpec, options: HJIOptions) -> HJIModel:
        if options.engine == "hj_reachability":
            from gamespec_levelset.hji_jax import available

            missing = available()
            if missing:
                raise UnsupportedFeature(missing)
        return HJIModel(spec, options)
