"""No process outlives the command that started it: a command killed with SIGKILL (no chance to end what it
started) takes its worker processes with it, so ``COMMAND | tee`` ends, instead of the workers waiting
forever while holding the pipe open: ``evolve``'s provers, ``sim``'s drawing copy, and the copy's watch
for its parent where the kernel does not kill it (not Linux)."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

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


class Teed:
    """``command | tee LOG`` as a shell runs it, the command's stderr in the pipe too."""

    def __init__(self, command: list[str], log: Path) -> None:
        self.log = log
        self.command = subprocess.Popen(
            command, env=env(), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL
        )
        assert self.command.stdout is not None
        self.reader = subprocess.Popen(["tee", str(log)], stdin=self.command.stdout, stdout=subprocess.DEVNULL)
        self.command.stdout.close()  # the pipe's write end is now held by the command and what it started, only
        self.seen: set[int] = set()

    def started(self, depth: int, what: str) -> None:
        """Wait until the command has a process ``depth`` levels below it (1: a child; evolve's provers are
        its fork server's children); every process under it is then kept in :attr:`seen`."""
        deadline = time.monotonic() + 120
        while True:
            under = descendants(self.command.pid)
            self.seen |= set(under)
            if any(d >= depth for d in under.values()):
                return
            assert self.command.poll() is None, self.log.read_text()
            assert time.monotonic() < deadline, f"the command started no {what}"
            time.sleep(0.05)

    def kill_and_check(self) -> None:
        """SIGKILL the command: ``tee`` must see the pipe's end and every process seen under it must end, soon."""
        os.kill(self.command.pid, signal.SIGKILL)
        self.command.wait()
        try:
            self.reader.wait(timeout=GRACE_S)
        except subprocess.TimeoutExpired:
            raise AssertionError(f"`COMMAND | tee` did not end: {sorted(living(self.seen))} hold the pipe") from None
        deadline = time.monotonic() + GRACE_S
        while living(self.seen) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not living(self.seen), f"processes the command started outlived it: {sorted(living(self.seen))}"

    def close(self) -> None:
        """Whatever happened, nothing left behind by the test itself."""
        for pid in living(self.seen) | ({self.command.pid} if self.command.poll() is None else set()):
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        self.reader.kill()
        self.reader.wait()
        self.command.wait()


@contextlib.contextmanager
def teed(command: list[str], log: Path) -> Iterator[Teed]:
    pipeline = Teed(command, log)
    try:
        yield pipeline
    finally:
        pipeline.close()


def tablebot(*args: str) -> list[str]:
    return [sys.executable, "-m", "tablebot", *args]


def test_evolve_killed_with_sigkill_takes_its_workers_with_it(tmp_path: Path) -> None:
    command = tablebot(
        "evolve",
        str(BUMBERBOT),
        "--out",
        str(tmp_path / "out"),
        "--budget",
        "200",
        "--workers",
        "2",
        "--backend",
        "local",
    )
    with teed(command, tmp_path / "log") as pipeline:
        pipeline.started(2, "prover process")
        pipeline.kill_and_check()


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="with one core, sim draws in its own process")
def test_sim_killed_with_sigkill_takes_its_drawing_copy_with_it(tmp_path: Path) -> None:
    with teed(
        tablebot("sim", str(BUMBERBOT), "--seconds", "3000", "--out", str(tmp_path / "out")), tmp_path / "log"
    ) as pipeline:
        pipeline.started(1, "drawing copy")
        pipeline.kill_and_check()


#: A process whose forked copy (holding its stdout, as a drawing copy does) watches for it portably.
WATCHED = """
import os, time
from tablebot.sim.pictures.forked import watch_parent
parent = os.getpid()
if os.fork() == 0:
    watch_parent(parent)
    time.sleep(120)
    os._exit(0)
time.sleep(120)
"""


def test_where_the_kernel_does_not_kill_a_copy_with_its_parent_the_copy_sees_it_gone(tmp_path: Path) -> None:
    """The watch sim's copies keep where prctl is missing (not Linux), run here with the kernel's own left out."""
    with teed([sys.executable, "-c", WATCHED], tmp_path / "log") as pipeline:
        pipeline.started(1, "copy")
        pipeline.kill_and_check()
