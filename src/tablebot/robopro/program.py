"""The document's whole engine as a ROBO Pro program, generated from a table: the main loop
DetectEvent → DetermineAction → ExecuteAction over the lists Event, Action and Timer (pre-filled with the
table's encoding), with native bitwise operators, paced by a Wait of one tick (``tick_ms``).

The program follows the engine's tick rule exactly (the interpreter in :mod:`tablebot.robopro.interpret`
proves it on random tables): after the first pass the timer TM counts down by one per pass and each
counter by the pulses its input counted; EV holds T, the inputs reading their active level and each Cn at
0; the first row of the Event list whose state is ST and whose event bits are all in EV fires. ``rule``
says what happens on a pass whose EV is empty: ``"document"`` looks up no row ("if an event is
detected"), ``"always"`` looks up as on any pass (a row that requires no event matches); by default the
table's own rule, the robot file's ``match``.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

from tablebot.robopro import elements as el
from tablebot.robopro.document import Sub, document
from tablebot.robopro.fit import LAMP_KEEP, Plan, plan
from tablebot.robopro.rpp_write import Canvas, Element, Ids, Pin, caption
from tablebot.robopro.sheet import Const, Count, Input, Join, ListAt, Op, Sheet, Tree, Var
from tablebot.robot import Match
from tablebot.table import Table

Rule = Match  # the robot file's matching rules (tablebot.robot.Match)
RULES: tuple[Rule, ...] = ("document", "always")
MAIN, DETECT, DETERMINE, EXECUTE, COUNTDOWN = (
    "Main program",
    "DetectEvent",
    "DetermineAction",
    "ExecuteAction",
    "CountDown",
)
ENTRY, EXIT, FOUND, NONE = "Entry", "Exit", "Found", "None"
COLUMN = 136  # x of every subprogram's flow column
INDENT = "            "  # elements inside a subprogram


@dataclass(frozen=True)
class Lamp:
    """A lamp's single output (O1…O8), as a command's target."""

    output: int


class Builder:
    """Builds the subprograms of one plan, sharing one id counter (and, for a robot of several tables, the
    document's ids, subprograms and variables' initial values with the other tables' builders). ``prefix``
    names this table's variables, lists and subprograms (``drive ST``); "" for a robot of one table."""

    def __init__(
        self,
        p: Plan,
        prefix: str = "",
        ids: Ids | None = None,
        subs: dict[str, Sub] | None = None,
        inits: dict[str, int] | None = None,
    ) -> None:
        self.p, self.prefix = p, prefix
        self.ids = ids or Ids()
        self.inits = inits if inits is not None else {}
        self.inits.update({self.v("ST"): p.initial_state, self.v("TM"): p.initial_timer})
        self.subs: dict[str, Sub] = subs if subs is not None else {}

    def v(self, name: str) -> str:
        """The name of this table's variable, list or subprogram ``name``."""
        return self.prefix + name

    def reads(self, name: str) -> tuple[Tree, bool]:
        """What DetectEvent tests for the event ``name`` (an input or a counter), and whether a value above 0
        means the event is there. A table of several reads the input image of the tick (``in I3``, the counts
        ``C1 tick``), which the clock process takes before any table looks."""
        wiring = self.p.wiring
        if name in wiring.counters:
            return (Var(f"{name} tick") if self.p.several else Var(name)), False
        terminal, active = wiring.inputs[name]
        return (Var(f"in {name}") if self.p.several else Input(terminal)), bool(active)

    def sheet(self) -> Sheet:
        return Sheet(Canvas(self.ids), COLUMN, self.inits, INDENT)

    def send(self, sheet: Sheet, element: Element, target: str | int | Lamp) -> Element:
        """Wire a command element's output to a variable (by name), a motor (by output number) or a lamp on its
        right."""
        out = element.pin(0)
        x, y = out.at
        made = (
            el.variable(x + 12, y, target, self.inits.get(target, 0))
            if isinstance(target, str)
            else el.lamp(x + 12, y, target.output)
            if isinstance(target, Lamp)
            else el.motor(x + 12, y, target)
        )
        sheet.canvas.add(made)
        sheet.canvas.connect(out, made.pins_of("dataobjectinput")[0])
        return made

    def assign(
        self, sheet: Sheet, target: str | int | Lamp, command: str, value: int | None = None, data: Tree | None = None
    ) -> Element:
        element = sheet.step(lambda x, y: el.message(x, y, command, value), data=data)
        self.send(sheet, element, target)
        return element

    def side_send(
        self,
        sheet: Sheet,
        exit_pin: Pin,
        target: str | int | Lamp,
        command: str,
        value: int | None = None,
        data: Tree | None = None,
        hold: bool = False,
    ) -> None:
        sheet.side(
            exit_pin,
            [lambda x, y: el.message(x, y, command, value)],
            data=[data],
            extra=lambda e: self.send(sheet, e, target),
            hold=hold,
        )

    def note(self, sheet: Sheet, element: Element, text: str) -> None:
        sheet.note(element.y, text)

    def finish(
        self,
        name: str,
        sheet: Sheet,
        outputs: list[tuple[str, int]],
        documentation: str,
        inputs: list[tuple[str, int]] | None = None,
    ) -> Sub:
        x = max(sheet.right, sheet.lanes) + 24  # comments right of every lane
        for y, text in sheet.notes:
            sheet.canvas.comments.append(caption(INDENT, self.ids(), text, (x, y), size=3, align="336", linespace="0"))
        sub = Sub(name, sheet.canvas, inputs if inputs is not None else [(ENTRY, 1)], outputs, documentation)
        self.subs[name] = sub
        return sub

    def call(self, sheet: Sheet, name: str, dx: int = 0, release: bool = False) -> Element:
        sub = self.subs[name]
        pins, width, height = el.symbol_pins(sub.inputs, sub.outputs)
        return sheet.step(
            lambda x, y: el.call(x, y, name, sub.guid, pins, width, height, INDENT, self.ids()), dx=dx, release=release
        )


# --- the subprograms ---------------------------------------------------------------------------------


def detect_event(b: Builder) -> Sub:
    p, s, v = b.p, b.sheet(), b.v
    s.begin(el.flow_in(COLUMN, 8, ENTRY, 1))
    b.assign(s, v("EV"), "=", 0)
    for name in p.events:
        if name in p.table.cross:
            continue
        bit = p.bits[name]
        test: Tree
        if name == "T":
            test, add_when_yes = Var(v("TM")), False
        else:
            test, add_when_yes = b.reads(name)
        branch = s.step(partial(el.branch, yes_down=not add_when_yes), data=test)
        b.side_send(s, branch.pins[3], v("EV"), "+", bit)
        b.note(s, branch, p.event_note(name))
    for source, values in p.cross_lists.items():
        cross = b.assign(s, v("EV"), "+", data=ListAt(v(f"from {source}"), values, Var(f"{source} S0")))
        b.note(
            s,
            cross,
            f"the columns reading table {source}'s state at the start of the tick: "
            + ", ".join(f"{n} (+{p.bits[n]})" for n, e in p.table.cross.items() if e.table == source),
        )
    s.step(lambda x, y: el.flow_out(x, y, EXIT, 2))
    return b.finish(v(DETECT), s, [(EXIT, 2)], "EV := the events of this tick, one bit each: " + p.bit_text())


def determine_action(b: Builder) -> Sub:
    p, s, v = b.p, b.sheet(), b.v
    s.begin(el.flow_in(COLUMN, 8, ENTRY, 1))
    b.assign(s, v("ROW"), "=", 0)
    more = s.step(lambda x, y: el.branch(x, y, yes_down=True), data=Op("XOR", Var(v("ROW")), Const(len(p.event))))
    loop_wire, loop_in = s.last_wire, more.pins[1].at
    s.side(more.pins[3], [lambda x, y: el.flow_out(x, y, NONE, 3)], rejoin=False)
    b.note(s, more, f"rows left? (ROW < {len(p.event)})")
    b.assign(s, v("E"), "=", data=ListAt(v("Event"), p.event, Var(v("ROW"))))
    state = s.step(
        lambda x, y: el.branch(x, y, yes_down=False),
        data=Op("XOR", Op("SHR", Var(v("E")), Const(p.shift)), Var(v("ST"))),
    )
    b.note(s, state, f"row's state (E SHR {p.shift}) is not ST?")
    need = Op("AND", Var(v("E")), Const(p.mask))
    missing = s.step(lambda x, y: el.branch(x, y, yes_down=False), data=Op("XOR", Op("AND", need, Var(v("EV"))), need))
    b.note(s, missing, f"an event of the row (E AND {p.mask}) missing from EV?")
    (step_on,), wire = s.side(
        missing.pins[3], [lambda x, y: el.message(x, y, "+", 1)], extra=lambda e: b.send(s, e, v("ROW")), rejoin=False
    )
    assert wire is not None
    _ex, ey = state.pins[3].at
    sx, sy = wire.points[1]
    s.canvas.join(state.pins[3], wire, (sx, sy + 4), via=[(sx + 8, ey), (sx + 8, sy + 4)])
    s.step(lambda x, y: el.flow_out(x, y, FOUND, 2))
    assert loop_wire is not None
    s.loop_back(step_on.pin(2), loop_wire, (loop_in[0], loop_in[1] - 4))
    return b.finish(
        v(DETERMINE),
        s,
        [(FOUND, 2), (NONE, 3)],
        "ROW := the first row of the Event list whose state is ST and whose events are all in EV",
    )


def execute_action(b: Builder) -> Sub:
    p, s, v = b.p, b.sheet(), b.v
    s.begin(el.flow_in(COLUMN, 8, ENTRY, 1))
    b.assign(s, v("ACT"), "=", data=ListAt(v("Action"), p.action, Var(v("ROW"))))
    b.assign(s, v("TM"), "=", data=ListAt(v("Timer"), p.timer, Var(v("ROW"))))
    first = b.assign(s, v("ST"), "=", data=Op("SHR", Var(v("ACT")), Const(8)))
    b.note(s, first, "next state: ACT SHR 8")
    for motor, (speed_shift, dir_shift) in zip(p.table.robot.motors, ((4, 7), (0, 3)), strict=False):
        if p.drives(motor):
            _motor(b, s, motor, speed_shift, dir_shift)
    for name in p.levels:
        _lamp(b, s, name)
    for name in p.loads:
        b.assign(s, v("CL"), "=", data=ListAt(v(f"{name} load"), p.loads[name], Var(v("ROW"))))
        load = s.step(lambda x, y: el.branch(x, y, yes_down=False), data=Op("+", Var(v("CL")), Const(1)))
        b.note(s, load, f"{name}: a load of -1 leaves the counter alone")
        b.side_send(s, load.pins[3], name, "=", data=Var(v("CL")))
    s.step(lambda x, y: el.flow_out(x, y, EXIT, 2))
    return b.finish(
        v(EXECUTE),
        s,
        [(EXIT, 2)],
        "The action of row ROW: motors (speed 7 keeps), TM from the Timer list, ST := next state",
    )


def _motor(b: Builder, s: Sheet, motor: str, speed_shift: int, dir_shift: int) -> None:
    """Motor ``motor`` as the action word ACT says: speed 7 keeps it, 0 stops it, else its direction bit."""
    v = b.v
    output, forward = b.p.wiring.motors[motor]
    backward = "ccw" if forward == "cw" else "cw"
    field = Op("SHR", Var(v("ACT")), Const(speed_shift)) if speed_shift else Var(v("ACT"))
    speed = b.assign(s, v("SPEED"), "=", data=Op("AND", field, Const(7)))
    b.note(s, speed, f"{motor}: SPEED = (ACT SHR {speed_shift}) AND 7")
    keep = s.step(lambda x, y: el.branch(x, y, yes_down=True), data=Op("XOR", Var(v("SPEED")), Const(7)))
    b.note(s, keep, f"{motor}: speed 7 keeps the motor as it is")
    s.side(keep.pins[3], [], hold=True)
    moving = s.step(lambda x, y: el.branch(x, y, yes_down=True), data=Var(v("SPEED")))
    b.note(s, moving, f"{motor}: speed 0 stops it")
    b.side_send(s, moving.pins[3], output, "Stop", -32768, hold=True)
    direction = s.step(
        lambda x, y: el.branch(x, y, yes_down=False),
        data=Op("AND", Op("SHR", Var(v("ACT")), Const(dir_shift)), Const(1)),
    )
    b.note(
        s,
        direction,
        f"{motor}: direction (ACT SHR {dir_shift}) AND 1: 1 = backward ({backward}), 0 = forward ({forward})",
    )
    b.side_send(s, direction.pins[3], output, backward, data=Var(v("SPEED")), hold=True)
    b.assign(s, output, forward, data=Var(v("SPEED")))
    s.release()


def _lamp(b: Builder, s: Sheet, lamp: str) -> None:
    """Lamp ``lamp`` from its list: 9 leaves it alone, 0 turns it off, else on at that level."""
    v, target = b.v, Lamp(b.p.wiring.lamps[lamp])
    level = b.assign(s, v("LEVEL"), "=", data=ListAt(v(lamp), b.p.levels[lamp], Var(v("ROW"))))
    b.note(s, level, f"{lamp}: its level in row ROW")
    keep = s.step(lambda x, y: el.branch(x, y, yes_down=True), data=Op("XOR", Var(v("LEVEL")), Const(LAMP_KEEP)))
    b.note(s, keep, f"{lamp}: level {LAMP_KEEP} keeps the lamp as it is")
    s.side(keep.pins[3], [], hold=True)
    lit = s.step(lambda x, y: el.branch(x, y, yes_down=True), data=Var(v("LEVEL")))
    b.note(s, lit, f"{lamp}: level 0 turns it off")
    b.side_send(s, lit.pins[3], target, "Off", -32768, hold=True)
    b.assign(s, target, "On", data=Var(v("LEVEL")))
    s.release()


def count_down(b: Builder) -> Sub:
    """TM by one (and, in a robot of one table, the counters: in one of several the clock process counts them)."""
    p, s, v = b.p, b.sheet(), b.v
    s.begin(el.flow_in(COLUMN, 8, ENTRY, 1))
    timer = s.step(lambda x, y: el.branch(x, y, yes_down=False), data=Var(v("TM")))
    b.note(s, timer, "TM counts down to 0, one per tick")
    b.side_send(s, timer.pins[3], v("TM"), "-", 1)
    if not p.several:
        count_counters(b, s)
    s.step(lambda x, y: el.flow_out(x, y, EXIT, 2))
    return b.finish(v(COUNTDOWN), s, [(EXIT, 2)], "One tick later: TM and the counters count down")


def count_counters(b: Builder, s: Sheet) -> None:
    """Each counter down by the pulses its input counted since the last tick, never below 0."""
    for name, counter in b.p.wiring.counters.items():
        now, last = f"{name} now", f"{name} last"
        b.assign(s, now, "=", data=Count(counter))
        cmp = s.step(el.compare)
        pulses = Op("-", Var(now), Var(last))
        s.feed(Var(name), cmp.pin("A"))
        s.feed(pulses, cmp.pin("B"))
        b.note(s, cmp, f"{name} counts down by the pulses since the last tick, never below 0")
        s.joins.append(_left_join(cmp.pin("<")))
        b.assign(s, name, "=", 0)
        b.side_send(s, cmp.pin(">"), name, "=", data=Op("-", Var(name), pulses))
        b.assign(s, last, "=", data=Var(now))


def _left_join(pin: Pin) -> Join:
    return Join(pin, pin.at[1])


def begin_outputs(b: Builder, s: Sheet) -> None:
    """The start: ST and TM, the motors the table drives stopped, its lamps off (one table: the counters)."""
    p = b.p
    b.assign(s, b.v("ST"), "=", p.initial_state)
    b.assign(s, b.v("TM"), "=", p.initial_timer)
    for motor in p.table.robot.motors:
        if p.drives(motor):
            b.assign(s, p.wiring.motors[motor][0], "Stop", -32768)
    for lamp in p.levels:
        b.assign(s, Lamp(p.wiring.lamps[lamp]), "Off", -32768)
    if not p.several:
        for name, counter in p.wiring.counters.items():
            b.assign(s, name, "=", 0)
            b.assign(s, f"{name} last", "=", data=Count(counter))


def engine_loop(b: Builder, s: Sheet, end_tick: Callable[[Sheet], None], notes: bool = True) -> None:
    """DetectEvent, (if an event is detected,) DetermineAction, ExecuteAction, the end of the tick
    (``end_tick``: the flows that skipped a row are held to join its first element), CountDown, and back; with
    ``notes``, the table's lists as comments right of it."""
    p, v = b.p, b.v
    detect = b.call(s, v(DETECT))
    loop_wire, loop_in = s.last_wire, detect.pins[0].at
    if p.rule == "document":
        any_event = s.step(lambda x, y: el.branch(x, y, yes_down=True), data=Var(v("EV")))
        b.note(s, any_event, "if an event is detected (EV > 0)")
        s.side(any_event.pins[3], [], hold=True)
    determine = b.call(s, v(DETERMINE), dx=4)
    s.held.append(_left_join(determine.pin(NONE)))
    b.call(s, v(EXECUTE))
    end_tick(s)
    countdown = b.call(s, v(COUNTDOWN))
    assert loop_wire is not None
    s.loop_back(countdown.pins_of("flowobjectoutput")[0], loop_wire, (loop_in[0], loop_in[1] - 4))
    for n, line in enumerate(p.table_notes() if notes else ()):
        s.canvas.comments.append(
            caption(
                INDENT, b.ids(), line, (max(s.right, s.lanes) + 24 + 96, 8 + 4 * n), size=2, align="336", linespace="0"
            )
        )


def main_program(b: Builder) -> Sub:
    p, s = b.p, b.sheet()
    s.begin(el.start(COLUMN, 8))
    begin_outputs(b, s)

    def wait(s: Sheet) -> None:
        tick = s.step(lambda x, y: el.wait(x, y, p.table.robot.tick_ms), release=True)
        b.note(s, tick, f"one tick: {p.table.robot.tick_ms} ms")

    engine_loop(b, s, wait)
    return b.finish(MAIN, s, [], p.summary(), inputs=[])


#: The engine's subprograms, in the order they are built (each calls only those built before it).
ENGINE: tuple[Callable[[Builder], Sub], ...] = (detect_event, determine_action, execute_action, count_down)


def generate(table: Table, rule: Rule | None = None) -> str:
    """The whole .rpp text for ``table`` under ``rule`` (default: the table's own, the robot file's ``match``);
    raises :class:`TableBotError` when the table does not fit."""
    rule = rule or table.robot.match
    if rule not in RULES:
        raise ValueError(f"rule must be one of {RULES}, not {rule!r}")
    p = plan(table, rule)
    b = Builder(p)
    for build in ENGINE:
        build(b)
    main_program(b)
    return document(b.ids, p, [b.subs[n] for n in (MAIN, DETECT, DETERMINE, EXECUTE, COUNTDOWN)])


def file_name(table: Table) -> str:
    """``BumberBot.rpp``: the robot's name, in characters any file system takes."""
    return (re.sub(r"[^A-Za-z0-9_-]+", "_", table.robot.name).strip("_") or "engine") + ".rpp"
