"""Writing the document's three lists into an existing ROBO Pro program (.rpp), touching nothing else.
Only the lists' ``<init value="…">`` children and ``N`` change: the file is edited as text.

As real programs keep them: a global list appears once in every subprogram that uses it (same name, each
copy with its own inits: every copy is written); names are compared as ROBO Pro shows them (``Abst&#228;nde``
is Abstände); a list with ``initcsvbuffer="true"`` loads its values from a CSV file when the program starts
(column ``initcsvcolumn``, which ROBO Pro leaves out for column 0), replacing what is written here; a float
list (``datatype="11"``, inits ``value0/value1/value2``) is refused.
"""

from __future__ import annotations

import html
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from tablebot import overwrite as guard
from tablebot.csvtext import read_bytes
from tablebot.diagnostics import Collector, fail
from tablebot.escape import xml_attr
from tablebot.files import write_bytes
from tablebot.i18n import N_

LIST_CLASS = "ftProDataArray1D"
DEFAULT_NAMES = ("Event", "Action", "Timer")
TAG_RE = re.compile(r"""<(/?)([A-Za-z_][\w.:-]*)((?:\s+[^\s=/>]+\s*=\s*(?:"[^"]*"|'[^']*'))*)\s*(/?)>""")
SKIP_RE = re.compile(r"<!--.*?-->|<\?.*?\?>|<!\[CDATA\[.*?\]\]>|<!DOCTYPE[^>]*>", re.S)
ATTR_RE = re.compile(r"""([^\s=/>]+)\s*=\s*("([^"]*)"|'([^']*)')""")
#: An init as ROBO Pro writes it, on two lines (\x00 stands for the value, \x01 for the line end and indent).
DEFAULT_INIT = '<init value="\x00">\x01</init>'
INTEGER = "3"  # datatype of an integer list; 11 is float
VALUE_RE = re.compile(r"""value\s*=\s*("[^"]*"|'[^']*')""")
ENCODING_RE = re.compile(rb"""^(?:\xef\xbb\xbf)?<\?xml[^>]*encoding\s*=\s*["']([\w.-]+)["']""")


@dataclass
class ListElement:
    """Where one list sits in the text: its start tag, its N attribute, its init children."""

    name: str  # as ROBO Pro shows it (character references resolved)
    line: int
    start: int
    tag_end: int  # just after the start tag's '>'
    close: int = -1  # start of its '</o>'; -1: never closed, -2: written as an empty element <o .../>
    n_span: tuple[int, int] | None = None  # the N attribute's value
    n_value: int = 0
    csv_column: str | None = None  # initcsvcolumn, None when absent
    csv_buffer: bool = False  # initcsvbuffer="true"
    globalname: str = ""
    datatype: str = INTEGER
    inits: list[tuple[int, int]] = field(default_factory=list)

    @property
    def csv_source(self) -> int | None:
        """The CSV column ROBO Pro loads the list from when the program starts, or None."""
        column = (self.csv_column or "").strip()
        if column not in ("", "-1"):
            return int(column) if re.fullmatch(r"-?\d{1,100}", column) else 0  # more digits than int() takes: 0
        return 0 if self.csv_buffer and self.csv_column is None else None


def _attrs(text: str) -> dict[str, tuple[str, int, int]]:
    """Attribute name -> (value, value start, value end) within ``text``."""
    found = {}
    for m in ATTR_RE.finditer(text):
        group = 3 if m.group(3) is not None else 4
        found[m.group(1)] = (m.group(group), m.start(group), m.end(group))
    return found


def find_lists(text: str) -> list[ListElement]:
    """Every ftProDataArray1D element, with its direct init children, by scanning the tags."""
    skipped = [(m.start(), m.end()) for m in SKIP_RE.finditer(text)]
    stack: list[tuple[str, ListElement | None]] = []
    lists: list[ListElement] = []
    for m in TAG_RE.finditer(text):
        if any(a <= m.start() < b for a, b in skipped):
            continue
        closing, tag, attr_text, empty = m.group(1), m.group(2), m.group(3), m.group(4)
        if closing:
            if stack and stack[-1][0] == tag:
                _, element = stack.pop()
                if element is not None:
                    element.close = m.start()
                holder = stack[-1][1] if stack else None
                if tag == "init" and holder is not None and holder.inits and holder.inits[-1][1] < 0:
                    holder.inits[-1] = (holder.inits[-1][0], m.end())
            continue
        parent = stack[-1][1] if stack else None
        attrs = _attrs(attr_text)
        element = None
        if tag == "o" and attrs.get("classname", ("",))[0] == LIST_CLASS:
            element = ListElement(
                html.unescape(attrs.get("name", ("",))[0]), text.count("\n", 0, m.start()) + 1, m.start(), m.end()
            )
            if "N" in attrs:
                value, a, b = attrs["N"]
                element.n_span = (m.start(3) + a, m.start(3) + b)
                element.n_value = int(value) if re.fullmatch(r"\s*-?[0-9]{1,100}\s*", value) else 0  # int() limit
            element.csv_column = attrs["initcsvcolumn"][0] if "initcsvcolumn" in attrs else None
            element.csv_buffer = attrs.get("initcsvbuffer", ("",))[0].strip() == "true"
            element.globalname = html.unescape(attrs.get("globalname", ("",))[0])
            element.datatype = attrs.get("datatype", (INTEGER,))[0].strip()
            lists.append(element)
        elif tag == "init" and isinstance(parent, ListElement):
            parent.inits.append((m.start(), m.end() if empty else -1))
        if element is not None and empty:
            element.close = -2  # written <o .../>: it has no place for children
        if not empty:
            stack.append((tag, element))
    return lists


def _line_indent(text: str, at: int) -> str:
    start = text.rfind("\n", 0, at) + 1
    return text[start:at] if not text[start:at].strip() else ""


def _init_texts(text: str, element: ListElement, values: Sequence[int]) -> tuple[int, int, str]:
    """(start, end, replacement) that puts ``values`` as the list's init children.

    Existing inits are replaced in their own form and spacing; a list without any gets them as real files
    lay them out: after its pins, each ``<init value="…">`` and ``</init>`` on lines of their own at the
    pins' indent (one step deeper than the list's closing tag), just before that tag.
    """
    newline = "\r\n" if "\r\n" in text else "\n"
    if element.inits:
        first_start, first_end = element.inits[0]
        sample = text[first_start:first_end]
        indent = _line_indent(text, first_start)
        separator = text[first_end : element.inits[1][0]] if len(element.inits) > 1 else newline + indent
        # an init without a value (<init/>) has no form to copy: take ROBO Pro's own
        form = (
            VALUE_RE.sub('value="\x00"', sample, count=1)
            if VALUE_RE.search(sample)
            else DEFAULT_INIT.replace("\x01", newline + indent)
        )
        return first_start, element.inits[-1][1], separator.join(form.replace("\x00", xml_attr(str(v))) for v in values)
    indent = _line_indent(text, element.close) + "    "
    form = DEFAULT_INIT.replace("\x01", newline + indent)
    lines = "".join(f"{indent}{form.replace(chr(0), xml_attr(str(v)))}{newline}" for v in values)
    line_start = text.rfind("\n", 0, element.close) + 1
    if text[line_start : element.close].strip() == "" and line_start > 0:
        return line_start, line_start, lines  # the closing tag has its own line: insert above it
    return element.close, element.close, newline + lines + indent[:-4]


def _unwritable(element: ListElement) -> tuple[str, str] | None:
    """Why the values cannot be written into ``element`` (message, hint), or None."""
    name = element.name
    if element.datatype != INTEGER:
        return (
            f"list {name!r} holds floats (datatype {element.datatype}, inits value0/value1/value2); the "
            "document's lists hold integers",
            f"choose an integer list, or set {name}'s type to integer in ROBO Pro",
        )
    if element.close == -2:
        return (
            f"list {name!r} is an empty element <o .../> with no place for values",
            f"give it an end tag: <o ...></o>, or give {name} a value in ROBO Pro and save again",
        )
    if element.close < 0:
        return f"list {name!r} is never closed", "is the .rpp file complete?"
    return None


def rewrite(text: str, lists: Mapping[str, Sequence[int]], path: str | Path = "<rpp>") -> str:
    """The program with each named list holding ``values`` (N grown as needed); refuses a missing list."""
    out = Collector(path)
    found = find_lists(text)
    by_name: dict[str, list[ListElement]] = {}
    for element in found:
        by_name.setdefault(element.name, []).append(element)
    names = tuple(sorted(by_name)) or (N_("none"),)
    edits: list[tuple[int, int, str]] = []
    for name, values in lists.items():
        matches = by_name.get(name, [])
        if not matches:
            out.error(
                None,
                None,
                N_("no list named {name!r} ({kind}) in this program", name=name, kind=LIST_CLASS),
                N_(
                    "lists in the program: {names}; choose names with --event-list/--action-list/--timer-list",
                    names=names,
                ),
            )
            continue
        global_names = sorted({e.globalname for e in matches})
        if len(global_names) > 1:
            out.error(
                matches[1].line,
                None,
                N_(
                    "{n} different lists are named {name!r} (global names {globals}, lines {lines})",
                    n=len(matches),
                    name=name,
                    globals=tuple(map(repr, global_names)),
                    lines=tuple(str(e.line) for e in matches),
                ),
                N_("rename all but one in ROBO Pro"),
            )
            continue
        for element in matches:  # a global list: one copy per subprogram that uses it, each written
            problem = _unwritable(element)
            if problem:
                out.error(element.line, None, *problem)
                continue
            edits.append(_init_texts(text, element, values))
            if element.n_span and len(values) > element.n_value:
                edits.append((*element.n_span, str(len(values))))
    out.raise_if_any()
    for start, end, new in sorted(edits, reverse=True):
        text = text[:start] + new + text[end:]
    return text


def file_encoding(data: bytes) -> str:
    """The XML declaration's encoding (ROBO Pro writes UTF-8; older files may say ISO-8859-1)."""
    match = ENCODING_RE.match(data)
    return match.group(1).decode("ascii") if match else "utf-8"


def csv_loaded(text: str, names: Sequence[str]) -> dict[str, int]:
    """Lists among ``names`` that ROBO Pro fills from a CSV file when the program starts, with the column
    (their inits are then replaced): ``initcsvcolumn`` other than -1, or ``initcsvbuffer="true"`` without
    ``initcsvcolumn``, which is column 0."""
    found: dict[str, int] = {}
    for element in find_lists(text):
        column = element.csv_source
        if element.name in names and column is not None:
            found.setdefault(element.name, column)
    return found


def write_lists(rpp: Path, lists: Mapping[str, Sequence[int]], out: Path | None = None) -> tuple[Path, dict[str, int]]:
    """Rewrite ``rpp`` (or write the result to ``out``); returns the path and the lists loaded from a CSV
    file (with their columns)."""
    data = read_bytes(rpp)
    encoding = file_encoding(data)
    try:
        text = data.decode(encoding)
    except UnicodeDecodeError as exc:
        raise fail(
            rpp,
            N_("not a ROBO Pro program: byte {at} is not {encoding} text", at=exc.start, encoding=encoding),
            N_("give a .rpp file saved by ROBO Pro"),
        ) from None
    except LookupError:
        raise fail(
            rpp,
            N_("unknown text encoding {encoding!r} in the XML declaration", encoding=encoding),
            N_("save the program again in ROBO Pro (it writes UTF-8)"),
            1,
        ) from None
    if "<cvg" not in text[:4096] and LIST_CLASS not in text:
        raise fail(rpp, N_("not a ROBO Pro program (no <cvg> document element)"), N_("give a .rpp file"), 1, 1)
    new = rewrite(text, lists, rpp)
    target = out or rpp
    if out is None:
        guard.rewrite(rpp)  # the program is updated in place, as asked; its old version stays as .bak
    write_bytes(target, new.encode(encoding))  # all or nothing: a failed write leaves the program as it was
    return target, csv_loaded(new, list(lists))
