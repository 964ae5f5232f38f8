"""Benchmark: ``make demo``, the README's first command, as a user's first minute with tablebot (issue 34 §1:
at most 60 s from empty caches on 2 cores, and talking the whole time).

Run: ``.venv/bin/python benchmarks/demo.py [--runs 3] [--baseline-runs 1]``.

Each run is a whole process from nothing: a fresh ``git clone`` of this checkout's HEAD (what is committed) in a
temporary folder, with uv's, numba's and the user's cache folders (``UV_CACHE_DIR``, ``NUMBA_CACHE_DIR``,
``XDG_CACHE_HOME``: pip's and matplotlib's) new and empty, then ``make demo`` there, its output (stdout and
stderr, as one pipe: not a terminal, so the compile says it is still going every 10 s) read line by line with
the time each line came. Per run: the whole time; the set-up (until the demo says it simulates); the first
simulation's compile as it reports it; the longest silence between two lines, and the line after which it came;
and that the two pictures were written.

The baseline, in the same conditions: the old demo's recipe, the developer set-up (``scripts/bootstrap.sh``:
every dev package, bytecode compiled, ESLint from npm) and then the same simulation. On this machine its system
packages (Chromium, the AVR toolchain, simavr, Graphviz) are installed already, so apt does nothing and the
baseline is the old demo's time without its downloads from Debian (about 40 s more on a fresh machine).
The load average is printed: the machine is shared, and a compile of about 40 s of CPU takes longer beside
others' work.
"""

from __future__ import annotations

import argparse
import itertools
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET_S = 60.0
SILENCE_S = 15.0  # longest a first-time user is left without a word
SIMULATING = "simulating the BumberBot"
PICTURES = ("out/demo/trajectory.png", "out/demo/timeline.png")
OLD_DEMO = "./scripts/bootstrap.sh && .venv/bin/tablebot sim examples/bumberbot --out out/demo"


@dataclass
class Run:
    seconds: float
    setup_s: float | None  # until the line saying the demo simulates
    compile_s: float | None  # as the compile reports it
    silence_s: float
    silence_after: str
    pictures: bool


def fresh_env(caches: Path) -> dict[str, str]:
    """This environment with every cache a first run fills pointed at new empty folders."""
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("PYTHONDONTWRITEBYTECODE", "VIRTUAL_ENV", "PYTHONPATH", "MAKEFLAGS", "MFLAGS", "MAKELEVEL")
    }
    for name in ("UV_CACHE_DIR", "NUMBA_CACHE_DIR", "XDG_CACHE_HOME", "PIP_CACHE_DIR", "MPLCONFIGDIR"):
        env[name] = str(caches / name.lower())
    env["npm_config_cache"] = str(caches / "npm")
    return env


def timed_lines(argv: list[str], cwd: Path, env: dict[str, str]) -> tuple[float, list[tuple[float, str]], int]:
    """Run ``argv``; its wall seconds, each output line with the second it came, its exit code."""
    started = time.monotonic()
    proc = subprocess.Popen(
        argv, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace", bufsize=1
    )
    assert proc.stdout is not None
    lines: list[tuple[float, str]] = []
    reader = threading.Thread(
        target=lambda: lines.extend((time.monotonic() - started, line.rstrip("\n")) for line in proc.stdout),  # type: ignore[union-attr]
        daemon=True,
    )
    reader.start()
    code = proc.wait()
    seconds = time.monotonic() - started
    reader.join()
    return seconds, lines, code


def one(command: str, workdir: Path) -> Run:
    """One fresh clone, empty caches, ``command`` run there as a whole process."""
    clone, caches = workdir / "tablebot", workdir / "caches"
    subprocess.run(["git", "clone", "--quiet", str(ROOT), str(clone)], check=True)
    seconds, lines, code = timed_lines(["bash", "-c", command], clone, fresh_env(caches))
    if code != 0:
        tail = "\n".join(line for _, line in lines[-30:])
        raise SystemExit(f"{command} failed ({code}):\n{tail}")
    marks = [0.0, *(at for at, _ in lines), seconds]
    gaps = [(b - a, lines[k - 1][1] if k else "(the start)") for k, (a, b) in enumerate(itertools.pairwise(marks))]
    silence, after = max(gaps)
    setup = next((at for at, line in lines if line.startswith(SIMULATING)), None)
    compiled = next(
        (float(m[1]) for _, line in lines if (m := re.search(r"compiled the simulator in (\d+) s", line))), None
    )
    return Run(seconds, setup, compiled, silence, after, all((clone / p).is_file() for p in PICTURES))


def runs(command: str, count: int, label: str) -> list[Run]:
    done = []
    for k in range(count):
        with tempfile.TemporaryDirectory(prefix="tablebot-demo-bench-") as workdir:
            run = one(command, Path(workdir))
        done.append(run)
        parts = "".join(
            f", {name} {value:.1f} s" for name, value in (("set-up", run.setup_s), ("compile", run.compile_s)) if value
        )
        print(
            f"  {label} {k + 1}/{count}: {run.seconds:.1f} s{parts}; longest silence {run.silence_s:.1f} s "
            f"after {run.silence_after[:70]!r}; pictures {'written' if run.pictures else 'MISSING'}",
            flush=True,
        )
    return done


def median(values: list[float | None]) -> float | None:
    known = [v for v in values if v is not None]
    return statistics.median(known) if known else None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="runs of make demo (the median is judged)")
    parser.add_argument("--baseline-runs", type=int, default=1, help="runs of the old demo's recipe (0: none)")
    args = parser.parse_args(argv)
    if shutil.which("make") is None:
        raise SystemExit("make is needed (the demo is `make demo`)")
    print(
        f"make demo from empty caches, fresh clones of {ROOT} at HEAD; load average {os.getloadavg()[0]:.1f} "
        f"on {os.cpu_count()} cores",
        flush=True,
    )
    demo = runs("make demo", args.runs, "make demo")
    whole = statistics.median(r.seconds for r in demo)
    print(
        f"make demo: median {whole:.1f} s (set-up {median([r.setup_s for r in demo]) or 0:.1f} s, first compile "
        f"{median([r.compile_s for r in demo]) or 0:.1f} s); longest silence {max(r.silence_s for r in demo):.1f} s"
    )
    if args.baseline_runs:
        old = runs(OLD_DEMO, args.baseline_runs, "old demo (developer set-up + sim)")
        before = statistics.median(r.seconds for r in old)
        print(f"old demo: median {before:.1f} s; make demo takes {whole / before:.2f} of it")
    print(f"load average at the end: {os.getloadavg()[0]:.1f}")
    checks = [
        (f"make demo ≤ {TARGET_S:.0f} s (median)", whole <= TARGET_S),
        (f"never silent for more than {SILENCE_S:.0f} s", all(r.silence_s <= SILENCE_S for r in demo)),
        ("both pictures written", all(r.pictures for r in demo)),
    ]
    print("targets:")
    for label, ok in checks:
        print(f"  {label:<40} {'ok' if ok else 'MISSED'}")
    return 0 if all(ok for _, ok in checks) else 1


if __name__ == "__main__":
    sys.exit(main())
