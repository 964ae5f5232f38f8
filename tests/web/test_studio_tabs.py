"""A studio serves a bounded number of tabs (issue 33, section 4: 60 tabs, each with its robot live, made a
new request wait 20 s): one more is told why in the page's error banner, and once in the terminal; a place
comes free when a tab goes. Real servers, real WebSockets, a real Chromium. (The memory given back when tabs
go is measured by benchmarks/studio_tabs.py, not here.)
"""

from __future__ import annotations

import json
import shutil
from contextlib import ExitStack
from pathlib import Path
from typing import Any

import pytest
from websockets.sync.client import ClientConnection, connect

from core_helpers import EXAMPLE
from studio_helpers import studio_works, wait_for
from tablebot.web.app import Background

pytestmark = [pytest.mark.browser]


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("studio-tabs") / "bot"
    shutil.copytree(EXAMPLE, root)
    return root


def _tab(tabs: ExitStack, server: Background, wait: bool = False) -> ClientConnection | None:
    """A tab that opened the table (the page's WebSocket, closed with ``tabs``), once its robot is up;
    ``wait``: None if it was turned away."""
    ws = tabs.enter_context(
        connect(server.origin.replace("http", "ws") + "/ws", additional_headers=server.headers, max_size=2**24)
    )
    ws.send(json.dumps({"op": "open", "path": "table.csv"}))
    while (reply := json.loads(ws.recv(20)))["type"] not in ("arena", "error"):
        pass
    if wait and reply["type"] == "error":
        ws.close()
        return None
    assert reply["type"] == "arena", reply
    return ws


def _refused(server: Background) -> dict[str, Any]:
    """The studio's first answer to a tab that asks for the table (and the same to its next message)."""
    with connect(server.origin.replace("http", "ws") + "/ws", additional_headers=server.headers) as ws:
        ws.send(json.dumps({"op": "open", "path": "table.csv"}))
        reply: dict[str, Any] = json.loads(ws.recv(20))
        if reply["type"] == "error":
            ws.send(json.dumps({"op": "files"}))  # the connection stays: every message gets the same answer
            assert json.loads(ws.recv(20)) == reply
        return reply


def test_one_tab_more_than_the_studio_serves_is_told_why(folder: Path, caplog: pytest.LogCaptureFixture) -> None:
    server = Background(folder, "table.csv", max_tabs=3)
    try:
        with caplog.at_level("WARNING", logger="tablebot.studio"), ExitStack() as tabs:
            first, *_ = [_tab(tabs, server) for _ in range(3)]
            assert first is not None
            reply = _refused(server)
            assert _refused(server) == reply  # the terminal is told once, not once per tab
            first.close()  # a place comes free once the studio has seen the tab go (the next moment)
            wait_for(lambda: _tab(tabs, server, wait=True), "a place to come free", timeout=10)
    finally:
        server.stop()
    assert reply == {
        "type": "error",
        "op": "",
        "message": "this studio already has 3 tabs open, the most it "
        "serves at once: close one of them, then reload this tab",
    }
    said = [r.getMessage() for r in caplog.records if r.name == "tablebot.studio"]
    assert said == [
        "refused a tab: 3 tabs are open already, the most one studio serves at once (close one of them in the browser)"
    ], said


def test_the_refused_tab_shows_why_in_the_page(browser: Any, folder: Path) -> None:
    server = Background(folder, "table.csv", max_tabs=1)
    context = browser.new_context()
    try:
        first = context.new_page()
        first.goto(server.url)
        studio_works(first)
        second = context.new_page()
        second.goto(server.url)  # the printed address (the key is kept per tab, not in a cookie)
        second.wait_for_selector("#banner:not([hidden])")
        assert second.inner_text("#banner").startswith(
            "this studio already has 1 tab open, the most it serves at once: close one of them, then reload this tab"
        )
        first.close()  # the place comes free once the studio has seen the tab go (the next moment)
        wait_for(lambda: _reloaded(second), "the reloaded tab to be served", timeout=20)
        studio_works(second)
    finally:
        context.close()
        server.stop()


def _reloaded(page: Any) -> bool:
    """Reload the page: whether the studio served it this time."""
    page.reload()
    page.wait_for_selector("#play:not([disabled]), #banner:not([hidden])")
    return page.locator("#banner").is_hidden() or "already has" not in page.inner_text("#banner")
