"""Multi-phase problems (issue 17, item 4) against theory, on casadi and pyomo: a two-phase problem
with a fixed switch against the same problem in one phase, a free switching time at its closed form
with H = -dPhi/dt_f on each phase, a staged rocket's mass drop against Tsiolkovsky's equation, a
phase without the control against its closed form."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import yaml

import gamespec
from gamespec.loader import spec_from_dict
from gamespec.result import Result
from gamespec.solving import transformed
from tests.conftest import PROBLEMS

BACKENDS = ["casadi", "pyomo"]
ROCKET = PROBLEMS / "ocp" / "two_stage_rocket.yaml"
TWO_PHASES = PROBLEMS / "ocp" / "double_integrator_two_phases.yaml"
ONE_PHASE = PROBLEMS / "ocp" / "min_time_double_integrator.yaml"
IPOPT_LEVEL = 1e-6
"""What a quantity that IPOPT (tol 1e-8) determines is compared with, absolute or relative."""

REST_TO_REST = {
    "parameters": {"L": 1.0},
    "states": {"x": {"initial": 0.0, "final": "L"}, "v": {"initial": 0.0, "final": 0.0}},
    "controls": {"u": {}},
    "dynamics": {"x": "v", "v": "u"},
    "objective": {"lagrange": "u**2"},
}
"""Minimum energy from rest to rest over a distance L in time T: u linear, x cubic (Radau collocation
of degree 3 is exact), J = 12 L**2 / T**3; at T/2, x = L/2 by symmetry."""


def _two_phases(durations: tuple[float, float], intervals: int) -> dict:
    return {
        "kind": "multiphase_optimal_control",
        "name": "rest_to_rest_two_phases",
        "problem": {
            **copy.deepcopy(REST_TO_REST),
            "phases": [
                {"name": "first", "duration": durations[0]},
                {"name": "second", "duration": durations[1]},
            ],
        },
        "method": {"intervals": intervals, "degree": 3},
    }


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_fixed_switch_gives_the_single_phase_optimum(backend: str) -> None:
    two = gamespec.solve(spec_from_dict(_two_phases((1.0, 1.0), 4)), backend=backend)
    problem = copy.deepcopy(REST_TO_REST) | {"time": {"final": 2.0}}
    one_spec = {
        "kind": "optimal_control",
        "name": "rest_to_rest",
        "problem": problem,
        "method": {"intervals": 8},
    }
    one = gamespec.solve(spec_from_dict(one_spec), backend=backend)
    assert two.ok and one.ok
    assert two.objective == pytest.approx(one.objective, rel=IPOPT_LEVEL)
    assert two.objective == pytest.approx(12.0 / 2.0**3, rel=IPOPT_LEVEL)
    assert [p["end"] for p in two.metrics["phases"]] == pytest.approx([1.0, 2.0])
    boundary = np.flatnonzero(np.diff(two.arrays["phase"]))[0]
    assert two.states["x"][boundary] == pytest.approx(0.5, abs=IPOPT_LEVEL)
    assert two.states["x"][boundary + 1] == pytest.approx(two.states["x"][boundary], abs=IPOPT_LEVEL)
    assert np.interp(1.0, one.time, one.states["x"]) == pytest.approx(0.5, abs=IPOPT_LEVEL)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_free_switching_time_is_found_at_its_closed_form(backend: str) -> None:
    result = gamespec.solve(gamespec.load(TWO_PHASES), backend=backend)
    x0 = gamespec.load(TWO_PHASES).problem.parameters["x0"]
    assert result.ok
    switch, end = (p["end"] for p in result.metrics["phases"])
    assert switch == pytest.approx(math.sqrt(x0), rel=IPOPT_LEVEL)
    assert end == pytest.approx(2.0 * math.sqrt(x0), rel=IPOPT_LEVEL)
    assert result.t_final == pytest.approx(end)
    single = gamespec.solve(gamespec.load(ONE_PHASE, [f"problem.parameters.x0={x0}"]), backend=backend)
    assert single.t_final == pytest.approx(end, rel=IPOPT_LEVEL)
    for phase in ("accelerate", "brake"):
        assert result.checks[f"hamiltonian_end_error/{phase}"] < IPOPT_LEVEL
        assert result.checks[f"hamiltonian_variation/{phase}"] < IPOPT_LEVEL
        assert result.checks[f"max_defect/{phase}"] < IPOPT_LEVEL
    assert all(result.metrics["checks_passed"].values())


def _tsiolkovsky(p: dict) -> tuple[float, float, float]:
    """Final speed and the two burn times of the two-stage rocket at full throttle."""
    m1 = p["m0"] - p["fuel1"]
    m2 = m1 - p["structure1"]
    burn1, burn2 = p["fuel1"] / p["beta"], p["fuel2"] / p["beta"]
    v = p["c"] * math.log(p["m0"] / m1) + p["c"] * math.log(m2 / (m2 - p["fuel2"])) - p["g"] * (burn1 + burn2)
    return v, burn1, burn2


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_staged_rocket_drops_its_structure_and_meets_tsiolkovsky(backend: str) -> None:
    spec = gamespec.load(ROCKET)
    p = spec.problem.parameters
    result = gamespec.solve(spec, backend=backend)
    v, burn1, burn2 = _tsiolkovsky(p)
    assert result.ok
    assert result.objective == pytest.approx(v, rel=1e-5)
    assert [ph["duration"] for ph in result.metrics["phases"]] == pytest.approx([burn1, burn2], rel=1e-5)
    boundary = np.flatnonzero(np.diff(result.arrays["phase"]))[0]
    m = result.states["m"]
    assert m[boundary] - m[boundary + 1] == pytest.approx(p["structure1"], abs=IPOPT_LEVEL)
    assert result.checks["max_constraint_violation"] < IPOPT_LEVEL


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_phase_may_have_no_control(backend: str) -> None:
    """Push with u on [0, 1], coast on [1, 2], reach x = 1 at t = 2: x(1) + v(1) = 1, so u = k(2 - t)
    with k = 3/7 and J = integral of u**2 = 3/7."""
    data = _two_phases((1.0, 1.0), 4)
    data["problem"]["states"]["x"]["final"] = 1.0
    data["problem"]["states"]["v"].pop("final")
    data["problem"]["phases"][1] |= {"controls": {}, "dynamics": {"v": 0}, "lagrange": 0}
    result = gamespec.solve(spec_from_dict(data), backend=backend)
    assert result.ok
    assert result.objective == pytest.approx(3.0 / 7.0, rel=IPOPT_LEVEL)
    coasting = result.arrays["control_phase"] == 1
    assert np.all(np.isnan(result.controls["u"][coasting]))
    assert result.controls["u"][~coasting] == pytest.approx(
        3.0 / 7.0 * (2.0 - result.control_time[~coasting]), abs=1e-5
    )
    assert "control_swings/u/first" in result.checks and "control_swings/u/second" not in result.checks


def test_fixed_durations_are_parameters_of_the_compiled_model() -> None:
    data = _two_phases((1.0, "T2"), 4)
    data["problem"]["parameters"]["T2"] = 1.0
    solver = gamespec.compile_spec(spec_from_dict(data))
    longer = solver.solve(parameters={"T2": 3.0})
    assert longer.ok
    assert longer.t_final == pytest.approx(4.0)
    assert longer.objective == pytest.approx(12.0 / 4.0**3, rel=IPOPT_LEVEL)


def test_the_result_saves_plots_and_shows_the_lowered_problem(tmp_path, cli) -> None:
    result = gamespec.solve(gamespec.load(ROCKET, ["method.intervals=4"]))
    back = Result.load(result.save(tmp_path / "run"))
    assert back.metrics["phases"] == result.metrics["phases"]
    assert len(back.states["m"]) == len(back.time) == len(back.arrays["phase"])
    code, out, _ = cli("plot", str(tmp_path / "run"))
    assert code == 0 and (tmp_path / "run" / "two_stage_rocket_time.png").exists()
    lowered = transformed(gamespec.load(ROCKET))
    assert set(lowered.problem.design) == {"duration__stage1", "duration__stage2"}
    jumps = [c for c in lowered.problem.boundary_constraints if "m__stage2_0" in c]
    assert len(jumps) == 1 and "structure1" in jumps[0] and "m__stage1_f" in jumps[0]
    code, out, _ = cli("show", str(ROCKET), "--transformed")
    assert code == 0 and "duration__stage1" in out


def _rocket() -> dict:
    return yaml.safe_load(ROCKET.read_text())


def _edit_jump_first(d: dict) -> None:
    d["problem"]["phases"][0]["jump"] = {"m": "m_f"}


def _edit_no_dynamics(d: dict) -> None:
    d["problem"]["dynamics"].pop("h")


def _edit_undeclared(d: dict) -> None:
    d["problem"]["phases"][1]["states"]["mass"] = {"lower": 0.0}


def _edit_bad_jump(d: dict) -> None:
    d["problem"]["phases"][1]["jump"] = {"m": "m_f - drop"}


def _edit_separator(d: dict) -> None:
    d["problem"]["parameters"]["fuel__1"] = 1.0


def _edit_free_without_bounds(d: dict) -> None:
    d["problem"]["phases"][0]["duration"] = "free"


@pytest.mark.parametrize(
    ("edit", "needles"),
    [
        (_edit_jump_first, ["problem.phases.0.jump", "no phase before"]),
        (_edit_no_dynamics, ["problem.phases.0.dynamics", "no dynamics for state 'h'"]),
        (_edit_undeclared, ["problem.phases.1", "undeclared states ['mass']"]),
        (_edit_bad_jump, ["problem.phases.1.jump.m", "undefined symbol 'drop'"]),
        (_edit_separator, ["problem", "fuel__1"]),
        (_edit_free_without_bounds, ["problem.phases.0.duration", "bounds"]),
    ],
)
def test_bad_phases_are_one_line_naming_the_field(cli, tmp_path, edit, needles) -> None:
    data = _rocket()
    edit(data)
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump(data))
    code, _, err = cli("validate", str(path))
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])


@pytest.mark.parametrize("backend", BACKENDS)
def test_each_phase_runs_on_its_own_time(backend: str) -> None:
    """dx/dt = t over phases [0, 1] and [1, 3] (t the real time in each): x(3) = 9/2; dx/dt = 1 in a
    first phase of free duration bounded by t_f = 2 at its end (a phase boundary constraint)."""
    phases = [{"name": "a", "duration": 1.0}, {"name": "b", "duration": 2.0}]
    data = {
        "kind": "multiphase_optimal_control",
        "problem": {
            "states": {"x": {"initial": 0.0}},
            "dynamics": {"x": "t"},
            "objective": {"mayer": "x_f"},
            "phases": phases,
        },
        "method": {"intervals": 2},
    }
    result = gamespec.solve(spec_from_dict(data), backend=backend)
    assert result.ok and result.objective == pytest.approx(4.5, rel=IPOPT_LEVEL)
    assert result.states["x"] == pytest.approx(result.time**2 / 2, abs=IPOPT_LEVEL)
    data["problem"]["dynamics"] = {"x": 1}
    data["problem"]["phases"][0] = {
        "name": "a",
        "duration": {"value": "free", "bounds": [0.1, 5.0]},
        "boundary_constraints": ["t_f == 2"],
    }
    result = gamespec.solve(spec_from_dict(data), backend=backend)
    assert result.metrics["phases"][0]["end"] == pytest.approx(2.0, rel=IPOPT_LEVEL)
    assert "hamiltonian_end_error/a" not in result.checks


def test_mesh_refinement_refines_the_phases_to_the_tolerance() -> None:
    tolerance = 1e-8
    spec = gamespec.load(ROCKET, ["method.intervals=3", f"method.refine={{tolerance: {tolerance}}}"])
    result = gamespec.solve(spec)
    history = [entry["max_defect_relative"] for entry in result.metrics["refinement"]]
    assert result.metrics["refinement_converged"] and history[-1] <= tolerance < history[0]
    assert all(result.checks[f"max_defect_relative/{p}"] <= tolerance for p in ("stage1", "stage2"))
    assert len(result.time) == 2 * (3 * result.metrics["refinement"][-1]["intervals"] + 1)


@pytest.mark.parametrize("backend", BACKENDS)
def test_an_integral_constraint_runs_over_every_phase(backend: str) -> None:
    """integral of x dt = A over the horizon, in two phases as in one (the same discretization)."""
    constraint = [{"integrand": "x", "lower": 0.8, "upper": 0.8}]
    data = _two_phases((1.0, 1.0), 4)
    data["problem"]["integral_constraints"] = constraint
    two = gamespec.solve(spec_from_dict(data), backend=backend)
    problem = copy.deepcopy(REST_TO_REST) | {"time": {"final": 2.0}, "integral_constraints": constraint}
    one_spec = {"kind": "optimal_control", "name": "one", "problem": problem, "method": {"intervals": 8}}
    one = gamespec.solve(spec_from_dict(one_spec), backend=backend)
    assert two.ok and one.ok
    assert two.objective == pytest.approx(one.objective, rel=IPOPT_LEVEL)
    assert two.objective > 12.0 / 2.0**3


def test_each_stage_hamiltonian_tends_to_its_transversality_value() -> None:
    """The Mayer term v_f does not depend on t_f, so H = 0 on each stage of free duration; the
    costate estimates of LGR collocation converge at least at second order in h (degree 3)."""
    errors = []
    for intervals in (10, 40):
        result = gamespec.solve(gamespec.load(ROCKET, [f"method.intervals={intervals}"]))
        errors.append([result.checks[f"hamiltonian_end_error/{p}"] for p in ("stage1", "stage2")])
    coarse, fine = np.array(errors)
    assert np.all(fine < coarse / 4.0**2)


@pytest.mark.parametrize("backend", BACKENDS)
def test_three_arcs_switch_at_their_closed_form(backend: str) -> None:
    """Minimum time from rest at x0 to rest at 0 with |v| <= vmax: full thrust, a cruise on the
    constraint |v| = vmax, full braking: a free arc, a constrained arc and a last arc, the structure
    of the relay's arcs in §2.5 (Proposition 3, switching times tau_1, tau_2). Switches at vmax and
    t_f - vmax, t_f = 2 vmax + (x0 - vmax**2) / vmax."""
    x0, vmax = 2.0, 0.9
    free = {"value": "free", "bounds": [0.01, 10.0], "guess": 1.0}
    data = {
        "kind": "multiphase_optimal_control",
        "problem": {
            "parameters": {"x0": x0, "vmax": vmax},
            "states": {
                "x": {"initial": "x0", "final": 0.0},
                "v": {"initial": 0.0, "final": 0.0, "lower": "-vmax"},
            },
            "dynamics": {"x": "v"},
            "objective": {"mayer": "t_f"},
            "phases": [
                {"name": "accelerate", "duration": free, "dynamics": {"v": -1}},
                {"name": "cruise", "duration": free, "dynamics": {"v": 0}},
                {"name": "brake", "duration": free, "dynamics": {"v": 1}},
            ],
        },
        "method": {"intervals": 4},
    }
    result = gamespec.solve(spec_from_dict(data), backend=backend)
    t_f = 2 * vmax + (x0 - vmax**2) / vmax
    assert result.ok
    assert [p["end"] for p in result.metrics["phases"]] == pytest.approx(
        [vmax, t_f - vmax, t_f], rel=IPOPT_LEVEL
    )


@pytest.mark.parametrize("backend", BACKENDS)
def test_phases_with_their_own_intervals_match_the_single_phase_mesh(backend: str) -> None:
    """Phases of 2 and 6 intervals discretize as one phase on the mesh with 2 intervals on [0, 1]
    and 6 on [1, 2] (the dynamics are nonlinear, so the discretization error shows in the
    optimum unless the meshes are the same)."""
    problem = {
        "states": {"x": {"initial": 1.0}},
        "controls": {"u": {}},
        "dynamics": {"x": "-x**3 + u"},
        "objective": {"lagrange": "x**2 + u**2"},
    }
    phases = [
        {"name": "coarse", "duration": 1.0, "intervals": 2},
        {"name": "fine", "duration": 1.0, "intervals": 6},
    ]
    two_spec = {"kind": "multiphase_optimal_control", "problem": problem | {"phases": phases}}
    two = gamespec.solve(spec_from_dict(two_spec), backend=backend)
    mesh = [*np.linspace(0.0, 0.5, 3)[:-1], *np.linspace(0.5, 1.0, 7)]
    one_spec = {
        "kind": "optimal_control",
        "problem": problem | {"time": {"final": 2.0}},
        "method": {"mesh": [float(b) for b in mesh]},
    }
    one = gamespec.solve(spec_from_dict(one_spec), backend=backend)
    uniform = gamespec.solve(spec_from_dict(one_spec | {"method": {"intervals": 8}}), backend=backend)
    assert two.ok and one.ok
    assert two.objective == pytest.approx(one.objective, rel=IPOPT_LEVEL * 1e-2)
    assert abs(uniform.objective - one.objective) > 1e2 * abs(two.objective - one.objective)
    assert np.bincount(two.arrays["phase"]).tolist() == [2 * 3 + 1, 6 * 3 + 1]
    assert two.states["x"] == pytest.approx(np.interp(two.time, one.time, one.states["x"]), abs=1e-7)


def _three_phases(**extra: object) -> dict:
    data = _two_phases((1.0, 1.0), 4)
    data["problem"]["phases"].insert(1, {"name": "middle", "duration": 1.0, "intervals": 2})
    data["problem"]["phases"][0]["intervals"] = 4
    data["problem"]["phases"][2]["intervals"] = 4
    data["problem"].update(extra)
    return data


def test_phases_are_linked_by_name_as_by_their_own_constraints() -> None:
    """``phases.<phase>.x_f`` in the problem's boundary constraints (issue 25, item 3): the
    distance covered in the middle phase written over the first phase's end and the last one's
    start equals the middle phase's own ``x_f - x_0 == 0.3``; the link holds in the solution."""
    linked = _three_phases(boundary_constraints=["phases.last_one.x_0 - phases.first.x_f == 0.3"])
    linked["problem"]["phases"][2]["name"] = "last_one"
    own = _three_phases()
    own["problem"]["phases"][1]["boundary_constraints"] = ["x_f - x_0 == 0.3"]
    one, two = gamespec.solve(spec_from_dict(linked)), gamespec.solve(spec_from_dict(own))
    assert one.ok and two.ok
    assert one.objective == pytest.approx(two.objective, rel=1e-9)
    phase = one.arrays["phase"]
    x = one.states["x"]
    assert x[phase == 2][0] - x[phase == 0][-1] == pytest.approx(0.3, abs=1e-8)
    assert one.objective > 12.0 / 3.0**3 * (1 + 1e-3)


def test_a_phase_link_names_a_declared_phase() -> None:
    data = _three_phases(boundary_constraints=["phases.nowhere.x_f == 0"])
    with pytest.raises(gamespec.SpecError, match=r"phases\.nowhere\.x_f"):
        spec_from_dict(data)


def test_a_definition_may_belong_to_some_phases_only() -> None:
    """The same phase-only definition in two phases is each phase's own (it was refused as a
    name used twice); it equals the shared definition."""
    shared = _two_phases((1.0, 1.0), 4)
    shared["problem"]["definitions"] = {"w": "u**2"}
    shared["problem"]["objective"] = {"lagrange": "w"}
    own = copy.deepcopy(shared)
    del own["problem"]["definitions"]
    own["problem"]["objective"] = {"lagrange": 0}
    for phase in own["problem"]["phases"]:
        phase["definitions"] = {"w": "u**2"}
        phase["lagrange"] = "w"
    one, two = gamespec.solve(spec_from_dict(shared)), gamespec.solve(spec_from_dict(own))
    assert one.ok and two.ok
    assert one.objective == pytest.approx(two.objective, rel=1e-10)
