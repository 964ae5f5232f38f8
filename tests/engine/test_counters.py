"""Issue 4, items 1-3: pulse-counter events, signed motor commands, lamps; keep for every output."""

from __future__ import annotations

import json
import re
from typing import TYPE_CHECKING

import pytest

from core_helpers import COUNTER_ROBOT, EXAMPLE, column_of, example_machine, machine_of, problems, write_table
from tablebot.engine import Engine
from tablebot.machine import NO_ROW

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from collections.abc import Sequence
    from pathlib import Path


def rows_fired(engine: Engine, ticks: int, pulses: Sequence[int] = (1, 0)) -> list[int]:
    fired = []
    for _ in range(ticks):
        engine.step(0, pulses)
        fired.append(engine.row)
    return fired


# --- counters -----------------------------------------------------------------------------------------

COUNT_DOWN = """\
description,state,T,C1,C2,M1,M2,C1_load,timer,next
load 3,1,1,,,5,5,3,1000,2
C1 done,2,,1,,0,0,,0,3
idle,3,,,,=,=,,0,3
"""


def test_counter_event_fires_on_the_tick_the_counter_reaches_zero(tmp_path: Path) -> None:
    engine = Engine(machine_of(tmp_path, COUNT_DOWN, COUNTER_ROBOT))
    assert rows_fired(engine, 5) == [0, NO_ROW, NO_ROW, 1, 2]  # 3 pulses after the load
    assert engine.counters == [0, 0] and engine.outputs[:2] == (0, 0)


def test_counter_counts_its_own_motors_pulses_and_never_below_zero(tmp_path: Path) -> None:
    engine = Engine(machine_of(tmp_path, COUNT_DOWN, COUNTER_ROBOT))
    engine.step(0, (0, 0))
    engine.step(0, (0, 9))  # pulses of M2 do not touch C1
    assert engine.counters == [3, 0] and engine.row == NO_ROW
    engine.step(0, (7, 0))  # more pulses than left: 0, and the event fires at once
    assert engine.counters == [0, 0] and engine.row == 1


def test_pulses_as_a_numpy_array(tmp_path: Path) -> None:
    import numpy as np

    engine = Engine(machine_of(tmp_path, COUNT_DOWN, COUNTER_ROBOT))
    for pulses in ([0, 0], np.array([1, 0]), np.array([2, 0], dtype=np.int64)):
        engine.step(np.int64(0), pulses)
    assert engine.row == 1 and engine.counters == [0, 0]
    engine.step(0, np.array([0, 3]))
    assert json.loads(json.dumps(engine.snapshot()))["counters"] == {"C1": 0, "C2": 0}


def test_counters_ignore_pulses_on_the_first_tick(tmp_path: Path) -> None:
    """Like the timer: a count-down starts after the first tick."""
    table = "state,T,C1,M1,C1_load,timer,next\n1,,1,1,=,0,1\n"
    engine = Engine(machine_of(tmp_path, table, COUNTER_ROBOT))
    engine.step(0, (5, 5))
    assert engine.row == 0  # counters start at 0, so C1 is present from the start, as T is


LOAD_AND_LEAVE = """\
description,state,T,C1,M1,M2,C1_load,timer,next
load 5,1,1,,4,4,5,2,2
leave it,2,1,,4,-4,,2,3
leave it (=),3,1,,4,4,=,2,4
wait C1,4,,1,0,0,,0,5
load 0,5,1,,=,=,0,0,6
wait C1 again,6,,1,1,1,,0,6
"""


def test_a_row_that_loads_a_counter_and_rows_that_leave_it(tmp_path: Path) -> None:
    engine = Engine(machine_of(tmp_path, LOAD_AND_LEAVE, COUNTER_ROBOT))
    # tick 0 loads 5; ticks 2 and 4 fire rows that leave C1 alone, so it reaches 0 on tick 5
    assert rows_fired(engine, 6) == [0, NO_ROW, 1, NO_ROW, 2, 3]
    # "load 0" differs from blank: the counter is 0 at once and C1 fires on the next tick
    assert rows_fired(engine, 2, pulses=(0, 0)) == [4, 5]


def test_loads_on_the_batch_path(tmp_path: Path) -> None:
    """No pulses on the batch path: a loaded counter holds, a counter loaded with 0 fires."""
    engine = Engine(machine_of(tmp_path, LOAD_AND_LEAVE, COUNTER_ROBOT))
    batch = engine.run([0] * 8)
    assert batch.rows == [0, NO_ROW, 1, NO_ROW, 2, NO_ROW, NO_ROW, NO_ROW]
    assert engine.counters == [5, 0]
    engine.restore({**engine.snapshot(), "counters": {"C1": 0, "C2": 0}})
    assert engine.run([0, 0, 0]).rows == [3, 4, 5]


def test_counter_state_survives_snapshot(tmp_path: Path) -> None:
    machine = machine_of(tmp_path, LOAD_AND_LEAVE, COUNTER_ROBOT)
    engine = Engine(machine)
    rows_fired(engine, 3)
    other = Engine(machine)
    other.restore(engine.snapshot())
    assert rows_fired(other, 3) == rows_fired(engine, 3)
    assert other.snapshot() == engine.snapshot()


# --- signed motors --------------------------------------------------------------------------------------


def to_signed(text: str, keep: str = "=") -> str:
    """The BumberBot table rewritten with one signed column per motor."""
    lines = text.splitlines()
    head = lines[0].split(",")
    out = [",".join([*head[:8], "M1", "M2", *head[12:]])]
    for line in lines[1:]:
        cells = line.split(",")
        motors = []
        for direction, speed in ((cells[8], cells[9]), (cells[10], cells[11])):
            value = int(speed or 0)
            motors.append(keep if value == 7 else str(-value if direction == "1" else value))
        out.append(",".join(cells[:8] + motors + cells[12:]))
    return "\n".join(out) + "\n"


@pytest.mark.parametrize("keep", ["=", "keep", "Keep", "k"])
def test_signed_and_direction_forms_give_identical_machines(tmp_path: Path, keep: str) -> None:
    signed = to_signed((EXAMPLE / "table.csv").read_text(), keep)
    assert "M1_dir" not in signed and keep in signed
    machine = machine_of(tmp_path, signed, (EXAMPLE / "robot.toml").read_text())
    assert machine.signature() == example_machine().signature()


def test_one_motor_in_each_form(tmp_path: Path) -> None:
    text = (EXAMPLE / "table.csv").read_text()
    signed = to_signed(text).splitlines()
    mixed = []
    for doc, sig in zip(text.splitlines(), signed, strict=True):
        d, s = doc.split(","), sig.split(",")
        mixed.append(",".join([*d[:10], s[9], *d[12:]]))  # M1 as dir+speed, M2 signed
    machine = machine_of(tmp_path, "\n".join(mixed) + "\n", (EXAMPLE / "robot.toml").read_text())
    assert machine.signature() == example_machine().signature()


# --- keep for every output ------------------------------------------------------------------------------

KEEP_ALL = """\
description,state,T,M1,M2_dir,M2_speed,L1,L2,C1_load,C2_load,timer,next
set all,1,1,-6,1,2,8,3,40,50,0,2
keep all,2,1,=,1,7,,=,,=,0,3
keep all (words),3,1,keep,0,7,=,,=,,0,4
set again,4,1,0,,0,0,0,0,0,0,4
"""


def test_keep_semantics_for_every_output(tmp_path: Path) -> None:
    engine = Engine(machine_of(tmp_path, KEEP_ALL, COUNTER_ROBOT))
    snapshots = []
    for _ in range(4):
        engine.step(0, (0, 0))
        snapshots.append((engine.outputs, tuple(engine.counters)))
    assert snapshots == [
        ((-6, -2, 8, 3), (40, 50)),
        ((-6, -2, 8, 3), (40, 50)),
        ((-6, -2, 8, 3), (40, 50)),
        ((0, 0, 0, 0), (0, 0)),  # and 0 is a value, not keep
    ]


def test_blank_motor_cell_stops_but_blank_lamp_keeps(tmp_path: Path) -> None:
    table = "state,T,M1,M2,L1,timer,next\n1,1,5,5,6,0,2\n2,1,,,,0,2\n"
    engine = Engine(machine_of(tmp_path, table, COUNTER_ROBOT))
    engine.step(0, (0, 0))
    engine.step(0, (0, 0))
    assert engine.outputs == (0, 0, 6, 0)


# --- errors ---------------------------------------------------------------------------------------------

HEADER = "description,state,T,C1,M1,M2_dir,M2_speed,L1,C1_load,timer,next"


@pytest.mark.parametrize(
    ("line", "index", "pattern"),
    [
        ("a,1,1,,9,,0,,,0,1", 4, r"M1: 9 is out of range -8\.\.8"),
        ("a,1,1,,-9,,0,,,0,1", 4, r"M1: -9 is out of range -8\.\.8"),
        ("a,1,1,,fast,,0,,,0,1", 4, r"M1: 'fast' is not an integer"),
        ("a,1,1,,0,,=,,,0,1", 6, r"M2_speed: '=' is not an integer"),
        ("a,1,1,,0,,0,9,,0,1", 7, r"L1: 9 is out of range 0\.\.8"),
        ("a,1,1,,0,,0,-1,,0,1", 7, r"L1: -1 is out of range 0\.\.8"),
        ("a,1,1,,0,,0,on,,0,1", 7, r"L1: 'on' is not an integer"),
        ("a,1,1,,0,,0,,-1,0,1", 8, r"C1_load: -1 is out of range 0\.\.65535"),
        ("a,1,1,,0,,0,,65536,0,1", 8, r"C1_load: 65536 is out of range"),
        ("a,1,1,2,0,,0,,,0,1", 3, r"event C1: 2 is out of range 0\.\.1"),
    ],
)
def test_out_of_range_values_are_located(tmp_path: Path, line: str, index: int, pattern: str) -> None:
    diagnostics = problems(write_table(tmp_path, HEADER + "\n" + line + "\n", COUNTER_ROBOT))
    assert len(diagnostics) == 1, [d.message for d in diagnostics]
    d = diagnostics[0]
    assert (d.line, d.column) == (2, column_of(line, index))
    assert re.search(pattern, d.message) and d.hint
    assert str(d.render()).startswith(f"{tmp_path / 'table.csv'}:2:{column_of(line, index)}: error: ")


def test_signed_error_hint_mentions_keep(tmp_path: Path) -> None:
    (d,) = problems(write_table(tmp_path, HEADER + "\na,1,1,,x,,0,,,0,1\n", COUNTER_ROBOT))
    assert "keep" in d.hint


@pytest.mark.parametrize(
    "header",
    [
        "state,T,M1,M1_dir,M1_speed,timer,next",
        "state,T,M1_speed,M1,timer,next",
        "state,T,M1_dir,M1,timer,next",
    ],
)
def test_mixed_forms_for_one_motor(tmp_path: Path, header: str) -> None:
    diagnostics = problems(write_table(tmp_path, header + "\n1,1,1,1,1,0,1\n", COUNTER_ROBOT))
    hits = [d for d in diagnostics if "both as M1 and as M1_dir/M1_speed" in d.message]
    assert len(hits) == 1
    assert (hits[0].line, hits[0].column) == (1, column_of(header, header.split(",").index("M1")))


def test_counter_columns_need_a_counter_in_the_robot(tmp_path: Path) -> None:
    header = "state,T,C3,C3_load,M1,timer,next"
    diagnostics = problems(write_table(tmp_path, header + "\n1,1,,,1,0,1\n", COUNTER_ROBOT))
    assert [(d.line, d.column) for d in diagnostics] == [(1, column_of(header, 2)), (1, column_of(header, 3))]
    assert all("unknown column" in d.message for d in diagnostics)
