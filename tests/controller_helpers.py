"""Shared by the ROBO TX and ROBO Interface tests: the BumberBot wired to a serial controller, a run against an
emulator on a real pseudo-terminal, and sinks that end a run their own way."""

from __future__ import annotations

import dataclasses
import os
import signal
import time
from typing import Any

from core_helpers import EXAMPLE
from tablebot.engine import Engine
from tablebot.formats.table_read import load_table
from tablebot.loop import RealTimeClock, RunEnd, TickBlock, run
from tablebot.machine import Machine, compile_table

#: The document's wiring, as examples/bumberbot/robot.toml states it for every controller.
BUMBER_WIRING = {
    "I3": {"terminal": "I3", "mode": "switch", "pressed": 1},
    "I4": {"terminal": "I4", "mode": "switch", "pressed": 1},
    "I5": {"terminal": "I5", "mode": "switch", "pressed": 1},
    "I7": {"terminal": "I7", "mode": "phototransistor", "lit": 1},
    "I8": {"terminal": "I8", "mode": "phototransistor", "lit": 1},
    "M1": "M1",
    "M2": "M2",
}


def bumberbot(section: str, wiring: dict[str, Any] | None = None, example: str = "bumberbot") -> Machine:
    """An example's table on a robot whose ``section`` holds ``wiring`` (raw data, as a Robot made in code)."""
    table = load_table(EXAMPLE.parent / example / "table.csv")
    robot = dataclasses.replace(
        table.robot, sections={**table.robot.sections, section: BUMBER_WIRING if wiring is None else wiring}
    )
    return compile_table(dataclasses.replace(table, robot=robot))


class Record:
    """A sink that keeps every tick's block."""

    def __init__(self) -> None:
        self.blocks: list[TickBlock] = []

    def start(self, info: object) -> None:
        pass

    def block(self, block: TickBlock) -> None:
        self.blocks.append(block)

    def end(self, end: RunEnd) -> None:
        pass


class StopAt(Record):
    """Ends the run its own way at a given tick: Ctrl-C, SIGTERM to this process, or a bug."""

    def __init__(self, tick: int, how: str) -> None:
        super().__init__()
        self.tick, self.how = tick, how

    def block(self, block: TickBlock) -> None:
        super().block(block)
        if block.start != self.tick:
            return
        if self.how == "ctrl-c":
            raise KeyboardInterrupt
        if self.how == "sigterm":
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.05)  # the handler notes it; the loop ends the run before the next tick
        if self.how == "bug":
            raise RuntimeError("a bug in a sink")


def drive(
    machine: Machine, robot: Any, ticks: int | None = 30, sinks: tuple = (), behind_limit_s: float | None = None
) -> RunEnd:
    robot.connect()
    clock = RealTimeClock(machine.table.robot.tick_s)
    return run(
        Engine(machine),
        robot,
        clock=clock,
        sinks=list(sinks),
        ticks=ticks,
        target="test",
        behind_limit_s=behind_limit_s,
    )


def settle(emulator: Any, name: str | None = None, timeout_s: float = 2.0) -> None:
    """The emulator logs a request when it has read it whole: give it a moment after the client closed."""
    deadline = time.monotonic() + timeout_s
    count = len(emulator.log)
    while time.monotonic() < deadline:
        time.sleep(0.02)
        if (name is None or name in emulator.names()) and len(emulator.log) == count:
            return
        count = len(emulator.log)


def eventually(condition: Any, timeout_s: float = 2.0) -> bool:
    """Whether ``condition()`` becomes true within ``timeout_s`` (an emulator may still be busy with a late reply)."""
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True
