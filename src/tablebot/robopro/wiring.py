"""The robot file's ``[robopro]`` section: which controller the generated ROBO Pro program is for, and which
terminal each of the robot's inputs, motors and counters is wired to.

```toml
[robopro]
controller = "robo-interface"          # the document's; or "tx", "txt"
I3 = "I3"                               # an input's terminal, or { terminal = "I3", active = 0 }
M1 = { output = "M1", forward = "cw" }  # a motor's output, and the command that drives it forward
C1 = "C1"                               # a counter's terminal (ROBO TX and TXT only)
L1 = "O5"                               # a lamp's single output
```

Everything has a default, so the section may be left out: an input named I1…I8, a motor named M1…M4, a
counter named C1…C4 and a lamp named O1…O8 use the terminal of that name; a counter otherwise uses the counter
of its motor's number, and a lamp the single outputs the motors leave free, in order (a motor Mk takes O2k−1 and
O2k); ``active = 1`` (the event is present while the input reads 1) and ``forward = "cw"``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

from tablebot.i18n import N_
from tablebot.robot import Robot
from tablebot.tomlfile import Source

CONTROLLERS = ("robo-interface", "tx", "txt")
TERMINALS = {"input": ("I", 8), "motor": ("M", 4), "counter": ("C", 4), "lamp": ("O", 8)}
#: The kinds of terminal in the reader's words (Eingang, Motor, Zähler, Lampe).
KIND_WORDS = {"input": N_("input"), "motor": N_("motor"), "counter": N_("counter"), "lamp": N_("lamp")}
COMMANDS = ("cw", "ccw")
DEFAULT = object()


@dataclass(frozen=True)
class Wiring:
    """Terminal numbers (1-based) per robot name, plus each input's active level and each motor's
    forward command."""

    controller: str = "robo-interface"
    inputs: dict[str, tuple[int, int]] = field(default_factory=dict)  # name -> (terminal, active level)
    motors: dict[str, tuple[int, str]] = field(default_factory=dict)  # name -> (output, forward command)
    counters: dict[str, int] = field(default_factory=dict)  # name -> counter
    lamps: dict[str, int] = field(default_factory=dict)  # name -> single output O1..O8
    problems: tuple[tuple[str, str, str], ...] = ()  # (robot name, message, hint) of names left unwired


def _terminal(text: Any, kind: str) -> int | None:
    letter, count = TERMINALS[kind]
    match = re.fullmatch(rf"{letter}([1-9])", text) if isinstance(text, str) else None
    return int(match[1]) if match and int(match[1]) <= count else None


def _default(name: str, kind: str, robot: Robot) -> int | None:
    found = _terminal(name, kind)
    if found is None and kind == "counter":
        motor = next((c.motor for c in robot.counters if c.name == name), "")
        found = _terminal(motor.replace("M", "C", 1), kind)
    return found


class _Reader:
    """Reads entries; errors go to the robot file's collector, or (for a robot made in code) to a list."""

    def __init__(self, src: Source | None, robot: Robot) -> None:
        self.src, self.robot = src, robot
        self.errors: list[tuple[str, str, str]] = []

    def error(self, key: str, message: str, hint: str) -> None:
        if self.src is None:
            self.errors.append((key, N_("[robopro] {message}", message=message), hint))
        else:
            self.src.key_error(("robopro", None, key), N_("[robopro] {message}", message=message), hint)

    def entry(self, name: str, value: Any, kind: str, extra: dict[str, tuple[Any, ...]]) -> tuple[int, dict] | None:
        """A terminal (``"I3"``) or a table ``{terminal = "I3", key = value}`` with ``extra``'s keys."""
        letter, count = TERMINALS[kind]
        word = "output" if kind in ("motor", "lamp") else "terminal"
        options: dict[str, Any] = {}
        if isinstance(value, dict):
            unknown = sorted(set(value) - {word, *extra})
            if unknown:
                self.error(
                    name,
                    N_("{name}: unknown key {keys}", name=name, keys=tuple(unknown)),
                    N_("a {kind} takes {keys}", kind=KIND_WORDS[kind], keys=(word, *extra)),
                )
                return None
            options = {k: value[k] for k in extra if k in value}
            value = value.get(word, DEFAULT)
        terminal = _default(name, kind, self.robot) if value is DEFAULT else _terminal(value, kind)
        if terminal is None:
            shown = N_("no terminal") if value is DEFAULT else repr(value)
            self.error(
                name,
                N_(
                    "{name}: {shown} is not a {kind} terminal of the controller",
                    name=name,
                    shown=shown,
                    kind=KIND_WORDS[kind],
                ),
                N_('write {word} = "{letter}1" … "{letter}{count}"', word=word, letter=letter, count=count),
            )
            return None
        for key, allowed in extra.items():
            if key in options and options[key] not in allowed:
                self.error(
                    name,
                    N_(
                        "{name}: {key} = {value!r} is not one of {allowed}",
                        name=name,
                        key=key,
                        value=options[key],
                        allowed=tuple(map(repr, allowed)),
                    ),
                    N_("write {key} = {value!r}", key=key, value=allowed[0]),
                )
                return None
        return terminal, options


def read_robot_robopro(src: Source, section: Any, robot: Robot) -> Wiring:
    """``[robopro]`` of a robot file (a reader of :data:`tablebot.robot.SECTION_READERS`); errors go to
    ``src`` with their lines."""
    if not isinstance(section, dict):
        src.key_error(
            ("", None, "robopro"),
            N_("[robopro] must be a table"),
            N_("for example: {example}", example='controller = "txt"'),
        )
        return wiring_of(robot, {})
    reader = _Reader(src, robot)
    controller = section.get("controller", "robo-interface")
    if controller not in CONTROLLERS:
        reader.error(
            "controller",
            N_("controller = {controller!r} is not one ROBO Pro drives here", controller=controller),
            N_("write controller = one of {known}", known=tuple(map(repr, CONTROLLERS))),
        )
    for name in section:
        if name != "controller" and name not in (*robot.inputs, *robot.motors, *robot.counter_names, *robot.lamps):
            reader.error(
                name,
                N_("wires {name!r}, which robot {robot} does not have", name=name, robot=robot.name),
                N_("wire the robot's inputs, motors, counters and lamps (names from the robot file)"),
            )
    return wiring_of(robot, section, reader, str(controller))


def wiring_of(
    robot: Robot, section: dict[str, Any], reader: _Reader | None = None, controller: str = "robo-interface"
) -> Wiring:
    """The wiring ``section`` says, defaults filled in; names that cannot be wired are listed in
    ``problems`` (mistakes in the section itself go through ``reader``)."""
    inputs: dict[str, tuple[int, int]] = {}
    motors: dict[str, tuple[int, str]] = {}
    counters: dict[str, int] = {}
    lamps: dict[str, int] = {}
    problems: list[tuple[str, str, str]] = []
    reader = reader or _Reader(None, robot)
    extras: dict[str, dict[str, tuple[Any, ...]]] = {
        "input": {"active": (1, 0)},
        "motor": {"forward": COMMANDS},
        "counter": {},
        "lamp": {},
    }
    for kind, names in (
        ("input", robot.inputs),
        ("motor", robot.motors),
        ("counter", robot.counter_names),
        ("lamp", robot.lamps),
    ):
        extra = extras[kind]
        for name in names:
            if name in section:
                got = reader.entry(name, section[name], kind, extra)
            else:  # unwired names are the export's problem, not the robot file's
                terminal = _default(name, kind, robot) if kind != "lamp" else _free_output(name, robot, motors, lamps)
                got = (terminal, {}) if terminal is not None and name not in section else None
            if got is None:
                letter, count = TERMINALS[kind]
                problems.append(
                    (
                        name,
                        f"{kind} {name} is wired to no terminal of the controller",
                        f'add to [robopro]: {name} = "{letter}1" (one of {letter}1…{letter}{count})',
                    )
                )
                continue
            terminal, options = got
            if kind == "input":
                inputs[name] = (terminal, int(options.get("active", 1)))
            elif kind == "motor":
                motors[name] = (terminal, str(options.get("forward", "cw")))
            elif kind == "lamp":
                lamps[name] = terminal
            else:
                counters[name] = terminal
    return Wiring(
        controller if controller in CONTROLLERS else "robo-interface",
        inputs,
        motors,
        counters,
        lamps,
        tuple(problems) + tuple(reader.errors),
    )


def _free_output(name: str, robot: Robot, motors: dict[str, tuple[int, str]], lamps: dict[str, int]) -> int | None:
    """A lamp's default output: O1…O8 by its name, else the first single output no motor and no lamp takes."""
    named = _terminal(name, "lamp")
    if named is not None:
        return named
    taken = {o for output, _ in motors.values() for o in (2 * output - 1, 2 * output)} | set(lamps.values())
    taken |= {t for lamp in robot.lamps if (t := _terminal(lamp, "lamp")) is not None}
    return next((o for o in range(1, 9) if o not in taken), None)


def wiring(robot: Robot) -> Wiring:
    """The robot's ROBO Pro wiring: its ``[robopro]`` section as read with the file, else the defaults."""
    section = robot.sections.get("robopro")
    if isinstance(section, Wiring):
        return section
    section = section if isinstance(section, dict) else {}
    return wiring_of(robot, section, controller=str(section.get("controller", "robo-interface")))
