"""The documentation site builds with warnings as errors (once per run, :func:`site`), and its
generated pages hold what the code says: every kind's schema fields, every backend's options, every
kind, transform and gallery page in the navigation (no "not included in the nav" line), each
gallery page with its saved Result's figures, and the notebook page executed."""

from __future__ import annotations

import os
import re
import resource
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest
import yaml

from gamespec import registry
from gamespec.result import Result
from tests.conftest import ROOT
from tests.plots import fixtures

BUILD_CPU_S = 120
"""CPU seconds the build may take (``RLIMIT_CPU`` on the build process: a loaded machine slows it
down without failing it)."""


def _first_of_each_kind() -> tuple[str, ...]:
    """The problem stems whose gallery figures the build draws: the first saved one of each kind
    (``tests/plots`` draws every saved Result's figures; here the pages' embedding is what is
    tested)."""
    first: dict[str, str] = {}
    for path in fixtures.FILES:
        first.setdefault(yaml.safe_load(path.read_text())["kind"], path.stem)
    return tuple(first.values())


DRAWN = _first_of_each_kind()


@dataclass(frozen=True)
class Site:
    folder: Path
    log: str


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Site:
    """The site built with ``mkdocs build --strict``, and its log."""
    for module in ("mkdocs", "markdown_exec"):
        pytest.importorskip(module, reason=f"{module} is not installed (pip install -e '.[docs]')")
    folder = tmp_path_factory.mktemp("docs") / "site"
    build = subprocess.Popen(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(folder)],
        cwd=ROOT,
        env=os.environ | {"GAMESPEC_GALLERY_FIGURES": ",".join(DRAWN)},
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    resource.prlimit(build.pid, resource.RLIMIT_CPU, (BUILD_CPU_S, BUILD_CPU_S))
    log, _ = build.communicate()
    assert build.returncode == 0, log[-3000:]
    return Site(folder, log)


def _text(path: Path) -> str:
    return re.sub(r"<[^>]+>", " ", path.read_text())


def test_mkdocs_build_strict(site: Site) -> None:
    text = {
        page: _text(site.folder / page / "index.html")
        for page in ("backends", "statuses", "api", "extending")
    }
    for kind in registry.names("gamespec.kinds"):
        page = _text(site.folder / "kinds" / kind / "index.html")
        fields = registry.spec_class(kind).model_json_schema()["properties"]
        assert all(name in page for name in fields), kind
        assert "Worked example" in page, kind
    for name in registry.runner_names():
        options = registry.runner_class(name).options_model.model_json_schema().get("properties", {})
        assert all(option in text["backends"] for option in options), name
    assert "spec_from_dict" in text["api"] and "class ProjectileToOcp" in text["extending"]


def test_every_kind_transform_and_problem_is_in_the_nav(site: Site) -> None:
    """No page left out of the navigation, and the navigation (on every page, here the home page)
    links each kind's and each transform's page and each shipped problem's gallery page."""
    assert "not included in the" not in site.log, site.log
    home = (site.folder / "index.html").read_text()
    pages = [f"kinds/{kind}/" for kind in registry.names("gamespec.kinds")]
    pages += [f"transforms/{name}/" for name in registry.names("gamespec.transforms")]
    pages += [f"gallery/{path.stem}/" for path in sorted(fixtures.PROBLEMS.rglob("*.yaml"))]
    assert not [page for page in pages if f'href="{page}"' not in home]


def test_gallery_page_of_each_shipped_problem(site: Site) -> None:
    """Each shipped problem file's page names its file, kind and status, gives the command and
    shows every figure its saved Result draws, each written beside the page, or (the files this
    build does not draw, :data:`DRAWN`) says they are not drawn; a study's page, with no saved
    Result, gives the command."""
    for path in fixtures.FILES:
        page = site.folder / "gallery" / path.stem / "index.html"
        result = Result.load(fixtures.FIXTURES / path.stem)
        text = _text(page)
        relative = str(path.relative_to(ROOT))
        assert f"gamespec solve {relative}" in text and result.kind in text and result.status.value in text
        images = re.findall(r'<img alt="[^"]*" src="([^"]+)"', page.read_text())
        if path.stem not in DRAWN:
            assert not images and "not drawn in this build" in text, path.stem
            continue
        assert images, path.stem
        assert all((page.parent / image).read_bytes().startswith(b"\x89PNG") for image in images)
    for path in sorted(set(fixtures.PROBLEMS.rglob("*.yaml")) - set(fixtures.FILES)):
        text = _text(site.folder / "gallery" / path.stem / "index.html")
        assert f"gamespec solve {path.relative_to(ROOT)}" in text and "No saved Result" in text


def test_notebook_page_is_executed(site: Site) -> None:
    """The notebook page's code ran at build time: the Result's HTML table and inline figures."""
    page = (site.folder / "notebook" / "index.html").read_text()
    assert '<div class="gamespec-result">' in page and "capture time" in page
    assert page.count('<img src="data:image/png;base64,') >= 1
