"""Benchmark: the fleet and the one-robot simulator as the whole commands a user waits for, beside the kernel.

Run: ``.venv/bin/python benchmarks/fleet.py [--repeat 3] [--quick] [--no-dask] [--no-evolve] [--sweep-only]``.

Whole processes (a fresh ``python -m tablebot`` each time: imports, loading the compiled code, planning,
files written) and, beside each, the inner loop measured in this process -- so what is startup and what
is the kernel can be told apart:

* **sweep**: ``tablebot sweep examples/bumberbot --robots 10000 --seconds 10 --no-plots`` on this machine's
  cores, robot-ticks/s over the wall time; beside it the kernel alone (the same 10,000 robots as one
  in-process fleet, warm). Targets: the whole process >= 3.5 M robot-ticks/s on 2 cores (issue 22) and >= 0.6x
  the kernel's speed (issue 35); where the rest of the process's time goes (benchmarks/fleet_phases.py: the
  imports before planning, planning, the chunks, the result rows written meanwhile, merging), and the floor: a
  process that only imports the fleet and loads a chunk's machine code, the best ratio any sweep process could reach.
* **from Python**: the same sweep as ``tablebot.open("examples/bumberbot").sweep(robots=10000, seconds=10,
  plots=False)`` in this process (no process start; its first call, which loads the compiled code, not
  counted), against the kernel alone measured alternately. Target (issue 35): >= 0.85x.
* **Dask**: the same sweep through ``--scheduler`` to a cluster of 2 single-threaded worker processes
  started for it with an empty cache (*fresh*: they are sent this machine's compiled code), then again
  (*warm*), as speed ratios to the local sweep of the same repeat. Target: fresh >= 0.8x the local run.
  Then the same with workers started with tablebot's preload (``--preload tablebot.fleet.worker``: numba
  imported as a worker starts), reported beside: the target's verdict stays on plain ``dask worker``.
* **one robot**: ``tablebot sim examples/bumberbot --seconds 3600`` with its two pictures, beside the same
  command ``--no-plots`` (the loop and the trace); the trace must be byte-identical either way. Target:
  under 2 s with pictures.
* **small fleets**: microseconds per tick of a 1-robot and a 16-robot fleet, by blocks (``Fleet.run``) and
  tick by tick (``Fleet.tick``, as the Gymnasium vector env does), after a large fleet has woken numba's
  thread pool, beside one SimRobot tick: small fleets run on the calling thread and the pool's threads wait passively
  (OMP_WAIT_POLICY=passive, set by tablebot.jit), so they neither pay for waking the pool nor lose a core
  to threads spinning for their next job.
* **memory**: ``tablebot sweep --robots 10000 --seconds 60``'s process tree, its peak resident memory
  (sampled every 50 ms; target < 1 GiB, issue 11).
* **evolve**: ``tablebot evolve examples/bumberbot`` (a small budget) as a whole process: candidates/s and
  robot-ticks/s of the search (from benchmarks/evolve.py).

Every child process runs without PYTHONDONTWRITEBYTECODE (``tablebot.testing.processes.child_env``): bytecode
as an installed tablebot has it. Medians of the repeats, ratios against baselines of the same run. The machine
this was written on has 2 cores shared with other engineers' runs: figures move by tens of percent; the load
average is printed.
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from fleet_dask import dask_figures
from fleet_sweep import EXAMPLE, sweep_args, sweep_ratios, tablebot, verdict

ROOT = Path(__file__).resolve().parents[1]
SWEEP_ROBOTS, SWEEP_SECONDS = 10_000, 10.0
TARGET_FRESH = 0.8  # a fresh Dask cluster's speed as a share of the local run's
TARGET_HOUR_S = 2.0  # sim --seconds 3600 with pictures


# --- one robot ---------------------------------------------------------------------------------------------


def sim_hour(seconds: float, pictures: bool) -> tuple[float, str]:
    """Wall seconds of ``tablebot sim --seconds S`` (with or without its pictures) and its trace's sha256."""
    with tempfile.TemporaryDirectory() as out:
        wall = tablebot(
            "sim",
            str(EXAMPLE),
            "--seconds",
            f"{seconds:g}",
            "--quiet",
            "--out",
            out,
            *([] if pictures else ["--no-plots"]),
        )
        trace = hashlib.sha256((Path(out) / "trace.jsonl").read_bytes()).hexdigest()
        if pictures:
            assert (Path(out) / "trajectory.png").stat().st_size and (Path(out) / "timeline.png").stat().st_size
    return wall, trace


# --- small fleets, tick by tick -----------------------------------------------------------------------------


def small_fleet_us(robots: int, ticks: int, by_tick: bool) -> float:
    """Microseconds per tick of a fleet of ``robots`` robots, after a large fleet used numba's thread pool:
    ``Fleet.run`` (blocks of 256 ticks per compiled call), or with ``by_tick`` ``Fleet.tick`` (one call a tick,
    its noise rows handed over from Python: the Gymnasium vector env's path)."""
    from tablebot.cli.common import load
    from tablebot.fleet.run import Fleet, RobotSpec
    from tablebot.sim.model.scene import robot_layer, scene_for

    table, machine = load(EXAMPLE)
    world, params = scene_for(table, machine).world, robot_layer(table.robot)[0]
    Fleet(table, machine, world, [RobotSpec(seed=s) for s in range(512)], params).run(64, threads=True)
    fleet = Fleet(table, machine, world, [RobotSpec(seed=s) for s in range(robots)], params)
    started = time.perf_counter()
    if by_tick:
        for _ in range(ticks):
            fleet.tick()
    else:
        fleet.run(ticks)
    return (time.perf_counter() - started) / ticks * 1e6


def simrobot_us(ticks: int) -> float:
    """Microseconds per tick of one SimRobot through read/step/write (the loop's tick-by-tick path)."""
    from tablebot.cli.common import load
    from tablebot.engine import Engine
    from tablebot.sim.model.scene import scene_for
    from tablebot.sim.simrobot import SimRobot

    table, machine = load(EXAMPLE)
    robot, engine = SimRobot(scene_for(table, machine), 1, record_history=False), Engine(machine)
    robot.open()
    started = time.perf_counter()
    for _ in range(ticks):
        reading = robot.read()
        robot.write(engine.step(reading.mask, reading.pulses))
    return (time.perf_counter() - started) / ticks * 1e6


def peak_memory(robots: int, seconds: float) -> tuple[float, float]:
    """Peak resident MiB of the whole process tree of ``tablebot sweep``, and its wall seconds."""
    import psutil

    with tempfile.TemporaryDirectory() as out:
        started = time.perf_counter()
        proc = subprocess.Popen(
            [sys.executable, "-m", "tablebot", *sweep_args(robots, seconds, out + "/sweep")],
            cwd=ROOT,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        parent, peak = psutil.Process(proc.pid), 0
        while proc.poll() is None:
            with contextlib.suppress(psutil.Error):
                peak = max(peak, sum(p.memory_info().rss for p in [parent, *parent.children(recursive=True)]))
            time.sleep(0.05)
        if proc.returncode != 0:
            raise SystemExit(f"the sweep failed with exit code {proc.returncode}")
        return peak / 2**20, time.perf_counter() - started


def evolve_rates(budget: int, seconds: float) -> dict[str, float]:
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from evolve import whole  # benchmarks/evolve.py

    return whole(budget, seconds)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="smaller runs (a smoke test of this script)")
    parser.add_argument("--no-dask", action="store_true")
    parser.add_argument("--no-evolve", action="store_true")
    parser.add_argument("--no-memory", action="store_true")
    parser.add_argument("--sweep-only", action="store_true", help="only the sweep's figures (process, Python, kernel)")
    parser.add_argument(
        "--baseline",
        metavar="REV",
        help="the sweep's figures for git revision REV too, the rounds "
        "alternating (its src/ exported into the temporary folder)",
    )
    parser.add_argument(
        "--code",
        metavar="REV",
        help="the sweep's figures for git revision REV instead of the working tree (one others are editing meanwhile)",
    )
    args = parser.parse_args()
    robots, seconds = (1_000, 2.0) if args.quick else (SWEEP_ROBOTS, SWEEP_SECONDS)
    hour = 60.0 if args.quick else 3600.0
    med = statistics.median
    missed = 0
    print(
        f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the start (shared machine); "
        f"medians of {args.repeat}"
    )
    missed += sweep_ratios(robots, seconds, args.repeat, args.code, args.baseline)
    if args.sweep_only:
        print(f"load average {os.getloadavg()[0]:.2f} at the end")
        return 1 if missed else 0

    if not args.no_dask:
        missed += dask_figures(robots, seconds, args.repeat)

    with_pics = [sim_hour(hour, True) for _ in range(args.repeat)]
    without = [sim_hour(hour, False) for _ in range(args.repeat)]
    same = len({trace for _, trace in with_pics + without}) == 1
    a, b = med(w for w, _ in with_pics), med(w for w, _ in without)
    ok = a < TARGET_HOUR_S and same
    missed += not ok
    print(
        f"sim --seconds {hour:g}, whole process: with pictures {a:.2f} s, --no-plots {b:.2f} s "
        f"({a / b:.2f}x); trace bytes {'identical' if same else 'DIFFER'} either way   target < {TARGET_HOUR_S:g} s "
        f"with pictures  {verdict(ok)}"
    )

    one = med(simrobot_us(20_000) for _ in range(args.repeat))
    print(f"small fleets, after a large fleet woke numba's thread pool (one SimRobot tick by tick: {one:.2f} us):")
    for n in (1, 16):
        run = med(small_fleet_us(n, 20_000, False) for _ in range(args.repeat))
        by_tick = med(small_fleet_us(n, 2_000, True) for _ in range(args.repeat))
        print(
            f"  fleet of {n:>2}: Fleet.run {run:7.2f} us per tick ({run / n:.2f} per robot-tick), Fleet.tick "
            f"{by_tick:7.2f} us per tick ({by_tick / one:.1f}x the SimRobot tick)"
        )
    print(f"  numba threading layer {threading_layer()}, OMP_WAIT_POLICY={os.environ.get('OMP_WAIT_POLICY')}")

    if not args.no_evolve:
        budget, evolve_s = (16, 2.0) if args.quick else (32, 10.0)  # whole() runs --batch 16
        runs = [evolve_rates(budget, evolve_s) for _ in range(args.repeat)]
        print(
            f"evolve --budget {budget} --seeds 0..15 --seconds {evolve_s:g}, whole process: "
            f"{med(r['wall'] for r in runs):.2f} s, {med(r['tables/s'] for r in runs):.2f} candidates/s, "
            f"{med(r['robot-ticks/s'] for r in runs) / 1e3:,.0f} k robot-ticks/s (waiting for the fleet "
            f"{med(r['fleet'] for r in runs):.2f} s, proofs {med(r['proofs'] for r in runs):.2f} s)"
        )
    if not args.no_memory:
        robots, seconds = (1_000, 10.0) if args.quick else (10_000, 60.0)
        mib, wall = peak_memory(robots, seconds)
        print(
            f"sweep --robots {robots:,} --seconds {seconds:g}: peak {mib:.0f} MiB for the process tree, {wall:.1f} s "
            f"wall (target < 1024 MiB, issue 11)"
        )
    print(f"load average {os.getloadavg()[0]:.2f} at the end")
    return 1 if missed else 0


def threading_layer() -> str:
    import numba

    try:
        return str(numba.threading_layer())
    except ValueError:  # no parallel function has run yet
        return "(not started)"


if __name__ == "__main__":
    sys.exit(main())
