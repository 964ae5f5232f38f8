"""``export --to xstate``: a robot's tables as an XState 5 machine config (JSON), under the tick model of :mod:`.chart`,
with named, parameterised guards and actions that the fixed module ``tablebot-xstate.mjs`` implements.

The config is plain data: every guard and action is ``{"type": NAME, "params": {...}}`` (XState 5's named
implementations: statelyai/xstate, packages/core/src/guards.ts, evaluateGuard, and packages/core/src/setup.ts).
The module's ``tablebotMachine(config)`` turns a row's cross-table events into XState's own ``stateIn`` guards
(``and``/``or`` of them beside the row's named guard), since a named guard sees the context and the event but not
the state; ``createActor`` then runs it. What only tablebot reads back is in ``meta`` (the robot's names, each
table's event columns and rule) and in each row's ``description`` and ``meta`` (index as written, group).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from importlib import resources
from typing import Any

from tablebot.formats.statecharts.chart import STARTED, TICK, Chart, Part, chart_of, pulses
from tablebot.table import Row, Table

__all__ = ["FORMAT", "RUNTIME", "export_xstate", "runtime_module", "xstate_config"]

#: The version of the config's layout (``meta.tablebot.format``).
FORMAT = 1
#: The fixed module's file name, in this package and beside an exported config.
RUNTIME = "tablebot-xstate.mjs"


def export_xstate(tables: Sequence[Table]) -> str:
    """The machine config of a robot's tables (the main one first) as JSON text."""
    return json.dumps(xstate_config(chart_of(tables)), indent=2, ensure_ascii=False) + "\n"


def runtime_module() -> str:
    """The fixed JavaScript module that implements the config's guards and actions."""
    return resources.files("tablebot.formats.statecharts").joinpath(RUNTIME).read_text(encoding="utf-8")


def xstate_config(chart: Chart) -> dict[str, Any]:
    robot = chart.main.robot
    context: dict[str, Any] = {STARTED: 0, **{f"has_{name}": False for name in chart.inputs}}
    context.update({name: 0 for name in (*robot.motors, *robot.lamps)})
    for counter in robot.counter_names:
        context.update({counter: 0, f"has_{counter}": False})
    for part in chart.parts:
        context.update(
            {part.timer: part.table.robot.initial_timer, f"{part.prefix}has_T": False, part.pending: 0, part.row: -1}
        )
    tick = {
        "type": "tick",
        "params": {
            "inputs": list(chart.inputs),
            "started": STARTED,
            "counters": [{"name": c, "pulses": pulses(c)} for c in robot.counter_names],
            "tables": [{"timer": p.timer, "flag": f"{p.prefix}has_T", "pending": p.pending} for p in chart.parts],
        },
    }
    meta = {
        "tablebot": {
            "format": FORMAT,
            "tickMs": robot.tick_ms,
            "inputs": list(chart.inputs),
            "motors": list(robot.motors),
            "lamps": list(robot.lamps),
            "counters": [{"name": c.name, "motor": c.motor} for c in robot.counters],
            "tables": [
                {
                    "name": p.table.name,
                    "events": list(p.table.events),
                    "match": p.table.robot.match,
                    "writes": list(p.table.writes) if chart.several else [],
                }
                for p in chart.parts
            ],
        }
    }
    config: dict[str, Any] = {"id": robot.name, "context": context, "meta": meta, "on": {TICK: {"actions": [tick]}}}
    if chart.several:
        config["type"] = "parallel"
        config["states"] = {p.region: _region(p, chart) for p in chart.parts}
    else:
        config.update(_region(chart.parts[0], chart))
    return config


def _region(part: Part, chart: Chart) -> dict[str, Any]:
    idle = {
        "guard": {"type": "idle", "params": {"pending": part.pending}},
        "actions": [{"type": "idle", "params": {"pending": part.pending, "row": part.row}}],
    }
    states = {
        part.state(state): {"always": [*(_row(part, row, chart) for row in rows), idle]}
        for state, rows in part.states_rows()
    }
    return {"initial": part.state(part.table.robot.initial_state), "states": states}


def _cross(part: Part, event: str, chart: Chart) -> dict[str, Any]:
    region, column, ids = part.cross_states(event, chart.parts)
    return {"column": column, "in": [{region: ident} for ident in ids]}


def _row(part: Part, row: Row, chart: Chart) -> dict[str, Any]:
    table, robot = part.table, part.table.robot
    required = [e for e in table.events if e in row.events]
    some = None
    if part.needs_some(row):
        some = {
            "flags": [f for e in table.events if (f := part.flag(e))],
            "cross": [_cross(part, e, chart) for e in table.events if e in table.cross],
        }
    params = {
        "pending": part.pending,
        "flags": [f for e in required if (f := part.flag(e))],
        "cross": [_cross(part, e, chart) for e in required if e in table.cross],
        "some": some,
    }
    outputs = [
        *zip(robot.motors, row.motors, strict=True),
        *zip(robot.lamps, row.lamps, strict=True),
        *zip(robot.counter_names, row.counters, strict=True),
    ]
    fire = {
        "set": {name: value for name, value in outputs if value is not None},
        "timer": part.timer,
        "load": row.timer,
        "row": part.row,
        "index": row.as_written,
        "pending": part.pending,
    }
    transition: dict[str, Any] = {
        "guard": {"type": "row", "params": params},
        "target": part.state(row.next),
        "actions": [{"type": "fire", "params": fire}],
        "description": row.description,
        "meta": {"row": row.as_written},
    }
    if row.group:  # one row as written for each state of a group: its group, and where in the table it runs
        transition["meta"].update({"group": row.group, "index": row.index})
    return transition
