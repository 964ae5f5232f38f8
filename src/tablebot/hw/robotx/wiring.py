"""The robot file's ``[robotx]`` section: the table's inputs, motors, lamps and counters on a ROBO TX
Controller's terminals (read by :mod:`tablebot.hw.wiring`), and what that wiring means on the wire:
the TA_CONFIG to send, the duty of O1..O8 for the engine's outputs, the table's bits for a TA_INPUT."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from tablebot.hw import wiring
from tablebot.hw.robotx import protocol as wire
from tablebot.i18n import N_
from tablebot.tomlfile import Source

if TYPE_CHECKING:
    from tablebot.machine import Machine
    from tablebot.robot import Robot

INPUTS = tuple(f"I{i + 1}" for i in range(wire.N_INPUTS))
#: ROBO_TX_FW.h: MODE_U 10 V (mV up to U_MAX 9999), MODE_R 5 kOhm (R_MAX 4999), ultrasonic (cm, up to 1023).
TERMINALS = wiring.Terminals(
    section="robotx",
    controller="ROBO TX Controller",
    digital_inputs=INPUTS,
    analog={
        "resistance": wiring.Analog("ohm", 4999, INPUTS),
        "voltage": wiring.Analog("mV", 9999, INPUTS),
        "ultrasonic": wiring.Analog("cm", 1023, INPUTS),
    },
    motors=tuple(f"M{i + 1}" for i in range(wire.N_MOTORS)),
    lamps=tuple(f"O{i + 1}" for i in range(wire.N_OUTPUTS)),
    counters=tuple(f"C{i + 1}" for i in range(wire.N_COUNTERS)),
    min_tick_ms=10,
    tick_reason=N_("ftMscLib exchanges the transfer area every 10 ms"),
    distance_mode="ultrasonic",
)
MODES = {
    "switch": (wire.InputMode.RESISTANCE, True),
    "phototransistor": (wire.InputMode.RESISTANCE, True),
    "resistance": (wire.InputMode.RESISTANCE, False),
    "voltage": (wire.InputMode.VOLTAGE, False),
    "ultrasonic": (wire.InputMode.ULTRASONIC, False),
}


def read_robot_robotx(src: Source, section: Any, robot: Robot) -> wiring.Section:
    """``[robotx]`` (a robot-file section reader)."""
    return wiring.read_section(TERMINALS, src, section, robot)


def robotx_wiring(machine: Machine) -> RobotxWiring:
    """The table's wiring on a ROBO TX, checked (every problem at once, with its robot-file line)."""
    return RobotxWiring(wiring.wiring_for(TERMINALS, machine))


class RobotxWiring:
    """A checked wiring and what it means in fish.X1 payloads."""

    def __init__(self, wired: wiring.Wiring) -> None:
        self.wired = wired
        self.counters = tuple(TERMINALS.counters.index(c) for c in wired.counters)

    def config(self) -> wire.Config:
        """TA_CONFIG: pairs with a lamp are single outputs, every other pair a motor; unused inputs stay
        digital 5 kOhm (as fttxpy configures them); counters in mode 1."""
        inputs = self.wired.input_modes(INPUTS, MODES, (wire.InputMode.RESISTANCE, True))
        return wire.Config(motors=self.wired.motor_pairs(wire.N_MOTORS), inputs=tuple(inputs))

    def duty(self, outputs: Sequence[int]) -> list[int]:
        """O1..O8 duty for the engine's outputs: motor Mn forward on O(2n-1), backward on O(2n)."""
        return self.wired.output_values(outputs, wire.N_OUTPUTS, lambda level: wiring.level_duty(level, wire.MAX_DUTY))

    def values(self, inputs: wire.Inputs) -> dict[str, int]:
        return dict(zip(INPUTS, inputs.universal, strict=True))

    def mask(self, inputs: wire.Inputs, previous: int = 0) -> int:
        return self.wired.mask(self.values(inputs), previous)

    def raw(self, inputs: wire.Inputs) -> dict[str, int]:
        return self.wired.raw(self.values(inputs))
