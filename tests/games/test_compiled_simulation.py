"""The games' compiled true system and point evaluation against the interpreted routes they replace
(issue 29 item 1), kept here as the references only:

- the true system (:mod:`gamespec.games.simulate`, CVODES in CasADi) against SciPy's DOP853 with a
  Python right-hand side (the file's text parsed into SymPy, evaluated by the NumPy tape, the
  control held as each interval's polynomial by ``np.polyfit``), both at rtol 1e-11, to 1e-8 of
  the states' scale on every shipped game, on Radau of degrees 1 and 3 and on the trapezoidal
  scheme, with samples that do not fall on the intervals' breaks;
- the collocation states and payoff at a point (:mod:`gamespec.games.evaluation`, Newton's method
  in CasADi) against SciPy's ``hybr`` on the defects evaluated by the NumPy tape, to 1e-10;
- the chapter-7 run at Q = 1 (slow): the same capture time, clearances and collisions with the
  references in place of the compiled routes.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import root

import gamespec.games.equilibrium as equilibrium
from gamespec.games import evaluation
from gamespec.games.expressions import game_expressions
from gamespec.games.problems import player_problem, views
from gamespec.games.simulate import ControlPlan, Dynamics, grid_of
from gamespec.loader import load
from gamespec.ocp.checks import ARRAYS
from gamespec.ocp.transcription import Transcription
from gamespec.solving import compile_spec
from gamespec.symbolic.calculus import numeric_function
from gamespec.symbolic.language import parse, symbol
from tests.conftest import PROBLEMS

GAMES = sorted(
    p
    for p in (PROBLEMS / "ch7").glob("*.yaml")
    if load(p).kind == "differential_game" and not load(p).problem.time.free
)
"""The shipped games of a fixed horizon (a game of degree, ``time: {final: free}``, is the hji
backend's: it has no open-loop true system)."""
METHODS = {
    "file": [],
    "radau3": ["method.scheme=radau", "method.degree=3", "method.intervals=10"],
    "trapezoidal": ["method.scheme=trapezoidal", "method.intervals=10"],
}


def _signal(grid, values: np.ndarray, start: float, horizon: float):
    """The control between the evaluation points as the interpreted route held it."""
    tau_eval = grid.eval_tau
    if grid.scheme != "radau":
        return lambda t: float(np.interp((t - start) / horizon, tau_eval, values))
    d = grid.degree
    coefficients = [
        np.polyfit(tau_eval[k * d : (k + 1) * d], values[k * d : (k + 1) * d], d - 1)
        for k in range(grid.intervals)
    ]

    def signal(t: float) -> float:
        tau = min(max((t - start) / horizon, 0.0), 1.0)
        k = int(np.clip(np.searchsorted(grid.breaks, tau, side="left") - 1, 0, grid.intervals - 1))
        return float(np.polyval(coefficients[k], tau))

    return signal


def _interpreted_advance(spec, params, x0, controls, t0, duration, breaks, mesh):
    """SciPy's DOP853 with a Python right-hand side, piece by piece between ``breaks`` and the
    control intervals' breaks ``mesh``; the states at ``breaks``."""
    p = spec.problem
    states = list(p.states)
    names = [*p.parameters, *p.uncertain, *states, *controls, "t"]
    table = {n: symbol(n) for n in names}
    f = numeric_function([parse(p.dynamics[s], table) for s in states], [table[n] for n in names])
    values = [params[n] for n in [*p.parameters, *p.uncertain]]
    times = np.unique(np.clip(np.concatenate([[t0, t0 + duration], breaks]), t0, t0 + duration))
    edges = np.union1d(times, mesh[(mesh > t0 + 1e-9) & (mesh < t0 + duration - 1e-9)])
    x, rows = np.array([x0[s] for s in states], dtype=float), {t0: None}
    rows[t0] = x
    for a, b in itertools.pairwise(edges):
        middle = 0.5 * (a + b)

        def rhs(t, y, middle=middle):
            u = [controls[c](middle + (t - middle) * (1 - 1e-9)) for c in controls]
            return np.asarray(f(*values, *y, *u, t), dtype=float).ravel()

        x = solve_ivp(rhs, (a, b), x, method="DOP853", rtol=1e-11, atol=1e-12).y[:, -1]
        rows[b] = x
    return times, np.array([rows[t] for t in times])


CASES = [(p, "file") for p in GAMES] + [
    (PROBLEMS / "ch7" / f"{name}.yaml", method)
    for name in ("asymmetric_obstacle", "unicycle_pursuit_evasion")
    for method in ("radau3", "trapezoidal")
]


@pytest.mark.parametrize(("path", "method"), CASES, ids=lambda c: getattr(c, "stem", c))
def test_true_system_equals_the_interpreted_integration(path, method) -> None:
    spec = load(path, METHODS[method])
    p = spec.problem
    controls = [c for pl in p.players.values() for c in pl.controls]
    grid = grid_of(spec.method)
    rng = np.random.default_rng(7)
    values = {c: rng.uniform(-1.0, 1.0, grid.eval_tau.size) for c in controls}
    params = dict(p.parameters) | {n: u.actual for n, u in p.uncertain.items()}
    x0 = dict(p.values.initial)
    t0, horizon = float(p.time.initial), p.values.horizon
    samples = t0 + horizon * np.linspace(0.0, 1.0, 8)
    plan = ControlPlan.on_grid(grid, values, t0, horizon)
    dynamics = Dynamics(game_expressions(spec), controls)
    x = np.array([x0[s] for s in p.states])
    vector = np.array([params[n] for n in [*p.parameters, *p.uncertain]])
    times, rows = dynamics.advance(x, vector, plan, t0, horizon, samples)
    signals = {c: _signal(grid, values[c], t0, horizon) for c in controls}
    mesh = t0 + horizon * grid.breaks
    ref_times, ref_rows = _interpreted_advance(spec, params, x0, signals, t0, horizon, samples, mesh)
    np.testing.assert_array_equal(times, ref_times)
    scale = np.maximum(1.0, np.abs(ref_rows).max(axis=0))
    assert np.all(np.abs(rows - ref_rows) <= 1e-8 * scale), np.abs(rows - ref_rows).max()
    for t in (t0 + 0.3 * horizon, t0 + 0.77 * horizon):
        for c, value in plan.at(t).items():
            assert value == pytest.approx(signals[c](t), rel=1e-10, abs=1e-10)


def _interpreted_states(tr, params, U, Win, start):
    """The collocation states by SciPy's ``hybr`` on the defects of the NumPy tape (the route the
    point evaluation took before), None when not met to the same tolerance."""
    D, W, _ = tr.grid.matrices
    T = float(tr.bounds(params).t_lower)
    p = [np.float64(params[n]) for n in [*tr.ocp.parameters, *tr.ocp.design]]
    t = tr.t0 + T * tr.grid.eval_tau
    x0 = np.asarray(start[:, 0], dtype=float)

    def states(z):
        return np.column_stack([x0, z.reshape(tr.n_x, -1)])

    def defects(z):
        X = states(z)
        F = tr.ocp.running_function(*X[:, tr.grid.eval_index], *U, *Win, *p, t)[: tr.n_x]
        F = np.broadcast_to(F, (tr.n_x, W.shape[1]))
        return (D @ X.T - T * (W @ F.T)).T.ravel()

    with np.errstate(all="ignore"):
        solution = root(defects, np.asarray(start[:, 1:], dtype=float).ravel(), method="hybr", tol=1e-14)
        X = states(solution.x)
        scale = np.maximum(1.0, np.abs(X).max(axis=1))
        gap = np.abs(defects(solution.x)).reshape(tr.n_x, -1) / scale[:, None]
    return X if np.isfinite(gap).all() and gap.max() <= evaluation.DEFECT_TOLERANCE else None


def _interpreted_payoff(tr, params, X, U, Win):
    T = float(tr.bounds(params).t_lower)
    p = [np.float64(params[n]) for n in [*tr.ocp.parameters, *tr.ocp.design]]
    t = tr.t0 + T * tr.grid.eval_tau
    lagrange = np.broadcast_to(
        tr.ocp.running_function(*X[:, tr.grid.eval_index], *U, *Win, *p, t)[tr.n_x], t.shape
    )
    arrays = {n: np.float64(v) for n, v in params.items()}
    ends = tr.ocp.end_values((X[:, 0], X[:, -1]), tr.end_controls(U), np.float64(tr.t0 + T), arrays)
    mayer = float(tr.ocp.end_terms(ends, ARRAYS).mayer)
    return tr.ocp.sign * (mayer + T * float(tr.grid.triplets[2] @ lagrange))


@pytest.mark.parametrize("path", GAMES, ids=lambda p: p.stem)
def test_point_states_and_payoff_equal_the_interpreted_ones(path) -> None:
    spec = load(path)
    rng = np.random.default_rng(3)
    compared = 0
    for view in views(spec):
        for player in spec.problem.players:
            tr = Transcription(player_problem(spec, player, view))
            params = tr.ocp.parameter_values()
            k = tr.grid.eval_tau.size
            U = 0.5 * rng.standard_normal((tr.n_u, k))
            Win = tr.input_values(params) + 0.5 * rng.standard_normal((tr.n_w, k))
            start = tr.guess(params).X + 0.1 * rng.standard_normal((tr.n_x, tr.grid.n_nodes))
            ours = evaluation.states_at(tr, params, U, Win, start)
            theirs = _interpreted_states(tr, params, U, Win, start)
            assert (ours is None) == (theirs is None)
            if ours is None:
                continue
            compared += 1
            scale = np.maximum(1.0, np.abs(theirs).max(axis=1))[:, None]
            assert np.all(np.abs(ours - theirs) <= 1e-10 * scale)
            payoff = evaluation.payoff_at(tr, params, ours, U, Win)
            assert payoff == pytest.approx(
                _interpreted_payoff(tr, params, theirs, U, Win), rel=1e-10, abs=1e-10
            )


def _chapter_7(*sets: str) -> dict:
    spec = load(PROBLEMS / "ch7" / "asymmetric_obstacle.yaml", ["problem.parameters.Q=1", *sets])
    return compile_spec(spec).solve().metrics


@pytest.mark.slow
def test_chapter_7_run_is_unchanged_by_the_compiled_routes(monkeypatch) -> None:
    """Section 7.3.2 at Q = 1: capture time, each player's clearance of the obstacle and who
    collides are those of the run with the interpreted true system and point evaluation and
    IPOPT's default ``max_iter`` (the file caps it at 60)."""
    compiled = _chapter_7()

    def advance(self, x0, params, plan, t0, duration, breaks):
        p = spec.problem
        values = dict(zip([*p.parameters, *p.uncertain], params, strict=True))
        signals = {c: (lambda t, c=c: plan.at(t)[c]) for c in self.controls}
        start = dict(zip(self.states, x0, strict=True))
        return _interpreted_advance(spec, values, start, signals, t0, duration, breaks, plan.mesh)

    spec = load(PROBLEMS / "ch7" / "asymmetric_obstacle.yaml", ["problem.parameters.Q=1"])
    monkeypatch.setattr(Dynamics, "advance", advance)
    monkeypatch.setattr(equilibrium, "states_at", _interpreted_states)
    monkeypatch.setattr(equilibrium, "payoff_at", _interpreted_payoff)
    interpreted = _chapter_7("solver.options.casadi.max_iter=3000")
    assert compiled["captured"] and interpreted["captured"]
    assert compiled["capture_time"] == pytest.approx(interpreted["capture_time"], abs=1e-6)
    for player in ("pursuer", "evader"):
        assert compiled[f"{player}_collided"] == interpreted[f"{player}_collided"]
        clearance = f"{player}_min_obstacle_distance"
        assert compiled[clearance] == pytest.approx(interpreted[clearance], abs=1e-6)
    assert compiled["all_converged"] == interpreted["all_converged"]
