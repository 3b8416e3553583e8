"""Bad desensitization input stops with the field and the reason (issue 10, item 1)."""

from __future__ import annotations

import copy

import pytest
import yaml

from gamespec.desensitize.spec import DesensitizeOptions
from gamespec.desensitize.transform import Desensitize
from gamespec.errors import SpecError
from gamespec.loader import spec_from_dict
from tests.desensitize.helpers import FINAL, TRAJECTORY


def _data(path=TRAJECTORY):
    data = yaml.safe_load(path.read_text())
    return data, data.pop("transforms")[0]["desensitize"]


@pytest.mark.parametrize(
    ("uncertain", "field", "reason"),
    [
        ({"beta": {"normal": {"std": 1.0}}}, "problem", "undeclared parameters: ['beta']"),
        ({"rho": {"uniform": {"percent": 5, "low": 1.0}}}, "problem.uncertain.rho.uniform", "not both"),
        ({"rho": {"uniform": {"low": 2.0, "high": 1.0}}}, "problem.uncertain.rho.uniform", "below high"),
        ({"rho": {}}, "problem.uncertain.rho", "exactly one"),
        ({"rho": {"normal": {"std": -1.0}}}, "problem.uncertain.rho.normal.std", "greater than 0"),
    ],
)
def test_bad_uncertain_section(uncertain, field, reason) -> None:
    data, _ = _data()
    data["problem"]["uncertain"] = uncertain
    with pytest.raises(SpecError) as err:
        spec_from_dict(data, "f.yaml")
    assert err.value.field == field
    assert reason in err.value.reason


@pytest.mark.parametrize(
    ("edit", "field", "reason"),
    [
        ({"trajectory": {"S_x3_rho": 1.0}}, "transforms.desensitize.trajectory.S_x3_rho", "unknown entry"),
        (
            {"trajectory": "alpha*beta"},
            "transforms.desensitize.trajectory.S_x1_rho",
            "undefined symbol 'beta'",
        ),
        ({"fixed": {"S_x9_rho": 0.0}}, "transforms.desensitize.fixed.S_x9_rho", "unknown entry"),
        ({"method": "costate", "final": 1.0}, "transforms.desensitize", "use trajectory"),
        ({"trajectory": None}, "transforms.desensitize", "at least one"),
    ],
)
def test_bad_request(edit, field, reason) -> None:
    data, request = _data()
    spec = spec_from_dict(data)
    options = DesensitizeOptions.model_validate({**request, **edit})
    with pytest.raises(SpecError) as err:
        Desensitize().apply(spec, options)
    assert err.value.field == field
    assert reason in err.value.reason


def test_no_uncertain_parameter_is_refused() -> None:
    data, request = _data(FINAL)
    del data["problem"]["uncertain"]
    with pytest.raises(SpecError, match="needs uncertain parameters"):
        Desensitize().apply(spec_from_dict(data), DesensitizeOptions.model_validate(request))


def test_taken_names_are_refused() -> None:
    data, request = _data()
    data = copy.deepcopy(data)
    data["problem"]["parameters"]["S_x1_rho"] = 1.0
    with pytest.raises(SpecError, match="taken"):
        Desensitize().apply(spec_from_dict(data), DesensitizeOptions.model_validate(request))
