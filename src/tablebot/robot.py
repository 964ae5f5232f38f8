"""The robot description a table runs on: its inputs, motors, counters and lamps, start state and tick.

It lives in a small TOML file beside the table (``NAME.toml`` or ``robot.toml``); the document's
BumberBot is built in so that the seed table reads with no side file at all.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tablebot.diagnostics import Collector
from tablebot.tomlfile import read_toml

StateId = int | str

#: Sections of a robot file that belong to other stages (simulator, checker, hardware);
#: the core keeps them as plain data and does not interpret them.
FOREIGN_SECTIONS = ("sim", "wiring", "properties", "board")
KNOWN_KEYS = ("name", "tick_ms", "initial_state", "initial_timer", "inputs", "motors",
              "counters", "lamps", "states", *FOREIGN_SECTIONS)
NAME_RE = re.compile(r"^[A-Za-z][A-Za-z0-9]*$")
RESERVED_NAMES = {"T", "description", "state", "timer", "next"}
#: Header names the table parser reads case-insensitively as fixed columns (aliases included).
RESERVED_LOWER = {"description", "desc", "state", "st", "timer", "next"}


@dataclass(frozen=True)
class Counter:
    """A count-down register loaded by a row and decremented by the pulses of one motor's encoder."""

    name: str
    motor: str


@dataclass(frozen=True)
class Robot:
    """Names and start conditions of one robot; the table's columns must come from these names."""

    name: str
    inputs: tuple[str, ...]
    motors: tuple[str, ...]
    counters: tuple[Counter, ...] = ()
    lamps: tuple[str, ...] = ()
    initial_state: StateId = 1
    initial_timer: int = 0
    tick_ms: int = 10
    labels: dict[str, str] = field(default_factory=dict, compare=False)
    state_names: dict[StateId, str] = field(default_factory=dict, compare=False)
    sections: dict[str, Any] = field(default_factory=dict, compare=False)
    source: str = "built-in"
    #: Line in the robot file of ``initial_state`` and of each ``[states]`` entry, for error messages.
    lines: dict[str, int] = field(default_factory=dict, compare=False)

    @property
    def counter_names(self) -> tuple[str, ...]:
        return tuple(c.name for c in self.counters)


BUMBERBOT = Robot(
    name="BumberBot",
    inputs=("I3", "I4", "I5", "I7", "I8"),
    motors=("M1", "M2"),
    initial_state=2,
    initial_timer=0,
    tick_ms=10,
    labels={"I3": "front-right bumper", "I4": "front-left bumper", "I5": "rear bumper",
            "I7": "right phototransistor", "I8": "left phototransistor",
            "M1": "right motor", "M2": "left motor"},
)


def find_robot_file(table_path: Path) -> Path | None:
    """The side file of a table: ``NAME.toml`` beside ``NAME.csv``, else ``robot.toml`` there."""
    for candidate in (table_path.with_suffix(".toml"), table_path.parent / "robot.toml"):
        if candidate.is_file():
            return candidate
    return None


def _key_line(text: str, key: str) -> int | None:
    """Line of ``key = …`` or ``[key]`` in TOML text, for error messages (tomllib keeps no positions)."""
    pattern = re.compile(rf"^\s*(\[\s*{re.escape(key)}\s*\]|\"?{re.escape(key)}\"?\s*=)")
    for number, line in enumerate(text.splitlines(), start=1):
        if pattern.match(line):
            return number
    return None


def _error(out: Collector, line: int | None, message: str, hint: str) -> None:
    """A robot-file problem at the start of its line (TOML keys start lines)."""
    out.error(line, None if line is None else 1, message, hint)


def _names(section: Any, key: str, text: str, out: Collector) -> dict[str, str]:
    """A ``[inputs]``-style table of NAME = "label" pairs (or a list of names)."""
    if section is None:
        return {}
    if isinstance(section, list):
        section = {str(name): "" for name in section}
    if not isinstance(section, dict):
        _error(out, _key_line(text, key), f"[{key}] must be a table of NAME = \"label\"",
                  'for example: I3 = "front-right bumper"')
        return {}
    names: dict[str, str] = {}
    for name, label in section.items():
        _check_name(name, key, text, out)
        names[name] = label if isinstance(label, str) else str(label)
    return names


def _check_name(name: str, key: str, text: str, out: Collector) -> None:
    """Names become column headers, so they must not clash with the fixed columns or suffixes."""
    if not NAME_RE.match(name) or name in RESERVED_NAMES or name.lower() in RESERVED_LOWER:
        _error(out, _key_line(text, name), f"bad {key} name {name!r}",
                  "use a letter then letters/digits (like I3 or M1), not T, state, timer or next")


def _state_id(value: Any) -> StateId:
    """A state as the table parser reads it: digits are the integer state (``"2"`` is state 2)."""
    if isinstance(value, int):
        return value
    text = str(value).strip()
    return int(text) if text.isascii() and text.isdigit() else text


def load_robot(path: Path) -> Robot:
    """Read a robot TOML file, reporting every problem with its line."""
    data, text = read_toml(path, "see the robot file format in the README")
    out = Collector(path)
    for key in data:
        if key not in KNOWN_KEYS:
            _error(out, _key_line(text, key), f"unknown key {key!r}",
                      f"known keys: {', '.join(KNOWN_KEYS)}")
    inputs = _names(data.get("inputs"), "inputs", text, out)
    motors = _names(data.get("motors"), "motors", text, out)
    lamps = _names(data.get("lamps"), "lamps", text, out)
    counters_raw = data.get("counters") or {}
    counters: list[Counter] = []
    if isinstance(counters_raw, dict):
        for name, motor in counters_raw.items():
            _check_name(name, "counters", text, out)
            motor_name = motor.get("motor") if isinstance(motor, dict) else motor
            if motor_name not in motors:
                _error(out, _key_line(text, name),
                          f"counter {name} counts motor {motor_name!r}, which is not in [motors]",
                          f'write {name} = "M1" with a motor name from [motors]')
            counters.append(Counter(name, str(motor_name)))
    else:
        _error(out, _key_line(text, "counters"), "[counters] must be a table of C1 = \"M1\"",
                  "each counter names the motor whose encoder it counts")
    all_names = [*inputs, *motors, *lamps, *(c.name for c in counters)]
    for name in {n for n in all_names if all_names.count(n) > 1}:
        _error(out, _key_line(text, name), f"name {name} is used twice",
                  "inputs, motors, counters and lamps need distinct names")
    if not motors and not lamps:
        out.error(None, None, "the robot has no [motors] and no [lamps]",
                  'add a section like [motors] with M1 = "right motor"')
    tick_ms = data.get("tick_ms", 10)
    if not isinstance(tick_ms, int) or isinstance(tick_ms, bool) or tick_ms <= 0:
        _error(out, _key_line(text, "tick_ms"), f"tick_ms must be a positive integer, not {tick_ms!r}",
                  "the document's engine ticks every 10 ms: tick_ms = 10")
    initial_timer = data.get("initial_timer", 0)
    if not isinstance(initial_timer, int) or not 0 <= initial_timer <= 65535:
        _error(out, _key_line(text, "initial_timer"),
                  f"initial_timer must be an integer 0..65535, not {initial_timer!r}",
                  "the timer counts ticks; 0 means it has expired")
    if "initial_state" not in data:
        out.error(None, None, "initial_state is missing", "add a line like: initial_state = 2")
    states = data.get("states") or {}
    if not isinstance(states, dict):
        _error(out, _key_line(text, "states"), "[states] must be a table of NUMBER = \"name\"",
               'for example: 20 = "collision"')
    out.raise_if_any()
    return Robot(
        name=str(data.get("name", path.stem)),
        inputs=tuple(inputs), motors=tuple(motors), lamps=tuple(lamps), counters=tuple(counters),
        initial_state=_state_id(data["initial_state"]), initial_timer=initial_timer, tick_ms=tick_ms,
        labels={**inputs, **motors, **lamps},
        state_names={_state_id(k): str(v) for k, v in states.items()},
        sections={k: data[k] for k in FOREIGN_SECTIONS if k in data},
        source=str(path),
        lines={key: line for key in ("initial_state", *map(str, states))
               if (line := _key_line(text, key)) is not None},
    )
