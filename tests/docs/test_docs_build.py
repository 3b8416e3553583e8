"""The documentation site builds with warnings as errors, and its generated pages hold what the
code says (every kind's schema fields, every backend's options)."""

from __future__ import annotations

import re
import resource
import subprocess
import sys

import pytest

from gamespec import registry
from tests.conftest import ROOT

BUILD_CPU_S = 120
"""CPU seconds the build may take (``RLIMIT_CPU`` on the build process: a loaded machine slows it
down without failing it)."""


def test_mkdocs_build_strict(tmp_path) -> None:
    pytest.importorskip("mkdocs", reason="mkdocs is not installed (pip install -e '.[docs]')")
    site = tmp_path / "site"
    build = subprocess.Popen(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    resource.prlimit(build.pid, resource.RLIMIT_CPU, (BUILD_CPU_S, BUILD_CPU_S))
    _, stderr = build.communicate()
    assert build.returncode == 0, stderr[-3000:]
    text = {
        page: re.sub(r"<[^>]+>", " ", (site / page / "index.html").read_text())
        for page in ("backends", "statuses", "api", "extending")
    }
    for kind in registry.names("gamespec.kinds"):
        page = re.sub(r"<[^>]+>", " ", (site / "kinds" / kind / "index.html").read_text())
        fields = registry.spec_class(kind).model_json_schema()["properties"]
        assert all(name in page for name in fields), kind
        assert "Worked example" in page, kind
    for name in registry.runner_names():
        options = registry.runner_class(name).options_model.model_json_schema().get("properties", {})
        assert all(option in text["backends"] for option in options), name
    assert "spec_from_dict" in text["api"] and "class ProjectileToOcp" in text["extending"]
