"""``tablebot build`` of a robot of several tables (issue 36 §2, tablebot.firmware.several): the BumberBot with its
lights built for the Uno by the command a user types runs under simavr as tablebot.engine.several does, and the
UART decoder refuses a damaged stream, saying where."""

from __future__ import annotations

import random
import shutil
from pathlib import Path

import pytest

from tablebot.codegen.packing import plan
from tablebot.diagnostics import TableBotError
from tablebot.engine.as_one import robot_machine
from tablebot.firmware.boards import load_board, wire
from tablebot.firmware.build import Firmware
from tablebot.firmware.several import decode, emulate_several
from tablebot.loading import Loaded
from tablebot.replay import replay_several
from tablebot.testing.several_cases import several_ticks
from test_run_cli import invoke

LIGHTS = Path(__file__).resolve().parents[1] / "examples" / "bumberbot-lights"
pytestmark = pytest.mark.skipif(not shutil.which("avr-gcc"), reason="no avr-gcc")


def test_the_built_firmware_runs_both_tables_as_the_engine_does(tmp_path: Path) -> None:
    result = invoke("build", LIGHTS, "--board", "uno", "--out", tmp_path / "fw")
    assert result.exit_code == 0, result.output
    assert "tb_firmware_several.c" in {p.name for p in (tmp_path / "fw" / "src").iterdir()}
    tables = Loaded.open(LIGHTS).tables
    assert tables is not None
    board = load_board("uno")  # the firmware as the command wrote it
    firmware = Firmware(tmp_path / "fw" / "tablebot.elf", tmp_path / "fw" / "tablebot.hex", board,
                        wire(tables.robot, board), plan(tables.machines[0]), 0, 0)
    inputs = several_ticks(random.Random(2), tables, 300, density=0.2)
    got = emulate_several(firmware, tables, inputs, tmp_path / "run", robot_machine(tables))
    assert got == list(replay_several(tables, inputs))
    stream = (tmp_path / "run" / "uart.bin").read_bytes()
    broken = bytearray(stream)
    broken[40] ^= 0x01
    with pytest.raises(TableBotError, match=r"bad checksum|no frame starts here"):
        decode(tables, bytes(broken))
