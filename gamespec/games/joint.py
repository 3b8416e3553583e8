"""The joint scheme (``game.scheme: joint``): every player's first-order conditions stacked on the
players' own transcriptions and solved as one system, instead of iterating best responses.

Player ``p``'s best response is the collocation NLP its compiled CasADi model solves (the problem of
:func:`~gamespec.games.problems.player_problem`, after its transforms): ``min f_p(w_p, ω_p)`` over its
variables ``w_p`` (its copy of the states and its controls) subject to ``lbg ≤ g_p(w_p, ω_p) ≤ ubg``
and ``lbx ≤ w_p ≤ ubx``, with the other players' controls as its grid inputs ``ω_p``. Here ``ω_p``
is no longer data: it is the other players' controls inside their own ``w_j``, so the players' KKT
conditions (each the gradient of its own Lagrangian in its own variables, its own constraints and
complementarity) form one square system in all the variables and multipliers (the approach of
ALGAMES, Le Cleac'h, Schwager & Manchester, where each player keeps its own dynamics multipliers):

    ∇_{w_p} [f_p + λ_pᵀ g_p^eq + y_p^uᵀ g_p^u − y_p^lᵀ g_p^l] + z_p^u − z_p^l = 0   (its free variables),
    g_p^eq = lbg^eq,   g_p^l − lbg^l = s_p^l,   ubg^u − g_p^u = s_p^u,
    s ∘ y = μ,   (w_p − lbx) ∘ z^l = μ,   (ubx − w_p) ∘ z^u = μ,   s, y, z ≥ 0.

For a two-player zero-sum game these are the saddle's first-order conditions (the maximizer's NLP
minimizes ``−J``; each player keeps its own copy of the states and of the costates, equal at the
solution); for a Nash game, the joint stationarity system. Inequalities (control and state bounds,
path and terminal constraints) make it a mixed complementarity problem; it is solved here by the
**interior-point path** ``μ → 0`` (chosen over ALGAMES' augmented-Lagrangian penalty, whose
multiplier updates reach a constraint violation of 1e-3–1e-6 in practice, while the path reaches
the complementarity ``μ_end`` with Newton's quadratic convergence in each stage): for each ``μ`` the
square system is handed to IPOPT as a feasibility problem (objective 0, as many equations as free
variables — IPOPT's square-problem mode, so each iteration is a Newton step on the system with
IPOPT's filter line search and fraction-to-the-boundary rule keeping ``s, y, z > 0``), warm-started
from the stage before. A game without inequalities is one Newton solve. A root of the system is a
stationary point of every player's problem, not yet an equilibrium: the driver
(:meth:`~gamespec.games.equilibrium.GameModel.solve`) verifies it by one best response per player at
the returned point, and that Nash gap decides the status (issue 23's policy).

Limits: the players' problems must be compiled on casadi, share one control grid, and have no
free final time; each system is built once per game (on the structure of the first solve's
bounds) and re-solved with new parameter values and starting points (a receding horizon).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from enum import StrEnum
from typing import TYPE_CHECKING, Any

import numpy as np

from gamespec.errors import UnsupportedFeature
from gamespec.games.evaluation import states_at
from gamespec.result import Status
from gamespec.solving import build_steps

if TYPE_CHECKING:
    from gamespec.games.equilibrium import BestResponder, GameModel

BARRIER_START = 1e-2
"""The first stage's complementarity ``μ`` (games with inequalities). Measured on the homicidal
chauffeur (Radau degree 5): from 1e-1 the first stage stops at a nonzero local minimum of the
residual; from 1e-2, 1e-3 and 1e-4 every stage converges, to the same point."""
BARRIER_FACTOR = 1e-2
"""``μ`` shrinks by this factor per stage."""
BARRIER_END = 1e-13
"""The last stage's ``μ``: a bound's multiplier or slack is then off zero by ``μ`` over the other."""
NEWTON_TOL = 1e-12
"""IPOPT's ``tol`` on each stage's (scaled) residual."""
MAX_NEWTON = 300
"""IPOPT's iteration limit per stage."""
SLACK_FLOOR = 1e-2
"""The smallest slack of an inequality at the start (IPOPT keeps them positive from there)."""

STATUS = {
    "Solve_Succeeded": Status.OPTIMAL,
    "Solved_To_Acceptable_Level": Status.FEASIBLE,
    "Maximum_Iterations_Exceeded": Status.ITERATION_LIMIT,
    "Infeasible_Problem_Detected": Status.NOT_CONVERGED,
    "Restoration_Failed": Status.NUMERICAL_ERROR,
    "Error_In_Step_Computation": Status.NUMERICAL_ERROR,
    "Invalid_Number_Detected": Status.NUMERICAL_ERROR,
    "Diverging_Iterates": Status.NOT_CONVERGED,
}
"""IPOPT's status of a stage's square system → gamespec's. ``Infeasible_Problem_Detected`` means
IPOPT stopped at a local minimum of the residual that is not zero (no root found near the start)."""


class JointOutcome(StrEnum):
    """How a joint solve ended: every stage's Newton solve converged, one hit IPOPT's iteration
    limit, or one failed (no root found near its start, or numerical trouble)."""

    CONVERGED = "converged"
    ITERATION_LIMIT = "iteration_limit"
    FAILED = "failed"


@dataclass
class JointRun:
    """A joint solve, with the surface of :class:`~gamespec.best_response.BestResponseRun` the game
    drivers read: the strategies found (each player's controls at the evaluation points), the
    outcome, status and message, the Newton iterations (``history``: one entry per barrier stage)."""

    strategies: dict[str, np.ndarray]
    outcome: JointOutcome
    status: Status
    message: str
    history: list[dict] = field(default_factory=list)
    residual: float = float("nan")
    """The largest entry of the system at the returned point (μ = 0 in the complementarity)."""
    responses: int = 0
    """Best responses solved to start the path."""

    @property
    def converged(self) -> bool:
        return self.outcome is JointOutcome.CONVERGED

    @property
    def iterations(self) -> int:
        return sum(stage["iterations"] for stage in self.history)

    @property
    def best(self) -> int | None:
        """The engine's index of the returned iterate: 0, the run's one point (None without one)."""
        return 0 if self.strategies else None

    def as_metrics(self) -> dict:
        return {
            "converged": self.converged,
            "outcome": self.outcome.value,
            "iterations": self.iterations,
            "scheme": "joint",
            "residual": self.residual,
            "starting_responses": self.responses,
            "stages": self.history,
        }


@dataclass(frozen=True)
class _Player:
    """One player's part of the system: its model, the layout of its variables, and which of its
    bounds and constraint rows are fixed, one-sided or two-sided (the structure the system has)."""

    responder: BestResponder
    model: Any
    n_w: int
    controls: np.ndarray
    """Indices in ``w_p`` of its controls (scaled), control-major per evaluation point: (n_u, k)."""
    fixed: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    equal: np.ndarray
    g_lower: np.ndarray
    g_upper: np.ndarray

    @property
    def name(self) -> str:
        return self.responder.name


def _values(r: BestResponder) -> dict[str, float]:
    """The runtime parameter values of the spec ``r``'s model solves (after its transforms)."""
    spec = r.spec
    if r.solver.steps:
        spec = build_steps(spec, r.solver.backend)[-1].target
    return r.solver.compiled.tr.ocp.parameter_values(spec.runtime_parameters() or None)


def _casadi_model(r: BestResponder) -> Any:
    model = r.solver.compiled
    if r.solver.backend.name != "casadi" or not hasattr(model, "pack"):
        raise UnsupportedFeature("game.scheme: joint needs every player's problem compiled on casadi")
    if model.tr.free_time:
        raise UnsupportedFeature("game.scheme: joint does not handle a free final time")
    return model


@dataclass
class _Numbers:
    """One player's numbers for one solve: its parameter values, the NLP parameters without the
    grid inputs (``p``: the parameters and the horizon) and its variable and constraint bounds."""

    params: dict[str, float]
    p: np.ndarray
    lbx: np.ndarray
    ubx: np.ndarray
    lbg: np.ndarray
    ubg: np.ndarray


def _numbers(model: Any, values: dict[str, float]) -> _Numbers:
    tr = model.tr
    b = tr.bounds(values)
    lbx = model.pack(b.x_lower, b.u_lower, b.d_lower, b.t_lower)
    ubx = model.pack(b.x_upper, b.u_upper, b.d_upper, b.t_upper)
    lbg, ubg = model.constraint_bounds(values)
    p = np.array([*(values[n] for n in tr.ocp.parameters), b.t_lower])
    return _Numbers(values, p, lbx, ubx, np.asarray(lbg, float), np.asarray(ubg, float))


class JointSystem:
    """The stacked KKT system of one game's players (module doc), built once with CasADi and
    re-solved for new parameter values and starting points."""

    def __init__(self, order: list[BestResponder]) -> None:
        import casadi as ca
        from gamespec_casadi.nlp import collocation_nlp

        from gamespec.symbolic.library import casadi_library

        self.ca = ca
        models = [_casadi_model(r) for r in order]
        numbers = [_numbers(m, _values(r)) for r, m in zip(order, models, strict=True)]
        self.players: list[_Player] = []
        nlps = []
        for r, model, num in zip(order, models, numbers, strict=True):
            tr = model.tr
            nlp = collocation_nlp(tr, casadi_library(ca), ca.SX, model.sx, model.su).closed()
            nlps.append(nlp)
            nx, n, nu, k = model.shape
            controls = nx * n + np.arange(nu)[:, None] + nu * np.arange(k)[None, :]
            fixed = num.lbx == num.ubx
            equal = num.lbg == num.ubg
            self.players.append(
                _Player(
                    r,
                    model,
                    nlp["x"].numel(),
                    controls,
                    fixed,
                    np.isfinite(num.lbx) & ~fixed,
                    np.isfinite(num.ubx) & ~fixed,
                    equal,
                    np.isfinite(num.lbg) & ~equal,
                    np.isfinite(num.ubg) & ~equal,
                )
            )
        grids = {m.shape[3] for m in models}
        if len(grids) != 1:
            raise UnsupportedFeature("game.scheme: joint needs the players' problems on one control grid")
        self._build(nlps)

    def _owner(self, control: str) -> tuple[_Player, int]:
        for player in self.players:
            names = player.model.tr.ocp.controls
            if control in names:
                return player, names.index(control)
        raise UnsupportedFeature(f"game.scheme: joint: input {control!r} is no player's control")

    def _build(self, nlps: list[dict]) -> None:
        ca = self.ca
        variables, residuals, parameters, estimates = [], [], [], []
        mu = ca.SX.sym("mu")
        self.blocks: list[dict[str, slice]] = []
        offset = 0
        for player, nlp in zip(self.players, nlps, strict=True):
            tr = player.model.tr
            inputs = []
            for name in tr.ocp.inputs:
                owner, row = self._owner(name)
                w_owner = nlps[self.players.index(owner)]["x"]
                inputs.append(
                    ca.vertcat(*(owner.model.su[row] * w_owner[int(i)] for i in owner.controls[row])).T
                )
            numeric = ca.SX.sym(f"p_{player.name}", len(tr.ocp.parameters) + 1)
            win = ca.vec(ca.vertcat(*inputs)) if inputs else ca.SX(0, 1)
            p_expr = ca.vertcat(numeric[:-1], win, numeric[-1])
            f, g = (ca.substitute(nlp[key], nlp["p"], p_expr) for key in ("f", "g"))
            n_w, n_g = player.n_w, g.numel()
            bounds = ca.SX.sym(f"b_{player.name}", 2 * n_w + 2 * n_g)
            lbx, ubx, lbg, ubg = ca.vertsplit(bounds, [0, n_w, 2 * n_w, 2 * n_w + n_g, 2 * n_w + 2 * n_g])
            sizes = {
                "lam": int(player.equal.sum()),
                "y_l": int(player.g_lower.sum()),
                "y_u": int(player.g_upper.sum()),
                "z_l": int(player.lower.sum()),
                "z_u": int(player.upper.sum()),
                "s_l": int(player.g_lower.sum()),
                "s_u": int(player.g_upper.sum()),
            }
            sym = {key: ca.SX.sym(f"{key}_{player.name}", size) for key, size in sizes.items()}
            eq, gl, gu = (np.flatnonzero(m).tolist() for m in (player.equal, player.g_lower, player.g_upper))
            xl, xu = np.flatnonzero(player.lower).tolist(), np.flatnonzero(player.upper).tolist()
            w = nlp["x"]
            lagrangian = f + ca.dot(sym["lam"], g[eq]) + ca.dot(sym["y_u"], g[gu]) - ca.dot(sym["y_l"], g[gl])
            stationarity = ca.gradient(lagrangian, w)
            bound_terms = ca.SX.zeros(n_w)
            bound_terms[xu] = sym["z_u"]
            bound_terms[xl] = bound_terms[xl] - sym["z_l"]
            free = np.flatnonzero(~player.fixed).tolist()
            gradient = (stationarity + bound_terms)[free]
            estimates.append((gradient, sym["lam"]))
            residuals += [
                gradient,
                g[eq] - lbg[eq],
                g[gl] - lbg[gl] - sym["s_l"],
                ubg[gu] - g[gu] - sym["s_u"],
                sym["s_l"] * sym["y_l"] - mu,
                sym["s_u"] * sym["y_u"] - mu,
                (w[xl] - lbx[xl]) * sym["z_l"] - mu,
                (ubx[xu] - w[xu]) * sym["z_u"] - mu,
            ]
            block = {"w": slice(offset, offset + n_w)}
            offset += n_w
            variables.append(w)
            for key in ("lam", "y_l", "y_u", "z_l", "z_u", "s_l", "s_u"):
                block[key] = slice(offset, offset + sizes[key])
                offset += sizes[key]
                variables.append(sym[key])
            self.blocks.append(block)
            parameters += [numeric, bounds]
        self.n_z = offset
        z, p = ca.vertcat(*variables), ca.vertcat(*parameters, mu)
        F = ca.vertcat(*residuals)
        self.n_inequalities = sum(
            int(pl.lower.sum() + pl.upper.sum() + pl.g_lower.sum() + pl.g_upper.sum()) for pl in self.players
        )
        self.residual = ca.Function("joint_residual", [z, p], [F])
        self.constraints = [ca.Function("g", [nlp["x"], nlp["p"]], [nlp["g"]]) for nlp in nlps]
        self.multipliers = [
            ca.Function(
                "stationarity",
                [z, p],
                [ca.jacobian(gradient, lam), ca.substitute(gradient, lam, ca.DM.zeros(lam.numel()))],
            )
            for gradient, lam in estimates
        ]
        ipopt = {
            "print_level": 0,
            "sb": "yes",
            "tol": NEWTON_TOL,
            "max_iter": MAX_NEWTON,
            "hessian_approximation": "limited-memory",
            "bound_relax_factor": 0.0,
            "fixed_variable_treatment": "make_parameter",
        }
        options = {
            "ipopt": ipopt,
            "print_time": False,
            "calc_lam_p": False,
            "calc_lam_x": False,
            "show_eval_warnings": False,
        }
        self.solver = ca.nlpsol("joint", "ipopt", {"x": z, "p": p, "f": 0, "g": F}, options)

    def _start(
        self, strategies: dict[str, np.ndarray], responses: dict[str, Any], numbers: list[_Numbers], mu: float
    ) -> np.ndarray:
        """The system's starting point: each player's variables from its best response to the
        starting ``strategies`` (``responses``; where it failed or went through transforms, its
        starting controls and their states), the slacks of its inequalities there and ``y = μ/s``,
        and its equality multipliers by least squares on its stationarity."""
        z = np.zeros(self.n_z)
        inputs = {}
        for player in self.players:
            for row, name in enumerate(player.model.tr.ocp.controls):
                inputs[name] = np.asarray(strategies[player.name], dtype=float)[row]
        for player, block, num, g in zip(self.players, self.blocks, numbers, self.constraints, strict=True):
            tr, model = player.model.tr, player.model
            Win = np.array([inputs[n] for n in tr.ocp.inputs]).reshape(tr.n_w, -1)
            guess = tr.guess(num.params)
            response = responses.get(player.name)
            if response is not None and response.ok and all(n in response.states for n in tr.ocp.states):
                X = np.array([response.states[n] for n in tr.ocp.states])
                U = np.array([response.controls[n] for n in tr.ocp.controls])
            else:
                U = np.asarray(strategies[player.name], dtype=float)
                X = states_at(tr, num.params, U, Win, guess.X)
                X = guess.X if X is None else X
            w = np.clip(model.pack(X, U, guess.d, guess.T), num.lbx, num.ubx)
            z[block["w"]] = w
            p_full = np.concatenate([num.p[:-1], Win.ravel(order="F"), num.p[-1:]])
            gv = np.asarray(g(w, p_full)).ravel()
            s_l = np.maximum(gv[player.g_lower] - num.lbg[player.g_lower], SLACK_FLOOR)
            s_u = np.maximum(num.ubg[player.g_upper] - gv[player.g_upper], SLACK_FLOOR)
            z[block["s_l"]], z[block["s_u"]] = s_l, s_u
            z[block["y_l"]], z[block["y_u"]] = mu / s_l, mu / s_u
            d_l = np.maximum(w[player.lower] - num.lbx[player.lower], SLACK_FLOOR)
            d_u = np.maximum(num.ubx[player.upper] - w[player.upper], SLACK_FLOOR)
            z[block["z_l"]], z[block["z_u"]] = mu / d_l, mu / d_u
        p = self._parameters(numbers, mu)
        for block, estimate in zip(self.blocks, self.multipliers, strict=True):
            A, b = (np.asarray(v) for v in estimate(z, p))
            if A.size:
                z[block["lam"]] = np.linalg.lstsq(A, -b.ravel(), rcond=None)[0]
        return z

    def _bounds(self, numbers: list[_Numbers]) -> tuple[np.ndarray, np.ndarray]:
        lo, hi = np.full(self.n_z, -np.inf), np.full(self.n_z, np.inf)
        for block, num in zip(self.blocks, numbers, strict=True):
            lo[block["w"]], hi[block["w"]] = num.lbx, num.ubx
            for key in ("y_l", "y_u", "z_l", "z_u", "s_l", "s_u"):
                lo[block[key]] = 0.0
        return lo, hi

    def _parameters(self, numbers: list[_Numbers], mu: float) -> np.ndarray:
        parts = []
        for num in numbers:
            bounds = np.concatenate([num.lbx, num.ubx, num.lbg, num.ubg])
            parts += [num.p, np.where(np.isfinite(bounds), bounds, 0.0)]
        return np.concatenate([*parts, [mu]])

    def _structure_holds(self, numbers: list[_Numbers]) -> bool:
        return all(
            np.array_equal(p.fixed, n.lbx == n.ubx)
            and np.array_equal(p.lower, np.isfinite(n.lbx) & ~p.fixed)
            and np.array_equal(p.upper, np.isfinite(n.ubx) & ~p.fixed)
            and np.array_equal(p.equal, n.lbg == n.ubg)
            and np.array_equal(p.g_lower, np.isfinite(n.lbg) & ~p.equal)
            and np.array_equal(p.g_upper, np.isfinite(n.ubg) & ~p.equal)
            for p, n in zip(self.players, numbers, strict=True)
        )

    def solve(self, strategies: dict[str, np.ndarray], responses: dict[str, Any]) -> JointRun:
        """Solve the system from ``strategies`` (each player's controls at the evaluation points)
        along the barrier path, started from each player's best response to them (``responses``);
        where a stage fails, the point of the last stage that converged (the start when none did)
        is returned with the outcome that says so."""
        numbers = [_numbers(p.model, _values(p.responder)) for p in self.players]
        if not self._structure_holds(numbers):
            raise UnsupportedFeature(
                "game.scheme: joint: which variables are fixed or bounded changed with the parameters; "
                "compile the game again"
            )
        stages = [0.0] if self.n_inequalities == 0 else _barrier_path()
        z = self._start(strategies, responses, numbers, stages[0])
        lo, hi = self._bounds(numbers)
        history: list[dict] = []
        status, native = Status.OPTIMAL, "Solve_Succeeded"
        for mu in stages:
            tic = time.perf_counter()
            sol = self.solver(
                x0=np.clip(z, lo, hi), lbx=lo, ubx=hi, lbg=0.0, ubg=0.0, p=self._parameters(numbers, mu)
            )
            stats = self.solver.stats()
            native = stats.get("return_status", "unknown")
            status = STATUS.get(native, Status.ERROR)
            candidate = np.asarray(sol["x"]).ravel()
            history.append(
                {
                    "mu": mu,
                    "iterations": int(stats.get("iter_count", 0)),
                    "status": native,
                    "seconds": time.perf_counter() - tic,
                }
            )
            if not np.all(np.isfinite(candidate)) or status not in (Status.OPTIMAL, Status.FEASIBLE):
                break
            z = candidate
        residual = float(
            np.abs(np.asarray(self.residual(z, self._parameters(numbers, 0.0)))).max(initial=0.0)
        )
        ok = status is Status.OPTIMAL and history[-1]["mu"] == stages[-1]
        outcome = (
            JointOutcome.CONVERGED
            if ok
            else (JointOutcome.ITERATION_LIMIT if status is Status.ITERATION_LIMIT else JointOutcome.FAILED)
        )
        message = "" if ok else f"joint solve: IPOPT {native} at μ = {history[-1]['mu']:.1g}"
        return JointRun(
            self.strategies(z),
            outcome,
            Status.OPTIMAL if ok else (status if not status.ok else Status.NOT_CONVERGED),
            message,
            history,
            residual,
        )

    def strategies(self, z: np.ndarray) -> dict[str, np.ndarray]:
        """Each player's controls (unscaled, n_u × k) in the system's variables ``z``."""
        out = {}
        for player, block in zip(self.players, self.blocks, strict=True):
            w = z[block["w"]]
            out[player.name] = w[player.controls] * player.model.su[:, None]
        return out


def _barrier_path() -> list[float]:
    stages, mu = [], BARRIER_START
    while mu > BARRIER_END * (1 + 1e-9):
        stages.append(mu)
        mu *= BARRIER_FACTOR
    return [*stages, BARRIER_END]


def joint_run(
    model: GameModel, view: str, order: list[BestResponder], start: dict[str, np.ndarray]
) -> JointRun:
    """The joint solve of game ``view`` (its players' values already set) from ``start``: each
    player's best response to ``start`` begins the Newton path (each player's own problem then
    curves the right way where the path starts: from the plain start the path can end at a
    stationary point where a maximizer minimizes); its system built on first use and kept on
    ``model``."""
    system = model.joint.get(view)
    if system is None:
        system = model.joint[view] = JointSystem(order)
    responses = {r.name: r.respond({o: start[o] for o in r.opponents})[1] for r in order}
    run = system.solve(start, responses)
    run.responses = len(responses)
    rough = [f"{name}: {r.message}" for name, r in responses.items() if r.status is Status.FEASIBLE]
    if run.converged and rough:
        run.status = Status.FEASIBLE
        run.message = "; ".join(["a starting best response is only feasible", *rough])
    return run
