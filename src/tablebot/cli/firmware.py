"""Firmware commands: ``build`` (a .hex for a board), ``flash`` (avrdude) and ``monitor`` (the trace)."""

from __future__ import annotations

import sys
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from tablebot import registry
from tablebot.cli.app import app
from tablebot.cli.common import (
    FORCE_OPT,
    ROBOT_OPT,
    TABLE_ARG,
    console,
    err_console,
    guarded,
    load,
    out_file,
)
from tablebot.diagnostics import fail, severity_word
from tablebot.escape import plain, shell_word, terminal
from tablebot.i18n import N_, _, localise, ngettext

if TYPE_CHECKING:  # the firmware tools are imported when a command runs: `--help` stays quick
    from tablebot.firmware.build import Firmware


#: ``--board``'s choices: every registered board back-end.
BoardName = StrEnum("BoardName", {b.name: b.name for b in registry.backends("board")})  # type: ignore[misc]

BOARD_OPT = typer.Option(
    ...,
    "--board",
    help=" or ".join(f"{b.name} ({b.help})" if b.help else b.name for b in registry.backends("board")) + ".",
)
OUT_OPT = typer.Option(None, "--out", help="Folder for the firmware (default: build/firmware/BOARD).")


def _build(table: Path, board: BoardName, out: Path | None, robot: Path | None) -> Firmware:
    machine = load(table, robot)[1]
    backend = registry.exporter(board.value)
    assert backend is not None  # --board's choices are the registered boards
    done = backend.export(machine, out, registry.ExportOptions())
    for line in done.lines:
        console.print(terminal(str(localise(line))))
    return done.value


@app.command("build")
@guarded
def build_cmd(
    table: Path = TABLE_ARG, board: BoardName = BOARD_OPT, out: Path | None = OUT_OPT, robot: Path | None = ROBOT_OPT
) -> None:
    """Build firmware (.hex and .elf) running the table every tick and streaming its trace."""
    _build(table, board, out, robot)


@app.command("flash")
@guarded
def flash_cmd(
    table: Path = typer.Argument(
        ..., metavar="TABLE_OR_HEX", help="Table (built first) or a firmware .hex built by `tablebot build`."
    ),
    board: BoardName = BOARD_OPT,
    port: str = typer.Option(..., "--port", help="Serial port of the board's bootloader (/dev/ttyACM0, COM3)."),
    out: Path | None = OUT_OPT,
    baud: int | None = typer.Option(None, "--baud", min=1, help="Bootloader speed (default: the board file's)."),
    programmer: str | None = typer.Option(None, "--programmer", help="avrdude programmer (default: the board's)."),
    dry_run: bool = typer.Option(False, "--dry-run", help="Print the avrdude command instead of running it."),
    robot: Path | None = ROBOT_OPT,
) -> None:
    """Write the firmware to a board with avrdude (untested here: no board is attached to CI)."""
    from tablebot.firmware.boards import load_board
    from tablebot.firmware.flash import NOTES, avrdude_command, check_hex, flash

    if not port.strip():
        raise fail("--port", N_("the port is empty"), N_("give the board's serial port, such as /dev/ttyACM0 or COM3"))
    if table.suffix.lower() == ".hex":
        check_hex(table)
        hexfile = table
    else:
        hexfile = _build(table, board, out, robot).hex
    command = avrdude_command(load_board(board.value), hexfile, port, baud, programmer)
    console.print(terminal(" ".join(shell_word(word) for word in command)))
    if dry_run:
        return
    if board.value in NOTES:
        err_console.print(f"{severity_word('note')}: {localise(NOTES[board.value])}")
    status = flash(command)
    if status:
        raise fail(
            "avrdude",
            N_("avrdude failed with exit status {status}", status=status),
            N_("check --port, the cable and the board; the Uno needs no button, the ftDuino a reset just before"),
        )


@app.command("monitor")
@guarded
def monitor_cmd(
    source: str = typer.Argument(
        ..., metavar="PORT_OR_FILE", help="Serial port (/dev/ttyACM0, COM3) or a file of captured UART bytes."
    ),
    table: Path = typer.Option(..., "--table", help="The table the firmware was built from (names states)."),
    out: Path | None = typer.Option(None, "--out", help="Trace file (JSON Lines; default: standard output)."),
    baud: int = typer.Option(115200, "--baud", min=1, help="Serial speed of the trace stream."),
    ticks: int | None = typer.Option(None, "--ticks", min=1, help="Stop after this many ticks."),
    seconds: float | None = typer.Option(
        None, "--seconds", min=0.001, help="Stop a serial port after this many seconds."
    ),
    robot: Path | None = ROBOT_OPT,
    force: bool = FORCE_OPT,
) -> None:
    """Decode a firmware's trace stream into the core's JSON Lines trace, one line per tick."""
    from tablebot.files import PendingFile
    from tablebot.firmware.monitor import chunks_from, monitor

    machine = load(table, robot)[1]
    chunks = chunks_from(source, baud, seconds)

    def warn(text: str) -> None:
        err_console.print(plain(str(localise(text))), markup=False, soft_wrap=True)  # the source is the user's words

    if out is None:
        count = monitor(machine, chunks, sys.stdout, source, ticks, warn)
    else:
        pending = PendingFile(out_file(out, "--out"))
        try:
            count = monitor(machine, chunks, pending.stream, source, ticks, warn)
        except BaseException:  # Ctrl-C on a serial port: keep what came, under a name that says so
            err_console.print(_("kept the ticks so far in {path}").format(path=terminal(str(pending.keep_partial()))))
            raise
        pending.commit()
        err_console.print(
            ngettext("wrote {path} ({n} tick)", "wrote {path} ({n} ticks)", count).format(
                path=terminal(str(out)), n=count
            )
        )
