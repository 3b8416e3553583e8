"""Terminal conventions: no wrapping off a terminal, plain progress lines there, ``--quiet``."""

from __future__ import annotations

import subprocess
import sys

import pytest

from gamespec import terminal
from tests.conftest import PROBLEMS


def test_piped_output_is_not_wrapped_at_80_columns(tmp_path) -> None:
    """A summary and the 'saved to' line written to a pipe keep a long folder name on one line."""
    out = tmp_path / ("a_folder_name_long_enough_to_cross_eighty_columns_" * 2)
    entry = "from gamespec.cli import main; main()"
    command = [sys.executable, "-c", entry, "solve", str(PROBLEMS / "ocp" / "bryson_denham.yaml")]
    done = subprocess.run([*command, "--out", str(out)], capture_output=True, text=True, check=True)
    lines = done.stdout.splitlines()
    assert f"saved to {out}/" in lines
    assert any(len(line) > 80 for line in lines)
    table = [line for line in lines if line.startswith("│")]
    assert table and len({len(line) for line in table}) == 1, "the summary's rows are one table, unbroken"


def test_plain_progress_lines_off_a_terminal(monkeypatch, capsys) -> None:
    """Off a terminal, a long run prints a short line with its count and info; quiet prints none."""
    monkeypatch.setattr(terminal, "PROGRESS_PERIOD_S", 0.0)
    monkeypatch.setattr(sys.stderr, "isatty", lambda: False)
    with terminal.progress("study", total=3) as tracker:
        for k in range(3):
            tracker.advance(info=f"point {k}")
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 3
    assert lines[-1].startswith("study: 3/3 after ") and lines[-1].endswith(", point 2")
    terminal.set_quiet(True)
    try:
        with terminal.progress("study", total=3) as tracker:
            tracker.advance(3)
    finally:
        terminal.set_quiet(False)
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("flag", ["--quiet", "-q"])
def test_quiet_flag_sets_quiet(flag) -> None:
    from gamespec.cli import run

    try:
        assert run([flag, "validate", str(PROBLEMS / "ocp" / "bryson_denham.yaml")]) == 0
        assert terminal.quiet()
    finally:
        terminal.set_quiet(False)
