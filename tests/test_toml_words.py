"""The TOML parser's errors reach a user in tablebot's words, at the place they are about: a key or section
given twice names both lines; each other message says what is wrong and what to write."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.diagnostics import TableBotError
from tablebot.tomlfile import loads

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "line-follower"


def error(text: str) -> str:
    with pytest.raises(TableBotError) as caught:
        loads("f.toml", text, "the file's own hint")
    return str(caught.value)


def test_a_robot_file_with_an_input_given_twice_names_both_lines(tmp_path: Path) -> None:
    folder = tmp_path / "robot"
    folder.mkdir()
    (folder / "table.csv").write_text((EXAMPLE / "table.csv").read_text())
    lines = (EXAMPLE / "robot.toml").read_text().splitlines(keepends=True)
    first = next(n for n, line in enumerate(lines, start=1) if line.startswith("I1 ="))
    lines.insert(first + 1, 'I1 = "again"\n')
    (folder / "robot.toml").write_text("".join(lines))
    result = CliRunner().invoke(app, ["check", str(folder)])
    assert result.exit_code == 2
    assert f"robot.toml:{first + 2}:1: error: I1 is given twice: lines {first} and {first + 2}" in result.output
    assert "Cannot overwrite" not in result.output


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ('name = "x"\n[inputs]\nI1 = "a"\nI2 = "b"\nI1 = "c"\n', "f.toml:5:1: error: I1 is given twice: lines 3 and 5"),
        ('[inputs]\nI1 = "a"\n[motors]\n[inputs]\n', "f.toml:4:1: error: [inputs] is given twice: lines 1 and 4"),
        ('[sim]\nworld = "x"\n[sim.battery]\ncharge = 1\n[sim]\n', "error: [sim] is given twice: lines 1 and 5"),
        ("[[box]]\nat = 1\n[[box]]\nat = 2\nat = 3\n", "f.toml:5:1: error: at is given twice: lines 4 and 5"),
        ('[sensors]\nI1 = {sensor = "line"}\n[sensors.I1]\n', "error: [sensors.I1] is given twice: lines 2 and 3"),
        ("a.b = 1\na = 2\n", "f.toml:2:1: error: a is given twice: lines 1 and 2"),
        ("[a]\nx = {b = 1, b = 2}\n", "b is given twice inside { }"),
        ("a = {x = 1}\na.y = 2\n", "adds to an inline table"),
        ("I1 =\n", "f.toml:1:5: error: TOML syntax: this value is missing or not one TOML knows"),
        ("name = my robot\n", "this value is missing or not one TOML knows"),
        ("a = 1 2\n", "f.toml:1:7: error: TOML syntax: something follows the value on this line"),
        ("ultrasonic sensor here\n", "a key must be followed by '=' and a value"),
        ('a = "x\n', "a text in quotes is not closed on its line"),
        ("a = [1, 2\n", "a list [ ... ] is not closed"),
        ("a = {x = 1\n", "an inline table { ... } is not closed on its line"),
        ("[a\n", "f.toml:1:3: error: TOML syntax: a [section] header is not closed"),
        ('a = "C:\\x"\n', "a backslash in double quotes starts an escape"),
    ],
)
def test_each_parser_message_is_worded_and_placed(text: str, words: str) -> None:
    said = error(text)
    assert words in said and "hint: " in said and "the file's own hint" not in said
    for parser_words in ("Cannot", "Invalid", "Expected", "Unclosed", "Illegal", "Unescaped", "Duplicate"):
        assert parser_words not in said
