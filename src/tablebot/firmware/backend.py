"""``build --board uno`` and ``--board ftduino``: AVR firmware running the table, registered as back-ends; the
robot file's ``[board.NAME]`` sections are read here."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from tablebot.codegen import backend as c
from tablebot.diagnostics import Diagnostic
from tablebot.files import out_folder
from tablebot.i18n import N_
from tablebot.registry import ExportBackend, Exported, Exporter, ExportOptions, refused, register
from tablebot.robot import Robot
from tablebot.tomlfile import Source

if TYPE_CHECKING:
    from tablebot.machine import Machine


def read_section(src: Source, data: Any, robot: Robot) -> Any:
    from tablebot.firmware.boards import read_robot_boards

    return read_robot_boards(src, data, robot)


def fit_for(board: str) -> Any:
    def fit(machine: Machine) -> list[Diagnostic]:
        from tablebot.firmware.boards import load_board, wire

        return c.fit(machine) or refused(lambda: wire(machine.table.robot, load_board(board)))

    return fit


def export_for(board: str) -> Exporter:
    def export(machine: Machine, out: Path | None, options: ExportOptions) -> Exported:
        from tablebot.firmware.build import build
        from tablebot.firmware.several import build_several
        from tablebot.tables import several

        folder = out_folder(out or Path("build") / "firmware" / board, "--out")
        tables = several(machine.table)  # a robot of several tables: all of them in the tick interrupt
        firmware = build(machine, board, folder) if tables is None else build_several(tables, board, folder)
        wiring = firmware.wiring
        assert wiring is not None
        pins = ", ".join(
            f"{n}={t}"
            for kind in (wiring.inputs, wiring.motors, wiring.lamps, wiring.counters)
            for n, t in kind.items()
        )
        return Exported(
            (firmware.hex, firmware.elf),
            (
                N_(
                    "wrote {hex} and {elf} for {board}",
                    hex=str(firmware.hex),
                    elf=str(firmware.elf),
                    board=firmware.board.title,
                ),
                N_(
                    "flash {flash} bytes, static RAM {ram} bytes; wiring: {pins}",
                    flash=firmware.flash,
                    ram=firmware.ram,
                    pins=pins,
                ),
                N_("trace: {uart}, {baud} baud 8N1", uart=firmware.board.uart, baud=firmware.board.baud),
            ),
            value=firmware,
        )

    return export


UNO = register(
    ExportBackend(
        name="uno",
        board=True,
        makes="AVR firmware for an Arduino Uno with the Motor Shield Rev3",
        help="Arduino Uno + Motor Shield Rev3",
        fit=fit_for("uno"),
        section="board",
        read_section=read_section,
        export=export_for("uno"),
    )
)
FTDUINO = register(
    ExportBackend(
        name="ftduino",
        board=True,
        makes="AVR firmware for the ftDuino",
        fit=fit_for("ftduino"),
        section="board",
        read_section=read_section,
        export=export_for("ftduino"),
    )
)
