"""Engine.step's fast path (issue 22): the lookup itself checks the mask, the timer is kept as a deadline,
the counters choose their lookups when they change. Refusals, the engine's own bits in a mask, lookups
made on a state's first tick, and tick/timer/counters read and assigned as plain attributes."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import pytest

from core_helpers import COUNTER_ROBOT, MINI_ROBOT, example_machine, machine_of
from tablebot.engine import Engine
from tablebot.machine import FLAT_BITS, NO_ROW

if TYPE_CHECKING:
    from pathlib import Path

I3, I4, I5, I7, I8, T = 16, 8, 4, 2, 1, 32
RANGE = r"is not a mask of this table's 6 event columns \(0\.\.63\); its inputs are I3=16, I4=8, I5=4, I7=2, I8=1"


class Indexable:
    """Not an int, though a list would take it as an index."""

    def __index__(self) -> int:
        return 1


def whole_state(engine: Engine) -> tuple:
    return engine.snapshot(), engine.event, engine.row, engine.tick, engine.timer, engine.counters


BAD_INPUTS = [
    (-1, rf"input mask -1 {RANGE}"),
    (-(1 << 40), rf"input mask -{1 << 40} {RANGE}"),
    (64, rf"input mask 64 {RANGE}"),
    (127, rf"input mask 127 {RANGE}"),
    (1 << 40, rf"input mask {1 << 40} {RANGE}"),
    (np.int64(-3), rf"input mask -3 {RANGE}"),
    (np.uint16(64), rf"input mask 64 {RANGE}"),
    (True, "inputs must be an int mask or a mapping of input names, not bool"),
    (False, "not bool"),
    (np.True_, "not bool"),
    (1.0, "not float"),
    (16.0, "not float"),
    ("I3", "not str"),
    (None, "not NoneType"),
    (np.array(3), "not ndarray"),
    (Indexable(), "not Indexable"),
    ({"i3": 1}, r"unknown input 'i3'; the inputs are I3=16, I4=8, I5=4, I7=2, I8=1"),
    ({"I3": 2}, r"input 'I3': 2 is not 0 or 1"),
]


@pytest.mark.parametrize("ticks_before", [0, 1, 2, 500, 510], ids=lambda n: f"after{n}")
@pytest.mark.parametrize(("bad", "message"), BAD_INPUTS, ids=lambda v: repr(v)[:20])
def test_a_refused_input_names_what_is_wrong_and_changes_nothing(bad: object, message: str, ticks_before: int) -> None:
    """Fresh (no lookup made yet), timer running, timer at 0 (tick 500: T fires), in a new state (510)."""
    engine = Engine(example_machine())
    for _ in range(ticks_before):
        engine.step(0)
    before = whole_state(engine)
    with pytest.raises(ValueError, match=message):
        engine.step(bad)  # type: ignore[arg-type]  # what the hint refuses, refused at run time too
    assert whole_state(engine) == before
    engine.step(0)  # and the engine goes on as if the refused call had not happened
    again = Engine(example_machine())
    for _ in range(ticks_before + 1):
        again.step(0)
    assert whole_state(engine) == whole_state(again)


def test_refused_pulses_change_nothing_not_even_the_tick(tmp_path: Path) -> None:
    counting = Engine(
        machine_of(tmp_path, "state,T,C1,M1,C1_load,timer,next\n1,1,,5,3,2,1\n1,,1,0,=,0,1\n", COUNTER_ROBOT)
    )
    counting.step(0, (0, 0))
    before = whole_state(counting)
    for pulses, message in (
        ((1, 2, 3), r"pulses: 3 values for 2 counters \(C1, C2\)"),
        ((1,), r"pulses: 1 values for 2 counters"),
        ((2, -1), r"pulses: -1 for counter 2 is negative"),
        ((-1, 0), r"pulses: -1 for counter 1 is negative"),
    ):
        with pytest.raises(ValueError, match=message):
            counting.step(0, pulses)
        assert whole_state(counting) == before
    with pytest.raises(ValueError, match=r"input mask 4 is not a mask of this table's 2 event columns \(0\.\.3\)"):
        counting.step(4, (1, 1))  # the mask is refused before the counters count down
    assert whole_state(counting) == before
    plain = Engine(example_machine())
    plain.step(0)
    before = whole_state(plain)
    with pytest.raises(ValueError, match=r"pulses: 2 values for 0 counters \(none\)"):
        plain.step(0, (1, 2))
    assert whole_state(plain) == before


def test_no_pulses_as_none_empty_tuple_or_empty_list() -> None:
    trace = []
    nothing: tuple[Sequence[int] | np.ndarray | None, ...] = (None, (), [], np.zeros(0, dtype=np.int64))
    for pulses in nothing:
        engine = Engine(example_machine())
        trace.append(
            [
                (engine.step(mask, pulses), engine.event, engine.row, engine.timer)
                for mask in [0, I7, 0, I5, I3 | I4] * 3
            ]
        )
    assert trace[0] == trace[1] == trace[2] == trace[3]
    engine = Engine(example_machine())
    assert [engine.step(mask) for mask in [0, I7]] == [(4, 4), (1, 5)]


@pytest.mark.parametrize("ticks_before", [0, 1, 500])
def test_the_engines_own_bits_in_a_mask_are_ignored_by_every_input_kind(ticks_before: int) -> None:
    """T in a mask is neither an event nor a refusal, whether the state's lookup is made or not."""
    results = []
    for inputs in (I8 | T, I8, np.int64(I8 | T), np.uint8(I8), {"I8": 1}):
        engine = Engine(example_machine())
        for _ in range(ticks_before):
            engine.step(0)
        results.append((engine.step(inputs), engine.event, engine.row, engine.timer, engine.state))
    assert all(r == results[0] for r in results)
    assert results[0][1] & ~T == I8


def test_counter_bits_in_a_mask_are_ignored(tmp_path: Path) -> None:
    machine = machine_of(
        tmp_path, "state,T,C1,A,M1,C1_load,timer,next\n1,1,,,5,3,9,2\n2,,1,,6,=,0,1\n2,,,1,7,=,0,1\n", COUNTER_ROBOT
    )
    c1, a = machine.table.bit("C1"), machine.input_bits["A"]
    with_bit, without = Engine(machine), Engine(machine)
    for mask in (0, c1, c1 | a, c1, c1, c1):
        assert with_bit.step(mask, (0, 0)) == without.step(mask & ~c1, (0, 0))
        assert (with_bit.event, with_bit.row, with_bit.counters) == (without.event, without.row, without.counters)
    assert with_bit.row == NO_ROW and with_bit.counters == [3, 0]  # C1 is still 3: the mask's C1 bit did not fire


def test_wide_table_refuses_and_ignores_like_a_flat_one(tmp_path: Path) -> None:
    inputs = FLAT_BITS + 2
    names = [f"I{i}" for i in range(inputs)]
    robot = 'name = "Wide"\ninitial_state = 1\n[inputs]\n' + "".join(f'{n} = ""\n' for n in names)
    robot += '[motors]\nM1 = ""\n'
    table = f"state,T,{','.join(names)},M1,timer,next\n"
    table += f"1,,{','.join('1' if i == 0 else '' for i in range(inputs))},3,2,2\n"
    table += f"2,1,{','.join('' for _ in range(inputs))},4,0,1\n"
    machine = machine_of(tmp_path, table, robot)
    assert machine.flat is None
    width, t_bit, i0 = inputs + 1, machine.timer_bit, machine.input_bits["I0"]
    engine = Engine(machine)
    for bad in (-1, 1 << width, (1 << width) + i0, True):
        with pytest.raises(ValueError, match=r"input mask|not bool"):
            engine.step(bad)
        assert engine.tick == 0
    assert engine.step(i0 | t_bit) == (3,) and (engine.event, engine.row) == (i0 | t_bit, 0)  # timer 0: T is there
    assert engine.step(t_bit) == (3,) and (engine.event, engine.row) == (0, NO_ROW)  # timer 2 running: T ignored
    assert engine.step(t_bit) == (4,) and (engine.event, engine.row) == (t_bit, 1)  # the timer's own T


# --- tick, timer and counters: properties that read and assign as plain attributes --------------------

TIMER_TABLE = "state,T,A,M1,timer,next\n1,1,,5,4,1\n1,,1,6,2,1\n"


def test_timer_reads_as_counted_down_and_assigns(tmp_path: Path) -> None:
    engine = Engine(machine_of(tmp_path, TIMER_TABLE, MINI_ROBOT))
    assert (engine.tick, engine.timer) == (0, 0)
    engine.step()
    assert (engine.row, engine.timer) == (0, 4)
    timers = []
    for _ in range(5):
        engine.step()
        timers.append((engine.timer, engine.row))
    assert timers == [(3, NO_ROW), (2, NO_ROW), (1, NO_ROW), (4, 0), (3, NO_ROW)]  # a timer of 4: T 4 ticks later
    engine.timer = 1  # as for a plain attribute: counted down on the next tick, T there
    assert engine.timer == 1
    engine.step()
    assert (engine.row, engine.timer) == (0, 4)
    engine.timer = 0
    engine.step()
    assert engine.row == 0


def test_assigning_tick_keeps_the_timer(tmp_path: Path) -> None:
    engine = Engine(machine_of(tmp_path, TIMER_TABLE, MINI_ROBOT))
    engine.step()
    engine.step()
    assert (engine.tick, engine.timer) == (2, 3)
    engine.tick = 1000
    assert (engine.tick, engine.timer) == (1000, 3)
    engine.step()
    assert (engine.tick, engine.timer) == (1001, 2)
    engine.tick = 0  # back to a first tick: the timer is not counted down on it
    engine.step()
    assert (engine.tick, engine.timer, engine.row) == (1, 2, NO_ROW)


def test_the_first_tick_after_restoring_tick_0_does_not_count_down(tmp_path: Path) -> None:
    engine = Engine(machine_of(tmp_path, TIMER_TABLE, MINI_ROBOT))
    engine.restore({**engine.snapshot(), "tick": 0, "timer": 1})
    engine.step()
    assert (engine.timer, engine.row) == (1, NO_ROW)
    engine.step()
    assert (engine.timer, engine.row) == (4, 0)


def test_counters_assign_and_read_as_a_copy(tmp_path: Path) -> None:
    machine = machine_of(tmp_path, "state,T,C1,M1,C1_load,timer,next\n1,,1,7,=,0,1\n1,1,,=,=,0,1\n", COUNTER_ROBOT)
    engine = Engine(machine)
    engine.counters = [2, 0]
    engine.step(0, (0, 0))
    assert engine.row == 1  # C1 is 2: not an event, T fires
    engine.step(0, (2, 0))
    assert engine.row == 0 and engine.counters == [0, 0]  # counted down to 0 by the pulses: C1 fires
    engine.counters = [5, 5]
    engine.step(0)
    assert engine.row == 1  # assigned: C1 is no longer 0
    read = engine.counters
    read[0] = 0  # a copy: the engine's counters stay as they are
    assert engine.counters == [5, 5]
    engine.step(0)
    assert engine.row == 1
