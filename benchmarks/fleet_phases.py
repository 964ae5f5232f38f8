"""Where a ``tablebot sweep`` process spends its time: run by benchmarks/fleet.py as a fresh process.

    .venv/bin/python benchmarks/fleet_phases.py SWEEP-ARGS...

Runs ``tablebot SWEEP-ARGS`` in this process as ``python -m tablebot`` would, with the sweep's steps wrapped
to note when each starts and ends, and prints one JSON object: the seconds from the script's start to
planning (the imports), planning, the chunks (the compiled fleet, each chunk's set-up and, in the main thread
meanwhile, each chunk's result rows written: "results in the chunks"), merging results.csv, the rest, and
the whole; the interpreter's own start is what the caller's wall time adds. Beside each, as ``cpu: ...``, the
CPU seconds of every thread of the process in that phase (what a busy machine's waiting leaves out).
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

STARTED = time.perf_counter()
CPU_STARTED = time.process_time()  # every thread's CPU seconds: on a busy machine wall time is mostly waiting
ROOT = Path(__file__).resolve().parents[1]


def measure(args: list[str], env: dict[str, str] | None = None) -> dict[str, float]:
    """``tablebot ARGS`` (a sweep) by phase, run as this script in a fresh process (with ``env``: that
    environment, e.g. another tree's PYTHONPATH), the interpreter's own start and exit included (the caller's
    wall time less the script's)."""
    from tablebot.testing.processes import child_env  # not at the top: the script's own run imports tablebot timed

    started = time.perf_counter()
    done = subprocess.run(
        [sys.executable, __file__, *args], cwd=ROOT, env=env or child_env(), capture_output=True, text=True
    )
    wall = time.perf_counter() - started
    if done.returncode:
        raise SystemExit(f"benchmarks/fleet_phases.py failed:\n{done.stderr}")
    found: dict[str, float] = json.loads(done.stdout.strip().splitlines()[-1])
    found["interpreter start and exit"] = wall - found.pop("in this interpreter")
    found["wall"] = wall
    return found


def main() -> None:
    import tablebot.api.sweeping as sweeping
    import tablebot.fleet.backends as backends
    import tablebot.fleet.plan as plan
    from tablebot.cli import main as cli

    marks: dict[str, float] = {}
    cpu: dict[str, float] = {}  # the process's CPU seconds (every thread) at the same marks
    spent = {"part_text": 0.0, "write_part": 0.0}

    def timed(owner: Any, name: str, mark: str | None = None, into: str | None = None) -> None:
        original: Callable[..., Any] = getattr(owner, name)

        def wrapper(*args: Any, **kwargs: Any) -> Any:
            started = time.perf_counter()
            if mark:
                marks.setdefault(f"{mark} start", started - STARTED)
                cpu.setdefault(f"{mark} start", time.process_time() - CPU_STARTED)
            try:
                return original(*args, **kwargs)
            finally:
                if mark:
                    marks[f"{mark} end"] = time.perf_counter() - STARTED
                    cpu[f"{mark} end"] = time.process_time() - CPU_STARTED
                if into:
                    spent[into] += time.perf_counter() - started

        setattr(owner, name, wrapper)

    timed(plan, "make_plan", "plan")
    timed(backends.Runner, "run", "run")
    timed(sweeping, "_finish", "finish")
    timed(plan.Plan, "part_text", into="part_text")
    timed(store_module().Store, "write_part", into="write_part")
    sys.argv = ["tablebot", *sys.argv[1:]]
    try:
        cli()
    except SystemExit as exc:
        if exc.code:
            raise
    end, cpu_end = time.perf_counter() - STARTED, time.process_time() - CPU_STARTED
    plan_s, run_s = marks["plan end"] - marks["plan start"], marks["run end"] - marks["run start"]
    merge_s = marks["finish end"] - marks["finish start"]

    def cpu_of(mark: str) -> float:
        return cpu[f"{mark} end"] - cpu[f"{mark} start"]

    print(
        json.dumps(
            {
                "before planning": marks["plan start"],
                "planning": plan_s,
                "chunks": run_s,
                "results in the chunks": spent["part_text"] + spent["write_part"],
                "merging": merge_s,
                "after planning, besides": end - marks["plan start"] - plan_s - run_s - merge_s,
                "in this interpreter": end,
                "cpu: before planning": cpu["plan start"],
                "cpu: planning": cpu_of("plan"),
                "cpu: chunks": cpu_of("run"),
                "cpu: merging": cpu_of("finish"),
                "cpu: after planning, besides": cpu_end
                - cpu["plan start"]
                - cpu_of("plan")
                - cpu_of("run")
                - cpu_of("finish"),
                "cpu: in this interpreter": cpu_end,
            }
        )
    )


def store_module() -> Any:
    """Where the sweep's output folder is kept: tablebot.fleet.store, or in trees before it, fleet.plan."""
    import importlib

    try:
        return importlib.import_module("tablebot.fleet.store")
    except ImportError:
        return importlib.import_module("tablebot.fleet.plan")


if __name__ == "__main__":
    main()
