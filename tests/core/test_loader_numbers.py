"""Numbers written without a dot in the exponent (``1e-8``) are numbers, in files and in ``--set``
(YAML 1.1 reads them as text; a raw solver option given as text is refused by IPOPT)."""

from __future__ import annotations

import pytest

import gamespec
from gamespec.reading import read_value
from tests.conftest import PROBLEMS


@pytest.mark.parametrize(("text", "value"), [("1e-8", 1e-8), ("-2E3", -2000.0), ("+3e0", 3.0), ("7", 7)])
def test_exponent_floats_are_numbers(text: str, value: float) -> None:
    assert read_value(text) == value and type(read_value(text)) is type(value)


def test_text_stays_text() -> None:
    assert read_value("e-8") == "e-8" and read_value("1e") == "1e"


def test_raw_ipopt_option_from_set_reaches_the_solver() -> None:
    spec = gamespec.load(PROBLEMS / "ch6" / "zermelo_min_time.yaml", ["solver.options.nlp.bound_push=1e-8"])
    assert spec.solver.options["nlp"]["bound_push"] == 1e-8
    assert gamespec.solve(spec).ok
