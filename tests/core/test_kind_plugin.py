"""A kind is one plugin (issue 24, item 5): one ``gamespec.kinds`` entry point per kind returns a
:class:`~gamespec.registry.Kind` whose parts (spec model, default backend or study, plotter, summary,
metrics schema) all resolve; a transform owns its figures and summary rows, found by the names in
``Result.provenance.transforms``, not by the keys a Result's metrics happen to hold; a study kind is
run by a ``gamespec.studies`` plugin, which no backend poses as."""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest

import gamespec
from gamespec import registry
from gamespec.compiling.study_protocol import Study
from gamespec.errors import BackendError, UnsupportedFeature
from gamespec.metrics import Metrics, metrics_model
from gamespec.plotting import plot_result
from gamespec.result import Provenance, Result, Status
from gamespec.solving import compile_spec
from gamespec.specs.base import SpecBase
from gamespec.summaries import outcome
from gamespec.transforms.base import OcpRewrite
from tests.conftest import PROBLEMS


@pytest.mark.parametrize("name", registry.names("gamespec.kinds"))
def test_each_kind_is_one_entry_point_whose_parts_resolve(name: str) -> None:
    kind = registry.kind(name)
    spec = kind.part("spec")
    assert issubclass(spec, SpecBase) and spec.model_fields["kind"].default == name
    runner = kind.default_backend or kind.study
    group = "gamespec.backends" if kind.default_backend else "gamespec.studies"
    assert runner in registry.names(group)
    assert callable(kind.part("plot")) and callable(kind.part("summary"))
    assert issubclass(metrics_model(name), Metrics)


def test_a_kind_names_a_backend_or_a_study_not_both() -> None:
    with pytest.raises(BackendError):
        registry.Kind(SpecBase, default_backend="casadi", study="study")
    with pytest.raises(BackendError):
        registry.Kind(SpecBase)


def _marked(result: Result, output_dir: Path) -> list[Path]:
    path = output_dir / "marked.txt"
    path.write_text(str(result.metrics["mark"]))
    return [path]


class Marking(OcpRewrite):
    """A transform that adds ``metrics["mark"]`` and owns the figure and the row that show it."""

    name: ClassVar[str] = "marking"
    plot: ClassVar[object] = _marked
    summary: ClassVar[object] = lambda result: [("mark", result.metrics["mark"])]

    def apply(self, spec, options, upstream=None):
        return spec, None


@pytest.fixture
def marking():
    saved = dict(registry._IN_PROCESS["gamespec.transforms"])
    registry.register("gamespec.transforms", Marking.name, Marking)
    yield
    registry._IN_PROCESS["gamespec.transforms"] = saved
    registry.load.cache_clear()


def _ocp_result(transforms: list[str]) -> Result:
    t = np.linspace(0.0, 1.0, 5)
    return Result(
        status=Status.OPTIMAL,
        kind="optimal_control",
        problem="marked",
        backend="casadi",
        objective=1.0,
        time=t,
        states={"x": t},
        metrics={"mark": 7},
        provenance=Provenance(transforms=transforms),
    )


def test_a_transform_s_figure_and_rows_follow_the_kind_s_only_when_it_ran(marking, tmp_path: Path) -> None:
    ran = _ocp_result(["marking"])
    written = plot_result(ran, tmp_path / "ran")
    assert written[-1].name == "marked.txt" and written[-1].read_text() == "7"
    assert ("mark", 7) in outcome(ran)
    not_ran = _ocp_result([])
    assert "marked.txt" not in [p.name for p in plot_result(not_ran, tmp_path / "not")]
    assert ("mark", 7) not in outcome(not_ran)


@pytest.mark.parametrize("name", registry.names("gamespec.studies"))
def test_a_study_is_a_study_plugin_not_a_backend(name: str) -> None:
    study = registry.load("gamespec.studies", name)
    assert isinstance(study(), Study) and name not in registry.names("gamespec.backends")
    assert all(registry.kind(kind).study == name for kind in study.kinds)


def test_a_study_kind_is_refused_by_a_backend_with_the_reason() -> None:
    spec = gamespec.load(PROBLEMS / "ch2" / "pure_pursuit_suboptimal_study.yaml")
    with pytest.raises(UnsupportedFeature, match="is a study, run by a study plugin"):
        compile_spec(spec, "casadi")
