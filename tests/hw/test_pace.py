"""Keeping the table's tick: the run loop's rule on the loop's fake clock (sustained slowness ends the run as
``behind`` with the outputs off and the record in the trace; one stall restarts the grid and does not), the
same over a real pseudo-terminal, and the refusal before a run of a link too slow for the tick (the ROBO
Interface at its 38400 baud, a ROBO TX over a slow link, a TXT far away)."""

from __future__ import annotations

import dataclasses
import json
import os
import re
import subprocess
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

import pytest

from controller_helpers import bumberbot as wired_bumberbot
from controller_helpers import drive, eventually
from core_helpers import EXAMPLE
from tablebot.diagnostics import TableBotError
from tablebot.engine import Engine
from tablebot.formats.table_read import load_table
from tablebot.hw.link_speed import PROBES, LinkTime, judge, suggest_tick_ms
from tablebot.hw.roboif.controller import RoboifRobot
from tablebot.hw.roboif.wiring import roboif_wiring
from tablebot.loop import Reading, RealTimeClock, RunEnd, run
from tablebot.machine import Machine, compile_table
from tablebot.sinks.run_trace import RunTrace
from tablebot.testing.roboif_emulator import RoboifEmulator
from tablebot.testing.robotx_emulator import RobotxEmulator
from txt_fake import FakeTxt

pytestmark = [pytest.mark.realtime]

ROOT = Path(__file__).resolve().parents[2]
TICK_S = 0.01


def bumberbot() -> Machine:
    return compile_table(load_table(EXAMPLE / "table.csv"))


class FakeTime:
    """The loop's clock on made-up time: sleeping moves it on, and so does each tick's robot I/O."""

    def __init__(self) -> None:
        self.now = 1000.0
        self.starts: list[float] = []  # when each tick's read came

    def sleep(self, seconds: float) -> None:
        self.now += seconds


class TimedRobot:
    """A robot whose exchange (``write``) takes ``io_s(tick)`` of the fake time; records what it was sent."""

    def __init__(self, time: FakeTime, io_s: Callable[[int], float]) -> None:
        self.time, self.io_s = time, io_s
        self.writes: list[tuple[int, ...]] = []
        self.stopped_after: int | None = None

    def open(self) -> None:
        pass

    def read(self) -> Reading:
        self.time.starts.append(self.time.now)
        return Reading(0)

    def write(self, outputs: Sequence[int]) -> None:
        self.time.now += self.io_s(len(self.writes))
        self.writes.append(tuple(outputs))

    def stop(self) -> None:
        self.stopped_after = len(self.writes)

    def close(self) -> None:
        pass


def run_on_fake_time(
    io_s: Callable[[int], float], ticks: int, limit_s: float | None = 0.5, sinks: Sequence = ()
) -> tuple[RunEnd, TimedRobot, FakeTime]:
    time = FakeTime()
    robot = TimedRobot(time, io_s)
    clock = RealTimeClock(TICK_S, now=lambda: time.now, sleep=time.sleep)
    end = run(Engine(bumberbot()), robot, clock=clock, ticks=ticks, behind_limit_s=limit_s, sinks=list(sinks))
    return end, robot, time


# --- the rule, on the loop's fake clock -----------------------------------------------------------------------


def test_a_robot_a_little_too_slow_on_every_tick_ends_the_run_as_behind_with_the_outputs_off(tmp_path: Path) -> None:
    # The ROBO Interface at 38400 baud as measured: 14.3 ms a tick against a 10 ms tick. Each tick is only 4 ms
    # late, so the grid starts again every other tick and no single tick is anywhere near the 0.5 s limit.
    trace = RunTrace(tmp_path)
    end, robot, _ = run_on_fake_time(lambda tick: 0.0143, ticks=1000, sinks=[trace])
    assert end.reason == "behind" and end.exit_code == 5
    assert 110 <= end.ticks <= 120  # 0.5 s lost at 4.3 ms a tick: after 116 ticks, 1.7 s
    assert "took 14.3 ms on average" in end.message and "run 43 % slow" in end.message
    assert "tick_ms" in end.message and "--behind-limit 0" in end.message
    assert robot.stopped_after == end.ticks  # outputs off in the tick that fell behind
    last = json.loads((tmp_path / "trace.partial.jsonl").read_text().splitlines()[-1])
    assert last["end"] == "behind" and last["tick"] == end.ticks and "43 % slow" in last["why"]
    assert json.loads((tmp_path / "summary.partial.json").read_text())["exit_code"] == 5


def test_without_a_limit_the_same_robot_runs_on_with_its_late_ticks_counted() -> None:
    end, _, time = run_on_fake_time(lambda tick: 0.0143, ticks=300, limit_s=None)
    assert end.reason == "done" and end.late_ticks > 100
    assert time.starts[-1] - time.starts[0] == pytest.approx(299 * 0.0143, rel=0.01)  # timers 43 % slow


def test_one_stall_restarts_the_grid_without_a_burst_and_does_not_end_the_run() -> None:
    stall = {60: 0.4}  # a 0.4 s pause (a busy machine) after tick 60's exchange
    end, _, time = run_on_fake_time(lambda tick: stall.get(tick, 0.002), ticks=200)
    assert end.reason == "done" and end.late_ticks == 1 and end.worst_late_s == pytest.approx(0.39)
    gaps = [b - a for a, b in zip(time.starts, time.starts[1:], strict=False)]
    assert gaps[60] == pytest.approx(0.4)
    assert all(g == pytest.approx(TICK_S) for g in gaps[61:])  # one tick apart again at once: nothing made up


def test_one_stall_longer_than_the_limit_ends_the_run_and_says_it_was_one_stall() -> None:
    end, robot, _ = run_on_fake_time(lambda tick: 0.6 if tick == 30 else 0.002, ticks=200)
    assert end.reason == "behind" and end.ticks == 31 and robot.stopped_after == 31
    assert "one tick started 600 ms after the one before it" in end.message


@pytest.mark.parametrize(("tick_s", "reason"), [(0.0105, "done"), (0.0110, "done"), (0.0120, "behind")])
def test_the_limit_is_half_a_second_within_any_five_so_ticks_11_percent_too_slow_end_the_run(
    tick_s: float, reason: str
) -> None:
    end, _, time = run_on_fake_time(lambda tick: tick_s, ticks=1500)  # 15 s of table time
    assert end.reason == reason
    if reason == "behind":  # 2 ms lost every 12 ms: 0.5 s after 3 s of wall time
        assert time.starts[-1] - time.starts[0] == pytest.approx(3.0, abs=0.05)


# --- the rule, over a real pseudo-terminal --------------------------------------------------------------------


def test_a_serial_link_too_slow_for_the_tick_ends_the_run_as_behind_with_every_output_off_last() -> None:
    # The ROBO Interface emulator at 19200 baud: 19.8 ms a tick on the line alone (a busy machine only adds).
    # Driven past the pre-run check, as a link that slows down during a run would be.
    machine = wired_bumberbot("roboif")
    with RoboifEmulator(lambda n: ([0, 0, 1, 0, 0, 0, 0, 0], {}), baud=19200) as emu:
        robot = RoboifRobot(roboif_wiring(machine), emu.device, link_timeout_s=2.0)  # behind, not lost, if busy
        end = drive(machine, robot, ticks=500, behind_limit_s=0.3)
        assert eventually(lambda: emu.names()[-1:] == ["bye"], timeout_s=3)
    assert end.reason == "behind" and end.ticks < 200 and "cannot keep the table's 10 ms tick" in end.message
    last = emu.requests("exchange")[-1].fields
    assert last["outputs"] == 0 and last["pwm"] == [0] * 8


# --- before the run: the link timed against the tick ----------------------------------------------------------


def spawn(*args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    return subprocess.run(
        [sys.executable, "-m", "tablebot", "run", *args], env=env, capture_output=True, text=True, timeout=60
    )


def test_the_robo_interface_at_38400_baud_is_refused_for_a_10_ms_tick_naming_what_to_do() -> None:
    with RoboifEmulator(baud=38400) as emu:
        done = spawn(str(EXAMPLE), "--on", f"roboif://{emu.device}", "--seconds", "1")
        assert eventually(lambda: emu.names()[-1:] == ["bye"])
    said = " ".join(done.stderr.split())
    assert done.returncode == 2 and "Traceback" not in said
    assert f"{EXAMPLE / 'robot.toml'}:4:1: error: roboif://{emu.device}: one exchange with the ROBO Interface" in said
    assert "its 38 bytes alone take 9.9 ms on the 38400-baud line" in said and "(tick_ms = 10)" in said
    assert re.search(r"give tick_ms = \d+", said)  # 25 at 10 to 12.5 ms an exchange (test_the_suggested_tick...)
    assert "500ms for a timer of 50" in said and "--behind-limit 0" in said and "a ROBO TX or a TXT" in said
    exchanges = emu.requests("exchange")  # the timing only: every output off, then the farewell
    assert emu.names() == ["hello", *["exchange"] * PROBES, "bye"]
    assert all(r.fields["outputs"] == 0 and r.fields["pwm"] == [0] * 8 for r in exchanges)


def test_the_robo_interface_at_38400_baud_runs_with_slow_timers_accepted_or_with_a_longer_tick(tmp_path: Path) -> None:
    with RoboifEmulator(baud=38400) as emu:
        accepted = spawn(
            str(EXAMPLE),
            "--on",
            f"roboif://{emu.device}",
            "--seconds",
            "0.2",
            "--behind-limit",
            "0",
            "--link-timeout",
            "0.5",
        )
    assert accepted.returncode == 0, accepted.stderr
    assert "warning:" in accepted.stderr and "timers will run" in " ".join(accepted.stderr.split())
    robot = tmp_path / "robot.toml"
    robot.write_text((EXAMPLE / "robot.toml").read_text().replace("tick_ms = 10 ", "tick_ms = 50 "))
    with RoboifEmulator(baud=38400) as emu:
        longer = spawn(
            str(EXAMPLE / "table.csv"), "--robot", str(robot), "--on", f"roboif://{emu.device}", "--seconds", "0.5"
        )
    assert longer.returncode == 0 and "ran 10 ticks (0.50 s): done" in longer.stdout, longer.stderr


def test_a_rob_tx_on_a_slow_link_is_refused_pointing_at_its_usb_cable() -> None:
    with RobotxEmulator(delay_s=0.013) as emu:  # a Bluetooth link's latency
        done = spawn(str(EXAMPLE), "--on", f"robotx://{emu.device}", "--seconds", "1")
    said = " ".join(done.stderr.split())
    assert done.returncode == 2 and "one exchange with the ROBO TX takes" in said
    assert "the ROBO TX on its USB cable" in said and "config" not in emu.names()  # never configured, never moved


def test_a_txt_far_away_is_refused_pointing_at_its_usb_cable() -> None:
    with FakeTxt(latency_s=0.012) as fake:
        done = spawn(str(EXAMPLE), "--on", f"txt://127.0.0.1:{fake.port}", "--seconds", "1")
    said = " ".join(done.stderr.split())
    assert done.returncode == 2 and "a round trip to the controller takes" in said
    assert "the TXT on its USB cable" in said and "StartOnline" not in fake.names()  # never went online


def test_the_judgement_warns_when_the_link_takes_more_than_half_the_tick_and_locates_the_refusal() -> None:
    machine = bumberbot()
    assert judge(machine, LinkTime("t://x", "one exchange", 0.004), accept_slow=False) == ()
    (warning,) = judge(machine, LinkTime("t://x", "one exchange", 0.007), accept_slow=False)
    assert "70% of the table's 10 ms tick" in warning and "tick_ms = 25 would leave room" in warning
    with pytest.raises(TableBotError) as refused:
        judge(machine, LinkTime("t://x", "one exchange", 0.015), accept_slow=False)
    (problem,) = refused.value.diagnostics
    assert (problem.path, problem.line) == (str(EXAMPLE / "robot.toml"), 4)
    assert "at least 50 % slow" in problem.message and "tick_ms = 50" in problem.hint
    (accepted,) = judge(machine, LinkTime("t://x", "one exchange", 0.015), accept_slow=True)
    assert "timers will run at least 50 % slow" in accepted
    builtin = compile_table(
        dataclasses.replace(machine.table, robot=dataclasses.replace(machine.table.robot, toml=None))
    )
    with pytest.raises(TableBotError) as on:
        judge(builtin, LinkTime("t://x", "one exchange", 0.015), accept_slow=False)
    assert on.value.diagnostics[0].path == "--on"


def test_the_suggested_tick_leaves_half_for_the_host_and_keeps_the_tables_timers_whole() -> None:
    machine = bumberbot()  # timers of 50, 60, 75, 85, 125, 150, 500 and 895 ticks: all whole at 50 ms
    assert suggest_tick_ms(machine, 0.0099) == 25 and suggest_tick_ms(machine, 0.0131) == 50
    assert suggest_tick_ms(machine, 0.030) == 60  # no divisor of 50 ms from 60 to 120: a round 60
