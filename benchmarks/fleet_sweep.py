"""The sweep's figures of benchmarks/fleet.py: ``tablebot sweep`` as a whole process and from Python, each beside
its kernel measured alternately with it, and where the process's time goes -- for this tree's code and, with
``--baseline REV``, for a git revision's in the same run (rounds alternating), so that before and after are
ratios from one run on this shared machine.

Each tree's code runs in fresh processes importing it (``PYTHONPATH``): the sweep process, its phases
(benchmarks/fleet_phases.py) and a child that measures the kernel and ``tablebot.open(...).sweep(...)`` warm
(``--inner``). A revision's ``src/`` is exported (``git archive``) once into the temporary folder and kept there,
so its compiled code (numba caches by source path) serves the next run. ``--code REV`` measures a revision in
place of the working tree (one whose files others are editing meanwhile).
"""

from __future__ import annotations

import json
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from fleet_phases import measure as phases  # benchmarks/fleet_phases.py
from kernel import baseline_sources  # benchmarks/kernel.py
from tablebot.testing.processes import child_env

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "bumberbot"
TARGET_SWEEP = 3.5e6  # robot-ticks/s, whole process, 2 cores
TARGET_PROCESS_RATIO = 0.6  # the whole sweep process's speed as a share of its kernel's (issue 35)
TARGET_API_RATIO = 0.85  # tablebot.open(...).sweep(...) from Python, as a share of the kernel's speed
CPU_S: list[float] = []  # CPU seconds (user + system) of each tablebot() process: steadier than wall on a busy machine


def sources(rev: str | None) -> str:
    """The ``src`` folder of revision ``rev`` (exported once into the temporary folder, as benchmarks/kernel.py
    exports its baseline: the same folder serves both), or this tree's (None)."""
    return str(ROOT / "src") if rev is None else baseline_sources(rev)


def env_for(src: str) -> dict[str, str]:
    """A child's environment importing tablebot from ``src`` (bytecode written and read as a user's is)."""
    return child_env(PYTHONPATH=src)


def tablebot(*args: str, src: str | None = None, again: bool = True) -> float:
    """Wall seconds of ``python -m tablebot ARGS`` as a fresh process importing ``src`` (default: this tree; it
    must succeed); its CPU seconds go to ``CPU_S``. A process that ends in an internal error is said and run
    again once (``again``): trees before 5aff52d could, now and then, when a sweep's two threads started at once."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", *args],
        cwd=ROOT,
        env=env_for(src or sources(None)),
        capture_output=True,
        text=True,
    )
    elapsed = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode and again and "internal error" in done.stderr:
        print(f"  (run again: {src or 'this tree'} ended in {done.stderr.strip().splitlines()[-1][:160]})")
        return tablebot(*args, src=src, again=False)
    CPU_S.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    if done.returncode:
        raise SystemExit(f"tablebot {' '.join(args)} failed:\n{done.stderr}")
    return elapsed


def sweep_args(robots: int, seconds: float, out: str, example: Path = EXAMPLE) -> list[str]:
    """``tablebot sweep``'s arguments for ``robots`` runs of ``seconds`` each, no pictures, quiet, into ``out``."""
    return [
        "sweep",
        str(example),
        "--robots",
        str(robots),
        "--seconds",
        f"{seconds:g}",
        "--no-plots",
        "--quiet",
        "--out",
        out,
    ]


def sweep_process(robots: int, seconds: float, *extra: str, src: str | None = None) -> float:
    with tempfile.TemporaryDirectory() as out:
        return tablebot(*sweep_args(robots, seconds, out + "/sweep"), *extra, src=src)


def kernel_rate(robots: int, ticks: int) -> tuple[float, float]:
    """Robot-ticks/s of ``robots`` BumberBots as one warm in-process fleet (numba's threads over all cores), and
    its CPU seconds (every thread)."""
    from tablebot.cli.common import load
    from tablebot.fleet.run import Fleet, RobotSpec
    from tablebot.sim.model.scene import robot_layer, scene_for

    table, machine = load(EXAMPLE)
    world = scene_for(table, machine).world
    fleet = Fleet(table, machine, world, [RobotSpec(seed=s) for s in range(robots)], robot_layer(table.robot)[0])
    started, cpu = time.perf_counter(), time.process_time()
    fleet.run(ticks)
    return robots * ticks / (time.perf_counter() - started), time.process_time() - cpu


def api_rate(robots: int, seconds: float) -> float:
    """Robot-ticks/s of ``tablebot.open(EXAMPLE).sweep(...)`` in this process, results in memory, no pictures."""
    import tablebot

    robot = tablebot.open(EXAMPLE)
    started = time.perf_counter()
    sweep = robot.sweep(robots=robots, seconds=seconds, plots=False)
    elapsed = time.perf_counter() - started
    assert len(sweep.results) == robots
    return robots * round(seconds / 0.010) / elapsed


def inner(robots: int, seconds: float) -> dict[str, float]:
    """In this process (``--inner``): the kernel, the sweep from Python, the kernel again -- each warm."""
    api_rate(64, 1.0)  # the compiled code loaded (not counted)
    kernel_rate(4, 10)
    ticks = round(seconds / 0.010)
    kernel, cpu = kernel_rate(robots, ticks)
    api = api_rate(robots, seconds)
    after, _ = kernel_rate(robots, ticks)
    return {"kernel": kernel, "kernel_cpu": cpu, "api": api, "api_kernel": after}


def inner_child(robots: int, seconds: float, src: str) -> dict[str, float]:
    """:func:`inner` in a fresh process importing ``src``."""
    done = subprocess.run(
        [sys.executable, __file__, "--inner", str(robots), f"{seconds:g}"],
        cwd=ROOT,
        env=env_for(src),
        capture_output=True,
        text=True,
    )
    if done.returncode:
        raise SystemExit(f"benchmarks/fleet_sweep.py --inner failed:\n{done.stderr}")
    found: dict[str, float] = json.loads(done.stdout.strip().splitlines()[-1])
    return found


#: The least any sweep process does before its first chunk can run: Python starts, imports the fleet (numpy,
#: numba, the compiled modules) and loads the machine code a chunk runs -- no command line, table, plan or results.
FLOOR = (
    "import tablebot.fleet.run; from tablebot.fleet.work import chunk_functions, preload; "
    "assert preload(*chunk_functions(1)) > 0"
)


def floor_s(src: str) -> float:
    """Wall seconds of a fresh process doing :data:`FLOOR` with the tree ``src``."""
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", FLOOR], cwd=ROOT, env=env_for(src), capture_output=True, text=True)
    if done.returncode:
        raise SystemExit(f"the floor process failed:\n{done.stderr}")
    return time.perf_counter() - started


def rounds(robots: int, seconds: float, src: str) -> dict[str, Any]:
    """One round of the tree ``src``: the process (wall, CPU), its phases, the floor, and :func:`inner`."""
    wall = sweep_process(robots, seconds, src=src)
    cpu = CPU_S[-1]
    with tempfile.TemporaryDirectory() as out:
        parts = phases(sweep_args(robots, seconds, out + "/sweep"), env_for(src))
    return {"wall": wall, "cpu": cpu, "parts": parts, "floor": floor_s(src), **inner_child(robots, seconds, src)}


def verdict(ok: bool) -> str:
    return "ok" if ok else "MISSED"


def report(name: str, found: list[dict[str, Any]], robots: int, seconds: float) -> tuple[int, float, float]:
    """Print one tree's figures; returns the targets missed, and its process and Python ratios to its kernel."""
    med = statistics.median
    work = robots * round(seconds / 0.010)
    walls = [f["wall"] for f in found]
    rate = work / med(walls)
    ratio = med(work / f["wall"] / f["kernel"] for f in found)
    api = med(f["api"] / f["api_kernel"] for f in found)
    oks = (rate >= TARGET_SWEEP, ratio >= TARGET_PROCESS_RATIO, api >= TARGET_API_RATIO)
    parts = [f["parts"] for f in found]
    print(
        f"[{name}] sweep --robots {robots:,} --seconds {seconds:g}, whole process: {med(walls):.2f} s = "
        f"{rate / 1e6:.2f} M robot-ticks/s ({' '.join(f'{w:.2f}' for w in walls)} s; "
        f"{med(f['cpu'] for f in found):.2f} s CPU)  target >= {TARGET_SWEEP / 1e6:g} M  {verdict(oks[0])}"
    )
    print(
        f"  the kernel alone (warm fleet in a process of this tree): {med(f['kernel'] for f in found) / 1e6:.2f} M "
        f"robot-ticks/s; the process runs at {ratio:.2f}x the kernel's speed (median of the rounds' ratios)  "
        f"target >= {TARGET_PROCESS_RATIO}x  {verdict(oks[1])}"
    )
    print(
        "  where a sweep process's time goes (medians, s): "
        + ", ".join(f"{key} {med(p[key] for p in parts):.3f}" for key in parts[0] if not key.startswith("cpu: "))
    )
    floor, kernel_s = med(f["floor"] for f in found), med(work / f["kernel"] for f in found)
    print(
        f"  the floor (a process that only imports the fleet and loads a chunk's machine code): {floor:.3f} s; "
        f"a sweep process that did nothing else would run at {kernel_s / (kernel_s + floor):.2f}x its kernel"
    )
    kernel_cpu = med(f["kernel_cpu"] for f in found)
    print(
        "  its CPU seconds, every thread (medians): "
        + ", ".join(f"{key[5:]} {med(p[key] for p in parts):.3f}" for key in parts[0] if key.startswith("cpu: "))
        + f"; the kernel alone for the same robots {kernel_cpu:.3f} s CPU: the process spends "
        f"{med(p['cpu: in this interpreter'] for p in parts) - kernel_cpu:.3f} s CPU outside it"
    )
    print(
        f"  from Python, tablebot.open(...).sweep(robots={robots:,}, seconds={seconds:g}, plots=False): "
        f"{med(f['api'] for f in found) / 1e6:.2f} M robot-ticks/s against the kernel's "
        f"{med(f['api_kernel'] for f in found) / 1e6:.2f} M: {api:.2f}x  target >= {TARGET_API_RATIO}x  "
        f"{verdict(oks[2])}"
    )
    return sum(not ok for ok in oks), ratio, api


def sweep_ratios(robots: int, seconds: float, repeat: int, code: str | None = None, baseline: str | None = None) -> int:
    """The sweep's figures for this tree (or revision ``code``), and with ``baseline`` for that revision too, the
    rounds alternating; returns the targets this tree missed."""
    trees = {code or "this tree": sources(code)}
    if baseline:
        trees[baseline] = sources(baseline)
    for src in trees.values():  # each tree's compiled code into its cache (not counted)
        sweep_process(64, 1.0, src=src)
    found: dict[str, list[dict[str, Any]]] = {name: [] for name in trees}
    for _ in range(repeat):
        for name, src in trees.items():
            found[name].append(rounds(robots, seconds, src))
    results = {name: report(name, runs, robots, seconds) for name, runs in found.items()}
    if baseline:
        med = statistics.median
        first = next(iter(trees))
        mine, theirs = found[first], found[baseline]
        wall = med(f["wall"] for f in mine) / med(f["wall"] for f in theirs)
        cpu = med(f["cpu"] for f in mine) / med(f["cpu"] for f in theirs)
        print(
            f"{first} against {baseline} (same run): process/kernel {results[first][1]:.2f}x against "
            f"{results[baseline][1]:.2f}x; process wall x{wall:.2f}, CPU x{cpu:.2f} (after/before)"
        )
    return next(iter(results.values()))[0]


if __name__ == "__main__" and sys.argv[1:2] == ["--inner"]:
    print(json.dumps(inner(int(sys.argv[2]), float(sys.argv[3]))))
