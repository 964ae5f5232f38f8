"""A controller's serial link without a file descriptor, as on Windows (issue 34 §1): a COM port is a handle
there and select waits on sockets only, so tablebot.hw.serial_port reads and writes through pyserial's own
calls with the time left as their timeout (FD_IO False). Here that path drives the ROBO TX emulator on a real
pseudo-terminal: a run, a device that falls silent and one that hangs up end as they do through the descriptor."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from controller_helpers import bumberbot, drive, settle
from tablebot.hw import serial_port
from tablebot.hw.robotx.controller import RobotxRobot
from tablebot.hw.robotx.wiring import robotx_wiring
from tablebot.testing.robotx_emulator import RobotxEmulator


@pytest.fixture(autouse=True)
def without_descriptor(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    monkeypatch.setattr(serial_port, "FD_IO", False)
    yield


def robot_on(emulator: RobotxEmulator, timeout_s: float = 1.0) -> RobotxRobot:
    """Replies are due within ``timeout_s``: generous, as these tests run beside others on a busy machine."""
    return RobotxRobot(robotx_wiring(bumberbot("robotx")), emulator.device, link_timeout_s=timeout_s)


def test_a_run_greets_configures_and_exchanges_every_tick() -> None:
    with RobotxEmulator(lambda n: ([0, 0, int(n >= 10), 0, 0, 0, 0, 0], [0] * 4)) as emu:
        robot = robot_on(emu)
        end = drive(bumberbot("robotx"), robot, ticks=30)
        settle(emu)
    assert end.reason == "done" and end.ticks == 30, end
    assert robot.info is not None and robot.info.device == "ROBO TX-000"
    assert emu.names()[:3] == ["echo", "info", "config"] and emu.bad_frames == 0
    exchanges = emu.requests("exchange")
    assert len(exchanges) == 1 + 30 + 1 and exchanges[-1].fields["duty"] == [0] * 8


@pytest.mark.parametrize(("fault", "says"), [("silent", "no answer"), ("hang_up", "disconnected")])
def test_a_silent_or_vanished_device_ends_the_run_as_link_lost(fault: str, says: str) -> None:
    with RobotxEmulator(lambda n: ([0] * 8, [0] * 4), fault=(fault, 12)) as emu:
        end = drive(bumberbot("robotx"), robot_on(emu, timeout_s=0.5), ticks=60)
    assert end.reason == "link_lost" and end.ticks == 12, end
    assert says in end.message, end.message
