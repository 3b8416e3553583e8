"""The shipped chapter-5 files: they validate (fast) and solve as they are (slow)."""

from __future__ import annotations

import numpy as np
import pytest

import gamespec
from gamespec.flowfield.problem import evaluate
from tests.conftest import PROBLEMS

FILES = sorted((PROBLEMS / "ch5").glob("*.yaml"))


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_files_validate(path, cli) -> None:
    assert cli("validate", path)[0] == 0


def test_alpha_is_a_parameter(cli) -> None:
    spec = gamespec.load(PROBLEMS / "ch5" / "linear_flow.yaml", ["problem.parameters.alpha=0.2"])
    g = evaluate(spec).field.diffusion(np.zeros((1, 2)))[0]
    np.testing.assert_allclose(g, 0.05 * np.eye(2))


@pytest.mark.slow
@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_files_solve(path) -> None:
    """Each file reaches capture, the two reachability methods agree to a fraction of a cell, the
    minimax game converges (the file solves, exit 0), and the Monte Carlo of the SDE agrees with
    eq. 5.39 in both loops (the nonlinear drift is close to its linearization over the dispersion:
    a 0.01 allowance)."""
    result = gamespec.solve(gamespec.load(path))
    m = result.metrics
    spec = gamespec.load(path)
    dx = evaluate(spec).grid.spacing.max()
    assert m["capture_time"] > 0
    assert result.checks["capture_time_difference"] < 0.25 * dx / evaluate(spec).nominal_speeds[0]
    assert result.ok and m["game_converged"], result.message
    for loop in ("open_loop", "closed_loop"):
        carlo = m["monte_carlo_capture_probability"][loop]
        assert carlo["low"] - 0.01 <= m[f"capture_probability_{loop}"] <= carlo["high"] + 0.01
