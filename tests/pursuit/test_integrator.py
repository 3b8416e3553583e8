"""The compiled RK4 of the true dynamics (``gamespec.pursuit.integrator``) against SciPy's DOP853 at
rtol 1e-12 integrating the same heading as a Python law: the same capture instants and paths to
1e-9 (the compiled steps' own error is near 1e-11 on these cases, DOP853's below it)."""

from __future__ import annotations

import numpy as np
import pytest

from gamespec.ocp.control_signal import TranscribedSignal
from gamespec.pursuit import simulation
from gamespec.pursuit.simulation import (
    Players,
    ScheduledHeading,
    capture_bound,
    compiled_integration,
    simulate,
)

AGREEMENT = 1e-9
"""Capture times and positions of the two integrations agree to this (absolute, in lengths and
times of order one)."""


def _players(strategies: tuple[str, ...], eps: float) -> Players:
    rng = np.random.default_rng(len(strategies))
    n = len(strategies)
    return Players(
        names=tuple(f"P{i}" for i in range(n)),
        positions=rng.uniform(-2.0, 2.0, (n, 2)),
        speeds=np.array([0.0 if s == "stationary" else rng.uniform(1.0, 1.5) for s in strategies]),
        strategies=strategies,
        evader=np.array([0.3, -0.2]),
        v=0.6,
        eps=eps,
    )


def _signal() -> TranscribedSignal:
    """Four intervals of quadratics, with jumps at the interval boundaries."""
    rng = np.random.default_rng(7)
    return TranscribedSignal(np.array([0.0, 0.3, 0.5, 1.2, 2.0]), rng.uniform(-1.0, 1.0, (1, 4, 3)))


def _python_law(heading: ScheduledHeading):
    return lambda t, P, E: heading(t, P, E)


@pytest.mark.parametrize(
    ("strategies", "eps", "line_of_sight"),
    [(("pp", "pp"), 1e-3, True), (("cb", "pp", "stationary"), 0.05, False), (("cb", "cb"), 0.02, True)],
)
def test_capture_and_paths_equal_a_tight_scipy_integration(strategies, eps, line_of_sight) -> None:
    players = _players(strategies, eps)
    heading = ScheduledHeading(_signal(), line_of_sight)
    t_max = 1.01 * capture_bound(players)
    compiled = simulate(players, heading, t_max, method="compiled")
    reference = simulate(players, _python_law(heading), t_max, rtol=1e-12, method="DOP853")
    assert compiled.captured and reference.captured
    assert compiled.capture_time == pytest.approx(reference.capture_time, abs=AGREEMENT)
    np.testing.assert_allclose(compiled.pursuers, reference.pursuers, atol=AGREEMENT)
    np.testing.assert_allclose(compiled.evader, reference.evader, atol=AGREEMENT)
    np.testing.assert_allclose(compiled.heading, reference.heading, atol=1e-7)
    distance = compiled.distances()[-1][players.active].min()
    assert distance == pytest.approx(eps, abs=1e-12)


def test_no_capture_runs_to_the_end() -> None:
    """An evader as fast as its pursuer running straight away is never caught: the run ends at
    ``t_max`` with the distance unchanged."""
    players = Players(("P",), np.zeros((1, 2)), np.array([1.0]), ("pp",), np.array([1.0, 0.0]), 1.0, 0.1)
    run = simulate(players, 0.0, 3.0, method="compiled")
    assert not run.captured
    assert run.capture_time == 3.0
    np.testing.assert_allclose(run.distances()[:, 0], 1.0, atol=1e-12)
    np.testing.assert_allclose(run.evader[-1], [4.0, 0.0], atol=1e-12)


def test_the_compiled_route_is_taken_only_where_a_loop_asks_for_it(monkeypatch) -> None:
    """Without a method, a constant heading goes through SciPy unless inside
    :func:`~gamespec.pursuit.simulation.compiled_integration`, and the block leaves the route as
    it found it."""
    players = Players(("P",), np.zeros((1, 2)), np.array([1.0]), ("pp",), np.array([0.5, 0.0]), 0.5, 0.1)
    taken = []
    compiled = simulation._compiled
    monkeypatch.setattr(simulation, "_compiled", lambda *args: taken.append(args) or compiled(*args))
    outside = simulate(players, 0.0, 3.0)
    with compiled_integration():
        inside = simulate(players, 0.0, 3.0)
    after = simulate(players, 0.0, 3.0)
    assert len(taken) == 1
    assert inside.capture_time == pytest.approx(outside.capture_time, abs=1e-8)
    assert after.capture_time == outside.capture_time
