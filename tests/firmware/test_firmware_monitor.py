"""The UART trace framing and ``tablebot monitor``; ``tablebot flash``'s avrdude command line (the only
part of flashing that can be tested without a board)."""

from __future__ import annotations

import json
import random
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.cli.common import load
from tablebot.codegen.packing import plan
from tablebot.firmware.boards import load_board
from tablebot.firmware.flash import avrdude_command
from tablebot.firmware.framing import SYNC, Decoder, encode, hello_frame, tick_frame
from tablebot.formats.inputs_csv import load_inputs
from tablebot.machine import compile_table
from tablebot.replay import replay
from tablebot.testing.random_tables import Shape, random_inputs, random_table

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from typing import Any

    from tablebot.machine import Machine

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot"
runner = CliRunner()


@pytest.fixture(scope="module")
def bumberbot() -> tuple[Machine, list[dict[str, Any]]]:
    _, machine = load(EXAMPLE)
    return machine, list(replay(machine, load_inputs(EXAMPLE / "inputs.csv", machine)))


def test_frames_round_trip_in_any_chunking(bumberbot: tuple[Machine, list[dict[str, Any]]]) -> None:
    machine, trace = bumberbot
    stream = encode(machine, trace)
    decoder = Decoder(machine)
    rng = random.Random(1)
    lines, at = [], 0
    while at < len(stream):
        step = rng.randint(1, 40)
        lines += decoder.feed(stream[at : at + step])
        at += step
    assert lines == trace and decoder.problems == [] and len(decoder.hellos) == 1


def test_bumberbot_tick_frame_is_twelve_bytes(bumberbot: tuple[Machine, list[dict[str, Any]]]) -> None:
    machine, trace = bumberbot
    frame = tick_frame(machine, plan(machine), trace[0])
    # sync, 'T', tick (2 bytes), event, row, state, timer (2), M1, M2, check
    assert frame[:2] == bytes([SYNC, ord("T")]) and len(frame) == 12
    assert sum(frame[1:]) % 256 == 0


def test_random_table_with_counters_and_lamps_round_trips() -> None:
    rng = random.Random(4)
    table = random_table(rng, Shape(counters=2, lamps=2, rows=300, states=40))
    machine = compile_table(table)
    trace = list(replay(machine, random_inputs(rng, table, 200)))
    assert plan(machine).row.size == 2  # 300 rows: 16-bit row numbers in the frame
    assert Decoder(machine).feed(encode(machine, trace)) == trace


def test_corruption_is_skipped_and_reported(bumberbot: tuple[Machine, list[dict[str, Any]]]) -> None:
    machine, trace = bumberbot
    layout = plan(machine)
    frames = [tick_frame(machine, layout, line) for line in trace[:6]]
    broken = bytearray(frames[2])
    broken[5] ^= 0xFF  # the checksum no longer matches
    stream = (
        b"\x00\x7e\x99" + hello_frame(machine, layout) + b"".join(frames[:2]) + bytes(broken) + b"".join(frames[3:])
    )
    decoder = Decoder(machine)
    lines = decoder.feed(stream)
    assert [line["tick"] for line in lines] == [0, 1, 3, 4, 5]
    assert any("checksum" in p for p in decoder.problems)
    assert any("ticks 2..2 missing" in p for p in decoder.problems)


def test_tick_numbers_unwrap_past_16_bits(bumberbot: tuple[Machine, list[dict[str, Any]]]) -> None:
    machine, trace = bumberbot
    line = dict(trace[5])
    lines = [dict(line, tick=t) for t in (65534, 65535, 65536, 65537)]
    assert [out["tick"] for out in Decoder(machine).feed(encode(machine, lines))] == [65534, 65535, 65536, 65537]


def test_monitor_file_writes_the_core_trace(bumberbot: tuple[Machine, list[dict[str, Any]]], tmp_path: Path) -> None:
    machine, trace = bumberbot
    capture = tmp_path / "uart.bin"
    capture.write_bytes(encode(machine, trace))
    out = tmp_path / "trace.jsonl"
    result = runner.invoke(app, ["monitor", str(capture), "--table", str(EXAMPLE), "--out", str(out)])
    assert result.exit_code == 0, result.output
    expected = runner.invoke(app, ["trace", str(EXAMPLE), "--inputs", str(EXAMPLE / "inputs.csv")]).stdout
    assert out.read_text() == expected
    assert [json.loads(line) for line in out.read_text().splitlines()] == trace


def test_monitor_refuses_firmware_of_another_table(
    bumberbot: tuple[Machine, list[dict[str, Any]]], tmp_path: Path
) -> None:
    machine, trace = bumberbot
    other = compile_table(random_table(random.Random(2)))
    capture = tmp_path / "uart.bin"
    capture.write_bytes(hello_frame(other, plan(other)) + encode(machine, trace[:3]))
    result = runner.invoke(app, ["monitor", str(capture), "--table", str(EXAMPLE)])
    assert result.exit_code == 2
    assert "runs another table" in result.output


def test_monitor_stops_after_ticks(bumberbot: tuple[Machine, list[dict[str, Any]]], tmp_path: Path) -> None:
    machine, trace = bumberbot
    capture = tmp_path / "uart.bin"
    capture.write_bytes(encode(machine, trace))
    result = runner.invoke(app, ["monitor", str(capture), "--table", str(EXAMPLE), "--ticks", "5"])
    assert result.exit_code == 0 and len(result.stdout.splitlines()) == 5


def test_monitor_missing_port_is_a_clear_error() -> None:
    result = runner.invoke(app, ["monitor", "/dev/tablebot-no-such-port", "--table", str(EXAMPLE)])
    assert result.exit_code == 2
    assert "/dev/tablebot-no-such-port" in result.output


# --- flash: the command line only (no board here) ---------------------------------------------


def test_avrdude_command_for_the_uno_and_the_ftduino(tmp_path: Path) -> None:
    hexfile = tmp_path / "fw.hex"
    assert avrdude_command(load_board("uno"), hexfile, "/dev/ttyACM0") == [
        "avrdude",
        "-p",
        "atmega328p",
        "-c",
        "arduino",
        "-P",
        "/dev/ttyACM0",
        "-b",
        "115200",
        "-D",
        "-U",
        f"flash:w:{hexfile}:i",
    ]
    ftduino = avrdude_command(load_board("ftduino"), hexfile, "COM5", baud=19200)
    assert ftduino[1:7] == ["-p", "atmega32u4", "-c", "avr109", "-P", "COM5"] and ftduino[8] == "19200"


def test_flash_dry_run_builds_then_prints_the_command(tmp_path: Path) -> None:
    result = runner.invoke(
        app, ["flash", str(EXAMPLE), "--board", "uno", "--port", "/dev/ttyUSB0", "--out", str(tmp_path), "--dry-run"]
    )
    assert result.exit_code == 0, result.output
    assert (tmp_path / "tablebot.hex").is_file()
    assert (
        f"avrdude -p atmega328p -c arduino -P /dev/ttyUSB0 -b 115200 -D -U flash:w:{tmp_path}/tablebot.hex:i"
        in result.output
    )


def test_flash_of_a_missing_hex_is_refused(tmp_path: Path) -> None:
    result = runner.invoke(app, ["flash", str(tmp_path / "none.hex"), "--board", "uno", "--port", "x", "--dry-run"])
    assert result.exit_code == 2 and "firmware file not found" in result.output
