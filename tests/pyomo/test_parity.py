"""Parity of the two OCP backends on every shipped ``optimal_control`` file: CasADi's IPOPT and the
Pyomo backend (ripopt, or ipopt on PATH) solve the identical discretization, so at the same grid
they must reach the same optimum, the same trajectories and the same costates (defect multipliers
scaled by the Radau weights)."""

from __future__ import annotations

import numpy as np
import pytest

import gamespec
from gamespec.result import Result
from tests.pyomo.cases import OCP_FILES


def _close(a: dict[str, np.ndarray], b: dict[str, np.ndarray], rel: float) -> None:
    assert a.keys() == b.keys()
    for name in a:
        scale = 1.0 + np.max(np.abs(a[name]))
        np.testing.assert_allclose(b[name], a[name], rtol=0, atol=rel * scale, err_msg=name)


SLOW_PAIRS = {
    "hyper_sensitive",
    "cdoc_lqr_b_uncertain",
    "cdoc_lqr_marginal",
    "rcs_constraint_form",
    "free_flying_robot",
}
"""Files whose refined or long solves cost a second or more on each backend: compared with ``-m slow``
(the other C-DOC, RCS and refined files keep the parity in the default suite)."""


@pytest.fixture(
    scope="module",
    params=[pytest.param(p, marks=pytest.mark.slow) if p.stem in SLOW_PAIRS else p for p in OCP_FILES],
    ids=lambda p: p.stem,
)
def pair(request) -> tuple[Result, Result]:
    spec = gamespec.load(request.param)
    return gamespec.solve(spec, "casadi"), gamespec.solve(spec, "pyomo")


def test_there_are_ocp_files() -> None:
    assert len(OCP_FILES) >= 3  # pure_pursuit_two_on_one.yaml is an engagement file since issue 4


MESH_CHECKS = {"max_defect_relative", "chattering"}
"""Checks that measure a file's mesh (the same on both backends), not the solver's convergence."""


def test_both_backends_optimal_or_held_back_by_the_same_mesh_checks(pair) -> None:
    """Both solvers converge; where the file's mesh fails a check (the status policy makes the Result
    ``feasible``), it fails the same checks on both backends."""
    casadi, pyomo = pair
    assert casadi.status == pyomo.status and casadi.ok, (casadi.message, pyomo.message)
    failed = [{f.name for f in r.failed_checks()} for r in pair]
    assert failed[0] == failed[1] and failed[0] <= MESH_CHECKS, (casadi.message, pyomo.message)
    assert (casadi.status.value == "optimal") == (not failed[0])


def test_objectives_agree(pair) -> None:
    casadi, pyomo = pair
    assert pyomo.objective == pytest.approx(casadi.objective, rel=1e-4)
    assert pyomo.t_final == pytest.approx(casadi.t_final, rel=1e-4)


def test_trajectories_close_on_the_common_grid(pair) -> None:
    casadi, pyomo = pair
    np.testing.assert_allclose(pyomo.time, casadi.time, rtol=1e-4)
    np.testing.assert_allclose(pyomo.control_time, casadi.control_time, rtol=1e-4)
    _close(casadi.states, pyomo.states, 1e-4)
    _close(casadi.controls, pyomo.controls, 1e-3)


def test_costates_from_sol_duals_agree(pair) -> None:
    casadi, pyomo = pair
    assert pyomo.costates, "the SOL file carried no defect multipliers"
    _close(casadi.costates, pyomo.costates, 1e-3)


def test_solution_checks_agree(pair) -> None:
    """The solver-independent checks (defect re-integration, violation, Hamiltonian) see the same
    solution from both backends."""
    casadi, pyomo = pair
    assert pyomo.checks.keys() == casadi.checks.keys()
    for name, value in casadi.checks.items():
        assert pyomo.checks[name] == pytest.approx(value, rel=1e-2, abs=1e-6), name
