"""The robot file's ``[txt]`` section: the table's inputs, motors, lamps and counters on a TXT's terminals (read by
:mod:`tablebot.hw.wiring`, like every controller's), and what that wiring means on the wire: the UpdateConfig to
send, the PWM of O1..O8 for the engine's outputs, the table's bits for an ExchangeData reply. The TXT 4.0
export reads the same section. Besides the common modes the TXT reads a track sensor::

    [txt]
    I1 = { terminal = "I1", mode = "trail", dark = 1 }            # the table reads 1 over the dark line
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from tablebot.hw import wiring
from tablebot.hw.txt import protocol as wire
from tablebot.i18n import N_
from tablebot.tomlfile import Source

if TYPE_CHECKING:
    from tablebot.machine import Machine
    from tablebot.robot import Robot

INPUTS = tuple(f"I{i + 1}" for i in range(wire.N_INPUTS))
#: A track sensor is read in digital voltage mode, 1 over a light floor and 0 over the dark line, as ftrobopy's
#: ``trailfollower`` reads it (ftrobopy.py) and ftrobopy_server maps mode (0, digital) to ``ft::TrailFollower``;
#: ROBO Pro Coding's ``create_trail_follower(...).get_state()`` reads 0 on the line (fischertechnik's FTS
#: program, ORBIS-Modellfabrik ``integrations/TXT-FTS/.../lib/line_follower.py``).
TRAIL = wiring.Digital(
    "dark",
    N_("a track sensor"),
    N_("while the track sensor's spot is over the dark line"),
    reports=0,
    words=("track", "trail"),
)
TRAIL_LIGHT_MV = 600  # ftrobopy: a trail sensor reporting millivolts reads light above 600 mV
TERMINALS = wiring.Terminals(
    section="txt",
    controller="TXT",
    digital_inputs=INPUTS,
    analog={
        "resistance": wiring.Analog("ohm", 15000, INPUTS),
        "voltage": wiring.Analog("mV", 10000, INPUTS),
        "ultrasonic": wiring.Analog("cm", 1024, INPUTS),
    },
    motors=tuple(f"M{i + 1}" for i in range(wire.N_MOTORS)),
    lamps=tuple(f"O{i + 1}" for i in range(wire.N_OUTPUTS)),
    counters=tuple(f"C{i + 1}" for i in range(wire.N_COUNTERS)),
    min_tick_ms=10,
    tick_reason=N_("it answers one exchange every 10 ms"),
    distance_mode="ultrasonic",
    digital_modes={**wiring.DIGITAL, "trail": TRAIL},
)
#: mode -> the input's UpdateConfig (measuring mode, reported as 0/1)
MODES = {
    "switch": wire.InputConfig(wire.InputMode.RESISTANCE, True),
    "phototransistor": wire.InputConfig(wire.InputMode.RESISTANCE, True),
    "trail": wire.InputConfig(wire.InputMode.VOLTAGE, True),
    "resistance": wire.InputConfig(wire.InputMode.RESISTANCE, False),
    "voltage": wire.InputConfig(wire.InputMode.VOLTAGE, False),
    "ultrasonic": wire.InputConfig(wire.InputMode.ULTRASONIC, False),
}


def level_pwm(level: int) -> int:
    """A motor's speed (its size) or a lamp's level, 0..8, as the TXT family's PWM 0..512 (a level beyond 8 is 8,
    one below 0 is off; :func:`tablebot.hw.wiring.level_duty`): THE scaling of the TXT and the TXT 4.0, whose
    standalone program carries a copy that ``tests/hw/test_rules.py`` proves equal to this one."""
    return wiring.level_duty(level, wire.MAX_PWM)


def trail_light(raw: int) -> int:
    """A track sensor's reading as ftrobopy's ``trailfollower().state()`` reads it: 1 (a light floor) for a
    reported 1 or more than :data:`TRAIL_LIGHT_MV` millivolts, else 0 (the dark line)."""
    return int(raw == 1 or raw > TRAIL_LIGHT_MV)


def read_robot_txt(src: Source, section: Any, robot: Robot) -> wiring.Section:
    """``[txt]`` (a robot-file section reader)."""
    return wiring.read_section(TERMINALS, src, section, robot)


def txt_wiring(machine: Machine) -> TxtWiring:
    """The table's wiring on a TXT, checked (every problem at once, with its robot-file line)."""
    return TxtWiring(wiring.wiring_for(TERMINALS, machine))


class TxtWiring:
    """A checked wiring and what it means in the TXT's online protocol."""

    def __init__(self, wired: wiring.Wiring) -> None:
        self.wired = wired
        self.counters = tuple(TERMINALS.counters.index(c) for c in wired.counters)  # terminal 0..3 of each
        self.trails = {inp.terminal for inp in wired.inputs if inp.mode == "trail"}

    def config(self) -> wire.Config:
        """UpdateConfig: pairs with a lamp are single outputs, every other pair a motor; unused inputs keep
        the controller's default (digital 5 kOhm)."""
        inputs = self.wired.input_modes(INPUTS, MODES, wire.InputConfig())
        return wire.Config(motors=self.wired.motor_pairs(wire.N_MOTORS), inputs=tuple(inputs))

    def pwm(self, outputs: Sequence[int]) -> list[int]:
        """O1..O8 PWM for the engine's outputs: motor Mn forward on O(2n-1), backward on O(2n)."""
        return self.wired.output_values(outputs, wire.N_OUTPUTS, level_pwm)

    def values(self, universal: Sequence[int]) -> dict[str, int]:
        """One reply's I1..I8 by terminal, a track sensor's as its 0/1 (:func:`trail_light`)."""
        return {t: trail_light(v) if t in self.trails else v for t, v in zip(INPUTS, universal, strict=True)}

    def mask(self, universal: Sequence[int], previous: int = 0) -> int:
        """The engine's input bits for one reply's I1..I8 (``previous``: last tick's bits, for hysteresis)."""
        return self.wired.mask(self.values(universal), previous)

    def raw(self, universal: Sequence[int]) -> dict[str, int]:
        return self.wired.raw(self.values(universal))
