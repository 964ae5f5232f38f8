"""The live arena: one simulated robot driven through :func:`tablebot.loop.run` in a thread, paced by
a clock the page controls (play, pause, single tick, 1×/10×/as fast as possible), watched by a sink
that keeps only what the page draws (the latest tick, fired rows, a decimated path).

Every tick is simulated; only the drawing is thinned out, so a fast run never falls behind.
"""

from __future__ import annotations

import ctypes
import functools
import gc
import math
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from tablebot.engine import Engine
from tablebot.engine.as_one import RobotEngine
from tablebot.loop import Reading, RunEnd, RunInfo, Sink, TickBlock, run
from tablebot.sim import columns as L
from tablebot.sim.model.scene import Scene
from tablebot.sim.simrobot import SimRobot, light_keys
from tablebot.web.errors import INTERNAL, log

PATH_STEP_M = 0.005  # a path point every 5 mm (or at a state change): what the eye can see
MAX_FIRED = 200  # fired rows kept between two frames
SPEEDS = {"1": 1.0, "10": 10.0, "max": 0.0}  # 0: as fast as possible
# A counterexample played in the arena: its last ticks, up to the one where the property breaks, 10 times slower
# than real time (a person sees each of them), the ticks before at real time or faster (at most LEAD_S seconds)
SLOW_TICKS = 12
SLOW_SPEED = 0.1
LEAD_S = 3.0


class StopRequested(KeyboardInterrupt):
    """The page reset or closed the run: the loop's normal way to end an open-ended run."""


class PageClock:
    """Paces ticks at ``speed`` × real time (0 = no waiting); holds while paused; releases single steps."""

    free_running = False  # one tick at a time, so that pausing and stepping act between ticks
    behind_s = 0.0  # the page sets the pace (paused, stepped, 10x): never judged against the wall clock

    def __init__(self, speed: float, tick_s: float, paused: bool) -> None:
        self.tick_s = tick_s
        self.speed = speed
        self.paused = paused
        self.steps = 0
        self.stopping = False
        self._cond = threading.Condition()
        self._origin = (0.0, 0)  # (wall time, tick) the pacing counts from

    def start(self) -> None:
        self._rebase(0)

    def _rebase(self, tick: int) -> None:
        self._origin = (time.monotonic(), tick)

    def wait(self, tick: int) -> float:
        with self._cond:
            while True:
                if self.stopping:
                    raise StopRequested("reset by the page")
                if not self.paused:
                    break
                if self.steps:
                    self.steps -= 1
                    self._rebase(tick + 1)
                    return 0.0
                self._cond.wait(0.25)
            speed, (t0, k0) = self.speed, self._origin
        if not speed:
            return 0.0
        due = t0 + (tick - k0) * self.tick_s / speed
        ahead = due - time.monotonic()
        if ahead > 0:
            time.sleep(ahead)
            return 0.0
        if -ahead > 0.5:  # hopelessly behind (the machine was busy): start counting again from here
            self._rebase(tick)
        return -ahead

    def control(
        self,
        *,
        paused: bool | None = None,
        speed: float | None = None,
        step: bool = False,
        stop: bool = False,
        tick: int = 0,
    ) -> None:
        with self._cond:
            if paused is not None and paused != self.paused:
                self.paused = paused
                self._rebase(tick)
            if speed is not None:
                self.speed = speed
                self._rebase(tick)
            if step:
                self.steps += 1
            if stop:
                self.stopping = True
            self._cond.notify_all()


class HandInputs:
    """Wraps the simulated robot: inputs the user holds by hand (while paused) replace what the sensors
    read; each reading also carries the bumper switches and light levels the arena draws."""

    def __init__(self, robot: SimRobot) -> None:
        self.robot = robot
        self.light_keys = light_keys(robot.scene)
        self.forced: dict[int, bool] = {}  # input bit -> held on (True) or off (False)
        self.script: list[int] = []  # whole masks to read next (a counterexample), one per tick
        self.on_script: Callable[[int], None] | None = None  # told how many scripted masks are left, at each

    def open(self) -> None:
        self.robot.open()

    def read(self) -> Reading:
        reading = self.robot.read()
        mask = reading.mask
        if self.script:
            mask = self.script.pop(0)
            if self.on_script is not None:
                self.on_script(len(self.script))
        for bit, on in self.forced.items():
            mask = mask | bit if on else mask & ~bit
        s = self.robot.s
        extra = {
            **(reading.extra or {}),
            "sensed": reading.mask,
            "bumpers": int(s[L.BUMP_FR] > 0) | int(s[L.BUMP_FL] > 0) << 1 | int(s[L.BUMP_REAR] > 0) << 2,
            "light": (float(s[L.LIGHT_R]), float(s[L.LIGHT_L])),
        }
        return Reading(mask, reading.pulses, extra)

    def write(self, outputs: Sequence[int]) -> None:
        self.robot.write(outputs)

    def stop(self) -> None:
        self.robot.stop()

    def close(self) -> None:
        self.robot.close()


@dataclass
class Latest:
    tick: int = -1
    state: int = 0
    prev_state: int = 0
    timer: int = 0
    event: int = 0
    mask: int = 0
    row: int = -1
    outputs: tuple[int, ...] = ()
    extra: dict[str, Any] | None = None
    prev_extra: dict[str, Any] | None = None  # the tick before's (a robot's other tables: their states before it)


class FrameSink:
    """Collects what the page draws between two frames; the web server drains it with :meth:`frame`."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.latest = Latest()
        self._fired: list[list[int]] = []
        self._path: list[list[float | str]] = []
        self._last_point: tuple[float, float, str] | None = None
        self.ended: RunEnd | None = None
        self.ticks_seen = 0
        self._states: Sequence[Any] = ()
        #: A robot of several tables, another table's tab shown: the path is coloured by that table's states,
        #: read from this field of each tick (``lights.state``); None: by the main table's
        self.colour_by: str | None = None

    def start(self, info: RunInfo) -> None:
        with self._lock:
            self.latest.state = info.engine.state  # the state before the first tick (why it fired)
            self._states = info.engine.machine.states

    def block(self, block: TickBlock) -> None:
        extra = block.extra
        with self._lock:
            latest = self.latest
            for k in range(len(block)):
                state, row = int(block.states[k]), int(block.rows[k])
                if row >= 0 and len(self._fired) < MAX_FIRED:
                    self._fired.append([block.start + k, row])
                if "x" in extra:
                    by = extra.get(self.colour_by) if self.colour_by else None
                    self._add_point(
                        float(extra["x"][k]),
                        float(extra["y"][k]),
                        str(by[k] if by is not None else self._states[state]),
                    )
                latest.prev_state, latest.state = latest.state, state
            k = len(block) - 1
            latest.tick, latest.timer, latest.event = block.start + k, int(block.timers[k]), int(block.events[k])
            latest.mask, latest.row = int(block.masks[k]), int(block.rows[k])
            latest.outputs = tuple(int(v) for v in block.outputs[k])
            latest.prev_extra = {name: values[k - 1] for name, values in extra.items()} if k else latest.extra
            latest.extra = {name: values[k] for name, values in extra.items()}
            self.ticks_seen += len(block)

    def _add_point(self, x: float, y: float, state: str) -> None:
        last = self._last_point
        if last is None or last[2] != state or math.hypot(x - last[0], y - last[1]) >= PATH_STEP_M:
            self._path.append([round(x, 4), round(y, 4), state])
            self._last_point = (x, y, state)

    def end(self, end: RunEnd) -> None:
        self.ended = end

    def frame(self) -> dict[str, Any] | None:
        """What happened since the last frame, or None if nothing did."""
        with self._lock:
            if not self._fired and not self._path and self.latest.tick < 0:
                return None
            frame = {"fired": self._fired, "path": self._path, "latest": self.latest}
            self._fired, self._path = [], []
            latest = self.latest
            self.latest = Latest(**{**latest.__dict__})
        return frame


class LiveRun:
    """A simulated robot running a table in a thread, through the loop, until :meth:`close`."""

    def __init__(
        self,
        scene: Scene,
        robot: SimRobot,
        speed: str = "1",
        paused: bool = True,
        on_end: Callable[[RunEnd], None] | None = None,
        sinks: Sequence[Sink] = (),
    ) -> None:
        self.scene = scene
        # a robot of several tables runs whole: every table stepped together, the lights table's lamps too
        self.engine: Engine | RobotEngine = Engine(scene.machine) if scene.tables is None else RobotEngine(scene.tables)
        self.robot = HandInputs(robot)
        self.robot.on_script = self._scripted
        self.sink = FrameSink()
        self.sinks = [self.sink, *sinks]
        self.clock = PageClock(SPEEDS[speed], scene.tick_s, paused)
        self.speed = speed
        self.error: str | None = None
        self._on_end = on_end
        self._thread = threading.Thread(target=self._run, name="tablebot-live", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        try:
            end = run(self.engine, self.robot, clock=self.clock, sinks=self.sinks, target="studio")
        except Exception:  # a bug: the page says so, the terminal gets the traceback
            log.exception("the live robot stopped")
            self.error = INTERNAL
            return
        if self._on_end:
            self._on_end(end)

    @property
    def paused(self) -> bool:
        return self.clock.paused

    def play(self) -> None:
        self.clock.control(paused=False, tick=self.engine.tick)

    def pause(self) -> None:
        self.clock.control(paused=True, tick=self.engine.tick)

    def step(self) -> None:
        self.clock.control(paused=True, step=True, tick=self.engine.tick)

    def set_speed(self, speed: str) -> None:
        self.speed = speed
        self.clock.control(speed=SPEEDS[speed], tick=self.engine.tick)

    def hold(self, bit: int, on: bool | None) -> None:
        """Hold an input on or off by hand (None: let the sensor decide again)."""
        if on is None:
            self.robot.forced.pop(bit, None)
        else:
            self.robot.forced[bit] = on

    def play_script(self, masks: list[int]) -> None:
        """Play these input masks (a counterexample) at once: its lead-in at real time or faster, its last
        ticks slowly, and pause on its last tick (where the property shows broken)."""
        self.robot.script = list(masks)
        lead = len(masks) - SLOW_TICKS
        speed = SLOW_SPEED if lead <= 0 else max(1.0, lead * self.scene.tick_s / LEAD_S)
        self.clock.control(paused=False, speed=speed, tick=self.engine.tick)

    def _scripted(self, left: int) -> None:
        """Called in the run's thread as each scripted mask is read (``left``: how many remain)."""
        if left == SLOW_TICKS:
            self.clock.control(speed=SLOW_SPEED, tick=self.engine.tick)
        elif left == 0:  # this tick is the last: the run stops after it, and goes on at the page's speed
            self.clock.control(paused=True, speed=SPEEDS[self.speed], tick=self.engine.tick)

    def close(self, timeout: float = 5.0) -> None:
        self.clock.control(stop=True)
        self._thread.join(timeout)

    @property
    def running(self) -> bool:
        return self._thread.is_alive()


def give_back_memory() -> None:
    """Hand the memory closed tabs used back to the system. Their connections leave reference cycles that
    only a full collection frees, and Python runs one rarely in a process with as many objects as the
    studio (it grew by some 60 KB a connection, never given back: benchmarks/studio_tabs.py); then glibc
    keeps what was freed in its pools, and ``malloc_trim`` returns the free pages (without glibc: nothing
    to do). A full collection holds every thread for tens of milliseconds: once for tabs that close together."""
    gc.collect()
    trim = _malloc_trim()
    if trim is not None:
        trim(0)


@functools.cache
def _malloc_trim() -> Callable[[int], int] | None:
    try:
        return ctypes.CDLL(None).malloc_trim
    except (OSError, AttributeError, TypeError):  # no C library to ask, or not glibc
        return None
