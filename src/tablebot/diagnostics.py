"""Problems found in user files, each with a place (file, line, column), a message and a hint.

Every loader collects all of a file's problems before failing, so a user fixes them in one go; a note
(not a problem, such as an assumed text encoding) goes out through :func:`notify`.

A message or hint may be a :class:`tablebot.i18n.Message` (an id and its arguments, written ``N_(...)``): its
value is the English text, and :meth:`Diagnostic.render` says it in the reader's language, so the command line
and the studio show the same words.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from tablebot.i18n import N_, localise

#: The words of a diagnostic's kind and its hint's label, marked for the catalog (shown by :func:`severity_word`).
SEVERITIES = {"error": N_("error"), "warning": N_("warning"), "note": N_("note")}
HINT_LABEL = N_("hint")


def severity_word(severity: str, language: str | None = None) -> str:
    """``error``, ``warning`` or ``note`` in the reader's language (``Fehler``, ``Warnung``, ``Hinweis``)."""
    return localise(SEVERITIES.get(severity, severity), language)


@dataclass(frozen=True)
class Diagnostic:
    """One problem: where it is, what it is, and what to do about it."""

    path: str
    line: int | None
    column: int | None
    message: str
    hint: str = ""
    severity: str = "error"
    detail: str = ""  # a tool's own output (a compiler's errors), shown below the message, line by line

    def location(self) -> str:
        parts = [self.path]
        if self.line is not None:
            parts.append(str(self.line))
            if self.column is not None:
                parts.append(str(self.column))
        return ":".join(parts)

    def render(self, language: str | None = None) -> str:
        """The diagnostic as lines of text, in ``language`` (default: the language in use)."""
        text = f"{self.location()}: {severity_word(self.severity, language)}: {localise(self.message, language)}"
        if self.hint:
            text += f"\n    {localise(HINT_LABEL, language)}: {localise(self.hint, language)}"
        for line in self.detail.splitlines():
            text += f"\n    | {line}"
        return text


class TableBotError(Exception):
    """Raised with every problem of an input; the CLI prints them and exits with code 2."""

    def __init__(self, diagnostics: Iterable[Diagnostic]) -> None:
        self.diagnostics = tuple(diagnostics)
        super().__init__("\n".join(d.render() for d in self.diagnostics))


class Collector:
    """Gathers diagnostics for one file so a loader can report all of them at once."""

    def __init__(self, path: str | Path) -> None:
        self.path = str(path)
        self.items: list[Diagnostic] = []

    def error(self, line: int | None, column: int | None, message: str, hint: str = "") -> None:
        self.items.append(Diagnostic(self.path, line, column, message, hint))

    def raise_if_any(self) -> None:
        if self.items:
            raise TableBotError(self.items)


def fail(
    path: str | Path, message: str, hint: str = "", line: int | None = None, column: int | None = None, detail: str = ""
) -> TableBotError:
    """Build (not raise) an error with a single diagnostic (one line: a tool's output goes in ``detail``)."""
    return TableBotError([Diagnostic(str(path), line, column, message, hint, detail=detail)])


_note_sinks: list[Callable[[Diagnostic], None]] = []


def notify(note: Diagnostic) -> None:
    """Tell the user something that is not a problem but may surprise them (a file read in an assumed
    encoding): printed by the CLI as it comes, a Python warning for other callers."""
    if _note_sinks:
        _note_sinks[-1](note)
    else:
        warnings.warn(note.render(), UserWarning, stacklevel=3)


@contextmanager
def notes_to(sink: Callable[[Diagnostic], None]) -> Iterator[None]:
    """Send the notes of the block to ``sink`` (the CLI prints them as they come)."""
    _note_sinks.append(sink)
    try:
        yield
    finally:
        _note_sinks.remove(sink)
