"""Running tablebot's SCXML and XState exports in engines tablebot did not write, tick by tick, and reading their
traces in tablebot's trace keys (tests/formats/test_scxml*.py, tests/formats/test_xstate*.py).

python-statemachine loads the SCXML with its secure-by-default reader (fgmacedo/python-statemachine,
statemachine/io/loader.py: ``load(text, format="scxml")``) and takes ``send("tick", **data)``; XState 5 runs the
config through the exported module in Node (statelyai/xstate: ``createActor(machine).start()``, ``send``,
``getSnapshot()``). From each tick the test reads what the engine holds: its active states and its data model
(timers, rows, outputs, counters, event flags). A row's event mask is made of the flags the statechart set and,
for a cross-table event, of the states the engine was in when the tick was sent.
"""

from __future__ import annotations

import json
import os
import random
import shutil
import subprocess
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tablebot.formats.inputs_csv import TickInput
from tablebot.formats.statecharts.chart import Chart, Part, chart_of
from tablebot.formats.statecharts.xstate import RUNTIME, export_xstate, runtime_module
from tablebot.machine import Machine, compile_table
from tablebot.replay import replay
from tablebot.table import TIMER_EVENT, Table
from tablebot.tables import RobotTables

REPO = Path(__file__).resolve().parents[1]
NODE_MODULES = REPO / "node_modules"

XSTATE_DRIVER = """\
import { readFileSync } from "node:fs";
import { createActor } from "xstate";
import { tablebotMachine, tick } from "./tablebot-xstate.mjs";

const config = JSON.parse(readFileSync("machine.json", "utf8"));
const ticks = JSON.parse(readFileSync("ticks.json", "utf8"));
const actor = createActor(tablebotMachine(config)).start();
const seen = [];
for (const [inputs, pulses] of ticks) {
  const before = actor.getSnapshot().value;
  tick(actor, inputs, pulses);
  const snapshot = actor.getSnapshot();
  seen.push([before, snapshot.value, snapshot.context]);
}
actor.stop();
process.stdout.write(JSON.stringify(seen));
"""


@dataclass(frozen=True)
class Robot:
    """A robot's tables (the main one first), compiled, and its robot-wide input layout."""

    tables: tuple[Table, ...]
    input_bits: dict[str, int]

    @property
    def chart(self) -> Chart:
        return chart_of(self.tables)

    def payloads(self, inputs: Sequence[TickInput]) -> list[tuple[dict[str, int], dict[str, int]]]:
        """Each tick's event data: every input 0 or 1, every counter's pulses."""
        counters = self.tables[0].robot.counter_names
        return [
            (
                {name: int(bool(tick.mask & bit)) for name, bit in self.input_bits.items()},
                dict(zip(counters, (*tick.pulses, *[0] * len(counters)), strict=False)),
            )
            for tick in inputs
        ]


def one_table(table: Table) -> tuple[Robot, Machine]:
    machine = compile_table(table)
    return Robot((table,), dict(machine.input_bits)), machine


def expected(machine: Machine, inputs: Sequence[TickInput]) -> list[dict[str, Any]]:
    return list(replay(machine, inputs))


def several(tables: RobotTables) -> Robot:
    """A robot of several tables (:mod:`tablebot.tables`) as the statecharts run it."""
    return Robot(tables.tables, dict(tables.input_bits))


def random_several(rng: random.Random, folder: Path, count: int) -> RobotTables:
    """A random robot of ``count`` tables (cross-table events, a group, a counter loaded by one table and read by
    others, either rule per table), written as a user's files and read back."""
    from tablebot.loading import Loaded
    from tablebot.testing.random_robots import RobotShape, random_robot

    tables = Loaded.open(random_robot(rng, folder, RobotShape(tables=count)) / "t0.csv").tables
    assert tables is not None
    return tables


def random_ticks(rng: random.Random, tables: RobotTables, count: int) -> list[TickInput]:
    """Inputs for a robot of several tables: many ticks with no input at all (where the rules part), pulses."""
    width, counters = len(tables.input_bits), len(tables.robot.counters)
    return [
        TickInput(
            rng.randrange(1 << width) if rng.random() < 0.4 else 0,
            tuple(rng.choice((0, 0, 1, 3)) for _ in range(counters)),
        )
        for _ in range(count)
    ]


def _mask(part: Part, chart: Chart, data: dict[str, Any], before: dict[str, str]) -> int:
    """The table's event mask this tick: its flags as the statechart set them, and its cross-table events from
    the states the statechart was in when the tick came."""
    table, mask = part.table, 0
    for event in table.events:
        flag = part.flag(event)
        if flag is None:
            region, _, ids = part.cross_states(event, chart.parts)
            present = before[region] in ids
        else:
            present = bool(data[flag])
        mask |= table.bit(event) if present else 0
    return mask


def line(
    chart: Chart, tick: int, before: dict[str, str], after: dict[str, str], data: dict[str, Any]
) -> dict[str, Any]:
    """One tick in tablebot's trace keys (:func:`tablebot.replay.record`, ``record_several``)."""
    robot = chart.main.robot
    out: dict[str, Any] = {"tick": tick}
    for k, part in enumerate(chart.parts):
        key = "" if k == 0 else f"{part.table.name}."
        state = next(s for s in part.table.states if part.state(s) == after[part.region])
        row = data[part.row]
        out.update(
            {
                f"{key}event": _mask(part, chart, data, before),
                f"{key}row": None if row == -1 else row,
                f"{key}state": state,
                f"{key}timer": data[part.timer],
            }
        )
        if k == 0:
            out.update({name: data[name] for name in (*robot.motors, *robot.lamps, *robot.counter_names)})
    return out


# --- python-statemachine ------------------------------------------------------------------------------------


def run_statemachine(robot: Robot, text: str, inputs: Sequence[TickInput]) -> list[dict[str, Any]]:
    """The SCXML export in python-statemachine, one ``send("tick", ...)`` per tick."""
    from statemachine.io import load

    chart = robot.chart
    machine = load(text, format="scxml")()
    lines = []
    regions = {part.state(s): part.region for part in chart.parts for s in part.table.states}
    before = _active(machine, regions)
    names = _data_names(chart)
    for tick, (values, pulses) in enumerate(robot.payloads(inputs)):
        data: dict[str, Any] = {**values, **{f"{name}_pulses": count for name, count in pulses.items()}}
        machine.send("tick", **data)
        after = _active(machine, regions)
        lines.append(line(chart, tick, before, after, {n: getattr(machine.model, n) for n in names}))
        before = after
    return lines


def _active(machine: Any, regions: dict[str, str]) -> dict[str, str]:
    return {regions[ident]: ident for ident in machine.configuration_values if ident in regions}


def _data_names(chart: Chart) -> set[str]:
    robot = chart.main.robot
    names = {
        *robot.motors,
        *robot.lamps,
        *robot.counter_names,
        *(f"has_{n}" for n in chart.inputs),
        *(f"has_{c}" for c in robot.counter_names),
    }
    for part in chart.parts:
        names |= {part.timer, part.row, part.pending, f"{part.prefix}has_{TIMER_EVENT}"}
    return names


# --- XState 5 in Node -----------------------------------------------------------------------------------------


def node_missing() -> str | None:
    if shutil.which("node") is None:
        return "no node (scripts/bootstrap.sh installs nodejs)"
    if not (NODE_MODULES / "xstate").is_dir():
        return "no node_modules/xstate (npm ci)"
    return None


def run_xstate(robot: Robot, folder: Path, inputs: Sequence[TickInput]) -> list[dict[str, Any]]:
    """The XState export in XState 5 under Node, one ``tick`` event per tick (the module's ``tick``)."""
    chart = robot.chart
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "machine.json").write_text(export_xstate(robot.tables), encoding="utf-8")
    (folder / RUNTIME).write_text(runtime_module(), encoding="utf-8")
    (folder / "driver.mjs").write_text(XSTATE_DRIVER, encoding="utf-8")
    (folder / "ticks.json").write_text(json.dumps(robot.payloads(inputs)), encoding="utf-8")
    if not (folder / "node_modules").exists():
        (folder / "node_modules").symlink_to(NODE_MODULES)  # ES modules find packages beside them, not on a path
    done = subprocess.run(
        ["node", "driver.mjs"],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
        env={"PATH": os.environ.get("PATH", "")},
    )
    assert done.returncode == 0, done.stderr
    single = chart.parts[0].region
    lines = []
    for tick, (before, after, context) in enumerate(json.loads(done.stdout)):
        if not chart.several:
            before, after = {single: before}, {single: after}
        lines.append(line(chart, tick, before, after, context))
    return lines


def first_difference(got: Sequence[dict[str, Any]], want: Sequence[dict[str, Any]]) -> str | None:
    """The first tick where two traces differ, in words, or None."""
    if len(got) != len(want):
        return f"{len(got)} ticks, the engine made {len(want)}"
    for a, b in zip(got, want, strict=True):
        if a != b:
            keys = sorted(k for k in {*a, *b} if a.get(k) != b.get(k))
            return f"tick {b['tick']}: {', '.join(f'{k} {a.get(k)!r} (engine {b.get(k)!r})' for k in keys)}"
    return None
