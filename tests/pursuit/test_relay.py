"""Relay pursuit (§2.5): Proposition 2's region, its vertices, and the three-arc optimal paths."""

from __future__ import annotations

import numpy as np
import pytest

import gamespec
from gamespec.pursuit import relay
from gamespec.pursuit.relay import voronoi_margin
from gamespec.pursuit.simulation import Players, simulate_to_capture
from tests.conftest import PROBLEMS

RELAY_PP = PROBLEMS / "ch2" / "relay_pure_pursuit.yaml"
RELAY_CB = PROBLEMS / "ch2" / "relay_constant_bearing.yaml"
ACTIVE, GUARD = np.array([-2.0, 0.0]), np.array([0.0, 0.0])


def _relay_players(evader, strategy: str, v: float = 0.8) -> Players:
    return Players(
        names=("P1", "P2"),
        positions=np.array([ACTIVE, GUARD]),
        speeds=np.array([1.0, 0.0]),
        strategies=(strategy, "stationary"),
        evader=np.asarray(evader, dtype=float),
        v=v,
        eps=1e-6,
    )


@pytest.mark.parametrize("strategy", ["cb", "pp"])
def test_proposition_2_agrees_with_simulated_line_of_sight_evasion(strategy: str) -> None:
    """Non-degenerate ⇔ fleeing along P1's line of sight enters P2's Voronoi cell before capture."""
    seen = set()
    for x in np.linspace(-1.9, -1.05, 6):
        for y in np.linspace(-1.0, 1.0, 7):
            players = _relay_players((x, y), strategy)
            margin = voronoi_margin(simulate_to_capture(players, players.los_angles()[0]), players).max()
            if abs(margin) < 1e-2:
                continue
            expected = bool(margin > 0)
            assert bool(relay.is_nondegenerate(ACTIVE, GUARD, np.array([x, y]), 1.0, 0.8)) == expected
            seen.add(expected)
    assert seen == {True, False}


def test_vertices_lie_on_the_arcs_of_eq_2_33_and_bound_the_region() -> None:
    v = relay.vertices(ACTIVE, GUARD, 1.0, 0.8)
    for point in v.values():
        assert relay.boundary_residual(-2.0, 1.0, 0.8, *point) == pytest.approx(0.0, abs=1e-12)
    a, b = v["A"], v["B"]
    assert np.allclose(a, [-2.0 * 0.8, 0.0])
    step = np.array([1e-3, 0.0])
    assert not relay.is_nondegenerate(ACTIVE, GUARD, a - step, 1.0, 0.8)
    assert relay.is_nondegenerate(ACTIVE, GUARD, a + step, 1.0, 0.8)
    inside, outside = b * [1.0, 0.98] - [1e-4, 0.0], b * [1.0, 1.02] - [1e-4, 0.0]
    assert relay.is_nondegenerate(ACTIVE, GUARD, inside, 1.0, 0.8)
    assert not relay.is_nondegenerate(ACTIVE, GUARD, outside, 1.0, 0.8)


def test_slow_evader_never_reaches_the_voronoi_boundary() -> None:
    """v < u/2: the region of non-degeneracy is empty (after Proposition 2)."""
    grid = np.stack(np.meshgrid(np.linspace(-1.99, -1.01, 40), np.linspace(-1.5, 1.5, 40)), axis=-1)
    assert not relay.is_nondegenerate(ACTIVE, GUARD, grid, 1.0, 0.45).any()
    assert relay.is_nondegenerate(ACTIVE, GUARD, grid, 1.0, 0.8).any()


@pytest.mark.parametrize(("path", "frame"), [(RELAY_PP, "line_of_sight"), (RELAY_CB, "fixed")])
def test_optimal_relay_path_has_three_arcs_and_keeps_the_state_constraint(path, frame: str) -> None:
    """§2.5.3: interior arc, Voronoi-boundary arc, line-of-sight arc; at the switch eq. 2.41 (R-CB)
    or eq. 2.46 (R-PP) holds; re-simulated with an ODE integrator the path keeps eq. 2.28."""
    result = gamespec.solve(path)
    arcs = result.metrics["arcs"]
    assert result.status == gamespec.Status.OPTIMAL
    assert result.metrics["frame"] == frame
    assert result.metrics["capturing_set"] == ["P1"]
    assert 0.0 < arcs["tau1"] < arcs["tau2"] < result.t_final
    for part in ("interior_duration", "boundary_duration", "line_of_sight_duration"):
        assert arcs[part] > 0.05 * result.t_final
    assert abs(arcs["switching_residual"]) < 1e-2
    assert arcs["line_of_sight_heading_error"] < 1e-2
    assert result.checks["resimulated_max_voronoi_margin"] < 1e-4
    assert result.checks["resimulated_capture_time_error"] < 1e-3
    assert result.checks["hamiltonian_variation"] < 1e-3


def test_evader_starts_in_the_region_of_non_degeneracy() -> None:
    spec = gamespec.load(RELAY_PP)
    players = Players.from_spec(spec)
    assert relay.is_nondegenerate(ACTIVE, GUARD, players.evader, 1.0, spec.evader.speed)
    line_of_sight = simulate_to_capture(players, players.los_angles()[0])
    assert voronoi_margin(line_of_sight, players).max() > 0
