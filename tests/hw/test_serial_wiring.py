"""The robot file's [robotx] and [roboif] sections: the BumberBot example is wired for both, and a table that does
not fit the controller is refused before anything moves, every problem at once, each with its robot-file line."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from core_helpers import EXAMPLE
from tablebot.diagnostics import TableBotError
from tablebot.formats.table_read import load_table
from tablebot.hw.roboif.wiring import roboif_wiring
from tablebot.hw.robotx.wiring import robotx_wiring
from tablebot.machine import compile_table

pytestmark = [pytest.mark.realtime]

if TYPE_CHECKING:
    from collections.abc import Callable

ROBOT = (EXAMPLE / "robot.toml").read_text(encoding="utf-8")


def wire(tmp_path: Path, section: str, body: str, extra: str = "") -> Path:
    """The BumberBot whose robot file has only ``[section]`` with ``body`` (the other wirings cut off)."""
    core = ROBOT[: ROBOT.index("[txt]")]
    (tmp_path / "table.csv").write_text((EXAMPLE / "table.csv").read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "robot.toml").write_text(extra + core + f"[{section}]\n" + body, encoding="utf-8")
    return tmp_path / "robot.toml"


def errors_of(action: Callable[[], object]) -> list[str]:
    with pytest.raises(TableBotError) as info:
        action()
    return [d.render() for d in info.value.diagnostics]


def line_of(path: Path, needle: str, after: str = "") -> int:
    """The line of ``needle``'s first appearance after ``after``."""
    text = path.read_text(encoding="utf-8")
    return text[: text.index(needle, text.index(after))].count("\n") + 1


def test_the_bumberbot_example_is_wired_for_both_controllers_as_the_document_says() -> None:
    machine = compile_table(load_table(EXAMPLE / "table.csv"))
    tx, rif = robotx_wiring(machine), roboif_wiring(machine)
    for wired in (tx.wired, rif.wired):
        assert [(w.name, w.terminal, w.mode) for w in wired.inputs] == [
            ("I3", "I3", "switch"),
            ("I4", "I4", "switch"),
            ("I5", "I5", "switch"),
            ("I7", "I7", "phototransistor"),
            ("I8", "I8", "phototransistor"),
        ]
        assert [(w.name, w.terminal) for w in wired.outputs] == [("M1", "M1"), ("M2", "M2")]
    assert tx.duty((4, -8)) == [256, 0, 0, 512, 0, 0, 0, 0]
    assert rif.outputs((4, -8)) == (0b1001, [3, 3, 7, 7, 0, 0, 0, 0])


def test_every_mistake_of_a_robotx_section_is_reported_at_its_line(tmp_path: Path) -> None:
    body = (
        'I3 = { terminal = "I9", mode = "switch", pressed = 1 }\n'
        'I4 = { terminal = "I4", mode = "switch" }\n'
        'I5 = { terminal = "I5", mode = "trail", pressed = 1 }\n'
        'I7 = { terminal = "I4", mode = "phototransistor", lit = 1 }\n'
        'I8 = { terminal = "I8", mode = "resistance", below = 6000 }\n'
        'M1 = "m1"\nM2 = "M1"\nM9 = "M2"\n'
    )
    path = wire(tmp_path, "robotx", body)
    found = errors_of(lambda: compile_table(load_table(tmp_path / "table.csv")))
    expect = {
        "I3 =": "the ROBO TX Controller has no input terminal 'I9'",
        "I4 =": "pressed = 1 or pressed = 0",
        "I5 =": "mode must be one of",
        "I7 =": "terminal I4 is already used by I4",
        "I8 =": "below must be a whole number 0..4999 (ohm)",
        "M1 =": "case-sensitive: write 'M1'",
        "M9 =": "which robot BumberBot does not have",
    }
    for needle, message in expect.items():
        at = f"robot.toml:{line_of(path, needle, '[robotx]')}:"
        assert any(at in e and message in e for e in found), (needle, found)


def test_a_roboif_section_refuses_what_the_interface_lacks_and_a_tick_it_cannot_keep(tmp_path: Path) -> None:
    body = (
        'I3 = { terminal = "AX", mode = "switch", pressed = 1 }\n'
        'I4 = { terminal = "I4", mode = "ultrasonic", below = 20 }\n'
        'I5 = { terminal = "A1", mode = "voltage", above = 2000 }\n'
        'I7 = { terminal = "D1", mode = "distance", below = 300 }\n'
        'M1 = "M1"\nM2 = "M2"\n'
    )
    path = wire(tmp_path, "roboif", body)
    found = errors_of(lambda: compile_table(load_table(tmp_path / "table.csv")))
    assert any(f":{line_of(path, 'I3 =', '[roboif]')}:" in e and "terminals for this are I1" in e for e in found), found
    modes = "mode must be one of switch, phototransistor, resistance, voltage, distance"
    assert any(f":{line_of(path, 'I4 =', '[roboif]')}:" in e and modes in e for e in found), found
    assert any(f":{line_of(path, 'I5 =', '[roboif]')}:" in e and "0..1023" in e for e in found), found
    fast = wire(
        tmp_path,
        "roboif",
        'I3 = { terminal = "I3", mode = "switch", pressed = 1 }\n'
        'I4 = { terminal = "I4", mode = "switch", pressed = 1 }\nI5 = { terminal = "I5", mode = "switch", '
        'pressed = 1 }\nI7 = { terminal = "D1", mode = "distance", below = 300 }\n'
        'I8 = { terminal = "A2", mode = "voltage", above = 512 }\nM1 = "M1"\nM2 = "M2"\n',
    )
    fast.write_text(fast.read_text(encoding="utf-8").replace("tick_ms = 10", "tick_ms = 5"), encoding="utf-8")
    found = errors_of(lambda: roboif_wiring(compile_table(load_table(tmp_path / "table.csv"))))
    assert any(f"robot.toml:{line_of(fast, 'tick_ms')}:" in e and "38400 baud" in e for e in found), found
