"""The one escaping function per output language: every text from a user's file (robot name, descriptions,
state names, input and motor labels, property texts, file names) passes through one of these on its way
into generated C, XML (ROBO Pro .rpp, SVG), HTML, Mermaid, Graphviz dot, a shell command line, generated
Python or the terminal, so that no text can become code, markup or a command there.

Each function returns text that, placed where its name says, reads back as the literal input (or, where
the language has no way to say a character, as a visibly substituted one) and never ends the construct
it sits in.
"""

from __future__ import annotations

import re
import shlex

#: C0 controls, DEL and C1 controls: no output language should carry them as they are.
_CONTROL_RE = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f]")
_ANY_CONTROL_RE = re.compile(r"[\x00-\x1f\x7f-\x9f]")
#: What XML 1.0 cannot hold at all, even as a character reference.
_XML_BAD_RE = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")
REPLACEMENT = "\N{REPLACEMENT CHARACTER}"
#: What rich reads as a tag (rich.markup.RE_TAGS), with the backslashes before it.
_RICH_TAG_RE = re.compile(r"(\\*)\[(?=[a-z#/@][^[]*?\])")


# --- C ----------------------------------------------------------------------------------------------


def c_string(text: str) -> str:
    """A complete C string literal (with its quotes) holding ``text`` as UTF-8 bytes.

    Everything but printable ASCII is an octal escape (octal, not hex: a hex escape swallows the
    following hex digits); ``?`` is escaped so that no trigraph (``??/``) can form under -std=c99.
    """
    out = []
    for byte in text.encode("utf-8", "replace"):
        char = chr(byte)
        if char in '"\\?':
            out.append("\\" + char)
        elif 0x20 <= byte < 0x7F:
            out.append(char)
        else:
            out.append(f"\\{byte:03o}")
    return '"' + "".join(out) + '"'


def c_comment(text: str) -> str:
    """Text safe inside a C block comment ``/* … */``: printable ASCII only (other characters become
    ``?``), on one line, with no ``*/`` or ``/*``, no trigraph and no backslash (no line splice)."""
    safe = "".join(ch if " " <= ch <= "~" else "?" for ch in text).replace("\\", "/")
    safe = re.sub(r"\?{2,}", "?", safe)  # '??/' would be a backslash under trigraphs
    while "*/" in safe or "/*" in safe:
        safe = safe.replace("*/", "* /").replace("/*", "/ *")
    return safe


# --- XML, SVG, HTML ---------------------------------------------------------------------------------


def xml_text(text: str) -> str:
    """Character data for XML (ROBO Pro .rpp, SVG): ``& < >`` as entities; characters XML 1.0 cannot
    hold at all (most controls, lone surrogates) become U+FFFD."""
    text = _XML_BAD_RE.sub(REPLACEMENT, text)
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def xml_attr(text: str) -> str:
    """An XML attribute value for either quote style: also ``"`` and ``'``, and tab and line ends as
    character references (a parser would otherwise normalise them to spaces)."""
    text = xml_text(text).replace('"', "&quot;").replace("'", "&apos;")
    return text.replace("\t", "&#9;").replace("\n", "&#10;").replace("\r", "&#13;")


def html_text(text: str) -> str:
    """Text for HTML element content or a quoted attribute value (both quotes escaped); controls other
    than tab and line ends become U+FFFD."""
    text = _CONTROL_RE.sub(REPLACEMENT, text)
    return (
        text.replace("&", "&amp;")
        .replace("<", "&lt;")
        .replace(">", "&gt;")
        .replace('"', "&quot;")
        .replace("'", "&#x27;")
    )


# --- diagrams ---------------------------------------------------------------------------------------

#: Mermaid's state-diagram lexer ends a label at ':' ';' or a line end, takes '"' as a string end and
#: '%%' as a comment, decodes '#name;' entities, renders '<b>' and backquoted markdown, and turns any
#: line containing 'direction LR' into a direction statement; these stand-ins read the same to a person.
_MERMAID = str.maketrans(
    {
        ":": "∶",
        ";": ",",
        '"': "'",
        "`": "'",
        "<": "‹",
        ">": "›",
        "&": "＆",
        "#": "＃",
        "%": "％",
        "{": "(",
        "}": ")",
        "|": "¦",
        "\\": "/",
    }
)
_DOT_KEYWORDS = {"node", "edge", "graph", "digraph", "subgraph", "strict"}
_MERMAID_DIRECTION_RE = re.compile(r"(?i)(direction)\s+(?=tb|bt|rl|lr|td)")


def mermaid_label(text: str) -> str:
    """A Mermaid state or transition label: one line, none of the characters Mermaid reads as syntax."""
    text = _ANY_CONTROL_RE.sub(" ", text).translate(_MERMAID)
    return _MERMAID_DIRECTION_RE.sub(r"\1-", text)


def dot_id(text: str) -> str:
    """A Graphviz node or graph ID that needs no quoting: ASCII letters, digits and ``_`` (anything else
    becomes ``_``), never a keyword, never starting with a digit, never an HTML string. Lossy: a caller
    that needs distinct IDs for distinct texts numbers the clashes (see ``analysis.diagram``)."""
    ident = "".join(ch if ch.isascii() and (ch.isalnum() or ch == "_") else "_" for ch in text)
    if not ident or ident[0].isdigit() or ident.lower() in _DOT_KEYWORDS:
        ident = "_" + ident
    return ident


def dot_label(text: str) -> str:
    """Text inside a Graphviz HTML-like label (``<…>``): HTML-escaped, on one line, no controls.

    HTML-like labels are the only Graphviz strings with no escape sequences of their own (``\\N``,
    ``\\G``, a trailing backslash), so tablebot writes every label in that form.
    """
    return html_text(_ANY_CONTROL_RE.sub(" ", text))


# --- Markdown (report.md) -------------------------------------------------------------------------

#: What CommonMark reads as markup wherever it stands (a table's pipe too); ``_`` is escaped where it could
#: open or close emphasis (not inside a word, so ``front_bumper_stops`` reads as written either way).
_MARKDOWN_RE = re.compile(r"[\\`*\[\]<>|!#~&]|(?<![A-Za-z0-9])_|_(?![A-Za-z0-9])")


def markdown_text(text: str) -> str:
    """User text in a Markdown paragraph, heading or table cell: on one line, markup characters
    backslash-escaped (a ``|`` cannot end a cell, a ``*`` cannot start emphasis, ``<`` cannot start HTML)."""
    return _MARKDOWN_RE.sub(lambda m: "\\" + m.group(), _ANY_CONTROL_RE.sub(" ", text))


def markdown_code(text: str) -> str:
    """A complete Markdown code span (with its backticks) holding ``text`` on one line: fenced by one more
    backtick than the longest run inside it, padded when it starts or ends with one (not for a table's cell:
    a ``|`` would end it there)."""
    text = _ANY_CONTROL_RE.sub(" ", text)
    fence = "`" * (max((len(run) for run in re.findall("`+", text)), default=0) + 1)
    pad = " " if text.startswith("`") or text.endswith("`") else ""
    return f"{fence}{pad}{text}{pad}{fence}"


# --- command lines, Python, terminal ---------------------------------------------------------------


def shell_word(text: str) -> str:
    """One POSIX shell word that a shell reads back as ``text`` (for printing a command a person may
    paste); control characters are ANSI-C quoted so the printed line cannot drive the terminal."""
    if _ANY_CONTROL_RE.search(text):
        inner = "".join(f"\\x{ord(c):02x}" if _ANY_CONTROL_RE.match(c) or c in "\\'" else c for c in text)
        return f"$'{inner}'"
    return shlex.quote(text)


def python_string(text: str) -> str:
    """A Python string literal (ASCII only, with its quotes) that evaluates to ``text``."""
    return ascii(text)


_LINE_BREAKS = {"\n": "\\n", "\r": "\\r", "\x85": "\\x85", "\u2028": "\\u2028", "\u2029": "\\u2029"}
_TERMINAL_RE = re.compile("[\x00-\x08\x0a-\x1f\x7f-\x9f\u2028\u2029]")


def plain(text: str) -> str:
    """User text for plain terminal output (no markup: a pipe, a log, ``rich.text.Text``), on the line it
    is printed in: line breaks shown as ``\\n`` (a name cannot start a forged line of its own) and other
    control characters (an ANSI escape, a bell, NUL) as ``\\xNN``; tabs stay."""
    return _TERMINAL_RE.sub(lambda m: _LINE_BREAKS.get(m.group()) or f"\\x{ord(m.group()):02x}", text)


def picture(text: str) -> str:
    """User text for a picture (matplotlib): on one line, every character printable (a control character
    would draw a missing glyph: shown as ``\\xNN``, line breaks as ``\\n``). The pictures are drawn with
    maths parsing off (``tablebot.sim.pictures.draw.literal_text``), so a ``$`` stays a ``$``."""
    return plain(text)


def terminal(text: str) -> str:
    """User text for a rich console line: markup (``[bold]``) escaped, line breaks shown as ``\\n`` and
    control characters (an ANSI escape, a bell, NUL) as ``\\xNN`` instead of acting on the terminal; tabs stay.

    Rich reads backslashes just before a tag as escapes, so a template must not put a markup tag right
    after user text (end it with a plain character, as ``[bold]{path}:[/bold]``). Emoji codes (``:x:``)
    are no markup to escape: tablebot's consoles (``tablebot.cli.common``) are made with ``emoji=False``,
    so print user text only through them.
    """
    text = plain(text)
    # n backslashes before a tag-like '[' become 2n+1: n literal ones, then a literal '['.
    return _RICH_TAG_RE.sub(lambda m: "\\" * (2 * len(m.group(1)) + 1) + "[", text)
