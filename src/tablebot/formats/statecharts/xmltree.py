"""A small XML tree for the SCXML export: written with tablebot's one XML escaping, read back with each element's
line and column, by the standard library's expat with every DTD refused (so no entity is ever declared, let
alone expanded: tables are data). Comments, processing instructions and whitespace between elements are not
kept; text inside an element is an error (SCXML as tablebot writes it has none)."""

from __future__ import annotations

from dataclasses import dataclass, field
from xml.parsers import expat

from tablebot.diagnostics import fail
from tablebot.escape import xml_attr
from tablebot.i18n import N_

__all__ = ["Element", "parse", "serialise"]

#: The namespaces the export writes, by the prefix it gives them (the reader names attributes ``prefix:name``).
SCXML_NS = "http://www.w3.org/2005/07/scxml"
TB_NS = "urn:tablebot:statechart:1"
PREFIXES = {SCXML_NS: "", TB_NS: "tb:"}
#: Elements nested deeper than this are refused (the export nests five deep).
MAX_DEPTH = 64


@dataclass
class Element:
    """An element: its tag (SCXML's without prefix), attributes in order (tablebot's as ``tb:name``), children,
    and where it starts in the file it was read from (0: made, not read)."""

    tag: str
    attrs: dict[str, str] = field(default_factory=dict)
    children: list[Element] = field(default_factory=list)
    line: int = 0
    column: int = 0

    def add(self, tag: str, **attrs: str) -> Element:
        child = Element(tag, {k.replace("tb_", "tb:", 1): v for k, v in attrs.items()})
        self.children.append(child)
        return child


def serialise(root: Element, comment: str = "") -> str:
    """The document: an XML declaration, a comment (``--`` cannot occur in one), the tree two spaces a level."""
    lines = ['<?xml version="1.0" encoding="UTF-8"?>']
    if comment:  # tablebot's own words, never a user's: a comment cannot escape anything
        assert "--" not in comment and not comment.endswith("-")
        lines.append(f"<!-- {comment} -->")
    _write(root, 0, lines, root=True)
    return "\n".join(lines) + "\n"


def _write(element: Element, depth: int, lines: list[str], root: bool = False) -> None:
    names = {f'xmlns="{SCXML_NS}"': None, f'xmlns:tb="{TB_NS}"': None} if root else {}
    attrs = " ".join([*names, *(f'{k}="{xml_attr(v)}"' for k, v in element.attrs.items())])
    head = f"{'  ' * depth}<{element.tag}{' ' + attrs if attrs else ''}"
    if not element.children:
        lines.append(head + "/>")
        return
    lines.append(head + ">")
    for child in element.children:
        _write(child, depth + 1, lines)
    lines.append(f"{'  ' * depth}</{element.tag}>")


def parse(text: str, path: str) -> Element:
    """The document's root element; a located error (file, line, column) for anything but plain XML elements."""
    parser = expat.ParserCreate(namespace_separator=" ")
    stack: list[Element] = []
    done: list[Element] = []

    def where() -> tuple[int, int]:
        return parser.CurrentLineNumber, parser.CurrentColumnNumber + 1

    def refuse(message: str, hint: str) -> None:
        line, column = where()
        raise fail(path, message, hint, line, column)

    def start(name: str, attrs: dict[str, str]) -> None:
        if len(stack) >= MAX_DEPTH:
            refuse(N_("elements nested more than {most} deep", most=MAX_DEPTH), N_("tablebot's export nests five deep"))
        line, column = where()
        element = Element(
            _name(name, path, line, column),
            {_name(k, path, line, column): v for k, v in attrs.items()},
            line=line,
            column=column,
        )
        (stack[-1].children if stack else done).append(element)
        stack.append(element)

    def chars(data: str) -> None:
        if data.strip():
            refuse(N_("text inside an element"), N_("tablebot's SCXML holds everything in attributes"))

    def doctype(*_: object) -> None:
        line, column = where()  # expat is past the DOCTYPE's name: point at its start
        before = text.splitlines()[line - 1][:column] if line <= len(text.splitlines()) else ""
        start = before.rfind("<!DOCTYPE")
        raise fail(
            path,
            N_("a DOCTYPE (a DTD can declare entities, and a table is data)"),
            N_("remove the <!DOCTYPE ...>"),
            line,
            start + 1 if start >= 0 else column,
        )

    parser.StartElementHandler = start
    parser.EndElementHandler = lambda name: stack.pop()
    parser.CharacterDataHandler = chars
    parser.StartDoctypeDeclHandler = doctype
    parser.EntityDeclHandler = doctype
    try:
        parser.Parse(text, True)
    except expat.ExpatError as exc:
        raise fail(
            path,
            N_("not well-formed XML: {error}", error=expat.ErrorString(exc.code)),
            N_("an SCXML file as tablebot export --to scxml writes it"),
            exc.lineno,
            exc.offset + 1,
        ) from None
    return done[0]


def _name(name: str, path: str, line: int, column: int) -> str:
    """``SCXML-NS tag`` -> ``tag``, ``TB-NS attr`` -> ``tb:attr``, a plain attribute as it is; any other
    namespace is refused."""
    space, _, local = name.rpartition(" ")
    if not space:
        return local
    if space not in PREFIXES:
        raise fail(
            path,
            N_("{name!r} is in the namespace {space!r}", name=local, space=space),
            N_("tablebot reads SCXML and its own attributes"),
            line,
            column,
        )
    return PREFIXES[space] + local
