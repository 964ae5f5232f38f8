"""The golden files: what tablebot writes for the BumberBot (examples/bumberbot), kept in tests/golden/ and
reviewed like code, so that a change to any output shows up as a diff in the change that made it.

    make golden                     # (or .venv/bin/python scripts/golden.py) write them again, then git diff

tests/project/test_golden.py makes the same files and compares them byte for byte with these. Each is made by the
command a user types, as a process in the checkout (so paths in them read ``examples/bumberbot/...``):

* ``c/``: ``tablebot export examples/bumberbot OUT --to c`` (the generated C engine and table)
* ``robopro/``: ``tablebot export examples/bumberbot OUT --to robopro-program`` (the ROBO Pro program), and the
  same of examples/bumberbot-lights (the drive and the lights tables, a ROBO Pro process each)
* ``diagram.svg``: ``tablebot diagram examples/bumberbot --out diagram.svg`` (drawn by graphviz-pure, the same
  on every platform)
* ``check.txt``: what ``tablebot check examples/bumberbot`` prints
* ``sim-trace.jsonl``: the trace of ``tablebot sim examples/bumberbot --seconds 24 --seed 1`` (seeking, turning,
  then following the lamp); floating point may round otherwise on another platform (as the trace digests,
  tests/testing/test_trace_digests.py), so it is compared only on the platform in ``PLATFORM``.
"""

from __future__ import annotations

import os
import platform
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden"
EXAMPLE = "examples/bumberbot"
LIGHTS = "examples/bumberbot-lights"  # the document's robot whole: its ROBO Pro program, the lights a process
#: Where the files below were made; the simulated ones are compared only there.
PLATFORM = f"{sys.platform}-{platform.machine()}"
SIMULATED = ("sim-trace.jsonl",)


def tablebot(*args: str) -> str:
    """Run tablebot as a user does, in the checkout; its standard output. A failure says what it printed."""
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "TABLEBOT_LANG": "en", "COLUMNS": "120"},
    )
    if done.returncode != 0:
        raise RuntimeError(f"tablebot {' '.join(args)} failed ({done.returncode}):\n{done.stdout}{done.stderr}")
    return done.stdout


def make(out: Path) -> dict[str, bytes]:
    """Every golden file, made afresh into ``out``: {path under tests/golden: bytes}."""
    tablebot("export", EXAMPLE, str(out / "c"), "--to", "c")
    tablebot("export", EXAMPLE, str(out / "robopro"), "--to", "robopro-program")
    tablebot("export", LIGHTS, str(out / "robopro"), "--to", "robopro-program")  # a process per table
    tablebot("diagram", EXAMPLE, "--out", str(out / "diagram.svg"))
    (out / "check.txt").write_text(tablebot("check", EXAMPLE), encoding="utf-8")
    sim = out / "sim-run"
    tablebot("sim", EXAMPLE, "--seconds", "24", "--seed", "1", "--no-plots", "--quiet", "--out", str(sim))
    shutil.move(sim / "trace.jsonl", out / "sim-trace.jsonl")
    shutil.rmtree(sim)
    return {path.relative_to(out).as_posix(): path.read_bytes() for path in sorted(out.rglob("*")) if path.is_file()}


def recorded() -> dict[str, bytes]:
    """The golden files as committed (PLATFORM and .gitattributes aside)."""
    return {
        path.relative_to(GOLDEN).as_posix(): path.read_bytes()
        for path in sorted(GOLDEN.rglob("*"))
        if path.is_file() and path.name not in ("PLATFORM", ".gitattributes")
    }


def write() -> None:
    """Make them again into tests/golden (each file written whole under a temporary name, then renamed)."""
    with tempfile.TemporaryDirectory() as tmp:
        made = make(Path(tmp))
    stale = set(recorded()) - set(made)
    for name in stale:
        (GOLDEN / name).unlink()
    for name, data in made.items():
        path = GOLDEN / name
        path.parent.mkdir(parents=True, exist_ok=True)
        partial = path.with_name(f".{path.name}.tmp")
        partial.write_bytes(data)
        partial.replace(path)
    (GOLDEN / "PLATFORM").write_text(PLATFORM + "\n", encoding="utf-8")
    print(
        f"wrote {len(made)} golden files into {GOLDEN.relative_to(ROOT)} on {PLATFORM}"
        + (f" (removed {', '.join(sorted(stale))})" if stale else "")
        + "; review them with git diff"
    )


if __name__ == "__main__":
    if sys.argv[1:]:
        raise SystemExit(f"usage: {sys.argv[0]}   (writes tests/golden/ again)")
    write()
