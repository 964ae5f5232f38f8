"""Benchmark: a sweep of the BumberBot with its lights (two tables, examples/bumberbot-lights) against a sweep of
the BumberBot alone (examples/bumberbot), in the same run (issue 36 §2).

Run: ``.venv/bin/python benchmarks/sweep_several.py [--repeat 5] [--robots 2000] [--seconds 10]``.

* **whole command**: ``tablebot sweep EXAMPLE --robots N --seconds S --no-plots`` as a fresh process each, the two
  examples alternating; robot-ticks/s over the wall time and the ratio lights/alone per pair.
* **fleet alone**: the same N robots as one in-process fleet, warm (compiled and run once first), the two
  alternating: the cost of running the second table every tick, without start-up.

Medians of the repeats; each ratio is of two measurements taken one after the other (the machine's load moves
both). The load average is printed: on a shared 2-core machine the figures move by tens of percent.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from fleet_sweep import sweep_args  # beside this file (a script's folder is on the path)
from tablebot.testing.processes import child_env

ROOT = Path(__file__).resolve().parents[1]
ALONE, LIGHTS = ROOT / "examples" / "bumberbot", ROOT / "examples" / "bumberbot-lights"


def command_s(example: Path, robots: int, seconds: float) -> float:
    """Wall seconds of ``tablebot sweep`` of ``example`` as a fresh process (it must succeed)."""
    with tempfile.TemporaryDirectory(prefix="tablebot-bench-") as out:
        started = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "tablebot", *sweep_args(robots, seconds, out, example)],
            cwd=ROOT,
            env=child_env(),
            check=True,
            capture_output=True,
        )
        return time.perf_counter() - started


def fleet_runner(example: Path, robots: int, ticks: int) -> Callable[[], float]:
    """A function that runs ``robots`` robots of ``example`` (every table) for ``ticks`` ticks and returns its
    wall seconds."""
    import tablebot
    from tablebot.fleet.run import Fleet, RobotSpec
    from tablebot.sim.model.scene import robot_layer

    project = tablebot.open(example)
    scene = project.scene(every_table=True)
    layer = robot_layer(project.robot)[0]

    def run() -> float:
        fleet = Fleet(
            project.table,
            project.machine,
            scene.world,
            [RobotSpec(seed=k) for k in range(robots)],
            layer,
            tables=project.tables,
        )
        started = time.perf_counter()
        fleet.run(ticks)
        return time.perf_counter() - started

    run()  # compiled (or loaded) and warm
    return run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--robots", type=int, default=2000)
    parser.add_argument("--seconds", type=float, default=10.0)
    args = parser.parse_args()
    ticks = round(args.seconds * 100)
    work = args.robots * ticks
    print(f"load average {os.getloadavg()[0]:.1f}; {args.robots} robots x {ticks} ticks, {args.repeat} repeats")
    whole: dict[str, list[float]] = {"alone": [], "lights": []}
    for _ in range(args.repeat):
        whole["alone"].append(command_s(ALONE, args.robots, args.seconds))
        whole["lights"].append(command_s(LIGHTS, args.robots, args.seconds))
    alone_run, lights_run = fleet_runner(ALONE, args.robots, ticks), fleet_runner(LIGHTS, args.robots, ticks)
    inner: dict[str, list[float]] = {"alone": [], "lights": []}
    for _ in range(args.repeat):
        inner["alone"].append(alone_run())
        inner["lights"].append(lights_run())
    for what, times in (("tablebot sweep (whole process)", whole), ("fleet alone (warm, in process)", inner)):
        ratios = [b / a for a, b in zip(times["alone"], times["lights"], strict=True)]
        a, b = statistics.median(times["alone"]), statistics.median(times["lights"])
        print(
            f"{what}: bumberbot {a:.2f} s ({work / a / 1e6:.2f} M robot-ticks/s), bumberbot-lights {b:.2f} s "
            f"({work / b / 1e6:.2f} M/s); time ratio lights/alone, median of pairs: {statistics.median(ratios):.2f}"
        )
    print(f"load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
