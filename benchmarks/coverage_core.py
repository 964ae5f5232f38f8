"""Benchmark: what measuring coverage costs the tests, on Python 3.11 (coverage's C line tracer) and 3.12
(``sys.monitoring``, ``core = "sysmon"`` in pyproject.toml), which is why ``make setup`` makes the tests' venv
with 3.12 (docs/development.md, Coverage).

Run: ``.venv/bin/python benchmarks/coverage_core.py [--rounds 3] [--python311 PY] [--python312 PY] [TESTS ...]``.

Each configuration runs the same tests in one process (``-n 0``; default: the kernel-free tests of
tests/formats, tests/engine and tests/analysis, which are plain Python, where a tracer costs the most) and is
timed in CPU seconds (user + system, the process and its children): wall seconds on a shared 2-core machine
say more about the other engineers' runs than about these. The configurations take turns round by round; the
medians are printed with each one's ratio to 3.11 unmeasured. ``--python311``/``--python312``: the Python of a
venv holding requirements/dev.lock and tablebot (editable); without one, a venv of that version is made in a
temporary folder with uv, from the lock, from the interpreter pyenv or PATH has (a minute each). Each version
gets a numba cache folder of its own, shared by its rounds.
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
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TESTS = ["tests/formats", "tests/engine", "tests/analysis"]
#: name, Python version, pytest's coverage options, COVERAGE_CORE ("" : pyproject's)
CONFIGS = [
    ("3.11 unmeasured", "3.11", [], ""),
    ("3.11 coverage (C tracer)", "3.11", ["--cov", "--cov-report="], ""),
    ("3.12 unmeasured", "3.12", [], ""),
    ("3.12 coverage (sys.monitoring)", "3.12", ["--cov", "--cov-report="], "sysmon"),
    ("3.12 coverage (C tracer)", "3.12", ["--cov", "--cov-report="], "ctrace"),
]


def interpreter(version: str) -> str:
    """A Python ``version`` interpreter: on PATH (pythonX.Y), else pyenv's newest of that version."""
    found = shutil.which(f"python{version}")
    if found and subprocess.run([found, "-c", "pass"], capture_output=True).returncode == 0:
        return found
    pyenv = shutil.which("pyenv")
    if pyenv:
        root = Path(subprocess.run([pyenv, "root"], capture_output=True, text=True, check=True).stdout.strip())
        versions = sorted(root.glob(f"versions/{version}.*/bin/python3"), key=lambda p: p.parts[-3])
        if versions:
            return str(versions[-1])
    raise SystemExit(
        f"no Python {version} on PATH (python{version}) or in pyenv: name a venv's with --python"
        f"{version.replace('.', '')}"
    )


def make_venv(version: str, into: Path) -> str:
    """A venv of Python ``version`` in ``into`` with the lock's packages and tablebot, by the running venv's uv."""
    uv = str(Path(sys.executable).with_name("uv"))
    subprocess.run([interpreter(version), "-m", "venv", "--without-pip", str(into)], check=True)
    python = str(into / "bin" / "python")
    print(f"installing requirements/dev.lock into a Python {version} venv ({into})", flush=True)
    subprocess.run(
        [uv, "pip", "sync", "-q", "--python", python, "--require-hashes", "requirements/dev.lock"], cwd=ROOT, check=True
    )
    subprocess.run([uv, "pip", "install", "-q", "--python", python, "--no-deps", "-e", "."], cwd=ROOT, check=True)
    return python


def cpu_seconds(python: str, tests: list[str], options: list[str], env: dict[str, str]) -> float:
    """CPU seconds of one pytest run (it must pass), its children's included."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    argv = [python, "-m", "pytest", *tests, "-m", "kernel_free", "-q", "-n", "0", "-p", "no:cacheprovider", *options]
    done = subprocess.run(argv, cwd=ROOT, env=env, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed ({done.returncode}):\n{done.stdout[-3000:]}{done.stderr[-2000:]}")
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime


def run_rounds(pythons: dict[str, str], tests: list[str], rounds: int, work: Path) -> dict[str, list[float]]:
    """Every configuration's CPU seconds, round by round (they take turns: a busier minute falls on all)."""
    base = {k: v for k, v in os.environ.items() if k not in ("COVERAGE_CORE", "PYTHONDONTWRITEBYTECODE")}
    base["COVERAGE_FILE"] = str(work / ".coverage")  # not the checkout's build/coverage
    cpu: dict[str, list[float]] = {name: [] for name, *_ in CONFIGS}
    for round_ in range(rounds):
        for name, version, options, core in CONFIGS:
            env = base | {"NUMBA_CACHE_DIR": str(work / f"numba-{version}")}
            if core:
                env["COVERAGE_CORE"] = core
            cpu[name].append(cpu_seconds(pythons[version], tests, options, env))
            print(f"round {round_ + 1}: {name}: {cpu[name][-1]:.1f} CPU-s", flush=True)
    return cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--python311")
    parser.add_argument("--python312")
    parser.add_argument("tests", nargs="*", default=TESTS)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="tablebot-coverage-bench-") as tmp:
        work = Path(tmp)
        pythons = {
            "3.11": args.python311 or make_venv("3.11", work / "venv311"),
            "3.12": args.python312 or make_venv("3.12", work / "venv312"),
        }
        cpu = run_rounds(pythons, args.tests, args.rounds, work)
    baseline = statistics.median(cpu[CONFIGS[0][0]])
    print(
        f"\nmedian CPU seconds of {args.rounds} rounds ({' '.join(args.tests)}, kernel-free tests, one process; "
        f"load {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)"
    )
    for name, *_ in CONFIGS:
        median = statistics.median(cpu[name])
        print(f"  {name:32} {median:7.1f} s  {median / baseline:5.2f}x")


if __name__ == "__main__":
    main()
