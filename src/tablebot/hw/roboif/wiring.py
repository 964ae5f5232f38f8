"""The robot file's ``[roboif]`` section: the table's inputs, motors and lamps on a ROBO Interface's terminals
(read by :mod:`tablebot.hw.wiring`), and what that wiring means on the wire: the output bits and PWM of an
exchange for the engine's outputs, the table's bits for a reply.

The ROBO Interface has digital inputs I1..I8, analog inputs AX, AY (resistance), A1, A2 (voltage) and D1, D2
(distance sensors), each analog value a raw 10-bit number 0..1023 (``lib/roboint.h``), and no counters.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from tablebot.hw import wiring
from tablebot.hw.roboif import protocol as wire
from tablebot.i18n import N_
from tablebot.table import MAX_LAMP, MAX_SPEED
from tablebot.tomlfile import Source

if TYPE_CHECKING:
    from tablebot.machine import Machine
    from tablebot.robot import Robot

INPUTS = tuple(f"I{i + 1}" for i in range(wire.N_INPUTS))
TERMINALS = wiring.Terminals(
    section="roboif",
    controller="ROBO Interface",
    digital_inputs=INPUTS,
    analog={
        "resistance": wiring.Analog("raw 0..1023", 1023, ("AX", "AY")),
        "voltage": wiring.Analog("raw 0..1023", 1023, ("A1", "A2")),
        "distance": wiring.Analog("raw 0..1023", 1023, ("D1", "D2")),
    },
    motors=tuple(f"M{i + 1}" for i in range(wire.N_MOTORS)),
    lamps=tuple(f"O{i + 1}" for i in range(wire.N_OUTPUTS)),
    counters=(),
    min_tick_ms=10,
    tick_reason=N_("libroboint exchanges every 10 ms, and at 38400 baud one exchange already takes 9.9 ms on the wire"),
)


def read_robot_roboif(src: Source, section: Any, robot: Robot) -> wiring.Section:
    """``[roboif]`` (a robot-file section reader)."""
    return wiring.read_section(TERMINALS, src, section, robot)


def roboif_wiring(machine: Machine) -> RoboifWiring:
    """The table's wiring on a ROBO Interface, checked (every problem at once, with its robot-file line)."""
    return RoboifWiring(wiring.wiring_for(TERMINALS, machine))


def level_pwm(level: int) -> int:
    """A speed or lamp level 1..8 as the interface's PWM 0..7 (ROBO Pro's eight speeds on three bits)."""
    return max(0, min(wire.MAX_PWM, level - 1))


class RoboifWiring:
    """A checked wiring and what it means in exchange bytes."""

    def __init__(self, wired: wiring.Wiring) -> None:
        self.wired = wired
        self.counters: tuple[int, ...] = ()

    def outputs(self, outputs: Sequence[int]) -> tuple[int, list[int]]:
        """The output bits (O1..O8) and PWM for the engine's outputs: motor Mn forward on its "A" output
        O(2n-1), backward on "B" O(2n), both outputs given the speed's PWM (as libroboint's SetMotor does)."""
        bits, pwm = 0, [0] * wire.N_OUTPUTS
        for terminal, level in self.wired.levels(outputs).items():
            index = int(terminal[1:]) - 1
            if terminal[0] == "O":
                level = max(0, min(MAX_LAMP, level))
                if level:
                    bits |= 1 << index
                    pwm[index] = level_pwm(level)
            elif level:
                bits |= 1 << (2 * index + (level < 0))
                pwm[2 * index] = pwm[2 * index + 1] = level_pwm(min(MAX_SPEED, abs(level)))
        return bits, pwm

    def values(self, inputs: wire.Inputs) -> dict[str, int]:
        return {**{t: inputs.digital >> i & 1 for i, t in enumerate(INPUTS)}, **inputs.analog}

    def mask(self, inputs: wire.Inputs, previous: int = 0) -> int:
        return self.wired.mask(self.values(inputs), previous)

    def raw(self, inputs: wire.Inputs) -> dict[str, int]:
        return self.wired.raw(self.values(inputs))
