"""The documentation site builds with warnings as errors, and its generated pages hold what the
code says (every kind's schema fields, every backend's options)."""

from __future__ import annotations

import re
import subprocess
import sys

from gamespec import registry
from tests.conftest import ROOT


def test_mkdocs_build_strict(tmp_path) -> None:
    site = tmp_path / "site"
    run = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr[-3000:]
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
