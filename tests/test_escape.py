"""tablebot.escape: each function's output, read back by the real reader of its language, is the input."""

from __future__ import annotations

import ast
import html.parser
import shlex
import shutil
import subprocess
import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING

import pytest
from rich.console import Console

from hostile import HOSTILE
from tablebot.escape import (
    REPLACEMENT,
    c_comment,
    c_string,
    dot_id,
    dot_label,
    html_text,
    mermaid_label,
    python_string,
    shell_word,
    terminal,
    xml_attr,
    xml_text,
)

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from pathlib import Path

TEXTS = (*HOSTILE, "", "plain", "a\tb\r\nc", "\\" * 3, "??=??(??)", "x" * 300, "\ufffe\ud800lone")
needs_gcc = pytest.mark.skipif(shutil.which("gcc") is None, reason="no C compiler")
needs_dot = pytest.mark.skipif(shutil.which("dot") is None, reason="the Graphviz program is not installed")


@needs_gcc
def test_c_string_and_comment_compile_and_print_back(tmp_path: Path) -> None:
    """gcc -std=c99 (trigraphs on) -Wall -Werror: each string prints its UTF-8 bytes; comments vanish."""
    texts = [t for t in TEXTS if "\ud800" not in t]
    body = "\n".join(f"    /* {c_comment(t)} */ put({c_string(t)}, {len(t.encode())});" for t in texts)
    source = tmp_path / "s.c"
    source.write_text(
        "#include <stdio.h>\nstatic void put(const char *s, unsigned long n) "
        "{ fwrite(s, 1, n, stdout); fputc(0xff, stdout); }\n"
        f"int main(void)\n{{\n{body}\n    return 0;\n}}\n",
        encoding="ascii",
    )
    exe = tmp_path / "s"
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-o", exe, source], check=True)
    out = subprocess.run([exe], capture_output=True, check=True).stdout
    assert out.split(b"\xff")[:-1] == [t.encode() for t in texts]


@pytest.mark.parametrize("text", TEXTS)
def test_c_comment_is_one_inert_line(text: str) -> None:
    safe = c_comment(text)
    assert "*/" not in safe and "/*" not in safe and "??" not in safe and "\\" not in safe
    assert safe.isascii() and safe.isprintable()


@pytest.mark.parametrize("text", TEXTS)
def test_xml_text_and_attr_parse_back(text: str) -> None:
    expected = "".join(REPLACEMENT if c in "\ufffe\ud800" or (ord(c) < 32 and c not in "\t\r\n") else c for c in text)
    root = ET.fromstring(
        f"<r a=\"{xml_attr(text)}\" b='{xml_attr(text)}'>{xml_text(text)}</r>".encode("utf-8", "surrogatepass")
    )
    assert root.get("a") == expected and root.get("b") == expected
    assert (root.text or "") == expected.replace("\r\n", "\n").replace("\r", "\n")
    assert list(root) == []  # no element came from the text


class _Collect(html.parser.HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: list[str] = []
        self.data = ""
        self.attrs: list[tuple[str, str | None]] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append(tag)
        self.attrs += attrs

    def handle_data(self, data: str) -> None:
        self.data += data


@pytest.mark.parametrize("text", [t for t in TEXTS if "\ud800" not in t])
def test_html_text_parses_back(text: str) -> None:
    parser = _Collect()
    parser.feed(f'<p title="{html_text(text)}">{html_text(text)}</p>')
    parser.close()
    expected = "".join(
        REPLACEMENT if (ord(c) < 32 and c not in "\t\r\n") or 0x7F <= ord(c) <= 0x9F else c for c in text
    )
    assert parser.tags == ["p"] and parser.attrs == [("title", expected)]
    assert parser.data == expected


@pytest.mark.parametrize("text", TEXTS)
def test_shell_word_reads_back(text: str) -> None:
    word = shell_word(text)
    if "\ud800" in text:  # no command line can carry a lone surrogate: the word still quotes it whole
        assert shlex.split(word) == [text]
        return
    done = subprocess.run(["bash", "-c", f"printf %s {word}"], capture_output=True, check=True)
    # a command line ends a word at a NUL byte: the shell reads back everything before it, and no more
    assert done.stdout == text.split("\x00")[0].encode()


@pytest.mark.parametrize("text", TEXTS)
def test_python_string_evaluates_back(text: str) -> None:
    literal = python_string(text)
    assert literal.isascii() and ast.literal_eval(literal) == text


@pytest.mark.parametrize("text", TEXTS)
def test_terminal_prints_literally(text: str) -> None:
    console = Console(emoji=False, highlight=False, width=1000, force_terminal=False)
    with console.capture() as captured:
        console.print(f"[bold]<{terminal(text)}>[/bold]")
    shown = captured.get()
    assert "\x1b" not in shown and "\x07" not in shown and "\x00" not in shown
    breaks = {"\n": "\\n", "\r": "\\r", "\x85": "\\x85", "\u2028": "\\u2028", "\u2029": "\\u2029"}
    visible = "".join(
        breaks.get(c) or (f"\\x{ord(c):02x}" if (ord(c) < 32 and c != "\t") or 0x7F <= ord(c) <= 0x9F else c)
        for c in text
    )
    # on one line: a line break in user text is shown, not obeyed (rich expands tabs)
    assert shown == ("<" + visible + ">").expandtabs(console.tab_size) + "\n"


@pytest.mark.parametrize("text", TEXTS)
def test_mermaid_label_has_no_syntax(text: str) -> None:
    label = mermaid_label(text)
    assert not any(c in label for c in ':;\n\r"`<>&#%{}') and "direction " not in label.lower()


@needs_dot
def test_dot_ids_and_labels_parse_back() -> None:
    lines = ["digraph g {"]
    for i, text in enumerate(TEXTS):
        if "\ud800" in text:
            continue
        lines.append(f"  {dot_id(text + str(i))} [label=<[{dot_label(text)}]>];")  # <> alone is no label
    lines.append("}")
    done = subprocess.run(["dot", "-Tsvg"], input="\n".join(lines).encode(), capture_output=True, check=False)
    assert done.returncode == 0, done.stderr.decode()
    svg = ET.fromstring(done.stdout)
    texts = [e.text or "" for e in svg.iter("{http://www.w3.org/2000/svg}text")]
    assert "[</init><evil/><![CDATA[x]]> & <b>bold</b> \"q\" 'a']" in texts and "[trail\\]" in texts
    assert not [e for e in svg.iter() if e.tag.endswith("evil")]


def test_dot_id_is_a_plain_identifier() -> None:
    for text in (*TEXTS, "node", "123", "<html>"):
        ident = dot_id(text)
        assert ident and (ident[0].isalpha() or ident[0] == "_") and all(c.isalnum() or c == "_" for c in ident)
        assert ident.isascii() and ident.lower() not in {"node", "edge", "graph", "digraph", "subgraph", "strict"}
