"""Every command docs/controllers.md shows, and every command an example robot file's comments give, runs as
typed against the controllers' stand-ins: the commands name a real controller (txt://192.168.7.2, auto, a
serial port), so each runs with that address swapped for a fake TXT on loopback, a fake TXT 4.0 REST API, or
the ROBO TX or ROBO Interface emulator on a real pseudo-terminal (the ROBO Interface at its real 38400 baud,
where a 10 ms tick cannot be kept). A run the page leaves to Ctrl-C, or gives a minute, is ended after 0.3 s
by --seconds: the same way out, outputs off; and a run gets --link-timeout 1 unless it says otherwise, since the
stand-ins share a busy test machine, where a reply can come later than the default 5 ticks. Nothing else of a
command is changed."""

from __future__ import annotations

import contextlib
import csv
import io
import re
from collections import Counter
from collections.abc import Iterator
from pathlib import Path

import pytest

from doc_commands import ROOT, Command, Edit, commands, examples_copy, run, unaccounted
from tablebot.testing.roboif_emulator import RoboifEmulator
from tablebot.testing.robotx_emulator import RobotxEmulator
from txt4_fake_rest import FakeTxt4
from txt_fake import FakeTxt

pytestmark = [pytest.mark.realtime]

PAGE = "docs/controllers.md"
SECONDS = "0.3"
KEY = "SECRET"  # the API key the fake TXT 4.0 wants, as a reader would type it at the prompt


def _bumberbot_at_25_ms(folder: Path) -> None:
    """What the page asks for: tick_ms = 25, and every timer as ten times its ticks in milliseconds."""
    robot = folder / "my-bumberbot" / "robot.toml"
    text = robot.read_text(encoding="utf-8")
    assert re.search(r"^tick_ms = 10\b", text, re.M)
    robot.write_text(re.sub(r"^tick_ms = 10\b", "tick_ms = 25", text, count=1, flags=re.M), encoding="utf-8")
    table = folder / "my-bumberbot" / "table.csv"
    rows = list(csv.reader(io.StringIO(table.read_text(encoding="utf-8"))))
    column = rows[0].index("timer")
    for row in rows[1:]:
        if row and not row[0].startswith("#") and row[column] not in ("", "0"):
            row[column] = f"{int(row[column]) * 10}ms"
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerows(rows)
    table.write_text(out.getvalue(), encoding="utf-8")


#: Edits the page asks for between two commands: before the n-th run of a command.
EDITS: dict[tuple[str, int], Edit] = {("tablebot check my-bumberbot", 1): _bumberbot_at_25_ms}


@contextlib.contextmanager
def stand_in(command: Command, folder: Path) -> Iterator[tuple[list[str], dict[str, str]]]:
    """The command's words and environment with its controller swapped for a stand-in that runs here."""
    argv, env = list(command.argv), dict(command.env)
    address = next((w for w in argv if "://" in w), "")
    scheme = address.split("://")[0]
    with contextlib.ExitStack() as stack:
        if scheme == "txt":
            fake = stack.enter_context(FakeTxt())
            swap = f"txt://127.0.0.1:{fake.port}"
        elif scheme == "txt4":
            rest = stack.enter_context(FakeTxt4(folder / "controller", key=KEY))
            swap, env = f"txt4://127.0.0.1:{rest.port}", {**env, "TABLEBOT_TXT4_KEY": KEY}
        elif scheme == "robotx":
            swap = "robotx://" + stack.enter_context(RobotxEmulator()).device
        elif scheme == "roboif":
            swap = "roboif://" + stack.enter_context(RoboifEmulator(baud=38400)).device
        else:
            swap = address
        argv = [swap if w == address else w for w in argv]
        if argv[0] == "run":
            argv = _timed(argv)
        yield argv, env


def _timed(argv: list[str]) -> list[str]:
    if "--link-timeout" not in argv:
        argv = [*argv, "--link-timeout", "1"]
    if "--seconds" in argv:
        at = argv.index("--seconds") + 1
        return [*argv[:at], SECONDS, *argv[at + 1 :]]
    return [*argv, "--seconds", SECONDS]


def run_all(cmds: list[Command], folder: Path) -> list[str]:
    seen: Counter[str] = Counter()
    failed = []
    for command in cmds:
        if not command.argv:
            continue
        seen[command.text] += 1
        edit = EDITS.get((command.text, seen[command.text]))
        if edit is not None:
            edit(folder)
        with stand_in(command, folder) as (argv, env):
            result = run(argv, env=env or None)
        if result.exit_code != 0:
            failed.append(f"{command}: {argv}: exit {result.exit_code}: {result.output[-800:]}")
    return failed


def test_every_command_of_the_controllers_page_runs_against_the_stand_ins(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cmds = commands(PAGE)
    assert not unaccounted(cmds), "run these commands in the test, or exempt them with the reason"
    assert {c.argv[0] for c in cmds if c.argv} >= {"run", "trace", "export", "upload", "new", "check"}
    monkeypatch.chdir(examples_copy(tmp_path))
    assert run_all(cmds, tmp_path) == []
    assert (tmp_path / "runs" / "if" / "trace.jsonl").exists()  # the ROBO Interface ran at 25 ms, not refused


def robot_file_commands() -> list[Command]:
    """The commands an example robot file's comments give in backticks: a whole `tablebot ...` command, or
    `--on ADDRESS` alone, which tells the reader to run this robot there (`tablebot run FOLDER --on ADDRESS`).
    A comment's lines are read as one text, so a command may wrap; a command named without a table
    (`tablebot check --verbose` lists the notes) is a name, not a line to type."""
    found = []
    for path in sorted((ROOT / "examples").rglob("*.toml")):
        doc, folder = str(path.relative_to(ROOT)), str(path.parent.relative_to(ROOT))
        comment: list[str] = []
        lines = path.read_text(encoding="utf-8").splitlines()
        for number, line in enumerate([*lines, ""], 1):
            if line.lstrip().startswith("#"):
                comment.append(line.lstrip()[1:].strip())
                continue
            text = " ".join(comment)
            for quoted in re.findall(r"`((?:tablebot|--on) [^`]+)`", text):
                if quoted.startswith("tablebot") and "examples/" not in quoted:
                    continue
                found.append(
                    Command(
                        doc, number - 1, quoted if quoted.startswith("tablebot") else f"tablebot run {folder} {quoted}"
                    )
                )
            comment = []
    return found


def test_every_command_an_example_robot_file_gives_runs_as_typed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """examples/bumberbot/robot.toml told the reader to run `--on roboif:///dev/ttyUSB0`, which was refused
    at its 10 ms tick: each command its comments give must run as typed."""
    cmds = robot_file_commands()
    assert any("roboif://" in c.text for c in cmds) and any("txt://" in c.text for c in cmds)
    monkeypatch.chdir(examples_copy(tmp_path))
    assert run_all(cmds, tmp_path) == []


def test_the_robo_interface_refuses_the_bumberbots_10_ms_tick_at_38400_baud(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """What the two tests above rely on: the stand-in for the ROBO Interface is slow enough to refuse the
    example as it stands, so a page that gave that command would fail them."""
    monkeypatch.chdir(examples_copy(tmp_path))
    with stand_in(Command("-", 0, "tablebot run examples/bumberbot --on roboif:///dev/ttyUSB0"), tmp_path) as (argv, _):
        result = run(argv)
    assert result.exit_code == 2 and "38400-baud line" in " ".join(result.output.split())
