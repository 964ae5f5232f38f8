"""No process outlives the command that started it: ``evolve`` killed with SIGKILL (no chance to end its
prover processes) takes them with it, so ``evolve | tee`` ends, instead of the workers waiting forever for
their next task while holding the pipe open."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from test_sweep import env

ROOT = Path(__file__).resolve().parents[1]
BUMBERBOT = ROOT / "examples" / "bumberbot"
#: How long the reader and the workers get to see the parent gone (they see it at once: this is slack).
GRACE_S = 5.0


def processes() -> dict[int, tuple[int, str]]:
    """Every process: its parent's pid and its state (``ps``, as on any Unix)."""
    listing = subprocess.run(["ps", "-A", "-o", "pid=,ppid=,stat="], capture_output=True, text=True, check=True)
    table: dict[int, tuple[int, str]] = {}
    for line in listing.stdout.splitlines():
        pid, ppid, state = line.split()[:3]
        table[int(pid)] = (int(ppid), state)
    return table


def descendants(root: int) -> dict[int, int]:
    """The processes under ``root``, each with its depth (1: a child, 2: a grandchild...)."""
    table, found, depth = processes(), {root: 0}, 0
    while True:
        depth += 1
        new = {pid: depth for pid, (ppid, _) in table.items() if ppid in found and pid not in found}
        if not new:
            return {pid: d for pid, d in found.items() if pid != root}
        found.update(new)


def living(pids: set[int]) -> set[int]:
    """Those of ``pids`` still running (a zombie has ended: it only waits to be reaped)."""
    table = processes()
    return {pid for pid in pids if pid in table and not table[pid][1].startswith("Z")}


def with_workers(command: subprocess.Popen[bytes], log: Path) -> dict[int, int]:
    """The processes under ``command`` once a worker is among them (a child of its fork server)."""
    deadline = time.monotonic() + 120
    while True:
        under = descendants(command.pid)
        if any(depth >= 2 for depth in under.values()):
            return under
        assert command.poll() is None, log.read_text()
        assert time.monotonic() < deadline, "evolve started no worker process"
        time.sleep(0.05)


def test_evolve_killed_with_sigkill_takes_its_workers_with_it(tmp_path: Path) -> None:
    command = [sys.executable, "-m", "tablebot", "evolve", str(BUMBERBOT), "--out", str(tmp_path / "out"),
               "--budget", "200", "--workers", "2", "--backend", "local"]
    evolve = subprocess.Popen(command, env=env(), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              stdin=subprocess.DEVNULL)
    assert evolve.stdout is not None
    reader = subprocess.Popen(["tee", str(tmp_path / "log")], stdin=evolve.stdout, stdout=subprocess.DEVNULL)
    evolve.stdout.close()  # the pipe's write end is now held by evolve and what it started, only
    seen: set[int] = set()
    try:
        seen = set(with_workers(evolve, tmp_path / "log"))
        os.kill(evolve.pid, signal.SIGKILL)
        evolve.wait()
        try:
            reader.wait(timeout=GRACE_S)
        except subprocess.TimeoutExpired:
            raise AssertionError(f"`evolve | tee` did not end: {sorted(living(seen))} still hold the pipe") from None
        deadline = time.monotonic() + GRACE_S
        while living(seen) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not living(seen), f"processes evolve started outlived it: {sorted(living(seen))}"
    finally:  # on failure, nothing is left behind by the test itself
        for pid in living(seen) | ({evolve.pid} if evolve.poll() is None else set()):
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        reader.kill()
        reader.wait()
        evolve.wait()
