"""The robot description a table runs on: its inputs, motors, counters and lamps, start state and tick.

It lives in a small TOML file beside the table (``NAME.toml`` or ``robot.toml``); the document's
BumberBot is built in so that the seed table reads with no side file at all.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, cast

from tablebot import durations, plugins, robot_names
from tablebot.i18n import N_
from tablebot.robot_names import (
    NAME_RE,
    RESERVED_LOWER,
    RESERVED_NAMES,
    STATE_HINT,
    STATE_RE,
    TOP_KEYS,
    Counter,
    StateId,
)
from tablebot.sensors import Sensor, parse_sensors
from tablebot.tomlfile import Source

__all__ = [
    "BUMBERBOT",
    "CORE_SECTIONS",
    "DEFAULT_MATCH",
    "MATCHES",
    "MATCH_ALWAYS",
    "MATCH_DOCUMENT",
    "MATCH_HINT",
    "MAX_TICK_MS",
    "MAX_TIMER",
    "MISPLACED",
    "NAME_RE",
    "RESERVED_LOWER",
    "RESERVED_NAMES",
    "SECTION_READERS",
    "STATE_HINT",
    "STATE_RE",
    "TOP_KEYS",
    "Counter",
    "Match",
    "Robot",
    "SectionReader",
    "StateId",
    "find_robot_file",
    "load_robot",
    "register_section",
]

CORE_SECTIONS = ("inputs", "motors", "counters", "lamps", "states", "sensors")

#: Reads one section of a robot file that belongs to a later stage: ``(src, data, robot) -> value``, the
#: section checked and typed; problems go to ``src``'s collector with their lines.
SectionReader = Callable[[Source, Any, "Robot"], Any]
#: Sections of a robot file that belong to other stages (``[sim]``, ``[board]``, ``[properties]``, ``[txt]``,
#: ...), each with its reader. The stages register them (:func:`register_section`, called by
#: :func:`tablebot.registry.register` for back-ends), so this module imports none of them; reading a robot
#: file registers the readers of the sections it has first (their modules, named in
#: :data:`tablebot.catalog.SECTIONS`, through :func:`tablebot.plugins.load_sections`); asking the registry
#: registers every one. Every section is read when the file is, so all its mistakes show at once, whichever
#: command runs.
SECTION_READERS: dict[str, SectionReader] = {}


def register_section(name: str, reader: SectionReader) -> None:
    """Let ``[name]`` in a robot file be read by ``reader`` (once per name)."""
    known = SECTION_READERS.get(name)
    if known is not None and known is not reader:
        raise ValueError(f"robot-file section [{name}] has two readers")
    if name in TOP_KEYS or name in CORE_SECTIONS:
        raise ValueError(f"[{name}] is a section of the robot itself")
    SECTION_READERS[name] = reader


#: Sections people write in the wrong file: the hint says where they belong.
MISPLACED = {
    "wiring": N_("the simulator's wiring goes in [sim.wiring] in a robot file ([wiring] is for world files)"),
    **{
        s: N_("simulator parameters go in [sim.{section}] in a robot file", section=s)
        for s in ("body", "motor", "battery", "encoder", "light", "distance", "noise")
    },
}
#: Timer loads and the initial timer are 16-bit tick counts; one tick lasts at most a minute.
MAX_TIMER = 65535
MAX_TICK_MS = 60_000
#: ``match``: what a row that requires no event does on a tick with no event at all (no input reads 1, T
#: absent, no counter at 0). "document": nothing fires, as in the document's engine, which looks a row up
#: only "if an event is detected"; "always": such a row matches every event set, the empty one too.
#: The two matching rules (see below).
Match = Literal["document", "always"]
MATCH_DOCUMENT: Match = "document"
MATCH_ALWAYS: Match = "always"
MATCHES: tuple[Match, ...] = (MATCH_DOCUMENT, MATCH_ALWAYS)
#: A robot file that does not say: tablebot's rule from before the key existed, so that no existing table
#: silently changes (``tablebot check`` says when the choice matters). The built-in BumberBot follows the document.
DEFAULT_MATCH = MATCH_ALWAYS
MATCH_HINT = N_(
    'match = "document": a row that requires no event fires only on a tick with some event, as in the '
    'document\'s engine; match = "always": it fires on every tick, even one with no event at all'
)


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
    #: The matching rule for rows that require no event (MATCHES; see MATCH_DOCUMENT).
    match: Match = DEFAULT_MATCH
    #: What drives each input that is not a plain switch (``[sensors]``; see :mod:`tablebot.sensors`).
    sensors: tuple[Sensor, ...] = ()
    labels: dict[str, str] = field(default_factory=dict, compare=False)
    state_names: dict[StateId, str] = field(default_factory=dict, compare=False)
    sections: dict[str, Any] = field(default_factory=dict, compare=False)
    source: str = "built-in"
    #: The parsed robot file (None for the built-in robot), kept so that every stage can locate
    #: its errors in the file without reading it again.
    toml: Source | None = field(default=None, compare=False, repr=False)

    @property
    def tick_s(self) -> float:
        """One tick in seconds."""
        return durations.seconds(1, self.tick_ms)

    def seconds(self, ticks: float) -> float:
        """``ticks`` ticks in seconds (:func:`tablebot.durations.seconds`)."""
        return durations.seconds(ticks, self.tick_ms)

    @property
    def counter_names(self) -> tuple[str, ...]:
        return tuple(c.name for c in self.counters)

    @property
    def says_match(self) -> bool:
        """Whether the robot's own file chose the matching rule (the built-in robot's is the document's)."""
        return self.toml is not None and "match" in self.toml.data

    def line(self, section: str, key: str | None = None) -> int | None:
        """Line of ``[section] key`` (top-level keys: section "") in the robot file, if it has one."""
        return self.toml.line(section, None, key) if self.toml else None

    def file_source(self) -> Source:
        """The robot file as a :class:`Source` with a fresh error collector (empty for the built-in robot)."""
        toml = self.toml
        return Source(self.source, "", {}) if toml is None else Source(toml.path, toml.text, toml.data)


BUMBERBOT = Robot(
    name="BumberBot",
    inputs=("I3", "I4", "I5", "I7", "I8"),
    motors=("M1", "M2"),
    initial_state=2,
    initial_timer=0,
    tick_ms=10,
    match=MATCH_DOCUMENT,
    labels={
        "I3": "front-right bumper",
        "I4": "front-left bumper",
        "I5": "rear bumper",
        "I7": "right phototransistor",
        "I8": "left phototransistor",
        "M1": "right motor",
        "M2": "left motor",
    },
)


def find_robot_file(table_path: Path) -> Path | None:
    """The side file of a table: ``NAME.toml`` beside ``NAME.csv``, else ``robot.toml`` there."""
    for candidate in (table_path.with_suffix(".toml"), table_path.parent / "robot.toml"):
        if candidate.is_file():
            return candidate
    return None


def load_robot(path: str | Path) -> Robot:
    """Read a robot TOML file, reporting every problem with its line."""
    path = Path(path)
    src = Source.read(path, N_("see the robot file format in the README"))
    data = src.data
    plugins.load_sections(key for key in data if key not in TOP_KEYS and key not in CORE_SECTIONS)
    for key in data:
        if key not in TOP_KEYS and key not in CORE_SECTIONS and key not in SECTION_READERS:
            unknown = (
                N_("unknown section {key!r}", key=key)
                if isinstance(data[key], dict)
                else N_("unknown key {key!r}", key=key)
            )
            src.key_error(
                ("", None, key),
                unknown,
                MISPLACED.get(
                    key,
                    N_(
                        "known keys: {keys}; sections: {sections}",
                        keys=", ".join(TOP_KEYS),
                        sections=", ".join((*CORE_SECTIONS, *plugins.sections(), *_undeclared())),
                    ),
                ),
            )
    inputs, motors, lamps = (robot_names.section_names(src, key) for key in ("inputs", "motors", "lamps"))
    counters = robot_names.counters(src, motors)
    sensors = parse_sensors(src, inputs)
    robot_names.distinct(
        src, {"inputs": inputs, "motors": motors, "lamps": lamps, "counters": {c.name: "" for c in counters}}
    )
    if not motors and not lamps:
        src.out.error(
            None,
            None,
            N_("the robot has no [motors] and no [lamps]"),
            N_('add a section like [motors] with M1 = "right motor"'),
        )
    tick_ms = _whole(
        src,
        "tick_ms",
        10,
        (1, MAX_TICK_MS),
        N_(
            "{key} must be a positive whole number up to {most}, not {value!r}",
            key="tick_ms",
            most=MAX_TICK_MS,
            value=data.get("tick_ms"),
        ),
        N_("the document's engine ticks every 10 ms: tick_ms = 10"),
    )
    initial_timer = _whole(
        src,
        "initial_timer",
        0,
        (0, MAX_TIMER),
        N_(
            "{key} must be a whole number 0..{most}, not {value!r}",
            key="initial_timer",
            most=MAX_TIMER,
            value=data.get("initial_timer"),
        ),
        N_("the timer counts ticks; 0 means it has expired"),
    )
    initial_state = robot_names.initial_state(src)
    match = _match(src)
    states = robot_names.state_names(src)
    name = data.get("name", path.stem)
    if not isinstance(name, str):
        src.key_error(
            ("", None, "name"),
            N_("name must be text, not {value!r}", value=name),
            N_('write it in quotes: name = "BumberBot"'),
        )
    # The other stages' sections are read even when the core has mistakes, so that every mistake of the
    # file shows in one go; their readers see the names that did read.
    robot = Robot(
        name=str(name),
        inputs=tuple(inputs),
        motors=tuple(motors),
        lamps=tuple(lamps),
        counters=tuple(counters),
        initial_state=initial_state,
        initial_timer=initial_timer,
        tick_ms=tick_ms,
        match=match,
        sensors=sensors,
        labels={**inputs, **motors, **lamps},
        state_names=states,
        source=str(path),
        toml=src,
    )
    robot.sections.update(_foreign_sections(src, robot))
    return robot


def _undeclared() -> list[str]:
    """Sections a back-end registered without naming them to :mod:`tablebot.plugins` (none of tablebot's)."""
    return [name for name in SECTION_READERS if name not in plugins.sections()]


def _foreign_sections(src: Source, robot: Robot) -> dict[str, Any]:
    """Each stage's section, read by its own reader (see SECTION_READERS); all problems at once."""
    typed = {}
    for key, reader in list(SECTION_READERS.items()):  # (a reader may import a module that registers one)
        if key in src.data:
            typed[key] = reader(src, src.data[key], robot)
    src.raise_if_any()
    return typed


def _whole(src: Source, key: str, default: int, bounds: tuple[int, int], wrong: str, hint: str) -> int:
    """A top-level whole number within ``bounds`` (``default`` when absent or after reporting ``wrong``)."""
    value = src.data.get(key, default)
    if not isinstance(value, int) or isinstance(value, bool) or not bounds[0] <= value <= bounds[1]:
        src.key_error(("", None, key), wrong, hint)
        return default
    return value


def _match(src: Source) -> Match:
    """``match = "document"`` or ``"always"`` (DEFAULT_MATCH when the file does not say)."""
    value = src.data.get("match", DEFAULT_MATCH)
    if value not in MATCHES:
        src.key_error(
            ("", None, "match"),
            N_(
                'match must be "{document}" or "{always}", not {value!r}',
                document=MATCH_DOCUMENT,
                always=MATCH_ALWAYS,
                value=value,
            ),
            MATCH_HINT,
        )
        return DEFAULT_MATCH
    return cast(Match, value)  # one of MATCHES, checked above
