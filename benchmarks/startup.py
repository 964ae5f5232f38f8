"""Benchmark: where a fresh tablebot process spends its time before (and around) the work the user asked for.

Run: ``.venv/bin/python benchmarks/startup.py [--repeat 5] [--quick] [--help-only]``.

Two parts, both fresh processes (``python -m tablebot``, as a user runs it):

* **commands**: wall and CPU seconds (user + system, the process and its children) of ``python -c pass``
  (the interpreter alone), ``tablebot --version``, ``tablebot check examples/bumberbot``,
  ``tablebot sim examples/bumberbot --seconds 3600`` with and without pictures and ``tablebot sweep
  examples/bumberbot --robots 10000 --seconds 10 --no-plots``; for sim and sweep beside the time of the run
  inside (what the command itself reports: the simulated speed, "runs in N s"), so start-up and the rest
  around the run read as the difference. Which of numba, scipy, matplotlib, pydantic each command imports.
* **help**: ``tablebot --help`` and ``tablebot --lang de --help`` (the German catalog loaded, every help text
  translated), each against its target, 0.15 s, and as a ratio to the interpreter alone (``--help-only``: these
  rows alone, run in turn with ``python -c pass`` and ``python -c "import typer"`` -- what any typer program's
  help costs -- and the ratios taken round by round).
* **phases**: one fresh process doing a sweep's start-up step by step, each step timed: the imports (tablebot,
  its command line, numpy, numba), planning 10,000 runs (it loads the compiled code the scene
  checks use, and starts numba's runtime), and a one-robot fleet's first tick (loads the fleet kernel).

CPU seconds move less than wall seconds on a shared machine (2 cores, other engineers' runs): both are
printed, with the load average. Bytecode files are written as a user's would be (PYTHONDONTWRITEBYTECODE
is taken out of the children's environment: with it set, every edited module is compiled again in every run).
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from tablebot.testing.processes import child_env

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "bumberbot"
HEAVY = ("numba", "scipy", "matplotlib", "pydantic", "dask")


def timed(argv: list[str]) -> tuple[float, float, str]:
    """Wall and CPU seconds of a fresh process (it must succeed), and what it printed."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    done = subprocess.run(argv, cwd=ROOT, env=child_env(), capture_output=True, text=True)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode not in (0, 1):  # check exits 1 when it warns
        raise SystemExit(f"{' '.join(argv)} failed ({done.returncode}):\n{done.stderr[-2000:]}")
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    return wall, cpu, done.stdout + done.stderr


def inner_seconds(name: str, output: str) -> float | None:
    """The run's own time as the command reports it: sweep's "runs in N s", sim's "N× faster than real time"."""
    if name.startswith("sweep") and (m := re.search(r"runs in ([\d.]+) s", output)):
        return float(m.group(1))
    if name.startswith("sim") and (m := re.search(r"simulated ([\d,.]+)× faster", output)):
        return SIM_SECONDS / float(m.group(1).replace(",", ""))
    return None


# The command line run in a child that prints, on exit, the top-level packages it imported.
MODULES = """
import atexit, sys
atexit.register(lambda: print('PACKAGES', *sorted({m.split('.')[0] for m in list(sys.modules)})))
sys.argv = ['tablebot', *sys.argv[1:]]
from tablebot.cli import main
main()
"""


def imported(args: list[str]) -> list[str]:
    """Which of :data:`HEAVY` the command imports."""
    with tempfile.TemporaryDirectory() as out:
        argv = [sys.executable, "-c", MODULES, *[a.replace("OUT", out) for a in args]]
        done = subprocess.run(argv, cwd=ROOT, env=child_env(), capture_output=True, text=True)
    found = next((line.split()[1:] for line in done.stdout.splitlines() if line.startswith("PACKAGES")), [])
    return [name for name in HEAVY if name in found]


SIM_SECONDS = 3600.0
#: `tablebot --help` as a whole process, in either language (issue 38 §3).
HELP_TARGET = 0.15


def commands(quick: bool) -> list[tuple[str, list[str]]]:
    hour = "60" if quick else f"{SIM_SECONDS:g}"
    robots = "1000" if quick else "10000"
    return [
        ("python -c pass", []),
        ("--version", ["--version"]),
        ("--help", ["--help"]),
        ("--help (de)", ["--lang", "de", "--help"]),  # the German catalog loaded and every help text translated
        ("check", ["check", str(EXAMPLE)]),
        ("sim --no-plots", ["sim", str(EXAMPLE), "--seconds", hour, "--no-plots", "--out", "OUT"]),
        ("sim (pictures)", ["sim", str(EXAMPLE), "--seconds", hour, "--out", "OUT"]),
        (
            "sweep --no-plots",
            ["sweep", str(EXAMPLE), "--robots", robots, "--seconds", "10", "--no-plots", "--out", "OUT/sweep"],
        ),
    ]


PHASES = r"""
import sys, time
t = [time.perf_counter()]
def lap(name):
    now = time.perf_counter(); print(f"{name}\t{now - t[0]:.4f}"); t[0] = now
import tablebot; lap("import tablebot (every back-end registers)")
import tablebot.cli; lap("import tablebot.cli (typer, rich, every command)")
import numpy; lap("import numpy")
import tablebot.jit; lap("import numba (tablebot.jit)")
from tablebot.fleet.plan import make_plan; lap("import the fleet (plan, run, kernel modules)")
from pathlib import Path
plan = make_plan(Path(sys.argv[1]), None, [], [], None, 10000, 10.0)
lap("plan 10,000 runs (scene checks: first compiled code, numba's runtime)")
from tablebot.fleet.run import Fleet, RobotSpec
from tablebot.sim.model.scene import robot_layer
layer = robot_layer(plan.table.robot)[0]
fleet = Fleet(plan.table, plan.machine, plan.scenes[0].world, [RobotSpec(seed=0)], layer)
lap("place one robot (loads sense, observe)")
fleet.run(1); lap("its first tick (loads the fleet kernel)")
"""


def phases() -> list[tuple[str, float]]:
    done = subprocess.run(
        [sys.executable, "-c", PHASES, str(EXAMPLE)], cwd=ROOT, env=child_env(), capture_output=True, text=True
    )
    if done.returncode:
        raise SystemExit(f"the phases script failed:\n{done.stderr[-2000:]}")
    return [(name, float(sec)) for name, sec in (line.split("\t") for line in done.stdout.splitlines() if "\t" in line)]


def warm_up() -> None:
    """The compiled code into this machine's cache (not counted)."""
    with tempfile.TemporaryDirectory() as warm:
        timed(
            [
                sys.executable,
                "-m",
                "tablebot",
                "sweep",
                str(EXAMPLE),
                "--robots",
                "64",
                "--seconds",
                "1",
                "--no-plots",
                "--out",
                warm + "/s",
            ]
        )
        timed([sys.executable, "-m", "tablebot", "sim", str(EXAMPLE), "--seconds", "1", "--out", warm + "/t"])


#: ``--help-only``'s rows, run in turn (one of each per round, so that a ratio compares runs made side by side):
#: the interpreter alone, the interpreter with typer (what any typer help costs), and tablebot's help.
HELP_ROWS = (
    ("python -c pass", ["-c", "pass"]),
    ("import typer", ["-c", "import typer"]),
    ("--help", ["-m", "tablebot", "--help"]),
    ("--help (de)", ["-m", "tablebot", "--lang", "de", "--help"]),
)


def help_only(repeat: int) -> int:
    """--help in both languages beside the interpreter and typer, round by round; ratios pair by pair."""
    runs: dict[str, list[tuple[float, float]]] = {name: [] for name, _ in HELP_ROWS}
    for _ in range(repeat + 1):  # the first round warms the file cache and is not counted
        for name, argv in HELP_ROWS:
            wall, cpu, _out = timed([sys.executable, *argv])
            runs[name].append((wall, cpu))
    runs = {name: rows[1:] for name, rows in runs.items()}
    med = statistics.median
    print(f"{'command':<16} {'wall s':>7} {'cpu s':>7} {'wall/interpreter':>17} {'cpu/import typer':>17}")
    for name, rows in runs.items():
        walls = [w / p[0] for (w, _c), p in zip(rows, runs["python -c pass"], strict=True)]
        cpus = [c / t[1] for (_w, c), t in zip(rows, runs["import typer"], strict=True)]
        print(
            f"{name:<16} {med(w for w, _ in rows):7.3f} {med(c for _, c in rows):7.3f} {med(walls):16.1f}x "
            f"{med(cpus):16.2f}x"
        )
    for name in ("--help", "--help (de)"):
        wall = med(w for w, _ in runs[name])
        print(f"{name}: {wall:.3f} s wall, target under {HELP_TARGET} s ({'met' if wall < HELP_TARGET else 'NOT met'})")
    load, cores = os.getloadavg()[0], os.cpu_count() or 1
    print(
        f"load average {load:.2f} at the end"
        + (
            f": above {cores}, a process's wall time includes waiting for a "
            "core; its cpu seconds, and the ratios, move less"
            if load > cores
            else ""
        )
    )
    return 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="shorter sim and sweep (a smoke test of this script)")
    parser.add_argument("--help-only", action="store_true", help="only the interpreter and --help in both languages")
    args = parser.parse_args()
    med = statistics.median
    print(
        f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the start (shared machine); medians of "
        f"{args.repeat} fresh processes"
    )
    if args.help_only:
        return help_only(args.repeat)
    warm_up()

    print(f"{'command':<18} {'wall s':>7} {'cpu s':>7} {'run s':>7} {'around':>7}  imports")
    floor = None
    help_walls: dict[str, list[float]] = {}
    for name, cmd in commands(args.quick):
        runs = []
        for _ in range(args.repeat):
            with tempfile.TemporaryDirectory() as out:
                argv = (
                    [sys.executable, "-c", "pass"]
                    if not cmd
                    else [sys.executable, "-m", "tablebot", *[a.replace("OUT", out) for a in cmd]]
                )
                runs.append(timed(argv))
        wall, cpu = med(r[0] for r in runs), med(r[1] for r in runs)
        if name.startswith("--help"):
            help_walls[name] = [r[0] for r in runs]
        inner = [s for r in runs if (s := inner_seconds(name, r[2])) is not None]
        run = med(inner) if inner else None
        floor = floor if floor is not None else wall
        around = f"{wall - run:7.2f}" if run is not None else f"{'':7}"
        heavy = ", ".join(imported(cmd)) if cmd else ""
        shown = f"{run:7.2f}" if run is not None else f"{'':7}"
        print(f"{name:<18} {wall:7.2f} {cpu:7.2f} {shown} {around}  {heavy or '-'}")
    print(
        f"(run s: the run as the command reports it; around = wall - run: start-up, planning, files. The "
        f"interpreter alone is {floor:.3f} s.)"
    )
    assert floor is not None  # python -c pass is the first row
    helps = {name: med(w) for name, w in help_walls.items()}
    for name, wall in helps.items():
        print(
            f"{name}: {wall:.3f} s, {wall / floor:.1f}x the interpreter alone; target under {HELP_TARGET} s "
            f"({'met' if wall < HELP_TARGET else 'NOT met'})"
        )

    print("\nphases of a fresh process (a sweep's start-up, step by step; medians, ms):")
    laps = [phases() for _ in range(args.repeat)]
    names = [name for name, _ in laps[0]]
    total = 0.0
    for i, name in enumerate(names):
        ms = 1000 * med(lap[i][1] for lap in laps)
        total += ms
        print(f"  {ms:7.1f}  {name}")
    print(f"  {total:7.1f}  in all (after the interpreter's own start)")
    print(f"load average {os.getloadavg()[0]:.2f} at the end")
    return 0


if __name__ == "__main__":
    sys.exit(main())
