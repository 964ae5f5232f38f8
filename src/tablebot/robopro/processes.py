"""The ROBO Pro program of a robot of several tables (``[tables]``): one process per table, as the document's
main program runs its FlashLights routine beside the engine, and a clock process that keeps them in step.

ROBO Pro runs every Start of the main program as a process of its own (real main programs hold several: the
corpus's TeachIn robot eleven), switching between them as it likes, so the tables' rule (:mod:`tablebot.tables`:
inputs read once per tick, cross-table events from the states at the start of the tick) needs a barrier. The
clock process (the main program's first Start) takes the tick's image before any table looks: each input a table
reads into ``in I3``, each counter into ``C1 tick``, each table's state ``drive ST`` into ``drive S0``; then it
flips ``TICK`` (0, 1, 0, …: a 16-bit count would overflow after 32767 ticks), waits one tick, waits until
``DONE`` says every table has finished, sets it to 0 and counts the counters down. Each table's process (a Start
of its own beside it) is the document's engine loop on the table's own variables, lists and subprograms
(``drive ST``, ``drive Event``, ``drive DetectEvent``): it waits until ``TICK`` is not what it last saw
(``drive WaitTick``, looking every millisecond), runs DetectEvent (reading the image: cross-table columns through
a list by the other table's state number, ``drive from lights``), DetermineAction and ExecuteAction, adds 1 to
``DONE``, waits for the next tick and counts its timer down. A table writes only the outputs it has columns for,
so no two processes drive one output, and none reads what another writes during the tick: the order ROBO Pro
runs them in changes nothing (the interpreter switches between them at random after any element to show it:
tests/robopro/test_robopro_several.py).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial

from tablebot.diagnostics import Diagnostic, TableBotError
from tablebot.i18n import N_
from tablebot.robopro import elements as el
from tablebot.robopro.document import Sub, document
from tablebot.robopro.fit import Plan, problems
from tablebot.robopro.lists import number_states
from tablebot.robopro.program import (
    COLUMN,
    ENGINE,
    ENTRY,
    EXIT,
    INDENT,
    MAIN,
    Builder,
    begin_outputs,
    count_counters,
    engine_loop,
)
from tablebot.robopro.rpp_write import Canvas, Ids, caption
from tablebot.robopro.sheet import Const, Count, Input, Op, Sheet, Tree, Var
from tablebot.robopro.wiring import wiring
from tablebot.tables import RobotTables

__all__ = ["generate_several", "plans", "several_problems"]

WAIT_TICK = "WaitTick"
NOTES_WIDTH = 160  # room for a column's comments before the next process's column
POLL_MS = 1  # how often a table's process looks for the next tick
MIN_TICK_MS = 10  # a tick must leave the processes time to look for it and run


def plans(tables: RobotTables) -> list[Plan]:
    """Each table's plan, with every table's state numbers for its cross-table columns."""
    numbers = {t.name: number_states(t) for t in tables.tables}
    return [Plan(t, wiring(t.robot), t.robot.match, numbers[t.name], numbers) for t in tables.tables]


def several_problems(tables: RobotTables) -> list[Diagnostic]:
    """Every reason the robot's tables do not fit the program (a robot-wide one once)."""
    found: list[Diagnostic] = []
    seen: set[tuple[str, int | None, str]] = set()
    for table in tables.tables:
        for problem in problems(table):
            if (problem.path, problem.line, problem.message) not in seen:
                seen.add((problem.path, problem.line, problem.message))
                found.append(problem)
    robot = tables.robot
    if robot.tick_ms < MIN_TICK_MS:
        line = robot.line("", "tick_ms") if robot.toml else None
        found.append(
            Diagnostic(
                robot.source,
                line,
                None if line is None else 1,
                N_(
                    "tick_ms = {tick}: the processes of the tables look for the next tick every "
                    "{poll} ms and need a tick of at least {least} ms",
                    tick=robot.tick_ms,
                    poll=POLL_MS,
                    least=MIN_TICK_MS,
                ),
                N_("set tick_ms = {least} or more", least=MIN_TICK_MS),
            )
        )
    return found


def generate_several(tables: RobotTables) -> str:
    """The whole .rpp text for a robot of several tables; raises :class:`TableBotError` when one does not fit."""
    found = several_problems(tables)
    if found:
        raise TableBotError(found)
    ps = plans(tables)
    ids, subs, inits = Ids(), dict[str, Sub](), dict[str, int]()
    builders = [Builder(p, f"{p.table.name} ", ids, subs, inits) for p in ps]
    inits.update({f"{p.table.name} S0": p.initial_state for p in ps})
    for b in builders:
        for build in ENGINE:
            build(b)
        wait_tick(b)
    main = main_program(Builder(ps[0], "", ids, subs, inits), tables, builders)
    return document(ids, ps[0], [main, *(sub for name, sub in subs.items() if name != MAIN)])


def wait_tick(b: Builder) -> Sub:
    """Until the clock flips TICK away from what this table last saw, look again every POLL_MS ms."""
    s, v = b.sheet(), b.v
    s.begin(el.flow_in(COLUMN, 8, ENTRY, 1))
    new = s.step(lambda x, y: el.branch(x, y, yes_down=True), data=Op("XOR", Var("TICK"), Var(v("SEEN"))))
    loop_wire, loop_in = s.last_wire, new.pins[1].at
    (pause,), _ = s.side(new.pins[3], [lambda x, y: el.wait(x, y, POLL_MS)], rejoin=False)
    b.note(s, new, "a new tick (TICK is not SEEN)? else look again in 1 ms")
    b.assign(s, v("SEEN"), "=", data=Var("TICK"))
    s.step(lambda x, y: el.flow_out(x, y, EXIT, 2))
    assert loop_wire is not None
    s.loop_back(pause.pins_of("flowobjectoutput")[0], loop_wire, (loop_in[0], loop_in[1] - 4))
    return b.finish(b.v(WAIT_TICK), s, [(EXIT, 2)], "Wait until the clock process starts the next tick")


def table_process(b: Builder, s: Sheet) -> None:
    """The table's engine after its Start: its start, then each tick once the clock has started it, DONE + 1
    when it is done."""
    begin_outputs(b, s)
    b.call(s, b.v(WAIT_TICK))

    def end_tick(s: Sheet) -> None:
        s.release()
        done = b.assign(s, "DONE", "+", 1)
        b.note(s, done, "this table's tick is done")
        b.call(s, b.v(WAIT_TICK))

    engine_loop(b, s, end_tick, notes=False)


def clock(b: Builder, s: Sheet, tables: RobotTables) -> None:
    """After its Start: the tick's image (inputs, counters, states), TICK flipped, one tick, the barrier, the
    counters down, and again."""
    wired, robot = b.p.wiring, tables.robot
    for name, counter in wired.counters.items():
        b.assign(s, name, "=", 0)
        b.assign(s, f"{name} last", "=", data=Count(counter))
    snapshot: list[tuple[str, Tree]] = [(f"in {name}", Input(wired.inputs[name][0])) for name in tables.input_bits]
    snapshot += [(f"{name} tick", Var(name)) for name in robot.counter_names]
    sources = {event.table for table in tables.tables for event in table.cross.values()}
    snapshot += [(f"{name} S0", Var(f"{name} ST")) for name in tables.names if name in sources]
    loop_wire, loop_in = None, (0, 0)
    for target, tree in [*snapshot, ("TICK", Op("XOR", Var("TICK"), Const(1)))]:
        element = b.assign(s, target, "=", data=tree)
        if loop_wire is None:
            loop_wire, loop_in = s.last_wire, element.pins_of("flowobjectinput")[0].at
            b.note(s, element, "the tick's image: inputs, counters, states at the start of the tick")
    b.note(s, element, "TICK flips: the tables' processes start the tick")
    tick = s.step(lambda x, y: el.wait(x, y, robot.tick_ms))
    b.note(s, tick, f"one tick: {robot.tick_ms} ms")
    done = s.step(lambda x, y: el.branch(x, y, yes_down=False), data=Op("XOR", Var("DONE"), Const(len(tables.tables))))
    done_wire, done_in = s.last_wire, done.pins[1].at
    (pause,), _ = s.side(done.pins[3], [lambda x, y: el.wait(x, y, POLL_MS)], rejoin=False)
    b.note(s, done, f"every table done (DONE = {len(tables.tables)})? else look again in 1 ms")
    count_counters(b, s)
    last = b.assign(s, "DONE", "=", 0)
    assert loop_wire is not None and done_wire is not None
    s.loop_back(pause.pins_of("flowobjectoutput")[0], done_wire, (done_in[0], done_in[1] - 4))
    s.loop_back(last.pins_of("flowobjectoutput")[0], loop_wire, (loop_in[0], loop_in[1] - 4))


def main_program(b: Builder, tables: RobotTables, builders: list[Builder]) -> Sub:
    """A Start per process, as real main programs run several: the clock's column first (the process whose Wait
    is the tick), then each table's engine; each column's comments right of it; the tables' lists below all."""
    canvas, x, low = Canvas(b.ids), COLUMN, 0
    columns: list[tuple[Callable[[Sheet], None], str]] = [
        (lambda s: clock(b, s, tables), "the clock: keeps the tables' processes in step")
    ]
    columns += [(partial(table_process, t), f"table {t.p.table.name}") for t in builders]
    for body, title in columns:
        sheet = Sheet(canvas, x, b.inits, INDENT)
        start = sheet.begin(el.start(x, 8))
        sheet.note(start.y, title)
        body(sheet)
        notes_x = max(sheet.right, sheet.lanes) + 24
        for y, text in sheet.notes:
            canvas.comments.append(caption(INDENT, b.ids(), text, (notes_x, y), size=3, align="336", linespace="0"))
        x = notes_x + NOTES_WIDTH + COLUMN
        low = max(low, sheet.y)
    lines = [line for t in builders for line in t.p.table_notes()]
    for n, line in enumerate(lines):
        canvas.comments.append(
            caption(INDENT, b.ids(), line, (COLUMN - 96, low + 24 + 4 * n), size=2, align="336", linespace="0")
        )
    summary = (
        f"Generated by tablebot for {tables.robot.name} ({b.p.wiring.controller}): a process per table "
        f"({', '.join(tables.names)}) and a clock process that starts each tick for all of them from the "
        "same inputs and states."
    )
    sub = Sub(MAIN, canvas, [], [], summary)
    b.subs[MAIN] = sub
    return sub
