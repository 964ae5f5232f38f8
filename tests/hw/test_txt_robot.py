"""The TXT robot against a fake TXT over real sockets: configuration, cadence, PWM that follows the engine for
the inputs the fake serves, and zero PWM in the last exchange before StopOnline on every way a run ends.

Each test runs twice: against a TXT (which paces exchanges at 10 ms) and against ftrobopy_server on a
TXT 4.0 (which answers at once, so the client's clock must pace)."""

from __future__ import annotations

import dataclasses
import itertools
import os
import random
import signal
import statistics
import time
from pathlib import Path

import pytest

from core_helpers import EXAMPLE
from tablebot.engine import Engine
from tablebot.formats.inputs_csv import TickInput
from tablebot.formats.table_read import load_table
from tablebot.hw.txt.controller import TxtRobot
from tablebot.hw.txt.wiring import txt_wiring
from tablebot.loop import RealTimeClock, RunEnd, TickBlock, run
from tablebot.machine import Machine, compile_table
from tablebot.replay import replay
from tablebot.robot import load_robot
from tablebot.table import Table
from tablebot.testing.random_tables import Shape, random_table
from txt_fake import FakeTxt

pytestmark = [pytest.mark.realtime]

FLAVOURS: dict[str, dict[str, object]] = {
    "txt": {"period_s": 0.01},
    "ftrobopy_server": {"period_s": 0.0, "device": "TX2013", "version": 0x04070000, "single_recv": True},
}


def bumberbot() -> Machine:
    return compile_table(load_table(EXAMPLE / "table.csv"))


def drive(
    machine: Machine,
    fake: FakeTxt,
    ticks: int | None = 40,
    sinks: tuple = (),
    timeout_s: float = 0.15,
    behind_limit_s: float | None = None,
) -> RunEnd:
    robot = TxtRobot(txt_wiring(machine), "127.0.0.1", fake.port, link_timeout_s=timeout_s)
    robot.connect()
    clock = RealTimeClock(machine.table.robot.tick_s)
    end = run(
        Engine(machine), robot, clock=clock, sinks=list(sinks), ticks=ticks, target="txt", behind_limit_s=behind_limit_s
    )
    fake_settles(fake)
    assert all(r.whole for r in fake.requests()), "a request arrived in pieces"
    return end


def fake_settles(fake: FakeTxt) -> None:
    """The fake logs a request when it has read it; give it a moment after the client closed."""
    deadline = time.monotonic() + 2
    while "closed" not in fake.names() and time.monotonic() < deadline:
        time.sleep(0.005)


@pytest.fixture(params=list(FLAVOURS))
def flavour(request: pytest.FixtureRequest) -> dict[str, object]:
    return FLAVOURS[request.param]


def test_it_configures_the_bumberbots_inputs_and_motors_then_exchanges_every_10_ms(flavour: dict) -> None:
    with FakeTxt(**flavour) as fake:
        started = time.monotonic()
        end = drive(bumberbot(), fake, ticks=60)
        took = time.monotonic() - started
    assert end.reason == "done" and end.ticks == 60
    names = fake.names()
    assert names[:3] == ["QueryStatus", "StartOnline", "UpdateConfig"] and names[-2:] == ["StopOnline", "closed"]
    assert fake.requests("StartOnline")[0].fields["client"] == "tablebot"
    config = fake.requests("UpdateConfig")[0].fields
    assert config["motors"] == [1, 1, 1, 1] and config["counters"] == [1, 1, 1, 1]
    assert config["inputs"] == [(1, 1)] * 8  # I3, I4, I5 switches, I7, I8 phototransistors: digital 5 kOhm
    exchanges = fake.requests("ExchangeData")
    assert len(exchanges) == 1 + 60 + 1  # outputs off at open, one per tick, outputs off at the stop
    gaps = [b.t - a.t for a, b in itertools.pairwise(exchanges[1:-1])]
    assert 0.0085 < statistics.median(gaps) < 0.0115, gaps
    assert took >= 0.59


def test_pwm_follows_the_engine_for_the_inputs_the_fake_serves(tmp_path: Path, flavour: dict) -> None:
    """A random table on a robot wired with every kind of terminal: an inverted switch, an ultrasonic
    threshold, a reversed motor on another pair, a lamp, a counter on C3."""
    machine = wired_random_machine(tmp_path)
    rng = random.Random(5)
    script = [
        (
            [rng.randint(0, 1), 0, 0, rng.randint(0, 1), 0, rng.choice([5, 19, 20, 80]), 0, 0],
            [0, 0, rng.randint(0, 3), 0],
        )
        for _ in range(90)
    ]
    counts = [sum(s[1][2] for s in script[: n + 1]) for n in range(len(script))]
    with FakeTxt(lambda n: (script[n][0], [0, 0, counts[n], 0]), **flavour) as fake:
        end = drive(machine, fake, ticks=80)
    assert end.reason == "done"
    assert fake.requests("UpdateConfig")[0].fields["motors"] == [1, 1, 1, 0]  # O7/O8 are single outputs (lamp)
    inputs = fake.requests("UpdateConfig")[0].fields["inputs"]
    assert inputs[0] == (1, 1) and inputs[3] == (1, 1) and inputs[5] == (3, 0)  # ultrasonic, analog
    bits = machine.input_bits
    ticks = [
        TickInput(
            (bits["I1"] if u[0] else 0) | (bits["I2"] if not u[3] else 0) | (bits["I3"] if u[5] < 20 else 0),
            (0 if n == 0 else c[2],),
        )
        for n, (u, c) in enumerate(script[:80])
    ]
    expected = [pwm_of(line) for line in replay(machine, ticks)]
    sent = [r.fields["pwm"] for r in fake.requests("ExchangeData")]
    assert sent[0] == [0] * 8 and sent[-1] == [0] * 8
    assert sent[1:81] == expected
    assert any(any(p) for p in expected)  # the motors did move


def wired_random_machine(tmp_path: Path) -> Machine:
    shape = Shape(states=4, rows=14, inputs=3, motors=2, lamps=1, counters=1)
    table = random_table(random.Random(11), shape)
    robot_file = tmp_path / "robot.toml"
    robot_file.write_text(
        'initial_state = 1\n[inputs]\nI1 = "a"\nI2 = "b"\nI3 = "c"\n[motors]\nM1 = "r"\nM2 = "l"\n'
        '[lamps]\nL1 = "lamp"\n[counters]\nC1 = "M1"\n[txt]\n'
        'I1 = { terminal = "I1", mode = "switch", pressed = 1 }\n'
        'I2 = { terminal = "I4", mode = "switch", pressed = 0 }\n'
        'I3 = { terminal = "I6", mode = "ultrasonic", below = 20 }\n'
        'M1 = { terminal = "M2", reverse = true }\nM2 = "M1"\nL1 = "O7"\nC1 = "C3"\n',
        encoding="utf-8",
    )
    robot = dataclasses.replace(
        load_robot(robot_file), initial_state=table.robot.initial_state, initial_timer=table.robot.initial_timer
    )
    return compile_table(Table(robot=robot, events=table.events, rows=table.rows, path=table.path))


def pwm_of(line: dict) -> list[int]:
    """O1..O8 for the wiring above, worked out by hand: M1 reversed on M2 (O3/O4), M2 on M1, L1 on O7."""
    pwm = [0] * 8
    m1, m2 = -line["M1"], line["M2"]
    pwm[2 if m1 > 0 else 3] = abs(m1) * 64
    pwm[0 if m2 > 0 else 1] = abs(m2) * 64
    pwm[6] = line["L1"] * 64
    return pwm


class StopAt:
    """A sink that ends the run its own way at a given tick."""

    def __init__(self, tick: int, how: str) -> None:
        self.tick, self.how = tick, how

    def start(self, info: object) -> None:
        pass

    def block(self, block: TickBlock) -> None:
        if block.start == self.tick:
            if self.how == "ctrl-c":
                raise KeyboardInterrupt
            if self.how == "sigterm":
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(1)  # the handler raises in the meantime
            if self.how == "bug":
                raise RuntimeError("a bug in a sink")

    def end(self, end: RunEnd) -> None:
        pass


@pytest.mark.parametrize(
    ("how", "reason"), [("end", "done"), ("ctrl-c", "interrupted"), ("sigterm", "terminated"), ("bug", "error")]
)
def test_every_stop_path_zeroes_every_output_in_the_exchange_before_stop_online(
    how: str, reason: str, flavour: dict
) -> None:
    with FakeTxt(**flavour) as fake:
        if how == "bug":
            with pytest.raises(RuntimeError, match="a bug in a sink"):
                drive(bumberbot(), fake, ticks=40, sinks=(StopAt(20, how),))
            end_reason = "error"
        else:
            end = drive(bumberbot(), fake, ticks=40, sinks=(StopAt(20, how),))
            end_reason = end.reason
    assert end_reason == reason
    pwm = [r.fields["pwm"] for r in fake.requests("ExchangeData")]
    assert any(any(p) for p in pwm)  # the motors ran before the stop
    assert fake.last_exchange_before_stop().fields["pwm"] == [0] * 8
    assert fake.names()[-2:] == ["StopOnline", "closed"]


@pytest.mark.parametrize("fault", ["silent", "late", "garbage", "wrong_id"])
def test_a_faulty_link_ends_the_run_as_link_lost_with_the_outputs_zeroed_where_the_link_allows(
    fault: str, flavour: dict
) -> None:
    with FakeTxt(fault=(fault, 15), **flavour) as fake:
        started = time.monotonic()
        end = drive(bumberbot(), fake, ticks=100, timeout_s=0.1)
        took = time.monotonic() - started
    assert end.reason == "link_lost" and end.exit_code == 3 and 13 <= end.ticks <= 15, end
    assert took < 2.0
    what = {
        "silent": "no answer",
        "late": "no answer",
        "garbage": "malformed reply",
        "wrong_id": "wrong response id 0xBAC9723E",
    }[fault]
    assert what in end.message
    assert fake.last_exchange_before_stop().fields["pwm"] == [0] * 8  # the fake still reads what it is sent


def test_a_closed_socket_ends_the_run_as_link_lost(flavour: dict) -> None:
    with FakeTxt(fault=("close", 15), **flavour) as fake:
        end = drive(bumberbot(), fake, ticks=100)
    assert end.reason == "link_lost" and "closed the connection" in end.message
    assert "StopOnline" not in fake.names()  # nothing more can be sent: the controller stops on its own


def test_a_late_reply_within_the_deadline_is_a_late_tick_not_a_lost_link() -> None:
    with FakeTxt(fault=("late", 10), late_s=0.03) as fake:
        end = drive(bumberbot(), fake, ticks=30, timeout_s=0.2)
    assert end.reason == "done" and end.late_ticks >= 1 and end.worst_late_s > 0.02


def test_a_stall_longer_than_the_behind_limit_ends_the_run_as_behind() -> None:
    with FakeTxt(fault=("late", 10), late_s=0.3) as fake:
        end = drive(bumberbot(), fake, ticks=30, timeout_s=1.0, behind_limit_s=0.2)
    assert end.reason == "behind" and end.exit_code == 5 and "behind the wall clock" in end.message
    assert "one tick started" in end.message  # a stall, said as one
    assert fake.last_exchange_before_stop().fields["pwm"] == [0] * 8


def test_a_txt_a_little_slower_than_the_tick_on_every_tick_ends_the_run_as_behind() -> None:
    # 14 ms per exchange: each tick only a few ms late (the grid starts again every other tick, and no tick
    # comes near the limit), but the table's time falls 4 ms behind the wall clock every tick: past 0.2 s
    # within some 50 ticks. A busy machine only makes it slower.
    with FakeTxt(drift_s=0.004) as fake:
        end = drive(bumberbot(), fake, ticks=400, behind_limit_s=0.2)
    assert end.reason == "behind" and end.late_ticks >= 3 and end.ticks < 200, end
    assert "cannot keep the table's 10 ms tick" in end.message and "% slow" in end.message
    assert fake.last_exchange_before_stop().fields["pwm"] == [0] * 8


def test_the_paced_clock_sleeps_to_a_fixed_grid_and_starts_it_again_after_a_stall() -> None:
    now, slept = [100.0], []

    def sleep(seconds: float) -> None:
        slept.append(round(seconds, 6))
        now[0] += seconds

    clock = RealTimeClock(0.01, now=lambda: now[0], sleep=sleep)
    clock.start()
    assert clock.wait(0) == 0.0 and slept == []  # due at once: no sleep, not late
    now[0] += 0.004
    assert clock.wait(1) == 0.0 and slept == [0.006]  # early: sleeps to the grid, no drift
    now[0] += 0.013  # tick 2 starts 3 ms late: less than half a tick, the grid stays
    assert round(clock.wait(2), 6) == 0.003 and clock.wait(3) == 0.0 and slept[-1] == 0.007
    now[0] += 0.05  # a stall: tick 4 starts 40 ms late, and the grid starts again from it
    assert round(clock.wait(4), 6) == 0.04 and round(clock.behind_s, 6) == 0.04  # the table's time lost the stall
    assert clock.wait(5) == 0.0 and slept[-1] == 0.01  # one tick after the late one, not 40 ms behind
    assert round(clock.behind_s, 6) == 0.04  # and it stays lost: nothing is made up in a burst
