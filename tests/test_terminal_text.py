"""What the terminal shows (issue 18): a name cannot forge a line, a failing quiet run still says why,
nothing is wrapped into pieces when output is not a terminal, a deep property is a located error, and
the command line speaks tablebot's words."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot.cli import app
from tablebot.cli.common import err_console, print_diagnostic
from tablebot.diagnostics import Diagnostic
from tablebot.escape import plain, terminal
from txt_fake import FakeTxt

FORGED = "Bumber\nFAKE: error: forged line\r\u2028x"


def invoke(*args: object) -> tuple[int, str]:
    result = CliRunner().invoke(app, [str(a) for a in args])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exc_info
    return result.exit_code, result.output


@pytest.fixture
def bot(tmp_path: Path) -> Path:
    shutil.copytree(EXAMPLE, tmp_path / "bot")
    return tmp_path / "bot"


def test_line_breaks_in_user_text_are_shown_not_obeyed() -> None:
    assert plain("a\nb\r\tc\x1b") == "a\\nb\\r\tc\\x1b"
    assert terminal("[b]x[/b]\n") == "\\[b]x\\[/b]\\n"
    assert "\n" not in plain(FORGED) and "\u2028" not in plain(FORGED)


def test_a_robot_name_with_a_line_break_forges_no_line(bot: Path) -> None:
    robot = bot / "robot.toml"
    robot.write_text(robot.read_text().replace('name = "BumberBot"', 'name = "Bumber\\nFAKE: error: forged line"'))
    table = bot / "table.csv"
    table.write_text(table.read_text().replace("M2_speed", "M2_speed,X9", 1))
    code, output = invoke("check", bot)  # an error message naming the robot
    assert code == 2 and "for robot Bumber\\nFAKE: error: forged line" in output
    assert not [line for line in output.splitlines() if line.startswith("FAKE")], output
    table.write_text(table.read_text().replace("M2_speed,X9", "M2_speed", 1))
    code, output = invoke("check", bot)  # the report's first line names the robot too
    assert code == 0 and "robot Bumber\\nFAKE: error: forged line;" in output
    assert not [line for line in output.splitlines() if line.startswith("FAKE")], output


def test_a_tools_own_output_prints_below_its_diagnostic_marked_as_part_of_it() -> None:
    with err_console.capture() as captured:
        print_diagnostic(Diagnostic("avr-gcc", None, None, "avr-gcc failed", "report this",
                                    detail="tb.c:3: error: x\ntb.c:4: note: y"))
    assert captured.get().splitlines() == ["avr-gcc: error: avr-gcc failed", "    hint: report this",
                                           "    | tb.c:3: error: x", "    | tb.c:4: note: y"]


def test_a_quiet_run_that_fails_still_says_why(tmp_path: Path) -> None:
    with FakeTxt(fault=("silent", 20)) as fake:
        result = CliRunner().invoke(app, ["run", str(EXAMPLE), "--on", f"txt://127.0.0.1:{fake.port}", "-q",
                                          "--seconds", "5", "--link-timeout", "0.1", "--out", str(tmp_path)])
    assert result.exit_code == 3
    assert "ran 20 ticks: link_lost — no answer from" in result.stderr
    assert f"kept {tmp_path / 'trace.partial.jsonl'}" in result.stderr
    assert result.stdout == ""  # quiet: no summary
    with FakeTxt() as fake:
        result = CliRunner().invoke(app, ["run", str(EXAMPLE), "--on", f"txt://127.0.0.1:{fake.port}", "-q",
                                          "--seconds", "0.1"])
    assert result.exit_code == 0 and result.output == ""  # a run that succeeds stays silent


def test_paths_are_never_wrapped_when_output_is_not_a_terminal(bot: Path, tmp_path: Path) -> None:
    deep = tmp_path / ("a-rather-long-folder-name-" * 3) / ("and-another-one-beneath-it-" * 3)
    deep.mkdir(parents=True)
    code, output = invoke("trace", bot, "--inputs", bot / "inputs.csv", "--out", deep / "trace.jsonl")
    assert code == 0 and f"wrote {deep / 'trace.jsonl'} (3000 ticks)" in output.splitlines()
    code, output = invoke("check", deep / "missing.csv")
    assert code == 2 and any(line.startswith(f"{deep / 'missing.csv'}: error:") for line in output.splitlines())


def test_a_deeply_nested_property_is_a_located_error_and_a_long_flat_one_works(bot: Path) -> None:
    """300 nested parentheses (or 'not's) ended with RecursionError (exit 70); so did an 'or' of 1,000 terms."""
    deep = "(" * 300 + "I3" + ")" * 300
    (bot / "properties.toml").write_text(f'[deep]\nnever = "{deep}"\n\n[negated]\nnever = "{"not " * 400}I3"\n')
    code, output = invoke("check", bot)
    assert code == 2 and "Traceback" not in output and "internal error" not in output
    assert f"{bot / 'properties.toml'}:1: error: property deep: never: the condition nests parentheses" in output
    assert f"{bot / 'properties.toml'}:4: error: property negated" in output
    flat = " or ".join(["state == 20"] * 1000)
    every = " and ".join(["I3"] * 1000)
    (bot / "properties.toml").write_text(f'[flat]\nnever = "{flat}"\nlevel = "warning"\n\n'
                                         f'[every]\nnever = "{every} and M1 > 8"\n')
    code, output = invoke("check", bot)
    assert code == 0, output
    assert "VIOLATED flat" in output and "holds    every" in output
