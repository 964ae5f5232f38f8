"""The studio's protocol is one set on both sides: the operations and message kinds the page's module
(static/js/studio/protocol.js, imported under real Node) names are tablebot.web.protocol's, the page handles
every kind (messages.js), every operation reaches a handler of a real session, and what the server sends is
only of those kinds. Malformed messages are answered in the studio's words (tests/web/test_studio_server.py has
them over a real WebSocket)."""

from __future__ import annotations

import asyncio
import json
import shutil
import subprocess
from pathlib import Path
from typing import Any

import pytest

from core_helpers import EXAMPLE
from studio_helpers import run_async
from tablebot.web import protocol
from tablebot.web.errors import Refused
from tablebot.web.session import Hub, Session
from tablebot.web.workspace import Workspace

ROOT = Path(__file__).resolve().parents[2]
STUDIO = ROOT / "src" / "tablebot" / "web" / "static" / "js" / "studio"

NODE_SCRIPT = """
const protocol = await import(process.argv[1] + "/protocol.js");
const { messageHandlers } = await import(process.argv[1] + "/messages.js");
const handlers = messageHandlers({}, {}, () => {}, {});
const refused = [];
for (const bad of [{ op: "explode" }, { op: "edit", row: 1, col: 1, value: "x", colour: "red" }, { op: "toString" }]) {
  try { protocol.checkedOperation(bad); } catch (e) { refused.push(e.message); }
}
let partial = null;
try { protocol.byKind({ table() {} }); } catch (e) { partial = e.message; }
const sent = [];
protocol.checkedLink({ send: (m) => sent.push(m) }).send({ op: "sim", action: "reset", seed: 3, charge: 0.5 });
console.log(JSON.stringify({ operations: protocol.OPERATIONS, messages: protocol.MESSAGES,
  handled: Object.keys(handlers), refused, partial, sent }));
"""


@pytest.fixture(scope="module")
def page() -> dict[str, Any]:
    node = shutil.which("node")
    assert node is not None, "Node runs the page's modules here"
    done = subprocess.run(
        [node, "--input-type=module", "-e", NODE_SCRIPT, STUDIO.as_uri()],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=ROOT,
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def test_the_page_and_the_server_name_the_same_operations_with_the_same_fields(page: dict[str, Any]) -> None:
    server = {name: sorted(kind.wire_fields()) for name, kind in protocol.OPERATIONS.items()}
    assert {name: sorted(fields) for name, fields in page["operations"].items()} == server
    assert {"open", "edit", "save", "sim", "files"} <= set(server)  # what the page's controls send, and the listing


def test_the_page_handles_exactly_the_kinds_the_server_sends(page: dict[str, Any]) -> None:
    assert sorted(page["messages"]) == sorted(protocol.MESSAGES) and {"table", "analysis", "error"} <= set(
        protocol.MESSAGES
    )
    assert sorted(page["handled"]) == sorted(protocol.MESSAGES)
    assert page["partial"].startswith("handlers for table; the protocol has analysis, arena")


def test_the_page_sends_only_the_protocols_operations(page: dict[str, Any]) -> None:
    assert page["refused"] == [
        "not an operation of the studio: explode",
        "edit has no field colour",
        "not an operation of the studio: toString",
    ]
    assert page["sent"] == [{"op": "sim", "action": "reset", "seed": 3, "charge": 0.5}]


def test_operations_read_their_fields_or_are_refused_in_the_studios_words() -> None:
    assert protocol.operation({"op": "edit", "row": 2, "col": 1, "value": "", "seq": 9}) == protocol.Edit(2, 1, "", 9)
    sim = protocol.operation({"op": "sim", "action": "reset", "seed": 4})
    assert sim == protocol.Sim("reset", {"seed": 4})
    for message, words in [
        ([1], 'a message must be a JSON object with an "op"'),
        ({"op": "x"}, "unknown op 'x'"),
        ({"op": "edit", "row": True, "col": 0, "value": "1"}, '"row" must be a whole number'),
        ({"op": "open", "path": ""}, '"path" must be text'),
        ({"op": "save", "force": 3}, '"force" must be the version the conflict named ("theirs")'),
        (
            {"op": "restore", "header": ["a"], "grid": [[1]], "base": "v"},
            '"grid" must be rows of text (at most 20,000 rows of 200 cells)',
        ),
    ]:
        with pytest.raises(Refused) as refused:
            protocol.operation(message)
        assert str(refused.value) == words


def test_messages_go_out_with_their_fields_as_the_page_reads_them() -> None:
    assert protocol.ErrorMsg("no", "save").data() == {"type": "error", "message": "no", "op": "save"}
    assert protocol.GridMsg([["1"]], focus=0).data() == {"type": "grid", "grid": [["1"]], "focus": 0}
    assert protocol.AnalysisMsg(None, True, [2], {"cells": []}).data() == {
        "type": "analysis",
        "seq": None,
        "dirty": True,
        "lines": [2],
        "cells": [],
    }  # seq null: not after an edit


def test_a_real_session_answers_every_operation_in_the_protocols_kinds(tmp_path: Path) -> None:
    """Every operation reaches a handler (none is answered 'internal error' or left unanswered), and each
    reply is a kind the page handles."""
    for name in ("table.csv", "robot.toml", "arena.toml", "properties.toml"):
        shutil.copy(EXAMPLE / name, tmp_path / name)
    messages: dict[str, dict[str, Any]] = {
        "open": {"path": "table.csv"},
        "edit": {"row": 0, "col": 0, "value": "x", "seq": 1},
        "insert_row": {"after": 0, "seq": 2},
        "delete_row": {"row": 1, "seq": 3},
        "save": {},
        "restore": {"header": None, "grid": None, "base": "v"},
        "sim": {"action": "step"},
        "trace": {"path": "nothing.jsonl"},
        "counterexample": {"name": "no_such_property"},
        "files": {},
        "new": {"template": "empty", "name": "table.csv"},  # a taken name: refused in words
        "open_link": {"link": "nonsense"},  # no link opener handed in either: refused in words
        "share": {},  # no link maker handed in (tablebot studio hands one): refused in words
    }
    assert sorted(messages) == sorted(protocol.OPERATIONS)

    async def run() -> dict[str, list[dict[str, Any]]]:
        replies: dict[str, list[dict[str, Any]]] = {}
        current: list[dict[str, Any]] = []

        async def send(message: dict[str, Any]) -> None:
            current.append(message)

        session = Session(Workspace(tmp_path), Hub(), send)
        try:
            for op, fields in messages.items():
                current = replies.setdefault(op, [])
                await session.handle({"op": op, **fields})
        finally:
            session.close()
        return replies

    replies = run_async(run())
    for op, sent in replies.items():
        assert sent, f"{op} was not answered"
        assert {m["type"] for m in sent} <= set(protocol.MESSAGES), (op, sent)
        assert not any("internal error" in m.get("message", "") for m in sent), (op, sent)
    assert [m["type"] for m in replies["open"]][:3] == ["table", "analysis", "diagram"]
    assert replies["save"][0]["type"] == "saved" and replies["files"][0]["type"] == "files"
    assert replies["restore"] == [
        {
            "type": "error",
            "op": "restore",
            "message": '"header" must be a row of text (at most 20,000 rows of 200 cells)',
        }
    ]
    assert replies["counterexample"][0]["message"] == "property 'no_such_property' has no counterexample"


def test_a_refused_operation_is_said_in_the_tabs_language(tmp_path: Path) -> None:
    """The studio's refusals (the protocol's, the folder's, the arena's, the table's) are messages of the catalog: a
    German tab reads them in German, an English one in English (the same operations, one studio)."""

    async def replies(language: str) -> list[dict[str, Any]]:
        sent: list[dict[str, Any]] = []

        async def send(message: dict[str, Any]) -> None:
            sent.append(message)

        session = Session(Workspace(tmp_path), Hub(), send, language)
        try:
            for message in (
                {"op": "open", "path": ""},
                {"op": "edit", "row": "1", "col": 0, "value": ""},
                {"op": "explode"},
                [1],
                {"op": "open", "path": "../secret.csv"},
                {"op": "sim", "action": "play"},
                {"op": "save"},
            ):
                await session.handle(message)
        finally:
            session.close()
        return sent

    german = [m["message"] for m in run_async(replies("de"))]
    assert german == [
        '"path" muss Text sein',
        '"row" muss eine ganze Zahl sein',
        "unbekannte Operation 'explode'",
        'eine Nachricht muss ein JSON-Objekt mit einem "op" sein',
        "'../secret.csv' liegt außerhalb des freigegebenen Ordners",
        "der Roboter fährt nicht: zuerst die Tabelle berichtigen",
        "zuerst eine Tabelle öffnen",
    ]
    english = [m["message"] for m in run_async(replies("en"))]
    assert english == [
        '"path" must be text',
        '"row" must be a whole number',
        "unknown op 'explode'",
        'a message must be a JSON object with an "op"',
        "'../secret.csv' is outside the served folder",
        "the robot is not running: fix the table first",
        "open a table first",
    ]


def test_why_a_row_fired_is_said_in_the_tabs_language(tmp_path: Path) -> None:
    """The paused arena's why list (each row of the state: fired, or why not) in a German tab is German."""
    for name in ("table.csv", "robot.toml", "arena.toml", "properties.toml"):
        shutil.copy(EXAMPLE / name, tmp_path / name)

    async def why(language: str) -> list[str]:
        sent: list[dict[str, Any]] = []

        async def send(message: dict[str, Any]) -> None:
            sent.append(message)

        session = Session(Workspace(tmp_path), Hub(), send, language)
        try:
            await session.handle({"op": "open", "path": "table.csv"})
            await session.handle({"op": "sim", "action": "step"})
            for _ in range(200):
                await asyncio.sleep(0.02)
                await session.frame()
                frames = [m for m in sent if m["type"] == "frame" and m["tick"] >= 0 and m.get("why")]
                if frames:
                    return [item["why"] for item in frames[-1]["why"]]
        finally:
            session.close()
        raise AssertionError("no frame")

    german, english = run_async(why("de")), run_async(why("en"))
    assert english[0].startswith("line ") and " fired" in " ".join(english), english
    assert german[0].startswith("Zeile ") and "hat geschaltet" in " ".join(german), german
    assert len(german) == len(english)
