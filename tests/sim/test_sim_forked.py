"""The forked copy that draws one of a run's pictures on the other core (tablebot.sim.pictures.forked): its answer, its
errors, and no process left behind on any way out, the sim command's interrupts included."""

from __future__ import annotations

import os
import pickle
import shutil
import signal
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot.cli import app
from tablebot.interrupts import FAULT_ENV
from tablebot.sim.pictures import forked
from tablebot.sim.pictures.forked import Forked

pytestmark = pytest.mark.skipif(
    not sys.platform.startswith("linux") or (os.cpu_count() or 1) < 2,
    reason="the copy is forked on Linux with two cores or more (elsewhere the work "
    "runs in place, tested by test_without_a_copy_the_work_runs_here)",
)


def copies() -> list[int]:
    """Our forked copies still in the process table (running or unreaped), by the name they give themselves."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            status = (entry / "status").read_text()
        except OSError:
            continue
        fields = dict(line.split(":\t", 1) for line in status.splitlines() if ":\t" in line)
        if fields.get("Name", "").strip() == forked.NAME.decode() and int(fields["PPid"]) == os.getpid():
            found.append(int(entry.name))
    return found


def after(seconds: float, value: bytes) -> bytes:
    """``value``, a long while later (work a test cuts short)."""
    time.sleep(seconds)
    return value


def test_the_answer_comes_from_another_process() -> None:
    me = os.getpid()
    with Forked(lambda _: str(os.getpid()).encode()) as copy:
        assert copy.pid is not None
        assert int(copy.result()) not in (me, 0)
    assert copies() == []


def test_an_error_in_the_copy_is_raised_here() -> None:
    def work(_: forked.Inbox) -> bytes:
        raise ValueError("no picture today")

    with Forked(work) as copy, pytest.raises(ValueError, match="no picture today"):
        copy.result()
    assert copies() == []


def test_leaving_without_the_answer_kills_the_copy_at_once() -> None:
    started = time.monotonic()
    with pytest.raises(KeyboardInterrupt), Forked(lambda _: after(60, b"late")) as copy:
        while copies() != [copy.pid]:  # the copy names itself just after the fork
            assert time.monotonic() - started < 10
            time.sleep(0.01)
        raise KeyboardInterrupt
    assert copies() == [] and time.monotonic() - started < 30


def test_a_copy_killed_from_outside_is_replaced_by_the_work_done_here() -> None:
    me = os.getpid()
    with Forked(lambda _: b"here" if os.getpid() == me else after(60, b"there")) as copy:
        assert copy.pid is not None  # a copy was forked (two cores or more)
        os.kill(copy.pid, signal.SIGKILL)
        assert copy.result() == b"here"
    assert copies() == []


def test_messages_reach_the_copy_in_order_with_their_arrays() -> None:
    rows = np.arange(300_000, dtype=np.float32).reshape(-1, 3)  # larger than the pipe: written as it is read

    def work(inbox: forked.Inbox) -> bytes:
        first, second = inbox.get(), inbox.get()
        return pickle.dumps((os.getpid(), first, float(second["rows"].sum()), second["rows"].dtype.str))

    with Forked(work) as copy:
        copy.send("the scene")
        copy.send({"rows": rows})
        pid, first, total, dtype = pickle.loads(copy.result())
    assert pid != os.getpid() and (first, total, dtype) == ("the scene", float(rows.sum()), rows.dtype.str)
    assert copies() == []


def test_a_copy_that_died_gets_its_messages_here() -> None:
    me = os.getpid()

    def work(inbox: forked.Inbox) -> bytes:
        if os.getpid() != me:
            os._exit(3)  # dies before reading anything
        return inbox.get() + inbox.get()

    with Forked(work) as copy:
        deadline = time.monotonic() + 30
        while Path(f"/proc/{copy.pid}/stat").read_text().split(")")[-1].split()[0] != "Z":  # dead, not reaped
            assert time.monotonic() < deadline
            time.sleep(0.01)
        copy.send(b"big " * 400_000)  # more than the pipe holds: the dead reader is noticed
        copy.send(b"end")
        assert copy.result() == b"big " * 400_000 + b"end"


def test_a_copy_waiting_for_a_message_never_sent_leaves_quietly() -> None:
    with Forked(lambda inbox: inbox.get()) as copy:
        pid = copy.pid
        with pytest.raises(RuntimeError, match="never sent"):
            copy.result()  # the copy read the end of its messages and left: the work ran here, and asked again
    assert copies() == [] and pid is not None


def test_without_a_copy_the_work_runs_here(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(os, "cpu_count", lambda: 1)
    with Forked(lambda _: str(os.getpid()).encode()) as copy:
        assert copy.pid is None and int(copy.result()) == os.getpid()


@pytest.mark.parametrize("fault", ["2:INT", "3:TERM"])
def test_sim_interrupted_while_drawing_leaves_no_process(tmp_path: Path, fault: str) -> None:
    """Step 2 is trajectory.png written (the copy may still draw the timeline), step 3 timeline.png."""
    shutil.copytree(EXAMPLE, tmp_path / "bot")
    result = CliRunner().invoke(
        app,
        ["sim", str(tmp_path / "bot"), "--seconds", "20", "-q", "--out", str(tmp_path / "out")],
        env={FAULT_ENV: fault},
    )
    assert result.exit_code == (130 if fault.endswith("INT") else 143), result.output
    assert copies() == []
    assert not list((tmp_path / "out").glob("*.png"))
