"""Warm re-solves of a compiled RCS model (issue 29, item 3): a new α (the rcs weight, a runtime
parameter mapped through the transforms) and a new σ (the uncertain speed's standard deviation,
an analysis value: only the Monte Carlo reads it) re-solve the compiled model and give what a
fresh compile of the same file gives; the Monte Carlo's one-path route (every sample on the same
open-loop path) against its per-sample loop."""

import numpy as np
import pytest

from gamespec.desensitize.montecarlo import draws
from gamespec.desensitize.simulate import rk4
from gamespec.loader import load, with_values
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.solving import compile_spec
from gamespec.specs.uncertainty import UncertainParameter
from tests.conftest import PROBLEMS

SINGLE = PROBLEMS / "ch6" / "rcs_single_obstacle.yaml"
SIGMA = "problem.uncertain.rho.normal.std"
POINTS = [{"Q": 1.0, SIGMA: 0.3}, {"Q": 0.3, SIGMA: 0.2}]
"""Two (α, σ) points of the ahead homotopy class, with a collision probability well above 0."""


@pytest.fixture(scope="module")
def compiled():
    solver = compile_spec(SINGLE)
    solver.solve()
    return solver


def test_warm_resolve_equals_a_fresh_compile(compiled):
    for point in POINTS:
        warm = compiled.solve(parameters=point)
        fresh = compile_spec(with_values(load(SINGLE), point)).solve()
        assert warm.status == fresh.status and warm.ok
        assert warm.objective == pytest.approx(fresh.objective, rel=1e-8, abs=1e-8)
        assert warm.t_final == pytest.approx(fresh.t_final, rel=1e-8)
        mc_warm, mc_fresh = warm.metrics["monte_carlo"], fresh.metrics["monte_carlo"]
        assert mc_warm["collision_probability"] == pytest.approx(mc_fresh["collision_probability"], abs=1e-8)
        assert mc_warm["collision_probability"] > 0.05
        assert mc_warm["parameters"]["rho"]["std"] == pytest.approx(point[SIGMA], rel=0.1)  # σ was used


def test_a_new_sigma_keeps_every_compiled_step(compiled):
    spec = with_values(compiled.spec, {SIGMA: 0.25})
    steps = compiled.mapped_steps(spec, names=[SIGMA])
    assert [s.inverse for s in steps] == [s.inverse for s in compiled.steps]  # nothing re-applied
    assert all(s.inverse is old.inverse for s, old in zip(steps, compiled.steps, strict=True))
    for step in steps:
        assert step.source.problem.uncertain["rho"].normal.std == 0.25
    assert steps[-1].target.problem.uncertain["rho"].normal.std == 0.25


def test_one_path_equals_the_per_sample_loop(compiled):
    """Every sample of the file shares the agent's path (the obstacle's speed is what is drawn):
    the one-path route against the per-sample loop (a zero feedback forces it), same arithmetic."""
    result = compiled.solve()
    spec = compiled.steps[-1].source
    ocp = SymbolicOcp(spec)
    options = compiled.steps[-1].inverse.report.options.monte_carlo.model_copy(update={"samples": 300})
    wide = {"rho": UncertainParameter.model_validate({"normal": {"std": 0.3}})}
    d = draws(ocp, result, wide, options)
    args = (ocp, d.x0, d.controls, d.params, d.t0, d.tf, 400)
    shared = rk4(*args, keep=20, tolerance=1e-6)
    loop = rk4(*args, keep=20, feedback=lambda k, x: np.zeros((len(ocp.u), 1)), tolerance=1e-6)
    assert np.ptp(shared.violation) > 0  # the samples differ where it matters
    assert 0 < shared.violated[-1] < 1  # some samples collide, not all
    for name in ("x", "u", "final", "running", "energy", "violation", "violated"):
        np.testing.assert_allclose(getattr(shared, name), getattr(loop, name), rtol=1e-12, atol=1e-12)
