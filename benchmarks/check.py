"""How long `tablebot check` takes: the BumberBot with its shipped properties (target < 1 s) and a
random 50-state, 500-row table with four properties (target < 10 s). Prints medians.

    .venv/bin/python benchmarks/check.py [--repeat N] [--seed S]
"""

from __future__ import annotations

import argparse
import dataclasses
import random
import statistics
import sys
import time
from pathlib import Path

from tablebot.analysis.check import run_check
from tablebot.analysis.conditions import parse_condition
from tablebot.analysis.properties import Property, load_properties
from tablebot.formats.table_read import load_table
from tablebot.machine import Machine, compile_table
from tablebot.robot import BUMBERBOT
from tablebot.table import Row, Table

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "bumberbot"
EVENTS = ("T", *BUMBERBOT.inputs)


def random_table(seed: int, states: int = 50, rows_per_state: int = 10) -> Table:
    """Rows need one or two events (T often among them), set random speeds (sometimes keep),
    load timers up to 3 s and go anywhere; every state has rows, so every next state exists."""
    rng = random.Random(seed)
    rows = []
    for state in range(1, states + 1):
        for _ in range(rows_per_state):
            events = frozenset(rng.sample(EVENTS, rng.choice((1, 1, 2))))
            motors = tuple(None if rng.random() < 0.1 else rng.randint(-6, 6) for _ in BUMBERBOT.motors)
            rows.append(Row(len(rows), len(rows) + 2, f"row {len(rows)}", state, events, motors,
                            rng.randint(0, 300), rng.randint(1, states)))
    robot = dataclasses.replace(BUMBERBOT, initial_state=1, name="Random")
    return Table(robot, EVENTS, tuple(rows), f"<random seed {seed}>")


def random_properties(machine: Machine) -> list[Property]:
    def cond(text: str):
        return parse_condition(text, machine)

    return [
        Property("home", "can always get back to state 1", "always_reachable", cond=cond("state == 1")),
        Property("calm", "never forward in state 7", "never", cond=cond("state == 7 and M1 > 0 and M2 > 0")),
        Property("stop", "front bump stops within 10 ticks", "when", when=cond("I3"),
                 then=cond("M1 <= 0 and M2 <= 0"), within=10),
        Property("reach", "state 42 can happen", "reachable", cond=cond("state == 42")),
    ]


def timed(label: str, run, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        summary = run()
        times.append(time.perf_counter() - start)
    median = statistics.median(times)
    print(f"{label:<44} median {median * 1000:8.1f} ms  (min {min(times) * 1000:.1f}, max {max(times) * 1000:.1f}, "
          f"n={repeat})  {summary}")
    return median


def check_once(machine: Machine, props: list[Property]) -> str:
    report = run_check(machine, props)
    status = " ".join(f"{r.prop.name}={r.status}" for r in report.results)
    return f"[{report.situations} situations; {status}]"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()

    def bumberbot() -> str:  # loading included: this is what `tablebot check examples/bumberbot` does
        machine = compile_table(load_table(EXAMPLE / "table.csv"))
        return check_once(machine, load_properties(machine, [EXAMPLE / "properties.toml"]))

    def random_50() -> str:
        machine = compile_table(random_table(args.seed))
        return check_once(machine, random_properties(machine))

    small = timed("BumberBot, 37 rows, 6 properties", bumberbot, args.repeat)
    large = timed("random 50 states, 500 rows, 4 properties", random_50, max(3, args.repeat // 2))
    ok = small < 1.0 and large < 10.0
    print(f"targets (< 1 s, < 10 s): {'met' if ok else 'MISSED'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
