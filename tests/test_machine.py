"""The compiled machine equals the document's rule, a naive linear scan, over random tables and inputs.

Tables are generated as data, written as CSV (in either motor form, columns in random order),
parsed and compiled; the reference below runs the generated data directly, so parser, compiler and
engine are checked together against an implementation of the semantics that shares no code.
"""

from __future__ import annotations

import random
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from core_helpers import example_machine
from tablebot.engine import Engine
from tablebot.formats.table_read import parse_table
from tablebot.formats.table_write import format_table
from tablebot.machine import NO_ROW, PREFILL_BITS, compile_table, first_match
from tablebot.robot import MATCHES, Counter, Match, Robot
from tablebot.table import Row, Table

if TYPE_CHECKING:
    from tablebot.machine import Machine

SETTINGS = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
INPUTS = ("A", "B", "C")
MOTORS = ("M1", "M2")
COUNTERS = ("C1", "C2")


@dataclass(frozen=True)
class SpecRow:
    state: int | str
    events: frozenset[str]
    motors: tuple[int | None, ...]  # None = keep
    lamps: tuple[int | None, ...]
    loads: tuple[int | None, ...]  # None = leave the counter alone
    timer: int
    next: int | str


@dataclass(frozen=True)
class Spec:
    inputs: tuple[str, ...]
    counters: tuple[str, ...]
    lamps: tuple[str, ...]
    columns: tuple[str, ...]  # event columns, in header order
    forms: tuple[str, ...]  # per motor: "signed" or "doc"
    states: tuple[int | str, ...]
    rows: tuple[SpecRow, ...]
    initial_state: int | str
    initial_timer: int
    order: tuple[int, ...]  # permutation of the CSV's columns
    match: Match = "always"  # the robot file's rule for a tick with no event


# --- the reference: the document's algorithm, literally ---------------------------------------------


class Naive:
    """Linear scan over the generated rows, names and sets only."""

    def __init__(self, spec: Spec) -> None:
        self.spec = spec
        self.state = spec.initial_state
        self.timer = spec.initial_timer
        self.counters = [0] * len(spec.counters)
        self.outputs: list[int] = [0] * (len(MOTORS) + len(spec.lamps))
        self.first = True

    def step(self, inputs: set[str], pulses: tuple[int, ...]) -> tuple[int | None, set[str]]:
        if not self.first:
            self.timer = max(0, self.timer - 1)
            self.counters = [max(0, c - p) for c, p in zip(self.counters, pulses, strict=True)]
        self.first = False
        present = set(inputs) | ({"T"} if self.timer == 0 else set())
        present |= {name for name, value in zip(self.spec.counters, self.counters, strict=True) if value == 0}
        present &= set(self.spec.columns)  # T and counters are events only where they are columns
        if not present and self.spec.match == "document":  # "if an event is detected" ...
            return None, present
        for index, row in enumerate(self.spec.rows):
            if row.state == self.state and row.events <= present:
                self.fire(row)
                return index, present
        return None, present

    def fire(self, row: SpecRow) -> None:
        for i, value in enumerate((*row.motors, *row.lamps)):
            if value is not None:
                self.outputs[i] = value
        for i, load in enumerate(row.loads):
            if load is not None:
                self.counters[i] = load
        self.timer = row.timer
        self.state = row.next


# --- generating tables --------------------------------------------------------------------------------

STATE_POOL: tuple[int | str, ...] = (1, 2, 3, 20, "seek", "back off")


@st.composite
def specs(draw: st.DrawFn, max_rows: int = 12) -> Spec:
    inputs = tuple(draw(st.sampled_from([INPUTS[:n] for n in range(1, 4)])))
    counters = COUNTERS[: draw(st.integers(0, 2))]
    lamps = ("L1",)[: draw(st.integers(0, 1))]
    candidates = [*(["T"] if draw(st.booleans()) else []), *inputs, *counters]
    columns = tuple(draw(st.permutations(candidates)))
    states = tuple(draw(st.lists(st.sampled_from(STATE_POOL), min_size=1, max_size=4, unique=True)))
    forms = (draw(st.sampled_from(["signed", "doc"])), draw(st.sampled_from(["signed", "doc"])))
    rows = draw(
        st.lists(
            st.builds(
                SpecRow,
                state=st.sampled_from(states),
                events=st.frozensets(st.sampled_from(columns)) if columns else st.just(frozenset()),
                motors=st.tuples(*[_motor_values(form) for form in forms]),
                lamps=st.tuples(*[st.one_of(st.none(), st.integers(0, 8)) for _ in lamps]),
                loads=st.tuples(*[st.one_of(st.none(), st.integers(0, 4)) for _ in counters]),
                timer=st.integers(0, 4),
                next=st.sampled_from(states),
            ),
            max_size=max_rows,
        )
    )
    for state in states:  # every state needs a row, else "next state unknown"
        if all(r.state != state for r in rows):
            rows.insert(
                draw(st.integers(0, len(rows))),
                SpecRow(state, frozenset(), (0, 0), (None,) * len(lamps), (None,) * len(counters), 1, states[0]),
            )
    n_columns = 4 + len(columns) + sum(2 if f == "doc" else 1 for f in forms) + len(lamps) + len(counters)
    return Spec(
        inputs,
        counters,
        lamps,
        columns,
        forms,
        states,
        tuple(rows),
        initial_state=draw(st.sampled_from(states)),
        initial_timer=draw(st.integers(0, 3)),
        order=tuple(draw(st.permutations(range(n_columns)))),
        match=draw(st.sampled_from(MATCHES)),
    )


def _motor_values(form: str) -> st.SearchStrategy[int | None]:
    """Signed speeds or keep; the document's form has no speed 7 (7 means keep there)."""
    speeds = st.integers(-8, 8)
    return st.one_of(st.none(), speeds if form == "signed" else speeds.filter(lambda v: abs(v) != 7))


def robot_of(spec: Spec) -> Robot:
    return Robot(
        name="Random",
        inputs=spec.inputs,
        motors=MOTORS,
        counters=tuple(Counter(name, motor) for name, motor in zip(spec.counters, MOTORS, strict=False)),
        lamps=spec.lamps,
        initial_state=spec.initial_state,
        initial_timer=spec.initial_timer,
        match=spec.match,
    )


def _motor_cells(value: int | None, form: str, rnd: random.Random) -> list[str]:
    if form == "signed":
        return [rnd.choice(["=", "keep", "KEEP"]) if value is None else str(value)]
    if value is None:
        return [rnd.choice(["", "0", "1"]), "7"]  # speed 7 keeps, whatever the direction
    if value == 0:
        return [rnd.choice(["", "0", "1"]), rnd.choice(["0", ""])]
    return ["1" if value < 0 else rnd.choice(["", "0"]), str(abs(value))]


def _header(spec: Spec) -> list[str]:
    header = ["description", "state", *spec.columns]
    for motor, form in zip(MOTORS, spec.forms, strict=True):
        header += [motor] if form == "signed" else [f"{motor}_dir", f"{motor}_speed"]
    return [*header, *spec.lamps, *(f"{c}_load" for c in spec.counters), "timer", "next"]


def event_columns(spec: Spec) -> tuple[str, ...]:
    """The event columns in the order the shuffled CSV header has them."""
    header = _header(spec)
    return tuple(header[i] for i in spec.order if header[i] in spec.columns)


def to_csv(spec: Spec) -> str:
    """The spec as a spreadsheet would save it (blank cells where the format allows)."""
    rnd = random.Random(repr(spec))  # blanks vs zeros vary, but the same spec always gives the same text
    lines = [_header(spec)]
    for index, row in enumerate(spec.rows):
        cells = [
            f"r{index}",
            str(row.state),
            *("1" if e in row.events else rnd.choice(["", "0"]) for e in spec.columns),
        ]
        for value, form in zip(row.motors, spec.forms, strict=True):
            cells += _motor_cells(value, form, rnd)
        cells += [rnd.choice(["", "="]) if v is None else str(v) for v in row.lamps]
        cells += [rnd.choice(["", "="]) if v is None else str(v) for v in row.loads]
        cells += [str(row.timer) if row.timer or rnd.random() < 0.5 else "", str(row.next)]
        lines.append(cells)
    return "\n".join(",".join(cells[i] for i in spec.order) for cells in lines) + "\n"


def build(spec: Spec) -> Machine:
    return compile_table(parse_table(to_csv(spec), "<random>", robot_of(spec)))


ticks = st.lists(
    st.tuples(st.frozensets(st.sampled_from(INPUTS)), st.tuples(st.integers(0, 2), st.integers(0, 2))), max_size=40
)


def mask_of(present: set[str], columns: tuple[str, ...]) -> int:
    """The trace's event mask from names: the first event column is the highest bit."""
    return sum(1 << (len(columns) - 1 - columns.index(e)) for e in present if e in columns)


# --- the properties ---------------------------------------------------------------------------------


@SETTINGS
@given(spec=specs(), inputs=ticks)
def test_compiled_engine_equals_linear_scan(spec: Spec, inputs: list[tuple[frozenset[str], tuple[int, int]]]) -> None:
    machine = build(spec)
    engine, naive = Engine(machine), Naive(spec)
    for present, pulses in inputs:
        outputs = engine.step({name: 1 for name in present if name in machine.input_bits}, pulses[: len(spec.counters)])
        row, events = naive.step(set(present) & set(spec.inputs), pulses[: len(spec.counters)])
        assert engine.row == (NO_ROW if row is None else row)
        assert engine.event == mask_of(events, event_columns(spec))
        assert machine.states[engine.state] == naive.state
        assert engine.timer == naive.timer
        assert list(outputs) == naive.outputs
        assert engine.counters == naive.counters


@SETTINGS
@given(spec=specs(), inputs=ticks, split=st.integers(0, 40), jit=st.booleans())
def test_batch_path_equals_step_path(
    spec: Spec, inputs: list[tuple[frozenset[str], tuple[int, int]]], split: int, jit: bool
) -> None:
    """``run(masks)`` (no pulses on that path), compiled or in Python, gives what ``step`` gives,
    also when a run resumes from where the last one stopped."""
    machine = build(spec)
    masks = [sum(machine.input_bits.get(name, 0) for name in present) for present, _ in inputs]
    stepper, batcher = Engine(machine), Engine(machine)
    expected = []
    for mask in masks:
        stepper.step(mask)
        expected.append((stepper.event, stepper.row, stepper.state, stepper.timer))
    first, second = batcher.run(masks[:split], jit=jit), batcher.run(masks[split:], jit=jit)
    got = [
        *zip(first.events, first.rows, first.states, first.timers, strict=True),
        *zip(second.events, second.rows, second.states, second.timers, strict=True),
    ]
    assert got == expected
    assert batcher.snapshot() == stepper.snapshot()
    assert (batcher.event, batcher.row) == (stepper.event, stepper.row) or not masks


@SETTINGS
@given(spec=specs())
def test_lookup_is_first_match_for_every_event_set(spec: Spec) -> None:
    machine = build(spec)
    width = len(machine.table.events)
    for state in range(len(machine.states)):
        rows = [r for r in machine.rows if r.state == state]
        for events in range(1 << width):
            row = None if spec.match == "document" and not events else first_match(rows, events)
            assert machine.lookup(state, events) == (NO_ROW if row is None else row.index)


@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_lookup_beyond_prefill_width(data: st.DataObject) -> None:
    """A state whose rows use more than PREFILL_BITS events fills its map lazily; same answers."""
    names = tuple(f"I{i}" for i in range(PREFILL_BITS + 3))
    match = data.draw(st.sampled_from(MATCHES))
    robot = Robot(name="Wide", inputs=names, motors=("M1",), initial_state=1, match=match)
    required = data.draw(st.lists(st.frozensets(st.sampled_from(names), max_size=4), min_size=1, max_size=30))
    rows = tuple(Row(i, i + 2, "", 1, events, (i % 9,), 0, 1) for i, events in enumerate(required))
    machine = compile_table(Table(robot, names, rows))
    assert machine.dispatch[0].relevant.bit_count() > PREFILL_BITS or len(machine.dispatch[0]) == 1 << (
        machine.dispatch[0].relevant.bit_count()
    )
    events_list = data.draw(st.lists(st.integers(0, (1 << len(names)) - 1), max_size=50))
    for events in [0, *events_list]:
        row = None if match == "document" and not events else first_match(machine.rows, events)
        assert machine.lookup(0, events) == (NO_ROW if row is None else row.index)
        engine = Engine(machine)  # a table this wide steps through the lazily filled per-state hits
        engine.step(events)
        assert engine.row == (NO_ROW if row is None else row.index)


# --- compilation details ----------------------------------------------------------------------------


def test_bumberbot_compiles_to_ten_states_with_document_bits() -> None:
    machine = example_machine()
    assert machine.states == (1, 2, 20, 21, 22, 24, 26, 29, 11, 12)
    assert machine.timer_bit == 32
    assert machine.input_bits == {"I3": 16, "I4": 8, "I5": 4, "I7": 2, "I8": 1}
    assert machine.states[machine.initial_state] == 2
    assert machine.rows[0].mask == 16 | 8
    assert machine.output_names == ("M1", "M2")


def test_first_match_is_table_order_not_specificity() -> None:
    machine = example_machine()
    state1 = machine.state_index(1)
    # state 1: collision rows come before the light rows, so a bump wins over light
    assert machine.lookup(state1, 16 | 8 | 2 | 1) == 0
    assert machine.lookup(state1, 16 | 2) == 1
    assert machine.lookup(state1, 2 | 1) == 20
    assert machine.lookup(state1, 2) == 21
    assert machine.lookup(state1, 0) == NO_ROW


def test_signature_ignores_descriptions_and_lines_but_not_behaviour(tmp_path: Path) -> None:
    base = (Path(__file__).resolve().parents[1] / "examples" / "bumberbot" / "table.csv").read_text()
    robot = example_machine().table.robot
    renamed = base.replace("Collision detection", "Bump")
    spaced = base.replace("\n", "\n\n")
    slower = base.replace(",895,", ",896,")
    sig = example_machine().signature()
    assert compile_table(parse_table(renamed, "x", robot)).signature() == sig
    assert compile_table(parse_table(spaced, "x", robot)).signature() == sig
    assert compile_table(parse_table(slower, "x", robot)).signature() != sig


@SETTINGS
@given(spec=specs())
def test_random_tables_round_trip_through_the_writer(spec: Spec) -> None:
    """format_table writes the document's form where it can; reading it back gives the same machine."""
    machine = build(spec)
    again = compile_table(parse_table(format_table(machine.table), "<written>", machine.table.robot))
    assert again.signature() == machine.signature()
    assert [r.description for r in again.table.rows] == [r.description for r in machine.table.rows]


@SETTINGS
@given(spec=specs(), inputs=ticks, split=st.integers(0, 40))
def test_the_compiled_tick_rule_equals_step_with_pulses(
    spec: Spec, inputs: list[tuple[frozenset[str], tuple[int, int]]], split: int
) -> None:
    """tablebot.tick.tick, compiled (the simulator's and the fleet's rule), takes step's decisions
    tick for tick, counters counting down by their pulses included."""
    machine = build(spec)
    masks = [sum(machine.input_bits.get(name, 0) for name in present) for present, _ in inputs]
    pulses = [list(p[: len(spec.counters)]) for _, p in inputs]
    stepper, batcher = Engine(machine), Engine(machine)
    expected = []
    for mask, counts in zip(masks, pulses, strict=True):
        stepper.step(mask, counts)
        expected.append((stepper.event, stepper.row, stepper.state, stepper.timer))
    first = batcher.run(masks[:split], pulses[:split], jit=None)
    second = batcher.run(masks[split:], pulses[split:], jit=None)
    got = [
        *zip(first.events, first.rows, first.states, first.timers, strict=True),
        *zip(second.events, second.rows, second.states, second.timers, strict=True),
    ]
    assert got == expected
    assert batcher.snapshot() == stepper.snapshot()
