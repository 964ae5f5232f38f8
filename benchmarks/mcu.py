"""Cycles per engine step and per tick interrupt on an ATmega328P at 16 MHz, and flash/RAM use, for the
BumberBot firmware and a random 50-state, 500-row table (exact cycles from simavr).

    .venv/bin/python benchmarks/mcu.py [--ticks 3000] [--json results.json]

For each table: the Uno firmware runs recorded inputs under the emulation harness (BumberBot: its
recorded run; the random table: seeded random inputs) and its decoded trace must equal the Python
engine's, then per tick: the engine step (sampled inputs in, outputs decided) and the whole tick
interrupt (sampling, step, motor outputs, trace frame queued), min/median/max. A second firmware
times the step for every (state, event set) pair: the first-match worst case, exhaustively. Both
lookups are timed (dense: the default; scan: rows of the state in order, the document's rule).
Targets (issue 6): BumberBot step worst case <= 100 cycles, firmware < 4 KB flash and < 256 B RAM.
"""

from __future__ import annotations

import argparse
import json
import random
import sys
import tempfile
from pathlib import Path
from typing import Any

from tablebot.firmware.build import BENCH_MAIN, build
from tablebot.firmware.emulate import bench_steps, build_harness, emulate, summary
from tablebot.formats.inputs_csv import TickInput, load_inputs
from tablebot.formats.table_read import load_table
from tablebot.machine import Machine, compile_table
from tablebot.replay import replay
from tablebot.testing.random_tables import Shape, random_inputs, random_table

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "bumberbot"
STEP_TARGET, FLASH_TARGET, RAM_TARGET = 100, 4096, 256


def measure(machine: Machine, ticks: list[TickInput], work: Path, harness: Path) -> dict[str, Any]:
    firmware = build(machine, "uno", work / "fw")
    run = emulate(firmware, machine, ticks, work / "run", harness)
    if run.trace != list(replay(machine, ticks)) or run.problems:
        sys.exit(f"the firmware's trace differs from the Python engine's ({work}): no figures for a wrong firmware")
    result: dict[str, Any] = {
        "ticks": len(ticks),
        "flash": firmware.flash,
        "ram": firmware.ram,
        "lookup": "dense" if firmware.layout.dense else "scan",
        "lookup_bytes": firmware.layout.lookup_bytes,
        "step_run": summary([c.step for c in run.cycles]),
        "isr_run": summary([c.isr for c in run.cycles]),
    }
    for lookup in ("dense", "scan"):
        bench = build(machine, "uno", work / f"bench-{lookup}", lookup, BENCH_MAIN)
        steps = bench_steps(bench, work / f"bench-{lookup}" / "run", harness)
        result[f"step_all_{lookup}"] = {**summary(steps), "pairs": len(steps)}
    return result


def tables(n_ticks: int) -> dict[str, tuple[Machine, list[TickInput]]]:
    bumberbot = compile_table(load_table(EXAMPLE / "table.csv"))
    rng = random.Random(2009)
    big = random_table(rng, Shape(states=50, rows=500, inputs=5, motors=2, max_timer=200))
    big_machine = compile_table(big)
    return {
        "BumberBot": (bumberbot, load_inputs(EXAMPLE / "inputs.csv", bumberbot)[:n_ticks]),
        "random 50 states x 500 rows": (big_machine, random_inputs(rng, big, n_ticks, density=0.1)),
    }


def _mmm(stats: dict[str, float]) -> str:
    return f"{stats['min']:g} / {stats['median']:g} / {stats['max']:g}"


def report(results: dict[str, dict[str, Any]]) -> list[str]:
    names = list(results)
    rows = [
        ("ticks in the run", lambda r: str(r["ticks"])),
        ("engine step, run: min / median / max", lambda r: _mmm(r["step_run"])),
        ("engine step, every (state, events), dense", lambda r: _mmm(r["step_all_dense"])),
        ("engine step, every (state, events), scan", lambda r: _mmm(r["step_all_scan"])),
        ("tick interrupt, run: min / median / max", lambda r: _mmm(r["isr_run"])),
        ("flash / static RAM (bytes)", lambda r: f"{r['flash']} / {r['ram']}"),
        ("lookup used (bytes of flash)", lambda r: f"{r['lookup']} ({r['lookup_bytes']})"),
    ]
    width = max(len(label) for label, _ in rows) + 2
    lines = [
        "ATmega328P @ 16 MHz, Arduino Uno firmware, cycles counted exactly by simavr",
        "",
        " " * width + "".join(f"{n:>30}" for n in names),
    ]
    lines += [label.ljust(width) + "".join(f"{fmt(results[n]):>30}" for n in names) for label, fmt in rows]
    bb = results["BumberBot"]
    worst = max(bb["step_all_dense"]["max"], bb["step_run"]["max"])
    checks = [
        (f"BumberBot step worst case {worst:g} <= {STEP_TARGET} cycles", worst <= STEP_TARGET),
        (f"BumberBot flash {bb['flash']} < {FLASH_TARGET} bytes", bb["flash"] < FLASH_TARGET),
        (f"BumberBot static RAM {bb['ram']} < {RAM_TARGET} bytes", bb["ram"] < RAM_TARGET),
    ]
    lines += [
        "",
        *(f"{'PASS' if ok else 'FAIL'}  {text}" for text, ok in checks),
        "(the document's engine spent about 120 cycles on each bitwise AND of its ROBO Interface)",
    ]
    return lines


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ticks", type=int, default=3000, help="ticks of each run (BumberBot has 3000)")
    parser.add_argument("--json", type=Path, help="also write the figures as JSON")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="tablebot-mcu-") as tmp:
        work = Path(tmp)
        harness = build_harness(work / "harness")
        results = {
            name: measure(machine, ticks, work / str(i), harness)
            for i, (name, (machine, ticks)) in enumerate(tables(args.ticks).items())
        }
    lines = report(results)
    print("\n".join(lines))
    if args.json:
        args.json.write_text(json.dumps(results, indent=2), encoding="utf-8")
    return 0 if all(not line.startswith("FAIL") for line in lines) else 1


if __name__ == "__main__":
    sys.exit(main())
