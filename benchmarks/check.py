"""How long `tablebot check` takes: the BumberBot with its shipped properties (target < 1 s), a
random 50-state, 500-row table with four properties (target < 10 s), and how the findings of a
table scale: `tablebot check` run as a whole process on tables of 1,000, 10,000 and 100,000 rows
(100 rows per state; 1,000 states at 100,000 rows; target < 10 s), with the growth reported as the
slope of log(time) over log(rows) (1 = linear). Robots of several tables (issue 36): the state space (situations
of the product) and proof time of examples/bumberbot-lights (2 tables, 11 properties) and of a 3-table robot (it
and a beacon table reading both), and the BumberBot's own check timed on this checkout and on the code before
several tables existed (``--baseline REV``, unpacked with git archive), alternating, as a ratio. Prints medians.

    .venv/bin/python benchmarks/check.py [--repeat N] [--seed S] [--no-scaling] [--tables-only] [--baseline REV]
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import math
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.analysis.check import run_check
from tablebot.analysis.conditions import parse_condition
from tablebot.analysis.properties import Property, load_properties
from tablebot.formats.table_read import load_table
from tablebot.machine import Machine, compile_table
from tablebot.robot import BUMBERBOT
from tablebot.table import Row, Table

if TYPE_CHECKING:
    from collections.abc import Callable

    from tablebot.analysis.conditions import Condition

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "bumberbot"
EVENTS = ("T", *BUMBERBOT.inputs)


def random_table(seed: int, states: int = 50, rows_per_state: int = 10) -> Table:
    """Rows need one or two events (T often among them), set random speeds (sometimes keep),
    load timers up to 3 s and go anywhere; every state has rows, so every next state exists."""
    rng = random.Random(seed)
    rows: list[Row] = []
    for state in range(1, states + 1):
        for _ in range(rows_per_state):
            events = frozenset(rng.sample(EVENTS, rng.choice((1, 1, 2))))
            motors = tuple(None if rng.random() < 0.1 else rng.randint(-6, 6) for _ in BUMBERBOT.motors)
            rows.append(
                Row(
                    len(rows),
                    len(rows) + 2,
                    f"row {len(rows)}",
                    state,
                    events,
                    motors,
                    rng.randint(0, 300),
                    rng.randint(1, states),
                )
            )
    robot = dataclasses.replace(BUMBERBOT, initial_state=1, name="Random")
    return Table(robot, EVENTS, tuple(rows), f"<random seed {seed}>")


def random_properties(machine: Machine) -> list[Property]:
    def cond(text: str) -> Condition:
        return parse_condition(text, machine)

    return [
        Property("home", "can always get back to state 1", "always_reachable", cond=cond("state == 1")),
        Property("calm", "never forward in state 7", "never", cond=cond("state == 7 and M1 > 0 and M2 > 0")),
        Property(
            "stop",
            "front bump stops within 10 ticks",
            "when",
            when=cond("I3"),
            then=cond("M1 <= 0 and M2 <= 0"),
            within=10,
        ),
        Property("reach", "state 42 can happen", "reachable", cond=cond("state == 42")),
    ]


def timed(label: str, run: Callable[[], str], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        summary = run()
        times.append(time.perf_counter() - start)
    median = statistics.median(times)
    print(
        f"{label:<44} median {median * 1000:8.1f} ms  (min {min(times) * 1000:.1f}, max {max(times) * 1000:.1f}, "
        f"n={repeat})  {summary}"
    )
    return median


def check_once(machine: Machine, props: list[Property]) -> str:
    report = run_check(machine, props)
    status = " ".join(f"{r.prop.name}={r.status}" for r in report.results)
    return f"[{report.situations} situations; {status}]"


SCALE_ROWS = (1_000, 10_000, 100_000)
ROWS_PER_STATE = 100
SCALE_TARGET = 10.0


def scale_csv(rows: int, seed: int) -> str:
    """A BumberBot table of ``rows`` rows, 100 per state: each row needs one or two events, sets
    speeds from a few values (or keeps them), loads a timer and goes to any state."""
    rng = random.Random(seed)
    lines = ["description,state," + ",".join(EVENTS) + ",M1,M2,timer,next"]
    states = rows // ROWS_PER_STATE
    for state in range(1, states + 1):
        for k in range(ROWS_PER_STATE):
            events = set(rng.sample(EVENTS, rng.choice((1, 1, 2))))
            motors = [rng.choice(("3", "-3", "0", "=", "5")) for _ in range(2)]
            cells = ["1" if e in events else "" for e in EVENTS]
            lines.append(
                f"row {state}.{k},{state},{','.join(cells)},{motors[0]},{motors[1]},"
                f"{rng.randint(0, 300)},{rng.randint(1, states)}"
            )
    return "\n".join(lines) + "\n"


def check_process(path: Path) -> float:
    """Seconds of one `tablebot check TABLE` process (start-up, loading, findings, printing to a pipe)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")}
    start = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "tablebot.cli", "check", str(path)], capture_output=True, env=env, check=False
    )
    elapsed = time.perf_counter() - start
    if done.returncode not in (0, 1):
        raise SystemExit(f"tablebot check failed on {path}:\n{done.stderr.decode()}")
    return elapsed


def scaling(seed: int, repeat: int) -> bool:
    """Time check on each size; print medians and the log-log slope between sizes and overall."""
    medians = []
    with tempfile.TemporaryDirectory() as folder:
        for rows in SCALE_ROWS:
            path = Path(folder) / f"t{rows}.csv"
            path.write_text(scale_csv(rows, seed), encoding="utf-8")
            times = [check_process(path) for _ in range(repeat)]
            medians.append(statistics.median(times))
            print(
                f"check, {rows:>7,} rows, {rows // ROWS_PER_STATE:>5,} states (whole process)  median "
                f"{medians[-1]:7.2f} s  (min {min(times):.2f}, max {max(times):.2f}, n={repeat})"
            )
    logs = [(math.log(r), math.log(t)) for r, t in zip(SCALE_ROWS, medians, strict=True)]
    steps = [(b[1] - a[1]) / (b[0] - a[0]) for a, b in itertools.pairwise(logs)]
    overall = (logs[-1][1] - logs[0][1]) / (logs[-1][0] - logs[0][0])
    print(
        f"growth: slope {' then '.join(f'{s:.2f}' for s in steps)} (overall {overall:.2f}; 1 = linear, "
        f"2 = quadratic); 100k/10k time ratio {medians[-1] / medians[-2]:.1f}x for 10x the rows"
    )
    print(f"target (100,000 rows < {SCALE_TARGET:g} s): {'met' if medians[-1] < SCALE_TARGET else 'MISSED'}")
    return medians[-1] < SCALE_TARGET


# --- several tables (issue 36) ---------------------------------------------------------------------------------

LIGHTS = ROOT / "examples" / "bumberbot-lights"
#: The commit before the multi-table model: the BumberBot's check there is the baseline of the ratio.
BASELINE = "2b6391f^"
BEACON = """description,state,T,drive=20..29,"lights=blink_on,blink_off",L3,timer,next
Collision: beacon on,off,,1,,8,0,on
Heartbeat,off,1,,,0,100,off
Lamps blink: keep on,on,,1,1,8,0,on
Collision over: off,on,,,,0,100,off
"""
BEACON_PROPERTY = """
[beacon_in_collisions]
text = "the beacon is on from the tick after a collision starts until it is over"
when = "drive == 20"
then = "L3 == 8"
within = "1 tick"

[beacon_with_the_blinking]
text = "the beacon never burns while the lamps flash as if seeking, once the drive is seeking again"
never = "beacon == on and lights in [flash_left, flash_right] and drive in [1, 2] and L3 == 8 and M1 == 0"
"""


def three_tables(folder: Path) -> Path:
    """examples/bumberbot-lights with a third table, a beacon lamp L3 that reads both other tables' states."""
    for name in ("table.csv", "lights.csv", "properties.toml", "robot.toml"):
        (folder / name).write_text((LIGHTS / name).read_text(encoding="utf-8"), encoding="utf-8")
    robot = (folder / "robot.toml").read_text(encoding="utf-8")
    robot = robot.replace('L2 = "right lamp"\n', 'L2 = "right lamp"\nL3 = "beacon"\n', 1)
    robot = robot.replace(
        'initial_state = "flash_left", initial_timer = 0 }\n',
        'initial_state = "flash_left", initial_timer = 0 }\nbeacon = { file = "beacon.csv", initial_state = "off" }\n',
        1,
    )
    robot = robot.replace('L2 = "O6"\n', 'L2 = "O6"\nL3 = "O7"\n')
    (folder / "robot.toml").write_text(robot, encoding="utf-8")
    (folder / "beacon.csv").write_text(BEACON, encoding="utf-8")
    with (folder / "properties.toml").open("a", encoding="utf-8") as stream:
        stream.write(BEACON_PROPERTY)
    return folder


def check_robot(folder: Path) -> str:
    """``tablebot check FOLDER``'s work (loading included) as the front door does it: the product's situations."""
    from tablebot.loading import Loaded

    report = Loaded.open(folder).check_report()
    explored = max(r.explored for r in report.results)
    failed = [r.prop.name for r in report.results if r.failed]
    return (
        f"[{report.situations} situations in the product, up to {explored} per proof; "
        f"{len(report.results)} properties, not holding: {', '.join(failed) or 'none'}]"
    )


BENCH_BUMBERBOT = """
import sys, time
from pathlib import Path
from tablebot.analysis.check import run_check
from tablebot.analysis.properties import load_properties
from tablebot.formats.table_read import load_table
from tablebot.machine import compile_table
example = Path(sys.argv[1])
start = time.perf_counter()
machine = compile_table(load_table(example / "table.csv"))
run_check(machine, load_properties(machine, [example / "properties.toml"]))
print(time.perf_counter() - start)
"""


def bumberbot_ratio(baseline: str, repeat: int) -> float | None:
    """The BumberBot's check (loading, findings, 6 proofs) in a fresh process on this checkout's code and on
    ``baseline``'s, alternating; the ratio of the medians (above 1: slower now). None without that revision."""
    with tempfile.TemporaryDirectory() as folder:
        old = Path(folder) / "old"
        old.mkdir()
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", baseline, "src"], capture_output=True)
        if archive.returncode:
            print(
                f"BumberBot ratio: no baseline ({baseline} is not in this checkout's history: "
                f"{archive.stderr.decode().strip()})"
            )
            return None
        subprocess.run(["tar", "-x", "-C", str(old)], input=archive.stdout, check=True)
        times: dict[str, list[float]] = {"baseline": [], "now": []}
        for _ in range(repeat):
            for label, src in (("baseline", old / "src"), ("now", ROOT / "src")):
                env = {**os.environ, "PYTHONPATH": str(src)}
                done = subprocess.run(
                    [sys.executable, "-c", BENCH_BUMBERBOT, str(EXAMPLE)],
                    env=env,
                    capture_output=True,
                    text=True,
                    check=True,
                )
                times[label].append(float(done.stdout.strip().splitlines()[-1]))
    medians = {label: statistics.median(values) for label, values in times.items()}
    ratio = medians["now"] / medians["baseline"]
    print(
        f"BumberBot check in-process, baseline {baseline}: median {medians['baseline'] * 1000:.1f} ms, now "
        f"{medians['now'] * 1000:.1f} ms; ratio now/baseline {ratio:.2f} (n={repeat} each, alternating)"
    )
    return ratio


def several_tables(repeat: int, baseline: str) -> bool:
    two = timed("BumberBot with lights, 2 tables, 11 props", lambda: check_robot(LIGHTS), repeat)
    with tempfile.TemporaryDirectory() as folder:
        three = timed("3 tables (+ beacon), 13 properties", lambda: check_robot(three_tables(Path(folder))), repeat)
    ratio = bumberbot_ratio(baseline, repeat)
    ok = two < 10.0 and three < 30.0 and (ratio is None or ratio < 1.10)
    print(
        f"targets (2 tables < 10 s, 3 tables < 30 s, BumberBot not slower: ratio < 1.10): {'met' if ok else 'MISSED'}"
    )
    return ok


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--no-scaling", action="store_true", help="skip the 1k/10k/100k-row process timings")
    parser.add_argument("--tables-only", action="store_true", help="only the robots of several tables (issue 36)")
    parser.add_argument("--baseline", default=BASELINE, help="the revision the BumberBot's check is compared with")
    args = parser.parse_args()
    if args.tables_only:
        return 0 if several_tables(args.repeat, args.baseline) else 1

    def bumberbot() -> str:  # loading included: this is what `tablebot check examples/bumberbot` does
        machine = compile_table(load_table(EXAMPLE / "table.csv"))
        return check_once(machine, load_properties(machine, [EXAMPLE / "properties.toml"]))

    def random_50() -> str:
        machine = compile_table(random_table(args.seed))
        return check_once(machine, random_properties(machine))

    small = timed("BumberBot, 37 rows, 6 properties", bumberbot, args.repeat)
    large = timed("random 50 states, 500 rows, 4 properties", random_50, max(3, args.repeat // 2))
    ok = small < 1.0 and large < 10.0
    print(f"targets (< 1 s, < 10 s): {'met' if ok else 'MISSED'}")
    ok = several_tables(args.repeat, args.baseline) and ok
    if not args.no_scaling:
        ok = scaling(args.seed, max(1, args.repeat // 2)) and ok
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
