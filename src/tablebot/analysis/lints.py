"""What ``tablebot check`` finds in a table without any properties: rows that can never fire,
order-dependent overlaps, unreachable states, dead ends, zero-time loops, timers that never run
out, ignored inputs, rows that require no event (what the matching rule does with them) and export
limits. Each finding names rows by their line in the file.
"""

from __future__ import annotations

import functools
import operator
from dataclasses import dataclass, field

from tablebot import registry
from tablebot.analysis.finding import SEVERITIES, Finding
from tablebot.analysis.loops import zero_time_loops
from tablebot.analysis.matching import no_event_findings
from tablebot.analysis.model import Graph, Model
from tablebot.analysis.names import event_name, events_text, lines_text, mask_events, rows_phrase, state_text
from tablebot.i18n import N_
from tablebot.machine import NO_ROW, Machine
from tablebot.robot import StateId
from tablebot.table import TIMER_EVENT, Row, Table

MAX_IGNORED_BITS = 16


def find_all(machine: Machine, graph: Graph | None = None, targets: tuple[str, ...] = ()) -> list[Finding]:
    """Every finding, in file order; ``graph`` is the explored model (built here if not given)."""
    table = machine.table
    graph = graph or Model(machine).explore()
    shadowed = shadowed_rows(table)
    found = [*shadowed, *overlaps(table), *ignored_inputs(machine), *zero_time_loops(graph), *no_event_findings(table)]
    found += reachability(machine, graph, {f.lines[0] for f in shadowed})
    for target in targets:
        found += encoding(machine, target)
    order = {s: i for i, s in enumerate(SEVERITIES)}
    return sorted(found, key=lambda f: (f.lines[0] if f.lines else 0, order[f.severity], f.code))


def rows_of(table: Table, state: StateId) -> list[Row]:
    return list(table.rows_by_state.get(state, ()))


def _same_effect(a: Row, b: Row) -> bool:
    return (a.next, a.motors, a.timer, a.counters, a.lamps) == (b.next, b.motors, b.timer, b.counters, b.lamps)


# --- row order --------------------------------------------------------------------------------------


def _first_rows(masks: list[int]) -> dict[int, int]:
    """Each distinct event mask of a state's rows -> the first of its rows with that mask."""
    first: dict[int, int] = {}
    for i, mask in enumerate(masks):
        first.setdefault(mask, i)
    return first


def _winner(first_with: dict[int, int], events: int) -> int:
    """The row that fires for ``events`` (one of the rows' masks, or a union of them): the first whose
    mask is a subset. Compares distinct masks, not every row: a long table repeats a few masks."""
    return min(k for m, k in first_with.items() if m & events == m)


def shadowed_rows(table: Table) -> list[Finding]:
    """A row can never fire if an earlier row of its state needs a subset of its events: whenever
    this row's events are all present, so are the earlier row's, and the earlier row wins."""
    found = []
    for state in table.states:
        rows = rows_of(table, state)
        masks = [table.mask(r.events) for r in rows]
        first_with = _first_rows(masks)
        for i, row in enumerate(rows):
            winner = _winner(first_with, masks[i])
            if winner == i:
                continue
            earlier = rows[winner]
            needs = (
                N_("needs only {events}, so it always wins first", events=events_text(table, earlier.events))
                if earlier.events
                else N_("needs no event at all, so it fires first every time")
            )
            found.append(
                Finding(
                    "shadowed-row",
                    "warning",
                    N_(
                        "row on line {line} can never fire: in {state} the earlier row on line {earlier} {needs}",
                        line=row.line,
                        state=state_text(table, state),
                        earlier=earlier.line,
                        needs=needs,
                    ),
                    (row.line, earlier.line),
                    N_(
                        "move this row above line {earlier} if it is the more specific case, or delete it",
                        earlier=earlier.line,
                    ),
                    state,
                    {"shadowed_by": earlier.line},
                )
            )
    return found


def overlaps(table: Table) -> list[Finding]:
    """Pairs of rows of one state that both match some event set: the earlier one wins there."""
    found = []
    for state in table.states:
        rows = rows_of(table, state)
        masks = [table.mask(r.events) for r in rows]
        first_with = _first_rows(masks)
        # Only a row that wins its own events can win a pair; per later mask, which of those do.
        candidates = [i for i, mask in enumerate(masks) if _winner(first_with, mask) == i]
        partners: dict[int, list[int]] = {}
        for j, later in enumerate(rows):
            mask = masks[j]
            if mask not in partners:
                partners[mask] = [
                    i for i in candidates if masks[i] & mask != masks[i] and _winner(first_with, masks[i] | mask) == i
                ]
            for i in partners[mask]:
                if i >= j:
                    break
                first = rows[i]
                if _same_effect(first, later):
                    continue  # same effect means order cannot matter
                both = first.events | later.events
                kind = (
                    N_("specific before general") if later.events <= first.events else N_("neither contains the other")
                )
                found.append(
                    Finding(
                        "overlap",
                        "info",
                        N_(
                            "in {state}, when {events} happen together, the rows on lines {first} and {later} both "
                            "match; line {first} wins because it comes first ({kind})",
                            state=state_text(table, state),
                            events=events_text(table, both),
                            first=first.line,
                            later=later.line,
                            kind=kind,
                        ),
                        (first.line, later.line),
                        "",
                        state,
                        {"events": sorted(both, key=table.events.index), "winner": first.line},
                    )
                )
    return found


def ignored_inputs(machine: Machine) -> list[Finding]:
    """Inputs that never change which row fires in a state (pressing them there does nothing)."""
    table = machine.table
    found = []
    for index, state in enumerate(machine.states):
        ignored = [name for name, bit in machine.input_bits.items() if _never_matters(machine, index, bit)]
        if not ignored or not rows_of(table, state):
            continue
        names = tuple(event_name(table, n) for n in ignored)
        found.append(
            Finding(
                "ignored-inputs",
                "info",
                N_("in {state} the robot does not react to {names}", state=state_text(table, state), names=names),
                (rows_of(table, state)[0].line,),
                "",
                state,
                {"inputs": ignored},
            )
        )
    return found


def _never_matters(machine: Machine, state: int, bit: int) -> bool:
    relevant = machine.dispatch[state].relevant
    if not relevant & bit:  # unless it alone makes a tick with no other event fire a row (the document's rule)
        return machine.lookup(state, bit) == machine.lookup(state, 0)
    if relevant.bit_count() > MAX_IGNORED_BITS:
        return False
    lookup = machine.lookup
    sub = relevant
    while True:
        if lookup(state, sub) != lookup(state, sub ^ bit):
            return False
        if sub == 0:
            return True
        sub = (sub - 1) & relevant


# --- reachability -----------------------------------------------------------------------------------


@dataclass
class Seen:
    """What the explored model says per state: the timer/counter events seen there, rows fired."""

    contexts: dict[int, set[int]] = field(default_factory=dict)
    fired: set[int] = field(default_factory=set)
    idle_rows: dict[int, set[int]] = field(default_factory=dict)  # rows firing with no input pressed

    @classmethod
    def of(cls, graph: Graph) -> Seen:
        seen = cls()
        input_mask = graph.model.machine.input_mask
        for node, (events, _, row, _) in graph.ticks():
            seen.contexts.setdefault(node[0], set()).add(events & ~input_mask)
            if row != NO_ROW:
                seen.fired.add(row)
                if not events & input_mask:
                    seen.idle_rows.setdefault(node[0], set()).add(row)
        return seen


def reachability(machine: Machine, graph: Graph, shadowed_lines: set[int]) -> list[Finding]:
    """Unreachable states, dead ends, timers that never run out, and rows that never fire."""
    table = machine.table
    seen = Seen.of(graph)
    reached = graph.states()
    found = []
    for index, state in enumerate(machine.states):
        rows = rows_of(table, state)
        if index not in reached:
            found.append(_unreachable(machine, state, rows, seen))
            continue
        found += _dead_end(table, state, rows, seen)
        silent = [r for r in rows if r.index not in seen.fired and r.line not in shadowed_lines]
        found += _never_fire(machine, index, silent, seen)
    return found


def _unreachable(machine: Machine, state: StateId, rows: list[Row], seen: Seen) -> Finding:
    table = machine.table
    into = [r for r in table.rows if r.next == state and r.state != state]
    start = state_text(table, machine.states[machine.initial_state])
    why = (
        N_("no row leads to it")
        if not into
        else N_("the rows that lead to it ({lines}) can never fire", lines=lines_text(into))
    )
    return Finding(
        "unreachable-state",
        "warning",
        N_(
            "{state} can never be reached from the initial {start}: {why}; its rows ({lines}) are dead",
            state=state_text(table, state),
            start=start,
            why=why,
            lines=lines_text(rows),
        ),
        tuple(r.line for r in rows),
        N_("add a row that leads here, or delete these rows"),
        state,
    )


def _dead_end(table: Table, state: StateId, rows: list[Row], seen: Seen) -> list[Finding]:
    leaving = [r for r in rows if r.next != state]
    if any(r.index in seen.fired for r in leaving):
        return []
    why = (
        N_("no row of it leads to another state")
        if not leaving
        else N_("the rows that lead out ({lines}) can never fire", lines=lines_text(leaving))
    )
    return [
        Finding(
            "dead-end",
            "warning",
            N_("once the robot is in {state} it can never leave: {why}", state=state_text(table, state), why=why),
            (rows[0].line,),
            N_("add a row that leads to another state (a timeout on T, say)"),
            state,
        )
    ]


def _never_fire(machine: Machine, index: int, silent: list[Row], seen: Seen) -> list[Finding]:
    table = machine.table
    state = machine.states[index]
    contexts = seen.contexts.get(index, set())
    waiting_for_t = [r for r in silent if TIMER_EVENT in r.events and not any(c & machine.timer_bit for c in contexts)]
    found = []
    if waiting_for_t:
        busy = sorted(seen.idle_rows.get(index, set()))
        reload = lines_text([table.rows[i] for i in busy]) if busy else N_("other rows")
        found.append(
            Finding(
                "timer-never-expires",
                "warning",
                N_(
                    "in {state} the timer never runs out: on every tick a row fires first and reloads it ({reload}), "
                    "so {rows} waiting for T can never fire",
                    state=state_text(table, state),
                    reload=reload,
                    rows=rows_phrase(waiting_for_t),
                ),
                tuple(r.line for r in waiting_for_t),
                N_("a row that needs no input fires whenever nothing above it matches; give it an input to wait for"),
                state,
            )
        )
    for row in silent:
        if row in waiting_for_t:
            continue
        found.append(
            Finding(
                "row-never-fires",
                "warning",
                _why_silent(machine, index, row, contexts),
                (row.line,),
                N_("check the order and the events of this state's rows"),
                state,
            )
        )
    return found


def _why_silent(machine: Machine, index: int, row: Row, contexts: set[int]) -> str:
    """Why a row that is not shadowed still never fires in any reachable situation."""
    table = machine.table
    mask = table.mask(row.events)
    needs = mask & ~machine.input_mask
    where = state_text(table, machine.states[index])
    fits = [c for c in contexts if c & needs == needs]
    if not fits:
        missing = [e for e in mask_events(table, needs) if not any(c & table.bit(e) for c in contexts)]
        return N_(
            "row on line {line} can never fire: it needs {events}, which never happens while the robot is in {where}",
            line=row.line,
            events=events_text(table, missing),
            where=where,
        )
    winners = {machine.lookup(index, c | (mask & machine.input_mask)) for c in fits}
    lines = sorted(table.rows[w].line for w in winners if w != NO_ROW)
    if not lines:  # it needs no event, and no event ever comes here: the document's rule looks up no row
        return N_(
            "row on line {line} can never fire: it requires no event, and in {where} no event ever comes, "
            'so under match = "document" no row is looked up there',
            line=row.line,
            where=where,
        )
    always = functools.reduce(operator.and_, fits) & ~needs
    also = events_text(table, mask_events(table, always))
    if always:
        return N_(
            "row on line {line} can never fire: whenever its events happen, the row on line {first} fires "
            "first (in {where} there is always {also} as well)",
            line=row.line,
            first=", ".join(map(str, lines)),
            where=where,
            also=also,
        )
    return N_(
        "row on line {line} can never fire: whenever its events happen, the row on line {first} fires first",
        line=row.line,
        first=", ".join(map(str, lines)),
    )


# --- export limits ----------------------------------------------------------------------------------


def encoding(machine: Machine, target: str) -> list[Finding]:
    """What an export target cannot hold, as errors (its exporter would refuse the table): the fit
    check of its back-end (:mod:`tablebot.registry`)."""
    table_path = machine.table.path
    return [
        Finding(
            f"encoding-{target}",
            "error",
            N_("{target}: {problem}", target=target, problem=d.message)
            if d.path == table_path
            else N_("{target}: {problem} ({where})", target=target, problem=d.message, where=d.location()),
            (d.line,) if d.line is not None and d.path == table_path else (),
            d.hint,
        )
        for d in registry.get(target).problems(machine)
    ]
