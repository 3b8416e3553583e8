"""A Result in a notebook: ``Result._repr_html_`` renders its outcome as well-formed, escaped HTML
with the kind's summary rows, and ``Result.plot`` draws through the kind's registered plotter (the
one ``gamespec plot`` uses, :func:`gamespec.plotting.plot_result`), inline or into a folder."""

from __future__ import annotations

import base64
import re
from html.parser import HTMLParser
from pathlib import Path

import gamespec
from gamespec.plotting import plot_result
from gamespec.result import Figures, Status
from tests.plots import fixtures

VOID = {"img", "br", "hr", "meta", "input"}


class _Balance(HTMLParser):
    """The open tags, so a test can say every tag was closed in order, and the text."""

    def __init__(self) -> None:
        super().__init__()
        self.stack: list[str] = []
        self.text: list[str] = []
        self.errors: list[str] = []

    def handle_starttag(self, tag, attrs) -> None:
        if tag not in VOID:
            self.stack.append(tag)

    def handle_endtag(self, tag) -> None:
        if not self.stack or self.stack.pop() != tag:
            self.errors.append(tag)

    def handle_data(self, data) -> None:
        self.text.append(data)


def _parsed(markup: str) -> _Balance:
    parser = _Balance()
    parser.feed(markup)
    parser.close()
    assert not parser.errors and not parser.stack, (parser.errors, parser.stack)
    return parser


def test_repr_html_shows_the_outcome_of_a_saved_result() -> None:
    """The saved chapter-5 Result: its name, kind, backend and status, each summary row of its
    kind (capture time, probabilities ...) with the value as the table shows it, and the scalars."""
    result = fixtures.saved(fixtures.PROBLEMS / "ch5" / "linear_flow.yaml")
    parser = _parsed(result._repr_html_())
    text = "".join(parser.text)
    for part in (result.problem, result.kind, result.backend, result.status.value):
        assert part in text
    rows = result.summary_rows()
    assert rows, "a flow_field_game has summary rows"
    for label, _ in rows:
        assert label in text
    assert f"{result.t_final:.6g}" in text and "solve_time_s" in text


def test_repr_html_escapes_and_names_failed_checks() -> None:
    """Text from a Result is escaped (a message with markup stays text), and a check that failed
    its tolerance is a row with its value and tolerance."""
    result = gamespec.Result(
        problem="p",
        kind="optimal_control",
        backend="casadi",
        status=Status.FEASIBLE,
        message="<b>x</b> & y",
        checks={"max_defect": 0.5},
        metrics={"check_tolerances": {"max_defect": 1e-6}},
    )
    markup = result._repr_html_()
    assert "<b>" not in markup and "&lt;b&gt;x&lt;/b&gt; &amp; y" in markup
    text = "".join(_parsed(markup).text)
    assert "failed check" in text and str(result.failed_checks()[0]) in text


def test_plot_draws_what_gamespec_plot_draws(tmp_path: Path) -> None:
    """Into a folder: the files of :func:`plot_result` (same names, same bytes). Inline (no folder):
    the same figures, nothing left on disk, each one PNG shown by ``Figures._repr_html_``."""
    result = fixtures.saved(fixtures.PROBLEMS / "ch6" / "zermelo_min_time.yaml")
    cli = plot_result(result, tmp_path / "cli")
    written = result.plot(tmp_path / "notebook")
    assert [p.name for p in written.paths] == [p.name for p in cli]
    assert all(p.is_file() and p.parent == tmp_path / "notebook" for p in written.paths)
    inline = result.plot()
    assert isinstance(inline, Figures) and inline.paths == []
    assert inline.images == [(p.name, p.read_bytes()) for p in cli]
    assert all(data.startswith(b"\x89PNG") for _, data in inline.images)
    markup = inline._repr_html_()
    _parsed(markup)
    sources = re.findall(r'src="data:image/png;base64,([^"]+)"', markup)
    assert [base64.b64decode(s) for s in sources] == [data for _, data in inline.images]
