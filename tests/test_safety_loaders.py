"""No traceback, ever (issue 14): each reproduced crash of a loader is now a located error; every input has a
size limit; a Western European Excel's CSV is read with a note (issue 15); the CLI's last line of defence."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from core_helpers import EXAMPLE, MINI_ROBOT, write_table
from tablebot import csvtext
from tablebot.cli import INTERNAL_ERROR, app, main
from tablebot.diagnostics import TableBotError, notes_to
from tablebot.formats.table_read import load_table
from tablebot.formats.trace_lines import read_trace
from tablebot.robopro.lists import read_lists
from tablebot.robot import load_robot

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Never

    from typer.testing import Result

    from tablebot.diagnostics import Diagnostic

runner = CliRunner()
HEADER = "description,state,T,A,B,M1,M2,timer,next"


def error_of(call: Callable[..., object], *args: object) -> tuple[Diagnostic, ...]:
    with pytest.raises(TableBotError) as info:
        call(*args)
    return info.value.diagnostics


def cli(*args: object) -> Result:
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exc_info
    assert "Traceback" not in result.output
    return result


@pytest.mark.parametrize("nest", ["[", "{a="])
def test_toml_nested_500_levels_is_a_located_error(tmp_path: Path, nest: str) -> None:
    """Reproduced: RecursionError in tomllib."""
    close = "]" if nest == "[" else "}"
    path = tmp_path / "robot.toml"
    path.write_text(f'name = "x"\nweird = {nest * 500}1{close * 500}\n')
    (d,) = error_of(load_robot, path)
    assert d.line == 2 and "nested more than 32 levels" in d.message
    assert cli("check", EXAMPLE, "--robot", path).exit_code == 2


def test_counter_given_a_list_is_a_located_error(tmp_path: Path) -> None:
    """Reproduced: `[counters] C1 = ["M1"]` was a TypeError (unhashable list) in robot.py."""
    path = tmp_path / "robot.toml"
    path.write_text(MINI_ROBOT + '[counters]\nC1 = ["M1"]\nC2 = { motor = ["M2"] }\n')
    found = error_of(load_robot, path)
    assert [(d.line, "counts motor" in d.message) for d in found] == [(11, True), (12, True)]


def test_states_csv_with_a_superscript_digit(tmp_path: Path) -> None:
    """Reproduced: '²'.isdigit() is True but int('²') is a ValueError (robopro.lists)."""
    for name, text in (("event.csv", "97\n"), ("action.csv", "512\n"), ("timer.csv", "0\n")):
        (tmp_path / name).write_text(text)
    (tmp_path / "states.csv").write_text("number,name\n²,seek\n", encoding="utf-8")
    (d,) = error_of(read_lists, tmp_path)
    assert (d.line, d.column) == (2, 1) and "expected number,name" in d.message
    assert cli("import", tmp_path, "--from", "robopro").exit_code == 2


def test_dev_zero_stops_at_the_size_limit() -> None:
    """Reproduced: `tablebot check /dev/zero` read until MemoryError."""
    result = cli("check", "/dev/zero")
    assert result.exit_code == 2 and "larger than 16 MB" in result.stderr  # a table's limit


@pytest.mark.parametrize("loader", ["table", "robot", "inputs", "trace"])
def test_every_kind_of_input_has_a_size_limit(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, loader: str) -> None:
    monkeypatch.setattr(csvtext, "MAX_TEXT_BYTES", 1000)
    monkeypatch.setattr("tablebot.formats.table_read.MAX_TABLE_BYTES", 1000)
    monkeypatch.setattr("tablebot.tomlfile.MAX_TOML_BYTES", 1000)
    monkeypatch.setattr("tablebot.formats.trace_lines.MAX_TRACE_BYTES", 1000)
    path = tmp_path / "big"
    path.write_text("#" * 1001)
    calls = {
        "table": lambda: load_table(path),
        "robot": lambda: load_robot(path),
        "trace": lambda: read_trace(path),
        "inputs": lambda: csvtext.read_text(path),
    }
    with pytest.raises(TableBotError) as info:
        calls[loader]()
    assert "larger than 1000 bytes" in info.value.diagnostics[0].message


def test_toml_limit_is_a_megabyte(tmp_path: Path) -> None:
    path = tmp_path / "robot.toml"
    path.write_text("# " + "x" * (1 << 20) + "\n")
    (d,) = error_of(load_robot, path)
    assert "larger than 1 MB" in d.message


def test_toml_that_is_not_toml_does_not_echo_its_contents(tmp_path: Path) -> None:
    """A path named inside a file may point anywhere; the error about a file that is no TOML at all
    names the place, not the content (the parser's messages never quote the text)."""
    secret = tmp_path / "id_rsa"
    secret.write_text("-----BEGIN OPENSSH PRIVATE KEY-----\nb3BlbnNzaC1rZXktdjEAAAAABG5vbmUA\n")
    result = cli("check", EXAMPLE, "--robot", secret)
    assert result.exit_code == 2 and "TOML syntax" in result.stderr
    assert "b3BlbnNzaC1rZXk" not in result.stderr and "PRIVATE KEY" not in result.stderr


# --- Windows-1252 tables (issue 15) ---------------------------------------------------------------------


def test_cp1252_table_is_read_with_a_note(tmp_path: Path) -> None:
    text = f"{HEADER}\nZurück – à gauche €,1,1,,,3,3,10,1\n"
    path = write_table(tmp_path, text, MINI_ROBOT, encoding="cp1252")
    notes: list[Diagnostic] = []
    with notes_to(notes.append):
        table = load_table(path)
    assert table.rows[0].description == "Zurück – à gauche €"
    (note,) = notes
    assert note.severity == "note" and (note.line, note.column) == (2, 4) and "Windows-1252" in note.message
    result = cli("check", path)
    assert result.exit_code == 0 and "note: not UTF-8 (byte 0xfc); read as Windows-1252" in result.stderr


def test_latin1_byte_that_cp1252_lacks(tmp_path: Path) -> None:
    path = write_table(tmp_path, f"{HEADER}\n", MINI_ROBOT)
    path.write_bytes(f"{HEADER}\n".encode() + b"x\x81y,1,1,,,3,3,10,1\n")
    notes: list[Diagnostic] = []
    with notes_to(notes.append):
        assert load_table(path).rows[0].description == "x\x81y"
    assert "Latin-1" in notes[0].message


def test_cp1252_errors_are_located(tmp_path: Path) -> None:
    path = write_table(tmp_path, f"{HEADER}\nÉtat,1,1,,,9,3,10,1\n", MINI_ROBOT, encoding="cp1252")
    with notes_to(lambda note: None):
        (d,) = error_of(load_table, path)
    assert (d.line, d.column) == (2, 12) and "out of range" in d.message


def test_robot_file_is_not_guessed(tmp_path: Path) -> None:
    path = tmp_path / "robot.toml"
    path.write_bytes(MINI_ROBOT.replace("left switch", "Schalter für links").encode("cp1252"))
    (d,) = error_of(load_robot, path)
    assert "0xfc is not UTF-8" in d.message


# --- trace files ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('{"tick": 0}\n{"tick": 1\n', "line 2 is not JSON"),
        ('{"tick": 0}\n[1, 2]\n', "line 2 is JSON but not an object"),
        ("[" * 100000 + "]" * 100000 + "\n", "line 1 is not JSON"),
    ],
)
def test_bad_trace_files(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "t.jsonl"
    path.write_text(text)
    (d,) = error_of(read_trace, path)
    assert message in d.message and d.line == int(message.split()[1])


# --- the last line of defence ----------------------------------------------------------------------------


def _crash(*args: object, **kwargs: object) -> Never:
    raise RuntimeError("boom \x1b[31m")


def test_internal_error_is_one_line(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr("tablebot.cli.core.open_project", _crash)  # what trace calls first
    monkeypatch.setattr(sys, "argv", ["tablebot", "trace", str(EXAMPLE), "--inputs", str(EXAMPLE / "inputs.csv")])
    monkeypatch.delenv("TABLEBOT_DEBUG", raising=False)
    with pytest.raises(SystemExit) as info:
        main()
    assert info.value.code == INTERNAL_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "internal error: RuntimeError" in err and "TABLEBOT_DEBUG=1" in err
    assert "\x1b" not in err and "Traceback" not in err
    monkeypatch.setenv("TABLEBOT_DEBUG", "1")
    with pytest.raises(SystemExit):
        main()
    assert "Traceback" in capsys.readouterr().err


def test_python_dash_m_runs_the_cli() -> None:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run(
        [sys.executable, "-m", "tablebot.cli", "--help"],
        capture_output=True,
        text=True,
        env=env,
        check=False,
        cwd=Path(__file__).parent,
    )
    assert done.returncode == 0 and "check" in done.stdout
