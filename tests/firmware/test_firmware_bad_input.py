"""Regression tests from a review of ``build``, ``monitor``, ``flash`` and ``export --to robopro-rpp`` with
bad input: each is a located error with a hint and exit code 2, never a traceback or a silent wrong file."""

from __future__ import annotations

import random
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.cli.common import load
from tablebot.diagnostics import TableBotError
from tablebot.firmware.boards import load_board, wire
from tablebot.firmware.framing import Decoder, encode
from tablebot.formats.inputs_csv import load_inputs
from tablebot.machine import compile_table
from tablebot.replay import replay
from tablebot.robopro.rpp_edit import rewrite
from tablebot.robot import load_robot
from tablebot.testing.random_tables import random_inputs, random_table

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from typing import Any

    from typer.testing import Result

    from tablebot.machine import Machine

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot"
ROBOT_TEXT = (EXAMPLE / "robot.toml").read_text(encoding="utf-8")
runner = CliRunner()


def invoke(*args: str) -> Result:
    result = runner.invoke(app, list(args))
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    return result


def wiring_errors(tmp_path: Path, extra: str, board: str = "uno") -> list[str]:
    path = tmp_path / "robot.toml"
    path.write_text(ROBOT_TEXT + extra, encoding="utf-8")
    with pytest.raises(TableBotError) as info:
        wire(load_robot(path), load_board(board))
    return [d.render() for d in info.value.diagnostics]


# --- build: wiring onto a board -------------------------------------------------------------------


def test_board_section_errors_name_their_line(tmp_path: Path) -> None:
    lines = ROBOT_TEXT.count("\n")
    found = wiring_errors(tmp_path, '\n[board.uno]\nI3 = "D99"\nI4 = 5\nX9 = "D4"\n')
    path = tmp_path / "robot.toml"
    assert any(e.startswith(f"{path}:{lines + 3}: error: input I3 cannot use 'D99'") for e in found), found
    assert any(
        e.startswith(f"{path}:{lines + 4}: error: [board.uno] I4 must be a terminal name, not 5") and 'I4 = "D2"' in e
        for e in found
    ), found
    assert any(e.startswith(f"{path}:{lines + 5}: error: [board.uno] maps 'X9'") for e in found), found


def test_a_terminal_in_the_wrong_case_gets_the_right_spelling(tmp_path: Path) -> None:
    (found,) = wiring_errors(tmp_path, '\n[board.uno]\nI7 = "a2"\n')
    assert "hint: terminal names are case-sensitive: write 'A2'" in found


def test_too_many_inputs_name_the_inputs_line_and_what_to_do(tmp_path: Path) -> None:
    robot = ROBOT_TEXT.replace('I8 = "left phototransistor"\n', 'I8 = "left"\nI1 = "a"\nI2 = "b"\nI6 = "c"\nI9 = "d"\n')
    path = tmp_path / "robot.toml"
    path.write_text(robot, encoding="utf-8")
    with pytest.raises(TableBotError) as info:
        wire(load_robot(path), load_board("uno"))
    (found,) = [d.render() for d in info.value.diagnostics]
    line = robot.splitlines().index('I9 = "d"') + 1
    assert found.startswith(f"{path}:{line}: error: the uno board has no free terminal for input I9")
    assert "are all taken: use fewer inputs, or another board" in found


# --- monitor --------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def bumberbot() -> tuple[Machine, list[dict[str, Any]]]:
    _, machine = load(EXAMPLE)
    return machine, list(replay(machine, load_inputs(EXAMPLE / "inputs.csv", machine)))[:50]


def test_monitor_of_a_missing_file_says_so(tmp_path: Path) -> None:
    result = invoke("monitor", str(tmp_path / "capture.bin"), "--table", str(EXAMPLE))
    assert result.exit_code == 2 and "no such file, and not a serial port name" in result.output


def test_monitor_of_a_folder_says_so(tmp_path: Path) -> None:
    result = invoke("monitor", str(tmp_path), "--table", str(EXAMPLE))
    assert result.exit_code == 2 and "is a folder, not a capture file or serial port" in result.output


@pytest.mark.parametrize("data", [b"", bytes(random.Random(3).randrange(256) for _ in range(3000))])
def test_monitor_of_garbage_is_an_error_not_an_empty_trace(tmp_path: Path, data: bytes) -> None:
    capture = tmp_path / "garbage.bin"
    capture.write_bytes(data)
    result = invoke("monitor", str(capture), "--table", str(EXAMPLE))
    assert result.exit_code == 2 and f"no trace frame in {len(data)} bytes" in result.output
    assert result.stdout == ""


def test_a_stream_of_another_table_without_hello_is_refused_with_few_warnings(tmp_path: Path) -> None:
    rng = random.Random(0)
    table = random_table(rng)
    other = compile_table(table)
    stream = encode(other, list(replay(other, random_inputs(rng, table, 200))))
    capture = tmp_path / "other.bin"
    capture.write_bytes(stream[stream.index(b"\x7eT") :])  # from the first tick frame: no hello
    result = invoke("monitor", str(capture), "--table", str(EXAMPLE))
    assert result.exit_code == 2 and "tick frames are impossible for this table" in result.output
    assert result.output.count("warning:") == 21 and "not this table's firmware?" in result.output


def test_a_truncated_stream_keeps_its_whole_frames(
    tmp_path: Path, bumberbot: tuple[Machine, list[dict[str, Any]]]
) -> None:
    machine, trace = bumberbot
    capture = tmp_path / "cut.bin"
    capture.write_bytes(encode(machine, trace)[:-5])
    result = invoke("monitor", str(capture), "--table", str(EXAMPLE))
    assert result.exit_code == 0 and len(result.stdout.splitlines()) == len(trace) - 1
    assert "bytes at the end are not a whole frame" in result.output


def test_checksum_problems_give_stream_positions_not_chunk_positions(
    bumberbot: tuple[Machine, list[dict[str, Any]]],
) -> None:
    machine, trace = bumberbot
    stream = bytearray(encode(machine, trace))
    stream[15 + 7 * 12 + 5] ^= 0x55  # inside tick frame 7 (after the 15-byte hello; 12 bytes a frame)
    decoder = Decoder(machine)
    for at in range(0, len(stream), 7):
        decoder.feed(bytes(stream[at : at + 7]))
    assert decoder.problems and all("of this chunk" not in p for p in decoder.problems)
    positions = [int(p.split("byte ")[1].split(";")[0]) for p in decoder.problems if "checksum" in p]
    assert positions == [15 + 7 * 12], decoder.problems


@pytest.mark.parametrize("option", [["--ticks", "0"], ["--ticks", "-1"], ["--baud", "0"]])
def test_monitor_options_out_of_range_are_usage_errors(tmp_path: Path, option: list[str]) -> None:
    result = invoke("monitor", str(tmp_path / "x.bin"), "--table", str(EXAMPLE), *option)
    assert result.exit_code == 2 and option[0] in result.output


# --- flash --dry-run ------------------------------------------------------------------------------


def test_flash_refuses_a_file_that_is_not_intel_hex(tmp_path: Path) -> None:
    bad = tmp_path / "fw.hex"
    bad.write_text("garbage\n", encoding="utf-8")
    result = invoke("flash", str(bad), "--board", "uno", "--port", "/dev/ttyACM0", "--dry-run")
    assert result.exit_code == 2 and f"{bad}:1:1: error: not an Intel HEX file" in result.output


def test_flash_refuses_an_empty_port_and_a_bad_baud(tmp_path: Path) -> None:
    good = tmp_path / "fw.hex"
    good.write_text(":00000001FF\n", encoding="utf-8")
    result = invoke("flash", str(good), "--board", "uno", "--port", "", "--dry-run")
    assert result.exit_code == 2 and "--port: error: the port is empty" in result.output
    result = invoke("flash", str(good), "--board", "uno", "--port", "COM3", "--baud", "-5", "--dry-run")
    assert result.exit_code == 2 and "--baud" in result.output


def test_flash_prints_a_command_that_a_shell_can_run(tmp_path: Path) -> None:
    good = tmp_path / "my fw.hex"
    good.write_text(":00000001FF\n", encoding="utf-8")
    result = invoke("flash", str(good), "--board", "uno", "--port", "/dev/tty ACM0", "--dry-run")
    assert result.exit_code == 0
    assert f"-P '/dev/tty ACM0' -b 115200 -D -U 'flash:w:{good}:i'" in result.stdout


# --- export --to robopro-rpp -----------------------------------------------------------------------

LISTS = {"Event": [1, 2], "Action": [3, 4], "Timer": [5, 6]}


def test_inits_without_a_value_are_replaced_not_copied_blank() -> None:
    text = (
        '<cvg><o classname="ftProDataArray1D" name="Event" N="1"><init/></o>\n'
        '<o classname="ftProDataArray1D" name="Action" N="1"><init value="0"/></o>\n'
        '<o classname="ftProDataArray1D" name="Timer" N="1"></o></cvg>'
    )
    new = rewrite(text, LISTS)
    # ROBO Pro's own form (issue 20): <init value="…"> and </init> on lines of their own
    assert '<init value="1">\n</init>' in new and '<init value="2">\n</init>' in new and "<init/>" not in new
    assert '<init value="3"/>' in new and '<init value="6">\n    </init>' in new


def test_a_list_written_as_an_empty_element_is_a_clear_error() -> None:
    text = '<cvg>\n<o classname="ftProDataArray1D" name="Event" N="1"/>\n</cvg>'
    with pytest.raises(TableBotError) as info:
        rewrite(text, {"Event": [1]}, "prog.rpp")
    (found,) = info.value.diagnostics
    assert found.line == 2 and "empty element" in found.message and "never closed" not in found.message


def test_binary_and_unknown_encoding_files_are_not_programs(tmp_path: Path) -> None:
    binary = tmp_path / "b.rpp"
    binary.write_bytes(b"\x89PNG\r\n\x1a\n\xd3\xff")
    result = invoke("export", str(EXAMPLE), "--to", "robopro-rpp", "--into", str(binary))
    assert result.exit_code == 2 and "not a ROBO Pro program: byte 0 is not utf-8 text" in result.output
    odd = tmp_path / "o.rpp"
    odd.write_text('<?xml version="1.0" encoding="klingon"?>\n<cvg></cvg>\n', encoding="utf-8")
    result = invoke("export", str(EXAMPLE), "--to", "robopro-rpp", "--into", str(odd))
    assert result.exit_code == 2 and "unknown text encoding 'klingon'" in result.output


# --- output paths -----------------------------------------------------------------------------------


def test_build_out_naming_a_file_is_refused_before_building(tmp_path: Path) -> None:
    afile = tmp_path / "afile"
    afile.write_text("keep", encoding="utf-8")
    result = invoke("build", str(EXAMPLE), "--board", "uno", "--out", str(afile))
    assert result.exit_code == 2 and "--out names a file, not a folder" in result.output


def test_monitor_out_naming_a_folder_is_refused(
    tmp_path: Path, bumberbot: tuple[Machine, list[dict[str, Any]]]
) -> None:
    machine, trace = bumberbot
    capture = tmp_path / "uart.bin"
    capture.write_bytes(encode(machine, trace))
    result = invoke("monitor", str(capture), "--table", str(EXAMPLE), "--out", str(tmp_path))
    assert result.exit_code == 2 and "--out names a folder, not a file" in result.output


def test_a_lamp_on_an_ftduino_output_a_motor_drives_is_already_used(tmp_path: Path) -> None:
    robot = (
        'name = "L"\ninitial_state = 1\n[motors]\nM1 = "a"\nM2 = "b"\n[lamps]\nL1 = "x"\n[board.ftduino]\nL1 = "O1"\n'
    )
    path = tmp_path / "robot.toml"
    path.write_text(robot, encoding="utf-8")
    with pytest.raises(TableBotError) as info:
        wire(load_robot(path), load_board("ftduino"))
    (found,) = [d.render() for d in info.value.diagnostics]
    assert found.startswith(f"{path}:9: error: lamp L1: terminal O1 is already used")
    full = robot.replace('M2 = "b"\n', 'M2 = "b"\nM3 = "c"\nM4 = "d"\n').replace('[board.ftduino]\nL1 = "O1"\n', "")
    path.write_text(full, encoding="utf-8")
    with pytest.raises(TableBotError, match=r"its lamp terminals \(O1, O2, O3, O4, O5, O6, O7, O8\) are all taken"):
        wire(load_robot(path), load_board("ftduino"))
