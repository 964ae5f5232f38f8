"""The robot file's ``[txt]`` section: which TXT terminal each input, motor, lamp and counter of the table
is wired to, how each input measures, and what the table reads (a switch's polarity is stated, not guessed).

::

    [txt]
    I3 = { terminal = "I3", mode = "switch", pressed = 1 }        # the table reads 1 while pressed
    I7 = { terminal = "I7", mode = "phototransistor", lit = 1 }   # ... 1 while it sees light
    I1 = { terminal = "I1", mode = "trail", dark = 1 }            # ... 1 over the dark line
    US = { terminal = "I1", mode = "ultrasonic", below = 20 }     # ... 1 closer than 20 cm
    M1 = "M1"                                                     # or { terminal = "M1", reverse = true }
    C1 = "C1"
    L1 = "O5"

A table that needs something the controller cannot give is refused here, before anything moves,
with the robot-file line to fix.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from tablebot.hw.txt import protocol as wire
from tablebot.hw.wiring import input_event, level_duty
from tablebot.tomlfile import Source

if TYPE_CHECKING:  # read when a robot file is: only what the section needs is imported
    from tablebot.machine import Machine
    from tablebot.robot import Robot
    from tablebot.sensors import Sensor

MIN_TICK_MS = 10  # the TXT answers one exchange every 10 ms: a shorter tick cannot be kept


def level_pwm(level: int) -> int:
    """A motor's speed (its size) or a lamp's level, 0..8, as the TXT family's PWM 0..512 (a level beyond 8 is 8,
    one below 0 is off; :func:`tablebot.hw.wiring.level_duty`): THE scaling of the TXT and the TXT 4.0, whose
    standalone program carries a copy that ``tests/test_rules.py`` proves equal to this one."""
    return level_duty(level, wire.MAX_PWM)


#: mode -> (the controller's input mode (digital), the polarity key, its meaning, the controller's reading
#: then). A track sensor is read in digital voltage mode, 1 over a light floor and 0 over the dark line, as
#: ftrobopy's ``trailfollower`` reads it (ftrobopy.py) and ftrobopy_server maps mode (0, digital) to
#: ``ft::TrailFollower``; ROBO Pro Coding's ``create_trail_follower(...).get_state()`` reads 0 on the line
#: (fischertechnik's FTS program, ORBIS-Modellfabrik ``integrations/TXT-FTS/.../lib/line_follower.py``).
DIGITAL_MODES = {
    "switch": (wire.InputMode.RESISTANCE, "pressed", "while the push-button is pressed", 1),
    "phototransistor": (wire.InputMode.RESISTANCE, "lit", "while the phototransistor sees light", 1),
    "trail": (wire.InputMode.VOLTAGE, "dark", "while the track sensor's spot is over the dark line", 0),
}
TRAIL_LIGHT_MV = 600  # ftrobopy: a trail sensor reporting millivolts reads light above 600 mV
#: mode -> (the controller's input mode, unit, largest value)
ANALOG_MODES = {
    "resistance": (wire.InputMode.RESISTANCE, "ohm", 15000),
    "voltage": (wire.InputMode.VOLTAGE, "mV", 10000),
    "ultrasonic": (wire.InputMode.ULTRASONIC, "cm", 1024),
}
MODES = (*DIGITAL_MODES, *ANALOG_MODES)
KINDS = {"input": "I", "motor": "M", "lamp": "O", "counter": "C"}
COUNT = {"input": wire.N_INPUTS, "motor": wire.N_MOTORS, "lamp": wire.N_OUTPUTS, "counter": wire.N_COUNTERS}


@dataclass(frozen=True)
class InputWire:
    """One table input on terminal ``I{terminal+1}``. Digital modes read 1 for a closed contact or a lit
    phototransistor; ``invert`` flips that; analog modes compare against ``below`` or ``above``."""

    name: str
    terminal: int
    mode: str
    invert: bool = False
    below: int | None = None
    above: int | None = None
    hysteresis: int = 0  # analog: once on, stays on until the value is this far back past the limit

    @property
    def digital(self) -> bool:
        return self.mode in DIGITAL_MODES

    def config(self) -> wire.InputConfig:
        mode = DIGITAL_MODES[self.mode][0] if self.digital else ANALOG_MODES[self.mode][0]
        return wire.InputConfig(mode, self.digital)

    def reads(self, raw: int, was_on: bool = False) -> int:
        """What the table sees (0/1) for the controller's raw value (``was_on``: what it saw last tick,
        for the hysteresis)."""
        if self.mode == "trail":  # 0/1, or millivolts: as ftrobopy's trailfollower().state() reads it
            return int(raw == 1 or raw > TRAIL_LIGHT_MV) ^ int(self.invert)
        return input_event(self, raw, was_on)


@dataclass(frozen=True)
class OutputWire:
    """A motor on ``M{terminal+1}`` (outputs O(2n-1) forward, O(2n) backward) or a lamp on ``O{terminal+1}``."""

    name: str
    kind: str  # "motor" or "lamp"
    terminal: int
    reverse: bool = False


@dataclass(frozen=True)
class TxtWiring:
    """A table's signals on a TXT: inputs with their event bits, outputs in the engine's order, counters in
    the robot's order."""

    inputs: tuple[InputWire, ...]
    bits: tuple[int, ...]  # event bit of each input (Machine.input_bits)
    outputs: tuple[OutputWire, ...]  # one per engine output (motors, then lamps)
    counters: tuple[int, ...]  # terminal (0..3) of each robot counter

    def config(self) -> wire.Config:
        """UpdateConfig: pairs with a lamp are single outputs, every other pair a motor; unused inputs keep
        the controller's default (digital 5 kOhm)."""
        lamp_pairs = {out.terminal // 2 for out in self.outputs if out.kind == "lamp"}
        inputs = [wire.InputConfig()] * wire.N_INPUTS
        for inp in self.inputs:
            inputs[inp.terminal] = inp.config()
        return wire.Config(motors=tuple(i not in lamp_pairs for i in range(wire.N_MOTORS)), inputs=tuple(inputs))

    def pwm(self, outputs: Sequence[int]) -> list[int]:
        """O1..O8 PWM for the engine's outputs: signed motor speeds -8..8, lamp levels 0..8."""
        pwm = [0] * wire.N_OUTPUTS
        for out, value in zip(self.outputs, outputs, strict=True):
            if out.kind == "lamp":
                pwm[out.terminal] = level_pwm(value)
                continue
            speed = -value if out.reverse else value
            forward, backward = 2 * out.terminal, 2 * out.terminal + 1
            pwm[forward if speed > 0 else backward] = level_pwm(abs(speed))
        return pwm

    def mask(self, universal: Sequence[int], previous: int = 0) -> int:
        """The engine's input bits for one reply's I1..I8 (``previous``: last tick's bits, for hysteresis)."""
        mask = 0
        for inp, bit in zip(self.inputs, self.bits, strict=True):
            if inp.reads(universal[inp.terminal], bool(previous & bit)):
                mask |= bit
        return mask

    def raw(self, universal: Sequence[int]) -> dict[str, int]:
        """The measured value of each analog input (for the trace)."""
        return {f"{inp.name}_raw": universal[inp.terminal] for inp in self.inputs if not inp.digital}


@dataclass(frozen=True)
class TxtSection:
    """``[txt]`` as the robot file says it, checked on its own (terminals the TXT has, each used once, modes
    and polarities stated, names the robot has); :func:`txt_wiring` checks it against a table."""

    inputs: dict[str, InputWire]
    outputs: dict[str, OutputWire]
    counters: dict[str, int]  # name -> terminal 0..3


def read_robot_txt(src: Source, section: Any, robot: Robot) -> TxtSection:
    """The robot file's ``[txt]`` (a reader of :data:`tablebot.robot.SECTION_READERS`): errors go to ``src``
    with their lines; an entry with a mistake is left out."""
    found = TxtSection({}, {}, {})
    if not isinstance(section, dict):
        _error(src, src.line("", None, "txt"), "[txt] must be a table of NAME = terminal", 'for example: M1 = "M1"')
        return found
    reader = _Reader(robot, src, section)
    for name in section:
        if name in robot.inputs:
            wired: Any = reader.input(name)
            into: dict[str, Any] = found.inputs
        elif name in robot.motors or name in robot.lamps:
            wired, into = reader.output(name), found.outputs
        elif name in robot.counter_names:
            wired, into = reader.counter(name), found.counters
        else:
            reader.error(name, f"[txt] wires {name!r}, which robot {robot.name} does not have",
                         "wire the robot's inputs, motors, lamps and counters (names from the robot file)")
            continue
        if wired is not None:
            into[name] = wired
    return found


def txt_wiring(machine: Machine) -> TxtWiring:
    """The ``[txt]`` wiring of the table's robot, checked against what the table needs (every input it
    reads, every motor, lamp and counter; a tick the TXT can keep); every problem at once, with its line."""
    robot = machine.table.robot
    src = robot.file_source()
    section = robot.sections.get("txt")
    if section is None:
        raise_missing(robot, machine)
    if not isinstance(section, TxtSection):  # a Robot made in code, holding the section's raw data
        section = read_robot_txt(src, section, robot)
        src.raise_if_any()
    wired = {**section.inputs, **section.outputs, **section.counters}
    for kind, names in (("input", machine.input_bits), ("motor", robot.motors), ("lamp", robot.lamps),
                        ("counter", robot.counter_names)):
        for name in names:
            if name not in wired:
                _unwired(src, robot, kind, name)
    if robot.tick_ms < MIN_TICK_MS:
        _error(src, robot.line("", "tick_ms"), f"tick_ms = {robot.tick_ms} is shorter than the TXT's exchange "
               f"(one every {MIN_TICK_MS} ms)", f"use tick_ms = {MIN_TICK_MS} or more to run on a TXT")
    src.raise_if_any()
    inputs = tuple(section.inputs[name] for name in machine.input_bits)
    return TxtWiring(inputs, tuple(machine.input_bits[w.name] for w in inputs),
                     tuple(section.outputs[name] for name in machine.output_names),
                     tuple(section.counters[name] for name in robot.counter_names))


def _unwired(src: Source, robot: Robot, kind: str, name: str) -> None:
    """A name the table needs that [txt] does not wire: reported at its line in [inputs], [motors], ..."""
    example = (f'{name} = {{ terminal = "I1", mode = "switch", pressed = 1 }}' if kind == "input"
               else f'{name} = "{KINDS[kind]}1"')
    _error(src, robot.line(f"{kind}s", name) or src.line("txt"), f"{kind} {name} is used by the table but not "
           "wired to the TXT", f"add it to [txt], for example: {example}")


def raise_missing(robot: Robot, machine: Machine) -> None:
    """No ``[txt]`` at all: say so, and offer a section to paste (terminals named like the robot's)."""
    src = robot.file_source()
    _error(src, None, f"robot {robot.name} has no [txt] section: tablebot does not know how it is wired to the TXT",
           "add one to the robot file, for example:\n" + suggest(robot, machine))
    src.raise_if_any()


def suggest(robot: Robot, machine: Machine) -> str:
    """A ``[txt]`` section for ``robot`` (names that are TXT terminals keep them; inputs as push-buttons)."""
    lines = ["[txt]"]
    free = {kind: _names(kind) for kind in KINDS}
    for kind, names in (("input", machine.input_bits), ("motor", robot.motors), ("lamp", robot.lamps),
                        ("counter", robot.counter_names)):
        for name in names:
            terminal = name if name in free[kind] else (free[kind][0] if free[kind] else "?")
            if terminal in free[kind]:
                free[kind].remove(terminal)
            label = robot.labels.get(name, "").lower()
            mode = ('mode = "trail", dark = 1' if "track" in label or "trail" in label
                    else 'mode = "phototransistor", lit = 1' if "photo" in label or "light" in label
                    else 'mode = "switch", pressed = 1')
            lines.append(f'{name} = {{ terminal = "{terminal}", {mode} }}' if kind == "input"
                         else f'{name} = "{terminal}"')
    return "\n".join(f"        {line}" for line in lines)


def _error(src: Source, line: int | None, message: str, hint: str) -> None:
    src.out.error(line, None if line is None else 1, message, hint)


class _Reader:
    """Reads entries of ``[txt]`` one robot name at a time, remembering terminals already taken."""

    def __init__(self, robot: Robot, src: Source, section: dict[str, Any]):
        self.robot, self.src, self.section = robot, src, section
        self.taken: dict[tuple[str, int], str] = {}  # (input/motor/output/counter, terminal) -> name

    def line(self, name: str) -> int | None:
        return self.src.line("txt", None, name) or self.src.line(f"txt.{name}") or self.src.line("txt")

    def error(self, name: str, message: str, hint: str) -> None:
        _error(self.src, self.line(name), message, hint)

    def terminal(self, name: str, kind: str, value: Any) -> int | None:
        """``"I3"`` -> 2 for kind input (M for motors, O for lamps, C for counters), or None after an error."""
        names = _names(kind)
        if value is None:
            self.error(name, f"[txt] {name}: which terminal is it wired to?",
                       f'say it with terminal = "{names[0]}" (one of {names[0]}..{names[-1]})')
            return None
        if not isinstance(value, str):
            self.error(name, f"[txt] {name}: the terminal must be text like {names[0]!r}, not {value!r}",
                       f'write it in quotes: {name} = "{names[0]}"')
            return None
        if value not in names:
            same = [n for n in names if n.lower() == value.strip().lower()]
            hint = (f"terminal names are case-sensitive: write {same[0]!r}" if same
                    else f"the TXT's {kind} terminals are {names[0]}..{names[-1]}")
            self.error(name, f"{kind} {name}: the TXT has no {kind} terminal {value!r}", hint)
            return None
        index = names.index(value)
        space = "output" if kind in ("motor", "lamp") else kind
        needs = [(space, 2 * index), (space, 2 * index + 1)] if kind == "motor" else [(space, index)]
        for used in needs:
            if used in self.taken:
                self.error(name, f"{kind} {name}: terminal {value} is already used by {self.taken[used]}"
                           + (" (a motor drives both outputs of its pair)" if space == "output" else ""),
                           f"give {name} a terminal of its own in [txt]")
                return None
        self.taken.update(dict.fromkeys(needs, name))
        return index

    def input(self, name: str) -> InputWire | None:
        value = self.section[name]
        if not isinstance(value, dict):
            self.error(name, f"[txt] {name} must say its terminal, mode and polarity",
                       f'for example: {name} = {{ terminal = "I3", mode = "switch", pressed = 1 }}')
            return None
        mode = value.get("mode")
        if mode not in MODES:
            self.error(name, f"[txt] {name}: mode must be one of {', '.join(MODES)}, not {mode!r}",
                       'a push-button is mode = "switch", a phototransistor mode = "phototransistor", '
                       'a track sensor mode = "trail"')
            return None
        known = ("terminal", "mode", DIGITAL_MODES[mode][1]) if mode in DIGITAL_MODES else ("terminal", "mode",
                                                                                          "below", "above")
        for key in value:
            if key not in known:
                self.error(name, f"[txt] {name}: unknown key {key!r} for mode {mode!r}", f"keys: {', '.join(known)}")
        terminal = self.terminal(name, "input", value.get("terminal", name if name in _names("input") else None))
        polarity = self._digital(name, mode, value) if mode in DIGITAL_MODES else self._analog(name, mode, value)
        if terminal is None or polarity is None:
            return None
        return InputWire(name, terminal, mode, *polarity)

    def _digital(self, name: str, mode: str, value: dict[str, Any]) -> tuple[bool] | None:
        _, key, meaning, reported = DIGITAL_MODES[mode]
        reads = value.get(key)
        if reads not in (0, 1) or isinstance(reads, bool):
            self.error(name, f"[txt] {name}: say what the table reads {meaning}: {key} = 1 or {key} = 0"
                       + ("" if reads is None else f", not {reads!r}"),
                       f"{key} = 1 is the usual wiring (see docs/controllers.md, 'Input polarity')")
            return None
        return (reads != reported,)

    def _analog(self, name: str, mode: str, value: dict[str, Any]) -> tuple[bool, int | None, int | None, int] | None:
        unit, most = ANALOG_MODES[mode][1], ANALOG_MODES[mode][2]
        limits = {k: value[k] for k in ("below", "above") if k in value}
        declared = next((s for s in self.robot.sensors if s.name == name), None)
        if declared is not None and declared.sensor_kind.units:  # a kind with a threshold
            return self._declared(name, mode, declared, limits)
        if len(limits) != 1:
            self.error(name, f"[txt] {name}: a {mode} input needs exactly one of below = N or above = N ({unit})",
                       f"the table reads 1 while the value is below (or above) N, for example: below = {most // 50}")
            return None
        (key, limit), = limits.items()
        if isinstance(limit, bool) or not isinstance(limit, int) or not 0 <= limit <= most:
            self.error(name, f"[txt] {name}: {key} must be a whole number 0..{most} ({unit}), not {limit!r}",
                       f"for example: {key} = {most // 50}")
            return None
        return (False, limit if key == "below" else None, limit if key == "above" else None, 0)

    def _declared(self, name: str, mode: str, sensor: Sensor, limits: dict[str, Any]
                  ) -> tuple[bool, int | None, int | None, int] | None:
        """Threshold and hysteresis from the input's ``[sensors]`` declaration, the one the simulator
        uses, so the table reads the same on the robot: a distance sensor in ultrasonic mode, in cm."""
        if limits:
            self.error(name, f"[txt] {name}: its threshold is declared in [sensors] ({sensor.describe()})",
                       f"remove {', '.join(limits)} here: the simulator and the TXT read the one declaration")
            return None
        scale = sensor.sensor_kind.modes.get(mode)  # from the declaration's units into the mode's
        if scale is None:
            self.error(name, f"[txt] {name}: a {sensor.model} sensor ({sensor.describe()}) cannot be read in "
                       f"{mode} mode with its declared threshold",
                       'wire a distance sensor as mode = "ultrasonic"; a light sensor as mode = "phototransistor" '
                       "(threshold 1) or give its calibrated threshold in [txt] and drop it from [sensors]")
            return None
        limit, slack = round(sensor.threshold * scale, 6), round(sensor.hysteresis * scale, 6)
        if limit != int(limit) or slack != int(slack):
            self.error(name, f"[txt] {name}: the TXT measures whole centimetres; [sensors] says "
                       f"{sensor.describe()}", "declare the threshold and hysteresis in whole cm")
            return None
        below = sensor.direction == "below"
        return (False, int(limit) if below else None, None if below else int(limit), int(slack))

    def output(self, name: str) -> OutputWire | None:
        kind = "motor" if name in self.robot.motors else "lamp"
        value = self.section[name]
        reverse = False
        if isinstance(value, dict) and kind == "motor":
            for key in value:
                if key not in ("terminal", "reverse"):
                    self.error(name, f"[txt] {name}: unknown key {key!r}", "keys: terminal, reverse")
            reverse = value.get("reverse", False)
            if not isinstance(reverse, bool):
                self.error(name, f"[txt] {name}: reverse must be true or false, not {reverse!r}",
                           "reverse = true swaps the motor's forward and backward")
                reverse = False
            value = value.get("terminal", name if name in _names("motor") else None)
        terminal = self.terminal(name, kind, value)
        return None if terminal is None else OutputWire(name, kind, terminal, reverse)

    def counter(self, name: str) -> int | None:
        return self.terminal(name, "counter", self.section[name])


def _names(kind: str) -> list[str]:
    return [f"{KINDS[kind]}{i + 1}" for i in range(COUNT[kind])]
