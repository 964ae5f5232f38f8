"""The studio never loses a user's edits (issue 33, section 2), tested on a real server on loopback spoken to
by real WebSocket clients: tabs saving one table at once are serialised (each told the truth, each edit
either in the table or in the chain of backups), a table replaced by rename offers the same choice as one
edited in place, and line breaks in a cell are normalised. The page's part (the conflict dialog, drafts kept
in the browser) is in test_studio_drafts.py; a save cut by kill -9 in test_studio_temporaries.py.
"""

from __future__ import annotations

import asyncio
import hashlib
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import websockets

from studio_helpers import bumberbot, run_async, served
from tablebot.web.app import Background

TABS = 8
DESCRIPTION = 0


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    return bumberbot(tmp_path)


@pytest.fixture
def studio(folder: Path) -> Iterator[Background]:
    yield from served(folder)


def version(data: bytes) -> str:
    """The studio's version of a file's bytes (its digest), computed here independently."""
    return hashlib.sha256(data).hexdigest()[:16]


def marked(original: bytes, row: int, text: str) -> bytes:
    """The table with grid row ``row``'s description set to ``text`` (what that tab's draft must save)."""
    lines = original.split(b"\n")
    line = lines[row + 1]
    lines[row + 1] = text.encode() + line[line.index(b",") :]
    return b"\n".join(lines)


class Tab:
    """One tab's WebSocket, with every message it received kept in order."""

    def __init__(self, ws: Any) -> None:
        self.ws = ws
        self.seen: list[dict[str, Any]] = []

    async def send(self, message: dict[str, Any]) -> None:
        await self.ws.send(json.dumps(message))

    async def until(self, *types: str, op: str | None = None) -> dict[str, Any]:
        """The next message of one of ``types`` (and, if given, answering ``op``)."""
        while True:
            reply = json.loads(await asyncio.wait_for(self.ws.recv(), 20))
            self.seen.append(reply)
            if reply["type"] in types and (op is None or reply.get("op") == op):
                return reply


async def open_tab(server: Background, path: str = "table.csv") -> Tab:
    ws = await websockets.connect(
        server.origin.replace("http", "ws") + "/ws", max_size=2**24, max_queue=None, additional_headers=server.headers
    )  # unread notices never hold up its close
    tab = Tab(ws)
    await tab.send({"op": "open", "path": path})
    await tab.until("analysis")
    return tab


async def edit(tab: Tab, row: int, col: int, value: str, seq: int = 1) -> dict[str, Any]:
    await tab.send({"op": "edit", "row": row, "col": col, "value": value, "seq": seq})
    while True:
        reply = await tab.until("analysis", "error")
        if reply["type"] == "error" or reply.get("seq") == seq:
            return reply


async def save(tab: Tab, force: object = None) -> dict[str, Any]:
    """Save, and the answer to that save (not a notice that another tab saved)."""
    await tab.send({"op": "save", **({} if force is None else {"force": force})})
    return await tab.until("saved", "conflict", "error", op="save")


def test_eight_tabs_saving_at_once_lose_no_edit(studio: Background, folder: Path) -> None:
    """Eight tabs edit one cell each and save at the same moment: one is told "saved", the seven others are
    told their save lost and keep their drafts; each then saves anyway (over the version it was shown), at
    the same moment again, until all are saved: every saved version is the table or was moved to the
    backup by the save after it, so no tab told "saved" lost its edit."""
    path = folder / "table.csv"
    original = path.read_bytes()
    texts = [f"tab {i} was here" for i in range(TABS)]
    wanted = {version(marked(original, i, text)): i for i, text in enumerate(texts)}

    async def run() -> tuple[list[dict[str, Any]], list[tuple[int, dict[str, Any]]]]:
        tabs = [await open_tab(studio) for _ in range(TABS)]
        await asyncio.gather(*(edit(tab, i, DESCRIPTION, texts[i]) for i, tab in enumerate(tabs)))
        first = await asyncio.gather(*(save(tab) for tab in tabs))
        chain = [(i, reply) for i, reply in enumerate(first) if reply["type"] == "saved"]
        on_disk = path.read_bytes(), (folder / "table.csv.bak").read_bytes()

        async def insist(i: int, reply: dict[str, Any]) -> None:
            while reply["type"] == "conflict":  # "keep theirs in the backup, save mine", as often as it takes
                reply = await save(tabs[i], force=reply["theirs"])
            assert reply["type"] == "saved", reply
            chain.append((i, reply))

        await asyncio.gather(*(insist(i, reply) for i, reply in enumerate(first) if reply["type"] != "saved"))
        for tab in tabs:
            await tab.ws.close()
        assert on_disk[1] == original and version(on_disk[0]) == first_saved(first)
        return first, chain

    first, chain = run_async(run())
    assert [r["type"] for r in first].count("saved") == 1
    for reply in first:
        if reply["type"] == "conflict":
            assert reply["message"] == "table.csv was saved in another tab since you opened it"
            assert "your edits are kept" in reply["hint"] and reply["theirs"] == first_saved(first)
    assert sorted(i for i, _ in chain) == list(range(TABS))
    for i, reply in chain:  # each tab saved exactly its own draft
        assert wanted[reply["version"]] == i
    # the chain: each save moved the one before it to the backup, from the original to the table
    after = {reply["backup_version"]: reply["version"] for _, reply in chain}
    versions = [version(original)]
    while versions[-1] in after:
        versions.append(after[versions[-1]])
    assert len(versions) == TABS + 1 and version(path.read_bytes()) == versions[-1]
    assert version((folder / "table.csv.bak").read_bytes()) == versions[-2]


def first_saved(replies: list[dict[str, Any]]) -> str:
    return next(r["version"] for r in replies if r["type"] == "saved")


def replace_by_rename(path: Path, data: bytes) -> None:
    """What an editor's atomic save, ``sed -i`` or ``git checkout`` does: another file renamed over it."""
    (path.parent / "incoming.tmp").write_bytes(data)
    (path.parent / "incoming.tmp").replace(path)


def test_a_table_replaced_by_rename_offers_the_choice_and_both_answers_work(studio: Background, folder: Path) -> None:
    path = folder / "table.csv"
    original = path.read_bytes()
    theirs = marked(original, 5, "theirs")

    async def run() -> None:
        mine, other = await open_tab(studio), await open_tab(studio)
        for tab in (mine, other):
            await edit(tab, 2, DESCRIPTION, "mine")
        replace_by_rename(path, theirs)
        for tab in (mine, other):
            reply = await save(tab)
            assert reply["type"] == "conflict" and reply["how"] == "replaced", reply
            assert reply["message"] == "table.csv was replaced on disk since you opened it"
            assert reply["theirs"] == version(theirs) and path.read_bytes() == theirs
        # keep theirs in the backup, save mine
        saved = await save(mine, force=version(theirs))
        assert saved["type"] == "saved" and saved["backup_version"] == version(theirs)
        assert path.read_bytes() == marked(original, 2, "mine") and (folder / "table.csv.bak").read_bytes() == theirs
        # the other tab loads theirs (now mine's): its draft is dropped, and it saves nothing over them
        await other.send({"op": "open", "path": "table.csv"})
        loaded = await other.until("table")
        assert loaded["grid"][2][DESCRIPTION] == "mine" and loaded["version"] == saved["version"]
        assert (await other.until("analysis"))["dirty"] is False
        for tab in (mine, other):
            await tab.ws.close()

    run_async(run())


def test_a_forced_save_overwrites_only_the_version_it_was_shown(studio: Background, folder: Path) -> None:
    """ "Save mine" names their version: if the file changed again meanwhile, it asks again; a table replaced
    by the same bytes (a checkout of the same commit) asks nothing; a deleted table is written again."""
    path = folder / "table.csv"
    original = path.read_bytes()

    async def run() -> None:
        tab = await open_tab(studio)
        await edit(tab, 2, DESCRIPTION, "mine")
        replace_by_rename(path, marked(original, 5, "first"))
        shown = await save(tab)
        replace_by_rename(path, marked(original, 5, "second"))
        again = await save(tab, force=shown["theirs"])
        assert again["type"] == "conflict" and again["theirs"] == version(marked(original, 5, "second"))
        assert path.read_bytes() == marked(original, 5, "second")
        path.unlink()
        gone = await save(tab, force=again["theirs"])
        assert gone["type"] == "conflict" and gone["how"] == "deleted" and gone["theirs"] == "deleted"
        written = await save(tab, force="deleted")
        assert written["type"] == "saved" and written["backup"] is None and written["backup_version"] is None
        assert path.read_bytes() == marked(original, 2, "mine")
        replace_by_rename(path, path.read_bytes())  # the same bytes, another file
        await edit(tab, 3, DESCRIPTION, "more", seq=2)
        assert (await save(tab))["type"] == "saved"
        bad = await save(tab, force=7)
        assert bad["type"] == "error" and bad["message"] == '"force" must be the version the conflict named ("theirs")'
        await tab.ws.close()

    run_async(run())


# --- line breaks in a cell, and a draft put back ------------------------------------------------------------


@pytest.mark.parametrize("newline", ["\n", "\r\n"])
@pytest.mark.parametrize("typed", ["two\r\nlines", "two\rlines", "two\nlines"])
def test_a_line_break_in_a_cell_is_one_line_break_whoever_sent_it(newline: str, typed: str) -> None:
    """A client other than the browser may send \\r\\n or \\r: the file gets one line end of its own kind."""
    from tablebot.formats.csv_document import CsvDocument

    doc = CsvDocument.from_text(newline.join(["description,state,next", "x,1,1", "y,1,1", ""]))
    doc.set_cell(0, 0, typed)
    doc.insert_row(1, [typed, "1", "1"])
    assert doc.text() == newline.join(
        ["description,state,next", '"two', 'lines",1,1', "y,1,1", '"two', 'lines",1,1', ""]
    )
    assert doc.grid()[0][0] == "two\nlines" and CsvDocument.from_text(doc.text()).grid() == doc.grid()


def test_a_line_break_sent_over_the_socket_adds_one_line(studio: Background, folder: Path) -> None:
    path = folder / "table.csv"
    original = path.read_bytes()

    async def run() -> None:
        tab = await open_tab(studio)
        await edit(tab, 0, DESCRIPTION, "Collision\r\ndetection")
        assert (await save(tab))["type"] == "saved"
        await tab.ws.close()

    run_async(run())
    assert path.read_bytes() == original.replace(b"Collision detection,1,,1,1,", b'"Collision\ndetection",1,,1,1,', 1)
    assert path.read_bytes().count(b"\n") == original.count(b"\n") + 1


def test_a_draft_put_back_changes_only_what_it_changed(studio: Background, folder: Path) -> None:
    """The page sends back the whole grid it kept: rows alike keep their bytes, an edited row is edited, a row
    added or deleted is added or deleted; it is a draft (unsaved) until saved."""
    path = folder / "table.csv"
    original = path.read_bytes()
    lines = original.decode().split("\n")
    wanted = [*lines[:3], ",1,,,,,,,,0,,0,1,1", *lines[3:5], lines[5].replace(",2,", ",7,", 1), *lines[7:]]

    async def run() -> None:
        tab = await open_tab(studio)
        loaded = next(m for m in tab.seen if m["type"] == "table")
        grid = [row[:] for row in loaded["grid"]]
        grid.insert(2, ["", "1", "", "", "", "", "", "", "", "0", "", "0", "1", "1"])
        grid[5][1] = "7"
        del grid[6]
        await tab.send({"op": "restore", "base": loaded["version"], "header": loaded["header"], "grid": grid, "seq": 5})
        shown = await tab.until("grid")
        assert shown["grid"] == grid and len(shown["lines"]) == len(grid)
        assert (await tab.until("analysis"))["dirty"] is True and path.read_bytes() == original
        assert (await save(tab))["type"] == "saved"
        await tab.ws.close()

    run_async(run())
    assert path.read_text() == "\n".join(wanted)


def test_a_draft_from_an_older_version_asks_before_it_is_saved(studio: Background, folder: Path) -> None:
    path = folder / "table.csv"
    original = path.read_bytes()

    async def run() -> None:
        tab = await open_tab(studio)
        loaded = next(m for m in tab.seen if m["type"] == "table")
        grid = [row[:] for row in loaded["grid"]]
        grid[2][DESCRIPTION] = "mine"
        replace_by_rename(path, marked(original, 5, "theirs"))
        await tab.send({"op": "open", "path": "table.csv"})
        await tab.until("analysis")
        await tab.send({"op": "restore", "base": loaded["version"], "header": loaded["header"], "grid": grid})
        await tab.until("analysis")
        asked = await save(tab)
        assert asked["type"] == "conflict" and asked["how"] == "changed"
        assert asked["theirs"] == version(marked(original, 5, "theirs"))
        assert (await save(tab, force=asked["theirs"]))["type"] == "saved"
        bad = {"op": "restore", "base": "x", "header": loaded["header"], "grid": [["1", 2]]}
        await tab.send(bad)
        assert (await tab.until("error"))["message"].startswith('"grid" must be rows of text')
        await tab.send({**bad, "grid": [], "header": ["state", "next"]})
        assert "the table now has 14 columns, the edits 2" in (await tab.until("error"))["message"]
        await tab.ws.close()

    run_async(run())
    assert path.read_bytes() == marked(original, 2, "mine")
    assert (folder / "table.csv.bak").read_bytes() == marked(original, 5, "theirs")


def test_a_reload_for_another_tabs_save_never_replaces_an_edit_made_meanwhile(folder: Path) -> None:
    """Tab b, with no edits, reloads the table tab a saved; an edit b sends while the reload reads the
    robot file stays b's (b is told of a's save instead), rather than being replaced by the reloaded table.
    The studio's threads are one worker here, held while the edit comes, to make that moment certain."""
    import threading
    from concurrent.futures import ThreadPoolExecutor

    from tablebot.web.session import Hub, Session
    from tablebot.web.workspace import Workspace

    async def run() -> list[dict[str, Any]]:
        loop = asyncio.get_running_loop()
        loop.set_default_executor(ThreadPoolExecutor(max_workers=1))
        hub, workspace, held = Hub(), Workspace(folder), threading.Event()
        told: list[dict[str, Any]] = []

        async def to_a(message: dict[str, Any]) -> None:
            if message["type"] == "saved":  # b reloads next: the worker is busy, b waits for it
                loop.run_in_executor(None, held.wait)
                edits.append(asyncio.create_task(b.handle({"op": "edit", "row": 1, "col": 0, "value": "b's"})))

        async def to_b(message: dict[str, Any]) -> None:
            told.append(message)

        edits: list[asyncio.Task[None]] = []
        a, b = Session(workspace, hub, to_a), Session(workspace, hub, to_b)
        hub.sessions |= {a, b}
        for tab in (a, b):
            await tab.handle({"op": "open", "path": "table.csv"})
        await a.handle({"op": "edit", "row": 0, "col": 0, "value": "a's"})
        saving = asyncio.create_task(a.handle({"op": "save"}))
        while not edits or b.draft.edits == 0:
            await asyncio.sleep(0.01)
        held.set()  # the edit is made; the reload goes on
        await saving
        await edits[0]
        assert b.draft.doc is not None and b.draft.doc.grid()[1][0] == "b's" and b.draft.dirty
        for tab in (a, b):
            tab.close()
        return told

    told = run_async(run())
    after = [m["type"] for m in told][[m["type"] for m in told].index("arena") + 1 :]  # b's messages since it opened
    assert after == ["conflict", "analysis", "diagram"]
    assert next(m for m in told if m["type"] == "conflict")["message"] == (
        "another tab saved table.csv while this one has unsaved edits"
    )
