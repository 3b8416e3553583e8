"""The contracts are checked (issue 24, item 6): mypy, configured by ``[tool.mypy]`` in
``pyproject.toml`` (``--strict`` on the public modules and the shipped plugins, see the comment
there), reports no error; and every backend, transform and study an entry point registers is in
that configuration, so that mypy holds each against ``Backend[SpecT, OptionsT]``,
``Transform[Src, Dst, Options, Inverse]`` or the ``Study`` protocol.

mypy runs in a child process (``mypy.api.run`` in the test's own process leaves mypy's whole object
graph behind, measured at 5-8 s of CPU more to collect at the worker's exit) and keeps its
incremental cache in pytest's cache folder, so a run after the first re-reads only what changed:
measured (``/usr/bin/time python -m pytest -q tests/core/test_typing.py -k mypy``, minus pytest's
own ~1.5 s) at ~5 s of CPU without a cache, as on CI's fresh clone, and ~0.4 s with one.
"""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from tests.conftest import ROOT

PYPROJECT = ROOT / "pyproject.toml"

PLUGIN_GROUPS = ("gamespec.backends", "gamespec.transforms", "gamespec.studies")
"""The entry-point groups of the plugin contracts: backends, transforms and the Study plugins."""


def _config() -> dict:
    return tomllib.loads(PYPROJECT.read_text())


def _module_file(target: str) -> str:
    """The file, relative to the repository, of an entry point's ``module:object``."""
    module = target.split(":")[0].replace(".", "/") + ".py"
    return module if module.startswith("gamespec/") else f"backends/{module}"


def test_mypy_reports_no_error(request: pytest.FixtureRequest, tmp_path: Path) -> None:
    store = getattr(request.config, "cache", None)
    cache = store.mkdir("mypy") if store is not None else tmp_path
    run = subprocess.run(
        [sys.executable, "-m", "mypy", "--config-file", str(PYPROJECT), "--cache-dir", str(cache)],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    output = run.stdout + run.stderr
    assert run.returncode == 0, f"mypy (pyproject.toml [tool.mypy]) found errors:\n{output}"
    assert "Success: no issues found" in run.stdout, output


def test_every_plugin_contract_is_checked() -> None:
    config = _config()
    checked = config["tool"]["mypy"]["files"]
    assert config["tool"]["mypy"]["strict"] is True
    groups = [config["project"]["entry-points"][g] for g in PLUGIN_GROUPS]
    plugins = {_module_file(target) for group in groups for target in group.values()}
    covered = {f for f in plugins if any(f == c or f.startswith(c.rstrip("/") + "/") for c in checked)}
    missing = sorted(plugins - covered)
    assert not missing, f"plugin modules not in [tool.mypy] files: {missing}"
