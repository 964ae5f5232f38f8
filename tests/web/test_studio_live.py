"""The studio's live robot: the simulated BumberBot through the run loop, paced by the page's clock.
It makes the same run as ``tablebot sim``; pausing, single steps and hand-held inputs act between ticks."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import pytest

from core_helpers import EXAMPLE
from tablebot.cli.common import load
from tablebot.loop import RunEnd, RunInfo, TickBlock
from tablebot.sim.model.scene import scene_for
from tablebot.sim.runner import simulate
from tablebot.sim.simrobot import SimRobot
from tablebot.web.live import LiveRun, PageClock

pytestmark = [pytest.mark.realtime]

if TYPE_CHECKING:
    from collections.abc import Callable

    from tablebot.sim.model.scene import Scene


class Rows:
    def __init__(self) -> None:
        self.rows: list[int] = []
        self.states: list[int] = []
        self.xs: list[float] = []
        self.ended: RunEnd | None = None

    def start(self, info: RunInfo) -> None:
        pass

    def block(self, block: TickBlock) -> None:
        self.rows += [int(r) for r in block.rows]
        self.states += [int(s) for s in block.states]
        self.xs += list(block.extra["x"])

    def end(self, end: RunEnd) -> None:
        self.ended = end


def wait_until(condition: Callable[[], bool], timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.01)


@pytest.fixture(scope="module")
def scene() -> Scene:
    table, machine = load(EXAMPLE)
    return scene_for(table, machine)


def test_the_live_run_is_the_sim_commands_run(scene: Scene) -> None:
    ticks = 3000
    expected = simulate(scene, ticks * scene.tick_s, seed=3)
    sink = Rows()
    live = LiveRun(scene, SimRobot(scene, seed=3, record_history=False), speed="max", paused=False, sinks=[sink])
    wait_until(lambda: len(sink.rows) >= ticks)
    live.close()
    assert not live.running and sink.ended is not None and sink.ended.reason == "stopped"
    assert sink.states[:ticks] == expected.states.tolist()
    assert sink.xs[:ticks] == pytest.approx(expected.kept_rows()[:ticks, 0].tolist(), abs=1e-5)


def test_pause_step_and_a_held_input(scene: Scene) -> None:
    sink = Rows()
    live = LiveRun(scene, SimRobot(scene, record_history=False), speed="max", paused=True, sinks=[sink])
    time.sleep(0.2)
    assert sink.rows == []  # paused from the start: not a single tick
    live.step()
    wait_until(lambda: len(sink.rows) == 1)
    assert sink.rows == [7]  # Seek - Turn (line 9) fires on the first tick
    state_1 = scene.machine.state_index(1)
    assert sink.states == [state_1]
    live.hold(scene.machine.input_bits["I3"], True)
    live.step()
    wait_until(lambda: len(sink.rows) == 2)
    assert sink.rows[1] == 1 and scene.machine.states[sink.states[1]] == 20  # line 3: I3 -> collision
    time.sleep(0.1)
    assert len(sink.rows) == 2  # still paused
    live.close()


def test_the_clock_keeps_ten_times_real_time() -> None:
    clock = PageClock(10.0, 0.01, paused=False)
    clock.start()
    started = time.monotonic()
    late = [clock.wait(tick) for tick in range(200)]  # 2 s of robot time
    assert 0.19 <= time.monotonic() - started < 0.5 and max(late) < 0.05
