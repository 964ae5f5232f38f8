"""Benchmark: simulated seconds per wall-clock second for one BumberBot in its shipped arena.

Run: ``.venv/bin/python benchmarks/sim.py [--repeat 7] [--seconds 120]``. Prints medians over the
repeats for the full loop (engine + physics), the engine alone on the same run's recorded inputs,
the physics core alone on the same run's recorded motor commands, and writing the trace.
Target (issue 3): the full loop at least 1000× real time.
"""

from __future__ import annotations

import argparse
import io
import statistics
import time
from pathlib import Path

import numpy as np

from tablebot.cli.common import load
from tablebot.engine import Engine
from tablebot.sim import layout as L
from tablebot.sim.physics import step_one
from tablebot.sim.runner import NOISE_BLOCK, Result, initial_state, run, write_trace
from tablebot.sim.scene import scene_for

ROOT = Path(__file__).resolve().parents[1]
TARGET = 1000.0


def engine_only(result: Result) -> float:
    """Wall seconds for a fresh engine to step through the run's recorded inputs."""
    inputs = [(t.mask, t.pulses) for t in result.inputs()]
    engine = Engine(result.scene.machine)
    step = engine.step
    start = time.perf_counter()
    for mask, pulses in inputs:
        step(mask, pulses)
    return time.perf_counter() - start


def physics_only(result: Result) -> float:
    """Wall seconds for the physics core to replay the run's motor commands (no engine)."""
    scene = result.scene
    geo = scene.geometry
    rng = np.random.default_rng(result.seed)
    S = initial_state(scene, rng)
    noise = rng.standard_normal((NOISE_BLOCK, 1, L.N_NOISE))
    hist = np.zeros((result.ticks + 1, L.N_STATE))
    cmd = np.zeros((1, 2), dtype=np.int64)
    right, left = scene.drive
    commands = result.outputs[:, [right, left]].tolist()
    args = (scene.P, geo.verts, geo.pstart, geo.pbound, geo.edges, geo.circles, geo.lamps)
    pcols = np.array(scene.pulse_columns, dtype=np.int64)
    pulses = np.zeros(len(pcols), dtype=np.int64)
    start = time.perf_counter()
    step_one(S, cmd, *args, noise, 0, scene.bits, hist, 0, pcols, pulses)
    for t, (r, lft) in enumerate(commands):
        cmd[0, 0], cmd[0, 1] = r, lft
        step_one(S, cmd, *args, noise, (t + 1) % NOISE_BLOCK, scene.bits, hist, t + 1, pcols, pulses)
    return time.perf_counter() - start


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--seconds", type=float, default=120.0)
    args = parser.parse_args(argv)
    table, machine = load(ROOT / "examples" / "bumberbot")
    scene = scene_for(table, machine)
    run(scene, 1.0)  # compile (or load the cached compilation of) the physics core
    full, engine, physics, trace = [], [], [], []
    for seed in range(1, args.repeat + 1):
        result = run(scene, args.seconds, seed)
        full.append(result.wall_s)
        engine.append(engine_only(result))
        physics.append(physics_only(result))
        start = time.perf_counter()
        write_trace(result, io.StringIO())
        trace.append(time.perf_counter() - start)
    sim_s = args.seconds
    ticks = round(sim_s / scene.tick_s)
    print(f"one {table.robot.name} in {scene.world.name}: {sim_s:g} s simulated ({ticks} ticks), "
          f"median of {args.repeat} runs (seeds 1..{args.repeat})")
    print(f"{'part':<28}{'wall s':>9}{'µs/tick':>10}{'× real time':>14}")
    for name, times in (("engine + physics (the loop)", full), ("engine only", engine),
                        ("physics only", physics), ("writing trace.jsonl", trace)):
        wall = statistics.median(times)
        print(f"{name:<28}{wall:9.4f}{wall / ticks * 1e6:10.2f}{sim_s / wall:14,.0f}")
    ratio = sim_s / statistics.median(full)
    verdict = "meets" if ratio >= TARGET else "MISSES"
    print(f"engine + physics runs {ratio:,.0f}× real time: {verdict} the {TARGET:,.0f}× target")


if __name__ == "__main__":
    main()
