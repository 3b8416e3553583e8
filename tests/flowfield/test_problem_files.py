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
    game reports its outcome, and the Monte Carlo of the SDE agrees with eq. 5.39 in open loop (the
    nonlinear drift is close to its linearization over the dispersion: a 0.01 allowance)."""
    result = gamespec.solve(gamespec.load(path))
    m = result.metrics
    spec = gamespec.load(path)
    dx = evaluate(spec).grid.spacing.max()
    assert m["capture_time"] > 0
    assert result.checks["capture_time_difference"] < 0.25 * dx / evaluate(spec).nominal_speeds[0]
    assert isinstance(m["game_converged"], bool)
    carlo = m["monte_carlo_capture_probability"]["open_loop"]
    assert carlo["low"] - 0.01 <= m["capture_probability_open_loop"] <= carlo["high"] + 0.01
