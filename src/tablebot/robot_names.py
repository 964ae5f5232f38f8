"""The names a robot file gives: its inputs', motors', lamps' and counters' (they become the table's column
headers, so each must be a good header and distinct) and its states' (the start state and ``[states]``).

:mod:`tablebot.robot` reads the whole file with these readers and re-exports the names it always had
(``StateId``, ``Counter``, ``NAME_RE``, ``STATE_RE``, ...)."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from tablebot import durations
from tablebot.i18n import N_
from tablebot.i18n.headers import GERMAN_FIXED
from tablebot.tomlfile import Source

#: A state: a number or a name; evolve's joint tables (tablebot.evolve.evaluate.joint) tag each candidate's
#: states with its index, ``(k, state)``.
StateId = int | str | tuple[int, "StateId"]
#: The robot file's top-level keys (a name written below a section header is one of them misplaced).
TOP_KEYS = ("name", "tick_ms", "initial_state", "initial_timer", "match")

NAME_RE = re.compile(r"^[A-Za-z][A-Za-z0-9]*$")
#: A state name as tables and robot files write it (a state is otherwise a whole number 0 or more).
STATE_RE = re.compile(r"^[A-Za-z_][\w .-]*$")
STATE_HINT = N_("use a number, or a name that starts with A-Z or _ (then letters, digits, spaces, _ . -)")
RESERVED_NAMES = {"T", "description", "state", "timer", "next"}
#: Header names the table parser reads case-insensitively as fixed columns (aliases included).
RESERVED_LOWER = {"description", "desc", "state", "st", "timer", "next", *GERMAN_FIXED}  # Zustand, Folgezustand too


@dataclass(frozen=True)
class Counter:
    """A count-down register loaded by a row and decremented by the pulses of one motor's encoder."""

    name: str
    motor: str


def section_names(src: Source, key: str) -> dict[str, str]:
    """A ``[inputs]``-style table of NAME = "label" pairs (or a list of names)."""
    section = src.data.get(key)
    if section is None:
        return {}
    if isinstance(section, list):
        section = {str(name): "" for name in section}
    if not isinstance(section, dict):
        src.key_error(
            ("", None, key),
            N_('[{key}] must be a table of NAME = "label"', key=key),
            N_('for example: I3 = "front-right bumper"'),
        )
        return {}
    for name, label in section.items():
        if good_name(src, key, name) and not isinstance(label, str):
            src.key_error(
                (key, None, name),
                N_("[{key}] {name}: the label must be text, not {label!r}", key=key, name=name, label=label),
                N_('write it in quotes: {name} = "what it is"', name=name),
            )
    return {name: str(label) for name, label in section.items()}


def good_name(src: Source, key: str, name: str) -> bool:
    """Names become column headers, so they must not clash with the fixed columns or suffixes."""
    if misplaced(src, key, name):
        return False
    if not NAME_RE.match(name) or name in RESERVED_NAMES or name.lower() in RESERVED_LOWER:
        src.key_error(
            (key, None, name),
            N_("bad {key} name {name!r}", key=key, name=name),
            N_("use a letter then letters/digits (like I3 or M1), not T, state, timer or next"),
        )
        return False
    return True


def misplaced(src: Source, section: str, key: str) -> bool:
    """Whether ``key`` is a top-level key written below the ``[section]`` header (TOML then puts it
    in that section); reported if so."""
    if key not in TOP_KEYS:
        return False
    src.key_error(
        (section, None, key),
        N_("{key} is inside [{section}]", key=key, section=section),
        N_(
            "move {key} = … above the first [section]: every key below [{section}] belongs to it",
            key=key,
            section=section,
        ),
    )
    return True


def counters(src: Source, motors: dict[str, str]) -> list[Counter]:
    """``[counters]``: C1 = "M1" (or C1 = {motor = "M1"}), each counting one motor's encoder."""
    section = src.data.get("counters") or {}
    if not isinstance(section, dict):
        src.key_error(
            ("", None, "counters"),
            N_('[counters] must be a table of C1 = "M1"'),
            N_("each counter names the motor whose encoder it counts"),
        )
        return []
    counters = []
    for name, value in section.items():
        good_name(src, "counters", name)
        motor = value.get("motor") if isinstance(value, dict) else value
        if isinstance(value, dict) and set(value) != {"motor"}:
            src.key_error(
                ("counters", None, name),
                N_(
                    'counter {name} may only say motor = "M1", not {keys}',
                    name=name,
                    keys=", ".join(sorted(set(value) - {"motor"})) or N_("nothing"),
                ),
                N_('write {name} = "M1"', name=name),
            )
        elif not isinstance(motor, str) or motor not in motors:  # a list or table is no motor name (nor hashable)
            src.key_error(
                ("counters", None, name),
                N_("counter {name} counts motor {motor!r}, which is not in [motors]", name=name, motor=motor),
                N_('write {name} = "M1" with a motor name from [motors]', name=name),
            )
        counters.append(Counter(name, str(motor)))
    return counters


def distinct(src: Source, sections: dict[str, dict[str, str]]) -> None:
    """Inputs, motors, lamps and counters share the table's header, so a name may be used once."""
    first: dict[str, str] = {}
    for key, names in sections.items():
        for name in names:
            if name in first and first[name] != key:
                src.key_error(
                    (first[name], None, name),
                    N_(
                        "name {name} is used twice ([{first}] and [{second}])", name=name, first=first[name], second=key
                    ),
                    N_("inputs, motors, counters and lamps need distinct names"),
                )
            first.setdefault(name, key)


def state_id(value: Any) -> StateId | None:
    """A state as the table parser reads it (``"2"`` is state 2), or None if no table could name it."""
    if isinstance(value, bool) or not isinstance(value, int | str):
        return None
    if isinstance(value, int):
        return value if value >= 0 else None
    text = value.strip()
    if text.isascii() and text.isdigit():
        return int(text) if len(text) <= durations.MAX_NUMBER_CHARS else None  # int() of more may fail
    return text if STATE_RE.match(text) else None


def initial_state(src: Source) -> StateId:
    if "initial_state" not in src.data:
        tables = src.data.get("tables")
        if isinstance(tables, dict) and tables:  # each table says its own ([tables], tablebot.robot_tables)
            first = next(iter(tables.values()))
            return state_id(first.get("initial_state") if isinstance(first, dict) else None) or 0
        src.out.error(None, None, N_("initial_state is missing"), N_("add a line like: initial_state = 2"))
        return 0
    state = state_id(src.data["initial_state"])
    if state is None:
        src.key_error(
            ("", None, "initial_state"),
            N_("initial_state {value!r} is not a state", value=src.data["initial_state"]),
            STATE_HINT,
        )
        return 0
    return state


def state_names(src: Source) -> dict[StateId, str]:
    """``[states]``: NUMBER = "name", the names people read for the table's states."""
    section = src.data.get("states") or {}
    if not isinstance(section, dict):
        src.key_error(
            ("", None, "states"), N_('[states] must be a table of NUMBER = "name"'), N_('for example: 20 = "collision"')
        )
        return {}
    names: dict[StateId, str] = {}
    for key, label in section.items():
        state = state_id(key)
        if misplaced(src, "states", key):
            continue
        if state is None:
            src.key_error(("states", None, key), N_("[states] {key!r} is not a state", key=key), STATE_HINT)
        elif not isinstance(label, str):
            src.key_error(
                ("states", None, key),
                N_("[states] {key}: the name must be text, not {label!r}", key=key, label=label),
                N_('write it in quotes: {key} = "seek"', key=key),
            )
        else:
            names[state] = label
    return names
