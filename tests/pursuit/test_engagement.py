"""The engagement kind and its transform: generated dynamics are the thesis's equations."""

from __future__ import annotations

import math

import pytest
import sympy as sp

import gamespec
from gamespec.specs.ocp import OptimalControlSpec
from gamespec.symbolic.language import parse, parse_relation, symbol
from gamespec.transforms.engagement import to_ocp
from tests.conftest import PROBLEMS

FILES = [
    PROBLEMS / "ch2" / "constant_bearing_two_on_one.yaml",
    PROBLEMS / "ch2" / "constant_bearing_degenerate.yaml",
    PROBLEMS / "ch2" / "pure_pursuit_two_on_one.yaml",
    PROBLEMS / "ch2" / "relay_pure_pursuit.yaml",
    PROBLEMS / "ch2" / "relay_constant_bearing.yaml",
    PROBLEMS / "ch3" / "mpse_optimal_evasion_cb.yaml",
    PROBLEMS / "ch2" / "pp_collinear_behind.yaml",
]

NAMES = ["r1", "r2", "psi", "phi1", "phi2", "theta", "theta_E", "u1", "u2", "v"]
S = {n: symbol(n) for n in NAMES}
r1, r2, psi, phi1, phi2, th, thE, u1, u2, v = (S[n] for n in NAMES)
cos, sin, sqrt = sp.cos, sp.sin, sp.sqrt

THESIS = {
    "2.8": {
        "r1": v * cos(thE - phi1) - sqrt(u1**2 - v**2 * sin(thE - phi1) ** 2),
        "r2": v * cos(thE - phi2) - sqrt(u2**2 - v**2 * sin(thE - phi2) ** 2),
    },
    "2.21": {
        "r1": -u1 + v * cos(th),
        "r2": -u2 - v * cos(psi - th),
        "psi": v / r2 * sin(psi - th) - v / r1 * sin(th),
    },
    "2.34": {
        "r1": v * cos(thE - phi1) - sqrt(u1**2 - v**2 * sin(thE - phi1) ** 2),
        "r2": v * cos(thE - phi2),
        "phi2": v / r2 * sin(thE - phi2),
    },
    "2.42": {
        "r1": -u1 + v * cos(th),
        "r2": -v * cos(psi - th),
        "psi": v / r2 * sin(psi - th) - v / r1 * sin(th),
    },
    "3.15-3.16": {
        "r1": -u1 + v * cos(thE - phi1),
        "phi1": v / r1 * sin(thE - phi1),
        "r2": -u2 + v * cos(thE - phi2),
        "phi2": v / r2 * sin(thE - phi2),
    },
}
CASES = [
    ("2.8", "constant_bearing_two_on_one.yaml", []),
    ("2.21", "pure_pursuit_two_on_one.yaml", []),
    ("2.34", "relay_constant_bearing.yaml", []),
    ("2.42", "relay_pure_pursuit.yaml", []),
    ("3.15-3.16", "pure_pursuit_two_on_one.yaml", ["frame=fixed"]),
]


@pytest.mark.parametrize(("equation", "name", "overrides"), CASES)
def test_generated_dynamics_are_the_thesis_equations(equation: str, name: str, overrides: list[str]) -> None:
    ocp, _ = to_ocp(gamespec.load(PROBLEMS / "ch2" / name, overrides))
    dynamics = ocp.problem.dynamics
    assert set(dynamics) == set(THESIS[equation])
    for state, expected in THESIS[equation].items():
        assert sp.simplify(parse(dynamics[state], S) - expected) == 0, (equation, state)


@pytest.mark.parametrize(
    ("name", "overrides", "reference"),
    [
        ("relay_pure_pursuit.yaml", [], None),
        ("relay_constant_bearing.yaml", [], "phi1"),
        ("pure_pursuit_two_on_one.yaml", ["frame=fixed"], "phi1_init"),
    ],
)
def test_generated_constraints_and_bounds(name: str, overrides: list[str], reference: str | None) -> None:
    """The Voronoi constraint ½(r_1² − r_2²) ≤ 0 of a stationary P2 (eq. 2.36), and the heading
    bounds: θ ∈ [−π, π] in the line-of-sight frame, θ_E within π of φ_1(0) in the fixed frame."""
    problem = to_ocp(gamespec.load(PROBLEMS / "ch2" / name, overrides))[0].problem
    symbols = S | {"phi1_init": symbol("phi1_init")}
    if name.startswith("relay"):
        (constraint,) = [parse_relation(c, symbols) for c in problem.path_constraints]
        assert (constraint.lower, constraint.upper) == (-math.inf, 0.0)
        assert sp.simplify(constraint.expr - (r1**2 - r2**2) / 2) == 0
    else:
        assert problem.path_constraints == []
    centre = sp.Integer(0) if reference is None else symbol(reference)
    (bounds,) = problem.controls.values()
    assert sp.simplify(parse(bounds.lower, symbols) - (centre - sp.pi)) == 0
    assert sp.simplify(parse(bounds.upper, symbols) - (centre + sp.pi)) == 0


def test_eq_3_2_for_five_pursuers_and_initial_conditions_from_positions() -> None:
    """One distance state per CB pursuer (eq. 3.2), r_i(0) from eq. 3.4, φ_i from eq. 3.17."""
    ocp, inverse = to_ocp(gamespec.load(FILES[5]))
    p = ocp.problem
    assert list(p.states) == [f"r{i}" for i in range(1, 6)]
    players = inverse.players
    for i, (r0, phi0) in enumerate(zip(players.distances(), players.los_angles(), strict=True), start=1):
        assert p.parameters[f"r{i}_init"] == pytest.approx(r0)
        assert p.parameters[f"phi{i}"] == pytest.approx(phi0)
        assert p.states[f"r{i}"].lower == "eps"


@pytest.mark.parametrize("path", FILES)
def test_generated_spec_validates_and_round_trips(path) -> None:
    ocp, _ = to_ocp(gamespec.load(path))
    again = gamespec.spec_from_dict(ocp.model_dump(mode="json"))
    assert isinstance(again, OptimalControlSpec)
    assert again == ocp
    assert ocp.problem.objective.sense == "maximize"


@pytest.mark.parametrize("path", FILES)
def test_problem_files_solve_as_they_are(cli, path, tmp_path) -> None:
    code, out, err = cli("solve", path, "--json", "--out", tmp_path / "run")
    assert code == 0, err
    result = gamespec.Result.load(tmp_path / "run")
    assert result.ok
    assert '"status": "optimal"' in out


def test_show_transformed_prints_the_generated_problem(cli) -> None:
    code, out, _ = cli("show", FILES[2], "--transformed")
    assert code == 0
    assert "psi" in out and "sin(psi - theta)" in out


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"evader": {"position": [1.0, 0.0], "speed": 1.5}}, "faster than the evader"),
        ({"pursuers": []}, "at least 1"),
        ({"capture_radius": 2.0}, "inside the capture radius"),
        ({"frame": "line_of_sight"}, "must be pp"),
    ],
)
def test_invalid_engagements_name_the_reason(change: dict, message: str) -> None:
    data = gamespec.load(FILES[0]).model_dump(mode="json") | change
    with pytest.raises(gamespec.SpecError, match=message):
        gamespec.spec_from_dict(data)


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("position: [0.0, 0.0]", "position: [.nan, 0.0]", "pursuers.0.position.0"),
        ("-0.875], speed: 1.0", "-0.875], speed: .nan", "pursuers.1.speed"),
        ("speed: 0.5}", "speed: .inf}", "evader.speed"),
        ("position: [1.0, 0.0]", "position: [1.0, -.inf]", "evader.position.1"),
        ("capture_radius: 0.001", "capture_radius: .nan", "capture_radius"),
        ("capture_radius: 0.001", "capture_radius: 0.001\nguess_heading: .nan", "guess_heading"),
    ],
)
@pytest.mark.parametrize("command", [("validate",), ("solve",), ("show", "--transformed")])
def test_non_finite_numbers_are_refused_in_one_line(cli, tmp_path, old, new, field, command) -> None:
    text = FILES[2].read_text()
    assert old in text
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace(old, new))
    code, _, err = cli(command[0], bad, *command[1:])
    assert code == 2
    assert len(err.strip().splitlines()) == 1
    assert field in err and "finite" in err


def test_a_stationary_pursuer_may_have_speed_zero() -> None:
    data = gamespec.load(FILES[3]).model_dump(mode="json")
    data["pursuers"][1]["speed"] = 0.0
    assert gamespec.spec_from_dict(data).is_relay


def test_evader_starting_in_the_stationary_pursuers_cell_is_refused(cli) -> None:
    """Eq. 2.28 at t = 0: E at (−0.5, 0) is nearer the stationary P2 (origin) than the active P1."""
    code, _, err = cli("validate", FILES[3], "--set", "evader.position=[-0.5, 0.0]")
    assert code == 2
    assert "Voronoi cell of stationary pursuer 'P2'" in err


def test_relay_needs_exactly_one_active_pursuer() -> None:
    data = gamespec.load(FILES[0]).model_dump(mode="json")
    data["pursuers"].append({"name": "P3", "position": [5.0, 5.0], "strategy": "stationary"})
    with pytest.raises(gamespec.SpecError, match="exactly one active"):
        gamespec.spec_from_dict(data)


def test_cli_validate_rejects_a_misspelled_key(cli, tmp_path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(FILES[0].read_text().replace("capture_radius", "capture_radios"))
    code, _, err = cli("validate", bad)
    assert code == 2
    assert "capture_radius" in err


def test_analytic_backend_refuses_relay(cli) -> None:
    code, _, err = cli("solve", FILES[3], "--backend", "analytic")
    assert code == 2
    assert "relay" in err


def test_generated_problem_solves_on_every_ocp_backend() -> None:
    """The generated eq. 2.21 problem is a plain optimal_control spec: pyomo agrees with casadi."""
    casadi = gamespec.solve(FILES[2], "casadi")
    pyomo = gamespec.solve(FILES[2], "pyomo")
    assert pyomo.ok
    assert pyomo.t_final == pytest.approx(casadi.t_final, rel=1e-6)
    assert pyomo.metrics["capturing_set"] == casadi.metrics["capturing_set"] == ["P1", "P2"]
