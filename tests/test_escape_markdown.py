"""Markdown (report.md, issue 38): user text read back by a CommonMark parser (markdown-it, the one rich uses) as
the literal text, in a paragraph, a table's cell and a code span; no name can start emphasis, a link, HTML or a
new cell."""

from __future__ import annotations

import html

import pytest
from hypothesis import given
from hypothesis import strategies as st
from markdown_it import MarkdownIt

from tablebot.escape import markdown_code, markdown_text

pytestmark = [pytest.mark.kernel_free]

PARSER = MarkdownIt("commonmark").enable("table")
NASTY = [
    "a|b",
    "*bold*",
    "_under_",
    "front_bumper_stops",
    "<b>x</b>",
    "[link](http://x)",
    "`tick`",
    "a\\",
    "# h",
    "&amp;",
    "![img](x.png)",
    "~~gone~~",
    "line\nbreak",
]


def _text_of(rendered: str, tag: str) -> str:
    inner = rendered.split(f"<{tag}>", 1)[1].split(f"</{tag}>", 1)[0]
    return html.unescape(inner)


@pytest.mark.parametrize("text", NASTY)
def test_markdown_text_reads_back_as_written(text: str) -> None:
    expected = text.replace("\n", " ")
    assert _text_of(PARSER.render(f"said {markdown_text(text)} here"), "p") == f"said {expected} here"
    table = PARSER.render(f"| a | b |\n|---|---|\n| {markdown_text(text)} | 1 |\n")
    assert _text_of(table.split("<tbody>")[1], "td") == expected and table.count("<td>") == 2


@given(st.text(alphabet=st.characters(codec="ascii"), max_size=30))
def test_any_text_stays_one_cell_and_one_code_span(text: str) -> None:
    row = PARSER.render(f"| a | b |\n|---|---|\n| {markdown_text(text)} | 1 |\n")
    assert row.split("<tbody>")[1].count("<td>") == 2
    if text.strip():  # a code span of spaces only is not one, in CommonMark
        assert PARSER.render(f"run {markdown_code(text)} now").count("<code>") == 1


@pytest.mark.parametrize("text", ["a`b", "`x", "x``", "tablebot sim 'a b.csv' --out /tmp/o"])
def test_markdown_code_holds_backticks(text: str) -> None:
    assert _text_of(PARSER.render(f"run {markdown_code(text)} now"), "code") == text
