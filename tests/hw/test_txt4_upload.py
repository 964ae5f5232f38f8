"""``tablebot upload`` against a fake of the TXT 4.0's REST routes over real HTTP (answering as harbaum/SofTXT
does, plus a key check), the API key taken from the environment, a file, a terminal prompt or ``--key``."""

from __future__ import annotations

import os
import pty
import select
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot.cli import app
from txt4_fake_rest import FakeTxt4

pytestmark = [pytest.mark.realtime]

runner = CliRunner()


def exported(tmp_path: Path) -> Path:
    out = tmp_path / "program"
    assert runner.invoke(app, ["export", str(EXAMPLE), str(out), "--to", "txt4"]).exit_code == 0
    return out


def test_upload_stops_sends_every_file_and_starts(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    program = exported(tmp_path)
    monkeypatch.setenv("TABLEBOT_TXT4_KEY", "SECRET")
    with FakeTxt4(tmp_path / "controller") as fake:
        result = runner.invoke(app, ["upload", str(program), "--to", f"txt4://127.0.0.1:{fake.port}"])
    assert result.exit_code == 0, result.output
    assert [method + " " + path for method, path in fake.calls] == [
        "GET /api/v1/ping",
        "DELETE /api/v1/stop",
        "POST /api/v1/workspaces/BumberBot/files",
        "POST /api/v1/application/BumberBot/start",
    ]
    assert fake.keys == ["SECRET"] * 4 and fake.started == ["BumberBot"]
    assert sorted(fake.filenames) == ["/.project.json", "/BumberBot.py", "/lib/__init__.py", "/lib/tablebot_program.py"]
    for path in program.rglob("*"):
        if path.is_file():
            assert (tmp_path / "controller" / "BumberBot" / path.relative_to(program)).read_bytes() == path.read_bytes()
    assert "uploaded 4 files to workspace BumberBot" in result.output and "SECRET" not in result.output


def test_no_start_only_installs_and_the_key_may_come_from_a_file(tmp_path: Path) -> None:
    program = exported(tmp_path)
    (tmp_path / "key").write_text("SECRET\n")
    with FakeTxt4(tmp_path / "controller") as fake:
        result = runner.invoke(
            app,
            [
                "upload",
                str(program),
                "--to",
                f"txt4://127.0.0.1:{fake.port}",
                "--key-file",
                str(tmp_path / "key"),
                "--no-start",
            ],
        )
    assert result.exit_code == 0, result.output
    assert fake.started == [] and set(fake.keys) == {"SECRET"}


def test_the_key_is_asked_for_on_a_terminal_without_echo(tmp_path: Path) -> None:
    """A real pseudo-terminal: the prompt appears, the typed key is not echoed, the upload uses it."""
    program = exported(tmp_path)
    env = {k: v for k, v in os.environ.items() if k != "TABLEBOT_TXT4_KEY"}
    with FakeTxt4(tmp_path / "controller") as fake:
        pid, master = pty.fork()
        if pid == 0:  # the child: tablebot, with the pty as its controlling terminal
            os.execve(
                sys.executable,
                [
                    sys.executable,
                    "-m",
                    "tablebot",
                    "upload",
                    str(program),
                    "--to",
                    f"txt4://127.0.0.1:{fake.port}",
                    "--no-start",
                ],
                env,
            )
        seen = read_until(master, b"(shown on its display): ")  # the final space: echo is off by then
        os.write(master, b"SECRET\n")
        seen += read_until(master, b"uploaded")
        status = wait(pid)
        os.close(master)
    assert os.waitstatus_to_exitcode(status) == 0, seen
    assert b"SECRET" not in seen and set(fake.keys) == {"SECRET"}


def wait(pid: int, timeout_s: float = 30.0) -> int:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return status
        time.sleep(0.05)
    os.kill(pid, 9)
    raise AssertionError("tablebot upload did not end")


def read_until(fd: int, marker: bytes, timeout_s: float = 30.0) -> bytes:
    seen, deadline = b"", time.monotonic() + timeout_s
    while marker not in seen and time.monotonic() < deadline:
        if select.select([fd], [], [], 0.1)[0]:
            try:
                seen += os.read(fd, 4096)
            except OSError:
                break
    return seen


def test_key_mistakes_are_located_errors(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    program = exported(tmp_path)
    monkeypatch.delenv("TABLEBOT_TXT4_KEY", raising=False)
    to = ["--to", "txt4://127.0.0.1:9"]
    none = runner.invoke(app, ["upload", str(program), *to])  # not a terminal: never waits for a prompt
    assert none.exit_code == 2 and "--key: error: no API key" in none.output and "TABLEBOT_TXT4_KEY" in none.output
    (tmp_path / "empty").write_text("\n")
    empty = runner.invoke(app, ["upload", str(program), *to, "--key-file", str(tmp_path / "empty")])
    assert empty.exit_code == 2 and "empty: error: the key file is empty" in empty.output
    missing = runner.invoke(app, ["upload", str(program), *to, "--key-file", str(tmp_path / "nokey")])
    assert missing.exit_code == 2 and "nokey: error: cannot read the key file" in missing.output
    both = runner.invoke(app, ["upload", str(program), *to, "--key", "K", "--key-file", str(tmp_path / "empty")])
    assert both.exit_code == 2 and "give the key once" in both.output


def test_a_wrong_key_an_unreachable_controller_and_a_bad_folder_are_located_errors(tmp_path: Path) -> None:
    program = exported(tmp_path)
    with FakeTxt4(tmp_path / "controller") as fake:
        port = fake.port
        wrong = runner.invoke(app, ["upload", str(program), "--to", f"txt4://127.0.0.1:{port}", "--key", "nope"])
    assert wrong.exit_code == 2 and "--key: error:" in wrong.output and "refused the API key (401" in wrong.output
    gone = runner.invoke(app, ["upload", str(program), "--to", f"txt4://127.0.0.1:{port}", "--key", "SECRET"])
    assert gone.exit_code == 2 and f"--to: error: cannot reach txt4://127.0.0.1:{port}" in gone.output
    bad_url = runner.invoke(app, ["upload", str(program), "--to", "http://127.0.0.1", "--key", "SECRET"])
    assert bad_url.exit_code == 2 and "is not txt4://HOST" in bad_url.output
    not_exported = runner.invoke(app, ["upload", str(tmp_path), "--to", "txt4://127.0.0.1", "--key", "SECRET"])
    assert not_exported.exit_code == 2 and "not a program written by `tablebot export --to txt4`" in not_exported.output
    a_file = runner.invoke(app, ["upload", str(program / "BumberBot.py"), "--to", "txt4://127.0.0.1", "--key", "K"])
    assert a_file.exit_code == 2 and "BumberBot.py: error: is a file, not a folder" in a_file.output
    missing = runner.invoke(app, ["upload", str(tmp_path / "nope"), "--to", "txt4://127.0.0.1", "--key", "K"])
    assert missing.exit_code == 2 and "nope: error: no such folder" in missing.output
