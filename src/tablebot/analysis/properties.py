"""Properties of a table: what they say, where they come from, and how to read them from TOML.

A property file (or the robot file's ``[properties]`` section) holds named tables; each has a
``text`` for people and exactly one kind of claim (see ``docs/checking.md``)::

    [front_bumper_stops]
    text = "whenever a front bumper is pressed, within 1 tick both motors are stopped or reversing"
    when = "I3 or I4"
    then = "M1 <= 0 and M2 <= 0"
    within = "1 tick"            # or "10 ms", "0.5 s", or a bare number of ticks

Kinds: ``never = COND``, ``always = COND``, ``reachable = COND`` (it can happen),
``always_reachable = COND`` (from every situation some inputs still make it happen) and
``when``/``then``/``within`` (a bounded response). ``level = "warning"`` makes a violation a
warning instead of an error; ``note`` is shown with the result. Nothing is ever executed.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tablebot.analysis.conditions import Condition, ConditionError, parse_condition
from tablebot.diagnostics import Collector, TableBotError
from tablebot.durations import DurationError, to_ticks
from tablebot.i18n import N_, NP_, Message
from tablebot.machine import Machine
from tablebot.tables import RobotTables
from tablebot.tomlfile import Source

KINDS = ("never", "always", "reachable", "always_reachable", "when")
#: How :meth:`Property.claim` says each kind but ``when`` (the condition is the user's, as written).
CLAIMS = {
    "never": N_("never: {cond}"),
    "always": N_("always: {cond}"),
    "reachable": N_("reachable: {cond}"),
    "always_reachable": N_("always reachable: {cond}"),
}
KEYS = {"text", "level", "note", "never", "always", "reachable", "always_reachable", "when", "then", "within"}
LEVELS = ("error", "warning")
PROPERTY_FILES = ("{stem}.properties.toml", "properties.toml")
HINT = "see the property format in docs/checking.md"
#: A property's name names its counterexample file, so it must stay a plain file name.
NAME_RE = re.compile(r"^\w[\w .-]*$")


@dataclass(frozen=True)
class Property:
    """One claim about every run of the table; ``cond`` for single-condition kinds, else when/then."""

    name: str
    text: str
    kind: str
    cond: Condition | None = None
    when: Condition | None = None
    then: Condition | None = None
    within: int = 0  # ticks
    level: str = "error"
    note: str = ""
    source: str = ""
    line: int | None = None

    @property
    def watch(self) -> int:
        """Input bits the property reads: the model keeps ticks that differ in them apart."""
        bits = 0
        for c in (self.cond, self.when, self.then):
            bits |= c.input_bits if c is not None else 0  # OR, not +: conditions share inputs
        return bits

    @property
    def tables(self) -> frozenset[int]:
        """In a robot of several tables: the tables whose state or outputs the property reads."""
        return frozenset().union(*(c.tables for c in (self.cond, self.when, self.then) if c is not None))

    @property
    def horizon(self) -> int:
        """Timer values the model must keep exact for this property (see the model's docstring)."""
        return self.within + 1 if self.kind == "when" else 1

    def claim(self) -> str:
        """The claim in tablebot's words, e.g. ``never: state == 20 and M1 > 0``."""
        if self.kind == "when":
            return NP_(
                "when {when}, then {then} within {n} tick",
                "when {when}, then {then} within {n} ticks",
                self.within,
                when=self.when.text,  # type: ignore[union-attr]
                then=self.then.text,  # type: ignore[union-attr]
            )
        return Message(CLAIMS[self.kind].msgid, {"cond": self.cond.text})  # type: ignore[union-attr]


def find_property_files(table_path: Path) -> list[Path]:
    """``NAME.properties.toml`` or ``properties.toml`` beside the table (the first that exists)."""
    for pattern in PROPERTY_FILES:
        candidate = table_path.parent / pattern.format(stem=table_path.stem)
        if candidate.is_file():
            return [candidate]
    return []


def load_properties(machine: Machine, files: list[Path], tables: RobotTables | None = None) -> list[Property]:
    """The robot file's ``[properties]`` plus every file given; all problems are reported at once. In a robot of
    several ``tables`` (``machine`` the main one's) a condition may name each table's state."""
    robot = machine.table.robot
    sources: list[tuple[Source, Any, str]] = []  # (file, its property tables, the section holding them)
    if "properties" in robot.sections:
        src = robot.file_source()
        sources.append((src, robot.sections["properties"], "properties"))
    for path in files:
        src = Source.read(path, HINT)
        copied = set(src.data) == {"properties"}  # a robot-file section copied as it is
        sources.append((src, src.data["properties"] if copied else src.data, "properties" if copied else ""))
    found: list[Property] = []
    errors = []
    for src, entries, section in sources:
        if not isinstance(entries, dict):
            src.out.error(
                src.line("", None, "properties"),
                None,
                N_("properties must be named tables"),
                N_("write [properties.my_name] (robot file) or [my_name] (properties file)"),
            )
        else:
            for name, entry in entries.items():
                line = src.line(f"{section}.{name}" if section else name) or src.line(section, None, name)
                prop = _property(name, entry, machine, src.out, src.path, line, tables)
                if prop is not None:
                    found.append(prop)
        errors.extend(src.out.items)
    if errors:
        raise TableBotError(errors)
    return found


def _property(
    name: str,
    entry: Any,
    machine: Machine,
    out: Collector,
    source: str,
    line: int | None,
    tables: RobotTables | None = None,
) -> Property | None:
    """One property table, or None after reporting everything wrong with it."""
    if not isinstance(entry, dict):
        out.error(
            line,
            None,
            N_("property {name!r} must be a table of keys", name=name),
            N_('write [{name}] followed by lines like never = "state == 3"', name=name),
        )
        return None
    before = len(out.items)
    if not NAME_RE.match(name):
        out.error(
            line,
            None,
            N_("property name {name!r} cannot name a file", name=name),
            N_("use letters, digits, spaces, _ . and - (its counterexample is written to NAME.csv)"),
        )
    kind = _kind(name, entry, line, out)
    if kind is None:
        return None
    fields = _claims(name, entry, kind, machine, line, out, tables)
    if len(out.items) > before:
        return None
    return Property(
        name=name,
        text=str(entry.get("text", name)),
        kind=kind,
        level=entry.get("level", "error"),
        note=str(entry.get("note", "")),
        source=source,
        line=line,
        **fields,
    )


def _kind(name: str, entry: dict[str, Any], line: int | None, out: Collector) -> str | None:
    """The property's kind (exactly one of KINDS must be given); the other keys are checked on the way."""
    for key in entry:
        if key not in KEYS:
            out.error(
                line,
                None,
                N_("property {name}: unknown key {key!r}", name=name, key=key),
                N_("known keys: {known}", known=", ".join(sorted(KEYS))),
            )
    level = entry.get("level", "error")
    if level not in LEVELS:
        out.error(
            line,
            None,
            N_("property {name}: level must be error or warning, not {level!r}", name=name, level=level),
            N_('write level = "warning" to make a violation a warning, or leave level out'),
        )
    for key in ("text", "note"):
        if not isinstance(entry.get(key, ""), str):
            out.error(
                line,
                None,
                N_("property {name}: {key} must be text, not {value!r}", name=name, key=key, value=entry[key]),
                N_('write it in quotes: {key} = "…"', key=key),
            )
    kinds = [k for k in KINDS if k in entry]
    if len(kinds) != 1:
        out.error(
            line,
            None,
            N_(
                "property {name} needs exactly one of {kinds} (found {found})",
                name=name,
                kinds=", ".join(KINDS),
                found=len(kinds),
            ),
            N_('for example: never = "state == 20 and M1 > 0"'),
        )
        return None
    return kinds[0]


def _claims(
    name: str,
    entry: dict[str, Any],
    kind: str,
    machine: Machine,
    line: int | None,
    out: Collector,
    tables: RobotTables | None = None,
) -> dict[str, Any]:
    """The parsed conditions (and ``within``) of a property of ``kind``, as Property fields."""

    def condition(key: str) -> Condition | None:
        value = entry.get(key)
        if not isinstance(value, str):
            out.error(
                line,
                None,
                N_("property {name}: {key} must be a condition in quotes", name=name, key=key),
                N_('for example: {key} = "state == 20"', key=key),
            )
            return None
        try:
            return parse_condition(value, machine, tables)
        except ConditionError as exc:
            out.error(
                line,
                None,
                N_("property {name}: {key}: {problem}", name=name, key=key, problem=exc.problem),
                N_("see the condition language in docs/checking.md"),
            )
            return None

    if kind != "when":
        return {"cond": condition(kind)}
    return {
        "when": condition("when"),
        "then": condition("then"),
        "within": _duration(entry.get("within"), machine.table.robot.tick_ms, name, line, out),
    }


def _duration(value: Any, tick_ms: int, name: str, line: int | None, out: Collector) -> int:
    """``within`` in ticks, from a number of ticks or a text like "10 ms", "1 tick", "0.5 s"."""
    hint = N_('write within = "100 ms" or "3 ticks" (one tick is {tick} ms)', tick=tick_ms)
    if value is None:
        out.error(line, None, N_("property {name}: within is missing (when/then needs a time limit)", name=name), hint)
        return 0
    if isinstance(value, int) and not isinstance(value, bool) and value >= 0:
        return value
    if not isinstance(value, str):
        out.error(line, None, N_("property {name}: within = {value!r} is not a duration", name=name, value=value), hint)
        return 0
    try:
        return to_ticks(value, tick_ms)
    except DurationError as exc:
        out.error(line, None, N_("property {name}: within = {problem}", name=name, problem=exc.message), exc.hint)
        return 0
