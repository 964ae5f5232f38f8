"""How fast the SCXML and XState exports run in the engines that run them, beside tablebot's own engine.

Run: ``.venv/bin/python benchmarks/statecharts.py [--repeats 3]``. The BumberBot's recorded inputs
(examples/bumberbot/inputs.csv, 3000 ticks) go through ``Engine.step`` (the baseline), the SCXML export in
python-statemachine (``send("tick", ...)`` a tick) and the XState export in XState 5 under Node (``actor.send`` a
tick, timed inside Node without its start); each the median of the repeats, in µs a tick and as a ratio to the
baseline. The target: both keep the BumberBot's 10 ms tick (a statechart can drive the real robot). Exits 1 when
one does not, or when its trace is not the engine's.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from tablebot.engine import Engine
from tablebot.formats.inputs_csv import TickInput, load_inputs
from tablebot.formats.statecharts.chart import state_id
from tablebot.formats.statecharts.scxml import export_scxml
from tablebot.formats.statecharts.xstate import RUNTIME, export_xstate, runtime_module
from tablebot.formats.table_read import load_table
from tablebot.machine import Machine, compile_table

ROOT = Path(__file__).resolve().parents[1]
TICK_US = 10_000  # the BumberBot's tick
DRIVER = """\
import { readFileSync } from "node:fs";
import { createActor } from "xstate";
import { tablebotMachine, tick } from "./tablebot-xstate.mjs";
const config = JSON.parse(readFileSync("machine.json", "utf8"));
const ticks = JSON.parse(readFileSync("ticks.json", "utf8"));
const actor = createActor(tablebotMachine(config)).start();
const states = [];
const start = performance.now();
for (const inputs of ticks) { tick(actor, inputs); states.push(actor.getSnapshot().value); }
const seconds = (performance.now() - start) / 1000;
process.stdout.write(JSON.stringify({ seconds, states }));
"""


def engine(machine: Machine, ticks: list[TickInput]) -> tuple[float, list[str]]:
    start = time.perf_counter()
    run = Engine(machine)
    states = []
    for tick in ticks:
        run.step(tick.mask)
        states.append(state_id(machine.states[run.state]))
    return time.perf_counter() - start, states


def statemachine(text: str, payloads: list[dict[str, Any]]) -> tuple[float, list[str]]:
    from statemachine.io import load

    robot = load(text, format="scxml")()
    start = time.perf_counter()
    states = []
    for data in payloads:
        robot.send("tick", **data)
        states.append(next(s for s in robot.configuration_values if s != "robot_"))
    return time.perf_counter() - start, states


def xstate(config: str, payloads: list[dict[str, int]], folder: Path) -> tuple[float, list[str]]:
    (folder / "machine.json").write_text(config, encoding="utf-8")
    (folder / RUNTIME).write_text(runtime_module(), encoding="utf-8")
    (folder / "driver.mjs").write_text(DRIVER, encoding="utf-8")
    (folder / "ticks.json").write_text(json.dumps(payloads), encoding="utf-8")
    if not (folder / "node_modules").exists():
        (folder / "node_modules").symlink_to(ROOT / "node_modules")
    done = subprocess.run(["node", "driver.mjs"], cwd=folder, capture_output=True, text=True, check=True)
    result = json.loads(done.stdout)
    return result["seconds"], result["states"]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    repeats = parser.parse_args().repeats
    table = load_table(ROOT / "examples" / "bumberbot" / "table.csv")
    machine = compile_table(table)
    ticks = load_inputs(ROOT / "examples" / "bumberbot" / "inputs.csv", machine)
    payloads: list[dict[str, Any]] = [
        {name: int(bool(t.mask & bit)) for name, bit in machine.input_bits.items()} for t in ticks
    ]
    scxml, config = export_scxml([table]), export_xstate([table])
    with tempfile.TemporaryDirectory() as folder:
        runs = {
            "Engine.step (baseline)": [engine(machine, ticks) for _ in range(repeats)],
            "SCXML in python-statemachine": [statemachine(scxml, payloads) for _ in range(repeats)],
            "XState 5 in Node": [xstate(config, payloads, Path(folder)) for _ in range(repeats)],
        }
    want = runs["Engine.step (baseline)"][0][1]
    base = statistics.median(seconds for seconds, _ in runs["Engine.step (baseline)"])
    print(f"BumberBot, {len(ticks)} ticks, median of {repeats}:")
    failed = False
    for name, results in runs.items():
        seconds = statistics.median(s for s, _ in results)
        per_tick = seconds / len(ticks) * 1e6
        same = all(states == want for _, states in results)
        keeps = per_tick < TICK_US
        failed |= not (same and keeps)
        print(
            f"  {name:30} {per_tick:9.1f} µs/tick  {seconds / base:8.1f}x the engine  "
            f"{'keeps' if keeps else 'MISSES'} the 10 ms tick  {'same states' if same else 'STATES DIFFER'}"
        )
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
