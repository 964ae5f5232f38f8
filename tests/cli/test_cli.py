"""The real `tablebot` command: check, export, import, trace, demo; errors exit 2 with located messages."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest
import typer.main
from typer.testing import CliRunner

from core_helpers import EXAMPLE, MINI_ROBOT, SEED_TSV, column_of, example_machine, write_table
from tablebot.cli import app
from tablebot.formats.table_read import load_table
from tablebot.machine import compile_table

if TYPE_CHECKING:
    from typer.testing import Result

runner = CliRunner()
LOCATED = re.compile(r"^(?P<path>\S.*?):(?P<line>\d+):(?P<column>\d+): error: .+$")
BAD_TABLE = """\
description,state,T,A,B,M1,M2,timer,next
ok,1,1,,,3,3,10,1
speed,1,1,,,9,3,10,1
timer,1,1,,,3,3,x,1
next,1,1,,,3,3,10,7
"""


def invoke(*args: object) -> Result:
    """Run the app in-process; anything but a clean exit (an escaped exception) fails the test."""
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exc_info
    return result


def assert_located_errors(stderr: str, count: int) -> list[re.Match]:
    """Every error line is file:line:column: error: …, each followed by a hint; no traceback."""
    assert "Traceback" not in stderr
    lines = stderr.splitlines()
    errors = [LOCATED.match(line) for line in lines if ": error: " in line]
    assert len(errors) == count and all(errors), stderr
    for i, line in enumerate(lines):
        if ": error: " in line:
            assert lines[i + 1].startswith("    hint: "), stderr
    return errors  # type: ignore[return-value]


# --- help ---------------------------------------------------------------------------------------------


def commands() -> dict[str, Any]:
    """The commands as the command line has them (click's, as typer builds them)."""
    return dict(typer.main.get_command(app).commands)  # type: ignore[attr-defined]


@pytest.mark.parametrize("command", ["check", "export", "import", "trace", "demo"])
def test_a_commands_help_says_what_it_does_and_lists_every_option(command: str) -> None:
    """What a user reads in ``tablebot COMMAND -h``: how to call it, what it does (its docstring's first
    sentence) and each of its arguments and options by name, as the command really takes them."""
    result = invoke(command, "--help")
    assert result.exit_code == 0, result.output
    said = " ".join(result.output.split())  # rich wraps the help to the terminal's width
    the = commands()[command]
    assert said.startswith(f"Usage: tablebot {command} [OPTIONS]")
    assert " ".join((the.help or "").split(".")[0].split()) in said
    for param in the.params:
        names = param.opts if param.param_type_name == "option" else [param.human_readable_name]
        assert any(name in said for name in names), (command, param.name, said)


def test_no_arguments_lists_every_command_with_what_it_does() -> None:
    result = invoke()
    lines = result.output.splitlines()
    listed = {
        line.split()[0]: line.split(maxsplit=1)[1]
        for line in lines[lines.index("Commands:") + 1 :]
        if line.startswith("  ") and len(line.split()) > 1
    }
    assert set(listed) == set(commands()) and len(listed) >= 15
    for name, command in commands().items():
        first = command.get_short_help_str().split()[:3]  # the index's summary (tablebot.cli.index)
        assert listed[name].split()[:3] == first, (name, listed[name])


def test_a_missing_argument_is_named_with_where_to_read_about_it() -> None:
    result = invoke("check")
    assert result.exit_code == 2
    assert result.output.splitlines() == [
        "TABLE: error: TABLE is missing",
        "    hint: tablebot check -h says what TABLE takes",
    ]
    assert "Traceback" not in result.output


# --- check --------------------------------------------------------------------------------------------


def test_check_seed_tsv(tmp_path: Path) -> None:
    shutil.copy(SEED_TSV, tmp_path / "bumberbot-table.tsv")
    result = invoke("check", tmp_path / "bumberbot-table.tsv")
    assert result.exit_code == 0, result.output
    assert "37 rows, 10 states" in result.stdout and "BumberBot" in result.stdout


def test_check_a_folder_means_its_table() -> None:
    result = invoke("check", EXAMPLE)
    assert result.exit_code == 0 and "table.csv" in result.stdout


def test_check_reports_every_problem_located(tmp_path: Path) -> None:
    path = write_table(tmp_path, BAD_TABLE, MINI_ROBOT)
    result = invoke("check", path)
    assert result.exit_code == 2
    errors = assert_located_errors(result.stderr, 3)
    lines = BAD_TABLE.splitlines()
    expected = [(3, column_of(lines[2], 5)), (4, column_of(lines[3], 7)), (5, column_of(lines[4], 8))]
    assert [(int(m["line"]), int(m["column"])) for m in errors] == expected
    assert all(m["path"] == str(path) for m in errors)
    assert result.stdout == ""


def test_check_undecodable_file(tmp_path: Path) -> None:
    """Binary data (a NUL byte) that is not UTF-8 is refused where its first bad byte is; text that is
    not UTF-8 is read as Windows-1252 instead (see test_safety_loaders)."""
    path = tmp_path / "t.csv"
    path.write_bytes(b"state,T,I3,M1_speed,next\n1,1,\xff\x00,3,1\n")
    result = invoke("check", path)
    assert result.exit_code == 2
    (m,) = assert_located_errors(result.stderr, 1)
    assert (m["line"], m["column"]) == ("2", "5")


def test_check_with_explicit_robot(tmp_path: Path) -> None:
    table = write_table(tmp_path, "state,T,A,M1,timer,next\n1,,1,0,5,2\n1,1,,3,10,2\n2,1,,-3,10,1\n")
    (tmp_path / "mini.toml").write_text(MINI_ROBOT)
    assert invoke("check", table).exit_code == 2  # the built-in BumberBot has no input A
    result = invoke("check", table, "--robot", tmp_path / "mini.toml")
    assert result.exit_code == 0, result.output
    assert "robot Mini" in result.stdout


def test_check_missing_file(tmp_path: Path) -> None:
    result = invoke("check", tmp_path / "nope.csv")
    assert result.exit_code == 2
    assert "cannot read" in result.stderr and "Traceback" not in result.output


def test_real_command_is_plain_when_piped(tmp_path: Path) -> None:
    """The installed script, in a subprocess: stderr is a pipe, so no colour codes, and exit code 2."""
    path = write_table(tmp_path, BAD_TABLE, MINI_ROBOT)
    script = Path(sys.executable).parent / "tablebot"
    done = subprocess.run([str(script), "check", str(path)], capture_output=True, text=True, check=False)
    assert done.returncode == 2
    assert "\x1b[" not in done.stderr
    assert_located_errors(done.stderr, 3)


# --- export and import --------------------------------------------------------------------------------


def test_export_then_import_round_trip(tmp_path: Path) -> None:
    out = tmp_path / "lists"
    result = invoke("export", EXAMPLE / "table.csv", out, "--to", "robopro")
    assert result.exit_code == 0, result.output
    assert (out / "event.csv").read_text().splitlines()[0] == "88"
    assert (out / "action.csv").read_text().splitlines()[0] == "5120"
    assert (out / "timer.csv").read_text().splitlines()[0] == "50"
    result = invoke("import", out, "--from", "robopro", "--out", tmp_path / "back.csv")
    assert result.exit_code == 0, result.output
    assert "descriptions" in result.stderr
    back = compile_table(load_table(tmp_path / "back.csv", example_machine().table.robot))
    assert back.signature() == example_machine().signature()


def test_import_to_standard_output(tmp_path: Path) -> None:
    invoke("export", EXAMPLE, tmp_path, "--to", "robopro")
    result = invoke("import", tmp_path, "--from", "robopro")
    assert result.exit_code == 0
    assert result.stdout.splitlines()[0].startswith("description,state,T,I3,I4,I5,I7,I8,M1_dir")
    assert result.stdout.splitlines()[1] == ",1,,1,1,,,,,0,,0,50,20"


def test_export_named_states(tmp_path: Path) -> None:
    robot = MINI_ROBOT.replace("initial_state = 1", 'initial_state = "go"')
    table = write_table(tmp_path, "state,T,M1,M2,timer,next\ngo,1,3,3,9,stop\nstop,1,0,0,9,go\n", robot)
    assert invoke("export", table, tmp_path / "l", "--to", "robopro").exit_code == 0
    assert (tmp_path / "l" / "states.csv").read_text() == "number,name\n1,go\n2,stop\n"
    result = invoke("import", tmp_path / "l", "--from", "robopro", "--robot", tmp_path / "robot.toml")
    assert result.exit_code == 0, result.output
    assert [line.split(",")[1] for line in result.stdout.splitlines()[1:]] == ["go", "stop"]


def test_export_refuses_what_does_not_fit(tmp_path: Path) -> None:
    table = write_table(tmp_path, "state,T,M1,M2,timer,next\n1,1,8,3,40000,1\n", MINI_ROBOT)
    result = invoke("export", table, tmp_path / "l", "--to", "robopro")
    assert result.exit_code == 2
    assert "row 0: timer 40000 is over 32767" in result.stderr and "row 0: M1 speed 8" in result.stderr
    assert not (tmp_path / "l").exists()


def test_export_into_a_file_is_an_error_not_a_traceback(tmp_path: Path) -> None:
    (tmp_path / "afile").write_text("")
    result = invoke("export", EXAMPLE, tmp_path / "afile", "--to", "robopro")
    assert result.exit_code == 2
    assert ("afile" in result.stderr and result.exception is None) or isinstance(result.exception, SystemExit)


def test_import_errors(tmp_path: Path) -> None:
    result = invoke("import", tmp_path, "--from", "robopro")
    assert result.exit_code == 2 and "list file not found" in result.stderr


# --- trace and demo -----------------------------------------------------------------------------------


def test_trace_to_stdout_and_file_are_the_same_bytes(tmp_path: Path) -> None:
    inputs = EXAMPLE / "inputs.csv"
    to_stdout = invoke("trace", EXAMPLE, "--inputs", inputs)
    assert to_stdout.exit_code == 0
    assert invoke("trace", EXAMPLE, "--inputs", inputs, "--out", tmp_path / "a.jsonl").exit_code == 0
    assert invoke("trace", EXAMPLE / "table.csv", "--inputs", inputs, "--out", tmp_path / "b.jsonl").exit_code == 0
    a, b = (tmp_path / "a.jsonl").read_bytes(), (tmp_path / "b.jsonl").read_bytes()
    assert a == b == to_stdout.stdout.encode()
    assert a.startswith(b'{"tick":0,"event":32,"row":7,"state":1,"timer":500,"M1":4,"M2":4}\n')
    assert len(a.splitlines()) == 3000


def test_trace_bad_inputs(tmp_path: Path) -> None:
    (tmp_path / "in.csv").write_text("I3,T\n1,\n")
    result = invoke("trace", EXAMPLE, "--inputs", tmp_path / "in.csv")
    assert result.exit_code == 2
    (m,) = assert_located_errors(result.stderr, 1)
    assert (m["line"], m["column"]) == ("1", "4")


def test_trace_into_a_missing_folder(tmp_path: Path) -> None:
    result = invoke("trace", EXAMPLE, "--inputs", EXAMPLE / "inputs.csv", "--out", tmp_path / "no" / "t.jsonl")
    assert result.exit_code == 2 and "Traceback" not in result.output


def test_demo_writes_the_trace_of_the_example(tmp_path: Path) -> None:
    result = invoke("demo", "--out", tmp_path)
    assert result.exit_code == 0, result.output
    assert "BumberBot: 3000 ticks (30.0 s)" in result.stdout
    expected = invoke("trace", EXAMPLE, "--inputs", EXAMPLE / "inputs.csv").stdout
    assert (tmp_path / "trace.jsonl").read_text() == expected


def test_trace_into_a_closed_pipe_stops_quietly() -> None:
    """`tablebot trace ... | head -1`: the reader leaving early is no error."""
    command = [
        sys.executable,
        "-c",
        "from tablebot.cli import main; main()",
        "trace",
        str(EXAMPLE),
        "--inputs",
        str(EXAMPLE / "inputs.csv"),
    ]
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert proc.stdout is not None and proc.stderr is not None
    first = proc.stdout.readline()
    proc.stdout.close()
    stderr = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 0
    assert first.startswith(b'{"tick":0,')
    assert stderr == ""


def test_the_command_line_loads_no_heavy_library_until_a_command_runs() -> None:
    """`tablebot --help` must be quick: no numpy, numba, matplotlib, web server, HTTP or graphviz at import, and
    of the engine, the simulator and the analysis only the light modules that register back-ends."""
    code = "import json, sys, tablebot.cli; print(json.dumps(sorted(sys.modules)))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    heavy = (
        "numpy",
        "numba",
        "matplotlib",
        "starlette",
        "uvicorn",
        "httpx",
        "graphviz",
        "serial",
        "dask",
        "tablebot.engine",
        "tablebot.machine",
    )
    registering = {"tablebot.sim", "tablebot.sim.backend", "tablebot.analysis", "tablebot.analysis.section"}
    loaded = [m for m in json.loads(done.stdout) if m.startswith((*heavy, "tablebot.sim", "tablebot.analysis"))]
    assert [m for m in loaded if m not in registering] == []
