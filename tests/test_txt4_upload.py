"""``tablebot upload`` against a fake of the TXT 4.0's REST routes over real HTTP."""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot.cli import app
from txt4_fake_rest import FakeTxt4

runner = CliRunner()


def exported(tmp_path: Path) -> Path:
    out = tmp_path / "program"
    assert runner.invoke(app, ["export", str(EXAMPLE), str(out), "--to", "txt4"]).exit_code == 0
    return out


def test_upload_stops_creates_sends_every_file_and_starts(tmp_path: Path) -> None:
    program = exported(tmp_path)
    with FakeTxt4(tmp_path / "controller") as fake:
        to = f"txt4://127.0.0.1:{fake.port}"
        result = runner.invoke(app, ["upload", str(program), "--to", to, "--key", "SECRET"])
    assert result.exit_code == 0, result.output
    assert [method + " " + path for method, path in fake.calls] == [
        "GET /api/v1/ping", "DELETE /api/v1/stop", "POST /api/v1/workspaces?workspace_name=BumberBot",
        "POST /api/v1/workspaces/BumberBot/files", "POST /api/v1/application/BumberBot/start"]
    assert fake.started == ["BumberBot"]
    for path in program.rglob("*"):
        if path.is_file():
            assert (tmp_path / "controller" / "BumberBot" / path.relative_to(program)).read_bytes() == path.read_bytes()
    assert "uploaded 4 files to workspace BumberBot" in result.output


def test_no_start_only_installs(tmp_path: Path) -> None:
    program = exported(tmp_path)
    with FakeTxt4(tmp_path / "controller") as fake:
        result = runner.invoke(app, ["upload", str(program), "--to", f"txt4://127.0.0.1:{fake.port}", "--key", "SECRET",
                                     "--no-start"])
    assert result.exit_code == 0 and fake.started == []


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
