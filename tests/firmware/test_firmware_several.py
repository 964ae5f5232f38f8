"""``tablebot build`` of a robot of several tables (issue 36 §2, tablebot.firmware.several): the BumberBot with its
lights built for the Uno by the command a user types runs under simavr as tablebot.engine.several does,
``tablebot monitor`` reads its stream as the same trace, and a damaged stream is refused by the harness's decoder
and resynchronised by monitor, each saying where."""

from __future__ import annotations

import json
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

LIGHTS = Path(__file__).resolve().parents[2] / "examples" / "bumberbot-lights"
pytestmark = pytest.mark.skipif(not shutil.which("avr-gcc"), reason="no avr-gcc")


def test_the_built_firmware_runs_both_tables_as_the_engine_does(tmp_path: Path) -> None:
    result = invoke("build", LIGHTS, "--board", "uno", "--out", tmp_path / "fw")
    assert result.exit_code == 0, result.output
    assert "tb_firmware_several.c" in {p.name for p in (tmp_path / "fw" / "src").iterdir()}
    tables = Loaded.open(LIGHTS).tables
    assert tables is not None
    board = load_board("uno")  # the firmware as the command wrote it
    firmware = Firmware(
        tmp_path / "fw" / "tablebot.elf",
        tmp_path / "fw" / "tablebot.hex",
        board,
        wire(tables.robot, board),
        plan(tables.machines[0]),
        0,
        0,
    )
    inputs = several_ticks(random.Random(2), tables, 300, density=0.2)
    got = emulate_several(firmware, tables, inputs, tmp_path / "run", robot_machine(tables))
    assert got == list(replay_several(tables, inputs))
    uart = tmp_path / "run" / "uart.bin"
    monitored = invoke("monitor", uart, "--table", LIGHTS)  # what a user reads off the board's serial port
    assert monitored.exit_code == 0, monitored.output
    traced = [json.loads(line) for line in monitored.output.splitlines() if line.startswith("{")]
    assert traced[: len(got)] == got
    broken = bytearray(uart.read_bytes())
    broken[40] ^= 0x01
    with pytest.raises(TableBotError, match=r"bad checksum at byte \d+"):
        decode(tables, bytes(broken))
    (tmp_path / "broken.bin").write_bytes(bytes(broken))
    resynced = invoke("monitor", tmp_path / "broken.bin", "--table", LIGHTS)
    assert resynced.exit_code == 0 and "warning: bad checksum at byte" in resynced.output
    assert "warning: ticks 1..1 missing from the stream" in resynced.output  # the damaged frame, and no other
