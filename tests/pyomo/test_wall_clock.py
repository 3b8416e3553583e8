"""The Pyomo backend's wall-clock limit is one (issue 25, item 6): ripopt checks its own
``max_wall_time`` once an iteration only, so the process is killed at the limit and the Result is
``time_limit``. The unscaled shuttle (``method.scale: none``) runs to ripopt's limits (hundreds of
iterations); with a 1 s limit the process must end within a fraction of a second after it."""

from __future__ import annotations

import gamespec
from gamespec.result import Status
from tests.conftest import PROBLEMS

SHUTTLE = PROBLEMS / "ocp" / "shuttle_reentry.yaml"
LIMIT = 1.0


def test_the_solver_process_ends_at_the_wall_clock_limit() -> None:
    overrides = ["method.scale=none", "method.intervals=10", f"solver.options.pyomo.max_wall_time={LIMIT}"]
    result = gamespec.solve(gamespec.load(SHUTTLE, overrides), "pyomo")
    assert result.status is Status.TIME_LIMIT, result.message
    assert result.solver_stats["process_time_s"] <= LIMIT + 0.5
    assert "wall-clock limit" in result.message or "Time Exceeded" in result.message
