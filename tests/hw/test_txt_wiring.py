"""The robot file's [txt] section: what the table reads, and every way a table that does not fit the TXT is
refused before anything moves, naming the robot-file line."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot.cli import app
from tablebot.diagnostics import TableBotError
from tablebot.formats.table_read import load_table
from tablebot.hw.txt import protocol as wire
from tablebot.hw.txt.wiring import txt_wiring
from tablebot.machine import compile_table
from txt_fake import FakeTxt

pytestmark = [pytest.mark.realtime]

#: The example's robot file up to its [txt] wiring (the other controllers' sections after it are not the TXT's).
FULL = (EXAMPLE / "robot.toml").read_text(encoding="utf-8")
ROBOT = FULL[: FULL.index("\n# The same wiring on the document's own controllers") + 1]
TXT_START = ROBOT.index("[txt]")


def errors(tmp_path: Path, robot_text: str) -> list[str]:
    (tmp_path / "table.csv").write_text((EXAMPLE / "table.csv").read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "robot.toml").write_text(robot_text, encoding="utf-8")
    with pytest.raises(TableBotError) as info:
        txt_wiring(compile_table(load_table(tmp_path / "table.csv")))
    return [d.render() for d in info.value.diagnostics]


def line_of(text: str, needle: str) -> int:
    return text[: text.index(needle)].count("\n") + 1


def test_the_bumberbot_is_wired_as_the_document_says() -> None:
    wiring = txt_wiring(compile_table(load_table(EXAMPLE / "table.csv")))
    assert [(w.name, w.terminal, w.mode) for w in wiring.wired.inputs] == [
        ("I3", "I3", "switch"),
        ("I4", "I4", "switch"),
        ("I5", "I5", "switch"),
        ("I7", "I7", "phototransistor"),
        ("I8", "I8", "phototransistor"),
    ]
    assert [(w.name, w.terminal) for w in wiring.wired.outputs] == [("M1", "M1"), ("M2", "M2")]
    assert wiring.pwm((4, -8)) == [256, 0, 0, 512, 0, 0, 0, 0]
    assert wiring.pwm((0, 0)) == [0] * 8
    closed = [0, 0, 1, 0, 0, 0, 1, 0]  # I3 pressed, I7 lit
    assert wiring.mask(closed) == wiring.wired.bits[0] | wiring.wired.bits[3]
    assert wiring.config() == wire.Config()  # exactly the TXT's default configuration


def test_polarity_and_thresholds_decide_what_the_table_reads(tmp_path: Path) -> None:
    text = ROBOT[:TXT_START] + (
        '[txt]\nI3 = { terminal = "I1", mode = "switch", pressed = 0 }\n'
        'I4 = { terminal = "I2", mode = "ultrasonic", below = 20 }\n'
        'I5 = { terminal = "I3", mode = "voltage", above = 5000 }\n'
        'I7 = { terminal = "I4", mode = "phototransistor", lit = 0 }\n'
        'I8 = { terminal = "I8", mode = "resistance", below = 1000 }\n'
        'M1 = { terminal = "M3", reverse = true }\nM2 = "M4"\n'
    )
    (tmp_path / "table.csv").write_text((EXAMPLE / "table.csv").read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "robot.toml").write_text(text, encoding="utf-8")
    wiring = txt_wiring(compile_table(load_table(tmp_path / "table.csv")))
    i3, i4, i5, i7, i8 = wiring.wired.bits
    assert wiring.mask([0, 100, 0, 1, 0, 0, 0, 2000]) == i3
    assert wiring.mask([1, 19, 5001, 0, 0, 0, 0, 999]) == i4 | i5 | i7 | i8
    assert wiring.config().inputs[1] == wire.InputConfig(wire.InputMode.ULTRASONIC, False)
    assert wiring.config().inputs[2] == wire.InputConfig(wire.InputMode.VOLTAGE, False)
    assert wiring.pwm((3, 2)) == [0, 0, 0, 0, 0, 192, 128, 0]  # M1 reversed on M3 (O5/O6), M2 on M4 (O7/O8)
    assert wiring.raw([0, 19, 5001, 0, 0, 0, 0, 999]) == {"I4_raw": 19, "I5_raw": 5001, "I8_raw": 999}


def check_found(found: list[str], path: Path, expect: list[tuple[int, str, str]]) -> None:
    for line, message, hint in expect:
        assert any(f.startswith(f"{path}:{line}:1: error: {message}") and hint in f for f in found), (message, found)
    assert len(found) == len(expect)


def test_every_mistake_in_the_section_is_reported_at_once_with_its_line_when_the_robot_file_is_read(
    tmp_path: Path,
) -> None:
    text = ROBOT
    for old, new in [
        ('terminal = "I4"', 'terminal = "I9"'),
        ('terminal = "I5", mode = "switch", pressed = 1', 'terminal = "I3", mode = "switch"'),
        ('I8 = { terminal = "I8", mode = "phototransistor", lit = 1 }', 'X1 = "I1"'),
        ('M2 = "M2"', 'M2 = "m1"'),
    ]:
        text = text.replace(old, new)
    found = errors(tmp_path, text)
    check_found(
        found,
        tmp_path / "robot.toml",
        [
            (
                line_of(text, 'I4 = { terminal = "I9"'),
                "input I4: the TXT has no input terminal 'I9'",
                "the TXT's terminals for this are I1, I2, I3, I4, I5, I6, I7, I8",
            ),
            (line_of(text, 'I5 = { terminal = "I3"'), "input I5: terminal I3 is already used by I3", "of its own"),
            (
                line_of(text, 'I5 = { terminal = "I3"'),
                "[txt] I5: say what the table reads while the push-button is pressed",
                "pressed = 1 is the usual wiring",
            ),
            (line_of(text, 'M2 = "m1"'), "motor M2: the TXT has no motor terminal 'm1'", "write 'M1'"),
            (line_of(text, 'X1 = "I1"'), "[txt] wires 'X1', which robot BumberBot does not have", "wire the robot's"),
        ],
    )


def test_what_the_table_needs_and_the_section_lacks_is_reported_with_its_line(tmp_path: Path) -> None:
    text = (
        ROBOT.replace("tick_ms = 10 ", "tick_ms = 5 ")
        .replace('I8 = { terminal = "I8", mode = "phototransistor", lit = 1 }\n', "")
        .replace('M2 = "M2"\n', "")
    )
    check_found(
        errors(tmp_path, text),
        tmp_path / "robot.toml",
        [
            (
                line_of(text, 'I8 = "left phototransistor"'),
                "input I8 is used by the table but not wired to the TXT",
                'I8 = { terminal = "I1", mode = "switch", pressed = 1 }',
            ),
            (line_of(text, 'M2 = "left motor"'), "motor M2 is used by the table but not wired to the TXT", 'M2 = "M1"'),
            (
                line_of(text, "tick_ms = 5"),
                "tick_ms = 5 is shorter than the TXT can keep (it answers one exchange every 10 ms)",
                "use tick_ms = 10 or more",
            ),
        ],
    )


@pytest.mark.parametrize(
    ("entry", "message"),
    [
        ('I3 = "I3"', "[txt] I3 must say its terminal, mode and polarity"),
        (
            'I3 = { terminal = "I3", mode = "button", pressed = 1 }',
            "mode must be one of switch, phototransistor, trail, "
            "resistance, voltage, ultrasonic, not 'button'\n    hint: a push-button is mode = \"switch\"; "
            "a phototransistor "
            'is mode = "phototransistor"; a track sensor is mode = "trail"',
        ),
        ('I3 = { terminal = "I3", mode = "switch", pressed = true }', "pressed = 1 or pressed = 0, not True"),
        ('I3 = { terminal = "I3", mode = "switch", pressed = 1, lit = 1 }', "unknown key 'lit' for mode 'switch'"),
        ('I3 = { terminal = "I3", mode = "ultrasonic" }', "needs exactly one of below = N or above = N (cm)"),
        ('I3 = { terminal = "I3", mode = "ultrasonic", below = 2000 }', "below must be a whole number 0..1024 (cm)"),
        ('I3 = { mode = "switch", pressed = 1, terminal = 3 }', "the terminal must be text like 'I1', not 3"),
    ],
)
def test_a_bad_input_entry_says_what_to_write(tmp_path: Path, entry: str, message: str) -> None:
    text = ROBOT.replace('I3 = { terminal = "I3", mode = "switch", pressed = 1 }', entry)
    (found,) = errors(tmp_path, text)
    assert f":{line_of(text, entry)}:1: error: " in found and message in found, found


def test_a_lamp_cannot_share_a_motors_outputs(tmp_path: Path) -> None:
    text = ROBOT.replace("[motors]", '[lamps]\nL1 = "lamp"\n\n[motors]') + 'L1 = "O2"\n'
    (found,) = errors(tmp_path, text)
    assert "lamp L1: terminal O2 is already used by M1 (a motor drives both outputs of its pair)" in found


def test_a_robot_without_a_txt_section_gets_one_to_paste(tmp_path: Path) -> None:
    (found,) = errors(tmp_path, ROBOT[:TXT_START])
    assert "robot BumberBot has no [txt] section" in found
    assert 'I7 = { terminal = "I7", mode = "phototransistor", lit = 1 }' in found and 'M2 = "M2"' in found
    follower = EXAMPLE.parent / "line-follower"
    robot = (follower / "robot.toml").read_text(encoding="utf-8")
    (tmp_path / "robot.toml").write_text(robot[: robot.index("[txt]")], encoding="utf-8")
    (tmp_path / "table.csv").write_text((follower / "table.csv").read_text(encoding="utf-8"), encoding="utf-8")
    with pytest.raises(TableBotError) as info:  # inputs labelled "track sensor" are offered the trail mode
        txt_wiring(compile_table(load_table(tmp_path / "table.csv")))
    assert 'I2 = { terminal = "I2", mode = "trail", dark = 1 }' in info.value.diagnostics[0].render()


def test_tablebot_run_refuses_before_connecting(tmp_path: Path) -> None:
    (tmp_path / "table.csv").write_text((EXAMPLE / "table.csv").read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "robot.toml").write_text(ROBOT.replace('M2 = "M2"', 'M2 = "M5"'), encoding="utf-8")
    with FakeTxt() as fake:
        result = CliRunner().invoke(app, ["run", str(tmp_path), "--on", f"txt://127.0.0.1:{fake.port}"])
        assert fake.connections == 0  # nothing moved: the controller was never even contacted
    assert result.exit_code == 2 and "motor M2: the TXT has no motor terminal 'M5'" in result.output


def test_declared_distance_sensors_give_the_txt_their_threshold_and_hysteresis() -> None:
    """[sensors] I1 = distance below 25 cm, hysteresis 5 cm; [txt] I1 in ultrasonic mode: the TXT's
    centimetres are read against that one declaration, so the table reads what the simulator reads."""
    from core_helpers import ROOT

    wiring = txt_wiring(compile_table(load_table(ROOT / "examples" / "obstacle-avoider" / "table.csv")))
    right, left = wiring.wired.inputs
    assert (left.below, left.hysteresis) == (25, 5)
    assert (right.mode, right.below, right.hysteresis) == ("ultrasonic", 25, 5)
    bit = wiring.wired.bits[0]
    seen, mask = [], 0
    for cm in (40, 30, 25, 24, 26, 29, 30, 24):  # on below 25; once on, off only from 30
        mask = wiring.mask([cm, 400, 0, 0, 0, 0, 0, 0], mask)
        seen.append(int(bool(mask & bit)))
    assert seen == [0, 0, 0, 1, 1, 1, 0, 1]
    assert wiring.config().inputs[0] == wire.InputConfig(wire.InputMode.ULTRASONIC, False)


@pytest.mark.parametrize(
    "entry, message",
    [
        ('I1 = { terminal = "I1", mode = "ultrasonic", below = 20 }', "its threshold is declared in [sensors]"),
        ('I1 = { terminal = "I1", mode = "voltage" }', "cannot be read in voltage mode"),
    ],
)
def test_a_txt_entry_that_contradicts_the_sensor_declaration_is_refused(
    tmp_path: Path, entry: str, message: str
) -> None:
    from core_helpers import ROOT

    folder = ROOT / "examples" / "obstacle-avoider"
    text = (folder / "robot.toml").read_text(encoding="utf-8")
    text = text.replace('I1 = { terminal = "I1", mode = "ultrasonic" }', entry)
    (tmp_path / "table.csv").write_text((folder / "table.csv").read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "robot.toml").write_text(text, encoding="utf-8")
    with pytest.raises(TableBotError) as info:
        load_table(tmp_path / "table.csv")
    found = [d.render() for d in info.value.diagnostics]
    assert any(message in e and f"robot.toml:{line_of(text, entry)}:" in e for e in found), found


def test_the_line_follower_reads_its_track_sensor_in_digital_voltage_mode() -> None:
    """ftrobopy's trailfollower() configures (voltage, digital) -- ftrobopy_server's ft::TrailFollower --
    and reads 1 for a reported 1 or more than 600 mV (a light floor), else 0 (the dark line)."""
    machine = compile_table(load_table(EXAMPLE.parent / "line-follower" / "table.csv"))
    wiring = txt_wiring(machine)
    assert [(w.name, w.terminal, w.mode, w.invert) for w in wiring.wired.inputs] == [
        ("I1", "I1", "trail", True),
        ("I2", "I2", "trail", True),
    ]
    assert wiring.config().inputs[:3] == (
        wire.InputConfig(wire.InputMode.VOLTAGE, True),
        wire.InputConfig(wire.InputMode.VOLTAGE, True),
        wire.InputConfig(),
    )
    i1, i2 = machine.input_bits["I1"], machine.input_bits["I2"]
    assert wiring.mask([0, 0] + [0] * 6) == i1 | i2  # both spots over the line
    assert wiring.mask([1, 0] + [0] * 6) == i2
    assert wiring.mask([1200, 150] + [0] * 6) == i2  # millivolts, as ftrobopy allows for
    assert wiring.mask([1, 1] + [0] * 6) == 0
    with FakeTxt(lambda n: ([1, 0, 0, 0, 0, 0, 0, 0], [0] * 4), period_s=0) as fake:
        result = CliRunner().invoke(
            app,
            [
                "run",
                str(EXAMPLE.parent / "line-follower"),
                "--on",
                f"txt://127.0.0.1:{fake.port}",
                "--seconds",
                "0.1",
                "--link-timeout",
                "1",
            ],
        )
    assert result.exit_code == 0, result.output
    assert fake.requests("UpdateConfig")[0].fields["inputs"][:3] == [(0, 1), (0, 1), (1, 1)]
    assert fake.requests("ExchangeData")[-2].fields["pwm"][:4] == [3 * 64, 0, 6 * 64, 0]  # line on the right


def test_a_trail_input_says_what_it_reads_over_the_line(tmp_path: Path) -> None:
    robot = ROBOT.replace(
        'I3 = { terminal = "I3", mode = "switch", pressed = 1 }',
        'I3 = { terminal = "I3", mode = "trail", pressed = 1 }',
    )
    found = errors(tmp_path, robot)
    assert any("unknown key 'pressed' for mode 'trail'" in e for e in found), found
    assert any(
        "say what the table reads while the track sensor's spot is over the dark line: dark = 1" in e for e in found
    ), found
