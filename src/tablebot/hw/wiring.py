"""A controller's wiring section of the robot file (``[txt]``, ``[robotx]``, ``[roboif]``): which terminal each
input, motor, lamp and counter of the table is wired to, how each input measures and what the table reads.
One reader for every controller, driven by what the controller offers (:class:`Terminals`)::

    [robotx]
    I3 = { terminal = "I3", mode = "switch", pressed = 1 }       # the table reads 1 while pressed
    I7 = { terminal = "I7", mode = "phototransistor", lit = 1 }  # ... 1 while it sees light
    US = { terminal = "I1", mode = "ultrasonic", below = 20 }    # ... 1 closer than 20 cm
    M1 = "M1"                                                    # or { terminal = "M1", reverse = true }
    L1 = "O5"
    C1 = "C1"

A table that needs something the controller cannot give is refused before anything moves (before the
controller is even opened), every problem at once, each with its robot-file line. What a controller offers and
the wiring read are the types of :mod:`tablebot.hw.terminals`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from tablebot.hw.terminals import (
    DIGITAL,
    Analog,
    Digital,
    InputWire,
    OutputWire,
    Section,
    Terminals,
    Wiring,
    input_event,
    level_duty,
)
from tablebot.hw.wiring_entries import KINDS, EntryReader, error
from tablebot.i18n import N_
from tablebot.tomlfile import Source

if TYPE_CHECKING:  # read when a robot file is: only what the section needs is imported
    from tablebot.machine import Machine
    from tablebot.robot import Robot

#: The reader's own names, and the types of :mod:`tablebot.hw.terminals` that every controller's wiring reaches
#: through this module.
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
    "read_section",
    "suggest",
    "wiring_for",
]


def read_section(spec: Terminals, src: Source, section: Any, robot: Robot) -> Section:
    """The robot file's section for ``spec`` (a robot-file section reader): errors go to ``src`` with their
    lines; an entry with a mistake is left out."""
    found = Section({}, {}, {})
    if not isinstance(section, dict):
        error(
            src,
            src.line("", None, spec.section),
            N_("[{section}] must be a table of NAME = terminal", section=spec.section),
            N_("for example: {example}", example='M1 = "M1"'),
        )
        return found
    reader = EntryReader(spec, robot, src, section)
    for name in section:
        into: dict[str, Any]
        if name in robot.inputs:
            wired: Any = reader.input(name)
            into = found.inputs
        elif name in robot.motors or name in robot.lamps:
            wired, into = reader.output(name), found.outputs
        elif name in robot.counter_names:
            wired, into = reader.terminal(name, "counter", section[name]), found.counters
        else:
            reader.error(
                name,
                N_(
                    "[{section}] wires {name!r}, which robot {robot} does not have",
                    section=spec.section,
                    name=name,
                    robot=robot.name,
                ),
                N_("wire the robot's inputs, motors, lamps and counters (names from the robot file)"),
            )
            continue
        if wired is not None:
            into[name] = wired
    return found


def wiring_for(spec: Terminals, machine: Machine) -> Wiring:
    """The wiring of the table's robot, checked against what the table needs (every input it reads, every
    motor, lamp and counter; a tick the controller can keep); every problem at once, with its line."""
    robot = machine.table.robot
    src = robot.file_source()
    section = robot.sections.get(spec.section)
    if section is None:
        error(
            src,
            None,
            N_(
                "robot {robot} has no [{section}] section: tablebot does not know how it is wired to the {controller}",
                robot=robot.name,
                section=spec.section,
                controller=spec.controller,
            ),
            N_("add one to the robot file, for example:\n{section}", section=suggest(spec, robot, machine)),
        )
        for name in robot.counter_names if not spec.counters else ():
            _unwired(spec, src, robot, "counter", name)
        src.raise_if_any()
    if not isinstance(section, Section):  # a Robot made in code, holding the section's raw data
        section = read_section(spec, src, section, robot)
        src.raise_if_any()
    wired = {**section.inputs, **section.outputs, **section.counters}
    for kind, names in (
        ("input", machine.input_bits),
        ("motor", robot.motors),
        ("lamp", robot.lamps),
        ("counter", robot.counter_names),
    ):
        for name in names:
            if name not in wired:
                _unwired(spec, src, robot, kind, name)
    if robot.tick_ms < spec.min_tick_ms:
        error(
            src,
            robot.line("", "tick_ms"),
            N_(
                "tick_ms = {tick} is shorter than the {controller} can keep ({reason})",
                tick=robot.tick_ms,
                controller=spec.controller,
                reason=spec.tick_reason,
            ),
            N_("use tick_ms = {least} or more to run on it", least=spec.min_tick_ms),
        )
    src.raise_if_any()
    inputs = tuple(section.inputs[name] for name in machine.input_bits)
    return Wiring(
        inputs,
        tuple(machine.input_bits[w.name] for w in inputs),
        tuple(section.outputs[name] for name in machine.output_names),
        tuple(section.counters[name] for name in robot.counter_names),
    )


def _unwired(spec: Terminals, src: Source, robot: Robot, kind: str, name: str) -> None:
    if kind == "counter" and not spec.counters:
        error(
            src,
            robot.line("counters", name) or src.line(spec.section),
            N_("counter {name}: the {controller} has no counter inputs", name=name, controller=spec.controller),
            N_("run this table on a controller with counters (ROBO TX, TXT)"),
        )
        return
    first = spec.names(kind)[0]
    example = (
        f'{name} = {{ terminal = "{first}", mode = "switch", pressed = 1 }}'
        if kind == "input"
        else f'{name} = "{first}"'
    )
    error(
        src,
        robot.line(f"{kind}s", name) or src.line(spec.section),
        N_(
            "{kind} {name} is used by the table but not wired to the {controller}",
            kind=KINDS[kind],
            name=name,
            controller=spec.controller,
        ),
        N_("add it to [{section}], for example: {example}", section=spec.section, example=example),
    )


def suggest(spec: Terminals, robot: Robot, machine: Machine) -> str:
    """A section for ``robot`` (names that are terminals keep them; inputs as push-buttons)."""
    lines = [f"[{spec.section}]"]
    free = {kind: list(spec.names(kind)) for kind in ("input", "motor", "lamp", "counter")}
    free["input"] = list(spec.digital_inputs)
    for kind, names in (
        ("input", machine.input_bits),
        ("motor", robot.motors),
        ("lamp", robot.lamps),
        ("counter", robot.counter_names if spec.counters else ()),
    ):
        for name in names:
            terminal = name if name in free[kind] else (free[kind][0] if free[kind] else "?")
            if terminal in free[kind]:
                free[kind].remove(terminal)
            lines.append(
                f'{name} = {{ terminal = "{terminal}", {_suggested_mode(spec, robot, name)} }}'
                if kind == "input"
                else f'{name} = "{terminal}"'
            )
    return "\n".join(f"        {line}" for line in lines)


def _suggested_mode(spec: Terminals, robot: Robot, name: str) -> str:
    """The digital mode an input's label suggests (the controller's last, most specific, whose words it has)."""
    label = robot.labels.get(name, "").lower()
    mode = next((m for m, d in reversed(spec.digital_modes.items()) if any(w in label for w in d.words)), "switch")
    return f'mode = "{mode}", {spec.digital_modes[mode].key} = 1'
