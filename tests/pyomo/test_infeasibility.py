"""Fast honest statuses on Pyomo (issue 27, item 6): a transcription whose constraints are linear is
checked for feasibility by an LP before ripopt runs.

The double integrator ``x'' = u, |u| <= 1`` from rest at x = x0 to rest at 0 needs at least the
bang-bang time ``2 sqrt(x0)`` (accelerate for half, brake for half): with x0 = 1 a fixed final time
of 1 is infeasible, one of 2.5 feasible (both independent of any solver)."""

from __future__ import annotations

import math
import resource

import pytest

import gamespec
from gamespec.result import Status


def _double_integrator(x0: float, t_final: float, parameter: bool = False) -> dict:
    """The problem; with ``parameter`` the control enters as ``b*u`` with b = 1 a parameter (a Var
    held by equal bounds in the Pyomo model: the defects are linear only once it is read as one)."""
    return {
        "kind": "optimal_control",
        "name": "double_integrator_to_rest",
        "problem": {
            "parameters": {"b": 1.0} if parameter else {},
            "states": {"x": {"initial": x0, "final": 0.0}, "v": {"initial": 0.0, "final": 0.0}},
            "controls": {"u": {"lower": -1.0, "upper": 1.0}},
            "dynamics": {"x": "v", "v": "b*u" if parameter else "u"},
            "objective": {"lagrange": "u**2"},
            "time": {"final": t_final},
        },
        "method": {"intervals": 40, "degree": 3},
    }


def _cpu_seconds() -> float:
    usage = [resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)]
    return sum(u.ru_utime + u.ru_stime for u in usage)


@pytest.mark.parametrize("parameter", [False, True])
def test_infeasible_linear_transcription_is_infeasible_without_the_nlp_solver(parameter: bool) -> None:
    spec = gamespec.spec_from_dict(_double_integrator(1.0, 0.5 * 2 * math.sqrt(1.0), parameter))
    start = _cpu_seconds()
    result = gamespec.solve(spec, "pyomo")
    assert result.status is Status.INFEASIBLE, result.message
    assert "LP feasibility check" in result.message
    assert _cpu_seconds() - start < 20  # ripopt ran 3000 iterations (minutes on a loaded machine)


def test_feasible_linear_transcription_is_solved_and_agrees_with_casadi() -> None:
    spec = gamespec.spec_from_dict(_double_integrator(1.0, 1.25 * 2 * math.sqrt(1.0)))
    pyomo, casadi = gamespec.solve(spec, "pyomo"), gamespec.solve(spec, "casadi")
    assert pyomo.status is Status.OPTIMAL and casadi.status is Status.OPTIMAL
    assert pyomo.objective == pytest.approx(casadi.objective, rel=1e-6)


def test_casadi_agrees_that_it_is_infeasible() -> None:
    spec = gamespec.spec_from_dict(_double_integrator(1.0, 1.0))
    assert gamespec.solve(spec, "casadi").status is Status.LOCALLY_INFEASIBLE


def _cubic_decay(x_final: float) -> dict:
    """``x' = -x^3 + u``, ``|u| <= 1/2``, from x(0) = 0 to x(1) = x_final: while x >= 0 the slope is
    at most 1/2, so x(1) <= 1/2 (a comparison argument, no solver): x_final = 2 is infeasible."""
    return {
        "kind": "optimal_control",
        "name": "cubic_decay",
        "problem": {
            "states": {"x": {"initial": 0.0, "final": x_final}},
            "controls": {"u": {"lower": -0.5, "upper": 0.5}},
            "dynamics": {"x": "-x**3 + u"},
            "objective": {"lagrange": "u**2"},
            "time": {"final": 1.0},
        },
        "method": {"intervals": 20, "degree": 3},
    }


def test_infeasible_nonlinear_problem_is_locally_infeasible_in_seconds() -> None:
    """ripopt alone ends ``Restoration Failed`` (numerical_error); the elastic problem of
    :mod:`gamespec_pyomo.feasibility` finds a positive least violation, as IPOPT does on casadi."""
    spec = gamespec.spec_from_dict(_cubic_decay(2.0))
    start = _cpu_seconds()
    result = gamespec.solve(spec, "pyomo")
    assert result.status is Status.LOCALLY_INFEASIBLE, result.message
    assert "l1 norm of the constraint violation" in result.message
    assert _cpu_seconds() - start < 20
    assert gamespec.solve(spec, "casadi").status is Status.LOCALLY_INFEASIBLE


def test_feasible_nonlinear_counterpart_is_solved() -> None:
    """x_final = 0.3 is below the bound 1/2: both backends solve it and agree."""
    spec = gamespec.spec_from_dict(_cubic_decay(0.3))
    pyomo, casadi = gamespec.solve(spec, "pyomo"), gamespec.solve(spec, "casadi")
    assert pyomo.status is Status.OPTIMAL and casadi.status is Status.OPTIMAL
    assert pyomo.objective == pytest.approx(casadi.objective, rel=1e-6)


def _scaled_control(t_final: float) -> dict:
    """``x'' = u (1 + x^2/10)``, ``|u| <= 1``, from rest at x = 1 to rest at 0: on [0, 1] the
    acceleration is at most 1.1 in size, so a path that stays there needs the bang-bang time
    ``2 sqrt(1/1.1) = 1.91`` of the double integrator with that bound; ``t_final = 1`` is far below
    it (not a proof for paths that leave [0, 1]: IPOPT on casadi's local infeasibility is asserted
    beside), 3 above it."""
    data = _double_integrator(1.0, t_final)
    data["problem"]["dynamics"]["v"] = "u*(1 + 0.1*x**2)"
    return data


def test_ripopt_probe_finds_local_infeasibility_without_running_its_iteration_limit() -> None:
    """ripopt has no infeasibility detection: it ran its 3000 iterations here (9.7 s CPU, against
    IPOPT's 24 on casadi). The probe (:data:`gamespec_pyomo.feasibility.PROBE_ITERATIONS`) stops it
    early, the violation stagnant, and the elastic problem proves local infeasibility."""
    from gamespec_pyomo.feasibility import PROBE_ITERATIONS

    spec = gamespec.spec_from_dict(_scaled_control(1.0))
    gamespec.solve(gamespec.spec_from_dict(_scaled_control(3.0)), "pyomo")  # imports and first builds
    start = _cpu_seconds()
    result = gamespec.solve(spec, "pyomo")
    assert result.status is Status.LOCALLY_INFEASIBLE, result.message
    assert result.iterations is not None and result.iterations <= PROBE_ITERATIONS
    assert "l1 norm of the constraint violation" in result.message
    assert _cpu_seconds() - start < 5
    assert gamespec.solve(spec, "casadi").status is Status.LOCALLY_INFEASIBLE


def test_a_feasible_problem_past_the_probe_is_the_single_run_answer(monkeypatch) -> None:
    """With a probe shorter than the solve (2 iterations) the feasible counterpart ends as one run
    ends: the same objective and iteration count to the bit, the full run starting where the probe
    did."""
    import gamespec_pyomo.backend as backend

    spec = gamespec.spec_from_dict(_scaled_control(3.0))
    single = gamespec.solve(spec, "pyomo")
    monkeypatch.setattr(backend, "PROBE_ITERATIONS", 2)
    probed = gamespec.solve(spec, "pyomo")
    assert single.status is Status.OPTIMAL and probed.status is Status.OPTIMAL
    assert single.iterations is not None and single.iterations > 2
    assert probed.objective == single.objective and probed.iterations == single.iterations
