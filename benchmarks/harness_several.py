"""The heavy sweep of the differential harness on robots of several tables (issue 36 §2): many random robots of
2-3 tables with cross-table events (tablebot.testing.random_robots) through every executor that runs several
tables, each held to tablebot.engine.several tick by tick; and every order of each robot's tables stepped by the
engine, which must give the same trace.

Run: ``.venv/bin/python benchmarks/harness_several.py [--robots 40] [--ticks 600]``. Prints, per executor, how
many robots it agreed on and the median seconds a robot took, as a ratio to the Python engine's (the baseline,
measured in the same run). Exits 1 when any executor or any order of the tables disagrees.
"""

from __future__ import annotations

import argparse
import itertools
import os
import statistics
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import tablebot.testing.executors  # noqa: F401  (registers the executors)
from tablebot.engine.as_one import robot_machine
from tablebot.replay import replay_several
from tablebot.testing.harness import EXECUTORS
from tablebot.testing.several_cases import random_several_case, several_differences

ROOT = Path(__file__).resolve().parents[1]
BASELINE = "python step"


def sweep(robots: int, ticks: int, folder: Path) -> int:
    os.environ.setdefault("TABLEBOT_TXT4_STUB", str(ROOT / "tests" / "txt4_stub"))
    times: dict[str, list[float]] = defaultdict(list)
    agreed: dict[str, int] = defaultdict(int)
    failures = []
    for seed in range(robots):
        case = random_several_case(seed, folder / f"robot{seed}", ticks)
        want, robot = list(replay_several(case.tables, case.inputs)), robot_machine(case.tables)
        for order in itertools.permutations(range(len(case.tables.machines))):
            if list(replay_several(case.tables, case.inputs, order)) != want:
                failures.append(f"robot {seed}: the order {order} gives another trace")
        for name, executor in EXECUTORS.items():
            if executor.several is None or executor.missing() is not None or not executor.fits(robot):
                continue  # the ROBO Interface counts nothing: a random robot loads a counter
            started = time.perf_counter()
            run = executor.several(case, folder / f"run{seed}" / name.replace(" ", "-"))
            times[name].append(time.perf_counter() - started)
            difference = several_differences(case.tables, run)
            if difference is None:
                agreed[name] += 1
            else:
                failures.append(f"robot {seed}, {name}: {difference}")
    base = statistics.median(times[BASELINE])
    print(f"{robots} random robots of 2-3 tables, {ticks} ticks each (load {os.getloadavg()[0]:.1f}):")
    for name, seconds in times.items():
        median = statistics.median(seconds)
        print(
            f"  {name:18} agreed {agreed[name]:3}/{len(seconds)}   median {median:7.3f} s a robot   "
            f"x{median / base:8.1f} the Python engine"
        )
    for failure in failures:
        print("DIFFERS:", failure)
    return 1 if failures else 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=40)
    parser.add_argument("--ticks", type=int, default=600)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        return sweep(args.robots, args.ticks, Path(folder))


if __name__ == "__main__":
    sys.exit(main())
