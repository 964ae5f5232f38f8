"""The studio trusts only its own page (issue 18, section 1), tested over real HTTP and WebSocket connections
to a real server (its gate, which checks the Host, the Origin and the token before any route runs, in
test_studio_gate.py): the page may name only tables and traces of the folder (no dotfile, no other kind,
nothing outside); a save writes only the file the session opened; bad messages, pipes and devices neither
end a connection nor block the server. The command itself, a real process, is in test_studio_command.py;
the same attacks from a page in a real Chromium are in test_studio_attacks.py.
"""

from __future__ import annotations

import asyncio
import json
import os
import shutil
import socket
import stat
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import websockets

from core_helpers import EXAMPLE
from studio_helpers import bumberbot, http, run_async, served
from tablebot.web.app import Background
from tablebot.web.errors import Refused
from tablebot.web.workspace import Kind, Workspace

SECRET = "API_KEY=do-not-leak-4711\n"
HOOK = "print('the page wrote this')\n"
PYTHON_WORDS = ("Errno", "Traceback", "subpath", "Error:", "errno", "object has no attribute")


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    """A BumberBot folder with things a page must never reach: a secret, code, a git folder, a file
    outside, hidden tables, and links leading out of the folder or into a hidden one."""
    root = bumberbot(tmp_path)
    (root / "secret.env").write_text(SECRET)
    (root / "hook.py").write_text(HOOK)
    (root / "notes.txt").write_text("state,next\n")
    (root / "data.csv").write_text("name,password\nadmin,hunter2\n")  # a CSV, but not a table
    (root / ".git").mkdir()
    (root / ".git" / "config").write_text("[remote]\nurl = secret\n")
    (root / ".git" / "table.csv").write_bytes((EXAMPLE / "table.csv").read_bytes())
    (root / ".hidden.csv").write_bytes((EXAMPLE / "table.csv").read_bytes())
    (root / "sub" / ".private").mkdir(parents=True)
    (root / "sub" / ".private" / "t.csv").write_bytes((EXAMPLE / "table.csv").read_bytes())
    (root / "victim.csv").write_bytes((EXAMPLE / "table.csv").read_bytes())
    (tmp_path / "outside.csv").write_text("state,next\n1,1\n")
    (root / "out.csv").symlink_to(tmp_path / "outside.csv")
    (root / "into-git.csv").symlink_to(root / ".git" / "table.csv")
    return root


@pytest.fixture
def studio(folder: Path) -> Iterator[Background]:
    yield from served(folder)


async def _session(
    server: Background, messages: list[Any], replies_wanted: int, headers: dict[str, str] | None = None
) -> list[dict[str, Any]]:
    async with websockets.connect(
        server.origin.replace("http", "ws") + "/ws",
        max_size=2**24,
        additional_headers=server.headers if headers is None else headers,
    ) as ws:
        for message in messages:
            await ws.send(message if isinstance(message, str) else json.dumps(message))
        return [json.loads(await asyncio.wait_for(ws.recv(), 20)) for _ in range(replies_wanted)]


def talk(server: Background, messages: list[Any], until: str, limit: int = 40) -> list[dict[str, Any]]:
    """Send ``messages`` as the page would; replies up to the first of type ``until``."""

    async def run() -> list[dict[str, Any]]:
        replies: list[dict[str, Any]] = []
        async with websockets.connect(
            server.origin.replace("http", "ws") + "/ws", max_size=2**24, additional_headers=server.headers
        ) as ws:
            for message in messages:
                await ws.send(message if isinstance(message, str) else json.dumps(message))
            while len(replies) < limit:
                replies.append(json.loads(await asyncio.wait_for(ws.recv(), 20)))
                if replies[-1]["type"] == until:
                    break
        return replies

    return run_async(run())


# --- what the page may name ----------------------------------------------------------------------------------

REFUSED = {
    "secret.env": "is not a table",
    "hook.py": "is not a table",
    "notes.txt": "is not a table",
    "data.csv": "is not a table",
    ".git/config": "hidden files",
    ".git/table.csv": "hidden files",
    ".hidden.csv": "hidden files",
    "sub/.private/t.csv": "hidden files",
    "./.hidden.csv": "hidden files",
    "into-git.csv": "hidden files",
    "out.csv": "outside the served folder",
    "../outside.csv": "outside the served",
    "/etc/passwd": "outside the served folder",
    "sub/../../outside.csv": "outside the served folder",
}


def test_only_tables_and_traces_of_the_folder_open(studio: Background, folder: Path) -> None:
    names = list(REFUSED)
    replies = talk(
        studio,
        [
            *({"op": "open", "path": n} for n in names),
            *({"op": "trace", "path": n} for n in ("secret.env", "table.csv", ".t.jsonl")),
            {"op": "files"},
        ],
        until="files",
    )
    errors = [r for r in replies if r["type"] == "error"]
    assert [r["type"] for r in replies] == ["error"] * (len(names) + 3) + ["files"]
    for name, reply in zip(names, errors, strict=False):
        assert REFUSED[name] in reply["message"], (name, reply)
    assert "is not a trace" in errors[-3]["message"] and "is not a trace" in errors[-2]["message"]
    assert "hidden files" in errors[-1]["message"]
    text = json.dumps(replies)
    assert "do-not-leak" not in text and "the page wrote" not in text and "hunter2" not in text
    assert not [w for w in PYTHON_WORDS if w in text]
    assert str(folder.parent) not in text  # no path of the machine, only names in the folder
    listed = replies[-1]
    assert listed["tables"] == ["table.csv", "victim.csv"] and listed["traces"] == []


def test_a_table_opens_and_saves_through_a_link_inside_the_folder(studio: Background, folder: Path) -> None:
    (folder / "latest.csv").symlink_to("victim.csv")
    replies = talk(
        studio,
        [{"op": "open", "path": "latest.csv"}, {"op": "edit", "row": 3, "col": 12, "value": "901"}, {"op": "save"}],
        until="saved",
    )
    assert replies[0]["path"] == "victim.csv" and replies[-1]["type"] == "saved"
    assert b",901," in (folder / "victim.csv").read_bytes() and (folder / "latest.csv").is_symlink()


# --- saving: only the file this session opened ------------------------------------------------------------


def _swap_then_save(studio: Background, swap: Any, force: bool = True) -> list[dict[str, Any]]:
    async def run() -> list[dict[str, Any]]:
        async with websockets.connect(
            studio.origin.replace("http", "ws") + "/ws", additional_headers=studio.headers, max_size=2**24
        ) as ws:
            await ws.send(json.dumps({"op": "open", "path": "victim.csv"}))
            await _until(ws, "analysis")
            await ws.send(json.dumps({"op": "edit", "row": 3, "col": 12, "value": "777", "seq": 1}))
            await _until(ws, "analysis")
            swap()
            await ws.send(json.dumps({"op": "save", "force": force}))
            reply = await _until(ws, "error", "saved", "conflict")
            await ws.send(json.dumps({"op": "files"}))  # the connection lives on
            return [reply, await _until(ws, "files")]

    return run_async(run())


async def _until(ws: Any, *types: str) -> dict[str, Any]:
    while True:
        reply = json.loads(await asyncio.wait_for(ws.recv(), 20))
        if reply["type"] in types:
            return reply


def test_a_link_swapped_in_after_opening_is_never_written_through(studio: Background, folder: Path) -> None:
    """The audit's attack: open victim.csv, replace it by a link to a file outside, save with force."""
    outside = folder.parent / "outside.csv"
    before = outside.read_bytes()

    def swap() -> None:
        (folder / "victim.csv").unlink()
        (folder / "victim.csv").symlink_to(outside)

    reply, _ = _swap_then_save(studio, swap)
    assert reply["type"] == "error" and "outside the served folder" in reply["message"]
    assert outside.read_bytes() == before
    assert not (folder / "victim.csv.bak").exists()  # nothing from outside leaks into a backup
    assert not [p for p in folder.iterdir() if p.name.endswith(".tmp")]


def test_a_file_replaced_after_opening_is_not_overwritten_without_asking(studio: Background, folder: Path) -> None:
    """Replaced by a rename (an editor's save): the page is asked, as for an edit in place (what each answer
    does: test_studio_saves.py)."""

    def swap() -> None:
        (folder / "other.csv").write_bytes(b"state,next\n1,1\n")
        os.replace(folder / "other.csv", folder / "victim.csv")

    reply, _ = _swap_then_save(studio, swap, force=False)
    assert reply["type"] == "conflict" and "victim.csv was replaced on disk" in reply["message"]
    assert (folder / "victim.csv").read_bytes() == b"state,next\n1,1\n" and not (folder / "victim.csv.bak").exists()


def test_a_link_to_another_table_in_the_folder_is_not_written(studio: Background, folder: Path) -> None:
    table = (folder / "table.csv").read_bytes()

    def swap() -> None:
        (folder / "victim.csv").unlink()
        (folder / "victim.csv").symlink_to("table.csv")

    reply, _ = _swap_then_save(studio, swap)
    assert reply["type"] == "error" and "now leads to another file" in reply["message"]
    assert (folder / "table.csv").read_bytes() == table and not (folder / "table.csv.bak").exists()


def test_a_changed_file_asks_first_and_a_forced_save_keeps_a_backup(studio: Background, folder: Path) -> None:
    victim = folder / "victim.csv"
    changed = victim.read_bytes().replace(b",895,", b",896,")
    reply, _ = _swap_then_save(studio, lambda: victim.write_bytes(changed), force=False)
    assert reply["type"] == "conflict" and victim.read_bytes() == changed
    mode = stat.S_IMODE(victim.stat().st_mode)
    reply, _ = _swap_then_save(studio, lambda: victim.chmod(0o640))
    assert reply["type"] == "saved" and b",777," in victim.read_bytes()
    assert (folder / "victim.csv.bak").read_bytes() == changed and stat.S_IMODE(victim.stat().st_mode) == 0o640
    assert mode != 0o640


def test_a_race_between_check_and_write_meets_no_follow(folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The link appears after the name was checked (here: the check is made to pass regardless): the
    file and its folder are opened without following links, so nothing outside is read or written."""
    workspace = Workspace(folder)
    outside = folder.parent / "outside.csv"
    before = outside.read_bytes()
    (folder / "sub" / "t.csv").write_bytes((EXAMPLE / "table.csv").read_bytes())
    for name, swap in (
        ("victim.csv", lambda: _relink(folder / "victim.csv", outside)),
        ("sub/t.csv", lambda: _relink(folder / "sub", folder.parent)),
    ):
        opened = workspace.read(name, Kind.TABLE, 10**6)
        swap()
        monkeypatch.setattr(Workspace, "locate", lambda self, n, kind: n)
        with pytest.raises(Refused, match="changed while the studio was opening it"):
            workspace.save(opened, b"state,next\n2,2\n", force=True)
        monkeypatch.undo()
    assert outside.read_bytes() == before and not (folder.parent / "outside.csv.bak").exists()
    assert not (folder.parent / "t.csv").exists() and not (folder.parent / "t.csv.bak").exists()
    assert not (folder / "victim.csv.bak").exists()


def _relink(path: Path, target: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    else:
        path.unlink()
    path.symlink_to(target)


# --- messages that must not end the connection ---------------------------------------------------------------


def test_a_message_nested_100000_deep_is_an_error_and_the_connection_lives(studio: Background) -> None:
    deep = "[" * 100_000 + "]" * 100_000
    replies = talk(
        studio,
        [deep, '{"op": "open", "path": ' + "[" * 100_000, b"\x00binary".decode(), {"op": "files"}],
        until="files",
    )
    assert [r["type"] for r in replies] == ["error", "error", "error", "files"]
    assert "nested too deeply" in replies[0]["message"]
    status, body = http(studio, "api/trace?name=deep.jsonl", data=b'{"tick":0,"state":1}\n' + deep.encode() + b"\n")
    assert status == 400 and b"deep.jsonl:2:1" in body and b"nested too deeply" in body


def test_a_binary_frame_is_an_error_and_the_connection_lives(studio: Background) -> None:
    async def run() -> list[dict[str, Any]]:
        async with websockets.connect(
            studio.origin.replace("http", "ws") + "/ws", additional_headers=studio.headers
        ) as ws:
            await ws.send(b"\x01\x02")
            await ws.send(json.dumps({"op": "files"}))
            return [json.loads(await ws.recv()), json.loads(await ws.recv())]

    first, second = run_async(run())
    assert first["message"] == "a message must be JSON text, not binary data" and second["type"] == "files"


def test_a_table_that_is_not_utf8_is_refused_in_the_studios_words(studio: Background, folder: Path) -> None:
    (folder / "bad.csv").write_bytes(b"state,next\n1,1\xff\n")
    replies = talk(studio, [{"op": "open", "path": "bad.csv"}, {"op": "files"}], until="files")
    assert replies[0]["type"] == "error" and "byte 14 is not UTF-8 text" in replies[0]["message"]
    assert not [w for w in PYTHON_WORDS if w in json.dumps(replies)]


# --- pipes, sockets, devices -------------------------------------------------------------------------------


def _can_mknod(tmp: Path) -> bool:
    try:
        os.mknod(tmp / "probe", stat.S_IFCHR | 0o600, os.makedev(1, 5))
    except OSError:
        return False
    return True


def _specials(folder: Path) -> list[str]:
    os.mkfifo(folder / "notes.csv")
    os.mkfifo(folder / "pipe.jsonl")
    (folder / "dir.csv").mkdir()
    unix = socket.socket(socket.AF_UNIX)
    unix.bind(str(folder / "sock.csv"))
    names = ["notes.csv", "pipe.jsonl", "dir.csv", "sock.csv"]
    if _can_mknod(folder):
        os.mknod(folder / "zero.csv", stat.S_IFCHR | 0o600, os.makedev(1, 5))  # /dev/zero: it never ends
        names.append("zero.csv")
    return names


def test_pipes_sockets_and_devices_are_skipped_without_blocking(studio: Background, folder: Path) -> None:
    names = _specials(folder)
    started = time.monotonic()
    status, body = http(studio, "api/config", timeout=10)
    assert status == 200 and time.monotonic() - started < 5
    listed = json.loads(body)
    assert not set(names) & set(listed["tables"] + listed["traces"])
    messages = [{"op": "trace" if n.endswith(".jsonl") else "open", "path": n} for n in names]
    replies = talk(studio, [*messages, {"op": "files"}], until="files")
    assert [r["type"] for r in replies] == ["error"] * len(names) + ["files"]
    assert all("is not a regular file (a folder, pipe or device)" in r["message"] for r in replies[:-1]), replies
