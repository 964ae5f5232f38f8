"""Benchmark: many simulated BumberBots at once (the fleet kernel, the sweep backends), beside one robot.

Run: ``.venv/bin/python benchmarks/fleet.py [--repeat 3] [--quick] [--no-dask] [--no-memory]``.

* **robot-ticks/s** of N = 1, 100, 1,000, 10,000 BumberBots in the shipped arena (seeds 0..N-1, the
  arena's start), run in this process by the fleet kernel (numba ``prange`` over all cores), beside the
  single-robot ``tablebot sim`` loop (SimRobot through the run loop, compiled block path) measured in the
  same run; noise drawing is included (each robot's own numpy Generator, as SimRobot draws it);
* **local backend vs Dask**: the same 10,000-robot sweep (``--sweep-seconds`` of robot time each) through
  the local backend (one process per core) and through a local Dask cluster of 2 single-threaded worker
  processes; both warmed up first (compiled kernels loaded), so this is the scheduling overhead;
* **memory**: ``tablebot sweep --robots 10000 --seconds 60`` as a whole process tree (parent and worker
  processes, resident memory sampled every 50 ms), the peak of the sum.

Medians of the repeats, ratios against the baselines of the same run. Targets (issue 11): 10 M robot-ticks/s
on 2 cores; Dask within 1.3× of local; the 10,000-robot 60 s sweep under 1 GiB. The machine this was
written on has 2 cores shared with other engineers' test runs: figures move by tens of percent.
"""

from __future__ import annotations

import argparse
import logging
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "bumberbot"


def single_robot(ticks: int) -> float:
    """Robot-ticks/s of one robot through the run loop (what ``tablebot sim`` runs), no history kept."""
    from tablebot.cli.common import load
    from tablebot.engine import Engine
    from tablebot.loop import run as run_loop
    from tablebot.sim.scene import scene_for
    from tablebot.sim.simrobot import SimRobot

    table, machine = load(EXAMPLE)
    scene = scene_for(table, machine)
    robot, engine = SimRobot(scene, 1, record_history=False), Engine(machine)
    started = time.perf_counter()
    run_loop(engine, robot, ticks=ticks)
    return ticks / (time.perf_counter() - started)


def fleet(n: int, ticks: int) -> tuple[float, float]:
    """Robot-ticks/s of n robots in one in-process fleet, and the seconds to set the fleet up."""
    from tablebot.cli.common import load
    from tablebot.fleet.run import Fleet, RobotSpec
    from tablebot.sim.scene import robot_layer, scene_for

    table, machine = load(EXAMPLE)
    world = scene_for(table, machine).world
    started = time.perf_counter()
    robots = Fleet(table, machine, world, [RobotSpec(seed=s) for s in range(n)], robot_layer(table.robot)[0])
    setup = time.perf_counter() - started
    started = time.perf_counter()
    robots.run(ticks)
    return n * ticks / (time.perf_counter() - started), setup


def breakdown(repeat: int) -> dict[str, float]:
    """Nanoseconds per robot-tick of each part of the shared physics, on one core, over the robot rows of
    a recorded 300 s BumberBot run (each part called on every row; its share is what it costs a tick)."""
    import numpy as np

    from tablebot.cli.common import load
    from tablebot.jit import njit
    from tablebot.sim import physics as ph
    from tablebot.sim.runner import simulate
    from tablebot.sim.scene import scene_for

    table, machine = load(EXAMPLE)
    scene = scene_for(table, machine)
    rows = simulate(scene, 300.0, 1).hist.astype(np.float64)
    g, p = scene.geometry, scene.P[0]

    @njit
    def copy_only(rows):  # type: ignore[no-untyped-def]
        s = rows[0].copy()
        for i in range(rows.shape[0]):
            s[:] = rows[i]

    @njit
    def motors(rows, p):  # type: ignore[no-untyped-def]
        z, s = np.zeros(4), rows[0].copy()
        for i in range(rows.shape[0]):
            s[:] = rows[i]
            ph.drive(s, (2, -2), p, z)

    @njit
    def contacts(rows, p, verts, pstart, pbound, circles):  # type: ignore[no-untyped-def]
        corners, s = np.empty((4, 2)), rows[0].copy()
        for i in range(rows.shape[0]):
            s[:] = rows[i]
            ph.resolve(s, p, corners, verts, pstart, pbound, circles)

    @njit
    def bumpers(rows, p, verts, pstart, pbound, circles):  # type: ignore[no-untyped-def]
        s = rows[0].copy()
        for i in range(rows.shape[0]):
            s[:] = rows[i]
            ph.sense_bumpers(s, p, verts, pstart, pbound, circles)

    @njit
    def light(rows, p, edges, circles, lamps):  # type: ignore[no-untyped-def]
        total = 0.0
        for i in range(rows.shape[0]):
            total += ph.light_at(rows[i], p, -1.0, edges, circles, lamps) + ph.light_at(rows[i], p, 1.0, edges,
                                                                                          circles, lamps)
        return total

    def ns(function, *args) -> float:  # type: ignore[no-untyped-def]
        function(*args)
        best = []
        for _ in range(max(3, repeat)):
            started = time.perf_counter()
            function(*args)
            best.append(time.perf_counter() - started)
        return statistics.median(best) / len(rows) * 1e9

    base = ns(copy_only, rows)
    rng, noise = np.random.default_rng(0), np.empty((len(rows), 4))
    started = time.perf_counter()
    rng.standard_normal(out=noise)
    noise_ns = (time.perf_counter() - started) / len(rows) * 1e9
    return {"light (2 phototransistors)": ns(light, rows, p, g.edges, g.circles, g.lamps),
            "bumpers (broad phase + plates)": ns(bumpers, rows, p, g.verts, g.pstart, g.pbound, g.circles) - base,
            "contacts (broad phase + push out)": ns(contacts, rows, p, g.verts, g.pstart, g.pbound, g.circles) - base,
            "motors, battery, motion": ns(motors, rows, p) - base,
            "noise (4 normals, numpy Generator)": noise_ns}


def sweep_plan(robots: int, seconds: float):  # type: ignore[no-untyped-def]
    from tablebot.fleet.plan import make_plan

    return make_plan(EXAMPLE, None, [], [], None, robots, seconds)


def sweep_seconds(plan, runner) -> float:  # type: ignore[no-untyped-def]
    """Wall seconds of the sweep's runs through an open backend (results collected, no files written)."""
    rows: list[int] = []
    started = time.perf_counter()
    runner.run(plan.jobs(), lambda job, summary: rows.append(len(summary)))
    elapsed = time.perf_counter() - started
    assert sum(rows) == plan.spec.total
    return elapsed


def dask_vs_local(robots: int, seconds: float, repeat: int) -> tuple[list[float], list[float], int]:
    """Wall seconds of each repeat through the local backend and through Dask, and the robot-ticks of one.

    Each backend stays open over the repeats (as through one command): the local worker processes start
    and load the kernels once, as the Dask workers do, so the ratio is the scheduling overhead alone."""
    from distributed import LocalCluster

    from tablebot.fleet.backends import Runner

    plan = sweep_plan(robots, seconds)
    small = sweep_plan(64, 1.0)
    local, dask = [], []
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                      silence_logs=logging.ERROR) as cluster, Runner("local", workers=2) as on_local, \
            Runner("dask", cluster.scheduler_address) as on_dask:
        sweep_seconds(small, on_dask)  # warm: the workers load the kernel
        sweep_seconds(small, on_local)  # warm: the worker processes start and load it
        for _ in range(repeat):
            local.append(sweep_seconds(plan, on_local))
            dask.append(sweep_seconds(plan, on_dask))
    return local, dask, plan.spec.total * plan.spec.ticks


def peak_memory(robots: int, seconds: float) -> tuple[float, float]:
    """Peak resident MiB of the whole process tree of ``tablebot sweep``, and its wall seconds."""
    import psutil

    with tempfile.TemporaryDirectory() as out:
        command = [sys.executable, "-m", "tablebot", "sweep", str(EXAMPLE), "--robots", str(robots), "--seconds",
                   str(seconds), "--no-plots", "--quiet", "--out", out]
        started = time.perf_counter()
        proc = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        parent, peak = psutil.Process(proc.pid), 0
        while proc.poll() is None:
            try:
                tree = [parent, *parent.children(recursive=True)]
                peak = max(peak, sum(p.memory_info().rss for p in tree))
            except psutil.Error:
                pass
            time.sleep(0.05)
        if proc.returncode != 0:
            raise SystemExit(f"the sweep failed with exit code {proc.returncode}")
        return peak / 2**20, time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="fewer ticks (a smoke test of this script)")
    parser.add_argument("--sweep-seconds", type=float, default=10.0)
    parser.add_argument("--no-dask", action="store_true")
    parser.add_argument("--no-memory", action="store_true")
    args = parser.parse_args()
    budget = 200_000 if args.quick else 3_000_000  # robot-ticks per fleet measurement
    print(f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the start (shared machine)")
    fleet(4, 10)  # compile or load the kernels
    base = statistics.median(single_robot(budget // 10 if args.quick else 200_000) for _ in range(args.repeat))
    print(f"single robot, tablebot sim loop:   {base / 1e6:6.2f} M robot-ticks/s   (baseline)")
    for n in (1, 100, 1_000, 10_000):
        ticks = max(100, min(6_000, budget // n))
        runs = [fleet(n, ticks) for _ in range(args.repeat)]
        rate = statistics.median(r for r, _ in runs)
        setup = statistics.median(s for _, s in runs)
        print(f"fleet of {n:>6,} ({ticks:>5} ticks):    {rate / 1e6:6.2f} M robot-ticks/s   {rate / base:5.2f}× "
              f"the single loop   (setting up the robots: {setup:.2f} s)")
    print("target: 10 M robot-ticks/s on 2 cores")
    parts = breakdown(args.repeat)
    print(f"where one robot-tick goes (one core, ns; the whole tick: {1e9 / base:.0f} ns in the single loop):")
    for name, value in parts.items():
        print(f"  {name:<36} {value:6.0f}")
    if not args.no_dask:
        robots = 1_000 if args.quick else 10_000
        local, dask, ticks = dask_vs_local(robots, args.sweep_seconds, args.repeat)
        a, b = statistics.median(local), statistics.median(dask)
        print(f"sweep of {robots:,} robots × {args.sweep_seconds:g} s: local backend {a:.2f} s "
              f"({ticks / a / 1e6:.2f} M robot-ticks/s), Dask 2 workers {b:.2f} s ({ticks / b / 1e6:.2f} M/s): "
              f"Dask/local = {b / a:.2f}× (target ≤ 1.3×)")
    if not args.no_memory:
        robots, seconds = (1_000, 10.0) if args.quick else (10_000, 60.0)
        mib, wall = peak_memory(robots, seconds)
        print(f"tablebot sweep --robots {robots:,} --seconds {seconds:g}: peak {mib:.0f} MiB for the process tree "
              f"(parent + workers), {wall:.1f} s wall (target < 1024 MiB)")
    print(f"load average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()
