"""Benchmark: how fast one simulated BumberBot runs, as the inner loop and as the whole command a user waits for.

Run: ``.venv/bin/python benchmarks/sim.py [--repeat 5] [--seconds 3600] [--no-commands]``.

Two kinds of figure, kept apart:

* **inner loop** (in this process, after warming up): the run loop driving the compiled simulator
  (engine and physics in one numba loop) for ``--seconds`` of robot time, against the same loop
  driving the same robot one tick at a time from Python (``read``/``step``/``write``: the path of real
  robots, the baseline), and the engine alone on the recorded inputs;
* **whole command** (a fresh process each time, what a user waits for): ``tablebot sim`` of a simulated
  hour with the trace and pictures, with ``--no-plots`` (the baseline: what the pictures add to it), the
  CPU seconds of the whole process tree (the command and its painter), the peak memory, and ``tablebot
  --help`` beside ``python -c pass`` (the interpreter's own start).

Medians of the repeats (runs with and without pictures interleaved); ratios against baselines measured in
the same run; the load average is printed beside (the machine may be shared). Targets (issues 10 and 22):
loop ≥ 10,000× real time; whole hour < 2 s with pictures and without; < 200 MiB; --help < 0.15 s.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.cli.common import load
from tablebot.engine import Engine
from tablebot.loop import run as run_loop
from tablebot.sim.model.scene import scene_for
from tablebot.sim.runner import simulate
from tablebot.sim.simrobot import SimRobot
from tablebot.testing.processes import child_env

if TYPE_CHECKING:
    from collections.abc import Callable

    from tablebot.sim.model.scene import Scene

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "bumberbot"
TABLEBOT = [sys.executable, "-m", "tablebot"]


def loop_seconds(scene: Scene, ticks: int, seed: int) -> float:
    """Wall seconds of the run loop on the compiled path (no history kept: the loop alone)."""
    robot, engine = SimRobot(scene, seed, record_history=False), Engine(scene.machine)
    start = time.perf_counter()
    run_loop(engine, robot, ticks=ticks)
    return time.perf_counter() - start


def tick_by_tick_seconds(scene: Scene, ticks: int, seed: int) -> float:
    """The same loop, one tick at a time from Python: the baseline (the path a real robot takes)."""
    robot, engine = SimRobot(scene, seed), Engine(scene.machine)
    from tablebot.loop import SimulatedClock

    class OneTick(SimulatedClock):
        free_running = False  # no block path: read, step, write per tick

    start = time.perf_counter()
    run_loop(engine, robot, clock=OneTick(), ticks=ticks)
    return time.perf_counter() - start


def engine_seconds(scene: Scene, seconds: float, seed: int) -> float:
    result = simulate(scene, seconds, seed)
    inputs = [(t.mask, t.pulses) for t in result.inputs()]
    step = Engine(scene.machine).step
    start = time.perf_counter()
    for mask, pulses in inputs:
        step(mask, pulses)
    return time.perf_counter() - start


def command(args: list[str]) -> tuple[float, float, float, float]:
    """Wall seconds, peak resident MiB, peak private MiB (resident minus the pages of shared libraries
    and files: RssAnon, sampled every 10 ms) of one fresh process, and the CPU seconds (user + system) of
    it and every process it started."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=ROOT, env=child_env())
    private = [0.0]
    sampler = threading.Thread(target=_sample_private, args=(proc.pid, private), daemon=True)
    sampler.start()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    sampler.join()
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(args)} failed")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)  # the command's forks were waited for by it
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    return wall, usage.ru_maxrss / 1024, private[0], cpu


def _sample_private(pid: int, peak: list[float]) -> None:
    status = Path(f"/proc/{pid}/status")
    while True:
        try:
            text = status.read_text()
        except OSError:
            return
        for line in text.splitlines():
            if line.startswith("RssAnon:"):
                peak[0] = max(peak[0], int(line.split()[1]) / 1024)
        if "State:\tZ" in text:
            return
        time.sleep(0.01)


def median_of(repeat: int, measure: Callable[[], float]) -> float:
    return statistics.median(measure() for _ in range(repeat))


def inner(repeat: int, seconds: float) -> float:
    table, machine = load(EXAMPLE)
    scene = scene_for(table, machine)
    ticks = round(seconds / scene.tick_s)
    simulate(scene, 1.0)  # compile, or load numba's cached compilation
    loop = median_of(repeat, lambda: loop_seconds(scene, ticks, 1))
    short = min(seconds, 60.0)  # the tick-by-tick baseline is slow: a minute of it, scaled
    one = median_of(repeat, lambda: tick_by_tick_seconds(scene, round(short / scene.tick_s), 1)) * seconds / short
    engine = median_of(repeat, lambda: engine_seconds(scene, short, 1)) * seconds / short
    print(
        f"inner loop: one {table.robot.name} in {scene.world.name}, {seconds:g} s simulated ({ticks:,} ticks), "
        f"median of {repeat}"
    )
    print(f"  {'':<44}{'wall s':>9}{'µs/tick':>9}{'× real time':>13}")
    for name, wall in (
        ("run loop, compiled block path", loop),
        ("run loop, tick by tick from Python (baseline)", one),
        ("engine alone, Engine.step on recorded inputs", engine),
    ):
        print(f"  {name:<44}{wall:9.3f}{wall / ticks * 1e6:9.2f}{seconds / wall:13,.0f}")
    print(f"  compiled loop vs tick-by-tick: {one / loop:.1f}×")
    return seconds / loop


def whole(repeat: int) -> dict[str, float]:
    with tempfile.TemporaryDirectory() as tmp:

        def sim(run: int) -> list[str]:  # a new folder each run: replacing a run's 59 MB trace costs more
            return [*TABLEBOT, "sim", str(EXAMPLE), "--seconds", "3600", "-q", "--out", f"{tmp}/{run}"]

        subprocess.run(sim(0), check=True, cwd=ROOT, capture_output=True)  # warm numba's cache and the disk
        load = os.getloadavg()[0]
        runs, bare = [], []
        for k in range(repeat):
            runs.append(command(sim(2 * k + 1)))
            bare.append(command([*sim(2 * k + 2), "--no-plots"]))
            for folder in (2 * k + 1, 2 * k + 2):
                shutil.rmtree(f"{tmp}/{folder}")
    helps = [command([*TABLEBOT, "--help"])[0] for _ in range(repeat)]
    python = [command([sys.executable, "-c", "pass"])[0] for _ in range(repeat)]
    figures = {
        "hour": statistics.median(r[0] for r in runs),
        "hour_mib": max(r[1] for r in runs),
        "hour_private": max(r[2] for r in runs),
        "hour_cpu": statistics.median(r[3] for r in runs),
        "bare": statistics.median(r[0] for r in bare),
        "bare_mib": max(r[1] for r in bare),
        "bare_private": max(r[2] for r in bare),
        "bare_cpu": statistics.median(r[3] for r in bare),
        "help": statistics.median(helps),
        "python": statistics.median(python),
    }
    print(
        f"whole command (fresh processes, median of {repeat}, load average {load:.2f} at the start; CPU: user + "
        "system of the whole process tree; memory: peak resident, and in brackets the private part, without "
        "shared library pages):"
    )
    print(
        f"  tablebot sim (1 h, trace + pictures)    {figures['hour']:6.2f} s   CPU {figures['hour_cpu']:5.2f} s   "
        f"peak {figures['hour_mib']:5.0f} MiB ({figures['hour_private']:.0f} MiB private)   "
        f"{figures['hour'] / figures['bare']:.2f}x --no-plots"
    )
    print(
        f"  tablebot sim (1 h, --no-plots)          {figures['bare']:6.2f} s   CPU {figures['bare_cpu']:5.2f} s   "
        f"peak {figures['bare_mib']:5.0f} MiB ({figures['bare_private']:.0f} MiB private)"
    )
    print(
        f"  tablebot --help                         {figures['help']:6.3f} s   "
        f"({figures['help'] / figures['python']:.1f}× python -c pass, {figures['python']:.3f} s)"
    )
    return figures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--seconds", type=float, default=3600.0)
    parser.add_argument("--no-commands", action="store_true", help="only the inner loop")
    args = parser.parse_args(argv)
    speed = inner(args.repeat, args.seconds)
    checks = [("run loop ≥ 10,000× real time", speed >= 10_000)]
    if not args.no_commands:
        f = whole(args.repeat)
        checks += [
            ("whole hour < 2 s", f["hour"] < 2),
            ("--no-plots hour < 2 s", f["bare"] < 2),
            ("peak memory < 200 MiB (resident)", f["hour_mib"] < 200),
            ("peak memory < 200 MiB (private)", f["hour_private"] < 200),
            ("--help < 0.15 s", f["help"] < 0.15),
        ]
    print("targets:")
    for label, ok in checks:
        print(f"  {label:<32} {'ok' if ok else 'MISSED'}")
    return 0 if all(ok for _, ok in checks) else 1


if __name__ == "__main__":
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    sys.exit(main())
