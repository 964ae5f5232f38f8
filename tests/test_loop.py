"""The run loop with a scripted fake robot: the seam every robot (simulator, controller) goes through."""

from __future__ import annotations

import time
from collections.abc import Sequence

import pytest

from core_helpers import EXAMPLE
from tablebot.engine import Engine
from tablebot.formats.inputs_csv import TickInput
from tablebot.formats.table_read import load_table
from tablebot.loop import LinkLost, Reading, RealTimeClock, RunEnd, RunInfo, TickBlock, Watchdog, run
from tablebot.machine import compile_table
from tablebot.replay import replay

pytestmark = [pytest.mark.realtime]


def bumberbot() -> Engine:
    return Engine(compile_table(load_table(EXAMPLE / "table.csv")))


class ScriptedRobot:
    """Reads a fixed list of masks; records every write and every stop; can fail or stall on a tick."""

    def __init__(
        self,
        masks: Sequence[int],
        fail_at: int | None = None,
        stall_at: int | None = None,
        error: type[Exception] = RuntimeError,
    ) -> None:
        self.masks, self.fail_at, self.stall_at, self.error = list(masks), fail_at, stall_at, error
        self.reads = 0
        self.writes: list[tuple[int, ...]] = []
        self.events: list[str] = []

    def open(self) -> None:
        self.events.append("open")

    def read(self) -> Reading:
        tick = self.reads
        self.reads += 1
        if tick == self.fail_at:
            raise self.error(f"sensor bus fault at tick {tick}")
        if tick == self.stall_at:
            time.sleep(30)
        return Reading(self.masks[tick % len(self.masks)])

    def write(self, outputs: Sequence[int]) -> None:
        self.writes.append(tuple(outputs))

    def stop(self) -> None:
        self.events.append(f"stop after {len(self.writes)} writes")
        self.writes.append((0,) * len(self.writes[-1] if self.writes else (0, 0)))

    def close(self) -> None:
        self.events.append("close")


class Collect:
    def __init__(self) -> None:
        self.blocks: list[TickBlock] = []
        self.info: RunInfo | None = None
        self.ended: RunEnd | None = None

    def start(self, info: RunInfo) -> None:
        self.info = info

    def block(self, block: TickBlock) -> None:
        self.blocks.append(block)

    def end(self, end: RunEnd) -> None:
        self.ended = end


MASKS = [0, 0, 16, 0, 0, 0, 8, 2, 3, 1, 0, 4, 0, 0]


def test_the_loop_takes_the_engines_decisions_and_writes_its_outputs() -> None:
    engine, robot, sink = bumberbot(), ScriptedRobot(MASKS), Collect()
    end = run(engine, robot, sinks=[sink], ticks=len(MASKS))
    assert end.reason == "done" and end.exit_code == 0 and end.ticks == len(MASKS)
    expected = list(replay(engine.machine, [TickInput(m) for m in MASKS]))
    motors = [(line["M1"], line["M2"]) for line in expected]
    assert robot.writes[: len(MASKS)] == motors
    assert robot.events == ["open", f"stop after {len(MASKS)} writes", "close"]
    assert [b.rows[0] for b in sink.blocks] == [-1 if line["row"] is None else line["row"] for line in expected]
    assert sink.ended == end


def test_a_failing_read_stops_the_outputs_in_the_same_tick_and_says_why() -> None:
    robot, sink = ScriptedRobot(MASKS, fail_at=5), Collect()
    with pytest.raises(RuntimeError, match="sensor bus fault"):
        run(bumberbot(), robot, sinks=[sink], ticks=100)
    assert robot.writes[-1] == (0, 0) and robot.events[-2:] == ["stop after 5 writes", "close"]
    assert sink.ended is not None and sink.ended.reason == "error" and "sensor bus fault" in sink.ended.message
    assert sink.ended.ticks == 5


def test_a_lost_link_ends_the_run_without_raising() -> None:
    robot, sink = ScriptedRobot(MASKS, fail_at=3, error=LinkLost), Collect()
    end = run(bumberbot(), robot, sinks=[sink], ticks=100)
    assert end.reason == "link_lost" and end.exit_code == 3 and end.ticks == 3
    assert robot.writes[-1] == (0, 0)


def test_a_stalled_tick_trips_the_watchdog() -> None:
    robot, sink = ScriptedRobot(MASKS, stall_at=4), Collect()
    started = time.monotonic()
    end = run(bumberbot(), robot, sinks=[sink], ticks=100, watchdog=Watchdog(0.05))
    assert time.monotonic() - started < 5
    assert end.reason == "watchdog" and end.ticks == 4 and "50 ms" in end.message
    assert robot.writes[-1] == (0, 0) and robot.events[-1] == "close"


def test_ctrl_c_in_an_open_ended_run_is_the_normal_stop() -> None:
    class StopAfter(Collect):
        def block(self, block: TickBlock) -> None:
            super().block(block)
            if len(self.blocks) == 7:
                raise KeyboardInterrupt

    sink = StopAfter()
    end = run(bumberbot(), ScriptedRobot(MASKS), sinks=[sink])
    assert end.reason == "stopped" and end.complete and end.ticks == 7
    sink2 = StopAfter()
    end = run(bumberbot(), ScriptedRobot(MASKS), sinks=[sink2], ticks=100)
    assert end.reason == "interrupted" and not end.complete and end.exit_code == 130


def test_a_real_time_clock_paces_ticks() -> None:
    engine = bumberbot()
    started = time.monotonic()
    end = run(engine, ScriptedRobot(MASKS), clock=RealTimeClock(0.01), ticks=10)
    assert end.reason == "done" and time.monotonic() - started >= 0.09
