"""`tablebot new` writes no file that breaks when a user uncomments its examples: every commented line of
every template that is itself a line of its file (a TOML key or section, a table row) is uncommented, block by
block, line by line under its section, and all at once, and the folder still loads as every command loads it."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from tablebot import templates
from tablebot.api import open as open_robot

Variant = tuple[str, dict[str, str]]


def is_example(file: str, line: str, columns: int) -> bool:
    """Whether a commented line is an example: without its '#', a line of its file that means something."""
    if not line.startswith("#"):
        return False
    text = uncomment(line).strip()
    if not text or text.startswith("#"):
        return False
    if file.endswith(".csv"):
        return len(text.split(",")) == columns
    try:
        tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        return False
    return True


def uncomment(line: str) -> str:
    return line[2:] if line.startswith("# ") else line[1:]


def blocks(file: str, text: str) -> list[list[int]]:
    """The example lines, in blocks of consecutive lines."""
    lines = text.splitlines()
    columns = len(lines[0].split(","))
    found: list[list[int]] = []
    for number, line in enumerate(lines):
        if is_example(file, line, columns):
            if found and found[-1][-1] == number - 1:
                found[-1].append(number)
            else:
                found.append([number])
    return found


def with_uncommented(text: str, numbers: list[int]) -> str:
    lines = text.splitlines()
    return "\n".join(uncomment(line) if n in numbers else line for n, line in enumerate(lines)) + "\n"


def variants(made: templates.Template) -> list[Variant]:
    """Each block alone; a [section] header with each one of its lines; every block of every file."""
    out: list[Variant] = []
    every = dict(made.files)
    for file, text in made.files.items():
        found = blocks(file, text)
        for block in found:
            out.append((f"{file} lines {block[0] + 1}-{block[-1] + 1}", {file: with_uncommented(text, block)}))
            # a [section]'s keys stand alone (each sensor is one); a [[thing]]'s lines are one thing together
            first = uncomment(text.splitlines()[block[0]]).lstrip()
            header = first.startswith("[") and not first.startswith("[[")
            for number in block[1:] if header and len(block) > 2 else ():
                out.append(
                    (f"{file} lines {block[0] + 1}, {number + 1}", {file: with_uncommented(text, [block[0], number])})
                )
        every[file] = with_uncommented(text, [n for block in found for n in block])
    return [*out, ("every example at once", every)]


def loads_whole(folder: Path) -> None:
    project = open_robot(folder)
    project.properties()
    project.scene()  # robot, table and world checked together, as sim and sweep check them


TEMPLATES = [
    (name, names)
    for name in templates.TEMPLATES
    for names in ([], [("A", "")], [("A", ""), ("B", "")])
    if not (names and name != "empty")
]


@pytest.mark.parametrize(("template", "inputs"), TEMPLATES)
def test_every_commented_example_can_be_uncommented(
    tmp_path: Path, template: str, inputs: list[tuple[str, str]]
) -> None:
    made = templates.make(template, "mine", inputs, [])
    tried = variants(made)
    for k, (what, changed) in enumerate(tried):
        folder = tmp_path / f"v{k}"
        templates.write_folder(folder, templates.Template({**made.files, **changed}))
        try:
            loads_whole(folder)
        except Exception as exc:  # any failure: the test names the variant that broke
            raise AssertionError(f"{template}: uncommenting {what} breaks the folder:\n{exc}") from None


def test_the_empty_templates_examples_are_found() -> None:
    """The search above finds the examples `new` writes (else it would pass by finding none)."""
    made = templates.make("empty", "mine", [], [])
    assert [len(b) for b in blocks("robot.toml", made.files["robot.toml"])] == [3]
    assert [len(b) for b in blocks("arena.toml", made.files["arena.toml"])] == [3]
    assert [len(b) for b in blocks("table.csv", made.files["table.csv"])] == [1]
