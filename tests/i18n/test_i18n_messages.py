"""The message carried by a diagnostic (tablebot.i18n.Message): English as a string, any language when shown,
the same across processes."""

from __future__ import annotations

import pickle

from tablebot.diagnostics import Diagnostic
from tablebot.i18n import N_, NP_, Message, localise


def test_a_message_is_its_english_text_and_renders_in_german() -> None:
    message = N_("{name} is missing", name=N_("next state"))
    assert message == "next state is missing" and isinstance(message, str)
    assert message.render("de") == "Folgezustand fehlt"
    assert message.render("pseudo") == "⟦⟦next state⟧ is missing⟧"
    assert localise("plain text", "de") == "plain text"  # not a message: as it is


def test_plurals_and_lists() -> None:
    assert NP_("{n} tick", "{n} ticks", 1) == "1 tick" and NP_("{n} tick", "{n} ticks", 3) == "3 ticks"
    assert NP_("{n} tick", "{n} ticks", 3).render("de") == "3 Takte"
    known = N_("known keys: {known}", known=("a", N_("none")))
    assert known == "known keys: a, none" and known.render("de") == "bekannte Schlüssel: a, keine"


def test_a_message_crosses_processes_whole() -> None:
    message = N_("timer: {problem}", problem=N_("{text!r} is not a duration", text="zwei"))
    back = pickle.loads(pickle.dumps(message))
    assert isinstance(back, Message) and back == message and back.render("de") == "Timer: 'zwei' ist keine Zeitangabe"


def test_a_diagnostic_renders_in_the_language_asked_for() -> None:
    found = Diagnostic("t.csv", 3, 7, N_("the table is empty"), N_("check the path"))
    assert found.render() == "t.csv:3:7: error: the table is empty\n    hint: check the path"
    assert found.render("de") == "t.csv:3:7: Fehler: die Tabelle ist leer\n    Tipp: den Pfad prüfen"
