"""``tablebot flash``: the avrdude command line that writes a firmware .hex to a board's bootloader.
It cannot be tested without a board: the tests check the command line it builds (``--dry-run``)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

from tablebot.diagnostics import fail
from tablebot.firmware.boards import Board
from tablebot.i18n import N_

#: What to tell the user before avrdude runs, per board.
NOTES = {
    "ftduino": "press the ftDuino's reset button just before flashing: its bootloader listens for a few "
    "seconds after a reset (the Arduino IDE does this with a 1200-baud touch)",
}


def avrdude_command(
    board: Board,
    hexfile: Path,
    port: str,
    baud: int | None = None,
    programmer: str | None = None,
    avrdude: str = "avrdude",
) -> list[str]:
    """avrdude with the board's part, programmer and speed; -D as the Arduino IDE uses it (the
    bootloader erases the pages it writes)."""
    settings = board.avrdude
    return [
        avrdude,
        "-p",
        settings["part"],
        "-c",
        programmer or settings["programmer"],
        "-P",
        port,
        "-b",
        str(baud or settings["baud"]),
        "-D",
        "-U",
        f"flash:w:{hexfile}:i",
    ]


def check_hex(path: Path) -> None:
    """Refuse, before avrdude sees it, a file that is missing or is not Intel HEX (every record starts ':')."""
    if not path.is_file():
        raise fail(path, N_("firmware file not found"), N_("build it first: tablebot build TABLE --board BOARD"))
    with path.open("rb") as f:
        first = f.readline().strip()
    if not first.startswith(b":"):
        raise fail(
            path,
            N_("not an Intel HEX file: its first line does not start with ':'"),
            N_("give the .hex file that `tablebot build` wrote, or the table itself"),
            1,
            1,
        )


def flash(command: list[str]) -> int:
    """Run avrdude; its own output goes to the terminal. Returns its exit status."""
    if not shutil.which(command[0]):
        raise fail(
            command[0],
            N_("avrdude not found"),
            N_(
                "install it (Debian, Ubuntu: sudo apt-get install avrdude; macOS: brew install avrdude; "
                "Windows: avrdude's release zip, its folder on PATH: docs/install.md) or use --dry-run and run "
                "the printed command where avrdude is"
            ),
        )
    return subprocess.run(command, check=False).returncode
