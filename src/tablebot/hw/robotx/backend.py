"""``run --on robotx://DEVICE`` and ``robotx://auto``: the ROBO TX Controller driven live over fish.X1,
registered as a live back-end; the robot file's ``[robotx]`` wiring is read here."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from tablebot.diagnostics import Diagnostic, fail
from tablebot.hw.serial_address import parse_serial_address
from tablebot.i18n import N_
from tablebot.registry import LinkOptions, LiveBackend, Opened, refused, register
from tablebot.robot import Robot
from tablebot.tomlfile import Source

if TYPE_CHECKING:
    from tablebot.machine import Machine

ADDRESSES = ("robotx://auto", "robotx:///dev/ttyACM0 (USB)", "robotx:///dev/rfcomm0 (Bluetooth)", "robotx://COM3")
ADDRESS_HINT = N_(
    "write --on robotx://auto, robotx:///dev/ttyACM0 (USB), robotx:///dev/rfcomm0 (Bluetooth) or robotx://COM3"
)
CONNECT_HINT = N_(
    "is the ROBO TX on and connected? Over USB it is a serial port /dev/ttyACM* (USB id 221d:1000); "
    "over Bluetooth pair it and bind an rfcomm device first (docs/controllers.md)"
)
FASTER = N_("the ROBO TX on its USB cable, robotx:///dev/ttyACM0, rather than Bluetooth")


def read_section(src: Source, data: Any, robot: Robot) -> Any:
    from tablebot.hw.robotx.wiring import read_robot_robotx

    return read_robot_robotx(src, data, robot)


def fit(machine: Machine) -> list[Diagnostic]:
    """What the ROBO TX's terminals cannot hold (its ``[robotx]`` wiring checked against the table)."""
    from tablebot.hw.robotx.wiring import robotx_wiring

    return refused(lambda: robotx_wiring(machine))


def open_robotx(machine: Machine, link: LinkOptions) -> Opened:
    """The wiring checked (nothing is opened if the table does not fit), the port found, and the controller
    asked who it is (it must answer fish.X1), and its exchange timed against the table's tick."""
    from tablebot.hw.link_speed import check_link
    from tablebot.hw.robotx.controller import ZERO, RobotxRobot
    from tablebot.hw.robotx.link import find
    from tablebot.hw.robotx.wiring import robotx_wiring
    from tablebot.loop import LinkLost

    device = parse_serial_address(link.address, "robotx", link.hint_or(ADDRESS_HINT))
    wiring = robotx_wiring(machine)
    if device is None:
        found = find()
        if found is None:
            raise fail(
                "--on", N_("robotx://auto found no serial port that answers as a ROBO TX Controller"), CONNECT_HINT
            )
        device = found[0]
    bot = RobotxRobot(wiring, device, link_timeout_s=link.timeout_s(machine.table.robot.tick_s))
    try:
        info = bot.connect()
    except LinkLost as exc:
        raise fail("--on", exc.args[0], CONNECT_HINT) from None
    warnings = check_link(
        bot,
        machine,
        link,
        lambda: bot.link.exchange(ZERO, bot.link.setup_timeout_s),
        N_("one exchange with the ROBO TX"),
        faster=FASTER,
        connect_hint=CONNECT_HINT,
    )
    return Opened(bot, bot.target, f"{info.device} {info.version_text}", warnings)


ROBOTX = register(
    LiveBackend(
        name="robotx",
        makes="a ROBO TX Controller driven live over fish.X1 by `tablebot run`",
        help="robotx://DEVICE (a ROBO TX on its USB or Bluetooth serial port), robotx://auto",
        fit=fit,
        section="robotx",
        read_section=read_section,
        open=open_robotx,
        addresses=ADDRESSES,
    )
)
