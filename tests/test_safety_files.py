"""Never lose the user's data (issue 14): no command writes over its own input, a table or robot file is
replaced only with --force (keeping NAME.bak), every output is complete or absent, check writes nothing."""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot import files
from tablebot import overwrite as guard
from tablebot.cli import app
from tablebot.diagnostics import TableBotError
from tablebot.files import PendingFile, atomic_write, replacing, write_text

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from typer.testing import Result

RPP = Path(__file__).resolve().parent / "fixtures" / "rpp" / "engine.rpp"
runner = CliRunner()


def cli(*args: object, code: int = 0) -> Result:
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exc_info
    assert result.exit_code == code, result.output
    return result


@pytest.fixture
def bot(tmp_path: Path) -> Path:
    folder = tmp_path / "bot"
    shutil.copytree(EXAMPLE, folder)
    return folder


def test_trace_refuses_to_write_over_its_inputs_file(bot: Path) -> None:
    """Reproduced: `trace --inputs in.csv --out in.csv` replaced the recording with JSON Lines."""
    before = (bot / "inputs.csv").read_bytes()
    result = cli("trace", bot, "--inputs", bot / "inputs.csv", "--out", bot / "inputs.csv", code=2)
    assert "reads this file, so it will not write over it" in result.stderr
    assert (bot / "inputs.csv").read_bytes() == before


@pytest.mark.parametrize("target", ["table.csv", "robot.toml", "inputs.csv"])
def test_no_command_writes_over_a_file_it_read(bot: Path, target: str) -> None:
    """Even with --force, and even through another spelling (a hard link) of the same file."""
    os.link(bot / target, bot / "alias")
    before = (bot / target).read_bytes()
    for out in (bot / target, bot / "alias"):
        cli("trace", bot, "--inputs", bot / "inputs.csv", "--out", out, "--force", code=2)
        if target != "inputs.csv":  # diagram reads the table and the robot, not the inputs
            cli("diagram", bot, "--format", "dot", "--out", out, "--force", code=2)
    assert (bot / target).read_bytes() == before


def test_import_refuses_to_replace_a_table_without_force(bot: Path, tmp_path: Path) -> None:
    """Reproduced: `import lists --from robopro --out table.csv` replaced a hand-written table."""
    lists = tmp_path / "lists"
    cli("export", bot, lists, "--to", "robopro")
    table = bot / "table.csv"
    before = table.read_bytes()
    result = cli("import", lists, "--from", "robopro", "--out", table, code=2)
    assert "table.csv exists and is a table file" in result.stderr and "--force" in result.stderr
    assert table.read_bytes() == before
    cli("import", lists, "--from", "robopro", "--out", table, "--force")
    assert (bot / "table.csv.bak").read_bytes() == before  # the descriptions survive in the backup
    assert table.read_bytes() != before and b"Collision" not in table.read_bytes()


def test_any_output_is_refused_over_a_robot_or_table_file(bot: Path, tmp_path: Path) -> None:
    other = tmp_path / "other.toml"
    other.write_text("name = 'x'\n")
    cli("diagram", bot, "--format", "dot", "--out", other, code=2)
    assert other.read_text() == "name = 'x'\n"
    plain = tmp_path / "plain.csv"  # a CSV that is no table (an inputs file, a list) is just an output
    plain.write_text("I3,I4\n1,\n")
    cli("trace", bot, "--inputs", bot / "inputs.csv", "--out", plain)


def test_rpp_in_place_keeps_a_backup(tmp_path: Path, bot: Path) -> None:
    program = tmp_path / "engine.rpp"
    shutil.copy(RPP, program)
    cli("export", bot, "--to", "robopro-rpp", "--into", program)
    assert (tmp_path / "engine.rpp.bak").read_bytes() == RPP.read_bytes()
    assert program.read_bytes() != RPP.read_bytes()


def test_check_writes_nothing_unless_asked(bot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Reproduced: check wrote ./out/check by default (and failed in a read-only folder)."""
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    before = sorted(p.name for p in bot.iterdir())
    result = cli("check", bot)
    assert "--counterexamples DIR saves it" in result.stdout
    assert list(work.iterdir()) == [] and sorted(p.name for p in bot.iterdir()) == before
    cli("check", bot, "--counterexamples", work / "cex")
    assert sorted(p.name for p in (work / "cex").iterdir()) == ["can_follow_light.csv", "front_bumper_stops.csv"]


# --- tablebot.files --------------------------------------------------------------------------------


def test_an_interrupted_write_keeps_the_old_file(tmp_path: Path) -> None:
    path = tmp_path / "d.png"
    path.write_bytes(b"old")
    with pytest.raises(KeyboardInterrupt), atomic_write(path, "wb") as f:
        f.write(b"half")
        raise KeyboardInterrupt
    assert path.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == ["d.png"]


def test_a_ctrl_c_just_after_the_temporary_file_opens_stays_a_ctrl_c(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The interrupt lands after os.fdopen returned its file object and before it was kept (the object is
    dropped, closing the descriptor): the command still hears KeyboardInterrupt, not EBADF from closing it twice
    (a sweep stopped with Ctrl-C said "Bad file descriptor" in a CI run), and the old file and folder are as
    they were."""
    target = tmp_path / "out.txt"
    target.write_text("old", encoding="utf-8")
    real_fdopen = os.fdopen

    def fdopen_then_interrupted(fd: int, *args: object, **kwargs: object) -> object:
        real_fdopen(fd, *args, **kwargs).close()  # type: ignore[call-overload]  # made, then dropped by the unwinding
        raise KeyboardInterrupt

    monkeypatch.setattr(files.os, "fdopen", fdopen_then_interrupted)
    with pytest.raises(KeyboardInterrupt), atomic_write(target) as stream:
        stream.write("new")
    assert target.read_text(encoding="utf-8") == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]


def test_a_tool_output_is_renamed_only_when_complete(tmp_path: Path) -> None:
    elf = tmp_path / "x.elf"
    with pytest.raises(RuntimeError), replacing(elf) as temp:
        temp.write_bytes(b"partial")
        raise RuntimeError("avr-gcc failed")
    assert list(tmp_path.iterdir()) == []
    with replacing(elf) as temp:
        temp.write_bytes(b"whole")
    assert elf.read_bytes() == b"whole" and list(tmp_path.iterdir()) == [elf]


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs Linux's /dev/full")
def test_a_device_is_written_not_replaced(tmp_path: Path) -> None:
    """Renaming onto /dev/full would put a regular file where the device was."""
    with pytest.raises(OSError) as info:
        write_text("/dev/full", "x" * 100000)
    assert info.value.filename == "/dev/full" and Path("/dev/full").is_char_device()
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    reader = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)
    pending = PendingFile(fifo)
    pending.stream.write("tick\n")
    assert pending.commit() == fifo and fifo.is_fifo()
    assert os.read(reader, 100) == b"tick\n"
    os.close(reader)


@pytest.mark.parametrize(
    "header",
    [
        b"\xef\xbb\xbfstate,T,I3,timer,next\n",  # Excel's "CSV UTF-8": a BOM before the first column
        b"sep=;\nDescription;St;T;I3;Timer;Next-State\n",  # aliases, another delimiter, Excel's sep= line
        b'"state"\t"T"\t"next"\n',  # quoted cells, tabs
        "state,T,I3,timer,next\n".encode("utf-16"),  # Excel's "Unicode Text"
    ],
)
def test_every_spelling_of_a_table_header_is_protected(tmp_path: Path, header: bytes) -> None:
    """Reproduced: a table saved with a BOM before its state column was replaced without --force."""
    table = tmp_path / "mine.csv"
    table.write_bytes(header)
    assert files.is_user_file(table)
    with guard.command(), pytest.raises(TableBotError, match="not replaced without --force"):
        write_text(table, "x")
    assert table.read_bytes() == header


@pytest.mark.parametrize("text", ["a,b\n1,2\n", "state,M1\n1,2\n", "", '"state,next\n'])
def test_other_csv_files_are_not_tables(tmp_path: Path, text: str) -> None:
    other = tmp_path / "data.csv"
    other.write_text(text)
    assert not files.is_user_file(other)


def test_the_guard_outside_a_command_refuses_nothing(tmp_path: Path) -> None:
    table = tmp_path / "t.csv"
    table.write_text("state,next\n1,1\n")
    write_text(table, "state,next\n2,2\n")  # library use: the caller decides
    with guard.command(), pytest.raises(TableBotError):
        write_text(table, "x")


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc, where no file can be made")
@pytest.mark.parametrize("args", [["diagram", "{table}", "--out", "/proc/tablebot-x.svg"], ["new", "/proc/tablebot-x"]])
def test_a_file_that_cannot_be_made_is_named_as_the_user_named_it(args: list[str]) -> None:
    """A temporary file (or staging folder) that could not be made was the one the error named:
    "/proc/.tablebot-x.svg.ygu7q6hw.tmp: error: ...", a name the user never gave."""
    result = CliRunner().invoke(app, [a.format(table=EXAMPLE) for a in args])
    assert result.exit_code == 2, result.output
    assert result.output.startswith(f"{args[-1]}: error: cannot write or read"), result.output
    assert ".tmp" not in result.output and ".tablebot-" not in result.output
