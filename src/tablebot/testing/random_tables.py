"""Random tables and recorded inputs for property tests and benchmarks of generated code, using keep
cells, the timer, counters, lamps, named states, shuffled event columns, rows that require no event and
either matching rule (the robot file's ``match``)."""

from __future__ import annotations

import random
from dataclasses import dataclass, replace

from tablebot.formats.inputs_csv import TickInput
from tablebot.machine import compile_table
from tablebot.replay import replay
from tablebot.robot import MATCHES, Counter, Match, Robot, StateId
from tablebot.table import MAX_LAMP, MAX_SPEED, TIMER_EVENT, Row, Table


@dataclass(frozen=True)
class Shape:
    """How big a random table is and which features it uses."""

    states: int = 4
    rows: int = 12
    inputs: int = 3
    motors: int = 2
    lamps: int = 0
    counters: int = 0
    max_timer: int = 6
    max_load: int = 6
    event_density: float = 0.3  # chance that a row requires a given event
    keep_chance: float = 0.2  # chance that an output cell is "keep"
    no_event_chance: float = 0.1  # chance that a row requires no event at all (where the two rules differ)
    match: Match | None = None  # the matching rule (robot.MATCHES); None: drawn
    max_speed: int = MAX_SPEED  # the fastest motor speed a row sets (the document's program holds 0..6)


def _state_ids(rng: random.Random, n: int) -> list[StateId]:
    """Numbers and names mixed, so that both kinds of state id go through the generated code."""
    return [f"S{i}" if rng.random() < 0.3 else i * 3 + 1 for i in range(n)]


def _row(
    rng: random.Random, shape: Shape, robot: Robot, events: tuple[str, ...], state: StateId, states: list[StateId]
) -> Row:
    def out(low: int, high: int) -> int | None:
        return None if rng.random() < shape.keep_chance else rng.randint(low, high)

    required = {e for e in events if rng.random() < shape.event_density}
    if rng.random() < shape.no_event_chance:
        required = set()
    elif not required:  # otherwise conditional rows, so that states are left
        required.add(rng.choice(events))
    return Row(
        index=-1,
        line=-1,
        description="random",
        state=state,
        events=frozenset(required),
        motors=tuple(out(-shape.max_speed, shape.max_speed) for _ in robot.motors),
        timer=rng.randint(0, shape.max_timer),
        next=rng.choice(states),
        counters=tuple(None if rng.random() < 0.5 else rng.randint(0, shape.max_load) for _ in robot.counters),
        lamps=tuple(out(0, MAX_LAMP) for _ in robot.lamps),
    )


def random_table(rng: random.Random, shape: Shape = Shape()) -> Table:
    """A valid table of ``shape``: every state has a row, every next state exists."""
    motors = tuple(f"M{i + 1}" for i in range(shape.motors))
    robot = Robot(
        name="Random",
        inputs=tuple(f"I{i + 1}" for i in range(shape.inputs)),
        motors=motors,
        counters=tuple(
            Counter(f"C{i + 1}", motors[i % len(motors)] if motors else "M1") for i in range(shape.counters)
        ),
        lamps=tuple(f"L{i + 1}" for i in range(shape.lamps)),
        initial_state=0,
        initial_timer=rng.randint(0, shape.max_timer),
        source="random",
    )
    states = _state_ids(rng, shape.states)
    robot = Robot(
        **{**robot.__dict__, "initial_state": rng.choice(states), "match": shape.match or rng.choice(MATCHES)}
    )
    events = [TIMER_EVENT, *robot.inputs, *robot.counter_names]
    rng.shuffle(events)
    owners = states + [rng.choice(states) for _ in range(max(0, shape.rows - len(states)))]
    rng.shuffle(owners)
    rows = [_row(rng, shape, robot, tuple(events), state, states) for state in owners]
    numbered = tuple(
        Row(i, i + 2, r.description, r.state, r.events, r.motors, r.timer, r.next, r.counters, r.lamps)
        for i, r in enumerate(rows)
    )
    return Table(robot=robot, events=tuple(events), rows=numbered, path="<random>")


def random_inputs(
    rng: random.Random, table: Table, ticks: int, density: float = 0.3, max_pulses: int = 2
) -> list[TickInput]:
    """Recorded inputs for a table: each input reads 1 with ``density``; a few pulses per counter."""
    bits = [table.bit(name) for name in table.input_events]
    n_counters = len(table.robot.counters)
    return [
        TickInput(
            sum(b for b in bits if rng.random() < density), tuple(rng.randint(0, max_pulses) for _ in range(n_counters))
        )
        for _ in range(ticks)
    ]


def with_match(table: Table, match: Match) -> Table:
    """The same table under the other (or a given) matching rule."""
    return replace(table, robot=replace(table.robot, match=match))


def random_case(
    rng: random.Random, shape: Shape = Shape(), ticks: int = 150, tries: int = 500
) -> tuple[Table, list[TickInput]]:
    """A random table of ``shape`` and inputs on which the two matching rules part: some tick comes with
    no event at all in a state with a row that requires none, so an executor that ignores the table's
    rule (``shape.match``, else drawn) takes another decision somewhere. Tests of an executor use it so
    that they can fail."""
    shape = replace(shape, no_event_chance=max(shape.no_event_chance, 0.25))
    for _ in range(tries):
        table = random_table(rng, shape)
        inputs = random_inputs(rng, table, ticks)
        other = with_match(table, next(m for m in MATCHES if m != table.robot.match))
        if list(replay(compile_table(table), inputs)) != list(replay(compile_table(other), inputs)):
            return table, inputs
    raise ValueError(f"no table of {shape} parts the two matching rules in {tries} tries")
