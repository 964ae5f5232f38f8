"""Repair before search: a starting table that breaks a property is mended by guard rows, guided by
``check``'s shortest counterexample, before any search starts (every candidate evolution keeps must
satisfy the properties, so the start must too).

Each step reads the shortest counterexample of the first broken property, looks at the ticks where it
goes wrong (for ``when … within D``: the last D + 1 ticks), and proposes a guard row at the top of the
state the robot was in (or just before the row that fired there): needing the pressed inputs the
property watches (each alone, and all together), doing what some row of the table already does for
those inputs (the BumberBot's "Collision detection": stop, pause, go to 20) or keeping the motors for a
few ticks while they stay pressed. Proposals are tried in that order; the first that mends its
counterexample, leaves the property's next counterexample no shorter (the hole moved further away) and
breaks no other property is kept, until every property holds.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from tablebot.analysis.diagram import action, condition
from tablebot.analysis.prove import Result
from tablebot.evolve.operators import Space
from tablebot.evolve.proofs import Prover
from tablebot.evolve.space import Candidate, Gene, to_table
from tablebot.i18n import N_
from tablebot.machine import Machine, compile_table
from tablebot.replay import replay
from tablebot.robot import StateId
from tablebot.table import Table

if TYPE_CHECKING:
    from tablebot.evolve.whole import Tick, Whole

STAY_TIMERS = (1, 10)  # ticks a "keep going while pressed" guard waits before looking again


@dataclass(frozen=True)
class Step:
    """One guard row the repair added: where, what it needs and does, and for which property."""

    prop: str
    state: StateId
    gene: Gene
    counterexample_ticks: int


@dataclass
class Repaired:
    """The outcome: the mended candidate (or the best reached), the steps, and what still fails."""

    candidate: Candidate
    steps: list[Step] = field(default_factory=list)
    failing: tuple[str, ...] = ()
    proposals: int = 0

    @property
    def ok(self) -> bool:
        return not self.failing


PREFERENCES = ("keep", "copy")


def repair(
    candidate: Candidate, base: Table, prover: Prover, space: Space, prefer: str = "keep", max_steps: int = 30
) -> Repaired:
    """Add guard rows until every property holds (or no proposal helps, or ``max_steps`` rows are in).
    Among guard rows that mend equally well, ``prefer`` decides: "keep" (keep going while pressed) or
    "copy" (do what another row does for those inputs); evolve seeds its archive with both repairs."""
    current = candidate
    machine = compile_table(to_table(current, base))
    report = Weighed(machine, *prover.results(machine))
    done = Repaired(current, failing=report.failing)
    for _ in range(max_steps):
        if done.ok:
            return done
        target = next((r for r in report.results if r.status != "holds" and r.inputs), None)
        if target is None:
            return done  # nothing to read a repair from (an unknown result, or a zero-time loop)
        proposals = guard_proposals(current, report.machine, target, space, prefer, prover.whole)
        done.proposals += len(proposals)
        found = None
        for mended, step in proposals:
            found = weigh(mended, base, prover, target, report)
            if found is not None:
                current, report = mended, found
                done = Repaired(current, [*done.steps, step], report.failing, done.proposals)
                break
        if found is None:
            return done  # no guard row mends it without breaking something else: say what still fails
    return done


@dataclass(frozen=True)
class Weighed:
    """A machine's property results and whether a zero-time loop traps it."""

    machine: Machine
    results: list[Result]
    stuck: bool

    @property
    def failing(self) -> tuple[str, ...]:
        return (*(r.prop.name for r in self.results if r.status != "holds"), *(("zero-time-loop",) * self.stuck))


def weigh(mended: Candidate, base: Table, prover: Prover, target: Result, before: Weighed) -> Weighed | None:
    """The mended table's results when it is a step forward: it mends the counterexample it was made for,
    the property's next counterexample is no shorter (or it holds), and no other property breaks."""
    machine = compile_table(to_table(mended, base))
    if prover.violation(target.prop, machine, target.inputs) is not None:
        return None
    again = prover.check(target.prop, machine)
    if again.status != "holds" and len(again.inputs) < len(target.inputs):
        return None
    results, stuck = prover.results(machine)
    after = Weighed(machine, results, stuck)
    if score(after, target.prop.name) > score(before, target.prop.name) or set(after.failing) - set(before.failing):
        return None
    return after


def score(report: Weighed, name: str) -> tuple[int, int]:
    """Fewer broken properties first; then a longer counterexample for the property being repaired."""
    target = next((r for r in report.results if r.prop.name == name and r.status != "holds"), None)
    return len(report.failing), -(len(target.inputs) if target is not None else 10**9)


def guard_proposals(
    candidate: Candidate,
    machine: Machine,
    result: Result,
    space: Space,
    prefer: str = "keep",
    whole: Whole | None = None,
) -> list[tuple[Candidate, Step]]:
    """Candidates with one guard row added where the counterexample goes wrong (see the module doc); of a
    robot of several tables (``whole``), the counterexample replays every table, and the guard rows are the
    evolved table's."""
    table = machine.table
    ticks = _ticks(machine, result) if whole is None else whole.ticks(machine, result.inputs)
    window = result.prop.within + 1 if result.prop.kind == "when" else 1
    watched = _watched(machine, result) if whole is None else whole.watched(result.prop)
    out: list[tuple[Candidate, Step]] = []
    seen: set[tuple] = set()
    for state, pressed, fired in ticks[max(0, len(ticks) - window) :]:
        if space.limits.state_frozen(state) or len(candidate) >= space.limits.max_rows:
            continue
        guard = (pressed & watched) or pressed
        for events in _event_sets(guard, table):
            for gene in _actions(table, state, events, result.prop.name, prefer):
                for at in _places(candidate, state, fired, table):
                    mended = (*candidate[:at], gene, *candidate[at:])
                    if (mended_key := tuple(g.effect() for g in mended)) in seen:
                        continue
                    seen.add(mended_key)
                    out.append((mended, Step(result.prop.name, state, gene, len(result.inputs))))
    return out


def _ticks(machine: Machine, result: Result) -> list[Tick]:
    """The counterexample replayed on the table: per tick the state before it, what was pressed, the row."""
    lines = list(replay(machine, result.inputs))
    pressed = [{name for name, bit in machine.input_bits.items() if line["event"] & bit} for line in lines]
    before = [machine.states[machine.initial_state], *(line["state"] for line in lines[:-1])]
    return [(state, p, line["row"]) for state, p, line in zip(before, pressed, lines, strict=True)]


def _watched(machine: Machine, result: Result) -> set[str]:
    return {name for name, bit in machine.input_bits.items() if bit & result.prop.watch}


def _event_sets(guard: set[str], table: Table) -> list[frozenset[str]]:
    """Each pressed input alone, and all of them together, in the table's column order."""
    ordered = [e for e in table.events if e in guard]
    sets = [frozenset([e]) for e in ordered]
    if len(ordered) > 1:
        sets.append(frozenset(ordered))
    return sets


def _actions(table: Table, state: StateId, events: frozenset[str], prop: str, prefer: str) -> list[Gene]:
    """Guard rows for ``events`` in ``state``: what other rows do for such inputs, or keep going a while."""
    donors = [row for row in table.rows if row.events and row.events <= events]
    copies: dict[tuple, Gene] = {}
    keeps: dict[tuple, Gene] = {}
    when = condition(table, [events])
    for row in donors:
        what = action(table, row)
        does = f"{what.text}{', ' + what.timer if what.timer else ''}"
        # Messages, not text: made in a worker process, said in the reader's language by the report
        text = N_("{when}: {action} (guard for {prop})", when=when, action=does, prop=prop)
        gene = Gene(
            state,
            events,
            row.motors,
            row.timer,
            row.next,
            text,
            row.counters,
            row.lamps,
            note=N_("guard for {prop}, doing what line {line} does", prop=prop, line=row.line),
        )
        copies.setdefault(gene.effect(), gene)
    keep = (None,) * len(table.robot.motors)
    lamps = (None,) * len(table.robot.lamps)
    counters = (None,) * len(table.robot.counter_names)
    for ticks in STAY_TIMERS:
        gene = Gene(
            state,
            events,
            keep,
            ticks,
            state,
            N_("{when}: keep going (guard for {prop})", when=when, prop=prop),
            counters,
            lamps,
            note=N_("guard for {prop}: keep the motors while {when}", prop=prop, when=when),
        )
        keeps.setdefault(gene.effect(), gene)
    first, second = (keeps, copies) if prefer == "keep" else (copies, keeps)
    return [*first.values(), *second.values()]


def _places(candidate: Candidate, state: StateId, fired: int | None, table: Table) -> list[int]:
    """The top of the state's rows, and just before the row that fired at the bad tick."""
    first = next(i for i, gene in enumerate(candidate) if gene.state == state)
    places = [first]
    if fired is not None and table.rows[fired].state == state and fired != first:
        places.append(fired)
    return places
