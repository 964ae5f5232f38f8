"""``run --on txt://HOST[:PORT]`` (a TXT, or a TXT 4.0 running ftrobopy_server) and ``txt://auto``, registered as
a live back-end; the robot file's ``[txt]`` wiring is read here (the TXT 4.0 export uses the same section)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from tablebot.diagnostics import Diagnostic, fail
from tablebot.i18n import N_
from tablebot.registry import LinkOptions, LiveBackend, Opened, refused, register
from tablebot.robot import Robot
from tablebot.tomlfile import Source

if TYPE_CHECKING:
    from tablebot.machine import Machine

PORT = 65000
ADDRESSES = ("txt://192.168.7.2 (USB)", "txt://HOST:PORT", "txt://auto")
FIRMWARE_HINT = N_("update the TXT's firmware to 4.6.6 or later")
ADDRESS_HINT = N_("write --on txt://192.168.7.2 (USB), txt://HOST:PORT or txt://auto")
CONNECT_HINT = N_(
    "is the controller on and connected? A TXT answers at 192.168.7.2 (USB), 192.168.8.2 (Wi-Fi) "
    "or 192.168.9.2 (Bluetooth); a TXT 4.0 needs ftrobopy_server running (docs/controllers.md)"
)
FASTER = N_("the TXT on its USB cable, txt://192.168.7.2, rather than Wi-Fi or Bluetooth")


def read_section(src: Source, data: Any, robot: Robot) -> Any:
    from tablebot.hw.txt.wiring import read_robot_txt

    return read_robot_txt(src, data, robot)


def fit(machine: Machine) -> list[Diagnostic]:
    """What the TXT's terminals cannot hold (its ``[txt]`` wiring checked against the table)."""
    from tablebot.hw.txt.wiring import txt_wiring

    return refused(lambda: txt_wiring(machine))


def parse_address(text: str, hint: str) -> tuple[str | None, int]:
    """``txt://HOST[:PORT]`` -> (HOST, PORT); ``txt://auto[:PORT]`` -> (None, PORT or 65000); anything else
    a located error."""
    if not text.startswith("txt://"):
        raise fail("--on", N_("unknown target {text!r}", text=text), hint)
    rest = text[len("txt://") :].rstrip("/")
    host, _, port = rest.rpartition(":") if ":" in rest else (rest, "", "")
    if not host or (port and not (port.isdigit() and 0 < int(port) < 65536)):
        raise fail("--on", N_("{text!r} is not txt://HOST or txt://HOST:PORT", text=text), hint)
    return None if host == "auto" else host, int(port) if port else PORT


def open_txt(machine: Machine, link: LinkOptions) -> Opened:
    """The robot, where it is and what it is: the wiring checked (nothing moves if the table does not
    fit), then the controller found (an address counts when it answers as a TXT), asked who it is, and its
    round trip timed against the table's tick."""
    from tablebot.hw.link_speed import check_link
    from tablebot.hw.txt import link as txt_link
    from tablebot.hw.txt.controller import FirmwareTooOld, TxtRobot
    from tablebot.hw.txt.wiring import txt_wiring
    from tablebot.loop import LinkLost

    host, port = parse_address(link.address, link.hint_or(ADDRESS_HINT))
    wiring = txt_wiring(machine)
    if host is None:
        host, tried = txt_link.find_controller(txt_link.AUTO_HOSTS, port)
        if host is None:
            raise fail("--on", N_("txt://auto found no TXT: {tried}", tried="; ".join(tried)), CONNECT_HINT)
    bot = TxtRobot(wiring, host, port, link_timeout_s=link.timeout_s(machine.table.robot.tick_s))
    try:
        status = bot.connect()
    except FirmwareTooOld as exc:
        raise fail("--on", exc.args[0], FIRMWARE_HINT) from None
    except LinkLost as exc:
        raise fail("--on", exc.args[0], CONNECT_HINT) from None
    # Before going online only QueryStatus can be asked; it costs the network's round trip, as each exchange
    # does (a TXT then paces exchanges at 10 ms on its own side).
    warnings = check_link(
        bot,
        machine,
        link,
        bot.link.query_status,
        N_("a round trip to the controller"),
        faster=FASTER,
        connect_hint=CONNECT_HINT,
    )
    return Opened(bot, bot.target, f"{status.device} {status.version_text}", warnings)


TXT = register(
    LiveBackend(
        name="txt",
        makes="a TXT (or TXT 4.0 with ftrobopy_server) driven live by `tablebot run`",
        help="txt://HOST[:PORT] (a TXT, or a TXT 4.0 running ftrobopy_server), txt://auto (USB, Wi-Fi, Bluetooth "
        "addresses)",
        fit=fit,
        section="txt",
        read_section=read_section,
        open=open_txt,
        addresses=ADDRESSES,
    )
)
