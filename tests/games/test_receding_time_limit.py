"""A receding-horizon run honours ``max_wall_time`` (issue 27, item 2): it stops at the end of the
step that passed it with the status ``time_limit`` and the steps it made."""

from __future__ import annotations

import gamespec
from gamespec.result import Status
from tests.conftest import PROBLEMS


def test_stops_after_one_step_with_status_time_limit() -> None:
    spec = gamespec.load(
        PROBLEMS / "ch7" / "asymmetric_obstacle.yaml",
        ["receding_horizon.max_wall_time=1e-9", "game.max_iterations=2"],
    )
    result = gamespec.solve(spec)
    assert result.status is Status.TIME_LIMIT
    assert result.metrics["stop"] == "max_wall_time"
    assert result.metrics["steps"] == 1
    assert len(result.control_time) == 1
