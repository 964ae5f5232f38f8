"""What every controller's wiring module asks of a checked wiring (tablebot.hw.terminals.Wiring): which output
pairs drive motors, each input terminal's setting and each output's value. The TXT and the ROBO TX asked it in
their own copies of the same loops (issue 35); their protocol tests (test_txt_robot, test_robotx) hold the bytes."""

from __future__ import annotations

from tablebot.hw.terminals import InputWire, OutputWire, Wiring

INPUTS = tuple(f"I{i + 1}" for i in range(8))
WIRED = Wiring(
    inputs=(InputWire("bumper", "I3", "switch", True), InputWire("eye", "I7", "phototransistor", True)),
    bits=(1, 2),
    outputs=(
        OutputWire("M1", "motor", "M1"),
        OutputWire("M2", "motor", "M2", reverse=True),
        OutputWire("L1", "lamp", "O5"),
    ),
    counters=(),
)


def test_a_lamps_pair_drives_no_motor() -> None:
    assert WIRED.motor_pairs(4) == (True, True, False, True)


def test_each_input_terminal_gets_its_wired_modes_setting_the_others_the_unused_one() -> None:
    modes = WIRED.input_modes(INPUTS, {"switch": "S", "phototransistor": "P"}, "-")
    assert modes == ["-", "-", "S", "-", "-", "-", "P", "-"]


def test_a_motor_drives_its_forward_or_backward_output_and_a_lamp_its_own() -> None:
    # M1 forward at 5 on O1; M2 at 3, reversed, so backward on O4; the lamp at 8 on O5
    assert WIRED.output_values([5, 3, 8], 8, lambda level: 10 * level) == [50, 0, 0, 30, 80, 0, 0, 0]
    assert WIRED.output_values([-2, 0, 0], 8, lambda level: 10 * level) == [0, 20, 0, 0, 0, 0, 0, 0]
