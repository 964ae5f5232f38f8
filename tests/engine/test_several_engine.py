"""Several tables in one robot, run (issue 36 §1): the engine against a literal reading of the rules, every order
of the tables giving the same trace, and ``tablebot trace`` writing the keys the issue pins."""

from __future__ import annotations

import itertools
import json
import random
import subprocess
import sys
from pathlib import Path
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from tablebot.formats.inputs_csv import TickInput
from tablebot.formats.trace_lines import dumps
from tablebot.loading import Loaded
from tablebot.replay import replay_several
from tablebot.table import TIMER_EVENT, Row, Table
from tablebot.tables import RobotTables
from tablebot.testing.random_robots import RobotShape, random_robot
from tables_helpers import robot


def literal(tables: RobotTables, ticks: list[TickInput]) -> list[dict[str, Any]]:
    """The rules of tablebot.tables read word for word, over the rows as read (no compiled lookups)."""
    robot = tables.robot
    states = [t.robot.initial_state for t in tables.tables]
    timers = [t.robot.initial_timer for t in tables.tables]
    counters = [0] * len(robot.counters)
    outputs = dict.fromkeys((*robot.motors, *robot.lamps), 0)
    names = list(tables.input_bits)
    lines = []
    for n, tick in enumerate(ticks):
        pressed = {name for name in names if tick.mask & tables.input_bits[name]}
        if n:  # not on the first tick
            timers = [max(0, t - 1) for t in timers]
            counters = [max(0, c - p) for c, p in zip(counters, tick.pulses or [0] * len(counters), strict=True)]
        start = list(states)
        fired: list[Row | None] = []
        events: list[set[str]] = []
        for k, table in enumerate(tables.tables):
            present = {
                e
                for e in table.events
                if e in pressed
                or (e == TIMER_EVENT and timers[k] == 0)
                or (e in robot.counter_names and counters[robot.counter_names.index(e)] == 0)
                or (e in table.cross and table.cross[e].covers(start[tables.index(table.cross[e].table)]))
            }
            events.append(present)
            quiet = not present and table.robot.match == "document"
            fired.append(
                None if quiet else next((r for r in table.rows if r.state == start[k] and r.events <= present), None)
            )
        for k, row in enumerate(fired):
            if row is None:
                continue
            for name, value in zip((*robot.motors, *robot.lamps), (*row.motors, *row.lamps), strict=True):
                if value is not None:
                    outputs[name] = value
            counters = [c if load is None else load for c, load in zip(counters, row.counters, strict=True)]
            states[k], timers[k] = row.next, row.timer
        lines.append(_line(tables, n, events, fired, states, timers, outputs, counters))
    return lines


def _line(
    tables: RobotTables,
    n: int,
    events: list[set[str]],
    fired: list[Row | None],
    states: list[Any],
    timers: list[int],
    outputs: dict[str, int],
    counters: list[int],
) -> dict[str, Any]:
    def mask(table: Table, present: set[str]) -> int:
        return table.mask(present)

    main = tables.tables[0]
    line: dict[str, Any] = {
        "tick": n,
        "event": mask(main, events[0]),
        "row": fired[0].as_written if fired[0] else None,
        "state": states[0],
        "timer": timers[0],
        **outputs,
        **dict(zip(tables.robot.counter_names, counters, strict=True)),
    }
    for k, table in enumerate(tables.tables[1:], start=1):
        line |= {
            f"{table.name}.event": mask(table, events[k]),
            f"{table.name}.row": fired[k].as_written if fired[k] else None,  # type: ignore[union-attr]
            f"{table.name}.state": states[k],
            f"{table.name}.timer": timers[k],
        }
    return line


def ticks_for(rng: random.Random, tables: RobotTables, count: int) -> list[TickInput]:
    width = len(tables.input_bits)
    return [
        TickInput(rng.randrange(1 << width) if rng.random() < 0.4 else 0, (rng.choice((0, 0, 1, 3)),))
        for _ in range(count)
    ]


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32), st.integers(2, 3))
def test_several_tables_run_as_the_rules_say_in_every_order(tmp_path_factory: Any, seed: int, count: int) -> None:
    rng = random.Random(seed)
    folder = random_robot(rng, tmp_path_factory.mktemp("robot"), shape=RobotShape(tables=count))
    tables = Loaded.open(folder / "t0.csv").tables
    assert tables is not None
    ticks = ticks_for(rng, tables, 60)
    expected = [dumps(line) for line in literal(tables, ticks)]
    for order in itertools.permutations(range(count)):
        assert [dumps(line) for line in replay_several(tables, ticks, order)] == expected, order


def test_cross_table_events_are_read_at_the_start_of_the_tick(tmp_path: Path) -> None:
    """The lights table sees drive's state before drive fires: drive enters 3 on tick 3, lights sees it on 4."""
    folder = robot(tmp_path)
    (folder / "inputs.csv").write_text("I1,I2\n0,0\n0,0\n0,1\n1,0\n0,0\n0,0\n")
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", "trace", str(folder), "--inputs", str(folder / "inputs.csv")],
        capture_output=True,
        text=True,
        check=True,
    )
    lines = [json.loads(line) for line in done.stdout.splitlines()]
    assert list(lines[0]) == [
        "tick",
        "event",
        "row",
        "state",
        "timer",
        "M1",
        "M2",
        "L1",
        "lights.event",
        "lights.row",
        "lights.state",
        "lights.timer",
    ]
    assert [(line["state"], line["lights.state"], line["L1"]) for line in lines] == [
        (2, 1, 0),
        (2, 1, 0),
        (2, 1, 0),
        (3, 1, 0),
        (3, 2, 8),
        (3, 1, 8),
    ]
    assert lines[3]["row"] == 0  # the group row, as written (the first line below the header)
    assert lines[0]["row"] == 1
