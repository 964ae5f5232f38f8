"""Problems found in user files, each with a place (file, line, column), a message and a hint.

Every loader collects all of a file's problems before failing, so a user fixes them in one go.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Diagnostic:
    """One problem: where it is, what it is, and what to do about it."""

    path: str
    line: int | None
    column: int | None
    message: str
    hint: str = ""
    severity: str = "error"

    def location(self) -> str:
        parts = [self.path]
        if self.line is not None:
            parts.append(str(self.line))
            if self.column is not None:
                parts.append(str(self.column))
        return ":".join(parts)

    def render(self) -> str:
        text = f"{self.location()}: {self.severity}: {self.message}"
        if self.hint:
            text += f"\n    hint: {self.hint}"
        return text


class TableBotError(Exception):
    """Raised with every problem of an input; the CLI prints them and exits with code 2."""

    def __init__(self, diagnostics: Iterable[Diagnostic]):
        self.diagnostics = tuple(diagnostics)
        super().__init__("\n".join(d.render() for d in self.diagnostics))


class Collector:
    """Gathers diagnostics for one file so a loader can report all of them at once."""

    def __init__(self, path: str | Path):
        self.path = str(path)
        self.items: list[Diagnostic] = []

    def error(self, line: int | None, column: int | None, message: str, hint: str = "") -> None:
        self.items.append(Diagnostic(self.path, line, column, message, hint))

    def raise_if_any(self) -> None:
        if self.items:
            raise TableBotError(self.items)


def fail(path: str | Path, message: str, hint: str = "", line: int | None = None,
         column: int | None = None) -> TableBotError:
    """Build (not raise) an error with a single diagnostic."""
    return TableBotError([Diagnostic(str(path), line, column, message, hint)])
