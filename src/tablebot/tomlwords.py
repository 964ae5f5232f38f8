"""The TOML parser's errors in tablebot's words: ``I1 is given twice: lines 12 and 14`` instead of ``Cannot
overwrite a value``, and each other message of :mod:`tomllib` that a user can meet with a hint that says what
to write. The parser gives a message and the place it stopped; the key or section it stopped at, and where
that was given first, are found again in the text."""

from __future__ import annotations

import re

from tablebot.i18n import N_, Message

__all__ = ["worded"]

_PART = r"""(?:"[^"\n]*"|'[^'\n]*'|[A-Za-z0-9_-]+)"""
_KEY_RE = re.compile(rf"^\s*({_PART}(?:\s*\.\s*{_PART})*)\s*=")
_HEADER_RE = re.compile(rf"^\s*(\[\[?)\s*({_PART}(?:\s*\.\s*{_PART})*)\s*\]\]?\s*(?:#.*)?$")
_PART_RE = re.compile(_PART)

#: The parser's message (a pattern of its start) -> (tablebot's message, the hint). Messages of Python 3.11 to
#: 3.13; one not listed here is shown as the parser gives it.
_WORDS: tuple[tuple[str, Message, Message], ...] = (
    (
        r"Expected '=' after a key",
        N_("a key must be followed by '=' and a value"),
        N_('write KEY = VALUE (text in quotes: name = "my robot"), or start the line with # to make it a comment'),
    ),
    (
        r"Expected newline or end of document",
        N_("something follows the value on this line"),
        N_("write one KEY = VALUE per line; anything after it must be a comment, starting with #"),
    ),
    (
        r"Invalid value",
        N_("this value is missing or not one TOML knows"),
        N_('write text in quotes ("left bumper"), a number (12, 0.5), true or false, or a list [1, 2]'),
    ),
    (
        r"Invalid statement",
        N_("this line is neither KEY = VALUE nor a [section]"),
        N_("start it with # to make it a comment"),
    ),
    (
        r"Invalid initial character for a key part",
        N_("a key cannot start with this character"),
        N_('keys are letters, digits, _ and -; put any other name in quotes ("my key" = 1)'),
    ),
    (r"Unclosed array", N_("a list [ ... ] is not closed"), N_("close it with ]")),
    (
        r"Unclosed inline table",
        N_("an inline table { ... } is not closed on its line"),
        N_("close it with } on the same line, or write it as a [section]"),
    ),
    (
        r"Expected '\]' at the end of a table declaration",
        N_("a [section] header is not closed"),
        N_("close it with ] on the same line"),
    ),
    (
        r"Expected '\]\]' at the end of an array declaration",
        N_("a [[section]] header is not closed"),
        N_("close it with ]] on the same line"),
    ),
    (r"Unterminated string", N_("a text in quotes is not closed"), N_("end it with the same quote")),
    (
        r"Illegal character '\\n'",
        N_("a text in quotes is not closed on its line"),
        N_("end it with the same quote on the same line"),
    ),
    (r"Illegal character", N_("a character that TOML does not allow here"), N_("delete it, or put it inside quotes")),
    (
        r"Unescaped '\\' in a string",
        N_("a backslash in double quotes starts an escape (\\n, \\t, \\\\)"),
        N_("write \\\\ for one backslash, or use single quotes: 'C:\\robots'"),
    ),
    (r"Invalid date or datetime", N_("a date or time that does not exist"), N_("quote it to keep it as text")),
    (
        r"Invalid hex value|Escaped character is not a Unicode",
        N_("an escape that is no character"),
        N_("write \\\\ for a backslash"),
    ),
    (r"Duplicate inline table key '?([^'(]*)'?", N_("{key} is given twice inside {{ }}"), N_("give each key once")),
    (
        r"Cannot mutate immutable namespace",
        N_("this adds to an inline table { ... }, which is closed once written"),
        N_("write the keys inside its braces, or make it a [section]"),
    ),
)


def worded(text: str, message: str, line: int, column: int) -> tuple[str, str, int, int]:
    """(message, hint, line, column) for the parser's ``message`` at ``line``, ``column`` of ``text``."""
    if message.startswith(("Cannot overwrite a value", "Cannot declare", "Cannot redefine namespace")):
        return _twice(text.splitlines(), line, column)
    for pattern, words, hint in _WORDS:
        found = re.match(pattern, message)
        if found:
            named = Message(words.msgid, {"key": found[1]}) if found.groups() else words
            return N_("TOML syntax: {problem}", problem=named), hint, line, column
    return N_("TOML syntax: {problem}", problem=message), "", line, column


def _twice(lines: list[str], line: int, column: int) -> tuple[str, str, int, int]:
    """A key or section given a second time at ``line``: named, with the line it was first given on."""
    paths = _paths(lines[:line])
    here = paths.get(line)
    if here is None:
        return N_("TOML syntax: a key or section given a second time"), N_("give each key once"), line, column
    shown, path = here
    earlier = [(n, p) for n, (_, p) in sorted(paths.items()) if n < line]
    first = next((n for n, p in earlier if p == path), None) or next((n for n, p in earlier if _clash(p, path)), None)
    twice = (
        N_("{shown} is given twice: lines {first} and {line}", shown=shown, first=first, line=line)
        if first is not None
        else N_("{shown} is given twice (line {line})", shown=shown, line=line)
    )
    if shown.startswith("["):
        return twice, N_("write each section once, with all its keys under it"), line, 1
    return twice, N_("keep one of them: a key is given once in its section"), line, 1


def _clash(first: tuple[str, ...], second: tuple[str, ...]) -> bool:
    """Whether a key or section at ``first`` is what ``second`` gives again (or a table that it replaces)."""
    shorter = min(len(first), len(second))
    return first[:shorter] == second[:shorter]


def _paths(lines: list[str]) -> dict[int, tuple[str, tuple[str, ...]]]:
    """Each line that gives a key or a section: (as written, its whole path). Keys inside one ``[[name]]``
    element are told apart from another element's by the element's line."""
    found: dict[int, tuple[str, tuple[str, ...]]] = {}
    current: tuple[str, ...] = ()
    for number, text in enumerate(lines, start=1):
        header = _HEADER_RE.match(text)
        if header:
            parts = _parts(header[2])
            current = (*parts[:-1], f"{parts[-1]}@{number}") if header[1] == "[[" else parts
            found[number] = (f"{header[1]}{'.'.join(parts)}{']' * len(header[1])}", current)
            continue
        key = _KEY_RE.match(text)
        if key:
            found[number] = (".".join(_parts(key[1])), (*current, *_parts(key[1])))
    return found


def _parts(dotted: str) -> tuple[str, ...]:
    return tuple(part.strip("\"'") for part in _PART_RE.findall(dotted))
