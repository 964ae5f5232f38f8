"""The studio's server without a browser: a real server on a real socket, spoken to over WebSocket and HTTP.
Bad messages get error replies and never end the server; nothing outside the folder is served."""

from __future__ import annotations

import asyncio
import json
import os
import shutil
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import websockets

from core_helpers import EXAMPLE, ROOT
from studio_helpers import run_async
from tablebot.web.app import Background


@pytest.fixture(scope="module")
def studio(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Background, Path]]:
    root = tmp_path_factory.mktemp("studio-server") / "bumberbot"
    shutil.copytree(EXAMPLE, root)
    (root.parent / "secret.csv").write_text("state,next\n1,1\n")
    server = Background(root)
    yield server, root
    server.stop()


def talk(
    server: Background, messages: list[Any], until: str, limit: int = 20, seq: int | None = None
) -> list[dict[str, Any]]:
    """Send the messages (text as is, anything else as JSON) as the studio's page would (its Origin and
    token cookie) and collect replies up to one of type ``until`` (with ``seq``, if given)."""

    async def run() -> list[dict[str, Any]]:
        replies: list[dict[str, Any]] = []
        async with websockets.connect(
            server.origin.replace("http", "ws") + "/ws", max_size=2**24, additional_headers=server.headers
        ) as ws:
            for message in messages:
                await ws.send(message if isinstance(message, str) else json.dumps(message))
            while len(replies) < limit:
                reply = json.loads(await asyncio.wait_for(ws.recv(), 10))
                replies.append(reply)
                if reply["type"] == until and (seq is None or reply.get("seq") == seq):
                    break
        return replies

    return run_async(run())


def get(server: Background, path: str, data: bytes | None = None) -> urllib.request.Request:
    """A request as the studio's page makes it (its Origin and token cookie)."""
    return urllib.request.Request(f"{server.origin}/{path}", data=data, headers=server.headers)


def test_malformed_messages_get_error_replies_and_the_server_goes_on(studio: tuple[Background, Path]) -> None:
    server, _ = studio
    bad = [
        "not json",
        "[1, 2]",
        {"op": 5},
        {"op": "explode"},
        {"op": "edit", "row": 0, "col": 0, "value": "x"},
        {"op": "open", "path": 7},
        {"op": "sim", "action": "play"},
        {"op": "open", "path": "table.csv"},
        {"op": "edit", "row": "zero", "col": 1, "value": "1"},
        {"op": "edit", "row": 999, "col": 1, "value": "1"},
        {"op": "sim", "action": "speed", "speed": "warp"},
        {"op": "sim", "action": "hold", "input": "I99", "on": True},
        {"op": "sim", "action": "reset", "seed": -4},
        {"op": "sim", "action": "reset", "charge": "full"},
    ]
    replies = talk(server, [*bad, {"op": "files"}], until="files", limit=40)
    errors = [r["message"] for r in replies if r["type"] == "error"]
    assert errors[:7] == [
        "not JSON: Expecting value",
        'a message must be a JSON object with an "op"',
        'a message must be a JSON object with an "op"',
        "unknown op 'explode'",
        "open a table first",
        '"path" must be text',
        "the robot is not running: fix the table first",
    ]
    assert errors[7:] == [
        '"row" must be a whole number',
        "there is no row 1000",
        "speed must be one of 1, 10, max",
        "unknown input 'I99': the robot's inputs are I3, I4, I5, I7, I8",
        '"seed" must be from 0 to 2.14748e+09',
        '"charge" must be a number',
    ]
    assert replies[-1]["type"] == "files" and "table.csv" in replies[-1]["tables"]
    assert "trace.jsonl" not in replies[-1]["tables"]


@pytest.mark.parametrize("path", ["../secret.csv", "/etc/passwd", "sub/../../secret.csv", "link.csv"])
def test_nothing_outside_the_folder_is_opened(studio: tuple[Background, Path], path: str) -> None:
    server, root = studio
    link = root / "link.csv"
    if not link.exists():
        link.symlink_to(root.parent / "secret.csv")
    replies = talk(server, [{"op": "open", "path": path}, {"op": "trace", "path": path}], until="error", limit=1)
    assert replies[0]["type"] == "error" and "outside the served folder" in replies[0]["message"]


def test_static_files_stay_in_the_package(studio: tuple[Background, Path]) -> None:
    server, _ = studio
    for path in ("static/../app.py", "static/%2e%2e/app.py", "static/..%2fapp.py", "table.csv"):
        with pytest.raises(urllib.error.HTTPError) as err:
            urllib.request.urlopen(get(server, path))
        assert err.value.code == 404
    page = urllib.request.urlopen(server.url)
    assert "script-src 'self'" in page.headers["Content-Security-Policy"]
    from tablebot.web.app import STATIC

    modules = sorted(p.relative_to(STATIC).as_posix() for p in (STATIC / "js").rglob("*.js"))
    assert "js/studio/main.js" in modules and len(modules) > 10
    for module in modules:  # no script is fetched from anywhere else
        text = urllib.request.urlopen(get(server, "static/" + module)).read()
        assert b"http" not in text.replace(b'location.protocol === "https:"', b""), module


def test_the_page_asks_for_every_module_its_script_imports_at_once(studio: tuple[Background, Path]) -> None:
    """A modulepreload link per module the page's script imports, however deep (found by reading the
    modules' own imports here, not by the server's list), each served; none for a module nothing imports."""
    import re

    from tablebot.web.app import STATIC

    server, _ = studio
    with urllib.request.urlopen(server.url) as reply:
        page, headers = reply.read().decode(), reply.headers
    assert headers["Cache-Control"] == "no-store" and "script-src 'self'" in headers["Content-Security-Policy"]
    preloaded = re.findall(r'<link rel="modulepreload" href="/static/([^"]+)">', page)
    assert page.index("modulepreload") < page.index('<script type="module" src="/static/js/studio/main.js">')
    wanted, todo = set(), ["js/studio/main.js"]
    while todo:
        name = todo.pop()
        if name not in wanted:
            wanted.add(name)
            text = (STATIC / name).read_text(encoding="utf-8")
            todo += [
                (Path(name).parent / spec).as_posix().replace("/./", "/")
                for spec in re.findall(r'from "(\.[^"]+)"', text)
            ]
    wanted = {str(Path(os.path.normpath(name)).as_posix()) for name in wanted}
    assert sorted(preloaded) == sorted(wanted) and len(preloaded) == len(set(preloaded)) > 20
    for name in preloaded:
        with urllib.request.urlopen(get(server, "static/" + name)) as reply:
            assert reply.status == 200 and "javascript" in reply.headers["Content-Type"], name


def test_a_table_comes_with_the_columns_its_analysis_gives_so_the_page_draws_its_grid_once(
    studio: tuple[Background, Path],
) -> None:
    server, _ = studio
    replies = talk(server, [{"op": "open", "path": "table.csv"}], until="analysis")
    table = next(r for r in replies if r["type"] == "table")
    analysis = next(r for r in replies if r["type"] == "analysis")
    assert table["columns"] == analysis["columns"] and table["tick_ms"] == analysis["machine"]["tick_ms"] == 10
    assert {"event", "dir", "speed", "timer", "state", "next"} <= {c["kind"] for c in table["columns"]}


def test_an_uploaded_trace_is_read_with_located_errors(studio: tuple[Background, Path]) -> None:
    server, _ = studio
    good = b'{"tick":0,"event":32,"row":7,"state":1,"timer":500,"M1":4,"M2":4}\n'
    reply = json.load(urllib.request.urlopen(get(server, "api/trace?name=t.jsonl", good)))
    assert reply["type"] == "trace" and reply["columns"]["state"] == [1]
    with pytest.raises(urllib.error.HTTPError) as err:
        bad = good + b'{"tick":1}\n'
        urllib.request.urlopen(get(server, "api/trace?name=t.jsonl", bad))
    assert err.value.code == 400
    assert "t.jsonl:2:1: error: a trace line needs state" in json.load(err.value)["message"]


def test_an_edit_is_checked_and_located(studio: tuple[Background, Path]) -> None:
    server, _ = studio
    replies = talk(
        server,
        [{"op": "open", "path": "table.csv"}, {"op": "edit", "row": 4, "col": 9, "value": "9", "seq": 1}],
        until="analysis",
        seq=1,
    )
    first, edited = (r for r in replies if r["type"] == "analysis")
    assert first["ok"] and first["machine"]["rows"] == 37 and len(first["machine"]["states"]) == 10
    assert not edited["ok"] and "machine" not in edited
    (d,) = edited["diagnostics"]
    assert (d["row"], d["col"], d["line"], d["column"]) == (4, 9, 6, 32)
    assert d["message"] == "M1_speed: 9 is out of range 0..8" and d["hint"] == "write a whole number from 0 to 8"


def test_a_counterexample_plays_in_the_arena_at_once_slows_down_and_stops_where_it_breaks(
    studio: tuple[Background, Path],
) -> None:
    server, _ = studio

    async def run() -> tuple[dict[str, Any], list[tuple[float, dict[str, Any]]]]:
        control: dict[str, Any] | None = None
        frames: list[tuple[float, dict[str, Any]]] = []
        async with websockets.connect(
            server.origin.replace("http", "ws") + "/ws", max_size=2**24, additional_headers=server.headers
        ) as ws:
            for message in (
                {"op": "open", "path": "table.csv"},
                {"op": "counterexample", "name": "front_bumper_stops", "where": "arena"},
            ):
                await ws.send(json.dumps(message))
            while True:
                reply = json.loads(await asyncio.wait_for(ws.recv(), 10))
                control = control or (reply if reply["type"] == "control" else None)
                if reply["type"] == "frame":
                    frames.append((time.monotonic(), reply))
                    if reply["paused"] and reply["scripted"] == 0 and reply["tick"] == 53:
                        assert control is not None, "no control message came before the violating tick"
                        return control, frames

    control, frames = run_async(run())
    assert not control["paused"] and 0 < control["scripted"] <= 54  # it plays at once, no Play needed
    # its last 12 ticks (42-53) are played 10 times slower than real time; it stops on tick 53, where it breaks
    slow_from = next(at for at, frame in frames if frame["tick"] >= 42)
    assert frames[-1][0] - slow_from >= 0.9
    last = frames[-1][1]
    assert last["state_id"] == "29" and last["row"] == -1 and last["why"][-1]["status"] == "none"
    replies = talk(server, [{"op": "counterexample", "name": "no_such"}], until="error", limit=1)
    assert replies[0]["message"] == "fix the table's errors first"


def test_the_arena_gets_the_tape_and_light_cones_only_for_a_robot_that_has_them() -> None:
    """A line follower's world carries its tape; its robot has no phototransistors, so no light cones."""
    from tablebot.cli.common import load
    from tablebot.sim.model.scene import scene_for
    from tablebot.web.worldview import world_json

    for name, tape, light in (("line-follower", True, False), ("bumberbot", False, True)):
        table, machine = load(ROOT / "examples" / name)
        scene = scene_for(table, machine)
        data = world_json(scene.world, scene.params)
        assert bool(data["tape"]) == tape and ("light" in data) == light, name
