"""Never write through a symbolic link (issue 33 §1): a project cloned from someone else (git keeps links)
can carry ``prog.rpp.bak -> ~/.bashrc`` or ``out/demo/trace.jsonl -> ../../victim``. Backups replace a link
at their name; every output file refuses one, and a full disk never truncates an earlier good backup."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot import files
from tablebot import overwrite as guard
from tablebot.cli import app
from tablebot.diagnostics import TableBotError

RPP = Path(__file__).resolve().parent / "fixtures" / "rpp" / "engine.rpp"
runner = CliRunner()


@pytest.fixture
def victim(tmp_path: Path) -> Path:
    """A file outside the project that a planted link points at (a user's ~/.bashrc)."""
    path = tmp_path / "home" / ".bashrc"
    path.parent.mkdir()
    path.write_text("export PATH=$HOME/bin:$PATH\n")
    return path


def test_rewriting_a_program_in_place_replaces_a_planted_backup_link(tmp_path: Path, victim: Path) -> None:
    """Reproduced: `export --to robopro-rpp --into prog.rpp` copied the old program into ~/.bashrc."""
    project = tmp_path / "project"
    project.mkdir()
    program = project / "prog.rpp"
    shutil.copy(RPP, program)
    old = program.read_bytes()
    (project / "prog.rpp.bak").symlink_to(victim)
    result = runner.invoke(app, ["export", str(EXAMPLE), "--to", "robopro-rpp", "--into", str(program)])
    assert result.exit_code == 0, result.output
    assert victim.read_text() == "export PATH=$HOME/bin:$PATH\n"
    backup = project / "prog.rpp.bak"
    assert not backup.is_symlink() and backup.read_bytes() == old
    assert program.read_bytes() != old
    assert sorted(p.name for p in project.iterdir()) == ["prog.rpp", "prog.rpp.bak"]  # no temporary left


def test_import_force_replaces_a_planted_backup_link(tmp_path: Path, victim: Path) -> None:
    lists = tmp_path / "lists"
    assert runner.invoke(app, ["export", str(EXAMPLE), str(lists), "--to", "robopro"]).exit_code == 0
    table = tmp_path / "mine.csv"
    table.write_text("state,next\n1,1\n")
    (tmp_path / "mine.csv.bak").symlink_to(victim)
    result = runner.invoke(app, ["import", str(lists), "--from", "robopro", "--out", str(table), "--force"])
    assert result.exit_code == 0, result.output
    assert victim.read_text() == "export PATH=$HOME/bin:$PATH\n"
    assert (tmp_path / "mine.csv.bak").read_text() == "state,next\n1,1\n"
    assert table.read_text().startswith("description,state,")


def test_an_output_that_is_a_link_is_refused_and_the_target_kept(tmp_path: Path, victim: Path) -> None:
    """Reproduced: `out/demo/trace.jsonl -> victim` made `sim --out out/demo` overwrite the victim."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "trace.jsonl").symlink_to(victim)
    result = runner.invoke(app, ["sim", str(EXAMPLE), "--out", str(out), "--seconds", "1", "--no-plots"])
    assert result.exit_code == 2, result.output
    assert f"{out / 'trace.jsonl'}: error: trace.jsonl is a symbolic link (to {victim})" in result.output
    assert "Traceback" not in result.output
    assert victim.read_text() == "export PATH=$HOME/bin:$PATH\n"
    assert sorted(p.name for p in out.iterdir()) == ["trace.jsonl"]  # nothing else of the set was swapped in


@pytest.mark.parametrize("dangling", [False, True])
def test_every_writer_refuses_a_link(tmp_path: Path, victim: Path, dangling: bool) -> None:
    """atomic_write, replacing, PendingFile and append: a link to a file, or to none yet (which writing
    through would create wherever it points)."""
    target = tmp_path / "nowhere" if dangling else victim
    link = tmp_path / "out.jsonl"
    link.symlink_to(target)
    writers = [
        lambda: files.write_text(link, "x"),
        lambda: files.PendingFile(link),
        lambda: files.replacing(link).__enter__(),
        lambda: files.append(link).__enter__(),
    ]
    for write in writers:
        with pytest.raises(TableBotError, match="is a symbolic link"):
            write()
    assert link.is_symlink() and not (tmp_path / "nowhere").exists()
    assert victim.read_text() == "export PATH=$HOME/bin:$PATH\n"
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")) == []


def test_a_link_to_a_device_is_still_written(tmp_path: Path) -> None:
    """`--out /dev/stdout` is a link to the process's descriptor: written as the device, as before."""
    link = tmp_path / "null.jsonl"
    link.symlink_to(os.devnull)
    files.write_text(link, "nothing\n")
    with files.append(link) as stream:
        stream.write("more\n")
    assert link.is_symlink()


def test_appending_records_never_follows_a_link(tmp_path: Path, victim: Path) -> None:
    log = tmp_path / "proofs.jsonl"
    log.write_text('{"key": "a"}\n{"key": "b"')  # a cut last line, which json_records ends
    assert files.json_records(log, ["key"]) == [{"key": "a"}]
    assert log.read_text().endswith('"b"\n')
    log.unlink()
    victim.write_text("alias ls='ls -F'")  # no line end: json_records would end it
    log.symlink_to(victim)
    with pytest.raises(TableBotError, match="symbolic link"):
        files.json_records(log, ["key"])
    assert victim.read_text() == "alias ls='ls -F'"


FULL_DISK = textwrap.dedent("""
    import resource, signal, sys
    from pathlib import Path
    from tablebot import files, overwrite as guard
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails (EFBIG) as on a full disk
    resource.setrlimit(resource.RLIMIT_FSIZE, (1000, 1000))
    path = Path(sys.argv[1])
    try:
        with guard.command(force=True):  # replacing a table with --force keeps the old one as NAME.bak first
            files.write_text(path, "state,next\\n1,1\\n")
    except OSError as exc:
        print(exc.filename, exc.strerror)
        sys.exit(3)
""")


@pytest.mark.skipif(sys.platform == "win32", reason="RLIMIT_FSIZE is POSIX")
def test_a_full_disk_never_truncates_an_earlier_backup(tmp_path: Path) -> None:
    """Reproduced: shutil.copy2 opened NAME.bak for writing (emptying it) before the copy failed."""
    program = tmp_path / "mine.csv"
    program.write_text("state,next\n" + "1,1\n" * 2000)  # larger than the file size the child may write
    backup = tmp_path / "mine.csv.bak"
    backup.write_bytes(b"the previous good backup")
    done = subprocess.run([sys.executable, "-c", FULL_DISK, str(program)], capture_output=True, text=True)
    assert done.returncode == 3, done.stderr
    assert done.stdout.startswith(str(backup)), done.stdout  # named as the user knows it, not the temporary
    assert backup.read_bytes() == b"the previous good backup"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine.csv", "mine.csv.bak"]
    assert program.read_text().startswith("state,next\n1,1\n1,1\n")  # nor the table itself


def test_a_backup_keeps_the_originals_permissions(tmp_path: Path) -> None:
    table = tmp_path / "t.csv"
    table.write_text("state,next\n1,1\n")
    table.chmod(0o640)
    with guard.command(force=True):
        files.write_text(table, "state,next\n2,2\n")
    backup = tmp_path / "t.csv.bak"
    assert backup.read_text() == "state,next\n1,1\n" and backup.stat().st_mode & 0o777 == 0o640
