"""MkDocs hooks: pages generated from the code, so that the documentation cannot drift from it.

- ``kinds/<kind>.md``: one page per registered kind: the spec's docstring, a worked example (the
  smallest shipped problem file of that kind) and the file format rendered from its JSON Schema
  (``gamespec schema KIND``);
- ``transforms/<name>.md``: one page per registered transform: its docstring, the kinds it maps
  and its options, from its ``options_model``;
- ``backends.md``: each backend's kinds, features and options, from its ``options_model``;
- ``gallery/<stem>.md``: one page per shipped problem file: the command, and the summary and the
  figures of its saved Result under ``tests/data/results/`` (:mod:`tests.plots.fixtures`; a study
  has none), drawn by the kind's plotter (:meth:`gamespec.Result.plot`), so the build solves
  nothing; ``gallery/index.md`` lists them by chapter. ``GAMESPEC_GALLERY_FIGURES`` (problem
  stems, comma-separated) draws only those files' figures, the others' pages saying so: the test
  suite's build (``tests/docs/test_docs_build.py``) draws a few, since ``tests/plots`` draws every
  saved Result's figures already;
- the navigation's ``Problem kinds``, ``Transforms`` and ``Gallery`` sections list those pages
  (:func:`on_config`), so a kind, transform or problem file added later is in the nav;
- ``<!-- example: NAME -->`` in a page is replaced by ``docs/examples/NAME`` as a code block (the
  files that ``tests/docs/test_extension_examples.py`` runs).
"""

from __future__ import annotations

import inspect
import os
import re
import sys
from pathlib import Path
from typing import Any

import yaml
from mkdocs.structure.files import File

from gamespec import registry
from gamespec.result import Result
from gamespec.specs.schema import json_schema
from gamespec.summaries import outcome

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = re.compile(r"<!-- example: ([\w.]+) -->")
RESULTS = ROOT / "tests" / "data" / "results"
"""The saved Results the gallery is drawn from (written by ``python -m tests.plots.fixtures``)."""
FIGURES_ENV = "GAMESPEC_GALLERY_FIGURES"
"""Names the problem stems whose figures the gallery draws (all when unset)."""
CHAPTERS = {"ocp": "Optimal-control classics"}
"""Gallery headings of the ``problems/`` folders that are not a thesis chapter (``chN``)."""


def _type(prop: dict[str, Any]) -> str:
    """A short type name of a JSON Schema property."""
    if "$ref" in prop:
        return f"`{prop['$ref'].rsplit('/', 1)[-1]}`"
    if "const" in prop:
        return f"`{prop['const']!r}`"
    if "enum" in prop:
        return " \\| ".join(f"`{v}`" for v in prop["enum"])
    for key in ("anyOf", "oneOf"):
        if key in prop:
            return " or ".join(_type(p) for p in prop[key])
    kind = prop.get("type", "any")
    if kind == "array":
        if "prefixItems" in prop:
            return "[" + ", ".join(_type(p) for p in prop["prefixItems"]) + "]"
        return f"list of {_type(prop.get('items', {}))}"
    if kind == "object" and isinstance(prop.get("additionalProperties"), dict):
        return f"map of {_type(prop['additionalProperties'])}"
    return str(kind)


def _cell(text: object) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _description(prop: dict[str, Any], defs: dict[str, Any]) -> str:
    """A property's description, or that of the definition it refers to (pydantic leaves out a
    field's description that equals its model's docstring)."""
    referred = defs.get(prop.get("$ref", "").rsplit("/", 1)[-1], {})
    return str(prop.get("description") or referred.get("description") or "")


def _table(model: dict[str, Any], defs: dict[str, Any] | None = None) -> str:
    """A Markdown table of one object schema's fields: name, type, default, description (``defs``:
    the definitions its references name)."""
    props, defs = model.get("properties", {}), defs or {}
    if not props:
        return "No fields.\n"
    required = set(model.get("required", []))
    lines = ["| field | type | default | description |", "|---|---|---|---|"]
    for name, prop in props.items():
        default = "required" if name in required else f"`{prop['default']!r}`" if "default" in prop else ""
        lines.append(
            f"| `{name}` | {_cell(_type(prop))} | {_cell(default)} | {_cell(_description(prop, defs))} |"
        )
    return "\n".join(lines) + "\n"


def schema_markdown(schema: dict[str, Any]) -> str:
    """The top-level fields, then every definition the schema refers to, as tables."""
    defs = schema.get("$defs", {})
    parts = ["### Top level\n", _table(schema, defs)]
    for name, definition in defs.items():
        parts += [
            f"\n### `{name}`\n",
            _cell(definition.get("description", "")) + "\n\n",
            _table(definition, defs),
        ]
    return "\n".join(parts)


def _example_file(kind: str) -> Path | None:
    """The smallest shipped problem file of ``kind``."""
    files = []
    for path in sorted((ROOT / "problems").rglob("*.yaml")):
        data = yaml.safe_load(path.read_text())
        if isinstance(data, dict) and data.get("kind") == kind:
            files.append(path)
    return min(files, key=lambda p: p.stat().st_size, default=None)


def _written_example(kind: str) -> list[str]:
    """For a kind no shipped file has but a lowering transform writes: the command that prints it
    from the smallest shipped file of the transform's source kind."""
    for name in registry.names("gamespec.transforms"):
        cls = registry.load("gamespec.transforms", name)
        source = _example_file(cls.source_kind) if cls.target_kind == kind and not cls.requested else None
        if source is not None:
            relative = source.relative_to(ROOT)
            return [
                "## Worked example\n",
                f"What the transform `{name}` writes from `{relative}` (and the backend receives):\n",
                f"```bash\ngamespec show --transformed {relative}\n```\n",
            ]
    return []


def _related(kind: str) -> list[str]:
    """Links from a kind's page: the requested transforms a file of the kind may list (their options
    are on their pages), the lowering transforms from and to it, and its files in the gallery."""
    links = []
    for name in registry.names("gamespec.transforms"):
        cls = registry.load("gamespec.transforms", name)
        link = f"[`{name}`](../transforms/{name}.md)"
        if cls.requested and cls.source_kind == kind:
            links.append(f"- {link}: may be listed under `transforms:` (its options on its page).")
        elif not cls.requested and kind in (cls.source_kind, cls.target_kind):
            links.append(f"- {link}: lowers `{cls.source_kind}` to `{cls.target_kind}`.")
    shipped = [stem for stem, path in _problem_files().items() if _kind_of(path) == kind]
    if shipped:
        links.append("- In the gallery: " + ", ".join(f"[`{s}`](../gallery/{s}.md)" for s in shipped) + ".")
    return ["## Transforms and gallery\n", "\n".join(links) + "\n"] if links else []


def _kind_of(path: Path) -> object:
    data = yaml.safe_load(path.read_text())
    return data.get("kind") if isinstance(data, dict) else None


def kind_page(kind: str) -> str:
    """The page of one problem kind."""
    cls = registry.spec_class(kind)
    text = [f"# Kind `{kind}`\n", inspect.cleandoc(cls.__doc__ or "") + "\n"]
    backend = registry.kind(kind).default_backend
    if backend:
        text.append(f"Default backend: [`{backend}`](../backends.md).\n")
    example = _example_file(kind)
    if example is not None:
        relative = example.relative_to(ROOT)
        text += [
            "## Worked example\n",
            f"`{relative}`:\n",
            f"```yaml\n{example.read_text().rstrip()}\n```\n",
            f"```bash\ngamespec solve {relative} --out runs/{example.stem} --plot\n```\n",
        ]
    else:
        text += _written_example(kind)
    text += _related(kind)
    text += [
        "## File format\n",
        f"Generated from the JSON Schema (`gamespec schema {kind}`).\n",
        schema_markdown(json_schema(kind)),
    ]
    return "\n".join(text)


def backends_page() -> str:
    """Every backend, then every study: what it solves, its features and its options block."""
    text = [
        "# Backend options\n",
        "Each backend (and each study, which runs a study kind) reads its own block",
        "`solver.options.<backend>` of a problem file, validated when the file is solved (a wrong key",
        "or value exits 2 naming `solver.options.<backend>.<key>`).",
        "Generated from each backend's `options_model`.\n",
    ]
    for name in registry.runner_names():
        cls = registry.runner_class(name)
        summary = (cls.__doc__ or "").strip().split("\n\n")[0]
        text += [
            f"## `{name}`\n",
            _cell(summary) + "\n",
            f"Kinds: {', '.join(f'`{k}`' for k in sorted(cls.kinds))}.",
        ]
        if cls.features:
            text.append(f"Features: {', '.join(f'`{f}`' for f in sorted(cls.features))}.")
        text += ["", f"Options (`solver.options.{name}`):\n", _table(cls.options_model.model_json_schema())]
    return "\n".join(text)


def transform_page(name: str) -> str:
    """The page of one transform: what it is, the kinds it maps, when the chain applies it and its
    options (the ``options_model``'s JSON Schema)."""
    cls = registry.load("gamespec.transforms", name)
    source, target = cls.source_kind, cls.target_kind
    if cls.requested:
        when = (
            f"Requested: applied when a file of kind `{source}` lists it under `transforms:` "
            f"(`- {name}: {{...}}`), in the order given, before any lowering transform."
        )
    else:
        when = (
            f"Lowering: applied by the chain when the backend solves `{target}` and the file is `{source}`."
        )
    text = [
        f"# Transform `{name}`\n",
        inspect.cleandoc(cls.__doc__ or "") + "\n",
        f"From [`{source}`](../kinds/{source}.md) to [`{target}`](../kinds/{target}.md). {when}\n",
        "## Options\n",
        f"Generated from `{cls.options_model.__name__}`.\n",
        schema_markdown(cls.options_model.model_json_schema()),
    ]
    return "\n".join(text)


def _value(value: object) -> str:
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def _problem_files() -> dict[str, Path]:
    """The shipped problem files, by stem."""
    return {p.stem: p for p in sorted((ROOT / "problems").rglob("*.yaml"))}


def _saved(stem: str) -> Result | None:
    """The saved Result of the problem file ``stem`` (None for a study, which has none)."""
    folder = RESULTS / stem
    return Result.load(folder) if (folder / "result.json").is_file() else None


def _chapter(path: Path) -> str:
    folder = path.parent.name
    return CHAPTERS.get(folder, f"Chapter {folder.removeprefix('ch')}")


def _settings(path: Path) -> str:
    """The ``--set`` assignments the saved Result of ``path`` was solved with, as text (the
    fixtures' settings that keep a solve short, :func:`tests.plots.fixtures.overrides`)."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    from tests.plots.fixtures import overrides

    chosen = overrides(path)
    if not chosen:
        return ": the file as shipped"
    settings = " ".join(f"--set {o}" for o in chosen)
    return f" with `{settings}` (to keep it short; the command above may print other digits)"


def _summary(path: Path, result: Result | None) -> list[str]:
    """The summary section of a gallery page: the saved Result's rows (the kind's, then the
    scalars), or why there is none."""
    if result is None:
        return [
            "## Summary\n",
            "No saved Result: a study runs many solves, too long for the documentation build; the command "
            "above runs it, and its figures are drawn from its store.\n",
        ]
    rows = outcome(result) + [
        (k, v) for k, v in result.summary().items() if k not in ("problem", "message") and v not in (None, "")
    ]
    table = ["| | |", "|---|---|", *(f"| {_cell(k)} | {_cell(_value(v))} |" for k, v in rows)]
    return [
        "## Summary\n",
        f"Of the saved Result `tests/data/results/{path.stem}/`, written by `python -m tests.plots.fixtures "
        f"{path.stem}`{_settings(path)}.\n",
        *([_cell(result.message) + "\n"] if result.message else []),
        "\n".join(table) + "\n",
    ]


def _drawn(stem: str) -> bool:
    """Whether this build draws ``stem``'s figures (:data:`FIGURES_ENV`)."""
    chosen = os.environ.get(FIGURES_ENV)
    return chosen is None or stem in chosen.split(",")


NOT_DRAWN = "The figures are not drawn in this build ({env} is set); the command above draws them."


def gallery_page(path: Path, result: Result | None, figures: list[str]) -> str:
    """A problem file's page: what it is, the command, the summary of its saved Result and its
    figures (or, where this build does not draw them, :data:`NOT_DRAWN`)."""
    relative = path.relative_to(ROOT)
    data = yaml.safe_load(path.read_text())
    kind = data.get("kind", "")
    plot = " --plot" if result is not None else ""
    undrawn = result is not None and not _drawn(path.stem)
    text = [
        f"# `{path.stem}`\n",
        _cell(data.get("description", "")) + "\n",
        f"`{relative}`, kind [`{kind}`](../kinds/{kind}.md).\n",
        "## Command\n",
        f"```bash\ngamespec solve {relative} --out runs/{path.stem}{plot}\n```\n",
        *_summary(path, result),
        *(["## Figures\n"] if figures or undrawn else []),
        *(f"![{name}]({path.stem}/{name})\n" for name in figures),
        *([NOT_DRAWN.format(env=f"`{FIGURES_ENV}`") + "\n"] if undrawn else []),
    ]
    return "\n".join(text)


def gallery(config) -> list[File]:
    """The gallery: a page per shipped problem file with its saved Result's figures (drawn into
    memory from the Result, :meth:`gamespec.Result.plot`), and the index by chapter."""
    generated, index = (
        [],
        [
            "# Gallery\n",
            "Every shipped problem file; the figures are drawn from its saved Result (the studies aside).\n",
        ],
    )
    chapter = None
    for stem, path in sorted(_problem_files().items(), key=lambda item: (str(item[1].parent), item[0])):
        result = _saved(stem)
        figures = result.plot().images if result is not None and _drawn(stem) else []
        for name, data in figures:
            generated.append(File.generated(config, f"gallery/{stem}/{name}", content=data))
        page = gallery_page(path, result, [name for name, _ in figures])
        generated.append(File.generated(config, f"gallery/{stem}.md", content=page))
        if _chapter(path) != chapter:
            chapter = _chapter(path)
            index += [f"\n## {chapter}\n", "| problem | kind | status |", "|---|---|---|"]
        status = result.status.value if result is not None else "(a study: not saved)"
        index.append(f"| [`{stem}`]({stem}.md) | `{_kind_of(path)}` | {status} |")
    generated.append(File.generated(config, "gallery/index.md", content="\n".join(index) + "\n"))
    return generated


def _gallery_nav() -> list[dict[str, object]]:
    chapters: dict[str, list[dict[str, str]]] = {}
    for stem, path in sorted(_problem_files().items(), key=lambda item: (str(item[1].parent), item[0])):
        chapters.setdefault(_chapter(path), []).append({stem: f"gallery/{stem}.md"})
    return [{"Overview": "gallery/index.md"}, *({c: pages} for c, pages in chapters.items())]


def on_config(config):
    """Fill the navigation's generated sections ``Problem kinds``, ``Transforms`` and ``Gallery``
    (placeholders in ``mkdocs.yml``): every kind, every transform, every gallery page."""
    sections = {
        "Problem kinds": [{kind: f"kinds/{kind}.md"} for kind in registry.names("gamespec.kinds")],
        "Transforms": [{name: f"transforms/{name}.md"} for name in registry.names("gamespec.transforms")],
        "Gallery": _gallery_nav(),
    }
    for item in config["nav"]:
        for title in set(item) & set(sections) if isinstance(item, dict) else ():
            item[title] = sections[title]
    return config


def on_files(files, config):
    """Add the generated pages."""
    for kind in registry.names("gamespec.kinds"):
        files.append(File.generated(config, f"kinds/{kind}.md", content=kind_page(kind)))
    for name in registry.names("gamespec.transforms"):
        files.append(File.generated(config, f"transforms/{name}.md", content=transform_page(name)))
    files.append(File.generated(config, "backends.md", content=backends_page()))
    for file in gallery(config):
        files.append(file)
    return files


def on_page_markdown(markdown: str, page, config, files) -> str:
    """Insert the example files named by ``<!-- example: NAME -->``."""

    def insert(match: re.Match) -> str:
        path = ROOT / "docs" / "examples" / match.group(1)
        language = "python" if path.suffix == ".py" else "yaml"
        return f"`docs/examples/{path.name}`:\n\n```{language}\n{path.read_text().rstrip()}\n```"

    return EXAMPLE.sub(insert, markdown)
