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

from tablebot.diagnostics import Collector, fail
from tablebot.formats.csvtext import read_text

HEADER_RE = re.compile(r"^\s*(\[\[?)\s*([^\]]+?)\s*\]\]?\s*(#.*)?$")
Where = tuple[str, int | None, str | None]  # (section path, index in an array of tables, key)


def read_toml(path: Path, hint: str) -> tuple[dict[str, Any], str]:
    """The data and text of a TOML file; unreadable bytes and syntax errors raise located errors."""
    text = read_text(path, "save the file as UTF-8 text")
    return loads(path, text, hint), text


def loads(path: str | Path, text: str, hint: str) -> dict[str, Any]:
    """Parse TOML text; a syntax error names its line and column and gives ``hint``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        match = re.search(r"\(at line (\d+), column (\d+)\)", str(exc))
        if match:
            line, col = int(match[1]), int(match[2])
        else:  # "(at end of document)": the last line, after its last character
            lines = text.splitlines() or [""]
            line, col = len(lines), len(lines[-1]) + 1
        message = re.sub(r"\s*\(at (line|end of document).*\)", "", str(exc))
        raise fail(path, f"TOML syntax: {message}", hint, line, col) from None


class Source:
    """A parsed TOML file and its text, for error locations."""

    def __init__(self, path: str | Path, text: str, data: dict[str, Any]):
        self.path, self.text, self.data = str(path), text, data
        self.out = Collector(self.path)
        self._lines = text.splitlines()

    @classmethod
    def read(cls, path: str | Path, hint: str = "see the commented example examples/bumberbot/arena.toml") -> Source:
        data, text = read_toml(Path(path), hint)
        return cls(path, text, data)

    @classmethod
    def parse(cls, path: str | Path, text: str,
              hint: str = "see the commented example examples/bumberbot/arena.toml") -> Source:
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
    kind = "an integer" if integer else "a number"
    if not is_number(value) or (integer and not isinstance(value, int)):
        src.error(where, f"{label(where)} must be {kind}, not {value!r}", f"write {kind} from {low:g} to {high:g}")
        return None
    if not low <= value <= high:
        src.error(where, f"{label(where)} = {value:g} is out of range {low:g}..{high:g}",
                  f"write {kind} from {low:g} to {high:g}")
        return None
    return value


def point(src: Source, where: Where, value: Any) -> tuple[float, float] | None:
    """An ``[x, y]`` pair of numbers in metres."""
    if (isinstance(value, list) and len(value) == 2 and all(is_number(v) for v in value)
            and all(abs(v) <= 1e4 for v in value)):
        return float(value[0]), float(value[1])
    src.error(where, f"{label(where)} must be a point [x, y] in metres, not {value!r}", "for example: at = [1.2, 0.5]")
    return None


def table_of(src: Source, where: Where, value: Any) -> dict[str, Any]:
    if isinstance(value, dict):
        return value
    src.error(where, f"{label(where)} must be a table", f"write it as a [{where[0]}] section")
    return {}


def known_keys(src: Source, where_section: tuple[str, int | None], table: dict[str, Any],
               known: tuple[str, ...]) -> None:
    for key in table:
        if key not in known:
            section, index = where_section
            src.error((section, index, key), f"unknown key {key!r} in {label((section, index, None)) or 'the file'}",
                      f"known keys: {', '.join(known)}")
