"""Fuzzing the bad-input promise: every input ends in exit 0, exit 1 with a status, or exit 2 with
one line naming the file (or ``--set``), within the time bound (see :mod:`tests.fuzz.harness`)."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from gamespec import registry
from tests.fuzz.harness import check
from tests.fuzz.strategies import (
    SHIPPED,
    dumped,
    mutated_bytes,
    mutated_documents,
    schema_documents,
    values,
    write,
)

KINDS = registry.names("gamespec.kinds")
COMMANDS = st.sampled_from(["validate", "show"])


def _check_file(command: str, stem: str, suffix: str, content: str | bytes, *extra: str) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = write(Path(folder), stem, suffix, content)
        check([command, path, *extra], str(path), "--set")


@pytest.mark.parametrize("kind", KINDS)
@given(data=st.data(), fmt=st.sampled_from(["yaml", "json"]), command=COMMANDS)
def test_documents_from_the_schema(kind: str, data: st.DataObject, fmt: str, command: str) -> None:
    document = data.draw(schema_documents(kind))
    _check_file(command, kind, f".{fmt}", dumped(document, fmt))


@given(mutant=mutated_documents(), fmt=st.sampled_from(["yaml", "json"]), command=COMMANDS)
def test_mutations_of_the_shipped_files(mutant: tuple[str, object], fmt: str, command: str) -> None:
    stem, document = mutant
    _check_file(command, stem, f".{fmt}", dumped(document, fmt))


@given(raw=mutated_bytes(), suffix=st.sampled_from([".yaml", ".json", ".toml"]))
def test_byte_edits_of_the_shipped_files(raw: bytes, suffix: str) -> None:
    _check_file("validate", "edited", suffix, raw)


@given(
    raw=st.one_of(st.binary(max_size=400), st.text(max_size=400)),
    suffix=st.sampled_from([".yaml", ".json", ".toml"]),
)
def test_raw_bytes_and_text(raw: bytes | str, suffix: str) -> None:
    _check_file("validate", "raw", suffix, raw)


@given(
    target=st.sampled_from(SHIPPED),
    key=st.one_of(
        st.sampled_from(
            [
                "problem.parameters.rho",
                "problem.parameters.rhoo",
                "method.intervals",
                "pursuers",
                "pursuers.0.speed",
                "pursuers[1].speed",
                "solver.options.casadi.max_iter",
                "solver.options.casadi.ipopt",
                "solver.options.nosuch.x",
                "horizon",
                "kind",
                "",
                "a..b",
                ".",
            ]
        ),
        st.text(max_size=20),
    ),
    value=values,
)
def test_set_assignments(target: Path, key: str, value: object) -> None:
    text = dumped(value, "json").strip()
    check(["validate", target, "--set", f"{key}={text}"], str(target), "--set")
