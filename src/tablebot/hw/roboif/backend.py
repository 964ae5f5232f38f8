"""``run --on roboif://DEVICE`` and ``roboif://auto``: the ROBO Interface driven live over its serial online
protocol, registered as a live back-end; the robot file's ``[roboif]`` wiring is read here."""

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

ADDRESSES = ("roboif://auto", N_("roboif:///dev/ttyUSB0 (its serial port)"), "roboif://COM1")
ADDRESS_HINT = N_("write --on roboif://auto, roboif:///dev/ttyUSB0 or roboif://COM1 (the interface's serial port)")
CONNECT_HINT = N_(
    "is the ROBO Interface on and its serial port connected (38400 baud)? tablebot drives it on its "
    "serial port only, not on its USB port (docs/controllers.md)"
)
FASTER = N_(
    "a ROBO TX or a TXT on its USB cable: the interface's serial port runs at 38400 baud only, and tablebot "
    "does not drive its USB port"
)


def read_section(src: Source, data: Any, robot: Robot) -> Any:
    from tablebot.hw.roboif.wiring import read_robot_roboif

    return read_robot_roboif(src, data, robot)


def fit(machine: Machine) -> list[Diagnostic]:
    """What the ROBO Interface cannot hold (its ``[roboif]`` wiring checked against the table)."""
    from tablebot.hw.roboif.wiring import roboif_wiring

    return refused(lambda: roboif_wiring(machine))


def open_roboif(machine: Machine, link: LinkOptions) -> Opened:
    """The wiring checked (nothing is opened if the table does not fit), the port found, the interface greeted
    (it must answer as a ROBO Interface), and its exchange timed against the table's tick."""
    from tablebot.hw.link_speed import check_link
    from tablebot.hw.roboif import protocol as wire
    from tablebot.hw.roboif.controller import OFF, RoboifRobot
    from tablebot.hw.roboif.link import find
    from tablebot.hw.roboif.wiring import roboif_wiring
    from tablebot.loop import LinkLost

    device = parse_serial_address(link.address, "roboif", link.hint_or(ADDRESS_HINT))
    wiring = roboif_wiring(machine)
    if device is None:
        device = find()
        if device is None:
            raise fail("--on", N_("roboif://auto found no serial port that answers as a ROBO Interface"), CONNECT_HINT)
    bot = RoboifRobot(wiring, device, link_timeout_s=link.timeout_s(machine.table.robot.tick_s))
    try:
        bot.connect()
    except LinkLost as exc:
        raise fail("--on", exc.args[0], CONNECT_HINT) from None
    line = N_(
        "its {count} bytes alone take {ms:.1f} ms on the {baud}-baud line",
        count=wire.REQUEST_BYTES + wire.REPLY_BYTES,
        ms=1000 * wire.EXCHANGE_LINE_S,
        baud=wire.BAUD,
    )
    warnings = check_link(
        bot,
        machine,
        link,
        lambda: bot.link.exchange(*OFF, bot.link.setup_timeout_s),
        N_("one exchange with the ROBO Interface"),
        line=line,
        faster=FASTER,
        connect_hint=CONNECT_HINT,
    )
    return Opened(bot, bot.target, "ROBO Interface (serial, 38400 baud)", warnings)


ROBOIF = register(
    LiveBackend(
        name="roboif",
        makes="a ROBO Interface driven live over its serial port by `tablebot run`",
        help="roboif://DEVICE (a ROBO Interface on its serial port), roboif://auto",
        fit=fit,
        section="roboif",
        read_section=read_section,
        open=open_roboif,
        addresses=ADDRESSES,
    )
)
