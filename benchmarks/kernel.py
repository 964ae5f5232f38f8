"""The simulator's kernel per robot-tick, whole and by part, on one core -- against a baseline tree in the same run.

    .venv/bin/python benchmarks/kernel.py [--example bumberbot] [--baseline main] [--rounds 3]

The whole kernel is a fleet of 1,000 robots run 1,000 ticks (10 s) from the world's start on this thread
(``run_fleet_serial``, noise drawn in the kernel): the workload of ``tablebot sweep --robots N --seconds 10``,
one core. The parts are each of the kernel's steps timed alone, in a loop over the robot rows such a run
records (100 robots x 10 s): light (both phototransistors, shadows included), bumpers, contacts, motors
(battery, wheels, pose), declared sensors, the lamp/collision summary, the noise (four normals) and the
engine's tick rule. A part's loop copies each row first; that copy is timed alone and subtracted.

Times are CPU time (``process_time``: what this process ran, not what others on a shared machine took), the
median of the repeats. With ``--baseline REF`` the same measurement runs on the git revision REF's sources
(exported once into the temporary folder, compiled into their own numba cache) in a fresh process, alternating with
this tree's, ``--rounds`` times each: the ratios (this tree / the baseline) are the figures to read on a busy
machine. Without it, each part is also shown as a share of the whole tick.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kernel_rows import as_rows, viewers  # beside this file (a script's folder is on the path)
from kernel_several import several_against_one

if TYPE_CHECKING:
    import numpy as np

ROOT = Path(__file__).resolve().parent.parent
WHOLE = "whole kernel"


def _sim(name: str) -> Any:
    """The simulator's module ``name`` (``physics.kernel``) in the tree this process imports; a baseline from before
    sim/ was split by what it owns (issue 35) has it one level up (``sim.kernel``; ``physics.step`` was
    ``sim.physics``)."""
    try:
        return importlib.import_module(f"tablebot.sim.{name}")
    except ModuleNotFoundError:
        old = "physics" if name == "physics.step" else name.split(".")[1]
        return importlib.import_module(f"tablebot.sim.{old}")


def measure(example: str, repeats: int) -> dict[str, float]:
    """ns per robot-tick of the whole kernel and of each part, in this process's tablebot."""
    import numpy as np

    from tablebot.cli.common import load
    from tablebot.fleet.run import Fleet, RobotSpec

    robot_layer, scene_for = _sim("model.scene").robot_layer, _sim("model.scene").scene_for

    table, machine = load(ROOT / "examples" / example)
    scene = scene_for(table, machine)
    layer = robot_layer(table.robot)[0]

    def whole() -> float:
        fleet = Fleet(table, machine, scene.world, [RobotSpec(seed=s) for s in range(1000)], layer)
        started = time.process_time()
        fleet.run(1000, threads=False)
        return (time.process_time() - started) / 1e6 * 1e9

    whole()  # compiled or loaded, warm
    out = {WHOLE: statistics.median(whole() for _ in range(repeats))}
    fleet = Fleet(table, machine, scene.world, [RobotSpec(seed=s) for s in range(100)], layer, traced=range(100))
    fleet.run(1000, threads=False)
    rows = np.concatenate([np.concatenate(trace.rows) for trace in fleet.traces.values()])
    out.update(_parts(rows, scene, fleet, repeats))
    out.update(several_against_one(repeats))
    return out


def _parts(rows: Any, scene: Any, fleet: Any, repeats: int) -> dict[str, float]:
    import numpy as np

    co, K, ph = _sim("physics.contacts"), _sim("physics.kernel"), _sim("physics.step")
    loops = _loops()
    g, p = scene.geometry, scene.P[0]
    shade = getattr(g, "shade", None)
    s, near_centre = rows[0].copy(), co.new_near(g.pstart, g.circles)

    def ns(name: str, *args: Any) -> float:
        loops[name](*args)
        times = []
        for _ in range(repeats):
            started = time.process_time()
            loops[name](*args)
            times.append(time.process_time() - started)
        return statistics.median(times) / rows.shape[0] * 1e9

    copy = ns("copy", rows, s)
    regs, outputs, counters = (a.copy() for a in fleet.initial)
    light = (
        ("light_shade", rows, as_rows(rows), p, g.edges, g.circles, g.lamps, np.empty(4), shade)
        if shade is not None
        else ("light", rows, as_rows(rows), p, g.edges, g.circles, g.lamps, np.empty(4))
    )
    parts = {
        "light (2 phototransistors)": ns(*light),
        "bumpers": ns("bumpers", rows, p, g.verts, g.pstart, g.pbound, g.circles, s, *near_centre) - copy,
        "contacts": ns("contacts", rows, p, g.verts, g.pstart, g.pbound, g.circles, s, np.empty((4, 2)), *near_centre)
        - copy,
        "motors": ns("motors", rows, p, s, np.zeros(4)) - copy,
        "declared sensors": ns(
            "declared",
            rows,
            p,
            g.edges,
            g.circles,
            g.lamps,
            g.lines,
            s,
            any(
                skip in inspect.getsource(ph.sense_near.py_func) for skip in ("P_SENSOR + F_KIND", "sensor[0, F_KIND]")
            ),
        )
        - copy,
        "summary (observe)": ns("observe", rows, g.lamps, K.new_accumulator(0.25, 20), np.zeros(16, np.int64), s)
        - copy,
        "noise (4 normals)": ns("noise", rows.shape[0], fleet.bitgens[0]),
        "engine tick": ns(
            "engine", rows, regs, outputs, counters, np.zeros(counters.shape[0], np.int64), fleet.machine.arrays.program
        ),
        "heading cos+sin": ns("trig", rows),
    }
    return parts


def _loops() -> dict[str, Any]:
    """The timing loops, compiled here (each a loop over recorded robot rows around one step of the kernel)."""
    from tablebot.engine_batch import tick_compiled
    from tablebot.jit import njit
    from tablebot.sim import columns as L

    co, K, ph = _sim("physics.contacts"), _sim("physics.kernel"), _sim("physics.step")
    standard_normal, sense_declared = _sim("physics.normals").standard_normal, _sim("physics.sensing").sense_declared
    fast = njit(refcounts=False, cache=False)
    S, P = viewers(fast)

    @fast
    def put(s: np.ndarray, rows: np.ndarray, i: int) -> None:
        for j in range(s.shape[0]):
            s[j] = rows[i, j]

    @fast
    def copy(rows: np.ndarray, s: np.ndarray) -> float:
        for i in range(rows.shape[0]):
            put(s, rows, i)
        return s[0]

    @fast
    def trig(rows: np.ndarray) -> float:
        t = 0.0
        for i in range(rows.shape[0]):
            t += math.cos(rows[i, L.TH]) + math.sin(rows[i, L.TH])
        return t

    @fast
    def light_shade(
        rows: np.ndarray,
        recs: np.ndarray,
        p: np.ndarray,
        edges: np.ndarray,
        circles: np.ndarray,
        lamps: np.ndarray,
        turns: np.ndarray,
        shade: np.ndarray,
    ) -> float:
        total = 0.0
        q = P(p)
        ph.aim_turns(q, turns)
        for i in range(rows.shape[0]):
            s = recs[i]
            c, sn = math.cos(rows[i, L.TH]), math.sin(rows[i, L.TH])
            total += ph.light_side(s, c, sn, q, -1.0, turns[0], turns[1], edges, circles, lamps, shade) + ph.light_side(
                s, c, sn, q, 1.0, turns[2], turns[3], edges, circles, lamps, shade
            )
        return total

    @fast
    def light(
        rows: np.ndarray,
        recs: np.ndarray,
        p: np.ndarray,
        edges: np.ndarray,
        circles: np.ndarray,
        lamps: np.ndarray,
        turns: np.ndarray,
    ) -> float:  # trees without a grid
        total = 0.0
        q = P(p)
        ph.aim_turns(q, turns)
        for i in range(rows.shape[0]):
            s = recs[i]
            c, sn = math.cos(rows[i, L.TH]), math.sin(rows[i, L.TH])
            total += ph.light_side(s, c, sn, q, -1.0, turns[0], turns[1], edges, circles, lamps) + ph.light_side(
                s, c, sn, q, 1.0, turns[2], turns[3], edges, circles, lamps
            )
        return total

    @fast
    def bumpers(
        rows: np.ndarray,
        p: np.ndarray,
        verts: np.ndarray,
        pstart: np.ndarray,
        pbound: np.ndarray,
        circles: np.ndarray,
        s: np.ndarray,
        near: np.ndarray,
        centre: np.ndarray,
    ) -> float:
        row, q = S(s), P(p)  # views of the rows, once
        reach, wide = co.reaches(q)
        for i in range(rows.shape[0]):
            put(s, rows, i)
            c, sn = math.cos(s[L.TH]), math.sin(s[L.TH])
            co.sense_bumpers(row, q, c, sn, verts, pstart, pbound, circles, reach, wide, near, centre)
        return s[0]

    @fast
    def contacts(
        rows: np.ndarray,
        p: np.ndarray,
        verts: np.ndarray,
        pstart: np.ndarray,
        pbound: np.ndarray,
        circles: np.ndarray,
        s: np.ndarray,
        corners: np.ndarray,
        near: np.ndarray,
        centre: np.ndarray,
    ) -> float:
        row, q = S(s), P(p)  # views of the rows, once
        reach, wide = co.reaches(q)
        for i in range(rows.shape[0]):
            put(s, rows, i)
            co.resolve(row, q, corners, verts, pstart, pbound, circles, reach, wide, near, centre)
        return s[0]

    @fast
    def motors(rows: np.ndarray, p: np.ndarray, s: np.ndarray, z: np.ndarray) -> float:
        row, q = S(s), P(p)
        for i in range(rows.shape[0]):
            put(s, rows, i)
            ph.drive(row, (2, -2), q, z)
        return s[0]

    @fast
    def declared(
        rows: np.ndarray,
        p: np.ndarray,
        edges: np.ndarray,
        circles: np.ndarray,
        lamps: np.ndarray,
        lines: np.ndarray,
        s: np.ndarray,
        skip: bool,
    ) -> float:
        row, q = S(s), P(p)
        for i in range(rows.shape[0]):
            put(s, rows, i)
            if not skip or p[L.P_SENSOR + L.F_KIND] != 0.0:  # skip: the tree's kernel skips robots without any
                sense_declared(row, math.cos(s[L.TH]), math.sin(s[L.TH]), q, edges, circles, lamps, lines)
        return s[0]

    @fast
    def observe(rows: np.ndarray, lamps: np.ndarray, acc: np.ndarray, collisions: np.ndarray, s: np.ndarray) -> float:
        row = S(s)
        for i in range(rows.shape[0]):
            put(s, rows, i)
            K.observe(row, lamps, acc, collisions)
        return s[0]

    @fast
    def noise(n: int, bitgen: np.uint64) -> float:
        t = 0.0
        for _ in range(n):
            for _ in range(4):
                t += standard_normal(bitgen)
        return t

    @fast
    def engine(
        rows: np.ndarray,
        regs: np.ndarray,
        outputs: np.ndarray,
        counters: np.ndarray,
        pulses: np.ndarray,
        program: np.ndarray,
    ) -> int:
        t = 0
        for i in range(rows.shape[0]):
            tick_compiled(regs, outputs, counters, int(rows[i, L.MASK]), pulses, program)
            t += outputs[0]
        return t

    return dict(locals())


def baseline_sources(ref: str) -> str:
    """REF's src/ exported (git archive) into a folder named after its commit, kept in the temporary folder so
    that its compiled code (numba caches by source path) serves the next run: the tree the baseline imports."""
    commit = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--verify", f"{ref}^{{commit}}"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    folder = Path(tempfile.gettempdir()) / f"tablebot-kernel-baseline-{commit[:12]}"
    if not (folder / "src").is_dir():
        partial = Path(tempfile.mkdtemp(prefix=folder.name + "."))
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", commit, "src"], check=True, capture_output=True)
        subprocess.run(["tar", "-x", "-C", str(partial)], input=archive.stdout, check=True)
        partial.rename(folder)  # whole or not at all
    return str(folder / "src")


def child(example: str, repeats: int, src: str | None) -> dict[str, float]:
    """:func:`measure` in a fresh process importing tablebot from ``src`` (this tree's when None)."""
    env = dict(os.environ, PYTHONPATH=src or str(ROOT / "src"))
    env.pop("NUMBA_CACHE_DIR", None)  # each tree its own cache (tablebot.jit names it after the sources)
    done = subprocess.run(
        [sys.executable, __file__, "--json", "--example", example, "--repeats", str(repeats)],
        env=env,
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(done.stdout.splitlines()[-1])


def report(now: dict[str, list[float]], base: dict[str, list[float]] | None) -> None:
    whole = statistics.median(now[WHOLE])
    print(
        f"{'ns per robot-tick (one core)':<30} {'this tree':>10}"
        + (f" {'baseline':>10} {'ratio':>7}" if base else f" {'of a tick':>10}")
    )
    for part, values in now.items():
        mine = statistics.median(values)
        if base:
            theirs = statistics.median(base[part]) if part in base else math.nan
            print(f"{part:<30} {mine:10.1f} {theirs:10.1f} {mine / theirs:7.2f}")
        else:
            print(f"{part:<30} {mine:10.1f} {mine / whole:10.0%}")
    print(
        f"whole kernel: {1e3 / whole:.2f} M robot-ticks/s per core"
        + (
            f" (baseline {1e3 / statistics.median(base[WHOLE]):.2f}; x{statistics.median(base[WHOLE]) / whole:.2f})"
            if base
            else ""
        )
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--example", default="bumberbot")
    parser.add_argument("--baseline", help="a git revision to compare with (e.g. main)")
    parser.add_argument("--rounds", type=int, default=3, help="fresh processes per tree, alternating")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--json", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.json:
        print(json.dumps(measure(args.example, args.repeats)))
        return
    print(
        f"load average {os.getloadavg()[0]:.1f} {os.getloadavg()[1]:.1f} {os.getloadavg()[2]:.1f} "
        f"on {os.cpu_count()} cores; example {args.example}"
    )
    now: dict[str, list[float]] = {}
    base: dict[str, list[float]] = {}
    src = baseline_sources(args.baseline) if args.baseline else None
    for _ in range(args.rounds):
        if src:
            for part, value in child(args.example, args.repeats, src).items():
                base.setdefault(part, []).append(value)
        for part, value in child(args.example, args.repeats, None).items():
            now.setdefault(part, []).append(value)
    report(now, base or None)


if __name__ == "__main__":
    main()
