"""Shared fixtures: paths of the shipped problem files, a CLI runner, and the status policy's
invariant asserted on every Result the solving chain returns anywhere in the suite. Hypothesis runs
derandomized: the same examples on every machine and run, so that a random tree SymPy takes
minutes to evaluate (seen once in the printer's random trees) cannot stall one CI run and not the
next."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import settings

settings.register_profile("gamespec", derandomize=True)
settings.load_profile("gamespec")

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "problems"


@pytest.fixture
def cli(capsys):
    """Run ``gamespec ARGS`` in-process; returns (exit code, stdout, stderr)."""
    from gamespec.cli import run

    def invoke(*args: str) -> tuple[int, str, str]:
        code = run([str(a) for a in args])
        captured = capsys.readouterr()
        return code, captured.out, captured.err

    return invoke


def rest_to_rest(a: float, t_final: float, **problem: object) -> dict:
    """The rest-to-rest double integrator ``x'' = u`` at 0 on [0, t_final] minimizing the integral
    of u², parameter ``a``, with ``problem``'s entries added (an event, a constraint): the
    closed-form cases of the interior-point tests."""
    return {
        "kind": "optimal_control",
        "problem": {
            "parameters": {"a": a},
            "states": {"x": {"initial": 0.0, "final": 0.0}, "v": {"initial": 0.0, "final": 0.0}},
            "controls": {"u": {}},
            "dynamics": {"x": "v", "v": "u"},
            "objective": {"lagrange": "u**2"},
            "time": {"final": t_final},
            **problem,
        },
    }


def assert_optimal_means_checked(result) -> None:
    """The status policy's invariant (README "Statuses and exit codes"): an ``optimal`` Result has
    every verdict in ``metrics["checks_passed"]`` True, every value with a verdict or a tolerance
    finite, and every value at most its ``metrics["check_tolerances"]`` entry."""
    import math

    if result.status.value != "optimal":
        return
    verdicts = result.metrics.get("checks_passed", {})
    tolerances = result.metrics.get("check_tolerances", {})
    assert all(verdicts.values()), f"optimal with failed verdicts {verdicts}"
    for name in set(verdicts) | set(tolerances):
        if name in result.checks:
            value = result.checks[name]
            assert value is not None and math.isfinite(value), f"optimal with {name} = {value}"
            if name in tolerances:
                assert value <= tolerances[name], f"optimal with {name} = {value} > {tolerances[name]}"


@pytest.fixture(autouse=True)
def _optimal_means_checked(monkeypatch):
    """Wrap the chain (:meth:`gamespec.solving.Solver._solve`, behind every ``solve``) so that every
    Result it returns in any test satisfies :func:`assert_optimal_means_checked`."""
    from gamespec import solving

    chain = solving.Solver._solve

    def checked(self, *args, **kwargs):
        result = chain(self, *args, **kwargs)
        assert_optimal_means_checked(result)
        return result

    monkeypatch.setattr(solving.Solver, "_solve", checked)
