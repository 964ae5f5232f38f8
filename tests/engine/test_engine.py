"""The engine's semantics, pinned tick by tick: timer, speed 7, first match, no match, resume."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

import numpy as np
import pytest

from core_helpers import EXAMPLE, MINI_ROBOT, example_machine, machine_of
from tablebot.engine import Engine
from tablebot.formats.inputs_csv import load_inputs
from tablebot.machine import NO_ROW
from tablebot.replay import record

if TYPE_CHECKING:
    from pathlib import Path

    from tablebot.formats.inputs_csv import TickInput
    from tablebot.machine import Machine
    from tablebot.robot import StateId

I3, I4, I5, I7, I8, T = 16, 8, 4, 2, 1, 32


def bumberbot() -> Engine:
    return Engine(example_machine())


def run(engine: Engine, masks: list[int]) -> list[tuple[int, int, StateId, int, tuple[int, ...]]]:
    """(event, row, state, timer, outputs) after each tick."""
    out = []
    for mask in masks:
        outputs = engine.step(mask)
        out.append((engine.event, engine.row, engine.machine.states[engine.state], engine.timer, outputs))
    return out


# --- the BumberBot, as the document describes it ------------------------------------------------------


def test_first_tick_timer_zero_fires_seek_turn() -> None:
    engine = bumberbot()
    assert engine.snapshot() == {"tick": 0, "state": 2, "timer": 0, "counters": {}, "outputs": {"M1": 0, "M2": 0}}
    assert run(engine, [0]) == [(T, 7, 1, 500, (4, 4))]


def test_timer_counts_down_only_after_the_first_tick_and_fires_after_its_value() -> None:
    engine = bumberbot()
    trace = run(engine, [0] * 502)
    assert [t[3] for t in trace[:4]] == [500, 499, 498, 497]
    assert all(t[1] == NO_ROW and t[0] == 0 for t in trace[1:500])
    # loaded with 500 on tick 0, it reaches 0 on tick 500: Seek - Straight (backward M1, as printed)
    assert trace[500] == (T, 3, 2, 895, (-2, 2))
    assert trace[501][1:4] == (NO_ROW, 2, 894)


def test_timer_zero_row_lets_t_fire_on_the_very_next_tick() -> None:
    engine = bumberbot()
    trace = run(engine, [0, I3 | I4] + [0] * 51)
    assert trace[1] == (I3 | I4, 0, 20, 50, (0, 0))  # collision: stop, 50 ticks
    assert trace[51] == (T, 8, 21, 0, (0, 0))  # Collision Entry: timer 0, motors kept
    assert trace[52] == (T, 12, 1, 500, (4, 4))  # T at once: Collision Fake (no bumper pressed)


def test_first_match_in_table_order_and_extra_events_do_not_matter() -> None:
    engine = bumberbot()
    run(engine, [0])  # now state 1, timer 500
    assert run(engine, [I3 | I4 | I7 | I8 | I5])[0][1:3] == (0, 20)  # both bumpers: row 0, not row 1 or 2
    engine = bumberbot()
    run(engine, [0])
    assert run(engine, [I3 | I7])[0][1] == 1  # collision rows come before the light rows
    engine = bumberbot()
    run(engine, [0])
    assert run(engine, [I7 | I8])[0][1:] == (20, 11, 125, (5, 5))
    engine = bumberbot()
    run(engine, [0])
    assert run(engine, [I7])[0][1:] == (21, 11, 125, (1, 5))


def test_no_match_changes_nothing_but_the_timer() -> None:
    engine = bumberbot()
    run(engine, [0, I7])  # state 11, timer 125, (1, 5)
    before = engine.snapshot()
    assert run(engine, [I5]) == [(I5, NO_ROW, 11, 124, (1, 5))]  # state 11 has no rear-bumper row
    after = engine.snapshot()
    assert after["state"] == before["state"] and after["outputs"] == before["outputs"]


def test_t_is_never_an_input() -> None:
    engine = bumberbot()
    run(engine, [0])
    assert run(engine, [T | I8]) == [(I8, 22, 11, 125, (5, 1))]


def test_inputs_as_names_or_mask_are_the_same() -> None:
    by_mask, by_name = bumberbot(), bumberbot()
    by_mask.step(0)
    by_name.step({})
    assert by_mask.step(I3 | I8) == by_name.step({"I3": 1, "I8": True, "I4": 0, "I5": False})
    assert by_mask.snapshot() == by_name.snapshot()


def test_step_returns_outputs_and_reset_starts_over() -> None:
    engine = bumberbot()
    assert engine.step() == (4, 4)
    engine.reset()
    assert engine.tick == 0 and engine.state == engine.machine.initial_state and engine.outputs == (0, 0)
    assert engine.step() == (4, 4)


# --- speed 7, keep, and small tables ------------------------------------------------------------------

KEEP_TABLE = """\
description,state,T,A,B,M1_dir,M1_speed,M2_dir,M2_speed,timer,next
set,1,1,,,1,3,,5,0,2
keep both (dir 1),2,1,,,1,7,1,7,0,3
keep M1 (dir 0) stop M2,3,1,,,,7,,0,0,4
keep M2 only,4,1,,,,6,1,7,0,4
"""


def test_speed_seven_keeps_the_motor_and_its_direction(tmp_path: Path) -> None:
    engine = Engine(machine_of(tmp_path, KEEP_TABLE, MINI_ROBOT))
    assert [engine.step() for _ in range(4)] == [(-3, 5), (-3, 5), (-3, 0), (6, 0)]


def test_row_without_events_fires_every_tick(tmp_path: Path) -> None:
    table = "state,A,M1,M2,timer,next\n1,1,8,8,9,1\n1,,1,1,3,1\n"
    engine = Engine(machine_of(tmp_path, table, MINI_ROBOT))
    assert [(engine.step({"A": a}), engine.row, engine.timer) for a in (0, 1, 0, 1)] == [
        ((1, 1), 1, 3),
        ((8, 8), 0, 9),
        ((1, 1), 1, 3),
        ((8, 8), 0, 9),
    ]


def test_initial_timer_from_the_robot(tmp_path: Path) -> None:
    robot = MINI_ROBOT.replace("initial_timer = 0", "initial_timer = 3")
    engine = Engine(machine_of(tmp_path, "state,T,M1,timer,next\n1,1,5,0,1\n", robot))
    assert [(engine.step(), engine.timer, engine.row) for _ in range(5)] == [
        ((0, 0), 3, NO_ROW),
        ((0, 0), 2, NO_ROW),
        ((0, 0), 1, NO_ROW),
        ((5, 0), 0, 0),
        ((5, 0), 0, 0),
    ]


@pytest.mark.parametrize(
    ("timer", "fired"),
    [
        (0, [0, 0, 0, 0, 0, 0]),  # timer 0: T is present again on the very next tick
        (1, [0, 0, 0, 0, 0, 0]),  # 1 is counted down to 0 before the next tick looks for T
        (2, [0, NO_ROW, 0, NO_ROW, 0, NO_ROW]),
        (3, [0, NO_ROW, NO_ROW, 0, NO_ROW, NO_ROW]),
    ],
)
def test_a_timer_of_n_fires_t_n_ticks_later(tmp_path: Path, timer: int, fired: list[int]) -> None:
    engine = Engine(machine_of(tmp_path, f"state,T,M1,timer,next\n1,1,=,{timer},1\n", MINI_ROBOT))
    rows = []
    for _ in range(6):
        engine.step()
        rows.append(engine.row)
    assert rows == fired


def test_table_without_t_column_never_sees_the_timer(tmp_path: Path) -> None:
    engine = Engine(machine_of(tmp_path, "state,A,M1,timer,next\n1,1,2,0,1\n", MINI_ROBOT))
    assert engine.machine.timer_bit == 0
    engine.step()
    assert (engine.event, engine.row) == (0, NO_ROW)
    engine.step({"A": 1})
    assert (engine.event, engine.row, engine.outputs) == (1, 0, (2, 0))


# --- snapshot and restore -----------------------------------------------------------------------------


def example_ticks() -> tuple[Machine, list[TickInput]]:
    machine = example_machine()
    return machine, load_inputs(EXAMPLE / "inputs.csv", machine)


def trace_lines(engine: Engine, ticks: list[TickInput]) -> list[str]:
    lines = []
    for tick in ticks:
        engine.step(tick.mask, tick.pulses)
        lines.append(json.dumps(record(engine)))
    return lines


@pytest.mark.parametrize("split", [0, 1, 137, 1001, 2999])
def test_snapshot_restore_resumes_exactly(split: int) -> None:
    machine, ticks = example_ticks()
    whole = trace_lines(Engine(machine), ticks)
    first = Engine(machine)
    head = trace_lines(first, ticks[:split])
    saved = json.loads(json.dumps(first.snapshot()))  # through JSON text, as a file would
    second = Engine(machine)
    second.restore(saved)
    assert head + trace_lines(second, ticks[split:]) == whole


def test_restore_rewinds_a_running_engine() -> None:
    machine, ticks = example_ticks()
    engine = Engine(machine)
    trace_lines(engine, ticks[:700])
    saved = engine.snapshot()
    again = trace_lines(engine, ticks[700:900])
    engine.restore(saved)
    assert trace_lines(engine, ticks[700:900]) == again


def test_snapshot_is_plain_json() -> None:
    engine = bumberbot()
    run(engine, [0, I7])
    snap = engine.snapshot()
    assert json.loads(json.dumps(snap)) == snap
    assert snap == {"tick": 2, "state": 11, "timer": 125, "counters": {}, "outputs": {"M1": 1, "M2": 5}}


def test_snapshot_names_named_states(tmp_path: Path) -> None:
    robot = MINI_ROBOT.replace("initial_state = 1", 'initial_state = "go"')
    engine = Engine(machine_of(tmp_path, "state,T,M1,timer,next\ngo,1,3,2,stop\nstop,1,0,0,go\n", robot))
    engine.step()
    assert engine.snapshot()["state"] == "stop"
    other = Engine(engine.machine)
    other.restore(json.loads(json.dumps(engine.snapshot())))
    assert other.step() == engine.step()


@pytest.mark.parametrize(
    ("change", "pattern"),
    [
        ({"state": 99}, "state: 99"),
        ({"timer": -1}, "must not be negative"),
        ({"tick": -5}, "must not be negative"),
        ({"outputs": {"M1": 0}}, "must name exactly"),
        ({"counters": {"C1": 0}}, "must name exactly"),
        ({"timer": "soon"}, "timer"),
    ],
)
def test_restore_refuses_a_snapshot_that_does_not_fit(change: dict[str, object], pattern: str) -> None:
    engine = bumberbot()
    with pytest.raises(ValueError, match=pattern):
        engine.restore({**engine.snapshot(), **change})


@pytest.mark.parametrize("missing", ["tick", "state", "timer"])
def test_restore_names_a_missing_field(missing: str) -> None:
    engine = bumberbot()
    snap = engine.snapshot()
    del snap[missing]
    with pytest.raises(ValueError, match=missing):
        engine.restore(snap)


def test_failed_restore_leaves_the_engine_as_it_was() -> None:
    engine = bumberbot()
    run(engine, [0, I7])
    before = engine.snapshot()
    with pytest.raises(ValueError):
        engine.restore({**before, "outputs": {"M1": 1}})
    assert engine.snapshot() == before


# --- the batch path -----------------------------------------------------------------------------------


def test_batch_results_as_lists_and_arrays() -> None:
    engine = bumberbot()
    batch = engine.run([0, I7, 0, I5])
    assert batch.events == [T, I7, 0, I5]
    assert batch.rows == [7, 21, NO_ROW, NO_ROW]
    assert [engine.machine.states[s] for s in batch.states] == [1, 11, 11, 11]
    assert batch.timers == [500, 125, 124, 123]
    assert len(batch) == 4 and [list(a) for a in batch.arrays] == [batch.events, batch.rows, batch.states, batch.timers]
    assert batch == bumberbot().run([0, I7, 0, I5], jit=False)
    assert "rows=[7, 21, -1, -1]" in repr(batch)
    assert (engine.tick, engine.event, engine.row, engine.outputs) == (4, I5, NO_ROW, (1, 5))
    assert json.loads(json.dumps(engine.snapshot())) == engine.snapshot()  # plain ints, not numpy ones
    assert all(type(v) is int for v in (engine.state, engine.timer, engine.event, engine.row, *engine.outputs))


@pytest.mark.parametrize(
    "masks",
    [
        [0, I3 | I4, 0, 0],
        (0, I3 | I4, 0, 0),
        np.array([0, I3 | I4, 0, 0], dtype=np.uint8),
        np.array([0, I3 | I4, 0, 0], dtype=np.int32),
        np.array([0, I3 | I4, 0, 0, 99], dtype=np.int64)[:4],
        [0, I3 | I4 | T, 0, 0],  # T's bit is the engine's to make: ignored, as step does
    ],
)
def test_batch_accepts_any_integer_sequence(masks: list[int] | tuple[int, ...] | np.ndarray) -> None:
    assert bumberbot().run(masks).rows == [7, 0, NO_ROW, NO_ROW]


@pytest.mark.parametrize("jit", [None, False])
@pytest.mark.parametrize("bad", [-1, 64, 256, 1 << 40])
def test_masks_beyond_the_tables_events_are_refused(bad: int, jit: bool | None) -> None:
    """Issue 14: a negative or too-wide mask is a ValueError naming the valid range and the inputs."""
    with (
        pytest.raises(ValueError, match=r"0\.\.63.*I3=16")
        if jit is False
        else pytest.raises(ValueError, match=r"0\.\.63")
    ):
        bumberbot().run([0, bad], jit=jit)
    engine = bumberbot()
    with pytest.raises(ValueError, match=rf"input mask {bad} .*0\.\.63.*I3=16, I4=8, I5=4, I7=2, I8=1"):
        engine.step(bad)
    assert engine.tick == 0  # refused before anything changed


@pytest.mark.parametrize(
    "inputs, message",
    [
        ({"i3": 1}, r"unknown input 'i3'; the inputs are I3=16, I4=8"),
        ({"I3": 2}, r"input 'I3': 2 is not 0 or 1"),
        ({"I3": 0.5}, r"input 'I3': 0.5 is not 0 or 1"),
        ("I3", r"not str"),
        (1.0, r"not float"),
        (True, r"not bool"),
        (None, r"not NoneType"),
    ],
)
def test_wrong_inputs_name_the_offending_key_and_the_valid_ones(inputs: object, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        bumberbot().step(inputs)  # type: ignore[arg-type]  # what the hint refuses, refused at run time too


def test_pulses_must_fit_the_counters(tmp_path: Path) -> None:
    engine = bumberbot()
    engine.step(0)
    with pytest.raises(ValueError, match=r"pulses: 2 values for 0 counters"):
        engine.step(0, (1, 2))


def test_step_accepts_numpy_integers() -> None:
    engine = bumberbot()
    engine.step(np.uint8(0))
    assert engine.step(np.int64(I7)) == (1, 5)


def test_empty_batch_changes_nothing() -> None:
    engine = bumberbot()
    assert len(engine.run([])) == 0
    assert engine.snapshot()["tick"] == 0 and engine.event == 0 and engine.row == NO_ROW


def wide_engine(tmp_path: Path, inputs: int) -> Engine:
    names = [f"I{i}" for i in range(inputs)]
    robot = 'name = "Wide"\ninitial_state = 1\n[inputs]\n' + "".join(f'{n} = ""\n' for n in names)
    robot += '[motors]\nM1 = ""\n'
    rows = [
        f"1,{','.join('1' if j in (i, (i * 7) % inputs) else '' for j in range(inputs))},{i % 9},{i},2"
        for i in range(inputs)
    ]
    rows += [f"2,{','.join('1' if j == i else '' for j in range(inputs))},-{i % 9},{i},1" for i in range(inputs)]
    table = f"state,{','.join(names)},M1,timer,next\n" + "\n".join(rows) + "\n"
    return Engine(machine_of(tmp_path, table, robot))


@pytest.mark.parametrize("inputs", [10, 14])
def test_wide_tables_batch_and_step_agree(tmp_path: Path, inputs: int) -> None:
    """10 event columns: flat lookup, masks over 255 (int64 path); 14: no flat table, Python batch."""
    engine = wide_engine(tmp_path, inputs)
    assert (engine.machine.flat is None) == (inputs > 10)
    rng = np.random.default_rng(inputs)
    masks = (rng.integers(0, 1 << inputs, 500) & rng.integers(0, 1 << inputs, 500)).tolist()
    stepped = []
    for mask in masks:
        engine.step(mask)
        stepped.append((engine.event, engine.row, engine.state, engine.timer))
    for jit in (None, False):
        batch = Engine(engine.machine).run(masks, jit=jit)
        assert list(zip(batch.events, batch.rows, batch.states, batch.timers, strict=True)) == stepped
    if inputs > 10:
        with pytest.raises(RuntimeError, match="FLAT_BITS"):
            Engine(engine.machine).run(masks, jit=True)
