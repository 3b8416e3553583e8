"""Shared fixtures: paths of the shipped problem files and a CLI runner."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "problems"


@pytest.fixture
def cli(capsys):
    """Run ``gamespec ARGS`` in-process; returns (exit code, stdout, stderr)."""
    from gamespec.cli import run

    def invoke(*args: str) -> tuple[int, str, str]:
        code = run([str(a) for a in args])
        captured = capsys.readouterr()
        return code, captured.out, captured.err

    return invoke
