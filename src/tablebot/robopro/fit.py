"""What the generated ROBO Pro program holds of a table (``Plan``: states numbered, the lists encoded, the
robot wired) and every reason a table does not fit it (``problems``, which ``check --target
robopro-program`` reports and the export refuses on).

Encoding, the document's generalised to counters: event = state · 2^B + the event bits, B = number of
events (T, the robot's inputs, then its counters; T highest), so the BumberBot's first row is the
document's 88 (B = 6); action = next · 256 + M1dir · 128 + M1speed · 16 + M2dir · 8 + M2speed (speed 7 =
keep) — the document's word; timer = ticks; one list per counter of loads, −1 = leave it alone; one list per
lamp of levels 0–8, 9 = leave it alone.

A table of a robot of several tables (``[tables]``) has the events it has columns for: T, the inputs and
counters it reads, then its cross-table columns (each a bit, set from the other table's state at the start of
the tick: :mod:`tablebot.robopro.processes`); it drives the outputs it has columns for.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

from tablebot.diagnostics import Collector, Diagnostic, TableBotError
from tablebot.i18n import N_
from tablebot.robopro.lists import NEXT_WEIGHT, number_states
from tablebot.robopro.wiring import Wiring, wiring
from tablebot.robot import StateId
from tablebot.table import DOC_KEEP_SPEED, TIMER_EVENT, Row, Table, to_direction_speed

MAX_VALUE = 32767  # ROBO Pro integers are 16-bit signed
MAX_MOTORS = 2  # the document's action word
MAX_NEXT = MAX_VALUE // NEXT_WEIGHT
MAX_WAIT_MS = 32767  # a Wait in ms; longer ticks need whole tens of ms (the 10 ms scale)
DOC_BITS = 6
LAMP_KEEP = 9  # a lamp list's "leave it alone" (levels are 0..8)


@dataclass(frozen=True)
class Plan:
    table: Table
    wiring: Wiring
    rule: str
    numbers: dict[StateId, int]
    #: In a robot of several tables: every table's state numbers, by table name (for its cross-table events).
    others: dict[str, dict[StateId, int]] = field(default_factory=dict)

    @cached_property
    def events(self) -> tuple[str, ...]:
        """The event bits, highest first: T, the robot's inputs, its counters (a table of several: those it
        reads, then its cross-table columns)."""
        return events_of(self.table)

    @property
    def several(self) -> bool:
        return bool(self.table.name)

    def drives(self, output: str) -> bool:
        """Whether this program's table writes ``output`` (one table: every output of the robot)."""
        return not self.several or output in self.table.writes

    @cached_property
    def cross_lists(self) -> dict[str, tuple[int, ...]]:
        """Per table whose state a cross-table column reads: by that table's state number, the sum of the bits
        of this table's cross-table columns present in it."""
        found: dict[str, list[int]] = {}
        for name, event in self.table.cross.items():
            numbers = self.others[event.table]
            values = found.setdefault(event.table, [0] * (max(numbers.values()) + 1))
            for state, number in numbers.items():
                if event.covers(state):
                    values[number] += self.bits[name]
        return {source: tuple(values) for source, values in found.items()}

    @property
    def shift(self) -> int:
        return len(self.events)

    @property
    def mask(self) -> int:
        return (1 << self.shift) - 1

    @cached_property
    def bits(self) -> dict[str, int]:
        return {name: 1 << (self.shift - 1 - i) for i, name in enumerate(self.events)}

    def encode(self, row: Row) -> tuple[int, int, int]:
        events = sum(self.bits[e] for e in row.events)
        motors = [to_direction_speed(m) for m in row.motors] + [(0, 0)] * (MAX_MOTORS - len(row.motors))
        (d1, s1), (d2, s2) = motors[:MAX_MOTORS]
        action = self.numbers[row.next] * NEXT_WEIGHT + d1 * 128 + s1 * 16 + d2 * 8 + s2
        return (self.numbers[row.state] << self.shift) + events, action, row.timer

    @cached_property
    def _lists(self) -> tuple[tuple[int, ...], ...]:
        return tuple(zip(*(self.encode(row) for row in self.table.rows), strict=True))

    @property
    def event(self) -> tuple[int, ...]:
        return self._lists[0]

    @property
    def action(self) -> tuple[int, ...]:
        return self._lists[1]

    @property
    def timer(self) -> tuple[int, ...]:
        return self._lists[2]

    @cached_property
    def loads(self) -> dict[str, tuple[int, ...]]:
        names = self.table.robot.counter_names
        return {
            name: tuple(-1 if (load := row.counters[i]) is None else load for row in self.table.rows)
            for i, name in enumerate(names)
            if self.drives(name)
        }

    @cached_property
    def levels(self) -> dict[str, tuple[int, ...]]:
        """Per lamp the table drives, its level in each row (LAMP_KEEP: leave it alone)."""
        return {
            name: tuple(LAMP_KEEP if (level := row.lamps[i]) is None else level for row in self.table.rows)
            for i, name in enumerate(self.table.robot.lamps)
            if self.drives(name)
        }

    @property
    def initial_state(self) -> int:
        return self.numbers[self.table.robot.initial_state]

    @property
    def initial_timer(self) -> int:
        return self.table.robot.initial_timer

    def event_note(self, name: str) -> str:
        label = "the timer ran out (TM = 0)" if name == TIMER_EVENT else self.table.robot.labels.get(name, "")
        if name in self.wiring.counters:
            label = f"counter C{self.wiring.counters[name]} reached 0"
        elif name in self.wiring.inputs:
            terminal, active = self.wiring.inputs[name]
            label = f"I{terminal} reads {active}" + (f": {label}" if label else "")
        return f"{name} (+{self.bits[name]}): {label}"

    def bit_text(self) -> str:
        return ", ".join(f"{name}={bit}" for name, bit in self.bits.items())

    def table_notes(self) -> list[str]:
        """The table as ROBO Pro shows text: a line per state name, then a line per row of the lists."""
        table = self.table
        lines = [
            f"{table.robot.name}: the transition table in the lists Event, Action, Timer",
            f"event = state * {1 << self.shift} + {self.bit_text()};  action = next * 256 + "
            "M1dir * 128 + M1speed * 16 + M2dir * 8 + M2speed (speed 7 = keep);  timer = ticks of "
            f"{table.robot.tick_ms} ms",
        ]
        lines += [
            f"state {self.numbers[s]}: {table.state_name(s) or s}"
            for s in table.states
            if table.state_name(s) or not isinstance(s, int)
        ]
        for row, (event, action, timer) in zip(
            table.rows, zip(self.event, self.action, self.timer, strict=True), strict=True
        ):
            loads = "".join(f", {n} load {self.loads[n][row.index]}" for n in self.loads)
            loads += "".join(f", {n} {self.levels[n][row.index]}" for n in self.levels)
            lines.append(
                f"row {row.as_written} (list index {row.index}): {event} / {action} / {timer}{loads}  {row.description}"
            )
        return lines

    def summary(self) -> str:
        robot = self.table.robot
        rule = (
            "if an event is detected: a tick with no event looks up no row"
            if self.rule == "document"
            else "a row with no required events always matches"
        )
        return (
            f"Generated by tablebot from {self.table.path} for {robot.name} ({self.wiring.controller}). "
            f"Main loop: DetectEvent, DetermineAction, ExecuteAction, a Wait of one tick "
            f"({robot.tick_ms} ms), CountDown. Rule: {rule}."
        )


def problems(table: Table, rule: str | None = None) -> list[Diagnostic]:
    """Every reason ``table`` does not fit the generated program, located in the table or robot file."""
    robot = table.robot
    out = Collector(table.path)
    wired = wiring(robot)
    where = robot.source if robot.toml else table.path

    def robot_error(message: str, hint: str, section: str = "", key: str | None = None) -> None:
        line = robot.line(section, key) if robot.toml else None
        out.items.append(Diagnostic(where, line, None if line is None else 1, message, hint))

    if len(robot.motors) > MAX_MOTORS:
        robot_error(
            f"{len(robot.motors)} motors; the document's action word holds M1 and M2 only",
            "use a robot with at most two motors",
            "motors",
        )
    for sensor in robot.sensors:
        why = (
            "fischertechnik's IR track sensor needs ROBO Pro's digital 10 V input mode, which no program of "
            "the corpus uses"
            if sensor.model == "line"
            else "its threshold is not generated"
        )
        robot_error(
            f"input {sensor.name} is a {sensor.model} sensor: the program reads inputs as digital switches "
            f"(digital 5 kOhm, as a push-button or a phototransistor) and {why}",
            f"leave {sensor.name} out of [sensors] if it is a switch-like input",
            "sensors",
            sensor.name,
        )
    if robot.counters and wired.controller == "robo-interface":
        robot_error(
            "the robot has counters, and the ROBO Interface has no counter inputs",
            'set controller = "tx" or "txt" in [robopro]',
            "robopro",
            "controller",
        )
    for name, message, hint in wired.problems:
        robot_error(message, hint, "robopro", name)
    for kind, used in (
        ("input", {n: t for n, (t, _) in wired.inputs.items()}),
        ("motor", {n: t for n, (t, _) in wired.motors.items()}),
        ("counter", wired.counters),
        ("lamp", wired.lamps),
    ):
        seen: dict[int, str] = {}
        for name, terminal in used.items():
            if terminal in seen:
                robot_error(
                    f"{kind}s {seen[terminal]} and {name} are wired to the same terminal",
                    "give each its own terminal in [robopro]",
                    "robopro",
                    name,
                )
            seen.setdefault(terminal, name)
    for name, output in wired.lamps.items():
        motor = next((m for m, (o, _) in wired.motors.items() if output in (2 * o - 1, 2 * o)), None)
        if motor is not None:
            robot_error(
                f"lamp {name} is wired to O{output}, an output of motor {motor}",
                "wire the lamp to an output no motor uses in [robopro]",
                "robopro",
                name,
            )
    _row_problems(table, out)
    if robot.tick_ms > MAX_WAIT_MS and robot.tick_ms % 10:
        robot_error(
            f"tick_ms = {robot.tick_ms}: a ROBO Pro Wait holds up to {MAX_WAIT_MS} ms, or whole tens of ms",
            "use a tick of at most 32767 ms or a multiple of 10 ms",
            "",
            "tick_ms",
        )
    if robot.initial_timer > MAX_VALUE:
        robot_error(
            f"initial_timer = {robot.initial_timer} is over {MAX_VALUE}",
            "ROBO Pro integers are 16-bit",
            "",
            "initial_timer",
        )
    return out.items


def events_of(table: Table) -> tuple[str, ...]:
    """The event bits of ``table``'s program, highest first (see :attr:`Plan.events`)."""
    robot = table.robot
    if not table.name:
        return (TIMER_EVENT, *robot.inputs, *robot.counter_names)
    read = set(table.events)
    return (
        TIMER_EVENT,
        *(n for n in robot.inputs if n in read),
        *(n for n in robot.counter_names if n in read),
        *table.cross,
    )


def _row_problems(table: Table, out: Collector) -> None:
    shift = len(events_of(table))
    max_state = (MAX_VALUE >> shift) if shift < 15 else 0
    numbers = number_states(table)
    if shift >= 15:
        out.error(
            1,
            1,
            N_("{n} events (T, inputs and counters) leave no bits for the state in a 16-bit word", n=shift),
            N_("use fewer inputs or counters"),
        )
        return
    for row in table.rows:
        for what, state, limit in (
            (N_("state"), row.state, max_state),
            (N_("next state"), row.next, min(MAX_NEXT, max_state)),
        ):
            if numbers[state] > limit:
                out.error(
                    row.line,
                    None,
                    N_(
                        "row {row}: {what} {state!r} is number {number}, over {limit}",
                        row=row.as_written,
                        what=what,
                        state=state,
                        number=numbers[state],
                        limit=limit,
                    ),
                    N_("with {n} event bits the 16-bit lists hold states 0..{limit}", n=shift, limit=limit),
                )
        if row.timer > MAX_VALUE:
            out.error(
                row.line,
                None,
                N_("row {row}: timer {timer} is over {most}", row=row.as_written, timer=row.timer, most=MAX_VALUE),
                N_("ROBO Pro integers are 16-bit signed"),
            )
        for motor, speed in zip(table.robot.motors, row.motors, strict=True):
            if speed is not None and abs(speed) >= DOC_KEEP_SPEED:
                out.error(
                    row.line,
                    None,
                    N_(
                        "row {row}: {motor} speed {speed} does not fit the action word",
                        row=row.as_written,
                        motor=motor,
                        speed=abs(speed),
                    ),
                    N_("the document's speeds are 0..6 (7 means keep): use 6 or less"),
                )
        for name, load in zip(table.robot.counter_names, row.counters, strict=True):
            if load is not None and load > MAX_VALUE:
                out.error(
                    row.line,
                    None,
                    N_(
                        "row {row}: {name} load {load} is over {most}",
                        row=row.as_written,
                        name=name,
                        load=load,
                        most=MAX_VALUE,
                    ),
                    N_("ROBO Pro integers are 16-bit signed"),
                )
    if numbers[table.robot.initial_state] > max_state:
        out.error(
            1,
            1,
            N_(
                "initial state {state!r} is number {number}, over {most}",
                state=table.robot.initial_state,
                number=numbers[table.robot.initial_state],
                most=max_state,
            ),
            N_("number the states lower"),
        )


def plan(table: Table, rule: str | None = None) -> Plan:
    """What the generator needs; ``rule`` defaults to the table's own (the robot file's ``match``)."""
    found = problems(table, rule)
    if found:
        raise TableBotError(found)
    return Plan(table, wiring(table.robot), rule or table.robot.match, number_states(table))
