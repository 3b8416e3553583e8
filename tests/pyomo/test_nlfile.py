"""The NL file written once per compiled model (:mod:`gamespec_pyomo.nlfile`): after new parameter
values, bounds and starts its text is exactly what Pyomo's NL writer writes for the model as it then
stands, and a re-solve through it is a solve of a model compiled for the new values."""

from __future__ import annotations

import copy
import io

import pytest
from gamespec_pyomo.nlfile import WRITER_CONFIG
from pyomo.repn.plugins.nl_writer import NLWriter

import gamespec
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS
from tests.pyomo.cases import CONSTRAINED

MIN_TIME = PROBLEMS / "ch6" / "zermelo_min_time.yaml"
CASES = {
    "constrained": (gamespec.spec_from_dict(CONSTRAINED), {"vmax": 1.5, "tf": 2.0}),
    "zermelo_min_time": (gamespec.load(MIN_TIME), {"rho": 5.0, "xf": 2.5}),
}
"""A fixed final time given by a parameter, and a free final time with parameters in the dynamics
and in an end bound: each with new values for every parameter."""


def _fresh_write(model) -> str:
    stream = io.StringIO()
    NLWriter().write(model, stream, None, None, **WRITER_CONFIG)
    return stream.getvalue()


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_rewritten_file_is_a_fresh_write(case: str) -> None:
    spec, parameters = CASES[case]
    compiled = compile_spec(spec, "pyomo").compiled
    before = compiled.nl.text()
    assert before == _fresh_write(compiled.model)
    result = compiled.solve(parameters=parameters)
    assert result.ok
    after = compiled.nl.text()
    assert after != before
    assert after == _fresh_write(compiled.model)


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_resolve_for_new_parameters_is_the_solve_of_a_model_built_for_them(case: str) -> None:
    """The same NL text from the same start: the same iterations and optimum (to 1e-10, room for a
    threaded solver's summation order)."""
    spec, parameters = CASES[case]
    resolved = compile_spec(spec, "pyomo", {"warm_start": False})
    resolved.solve()
    again = resolved.solve(parameters=parameters)
    data = copy.deepcopy(spec.model_dump(mode="json", by_alias=True, exclude_none=True))
    data["problem"]["parameters"] |= parameters
    built = gamespec.solve(gamespec.spec_from_dict(data), "pyomo")
    assert again.ok and built.ok
    assert again.objective == pytest.approx(built.objective, rel=1e-10)
    assert again.iterations == built.iterations
