"""The solving chain: requested transforms from files, staged transforms, runtime parameters
through the chain (a re-solve equals a fresh solve), and refusals that name the field."""

from __future__ import annotations

from importlib.metadata import EntryPoint

import pytest
import yaml

import gamespec
from gamespec import registry
from gamespec.errors import SpecError, UnsupportedFeature
from gamespec.loader import spec_from_dict
from gamespec.solving import transformed
from tests.conftest import PROBLEMS

MAX_RANGE = PROBLEMS / "ch6" / "zermelo_max_range.yaml"
MIN_TIME = PROBLEMS / "ch6" / "zermelo_min_time.yaml"
TEST_TRANSFORMS = {
    "weighted_lagrange": "WeightedLagrange",
    "fix_upstream_final_time": "FixUpstreamFinalTime",
}
WEIGHT_PATH = "transforms.0.weighted_lagrange.weight"


@pytest.fixture
def test_transforms(monkeypatch):
    """The transforms of :mod:`tests.core.chain_transforms` in the ``gamespec.transforms`` group."""
    real = registry._entry_points
    extra = {
        name: EntryPoint(name, f"tests.core.chain_transforms:{cls}", "gamespec.transforms")
        for name, cls in TEST_TRANSFORMS.items()
    }

    def patched(group: str) -> dict[str, EntryPoint]:
        return {**real(group), **extra} if group == "gamespec.transforms" else real(group)

    monkeypatch.setattr(registry, "_entry_points", patched)
    yield
    registry.load.cache_clear()


def _with_transforms(path, tmp_path, transforms) -> str:
    data = yaml.safe_load(path.read_text()) | {"transforms": transforms}
    out = tmp_path / path.name
    out.write_text(yaml.safe_dump(data))
    return str(out)


def test_requested_transform_resolves_like_fresh_solves(test_transforms, tmp_path) -> None:
    """A same-kind transform adds weight·∫(−u²) to max-range Zermelo; the weight (an option of the
    file's transforms section) is a runtime parameter of the compiled model: each re-solve equals a
    fresh solve of the file with that weight, and a larger weight gives a smaller objective."""
    file = _with_transforms(MAX_RANGE, tmp_path, [{"weighted_lagrange": {"term": "-u**2", "weight": 0.0}}])
    solver = gamespec.compile_spec(file)
    assert solver.target_spec.problem.parameters["lagrange_weight"] == 0.0
    objectives = []
    for weight in (0.0, 0.3, 1.0):
        again = solver.solve(parameters={WEIGHT_PATH: weight})
        fresh = gamespec.solve(gamespec.load(file, [f"{WEIGHT_PATH}={weight}"]))
        assert again.status == fresh.status == gamespec.Status.OPTIMAL
        assert again.objective == pytest.approx(fresh.objective, rel=1e-7)
        assert again.states["x1"][-1] == pytest.approx(fresh.states["x1"][-1], rel=1e-6)
        assert again.parameters == fresh.parameters == {"rho": 10.0}
        objectives.append(again.objective)
    assert objectives[0] > objectives[1] > objectives[2]
    plain = gamespec.solve(MAX_RANGE)
    assert objectives[0] == pytest.approx(plain.objective, rel=1e-7)


def test_weight_enters_the_compiled_model_as_the_envelope_theorem_says(test_transforms, tmp_path) -> None:
    """J*(w) = max x1(t_f) − w∫u²: by the envelope theorem dJ*/dw = −∫u² at the optimum, which the
    Result gives as (x1(t_f) − J*)/w. A central difference of re-solves over w must match it."""
    file = _with_transforms(MAX_RANGE, tmp_path, [{"weighted_lagrange": {"term": "-u**2", "weight": 0.5}}])
    solver = gamespec.compile_spec(file)
    weight, step = 0.5, 1e-3
    at = solver.solve()
    above, below = (solver.solve(parameters={WEIGHT_PATH: weight + d}) for d in (step, -step))
    slope = (above.objective - below.objective) / (2 * step)
    assert slope == pytest.approx(-(at.states["x1"][-1] - at.objective) / weight, rel=1e-3)
    assert slope < 0


def test_show_transformed_prints_what_the_backend_solves(test_transforms, tmp_path, cli) -> None:
    """The printed spec is the compiled target (requested, then no lowering for this kind) and
    solving it on its own gives the chain's answer."""
    file = _with_transforms(MAX_RANGE, tmp_path, [{"weighted_lagrange": {"term": "-u**2", "weight": 0.5}}])
    code, out, _ = cli("show", file, "--transformed")
    assert code == 0
    printed = yaml.safe_load(out)
    solver = gamespec.compile_spec(file)
    assert printed == solver.target_spec.model_dump(mode="json")
    assert printed["transforms"] == []
    assert printed["problem"]["parameters"]["lagrange_weight"] == 0.5
    alone = gamespec.solve(spec_from_dict(printed))
    assert alone.objective == pytest.approx(solver.solve().objective, rel=1e-9)


def test_staged_transform_gets_the_upstream_result_from_the_solving_layer(test_transforms, tmp_path) -> None:
    """The staged transform fixes t_f at the free-time optimum its upstream stage found: the fixed
    time problem then has the same solution; with a new rho, the upstream stage is re-solved too and
    the compiled model re-solves for the new t_f, equal to a fresh staged solve."""
    file = _with_transforms(MIN_TIME, tmp_path, [{"fix_upstream_final_time": {}}])
    solver = gamespec.compile_spec(file)
    assert not solver.target_spec.problem.time.free
    for rho in (10.0, 8.0):
        free = gamespec.solve(gamespec.load(MIN_TIME, [f"problem.parameters.rho={rho}"]))
        staged = solver.solve(parameters={"rho": rho})
        fresh = gamespec.solve(gamespec.load(file, [f"problem.parameters.rho={rho}"]))
        assert staged.status == gamespec.Status.OPTIMAL
        assert staged.t_final == pytest.approx(free.t_final, rel=1e-7)
        # At t_f = t_f* the fixed-time problem is feasible only just (a minimum-time path is the one
        # path that arrives then), so its states move like the square root of t_f's 1e-8 error.
        assert staged.states["x2"] == pytest.approx(free.states["x2"], abs=1e-3)
        assert staged.t_final == pytest.approx(fresh.t_final, rel=1e-7)


def test_a_transform_that_does_not_accept_the_spec_is_refused(test_transforms, tmp_path) -> None:
    """fix_upstream_final_time accepts free-final-time problems only (``Transform.accepts``)."""
    file = _with_transforms(MAX_RANGE, tmp_path, [{"fix_upstream_final_time": {}}])
    with pytest.raises(UnsupportedFeature, match="does not accept"):
        gamespec.compile_spec(file)


@pytest.mark.parametrize(
    ("entry", "field", "reason"),
    [
        (
            {"weighted_lagrang": {"term": "u", "weight": 1}},
            "transforms.0",
            "did you mean 'weighted_lagrange'",
        ),
        ({"weighted_lagrange": {"term": "u", "weight": -1}}, f"{WEIGHT_PATH}", "greater than or equal"),
        ({"weighted_lagrange": {"term": "u", "wieght": 1}}, "transforms.0.weighted_lagrange", "'weight'"),
        ({"engagement_to_ocp": {}}, "transforms.0", "cannot be requested"),
        ({"weighted_lagrange": {}, "fix_upstream_final_time": {}}, "transforms.0", "one transform"),
    ],
)
def test_bad_transforms_section_names_the_field(test_transforms, tmp_path, cli, entry, field, reason) -> None:
    file = _with_transforms(MAX_RANGE, tmp_path, [entry])
    with pytest.raises(SpecError, match=reason) as err:
        gamespec.load(file)
    assert err.value.field.startswith(field)
    code, _, stderr = cli("validate", file)
    assert code == 2
    assert len(stderr.strip().splitlines()) == 1
    assert field in stderr


def test_requested_transform_of_another_kind_is_refused(test_transforms, tmp_path) -> None:
    file = _with_transforms(
        PROBLEMS / "ch2" / "pure_pursuit_two_on_one.yaml", tmp_path, [{"fix_upstream_final_time": {}}]
    )
    with pytest.raises(SpecError, match="takes kind 'optimal_control', not 'engagement'"):
        gamespec.load(file)


def test_runtime_parameters_by_short_name_and_dotted_path() -> None:
    """``rho`` and ``problem.parameters.rho`` are the same parameter; a re-solve equals a fresh solve."""
    solver = gamespec.compile_spec(MAX_RANGE)
    short = solver.solve(parameters={"rho": 9.0})
    dotted = solver.solve(parameters={"problem.parameters.rho": 9.0})
    fresh = gamespec.solve(gamespec.load(MAX_RANGE, ["problem.parameters.rho=9"]))
    assert short.objective == pytest.approx(fresh.objective, rel=1e-7)
    assert dotted.objective == pytest.approx(fresh.objective, rel=1e-7)
    assert short.parameters == {"rho": 9.0}


def test_unknown_or_structural_runtime_parameter_is_refused() -> None:
    solver = gamespec.compile_spec(MAX_RANGE)
    with pytest.raises(SpecError, match=r"unknown parameter 'rh'.*did you mean 'rho'") as err:
        solver.solve(parameters={"rh": 2.0})
    assert err.value.field == "rh"
    with pytest.raises(SpecError, match=r"method\.intervals change") as err:
        solver.solve(parameters={"method.intervals": 10})
    assert err.value.field == "method.intervals"
    with pytest.raises(SpecError, match=r"problem\.states\.x2\.initial"):
        solver.solve(parameters={"problem.states.x2.initial": "nope"})
    with pytest.raises(SpecError, match=r"field guess\.controls\.u"):
        solver.solve(parameters={"guess.controls.u": 0.5})
    start = solver.solve()
    moved = solver.solve(parameters={"guess.controls.u": 0.5}, guess=start)
    assert moved.objective == pytest.approx(start.objective, rel=1e-9)


def test_transformed_spec_of_a_spec_without_transforms_is_itself() -> None:
    spec = gamespec.load(MAX_RANGE)
    assert transformed(spec) is spec
