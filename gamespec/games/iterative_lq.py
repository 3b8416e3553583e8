"""Feedback Nash equilibria of nonlinear differential games by iterative LQ games (iLQGames:
Fridovich-Keil, Ratner, Peters, Dragan & Tomlin, 2020), for ``game.information: feedback`` where the
game is not linear-quadratic.

The game is taken in discrete time on ``K`` equal steps of ``h = T / K``: ``x_{k+1} = F(x_k, u_k,
t_k)``, one classical Runge–Kutta step of the file's dynamics, and each player ``i`` minimizes
``J_i = Φ_i(x_K) + Σ_k h l_i(x_k, u_k, t_k)`` (a maximizer the negated payoff; eq. 7.1 with the
Lagrange term by the rectangle rule). Each iteration, about the current trajectory ``(x̂, û)``:

1. linearize the dynamics, ``δx_{k+1} ≈ A_k δx_k + B_k δu_k``, and quadratize every player's cost;
2. solve that LQ game for its feedback Nash equilibrium backward in time (Başar & Olsder,
   Corollary 6.1, with the linear terms: per step one linear system ``S [P α] = [Y_x Y_1]`` for the
   stacked gains and feedforward terms, then each player's value ``½ δxᵀ Z_i δx + ζ_iᵀ δx``), the
   strategies ``u_k = û_k − P_k (x_k − x̂_k) − η α_k``;
3. roll the strategies out on the nonlinear dynamics with a step ``η`` halved from 1 until the
   trajectory moves by at most :data:`TRUST` (iLQGames' line search on the strategy update).

It stops ``converged`` when ``‖η α‖∞`` (the change of the controls the strategies prescribe on the
trajectory) falls below ``game.tolerance``. iLQGames' quadratization ignores the dynamics'
curvature (Gauss–Newton); where a player's control enters its cost only through the dynamics (the
chauffeur's pedestrian: a heading, no control cost) its LQ game then has no curvature in that
control and the iteration has no equilibrium to move to. ``second_order`` (the default) adds each
player's ``Σ_a ζ_{i,a} ∇²F_a`` — its value gradient times the dynamics' Hessian, as differential
dynamic programming does — to its quadratic terms; ``gauss_newton`` is iLQGames' own step.

Bounded controls are kept inside their bounds by a logarithmic barrier ``−μ Σ log`` of the
distances to the bounds in the owner's stage cost (``μ`` = :data:`BARRIER`, the payoffs reported
without it), the line search refusing a step that leaves them.

The point is checked independently: each player's **best reply** to the others' feedback laws (they
keep ``u_j = û_j − P_j (x − x̂)``) is solved by IPOPT (single shooting on the same discrete game,
hard bounds), and its improvement is the Nash gap, a check against ``game.tolerance`` relative to
the payoffs' scale (issue 23's policy).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from gamespec.errors import UnsupportedFeature
from gamespec.games.expressions import GameExpressions
from gamespec.games.nash_gap import nash_gap
from gamespec.games.problems import initial_state
from gamespec.result import Result, Status
from gamespec.specs.differential_game import DifferentialGameSpec
from gamespec.symbolic.library import casadi_library
from gamespec.symbolic.translate import translate

TRUST = 1.0
"""The most any state may move in one iteration, relative to ``max(1, ‖x̂‖∞)``."""
BARRIER = 1e-8
"""The weight ``μ`` of the logarithmic barrier of a bounded control."""
MAX_HALVINGS = 30
"""Line-search halvings of ``η`` before an iteration gives up."""
STEPS_PER_POINT = 1
"""Discrete steps per collocation point of the file's ``method`` (intervals × degree points)."""


@dataclass
class FeedbackStrategies:
    """The iteration's result: the trajectory ``x`` (K+1 × n), controls ``u`` (K × m), the gains
    ``P`` (K × m × n) of ``u = û − P (x − x̂)``, each player's cost ``costs`` (as minimized, without
    the barrier), the iterations and the last update."""

    times: np.ndarray
    x: np.ndarray
    u: np.ndarray
    P: np.ndarray
    costs: np.ndarray
    iterations: int
    update: float
    converged: bool
    reason: str = ""


class DiscreteGame:
    """The discrete game of the module doc. Its CasADi functions are built once per compiled game
    from the game's parsed ``expressions`` (:mod:`gamespec.games.expressions`: no text is parsed
    here or at solve time), the parameters their last argument; :meth:`bind` sets the parameter
    values of a solve. UnsupportedFeature names what of the game the method does not take."""

    def __init__(self, game: DifferentialGameSpec, expressions: GameExpressions, second_order: bool) -> None:
        import casadi as ca

        why = unsupported(game)
        if why:
            raise UnsupportedFeature(
                f"game.information: feedback: {game.name!r} is not linear-quadratic, and iterative LQ "
                f"games take no {why}: solve the open-loop game instead (game.information: open_loop)"
            )
        self.ca = ca
        self.game = game
        self.expressions = expressions
        p = game.problem
        self.second_order = second_order
        library = casadi_library(ca)
        names = expressions.symbols.running
        self.states = list(p.states)
        self.players = list(p.players)
        self.controls = [c for pl in p.players.values() for c in pl.controls]
        self.slices, start = [], 0
        for pl in p.players.values():
            self.slices.append(slice(start, start + len(pl.controls)))
            start += len(pl.controls)
        n, m = len(self.states), len(self.controls)
        x, u, t, h = ca.SX.sym("x", n), ca.SX.sym("u", m), ca.SX.sym("t"), ca.SX.sym("h")
        par = ca.SX.sym("p", len(expressions.parameters))
        params = {names[name]: par[i] for i, name in enumerate(expressions.parameters)}
        controls = dict(zip((names[c] for c in self.controls), ca.vertsplit(u), strict=True))

        def table(xv: Any, tv: Any) -> dict[sp.Symbol, Any]:
            states = dict(zip((names[s] for s in self.states), ca.vertsplit(xv), strict=True))
            return params | controls | states | {names["t"]: tv}

        def f(xv: Any, tv: Any) -> Any:
            values = table(xv, tv)
            return ca.vertcat(*(translate(expressions.dynamics[s], values, library) for s in self.states))

        k1 = f(x, t)
        k2 = f(x + h / 2 * k1, t + h / 2)
        k3 = f(x + h / 2 * k2, t + h / 2)
        k4 = f(x + h * k3, t + h)
        step = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        args = [x, u, t, h, par]
        self._step = ca.Function("step", args, [step])
        z = ca.vertcat(x, u)
        lam = ca.SX.sym("lam", n)
        self._linear = ca.Function("linear", args, [ca.jacobian(step, x), ca.jacobian(step, u)])
        self._curvature = ca.Function("curvature", [*args, lam], [ca.hessian(ca.dot(lam, step), z)[0]])
        self.t0 = float(p.time.initial)
        final = translate(expressions.final_time, params, library)
        finals = (expressions.symbols.ends[f"{s}_f"] for s in self.states)
        ends = params | dict(zip(finals, ca.vertsplit(x), strict=True))
        ends[expressions.symbols.ends["t_f"]] = final
        bounds = [expressions.control_bounds[c] for c in self.controls]
        lower = [None if lo is None else translate(lo, params, library) for lo, _ in bounds]
        upper = [None if hi is None else translate(hi, params, library) for _, hi in bounds]
        self._limits = ca.Function(
            "limits",
            [par],
            [
                ca.vertcat(*(-ca.inf if lo is None else lo for lo in lower)),
                ca.vertcat(*(ca.inf if hi is None else hi for hi in upper)),
                final,
            ],
        )
        stage, terminal, barrier = [], [], []
        running = table(x, t)
        for name, pl in p.players.items():
            payoff = expressions.payoffs.get(name, expressions.payoff)
            sign = 1.0 if pl.objective == "minimize" else -1.0
            stage.append(h * sign * translate(payoff.lagrange, running, library))
            terminal.append(ca.SX(sign * translate(payoff.mayer, ends, library)))
            own = self.slices[self.players.index(name)]
            sides = [u[j] - lower[j] for j in range(own.start, own.stop) if lower[j] is not None]
            sides += [upper[j] - u[j] for j in range(own.start, own.stop) if upper[j] is not None]
            barrier.append(-h * BARRIER * ca.sum1(ca.log(ca.vertcat(*sides))) if sides else ca.SX(0))
        self._stage_cost = ca.Function("stage", args, [ca.vertcat(*stage)])
        self._terminal_cost = ca.Function("terminal", [x, par], [ca.vertcat(*terminal)])
        quadratic = []
        for i in range(len(self.players)):
            hess, grad = ca.hessian(stage[i] + barrier[i], z)
            quadratic += [hess, grad]
        self._stage_quadratic = ca.Function("stage_q", args, quadratic)
        terminal_q = []
        for i in range(len(self.players)):
            hess, grad = ca.hessian(terminal[i], x)
            terminal_q += [hess, grad]
        self._terminal_quadratic = ca.Function("terminal_q", [x, par], terminal_q)
        self.n, self.m = n, m

    def bind(self, parameters: Mapping[str, float]) -> DiscreteGame:
        """Set the parameter values of a solve: the bounds, the horizon and the initial state."""
        self.p = np.array([float(parameters[n]) for n in self.expressions.parameters])
        lower, upper, final = self._limits(self.p)
        self.lower, self.upper = np.asarray(lower).ravel(), np.asarray(upper).ravel()
        self.T = float(final) - self.t0
        self.x0 = np.array([initial_state(self.game, parameters)[s] for s in self.states])
        return self

    def step(self, x: Any, u: Any, t: Any, h: Any) -> Any:
        return self._step(x, u, t, h, self.p)

    def linear(self, x: Any, u: Any, t: Any, h: Any) -> Any:
        return self._linear(x, u, t, h, self.p)

    def curvature(self, x: Any, u: Any, t: Any, h: Any, lam: Any) -> Any:
        return self._curvature(x, u, t, h, self.p, lam)

    def stage_cost(self, x: Any, u: Any, t: Any, h: Any) -> Any:
        return self._stage_cost(x, u, t, h, self.p)

    def stage_quadratic(self, x: Any, u: Any, t: Any, h: Any) -> Any:
        return self._stage_quadratic(x, u, t, h, self.p)

    def terminal_cost(self, x: Any) -> Any:
        return self._terminal_cost(x, self.p)

    def terminal_quadratic(self, x: Any) -> Any:
        return self._terminal_quadratic(x, self.p)

    def grid(self, steps: int) -> tuple[np.ndarray, float]:
        h = self.T / steps
        return self.t0 + h * np.arange(steps + 1), h

    def inside(self, u: np.ndarray) -> bool:
        return bool(np.all(u > self.lower) and np.all(u < self.upper))

    def rollout(self, u_hat, x_hat, P, alpha, eta, times, h) -> tuple[np.ndarray, np.ndarray] | None:
        """The strategies ``u = û − P (x − x̂) − η α`` on the nonlinear dynamics (None when they
        leave a control's bounds or the states stop being finite)."""
        K = len(u_hat)
        x = np.empty((K + 1, self.n))
        u = np.empty((K, self.m))
        x[0] = self.x0
        for k in range(K):
            u[k] = u_hat[k] - P[k] @ (x[k] - x_hat[k]) - eta * alpha[k]
            if not self.inside(u[k]):
                return None
            x[k + 1] = np.asarray(self.step(x[k], u[k], times[k], h)).ravel()
        return (x, u) if np.all(np.isfinite(x)) else None

    def costs(self, x: np.ndarray, u: np.ndarray, times: np.ndarray, h: float) -> np.ndarray:
        """Each player's cost (as minimized, without the barrier)."""
        total = np.asarray(self.terminal_cost(x[-1])).ravel()
        for k in range(len(u)):
            total = total + np.asarray(self.stage_cost(x[k], u[k], times[k], h)).ravel()
        return total

    def backward(
        self, x: np.ndarray, u: np.ndarray, times: np.ndarray, h: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """The LQ game's feedback Nash strategies about ``(x, u)`` (module doc, step 2)."""
        K, n, m, N = len(u), self.n, self.m, len(self.players)
        terminal = self.terminal_quadratic(x[-1])
        Z = [np.asarray(terminal[2 * i]) for i in range(N)]
        zeta = [np.asarray(terminal[2 * i + 1]).ravel() for i in range(N)]
        P = np.empty((K, m, n))
        alpha = np.empty((K, m))
        for k in reversed(range(K)):
            A, B = (np.asarray(v) for v in self.linear(x[k], u[k], times[k], h))
            quad = self.stage_quadratic(x[k], u[k], times[k], h)
            H = [np.asarray(quad[2 * i]) for i in range(N)]
            g = [np.asarray(quad[2 * i + 1]).ravel() for i in range(N)]
            if self.second_order:
                H = [
                    Hi + np.asarray(self.curvature(x[k], u[k], times[k], h, zeta[i]))
                    for i, Hi in enumerate(H)
                ]
            S = np.empty((m, m))
            Y = np.empty((m, n + 1))
            for i, own in enumerate(self.slices):
                Q, N_, R = H[i][:n, :n], H[i][:n, n:], H[i][n:, n:]
                Bi = B[:, own]
                S[own] = R[own] + Bi.T @ Z[i] @ B
                Y[own, :n] = Bi.T @ Z[i] @ A + N_[:, own].T
                Y[own, n] = Bi.T @ zeta[i] + g[i][n:][own]
            solution = np.linalg.solve(S, Y)
            P[k], alpha[k] = solution[:, :n], solution[:, n]
            F = A - B @ P[k]
            beta = -B @ alpha[k]
            for i in range(N):
                Q, N_, R = H[i][:n, :n], H[i][:n, n:], H[i][n:, n:]
                q, r = g[i][:n], g[i][n:]
                cross = N_ @ P[k]
                zeta[i] = q + P[k].T @ (R @ alpha[k] - r) - N_ @ alpha[k] + F.T @ (zeta[i] + Z[i] @ beta)
                Z[i] = F.T @ Z[i] @ F + Q + P[k].T @ R @ P[k] - cross - cross.T
                Z[i] = 0.5 * (Z[i] + Z[i].T)
        return P, alpha


def iterative_lq(
    game: DiscreteGame, steps: int, start: np.ndarray, tolerance: float, max_iterations: int
) -> FeedbackStrategies:
    """iLQGames on ``game`` with ``steps`` steps from the controls ``start`` (K × m) held open loop."""
    times, h = game.grid(steps)
    K = steps
    zeros_P = np.zeros((K, game.m, game.n))
    first = game.rollout(start, np.zeros((K + 1, game.n)), zeros_P, np.zeros((K, game.m)), 0.0, times, h)
    if first is None:
        raise ValueError("the starting controls leave their bounds or the states diverge")
    x, u = first
    P = zeros_P
    update, reason = np.inf, ""
    for iteration in range(1, max_iterations + 1):
        try:
            P_new, alpha = game.backward(x, u, times, h)
        except np.linalg.LinAlgError:
            reason = "a step's LQ game has a singular gain system"
            return FeedbackStrategies(
                times, x, u, P, game.costs(x, u, times, h), iteration, update, False, reason
            )
        scale = TRUST * max(1.0, float(np.abs(x).max()))
        eta, moved = 1.0, None
        for _ in range(MAX_HALVINGS):
            moved = game.rollout(u, x, P_new, alpha, eta, times, h)
            if moved is not None and float(np.abs(moved[0] - x).max()) <= scale:
                break
            eta, moved = eta / 2, None
        if moved is None:
            reason = "the line search found no step that keeps the trajectory within its trust region"
            return FeedbackStrategies(
                times, x, u, P_new, game.costs(x, u, times, h), iteration, update, False, reason
            )
        update = float(np.abs(eta * alpha).max())
        x, u, P = moved[0], moved[1], P_new
        if update <= tolerance:
            P, _ = game.backward(x, u, times, h)
            return FeedbackStrategies(times, x, u, P, game.costs(x, u, times, h), iteration, update, True)
    reason = f"the strategy update {update:.3g} is above the tolerance after {max_iterations} iterations"
    return FeedbackStrategies(
        times, x, u, P, game.costs(x, u, times, h), max_iterations, update, False, reason
    )


def best_reply(game: DiscreteGame, solution: FeedbackStrategies, player: int) -> float:
    """``player``'s optimal cost (as minimized, hard bounds) when the others keep their feedback
    laws ``u_j = û_j − P_j (x − x̂)``: IPOPT on the single-shooting NLP of the discrete game."""
    ca = game.ca
    own = game.slices[player]
    K = len(solution.u)
    times, h = solution.times, solution.times[1] - solution.times[0]
    v = ca.SX.sym("v", K * (own.stop - own.start))
    blocks = ca.reshape(v, own.stop - own.start, K)
    x = ca.DM(game.x0)
    cost = 0
    for k in range(K):
        others = ca.DM(solution.u[k]) - ca.DM(solution.P[k]) @ (x - ca.DM(solution.x[k]))
        u = ca.vertcat(others[: own.start], blocks[:, k], others[own.stop :])
        cost += game.stage_cost(x, u, times[k], h)[player]
        x = game.step(x, u, times[k], h)
    cost += game.terminal_cost(x)[player]
    solver = ca.nlpsol(
        "reply",
        "ipopt",
        {"x": v, "f": cost},
        {
            "ipopt": {"print_level": 0, "sb": "yes", "tol": 1e-12},
            "print_time": False,
            "show_eval_warnings": False,
        },
    )
    lower = np.tile(game.lower[own], K)
    upper = np.tile(game.upper[own], K)
    result = solver(x0=solution.u[:, own].ravel(), lbx=lower, ubx=upper)
    return float(result["f"])


def unsupported(game: DifferentialGameSpec) -> str:
    """What of the game iterative LQ games do not take ('' when nothing)."""
    p = game.problem
    reasons = [
        (bool(p.uncertain), "uncertain parameters"),
        (
            any(pl.transforms or pl.path_constraints for pl in p.players.values()),
            "a player's transforms or path constraints",
        ),
        (bool(p.terminal_constraints), "terminal constraints"),
        (
            any(s.lower is not None or s.upper is not None or s.final is not None for s in p.states.values()),
            "state bounds or fixed final states",
        ),
        (any(s.initial is None for s in p.states.values()), "a free initial state"),
    ]
    return next((why for hit, why in reasons if hit), "")


def feedback_nash_nonlinear(discrete: DiscreteGame, parameters: Mapping[str, float]) -> Result:
    """The game's feedback equilibrium by iterative LQ games at ``parameters`` as a Result (module
    doc): concept ``feedback_saddle`` (zero-sum) or ``feedback_nash``, ``metrics.method =
    iterative_lq``."""
    game = discrete.bind(parameters).game
    settings = game.game
    steps = STEPS_PER_POINT * game.method.intervals * max(1, game.method.degree)
    start = np.array(
        [[pl.start.get(c, 0.0) for pl in game.problem.players.values() for c in pl.controls]] * steps,
        dtype=float,
    )
    width = discrete.upper - discrete.lower
    margin = np.where(np.isfinite(width), 1e-6 * np.where(np.isfinite(width), width, 0.0), 0.0)
    start = np.clip(start, discrete.lower + margin, discrete.upper - margin)
    solution = iterative_lq(discrete, steps, start, settings.tolerance, settings.max_iterations)
    zero_sum = all(pl.payoff is None for pl in game.problem.players.values())
    concept = "feedback_saddle" if zero_sum else "feedback_nash"
    signs = [1.0 if pl.objective == "minimize" else -1.0 for pl in game.problem.players.values()]
    payoffs = {name: s * float(c) for name, s, c in zip(discrete.players, signs, solution.costs, strict=True)}
    base = {"information": "feedback", "sought_concept": concept, "method": "iterative_lq"}
    run = {
        "iterations": solution.iterations,
        "update": solution.update,
        "converged": solution.converged,
        "steps": steps,
        "quadratization": settings.iterative_lq,
    }
    if not solution.converged:
        status = (
            Status.ITERATION_LIMIT if solution.iterations >= settings.max_iterations else Status.NOT_CONVERGED
        )
        return Result(
            status=status,
            message=f"iterative LQ games did not converge: {solution.reason}",
            iterations=solution.iterations,
            metrics=base | {"solution_concept": "none", "payoffs": payoffs, "iterative_lq": run},
        )
    improvements = {
        name: float(solution.costs[i] - best_reply(discrete, solution, i))
        for i, name in enumerate(discrete.players)
    }
    gap = nash_gap(improvements, payoffs, settings.tolerance)
    message = gap.message("the feedback equilibrium of iterative LQ games")
    times = solution.times
    return Result(
        status=Status.OPTIMAL,
        message=message,
        objective=payoffs[discrete.players[0]],
        t_final=float(times[-1]),
        time=times,
        control_time=times[:-1],
        states={s: solution.x[:, i] for i, s in enumerate(discrete.states)},
        controls={c: solution.u[:, j] for j, c in enumerate(discrete.controls)},
        iterations=solution.iterations,
        checks={"saddle_gap": gap.gap},
        metrics=base
        | gap.metrics(concept, payoffs)
        | {
            "iterative_lq": run,
            "gains": {c: solution.P[:, j, :].tolist() for j, c in enumerate(discrete.controls)},
        },
    )
