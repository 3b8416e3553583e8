"""The ``lq_stochastic_game`` kind: matrices from numbers and expressions, per-step and continuous
models, and bad input stopped with the field that holds it."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from gamespec import SpecError, spec_from_dict
from gamespec.specs.lq_model import zero_order_hold


def _data(**problem_updates) -> dict:
    problem = {
        "parameters": {"dt": 0.5, "k": 2.0},
        "horizon": 3,
        "discrete": {
            "A": [[1, "dt"], [0, 1]],
            "B": [["dt**2 / 2"], ["dt"]],
            "C": [[0], ["-dt"]],
            "D": {"identity": 0.1},
        },
        "cost": {"Q": {"identity": 1}, "R": [[1]], "S": [["10 * k"]]},
        "initial": {"mean": [1, 0], "covariance": {"diag": [0.1, "0.05 * k"]}},
    }
    problem.update(problem_updates)
    return {"kind": "lq_stochastic_game", "problem": problem}


def test_expressions_are_evaluated_with_the_parameters():
    spec = spec_from_dict(_data())
    game = spec.game()
    np.testing.assert_allclose(game.A[0], [[1, 0.5], [0, 1]])
    np.testing.assert_allclose(game.B[2], [[0.125], [0.5]])
    np.testing.assert_allclose(game.S[1], [[20.0]])
    np.testing.assert_allclose(game.D[0], 0.1 * np.eye(2))
    np.testing.assert_allclose(game.Sigma0, np.diag([0.1, 0.1]))
    np.testing.assert_allclose(spec.game({"dt": 1.0}).A[0], [[1, 1], [0, 1]])
    assert spec.state_names == ["x1", "x2"]


def test_a_terminal_covariance_requires_the_covariance_constraint():
    """Only a backend that enforces eq. 4.62 may take a file with ``terminal.covariance``."""
    assert spec_from_dict(_data()).required_features() == {"mean_steering"}
    assert spec_from_dict(_data(terminal={"mean": [0, 0]})).required_features() == {"mean_steering"}
    constrained = spec_from_dict(_data(terminal={"covariance": {"identity": 0.5}}))
    assert constrained.required_features() == {"mean_steering", "covariance_constraint"}


def test_per_step_matrices():
    data = _data()
    data["problem"]["cost"]["R"] = {"per_step": [[[1]], [[2]], [["3 * k"]]]}
    game = spec_from_dict(data).game()
    np.testing.assert_allclose(game.R[:, 0, 0], [1, 2, 6])


def test_continuous_model_is_held_over_the_step():
    data = _data(
        discrete=None,
        continuous={
            "A": [[0, 1], [0, "-k"]],
            "B": [[0], [1]],
            "C": [[0], [-1]],
            "noise": [[0], ["k / 10"]],
            "step": "dt",
        },
    )
    del data["problem"]["discrete"]
    game = spec_from_dict(data).game()
    A, (B, C, D) = zero_order_hold(
        np.array([[0, 1], [0, -2.0]]), [np.eye(2)[:, 1:], -np.eye(2)[:, 1:], 0.2 * np.eye(2)[:, 1:]], 0.5
    )
    np.testing.assert_allclose(game.A[0], A)
    np.testing.assert_allclose(game.B[0], B)
    np.testing.assert_allclose(game.C[0], C)
    np.testing.assert_allclose(game.D[0], D)
    assert game.dt == 0.5


def test_null_terminal_mean_entries_are_free():
    data = _data(terminal={"mean": [0, None], "covariance": {"identity": 0.5}})
    spec = spec_from_dict(data)
    game = spec.game()
    assert game.muN[0] == 0 and np.isnan(game.muN[1])
    np.testing.assert_allclose(game.SigmaN, 0.5 * np.eye(2))


@pytest.mark.parametrize(
    ("update", "field", "reason"),
    [
        ({"cost": {"Q": {"identity": 1}, "R": [[1, 0]], "S": [[1]]}}, "problem.cost.R", "expected 1×1"),
        ({"cost": {"Q": {"identity": 1}, "R": [[0]], "S": [[1]]}}, "problem.cost.R", "positive definite"),
        (
            {"cost": {"Q": {"identity": 1}, "R": [["q"]], "S": [[1]]}},
            "problem.cost.R.0.0",
            "undefined symbol",
        ),
        ({"cost": {"Q": {"identity": 1}, "R": [["__import__('os')"]], "S": [[1]]}}, "problem.cost.R.0.0", ""),
        (
            {"initial": {"mean": [1, 0], "covariance": [[1, 2], [2, 1]]}},
            "problem.initial.covariance",
            "semidefinite",
        ),
        ({"terminal": {"mean": [0]}}, "problem.terminal.mean", "expected 2"),
        (
            {"initial": {"mean": [1, 0], "covariance": {"diagonal": [1, 1]}}},
            "problem.initial.covariance",
            "a matrix is a list of rows",
        ),
        ({"states": ["x", "x"]}, "problem.states", "repeated: x"),
        (
            {"states": ["a", "b", "c"]},
            "problem.initial.mean",
            "expected 3 entries (one per name in problem.states), got 2",
        ),
        ({"terminal": {"covariance": {"diag": [1, 0]}}}, "problem.terminal.covariance", "positive definite"),
        (
            {"continuous": {"A": [[0]], "B": [[0]], "C": [[0]], "noise": [[0]], "step": 1}},
            "problem",
            "exactly one",
        ),
    ],
)
def test_bad_input_names_the_field(update: dict, field: str, reason: str):
    with pytest.raises(SpecError) as err:
        spec_from_dict(_data(**update))
    assert err.value.field == field
    assert reason in err.value.reason


def test_per_step_length_is_checked():
    data = _data()
    data["problem"]["discrete"]["A"] = {"per_step": [[[1, 0], [0, 1]]]}
    with pytest.raises(SpecError) as err:
        spec_from_dict(data)
    assert "3 matrices" in err.value.reason


NAN, INF = float("nan"), float("inf")


@pytest.mark.parametrize(
    ("location", "value"),
    [
        (("discrete", "A", 0, 1), NAN),
        (("discrete", "B", 1, 0), INF),
        (("cost", "S", 0, 0), -INF),
        (("cost", "Q", "identity"), NAN),
        (("initial", "mean", 0), NAN),
        (("initial", "covariance", "diag", 1), INF),
        (("parameters", "dt"), NAN),
    ],
)
def test_non_finite_numbers_are_refused_with_the_field(location: tuple, value: float):
    """NaN and ±inf are not numbers a matrix, mean, covariance or parameter may hold (the one finite
    ``Value``/``Number`` of :mod:`gamespec.specs.base`); the error names the entry."""
    data = _data()
    slot = data["problem"]
    for key in location[:-1]:
        slot = slot[key]
    slot[location[-1]] = value
    with pytest.raises(SpecError) as err:
        spec_from_dict(data)
    dotted = ".".join(str(k) for k in ("problem", *location))
    assert err.value.field.startswith(dotted), err.value.field
    assert "finite" in err.value.reason


def test_a_terminal_covariance_entry_read_as_nan_from_yaml_is_refused(cli, tmp_path):
    """YAML's ``.nan`` and ``.inf`` in a file: exit 2 and one line naming the field."""
    text = yaml.safe_dump(_data(terminal={"mean": [0, 0], "covariance": {"diag": [1, 1]}}))
    path = tmp_path / "nan.yaml"
    path.write_text(text.replace("- 1\n      - 1\n", "- .nan\n      - 1\n", 1))
    assert ".nan" in path.read_text()
    code, _, err = cli("validate", path)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "problem.terminal.covariance.diag.0" in err
