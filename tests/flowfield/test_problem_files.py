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
    game solves (exit 0) with every check passed, and the Monte Carlo of the SDE agrees with eq. 5.39
    in both loops (the nonlinear drift is close to its linearization over the dispersion: a 0.01
    allowance). Both report the thesis' reading (``lower_value``, the closed loop) and the mixed
    minimax beside it, and the saddle gap between them: the lower value captures more than open loop
    (Fig. 5.2, section 5.4), a worst-case evader less than the lower value."""
    result = gamespec.solve(gamespec.load(path))
    m = result.metrics
    spec = gamespec.load(path)
    dx = evaluate(spec).grid.spacing.max()
    assert m["capture_time"] > 0
    assert result.checks["capture_time_difference"] < 0.25 * dx / evaluate(spec).nominal_speeds[0]
    assert result.ok and m["game_converged"], result.message
    assert all(m["checks_passed"].values()), m["checks_passed"]
    assert m["solution_concept"] == "lower_value"
    assert m["capture_probability_closed_loop"] == m["capture_probability_lower_value"]
    assert m["capture_probability_lower_value"] > m["capture_probability_open_loop"]
    assert m["capture_probability_minimax_mixed"] < m["capture_probability_lower_value"]
    assert m["saddle_gap"] > spec.method.game.gap * m["upper_value"]
    for loop in ("open_loop", "closed_loop"):
        carlo = m["monte_carlo_capture_probability"][loop]
        assert carlo["low"] - 0.01 <= m[f"capture_probability_{loop}"] <= carlo["high"] + 0.01
