"""Benchmark: the largest inputs tablebot accepts (issue 33 §4), and how fast it refuses the ones just past them.

Run: ``.venv/bin/python benchmarks/limits.py [--repeat 3] [--dense]``.

Every figure is a whole fresh process (``python -m tablebot``, as a user runs it): wall seconds (median of the
repeats) and peak resident memory (the largest of the repeats, from its rusage, started by a launcher that
imports nothing: see LAUNCHER), each beside its
ratio to the BumberBot example run the same way in the same run (the baseline). The inputs are made in a
temporary folder at the limits (tablebot.formats.table_read, tablebot.csvtext, tablebot.formats.inputs_csv):

* **longest table**: 100,000 rows (the most lines below a header) in 1,000 states (the most), the BumberBot's
  columns, descriptions padded so that the file is just under 16 MB (the most);
* **widest table**: 63 event columns (the most: a robot of 62 inputs, and T; ``sim`` takes 10, so it runs on
  a table of 10) and blank columns up to 1,000 cells a line (the most), 1,000 states, as many rows as fit in
  16 MB;
* **longest cells**: descriptions of 4,000 characters (the most), as many rows as fit in 16 MB;
* **longest inputs**: 1,000,000 ticks (the most) of the BumberBot's inputs as CSV for ``trace --inputs``, and a
  run's trace (JSON Lines, as ``sim`` writes it) just under 64 MB (the most; about 540,000 ticks) replayed the same way;
* **refused**: the issue's 200,000-column header, the 100,001st line below a header, 1,000,001 ticks and a
  table file of 16 MB + 1 byte: each must end with exit 2.

``check`` and ``sim`` (60 simulated seconds, no pictures) run on each table, ``trace --inputs`` on each
recording (the trace to /dev/null). ``--dense`` adds the check of a table the analysis finds hardest at
these limits (100 rows in each of 1,000 states, each row needing a random half of 12 events: 50,000 findings);
it is slow (minutes) and large (GB) and has no target: the limits bound the input, not everything
an analysis can find in it. The load average is printed beside (the machine may be shared).

Targets: every accepted input within 60 s and 1 GiB; every refusal within 10 s and 200 MiB.
"""

from __future__ import annotations

import argparse
import os
import random
import resource
import statistics
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from tablebot.csvtext import MAX_COLUMNS, MAX_TEXT_BYTES
from tablebot.formats.inputs_csv import MAX_INPUT_TICKS
from tablebot.formats.table_read import MAX_EVENT_COLUMNS, MAX_STATES, MAX_TABLE_BYTES, MAX_TABLE_ROWS
from tablebot.machine import FLAT_BITS
from tablebot.robot import BUMBERBOT
from tablebot.testing.processes import child_env

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "bumberbot"
TABLEBOT = [sys.executable, "-m", "tablebot"]
EVENTS = ("T", *BUMBERBOT.inputs)
TARGET_S, TARGET_MIB = 60.0, 1024.0
REFUSE_S, REFUSE_MIB = 10.0, 200.0


@dataclass(frozen=True)
class Figure:
    wall: float
    mib: float


#: Starts one command and reports its wall seconds, peak resident KiB and exit code. A process started by this
#: one would count this one's memory too: on Linux a child's peak includes the pages it had before exec, the
#: parent's (which imported tablebot and numpy: 116 MiB); the launcher imports nothing of them.
LAUNCHER = """
import os, subprocess, sys, time
with open(os.devnull, "wb") as null, open(sys.argv[1], "wb") as err:
    start = time.perf_counter()
    proc = subprocess.Popen(sys.argv[2:], stdout=null, stderr=err)
    _, status, usage = os.wait4(proc.pid, 0)
    print(time.perf_counter() - start, usage.ru_maxrss, os.waitstatus_to_exitcode(status))
"""


def run(args: list[str], expect: tuple[int, ...]) -> Figure:
    """Wall seconds and peak resident MiB of one fresh process, started by :data:`LAUNCHER`; its exit code must
    be one of ``expect``."""
    with tempfile.NamedTemporaryFile() as err:
        done = subprocess.run(
            [sys.executable, "-c", LAUNCHER, err.name, *args],
            capture_output=True,
            text=True,
            check=True,
            cwd=ROOT,
            env=child_env(),
        )
        wall, kib, code = done.stdout.split()
        if int(code) not in expect:
            raise SystemExit(f"{' '.join(args)} ended with {code}, not {expect}:\n{Path(err.name).read_text()[-2000:]}")
    return Figure(float(wall), int(kib) / 1024)


def measured(args: list[str], repeat: int, expect: tuple[int, ...] = (0, 1)) -> Figure:
    """Median wall seconds and the largest peak of ``repeat`` runs."""
    figures = [run(args, expect) for _ in range(repeat)]
    return Figure(statistics.median(f.wall for f in figures), max(f.mib for f in figures))


# --- the inputs ------------------------------------------------------------------------------------------------


def _rows(rng: random.Random, events: tuple[str, ...], states: int, count: int) -> list[list[str]]:
    """``count`` rows (state, event cells, M1, M2, timer, next) spread evenly over ``states`` states, each row
    needing one or two events of five its state looks at (check explores at most 16 per state); every state has
    rows, so every next state exists."""
    rows = []
    for k in range(count):
        state = k * states // count + 1
        window = [events[(state * 5 + j) % len(events)] for j in range(min(5, len(events)))]
        needed = set(rng.sample(window, rng.choice((1, 1, 2))))
        rows.append(
            [
                str(state),
                *("1" if e in needed else "" for e in events),
                rng.choice(("3", "-3", "0", "=")),
                rng.choice(("3", "-3", "0", "=")),
                str(rng.randint(0, 300)),
                str(rng.randint(1, states)),
            ]
        )
    return rows


def _fill(lines: list[str], header: str, limit: int) -> str:
    """The table text; each description padded with the same number of x's so the file is just under ``limit``."""
    lines = [f"row {k} {line}" for k, line in enumerate(lines)]
    bare = len(header) + 1 + sum(len(line) + 1 for line in lines)
    pad = "x" * ((limit - 1024 - bare) // len(lines))
    text = "\n".join([header, *(line.replace(" ", " " + pad, 1) for line in lines)]) + "\n"
    assert len(text.encode()) < limit, len(text)
    return text


def longest_table(folder: Path, rng: random.Random) -> Path:
    rows = _rows(rng, EVENTS, MAX_STATES, MAX_TABLE_ROWS)
    header = "description,state," + ",".join(EVENTS) + ",M1,M2,timer,next"
    path = folder / "longest" / "table.csv"
    path.parent.mkdir()
    path.write_text(_fill(["," + ",".join(r) for r in rows], header, MAX_TABLE_BYTES))
    return path


def widest_table(folder: Path, rng: random.Random, events_count: int = MAX_EVENT_COLUMNS) -> Path:
    inputs = [f"I{i}" for i in range(events_count - 1)]
    events = ("T", *inputs)
    header = "description,state," + ",".join(events) + ",M1,M2,timer,next"
    blank = "," * (MAX_COLUMNS - header.count(",") - 1)  # blank header cells (ignored columns) up to the limit
    fit = (MAX_TABLE_BYTES - 2048) // (len(blank) + len(events) + 24)  # a row: a comma a cell, a few more
    lines = [header + blank, *(f"w,{','.join(cells)}{blank}" for cells in _rows(rng, events, MAX_STATES, fit))]
    path = folder / f"widest-{events_count}" / "table.csv"
    path.parent.mkdir()
    robot = "".join(f'{name} = "input {name}"\n' for name in inputs)
    (path.parent / "robot.toml").write_text(
        f'name = "Wide"\ninitial_state = 1\n[inputs]\n{robot}[motors]\nM1 = "right"\nM2 = "left"\n'
    )
    text = "\n".join(lines) + "\n"
    assert len(text) < MAX_TABLE_BYTES, len(text)
    path.write_text(text)
    return path


def longest_cells(folder: Path, rng: random.Random) -> Path:
    from tablebot.csvtext import MAX_CELL_CHARS

    count = MAX_TABLE_BYTES // (MAX_CELL_CHARS + 40)
    rows = _rows(rng, EVENTS, min(MAX_STATES, count), count)
    header = "description,state," + ",".join(EVENTS) + ",M1,M2,timer,next"
    path = folder / "cells" / "table.csv"
    path.parent.mkdir()
    path.write_text("\n".join([header, *(f"{'x' * MAX_CELL_CHARS},{','.join(r)}" for r in rows)]) + "\n")
    return path


def inputs_csv(folder: Path, rng: random.Random, ticks: int = MAX_INPUT_TICKS) -> Path:
    names = BUMBERBOT.inputs
    choices = [",".join("1" if rng.random() < 0.1 else "" for _ in names) for _ in range(1024)]
    path = folder / f"inputs-{ticks}.csv"
    path.write_text(",".join(names) + "\n" + "".join(choices[rng.randrange(1024)] + "\n" for _ in range(ticks)))
    return path


def trace_jsonl(folder: Path, rng: random.Random) -> Path:
    """A run's trace as ``tablebot sim`` writes it (pose fields and all), just under the 64 MB limit."""
    path = folder / "run.jsonl"
    size, tick = 0, 0
    with path.open("w") as stream:
        while True:
            line = (
                f'{{"tick":{tick},"event":{rng.randrange(64)},"row":{rng.randrange(37)},"state":2,"timer":0,'
                f'"M1":4,"M2":4,"x":{rng.random():.4f},"y":{rng.random():.4f},"heading":{rng.random():.4f},'
                f'"battery":8.91}}\n'
            )
            if size + len(line) > MAX_TEXT_BYTES - 1024:
                return path
            stream.write(line)
            size, tick = size + len(line), tick + 1


def dense_table(folder: Path, rng: random.Random) -> Path:
    inputs = [f"I{i}" for i in range(11)]
    header = "state,T," + ",".join(inputs) + ",M1,M2,timer,next"
    lines = [header]
    for k in range(MAX_TABLE_ROWS):
        state = k * MAX_STATES // MAX_TABLE_ROWS + 1
        needs = ",".join("1" if rng.random() < 0.5 else "" for _ in range(12))
        lines.append(f"{state},{needs},3,3,{rng.randint(0, 300)},{rng.randint(1, MAX_STATES)}")
    path = folder / "dense" / "table.csv"
    path.parent.mkdir()
    (path.parent / "robot.toml").write_text(
        'name = "Dense"\ninitial_state = 1\n[inputs]\n'
        + "".join(f'{n} = "{n}"\n' for n in inputs)
        + '[motors]\nM1 = "right"\nM2 = "left"\n'
    )
    path.write_text("\n".join(lines) + "\n")
    return path


# --- the runs --------------------------------------------------------------------------------------------------


def check(table: Path) -> list[str]:
    return [*TABLEBOT, "check", str(table)]


def sim(table: Path, out: Path) -> list[str]:
    return [*TABLEBOT, "sim", str(table), "--seconds", "60", "--no-plots", "-q", "--out", str(out)]


def trace(table: Path, inputs: Path) -> list[str]:
    return [*TABLEBOT, "trace", str(table), "--inputs", str(inputs)]


def row(label: str, figure: Figure, base: Figure | None, targets: tuple[float, float]) -> bool:
    ok = figure.wall < targets[0] and figure.mib < targets[1]
    ratio = f"{figure.wall / base.wall:6.1f}x {figure.mib / base.mib:6.1f}x" if base else " " * 15
    print(f"  {label:<46}{figure.wall:8.2f} s{figure.mib:8.0f} MiB  {ratio}  {'ok' if ok else 'MISSED'}")
    return ok


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--dense", action="store_true", help="also check the table hardest for the analysis")
    args = parser.parse_args()
    rng = random.Random(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        longest, cells = longest_table(folder, rng), longest_cells(folder, rng)
        tables = {
            "check": {
                "longest table (100,000 rows, 16 MB)": longest,
                "widest table (1,000 cells, 63 events)": widest_table(folder, rng),
                "longest cells (4,000 characters)": cells,
            },
            "sim": {
                "longest table (100,000 rows, 16 MB)": longest,
                "widest it takes (1,000 cells, 10 events)": widest_table(folder, rng, FLAT_BITS),
                "longest cells (4,000 characters)": cells,
            },
        }
        recordings = {
            "1,000,000 ticks of inputs (CSV)": inputs_csv(folder, rng),
            "a 64 MB trace replayed (JSON Lines)": trace_jsonl(folder, rng),
        }
        subprocess.run(sim(EXAMPLE, folder / "warm"), check=True, env=child_env(), capture_output=True)  # numba cache
        print(
            f"fresh processes, median of {args.repeat} (memory: the largest peak), load average "
            f"{os.getloadavg()[0]:.2f}; ratios to the BumberBot example (time, memory)"
        )
        print(f"  {'':<46}{'wall':>10}{'peak':>12}  {'ratios':>15}")
        ok = True
        for name, command in (("check", check), ("sim", lambda t: sim(t, folder / "out"))):
            base = measured(command(EXAMPLE), args.repeat)
            row(f"{name} BumberBot (baseline)", base, None, (TARGET_S, TARGET_MIB))
            for label, table in tables[name].items():
                ok = row(f"{name} {label}", measured(command(table), args.repeat), base, (TARGET_S, TARGET_MIB)) and ok
        base = measured(trace(EXAMPLE, EXAMPLE / "inputs.csv"), args.repeat)
        row("trace BumberBot's 3,000 ticks (baseline)", base, None, (TARGET_S, TARGET_MIB))
        for label, recording in recordings.items():
            ok = (
                row(f"trace {label}", measured(trace(EXAMPLE, recording), args.repeat), base, (TARGET_S, TARGET_MIB))
                and ok
            )
        ok = refusals(folder, rng, args.repeat) and ok
        if args.dense:
            print("  (no target)")
            row(
                "check dense (1,000 states x 100 rows, 12 events)",
                measured(check(dense_table(folder, rng)), 1),
                None,
                (float("inf"), float("inf")),
            )
    print(
        f"targets (accepted < {TARGET_S:g} s and {TARGET_MIB:g} MiB; refused < {REFUSE_S:g} s and "
        f"{REFUSE_MIB:g} MiB): {'met' if ok else 'MISSED'}"
    )
    return 0 if ok else 1


def refusals(folder: Path, rng: random.Random, repeat: int) -> bool:
    """Each input just past a limit (and the issue's 200,000 columns) must be refused: exit 2."""
    wide = folder / "wide.csv"
    wide.write_text(",".join(f"c{i}" for i in range(200_000)) + "\n" + "1," * 199_999 + "1\n")
    rows = folder / "rows" / "table.csv"
    rows.parent.mkdir()
    lines = ["description,state,T,I3,M1,M2,timer,next", *("r,1,1,,3,3,0,1" for _ in range(MAX_TABLE_ROWS + 1))]
    rows.write_text("\n".join(lines) + "\n")
    big = folder / "big" / "table.csv"
    big.parent.mkdir()
    with big.open("wb") as stream:
        stream.truncate(MAX_TABLE_BYTES + 1)
    ticks = inputs_csv(folder, rng, MAX_INPUT_TICKS + 1)
    ok = True
    print("refused (exit 2):")
    for label, args in (
        ("check: 200,000 header columns", check(wide)),
        ("check: 100,001 lines below the header", check(rows)),
        ("check: a table file of 16 MB + 1 byte", check(big)),
        ("trace: 1,000,001 ticks of inputs", trace(EXAMPLE, ticks)),
    ):
        ok = row(label, measured(args, repeat, expect=(2,)), None, (REFUSE_S, REFUSE_MIB)) and ok
    return ok


if __name__ == "__main__":
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    sys.exit(main())
