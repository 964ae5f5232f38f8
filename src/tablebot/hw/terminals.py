"""What a controller offers its wiring section and what a wiring is (:mod:`tablebot.hw.wiring` reads the section):
the controller's :class:`Terminals` and input modes, an input's :class:`InputWire` and the rule by which the table
reads it (:func:`input_event`), a motor's or lamp's :class:`OutputWire`, a section as written (:class:`Section`)
and a table's signals on a controller (:class:`Wiring`)."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, TypeVar

from tablebot.i18n import N_
from tablebot.sensors import threshold_event
from tablebot.table import MAX_SPEED

T = TypeVar("T")

__all__ = [
    "DIGITAL",
    "Analog",
    "Digital",
    "InputWire",
    "OutputWire",
    "Section",
    "Terminals",
    "Wiring",
    "input_event",
    "level_duty",
]


@dataclass(frozen=True)
class Digital:
    """A digital mode: the robot file says with ``key`` what the table reads ``meaning``."""

    key: str  # "pressed"
    device: str  # what is wired, for hints: "a push-button"
    meaning: str  # "while the push-button is pressed"
    reports: int = 1  # the controller's reading while so (a track sensor's over the line is 0)
    words: tuple[str, ...] = ()  # words of an input's label that suggest this mode for a section to paste


#: The digital modes every controller offers (a controller may add its own: :attr:`Terminals.digital_modes`)
DIGITAL = {
    "switch": Digital("pressed", N_("a push-button"), N_("while the push-button is pressed")),
    "phototransistor": Digital(
        "lit", N_("a phototransistor"), N_("while the phototransistor sees light"), words=("photo", "light")
    ),
}


@dataclass(frozen=True)
class Analog:
    """An analog mode: its unit, the largest value, and the terminals that can measure it."""

    unit: str
    most: int
    terminals: tuple[str, ...]


@dataclass(frozen=True)
class Terminals:
    """What a controller offers its wiring section."""

    section: str  # the robot file's section: "robotx"
    controller: str  # how messages name it: "ROBO TX Controller"
    digital_inputs: tuple[str, ...]  # terminals an input in a digital mode can be wired to
    analog: dict[str, Analog]  # mode -> what it measures and where
    motors: tuple[str, ...]
    lamps: tuple[str, ...]
    counters: tuple[str, ...]
    min_tick_ms: int
    tick_reason: str  # why a shorter tick cannot be kept
    distance_mode: str | None = None  # the analog mode a [sensors] distance declaration is read in (for hints;
    #                                   which modes read a kind's threshold is the kind's: SensorKind.modes)
    digital_modes: dict[str, Digital] = field(default_factory=lambda: dict(DIGITAL))

    @property
    def inputs(self) -> tuple[str, ...]:
        extra = [t for a in self.analog.values() for t in a.terminals if t not in self.digital_inputs]
        return (*self.digital_inputs, *dict.fromkeys(extra))

    @property
    def modes(self) -> tuple[str, ...]:
        return (*self.digital_modes, *self.analog)

    def names(self, kind: str) -> tuple[str, ...]:
        return {"input": self.inputs, "motor": self.motors, "lamp": self.lamps, "counter": self.counters}[kind]


def level_duty(level: int, most: int) -> int:
    """A motor's speed (its size) or a lamp's level, 0..8, as ``most`` / 8 per level (a level beyond 8 is 8, one
    below 0 is off): the scaling of the controllers whose outputs take 0..``most`` in eight equal steps (the TXT
    and TXT 4.0's PWM and the ROBO TX's duty, both 0..512). The ROBO Interface's is its own
    (``hw.roboif.wiring.level_pwm``)."""
    return max(0, min(MAX_SPEED, level)) * (most // MAX_SPEED)


@dataclass(frozen=True)
class InputWire:
    """A table input on ``terminal``. A digital one reads what the controller reports (``invert`` flips it);
    an analog one compares against ``below`` or ``above``, with a hysteresis."""

    name: str
    terminal: str
    mode: str
    digital: bool
    invert: bool = False
    below: int | None = None
    above: int | None = None
    hysteresis: int = 0

    def reads(self, raw: int, was_on: bool = False) -> int:
        """What the table sees (0/1) for the controller's value (``was_on``: last tick's, for the hysteresis)."""
        return input_event(self, raw, was_on)


def input_event(wire: Any, raw: int, was_on: bool) -> int:
    """What the table sees (0/1) for a controller input's value, every controller's rule: a digital input
    is its value (inverted when the wiring says so); an analog one goes through the threshold with
    hysteresis (``sensors.threshold_event``) of its ``below`` or ``above`` limit; one with neither reads 0.
    ``wire`` is any controller's input wire (``digital``, ``invert``, ``below``, ``above``, ``hysteresis``)."""
    if wire.digital:
        return int(bool(raw)) ^ int(wire.invert)
    if wire.below is not None:
        return int(threshold_event(raw, False, wire.below, wire.below + wire.hysteresis, was_on))
    if wire.above is not None:
        return int(threshold_event(raw, True, wire.above, wire.above - wire.hysteresis, was_on))
    return 0


@dataclass(frozen=True)
class OutputWire:
    """A motor on ``terminal`` (``M1``: forward on its first output) or a lamp on a single output (``O5``)."""

    name: str
    kind: str  # "motor" or "lamp"
    terminal: str
    reverse: bool = False


@dataclass(frozen=True)
class Section:
    """The section as the robot file says it, checked on its own; :func:`wiring_for` checks it against a table."""

    inputs: dict[str, InputWire]
    outputs: dict[str, OutputWire]
    counters: dict[str, str]  # name -> terminal


@dataclass(frozen=True)
class Wiring:
    """A table's signals on a controller: inputs with their event bits, outputs in the engine's order,
    counter terminals in the robot's order."""

    inputs: tuple[InputWire, ...]
    bits: tuple[int, ...]
    outputs: tuple[OutputWire, ...]
    counters: tuple[str, ...]

    def mask(self, values: dict[str, int], previous: int = 0) -> int:
        """The engine's input bits for the controller's values by terminal (``previous``: last tick's bits)."""
        mask = 0
        for inp, bit in zip(self.inputs, self.bits, strict=True):
            if inp.reads(values[inp.terminal], bool(previous & bit)):
                mask |= bit
        return mask

    def raw(self, values: dict[str, int]) -> dict[str, int]:
        """The measured value of each analog input (for the trace)."""
        return {f"{inp.name}_raw": values[inp.terminal] for inp in self.inputs if not inp.digital}

    def levels(self, outputs: Sequence[int]) -> dict[str, int]:
        """Each output's signed level by terminal: a motor's speed -8..8 (``reverse`` applied), a lamp's 0..8."""
        return {
            out.terminal: -value if out.reverse else value for out, value in zip(self.outputs, outputs, strict=True)
        }

    def motor_pairs(self, pairs: int) -> tuple[bool, ...]:
        """Per output pair (O1 and O2, O3 and O4, ...) whether it drives a motor: every pair without a lamp."""
        lamp_pairs = {(int(o.terminal[1:]) - 1) // 2 for o in self.outputs if o.kind == "lamp"}
        return tuple(i not in lamp_pairs for i in range(pairs))

    def input_modes(self, terminals: Sequence[str], modes: Mapping[str, T], unused: T) -> list[T]:
        """Each input terminal's setting, in ``terminals``' order: its wired input's mode's, else ``unused``."""
        found = [unused] * len(terminals)
        for inp in self.inputs:
            found[terminals.index(inp.terminal)] = modes[inp.mode]
        return found

    def output_values(self, outputs: Sequence[int], count: int, value: Callable[[int], int]) -> list[int]:
        """O1..O``count`` for the engine's outputs: a lamp's ``value(level)`` on its output, motor Mn's
        ``value(speed)`` on O(2n-1) forward or O(2n) backward (the other output 0)."""
        found = [0] * count
        for terminal, level in self.levels(outputs).items():
            index = int(terminal[1:]) - 1
            if terminal[0] == "O":
                found[index] = value(level)
            elif level:
                found[2 * index + (level < 0)] = value(abs(level))
        return found
