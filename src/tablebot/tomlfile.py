"""TOML files with located errors: read a file, find the line of any key, and check typed values.

``tomllib`` keeps no positions, so lines are found again in the text by section and key; every
problem goes to a :class:`~tablebot.diagnostics.Collector` so a user sees all of them at once.
"""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path
from typing import Any

from tablebot.csvtext import read_text
from tablebot.diagnostics import Collector, fail
from tablebot.durations import MAX_NUMBER_CHARS
from tablebot.i18n import N_, as_typed
from tablebot.tomlwords import worded

HEADER_RE = re.compile(r"^\s*(\[\[?)\s*([^\]]+?)\s*\]\]?\s*(#.*)?$")
Where = tuple[str, int | None, str | None]  # (section path, index in an array of tables, key)


#: A robot, world or property file is a few KB; a megabyte is surely the wrong file.
MAX_TOML_BYTES = 1024 * 1024
#: Deeper nesting of arrays and inline tables than any tablebot file needs (the parser recurses).
MAX_DEPTH = 32


def read_toml(path: Path, hint: str) -> tuple[dict[str, Any], str]:
    """The data and text of a TOML file; unreadable bytes and syntax errors raise located errors."""
    text = read_text(path, N_("save the file as UTF-8 text"), MAX_TOML_BYTES, spreadsheet=False)
    return loads(path, text, hint), text


def loads(path: str | Path, text: str, hint: str) -> dict[str, Any]:
    """Parse TOML text; a syntax error names its line and column and gives ``hint``."""
    unreadable = _unreadable(text)
    if unreadable:
        raise fail(path, *unreadable)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        match = re.search(r"\(at line (\d+), column (\d+)\)", str(exc))
        if match:
            line, col = int(match[1]), int(match[2])
        else:  # "(at end of document)": the last line, after its last character
            lines = text.splitlines() or [""]
            line, col = len(lines), len(lines[-1]) + 1
        message, better, line, col = worded(
            text, re.sub(r"\s*\(at (line|end of document).*\)", "", str(exc)), line, col
        )
        raise fail(path, message, better or hint, line, col) from None
    except RecursionError:  # nesting that _unreadable() did not count (it is a safety net, not the parser)
        raise fail(
            path, N_("nested too deeply to read"), N_("no tablebot file nests that deep: is this the right file?"), 1, 1
        ) from None


#: What may follow a digit in one TOML value or bare key: a number, a date or time, or a key such as ``20``.
TOKEN_RE = re.compile(r"[0-9A-Za-z_.:+-]+")


def _unreadable(text: str) -> tuple[str, str, int, int] | None:
    """(message, hint, line, column) of the first thing the parser should not be given, outside strings and
    comments: ``[``/``{`` brackets nested deeper than MAX_DEPTH (the parser recurses; a header line's ``[[x]]``
    counts too, which never reaches the limit), or a number (or bare key) that starts with a digit and runs
    longer than MAX_NUMBER_CHARS (tomllib's ``int()`` fails past 4,300 digits, and a huge hexadecimal one
    would reach every reader as an int too large for a float or for numpy)."""
    depth, quote = 0, ""
    line, column = 1, 0
    i, n = 0, len(text)
    while i < n:
        ch = text[i]
        column += 1
        if ch == "\n":
            line, column = line + 1, 0
            if quote in ('"', "'"):
                quote = ""  # a one-line string never spans lines (the parser reports it)
        elif quote:
            if text.startswith(quote, i) and (quote[0] == "'" or text[i - 1] != "\\"):
                i += len(quote) - 1
                quote = ""
        elif ch == "#":
            while i + 1 < n and text[i + 1] != "\n":
                i += 1
        elif ch in "\"'":
            quote = ch * 3 if text.startswith(ch * 3, i) else ch
            i += len(quote) - 1
        elif ch in "[{":
            depth += 1
            if depth > MAX_DEPTH:
                return (
                    N_("arrays or inline tables nested more than {most} levels deep", most=MAX_DEPTH),
                    N_("no tablebot file nests that deep: is this the right file?"),
                    line,
                    column,
                )
        elif ch in "]}":
            depth = max(0, depth - 1)
        elif token := TOKEN_RE.match(text, i):  # a value or a bare key: skipped whole
            length = token.end() - i
            if length > MAX_NUMBER_CHARS and ch in "0123456789+-":
                return (
                    N_(
                        "a number of {count:,} characters, more than the {most} tablebot reads",
                        count=length,
                        most=MAX_NUMBER_CHARS,
                    ),
                    N_("no tablebot setting needs such a number: is this the right file?"),
                    line,
                    column,
                )
            i += length - 1
            column += length - 1
        i += 1
    return None


class Source:
    """A parsed TOML file and its text, for error locations."""

    def __init__(self, path: str | Path, text: str, data: dict[str, Any]) -> None:
        self.path, self.text, self.data = str(path), text, data
        self.out = Collector(self.path)
        self._lines = text.splitlines()

    @classmethod
    def read(cls, path: str | Path, hint: str = "see the commented example examples/bumberbot/arena.toml") -> Source:
        data, text = read_toml(Path(path), hint)
        return cls(path, text, data)

    @classmethod
    def parse(
        cls, path: str | Path, text: str, hint: str = "see the commented example examples/bumberbot/arena.toml"
    ) -> Source:
        return cls(path, text, loads(path, text, hint))

    def line(self, section: str = "", index: int | None = None, key: str | None = None) -> int | None:
        """Line of ``key`` in ``[section]`` (the index-th ``[[section]]``), else of the section header."""
        current, seen, header_line = "", -1, None
        key_re = re.compile(rf"^\s*\"?{re.escape(key)}\"?\s*=") if key else None
        for number, text in enumerate(self._lines, start=1):
            header = HEADER_RE.match(text)
            if header:
                current = header[2].replace('"', "").replace(" ", "")
                if current == section:
                    seen += 1
                    if index is None or seen == index:
                        header_line = number
                continue
            in_place = current == section and (index is None or seen == index)
            if in_place and key_re and key_re.match(text):
                return number
        if key and not section and key_re:  # a dotted top-level key written as [key] table
            return self.line(key)
        return header_line

    def error(self, where: Where, message: str, hint: str = "") -> None:
        self.out.error(self.line(*where), None, message, hint)

    def key_error(self, where: Where, message: str, hint: str = "") -> None:
        """:meth:`error` at column 1 of the line found: the key ``where`` names starts that line."""
        line = self.line(*where)
        self.out.error(line, None if line is None else 1, message, hint)

    def raise_if_any(self) -> None:
        self.out.raise_if_any()


def label(where: Where) -> str:
    section, index, key = where
    place = f"[[{section}]] #{index + 1}" if index is not None else (f"[{section}]" if section else "")
    return f"{place} {key}".strip() if key else place


def is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def number(src: Source, where: Where, value: Any, low: float, high: float, integer: bool = False) -> float | None:
    """A number in [low, high] (an integer when asked), or None after reporting why not."""
    low_s, high_s = as_typed(low, "g"), as_typed(high, "g")  # the file's own syntax
    write = (
        N_("write an integer from {low} to {high}", low=low_s, high=high_s)
        if integer
        else N_("write a number from {low} to {high}", low=low_s, high=high_s)
    )
    if not is_number(value) or (integer and not isinstance(value, int)):
        src.error(
            where,
            N_("{name} must be an integer, not {value!r}", name=label(where), value=value)
            if integer
            else N_("{name} must be a number, not {value!r}", name=label(where), value=value),
            write,
        )
        return None
    if not low <= value <= high:
        value_s = f"{value:g}"
        src.error(
            where,
            N_(
                "{name} = {value} is out of range {low}..{high}",
                name=label(where),
                value=value_s,
                low=low_s,
                high=high_s,
            ),
            write,
        )
        return None
    return value


#: The largest distance from the origin, in metres, a world's points may have on either axis.
MAX_COORDINATE = 1e4
_MOST_S = (f"{-MAX_COORDINATE:g}", f"{MAX_COORDINATE:g}")  # as a file writes them, in every language


def point(src: Source, where: Where, value: Any) -> tuple[float, float] | None:
    """An ``[x, y]`` pair of numbers in metres."""
    pair = isinstance(value, list) and len(value) == 2 and all(is_number(v) for v in value)
    if pair and all(abs(v) <= MAX_COORDINATE for v in value):
        return float(value[0]), float(value[1])
    if pair:  # a point, but no room is that large (and the physics' floats would lose their millimetres)
        src.error(
            where,
            N_("{name}: the point {value!r} is out of range", name=label(where), value=value),
            N_("write x and y from {low} to {high} metres", low=_MOST_S[0], high=_MOST_S[1]),
        )
    else:
        src.error(
            where,
            N_("{name} must be a point [x, y] in metres, not {value!r}", name=label(where), value=value),
            N_("for example: [1.2, 0.5]"),
        )
    return None


def table_of(src: Source, where: Where, value: Any) -> dict[str, Any]:
    if isinstance(value, dict):
        return value
    src.error(
        where,
        N_("{name} must be a table", name=label(where)),
        N_("write it as a [{section}] section", section=where[0]),
    )
    return {}


def known_keys(
    src: Source, where_section: tuple[str, int | None], table: dict[str, Any], known: tuple[str, ...]
) -> None:
    for key in table:
        if key not in known:
            section, index = where_section
            place = label((section, index, None))
            src.error(
                (section, index, key),
                N_("unknown key {key!r} in {place}", key=key, place=place)
                if place
                else N_("unknown key {key!r} in the file", key=key),
                N_("known keys: {known}", known=", ".join(known)),
            )
