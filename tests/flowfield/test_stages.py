"""Chapter 5 as a staged chain (:mod:`gamespec.flowfield.transform`): the reachability stage
solved once by the solving layer, the covariance game it writes (``gamespec show --transformed``),
and re-solves with a new noise level that reuse the stage (a call counter on the reachability
solve) and equal a fresh compile."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml
from gamespec_levelset import reachability

from gamespec.flowfield.spec import FlowCovarianceGameSpec
from gamespec.loader import load, spec_from_dict
from gamespec.solving import compile_spec, solve
from tests.flowfield.test_flow_game import SPEC, T_EXACT


def _spec(**problem: object) -> dict:
    """The uniform flow of ``test_flow_game`` on a coarser grid, the lower value, no Monte Carlo and
    no cross-check: a cheap chain (about 1 s of CPU a solve)."""
    data = copy.deepcopy(SPEC)
    data["problem"] |= problem
    data["method"]["grid"]["nodes"] = [33, 31]
    data["method"]["game"] = {"scheme": "lower_value", "max_iterations": 6}
    data["method"]["monte_carlo"]["samples"] = 0
    data["solver"] = {"options": {"levelset": {"cross_check": False}}}
    return data


def _counting(calls: list[int], index: int, solve_once):
    def counting(*args, **kwargs):
        calls[index] += 1
        return solve_once(*args, **kwargs)

    return counting


@pytest.fixture
def counted(monkeypatch) -> list[int]:
    """Counts the level-set reachability solves of the ``levelset`` backend and its extremal
    cross-checks."""
    calls = [0, 0]
    monkeypatch.setitem(
        reachability.REACHABILITY, "levelset", _counting(calls, 0, reachability.REACHABILITY["levelset"])
    )
    monkeypatch.setattr(reachability, "_extremal_reach", _counting(calls, 1, reachability._extremal_reach))
    return calls


def test_show_transformed_prints_the_covariance_game(tmp_path, cli) -> None:
    """The backend receives the covariance game of section 5.3: the file's flow, players and
    parameters, ``N = round(T̂ / step)`` (eq. 5.7) and the nominal paths (eqs. 5.23–5.26) from
    ``x₀`` to the capture point ``x_f``, in a uniform flow the closed form of Theorem 6, within a
    cell. The printed game, read back as a file, is what the backend solves: the same answers to
    the last bit as the chain's."""
    path = tmp_path / "uniform.yaml"
    path.write_text(yaml.safe_dump(_spec()))
    code, out, err = cli("show", path, "--transformed")
    assert code == 0, err
    game = FlowCovarianceGameSpec.model_validate(yaml.safe_load(out))
    p = game.problem
    assert game.kind == "flow_covariance_game" and p.parameters == {"noise": 0.05}
    assert p.flow.diffusion.identity == "noise"
    assert p.steps == round(T_EXACT / 0.2) == 6
    times = np.array(p.nominal.times)
    assert times[-1] == pytest.approx(T_EXACT, abs=0.02)
    gap = np.array([1.0, 0.5])
    x_f = gap + np.array([0.4, -0.3]) * T_EXACT + 0.6 * T_EXACT * gap / np.linalg.norm(gap)
    dx = 6.5 / 32
    for player, start in (("pursuer", [0, 0]), ("evader", [1, 0.5])):
        x = np.array(getattr(p.nominal, player).positions)
        assert np.linalg.norm(x[0] - start) < dx
        assert np.linalg.norm(x[-1] - x_f) < dx
    game_file = tmp_path / "game.yaml"
    game_file.write_text(out)
    printed = solve(load(game_file))
    chained = solve(spec_from_dict(_spec()))
    assert printed.kind == "flow_covariance_game" and chained.kind == "flow_field_game"
    assert printed.status == chained.status and printed.objective == chained.objective
    for key in ("capture_probability_open_loop", "capture_probability_closed_loop", "lower_value"):
        assert printed.metrics[key] == chained.metrics[key]


def test_a_new_noise_re_solves_the_game_without_the_level_sets(counted) -> None:
    """The noise enters the game only: the compiled chain keeps the reachability stage's Result
    (``Step.upstream``) and re-solves the game for each new value; each re-solve equals a fresh
    compile at that value (which solves the level sets and the extremal cross-check again)."""
    data = _spec()
    data["solver"] = {"options": {"levelset": {"cross_check": True}}}
    data["method"]["extremals"] = {"directions": 64, "step": 0.01}
    solver = compile_spec(spec_from_dict(data))
    assert counted == [1, 1]
    first = solver.solve()
    again = solver.solve(parameters={"noise": 0.1})
    assert counted == [1, 1], "the re-solve recomputed the reachability"
    data["problem"]["parameters"]["noise"] = 0.1
    fresh = solve(spec_from_dict(data))
    assert counted == [2, 2]
    assert again.checks["capture_time_difference"] == fresh.checks["capture_time_difference"]
    assert again.status == fresh.status and again.ok
    assert again.objective == pytest.approx(fresh.objective, rel=1e-9)
    assert again.objective > first.objective  # more noise, more relative spread
    for key in ("capture_probability_open_loop", "capture_probability_closed_loop", "capture_time"):
        assert again.metrics[key] == pytest.approx(fresh.metrics[key], rel=1e-9)
    assert again.metrics["capture_time"] == first.metrics["capture_time"]
    assert again.metrics["capture_probability_open_loop"] < first.metrics["capture_probability_open_loop"]


def test_no_capture_is_an_infeasible_result() -> None:
    """Without a capture before ``max_time`` the stage has no nominal paths: the game is not played
    and the Result says why, in the stage's words."""
    data = _spec()
    data["method"]["max_time"] = 0.3
    result = solve(spec_from_dict(data))
    assert result.status.value == "infeasible"
    assert "capture" in result.message
    assert result.metrics["reachability"]["method"] == "levelset"
    assert result.metrics["game_converged"] is False
