"""The whole kernel of this tree against a baseline revision, timed as interleaved pairs of long-lived processes.

    .venv/bin/python benchmarks/kernel_pairs.py --baseline main [--pairs 4] [--reps 10]

benchmarks/kernel.py starts a fresh process per measurement, and on this shared 2-core machine one process of a
tree differs from the next by up to +-10 % (where its code and data land, who else runs): a single round can read
x1.13 where forty read x1.00. Here each of ``--pairs`` pairs starts one process of each tree, warms it, and then
asks them in turn (ABBA), ``--reps`` times each, to run the same work; the ratio of adjacent timings (this tree /
the baseline) keeps the machine's changing load out, and the median of every ratio is the figure. Two kinds of
work, as a sweep and a fleet run them:

* **one thread**: 1,000 BumberBots x 1,000 ticks (10 s) on the calling thread (``run_fleet_serial``: a sweep's
  chunks), CPU seconds;
* **numba's threads**: 4,000 BumberBots x 500 ticks on every core (``run_fleet``: a fleet from Python, the
  Gymnasium env), wall seconds.

The baseline's sources are exported once into the temporary folder (benchmarks/kernel.py's ``baseline_sources``)
and compiled into their own numba cache. A worker is this file run with ``--worker KIND``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
KINDS = {"one thread": (1000, 1000, False), "numba's threads": (4000, 500, True)}  # robots, ticks, threads


def worker(kind: str) -> None:
    """Warm up, say "ready", then for each line read time the work once and print its ns per robot-tick."""
    from tablebot.cli.common import load
    from tablebot.fleet.run import Fleet, RobotSpec
    from tablebot.sim.model.scene import robot_layer, scene_for

    robots, ticks, threads = KINDS[kind]
    table, machine = load(ROOT / "examples" / "bumberbot")
    world, layer = scene_for(table, machine).world, robot_layer(table.robot)[0]

    def once() -> float:
        fleet = Fleet(table, machine, world, [RobotSpec(seed=s) for s in range(robots)], layer)
        clock = time.perf_counter if threads else time.process_time  # the pool's threads: wall; one thread: CPU
        started = clock()
        fleet.run(ticks, threads=threads)
        return (clock() - started) / (robots * ticks) * 1e9

    once()
    print("ready", flush=True)
    for _ in sys.stdin:
        print(once(), flush=True)


def start(kind: str, src: str) -> subprocess.Popen[str]:
    env = dict(os.environ, PYTHONPATH=src)
    env.pop("NUMBA_CACHE_DIR", None)  # each tree its own cache (tablebot.jit names it after the sources)
    process = subprocess.Popen(
        [sys.executable, __file__, "--worker", kind],
        cwd=ROOT,
        env=env,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert process.stdin is not None and process.stdout is not None
    if process.stdout.readline().strip() != "ready":
        raise SystemExit(f"a {kind} worker of {src} did not start")
    return process


def timed(process: subprocess.Popen[str]) -> float:
    assert process.stdin is not None and process.stdout is not None
    process.stdin.write("\n")
    process.stdin.flush()
    return float(process.stdout.readline())


def ratios(kind: str, baseline: str, pairs: int, reps: int) -> list[float]:
    """This tree's time over the baseline's, adjacent timings of ``pairs`` process pairs, ``reps`` each."""
    found = []
    for k in range(pairs):
        mine, theirs = start(kind, str(ROOT / "src")), start(kind, baseline)
        for i in range(reps):
            if i % 2:
                b, a = timed(theirs), timed(mine)
            else:
                a, b = timed(mine), timed(theirs)
            found.append(a / b)
        for process in (mine, theirs):
            assert process.stdin is not None
            process.stdin.close()
            process.wait()
        print(
            f"  {kind}, pair {k}: x{statistics.median(found[-reps:]):.3f} (load {os.getloadavg()[0]:.1f})", flush=True
        )
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default="main", help="a git revision to compare with")
    parser.add_argument("--pairs", type=int, default=4, help="process pairs per kind of work")
    parser.add_argument("--reps", type=int, default=10, help="timings of each process of a pair")
    parser.add_argument("--worker", choices=list(KINDS), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args.worker)
        return
    sys.path.insert(0, str(Path(__file__).parent))
    from kernel import baseline_sources  # beside this file

    baseline = baseline_sources(args.baseline)
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; this tree against {args.baseline}")
    for kind in KINDS:
        found = ratios(kind, baseline, args.pairs, args.reps)
        print(f"{kind}: this tree's time x{statistics.median(found):.3f} the baseline's ({len(found)} pairs)")


if __name__ == "__main__":
    main()
