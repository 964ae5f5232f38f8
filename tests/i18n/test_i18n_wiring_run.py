"""A controller's wiring refusals and a run's end in the reader's language (issue 35): hw/wiring.py's messages, the
controllers' words in them (modes, why a tick is too short) and loop's and pacing's reasons are catalog messages,
English as they were, German when shown to a German reader."""

from __future__ import annotations

from pathlib import Path

import pytest

from core_helpers import EXAMPLE
from tablebot.diagnostics import TableBotError
from tablebot.formats.table_read import load_table
from tablebot.hw.txt.wiring import txt_wiring
from tablebot.i18n import Message
from tablebot.loop import Watchdog, run
from tablebot.machine import compile_table
from test_loop import MASKS, ScriptedRobot, bumberbot
from test_txt_wiring import ROBOT


def refusals(tmp_path: Path, robot_text: str, language: str) -> str:
    (tmp_path / "table.csv").write_text((EXAMPLE / "table.csv").read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "robot.toml").write_text(robot_text, encoding="utf-8")
    with pytest.raises(TableBotError) as info:
        txt_wiring(compile_table(load_table(tmp_path / "table.csv")))
    return "\n".join(d.render(language) for d in info.value.diagnostics)


def test_what_the_txt_lacks_is_said_in_german_and_in_english_as_before(tmp_path: Path) -> None:
    text = ROBOT.replace("tick_ms = 10 ", "tick_ms = 5 ").replace(
        'I8 = { terminal = "I8", mode = "phototransistor", lit = 1 }\n', ""
    )
    german = refusals(tmp_path, text, "de")
    assert "Fehler: Eingang I8 wird von der Tabelle benutzt, ist aber nicht mit dem TXT verdrahtet" in german
    assert 'Tipp: in [txt] ergänzen, zum Beispiel: I8 = { terminal = "I1", mode = "switch", pressed = 1 }' in german
    assert (
        "tick_ms = 5 ist kürzer, als der TXT halten kann (er beantwortet einen Austausch alle 10 ms)\n"
        "    Tipp: tick_ms = 10 oder mehr verwenden, um darauf zu laufen"
    ) in german
    english = refusals(tmp_path, text, "en")
    assert "error: input I8 is used by the table but not wired to the TXT" in english
    assert "tick_ms = 5 is shorter than the TXT can keep (it answers one exchange every 10 ms)" in english


def test_a_bad_mode_lists_the_controllers_devices_in_german(tmp_path: Path) -> None:
    text = ROBOT.replace(
        'I3 = { terminal = "I3", mode = "switch", pressed = 1 }',
        'I3 = { terminal = "I3", mode = "button", pressed = 1 }',
    )
    german = refusals(tmp_path, text, "de")
    assert (
        "[txt] I3: der Modus muss einer von switch, phototransistor, trail, resistance, voltage, ultrasonic sein, "
        "nicht 'button'" in german
    )
    assert (
        'Tipp: ein Taster ist mode = "switch"; ein Fototransistor ist mode = "phototransistor"; ein Spursensor '
        'ist mode = "trail"' in german
    )


def test_a_stalled_tick_ends_the_run_with_a_reason_a_german_reader_reads() -> None:
    end = run(bumberbot(), ScriptedRobot(MASKS, stall_at=4), ticks=100, watchdog=Watchdog(0.05))
    assert end.reason == "watchdog" and isinstance(end.message, Message)
    assert end.message == "a tick's robot I/O took longer than the watchdog's 50 ms"  # the trace's text, English
    assert end.message.render("de") == (
        "die Ein- und Ausgabe eines Takts mit dem Roboter dauerte länger als die 50 ms des Watchdogs"
    )
