"""The checks' compiled RK4 re-integration equals the NumPy one on every shipped OCP (issue 29
item 1): each shipped file's OCP (after its transforms and lowering), at its own starting guess
with a perturbation, re-integrated by :mod:`gamespec.ocp.compiled_checks` and by the reference
below — the NumPy route the checks took before, stage by stage through the problem's recorded
running function — to 1e-10."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

import gamespec
import gamespec.loader
from gamespec.ocp.checks import RK4_STEPS, Trajectory, _per_interval, _rk4, control_basis
from gamespec.ocp.transcription import Transcription
from gamespec.solving import transformed
from tests.conftest import PROBLEMS


def _reference(tr, sol, params, chosen, degree):
    X, T = sol.X, sol.T
    grid = tr.grid
    starts = grid.interval_start_index
    h = np.diff(grid.breaks)[chosen] * T
    t0 = tr.t0 + T * grid.breaks[chosen]
    Ui, Wi = _per_interval(tr, sol.U, chosen), _per_interval(tr, sol.Win, chosen)
    nx = tr.n_x
    n_int = len(tr.ocp.running_structure.integrands)
    y = np.vstack([X[:, starts[chosen]].astype(float), np.zeros((n_int, len(chosen)))])
    ds = 1.0 / RK4_STEPS
    halves = np.arange(2 * RK4_STEPS + 1) * ds / 2
    bases = control_basis(tr, halves, degree)
    p = [params[n] for n in [*tr.ocp.parameters, *tr.ocp.design]]

    def f(y, half):
        basis = bases[half]
        values = tr.ocp.running_function(*y[:nx], *(Ui @ basis), *(Wi @ basis), *p, t0 + halves[half] * h)
        return np.delete(values, nx, axis=0)

    for step in range(RK4_STEPS):
        k1 = f(y, 2 * step)
        k2 = f(y + 0.5 * ds * h * k1, 2 * step + 1)
        k3 = f(y + 0.5 * ds * h * k2, 2 * step + 1)
        k4 = f(y + ds * h * k3, 2 * step + 2)
        y = y + ds * h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    return np.abs(y[:nx] - X[:, starts[chosen + 1]]), y[nx:]


def _ocp_targets() -> list:
    """The shipped files of the collocation kinds (their kind read from the YAML: loading every
    file at collection cost each worker seconds)."""
    kinds = {"optimal_control", "multiphase_optimal_control", "engagement"}
    return [p for p in sorted(PROBLEMS.rglob("*.yaml")) if yaml.safe_load(p.read_text())["kind"] in kinds]


TIME_VARYING = {
    "kind": "optimal_control",
    "name": "time_varying",
    "problem": {
        "parameters": {"a": 0.7},
        "states": {"x": {"initial": 1.0}, "y": {"initial": 0.0}},
        "controls": {"u": {"lower": -2, "upper": 2}},
        "inputs": {"w": {"default": "sin(5*tau)"}},
        "dynamics": {"x": "a*t*x + sin(3*t)*u + w", "y": "x**2 - cos(t)*u"},
        "objective": {"lagrange": "u**2 + t*x**2"},
        "integral_constraints": [{"integrand": "x*t + w", "upper": 10}],
        "time": {"final": 2.0},
    },
    "method": {"scheme": "radau", "intervals": 7, "degree": 3, "degrees": [1, 2, 3, 4, 3, 2, 5]},
}


def _time_varying():
    return gamespec.loader.spec_from_dict(TIME_VARYING)


@pytest.mark.parametrize("path", [*_ocp_targets(), "time_varying"], ids=lambda p: getattr(p, "stem", p))
def test_compiled_reintegration_equals_the_numpy_one(path) -> None:
    """Every shipped OCP, and a time-varying one with a grid input, an integrand and mixed degrees
    (where the stage times, the input basis and the integrals matter)."""
    target = _time_varying() if path == "time_varying" else transformed(gamespec.load(path), "casadi")
    tr = Transcription(target)
    params = tr.ocp.parameter_values() | dict(zip(tr.ocp.design, np.zeros(tr.n_d), strict=True))
    start = tr.guess(params)
    rng = np.random.default_rng(0)
    X = start.X * (1 + 0.01 * rng.standard_normal(start.X.shape)) + 0.01 * rng.standard_normal(start.X.shape)
    U = start.U + 0.01 * rng.standard_normal(start.U.shape)
    sol = Trajectory(X, U, tr.input_values(params), start.T)
    with np.errstate(all="ignore"):
        for degree in sorted(set(tr.grid.interval_degrees.tolist())):
            chosen = np.flatnonzero(tr.grid.interval_degrees == degree)
            compiled = _rk4(tr, sol, params, chosen, int(degree))
            reference = _reference(tr, sol, params, chosen, int(degree))
            for ours, theirs in zip(compiled, reference, strict=True):
                scale = max(1.0, float(np.nanmax(np.abs(theirs), initial=0.0)))
                np.testing.assert_allclose(ours, theirs, rtol=1e-10, atol=1e-10 * scale, equal_nan=True)


def _reference_point_values(tr, sol, params) -> np.ndarray:
    """The running terms at the evaluation points as the checks evaluated them before: the recorded
    NumPy running function (dynamics, Lagrange integrand, integrands) and the path constraints
    walked from the text over NumPy arrays."""
    from gamespec.ocp.checks import ARRAYS

    t_eval = tr.t0 + sol.T * tr.grid.eval_tau
    xe = sol.X[:, tr.grid.eval_index]
    p = [params[n] for n in [*tr.ocp.parameters, *tr.ocp.design]]
    running = tr.ocp.running_function(*xe, *sol.U, *sol.Win, *p, t_eval)
    arrays = {n: np.float64(v) for n, v in params.items()}
    terms = tr.ocp.running_terms(tr.ocp.running_values(xe, sol.U, sol.Win, t_eval, arrays), ARRAYS)
    path = [np.broadcast_to(np.asarray(r.expr, dtype=float), t_eval.shape) for r in terms.path]
    return np.vstack([np.broadcast_to(running, (running.shape[0], t_eval.size)), *path])


@pytest.mark.parametrize("path", [*_ocp_targets(), "time_varying"], ids=lambda p: getattr(p, "stem", p))
def test_compiled_point_values_equal_the_numpy_ones(path) -> None:
    """What the path-constraint, integral and Hamiltonian checks read (the running terms at the
    evaluation points), compiled once per transcription, equals the NumPy route to 1e-10 on every
    shipped OCP."""
    from gamespec.ocp.checks import _point_values

    target = _time_varying() if path == "time_varying" else transformed(gamespec.load(path), "casadi")
    tr = Transcription(target)
    params = tr.ocp.parameter_values() | dict(zip(tr.ocp.design, np.zeros(tr.n_d), strict=True))
    start = tr.guess(params)
    rng = np.random.default_rng(1)
    X = start.X * (1 + 0.01 * rng.standard_normal(start.X.shape)) + 0.01 * rng.standard_normal(start.X.shape)
    U = start.U + 0.01 * rng.standard_normal(start.U.shape)
    sol = Trajectory(X, U, tr.input_values(params), start.T)
    with np.errstate(all="ignore"):
        ours, theirs = _point_values(tr, sol, params), _reference_point_values(tr, sol, params)
    np.testing.assert_allclose(ours, theirs, rtol=1e-10, atol=1e-300, equal_nan=True)
