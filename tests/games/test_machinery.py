"""The game machinery: builds counted, per-player transforms through the solving chain (with the
views ``G^i`` they create), the receding horizon against the open-loop solution, and bad input."""

from __future__ import annotations

import numpy as np
import pytest
from gamespec_casadi import backend as casadi_backend

from gamespec import registry
from gamespec.errors import SpecError
from gamespec.games.problems import player_problem, views
from gamespec.loader import load
from gamespec.solving import compile_spec
from gamespec.summaries import outcome
from tests.conftest import PROBLEMS
from tests.core.test_chain import test_transforms  # noqa: F401  (the chain's test-only transforms)
from tests.games.test_lq_game import FILE, SOLVER_TOL, closed_form, expected

WEIGHT = 0.5
SHRINKING = [
    "receding_horizon.step=0.1",
    "receding_horizon.time_limit=1.0",
    "receding_horizon.horizon=shrinking",
]


@pytest.fixture
def builds(monkeypatch) -> list[int]:
    """Counts every CasADi model built (one NLP and its solver each)."""
    count = [0]
    real = casadi_backend.CasadiModel.__init__

    def counting(self, *args, **kwargs):
        count[0] += 1
        real(self, *args, **kwargs)

    monkeypatch.setattr(casadi_backend.CasadiModel, "__init__", counting)
    return count


def test_best_response_resolves_do_not_rebuild(builds):
    """Each player's problem is built once: the iteration's re-solves, a re-solve with a new
    parameter value and every receding-horizon step reuse the models."""
    solver = compile_spec(load(FILE))
    assert builds[0] == 2
    first = solver.solve()
    solver.solve(parameters={"q": 5.0})
    responses = sum(p["responses"] for p in first.metrics["best_response"]["pursuer"]["players"].values())
    assert responses > 2 and builds[0] == 2
    receding = load(FILE, ["receding_horizon.step=0.1", "receding_horizon.time_limit=0.5"])
    run = compile_spec(receding).solve()
    assert builds[0] == 4 and run.metrics["steps"] == 5 and run.metrics["builds"] == 2
    assert run.metrics["solves"] > 10


@pytest.mark.usefixtures("test_transforms")
def test_a_players_transform_goes_through_the_chain_in_its_own_game():
    """The pursuer's requested transform (the test-only ``weighted_lagrange``: + w(u1² + u2²), i.e.
    r → r + 2w) enters its own game only; the evader, unaware of it, solves the plain game. Each
    applies its own game's controls, and the true system moves by their sum (closed forms of
    :mod:`tests.games.test_lq_game`)."""
    entry = f'[{{weighted_lagrange: {{term: "u1**2 + u2**2", weight: {WEIGHT}}}}}]'
    spec = load(FILE, [f"problem.players.pursuer.transforms={entry}"])
    assert views(spec) == ["pursuer", "evader"]
    assert player_problem(spec, "pursuer", "pursuer").transforms
    assert not player_problem(spec, "pursuer", "evader").transforms
    solver = compile_spec(spec)
    pursuer = solver.compiled.model.responders[("pursuer", "pursuer")].solver
    assert [s.transform.name for s in pursuer.steps] == ["weighted_lagrange"]
    result = solver.solve()
    assert result.ok, result.message
    p, want = spec.problem.parameters, expected(spec)
    delta0 = np.array([want["x0"]["xp"] - want["x0"]["xe"], want["x0"]["yp"] - want["x0"]["ye"]])
    own = closed_form(p["s"], p["r"] + 2 * WEIGHT, p["q"], p["T"], delta0)
    np.testing.assert_allclose(result.controls["u1"], own["u"][0], atol=SOLVER_TOL)
    np.testing.assert_allclose(result.controls["v2"], want["v"][1], atol=SOLVER_TOL)
    T = p["T"]
    np.testing.assert_allclose(result.states["xp"][-1], want["x0"]["xp"] + T * own["u"][0], atol=SOLVER_TOL)
    np.testing.assert_allclose(result.states["ye"][-1], want["x0"]["ye"] + T * want["v"][1], atol=SOLVER_TOL)
    game_xp = result.arrays["game/pursuer/xp"]
    np.testing.assert_allclose(game_xp[-1], want["x0"]["xp"] + T * own["u"][0], atol=SOLVER_TOL)


def test_shrinking_receding_horizon_equals_the_open_loop_solution():
    """Open-loop Nash equilibria are time consistent: re-solving from the state reached on the
    equilibrium path gives the rest of the same path, so a receding horizon reaching the final
    time reproduces the open-loop solution (the true system integrated between steps)."""
    open_loop = compile_spec(load(FILE)).solve()
    closed = compile_spec(load(FILE, SHRINKING)).solve()
    assert closed.ok and closed.metrics["steps"] == 10
    steps = closed.control_time
    for name in open_loop.states:
        np.testing.assert_allclose(
            np.interp(open_loop.time, closed.time, closed.states[name]),
            open_loop.states[name],
            atol=SOLVER_TOL,
        )
    np.testing.assert_allclose(
        closed.controls["u1"],
        np.interp(steps, open_loop.control_time, open_loop.controls["u1"]),
        atol=SOLVER_TOL,
    )


@pytest.mark.parametrize(
    ("override", "field"),
    [
        ("problem.uncertain={rho: {actual: 1.0, beliefs: {nobody: 0.5}}}", "problem.uncertain"),
        (
            "problem.players.pursuer.transforms=[{no_such_transform: {}}]",
            "problem.players.pursuer.transforms.0",
        ),
        ("problem.players.evader.start={w: 1.0}", "problem"),
        ("problem.dynamics.xp=u1 + bogus", "problem"),
    ],
)
def test_bad_input_names_the_field(override, field):
    with pytest.raises(SpecError) as err:
        load(FILE, [override])
    assert err.value.field.startswith(field)
    assert err.value.source == str(FILE)


def test_bad_file_exits_2_with_one_line(cli, tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(FILE.read_text().replace("objective: maximize", "objective: maximise"))
    code, _, err = cli("solve", bad)
    assert code == 2 and "players.evader.objective" in err and len(err.strip().splitlines()) == 1


def test_asymmetric_obstacle_first_steps_and_the_pursuers_belief():
    """Three steps of §7.3.2: the pursuer predicts the obstacle with ρ̂ while it moves with the true
    ρ, so the believed and true centres differ by (ρ̄ − ρ̂) t along the obstacle's direction."""
    spec = load(PROBLEMS / "ch7" / "asymmetric_obstacle.yaml", ["receding_horizon.time_limit=0.3"])
    result = compile_spec(spec).solve()
    m = result.metrics
    assert m["steps"] == 3 and not m["captured"] and not m["pursuer_collided"]
    rho = spec.problem.uncertain["rho"]
    direction = spec.problem.parameters["direction"]
    gap = result.arrays["obstacle/true/y"] - result.arrays["obstacle/pursuer/y"]
    np.testing.assert_allclose(
        gap, direction * (rho.actual - rho.beliefs["pursuer"]) * result.time, atol=1e-9
    )
    assert result.arrays["lookahead/pursuer/xp"].shape == (3, spec.method.intervals + 1)
    assert set(m["per_step"][0]["games"]) == {"pursuer", "evader"}
    rows = dict(outcome(result))
    assert rows["captured"] is False and "capture time" not in rows
    assert rows["receding-horizon steps"] == 3
    assert rows["pursuer: closest to the obstacle"] == m["pursuer_min_obstacle_distance"]


@pytest.mark.parametrize("timing", ["absolute", "relative"])
def test_sensitivity_time_of_the_predicted_obstacle(timing):
    """The pursuer's payoff modification is chapter 6's registered transform, applied by the chain
    to its own problem only. With ``desensitize`` in the pursuer's game, the sensitivity of the
    obstacle it predicts, z = d + direction·ρ̂·t, starts each step at ∂z/∂ρ = direction·t_k
    (absolute time: the initial value is the prediction's first-order expansion, eq. 7.14) or at 0
    (relative), and grows by
    direction·(t − t_k) along the step's horizon."""
    spec = load(
        PROBLEMS / "ch7" / "asymmetric_obstacle.yaml",
        [
            "receding_horizon.time_limit=0.3",
            f"receding_horizon.sensitivity_time={timing}",
            "problem.uncertain.rho.distribution={normal: {std: 0.1}}",
            "problem.players.pursuer.transforms=[{desensitize: {trajectory: {S_yp_rho: Q}, "
            "monte_carlo: {samples: 0}}}]",
        ],
    )
    solver = compile_spec(spec)
    pursuer = solver.compiled.model.responders[("pursuer", "pursuer")]
    evader = solver.compiled.model.responders[("pursuer", "evader")]
    chapter6 = registry.load("gamespec.transforms", "desensitize")
    assert [type(s.transform) for s in pursuer.solver.steps] == [chapter6]
    assert not evader.solver.steps
    result = solver.solve()
    assert result.ok, result.message
    last = pursuer.last
    direction, t_k = spec.problem.parameters["direction"], result.control_time[-1]
    start = direction * t_k if timing == "absolute" else 0.0
    np.testing.assert_allclose(last.states["S_z_rho"], start + direction * last.time, atol=1e-6)
