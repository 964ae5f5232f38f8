"""The server's words in each tab's language (issue 38): a tab tells the studio its language when its WebSocket
opens (``/ws?lang=de``), and every message to it has its :class:`~tablebot.i18n.Message` texts (a diagnostic's
message and hint, a finding, a property's note) rendered in that language, so one studio serves a German and
an English tab at once (the process's own language is the terminal's)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from tablebot.diagnostics import Diagnostic
from tablebot.i18n import LANGUAGES, PSEUDO, Message

__all__ = ["PAGE_PSEUDO", "diagnostics_text", "language_of", "localised"]

#: The page's pseudo-language (lib/words.js): every text between markers; the server's is i18n's PSEUDO.
PAGE_PSEUDO = "qps"


def language_of(asked: str | None) -> str:
    """The language a page asked for (``de``, ``en``, or the pseudo-language ``qps``); anything else English,
    as a page that said nothing (a client of its own) gets."""
    if asked == PAGE_PSEUDO:
        return PSEUDO
    return asked if asked in LANGUAGES else LANGUAGES[0]


def localised(value: Any, language: str) -> Any:
    """``value`` (a message's data: dicts, lists, texts) with every :class:`Message` in it said in ``language``."""
    if isinstance(value, Message):
        return value.render(language)
    if isinstance(value, dict):
        out = {key: localised(item, language) for key, item in value.items()}
        if value.keys() >= DIAGNOSTIC_KEYS and isinstance(value["message"], Message):
            out["text"] = _diagnostic(value).render(language)  # its whole text was said in the terminal's
        return out
    if isinstance(value, list | tuple):
        return [localised(item, language) for item in value]
    return value


#: The fields of a diagnostic in an analysis (web/analyse.py): its ``text`` is said again in the tab's language.
DIAGNOSTIC_KEYS = frozenset({"file", "line", "column", "message", "hint", "severity", "text"})
DETAIL = "    | "  # how Diagnostic.render sets a tool's own output under the message


def _diagnostic(data: dict[str, Any]) -> Diagnostic:
    detail = "\n".join(line[len(DETAIL) :] for line in str(data["text"]).splitlines() if line.startswith(DETAIL))
    return Diagnostic(
        data["file"], data["line"], data["column"], data["message"], data["hint"] or "", data["severity"], detail
    )


def diagnostics_text(diagnostics: Iterable[Diagnostic], language: str) -> str:
    """An error's whole text (file:line:column, message, hint) in ``language``, as the command line prints it."""
    return "\n".join(d.render(language) for d in diagnostics)
