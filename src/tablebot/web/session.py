"""One browser tab's session: its table draft, the checks of every edit, saving, and its live robot.

Messages in and out are plain JSON objects (``op`` in, ``type`` out); :meth:`Session.handle` answers
one message and never raises for bad input: the page gets an ``error`` reply instead.
"""

from __future__ import annotations

import asyncio
from collections.abc import Awaitable, Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tablebot.diagnostics import TableBotError
from tablebot.formats.csv_document import MAX_TABLE_BYTES, CsvDocument
from tablebot.robot import Robot
from tablebot.web.analyse import Analysis, analyse, explain, robot_failed, robot_for
from tablebot.web.errors import Refused, log
from tablebot.web.simulate import Arena, ArenaSettings
from tablebot.web.tracefile import MAX_PLAYER_TRACE_BYTES, read_trace_bytes, trace_columns
from tablebot.web.workspace import BACKUP_SUFFIX, OTHER_TAB, ChangedOnDisk, Kind, Opened, Workspace

Send = Callable[[dict[str, Any]], Awaitable[None]]
MAX_ROWS = 20_000  # a restored draft: far more than a table a person edits in a grid
MAX_COLUMNS = 200


class Hub:
    """Which sessions have which file open, so that a save reaches the other tabs."""

    def __init__(self) -> None:
        self.sessions: set[Session] = set()

    async def saved(self, by: Session, file: Opened) -> None:
        for other in list(self.sessions):
            if other is not by and other.opened is not None and other.opened.name == file.name:
                try:
                    await other.saved_elsewhere(file)
                except Exception as exc:  # that tab closed meanwhile (its send failed): this save stands
                    log.info("a tab was not told of the save of %s: %r", file.name, exc, exc_info=True)


@dataclass(eq=False)  # sessions are compared (and hashed) by identity
class Session:
    workspace: Workspace
    hub: Hub
    send: Send
    opened: Opened | None = None  # the table file as read (or last saved): a save writes only this file
    base: str | None = None  # the version a restored draft started from, when not opened's
    doc: CsvDocument | None = None
    dirty: bool = False
    edits: int = 0  # changes made to the draft, ever: a reload does not replace a draft edited meanwhile
    analysis: Analysis | None = None
    robot: Robot | None = None  # the table's robot file, read when the table is opened
    robot_error: TableBotError | None = None
    arena: Arena = field(default_factory=Arena)

    # --- dispatch --------------------------------------------------------------------------------------

    async def handle(self, message: Any) -> None:
        if not isinstance(message, dict) or not isinstance(message.get("op"), str):
            await self.error('a message must be a JSON object with an "op"')
            return
        handler = HANDLERS.get(message["op"])
        if handler is None:
            await self.error(f"unknown op {message['op']!r}")
            return
        try:
            await handler(self, message)
        except TableBotError as exc:
            await self.send({"type": "error", "message": exc.diagnostics[0].message if exc.diagnostics else str(exc),
                             "text": str(exc), "op": message["op"]})
        except Refused as exc:
            await self.error(str(exc), message["op"])

    @property
    def path(self) -> Path | None:
        """Where the open table is (the robot file, world and properties are looked for beside it)."""
        return None if self.opened is None else self.workspace.root / self.opened.name

    @property
    def version(self) -> str | None:
        """Digest of the file on disk this draft started from."""
        return self.base or (None if self.opened is None else self.opened.version)

    async def error(self, text: str, op: str = "") -> None:
        await self.send({"type": "error", "message": text, "op": op})

    def close(self) -> None:
        self.arena.close()

    # --- the table -------------------------------------------------------------------------------------

    async def open_table(self, message: dict[str, Any]) -> None:
        opened = await asyncio.to_thread(self.workspace.read, _text(message, "path"), Kind.TABLE, MAX_TABLE_BYTES)
        await self.show(opened, CsvDocument.from_bytes(opened.data, opened.name))

    async def show(self, opened: Opened, doc: CsvDocument, unless_edited_since: int | None = None) -> bool:
        """Make ``doc`` (read from ``opened``) this tab's draft, with no edits, and send it to the page; not if
        the draft was edited after edit count ``unless_edited_since`` meanwhile (the edit would be lost)."""
        path = self.workspace.root / opened.name
        try:
            robot, robot_error = await asyncio.to_thread(robot_for, path), None
        except TableBotError as exc:  # the grid still opens; the robot file's errors are listed
            robot, robot_error = None, exc
        if unless_edited_since is not None and self.edits != unless_edited_since:
            return False
        self.robot, self.robot_error = robot, robot_error
        self.opened, self.base, self.doc, self.dirty = opened, None, doc, False
        self.arena.close()
        self.arena = Arena()
        await self.send({"type": "table", "path": opened.name, "header": doc.header_values(),
                         "grid": doc.grid(), "lines": _grid_lines(doc), "version": self.version,
                         "dialect": {"delimiter": doc.dialect.delimiter, "encoding": doc.dialect.encoding,
                                     "newline": repr(doc.dialect.newline)[1:-1]}})
        await self.reanalyse(None)
        if self.analysis and self.analysis.table is not None:
            await self.reset_arena({})
        return True

    async def reanalyse(self, seq: Any) -> None:
        assert self.doc is not None and self.path is not None and self.opened is not None
        if self.robot is None:
            assert self.robot_error is not None
            await self.send({"type": "analysis", "seq": seq, "dirty": self.dirty, "lines": _grid_lines(self.doc),
                             **robot_failed(self.robot_error, self.doc)})
            return
        self.analysis = await asyncio.to_thread(analyse, self.doc, self.path, self.robot, self.opened.name)
        await self.send({"type": "analysis", "seq": seq, "dirty": self.dirty, "lines": _grid_lines(self.doc),
                         **self.analysis.data})
        if self.analysis.table is not None:
            svg = await asyncio.to_thread(self.arena.diagram, self.analysis.table)
            await self.send({"type": "diagram", "svg": svg})

    def touched(self) -> None:
        """The draft was edited (right after the change, before any await: see :meth:`show`)."""
        self.dirty = True
        self.edits += 1

    def _need_doc(self) -> CsvDocument:
        if self.doc is None:
            raise Refused("open a table first")
        return self.doc

    async def edit(self, message: dict[str, Any]) -> None:
        doc = self._need_doc()
        doc.set_cell(_int(message, "row"), _int(message, "col"), _text(message, "value", allow_empty=True))
        self.touched()
        await self.reanalyse(message.get("seq"))

    async def insert_row(self, message: dict[str, Any]) -> None:
        doc = self._need_doc()
        row = doc.insert_row(_int(message, "after"))
        self.touched()
        await self.send({"type": "grid", "grid": doc.grid(), "focus": row})
        await self.reanalyse(message.get("seq"))

    async def delete_row(self, message: dict[str, Any]) -> None:
        doc = self._need_doc()
        doc.delete_row(_int(message, "row"))
        self.touched()
        await self.send({"type": "grid", "grid": doc.grid()})
        await self.reanalyse(message.get("seq"))

    async def save(self, message: dict[str, Any]) -> None:
        """Save the draft under the name this session opened (see Workspace.save). A save that lost to a
        change on disk (another tab's save among them) is told so; the draft stays, to save anyway or drop."""
        doc = self._need_doc()
        assert self.opened is not None
        force = message.get("force", False)
        if not isinstance(force, (bool, str)):
            raise Refused('"force" must be the version the conflict named ("theirs")')
        try:
            saved = await asyncio.to_thread(self.workspace.save, self.opened, doc.to_bytes(), force, self.base)
        except ChangedOnDisk as exc:
            await self.send(_conflict(str(exc), exc.how, exc.theirs, exc.name, "save"))
            return
        self.opened, self.base, self.dirty = saved.file, None, False
        await self.send({"type": "saved", "op": "save", "version": saved.file.version, "path": saved.file.name,
                         "backup": None if saved.backup is None else saved.file.name + BACKUP_SUFFIX,
                         "backup_version": saved.backup})
        await self.hub.saved(self, saved.file)

    async def saved_elsewhere(self, file: Opened) -> None:
        """Another tab saved this file: reload it when this tab has no edits of its own, else say so."""
        if not self.dirty:
            shown = await self.show(file, CsvDocument.from_bytes(file.data, file.name), self.edits)
            if shown:
                await self.send({"type": "notice", "message": "reloaded: the table was saved in another tab"})
                return
        await self.send(_conflict(f"another tab saved {file.name} while this one has unsaved edits", OTHER_TAB,
                                  file.version, file.name, ""))

    async def restore(self, message: dict[str, Any]) -> None:
        """A draft the page kept (the WebSocket dropped, the page was reloaded) made this tab's draft again,
        over the file as it is now; if it started from another version, a save asks first."""
        self._need_doc()
        assert self.opened is not None
        header, grid = _rows(message, "header", single=True)[0], _rows(message, "grid")
        base = _text(message, "base")
        doc = CsvDocument.from_bytes(self.opened.data, self.opened.name)
        doc.replace_grid(header, grid)
        if len(doc.to_bytes()) > MAX_TABLE_BYTES:
            raise Refused(f"the restored table would have more than {MAX_TABLE_BYTES:,} bytes")
        self.doc, self.base = doc, base if base != self.opened.version else None
        self.touched()
        await self.send({"type": "grid", "grid": doc.grid(), "lines": _grid_lines(doc)})
        await self.reanalyse(message.get("seq"))

    # --- the arena -------------------------------------------------------------------------------------

    async def reset_arena(self, message: dict[str, Any]) -> None:
        if self.analysis is None or self.analysis.table is None or self.analysis.machine is None:
            raise Refused("fix the table's errors first: the robot runs only a table that reads")
        settings = ArenaSettings.of(message, self.arena.settings)
        info = await asyncio.to_thread(self.arena.reset, self.analysis.table, self.analysis.machine, settings)
        await self.send({"type": "arena", **info})

    async def control(self, message: dict[str, Any]) -> None:
        action = _text(message, "action")
        if action == "reset":
            await self.reset_arena(message)
            return
        self.arena.control(action, message)
        await self.send({"type": "control", **self.arena.status()})

    async def frame(self) -> None:
        """Send what the live robot did since the last frame (called by the app's timer)."""
        frame = self.arena.frame(explain)
        if frame is not None:
            await self.send(frame)

    # --- traces ----------------------------------------------------------------------------------------

    async def open_trace(self, message: dict[str, Any]) -> None:
        opened = await asyncio.to_thread(self.workspace.read, _text(message, "path"), Kind.TRACE,
                                         MAX_PLAYER_TRACE_BYTES)
        await self.send_trace(opened.data, opened.name)

    async def send_trace(self, data: bytes, name: str) -> None:
        lines = await asyncio.to_thread(read_trace_bytes, data, name)
        await self.send({"type": "trace", "name": name, "columns": trace_columns(lines)})

    async def counterexample(self, message: dict[str, Any]) -> None:
        """A property's counterexample: replayed on the table (trace player) or scripted into the arena."""
        if self.analysis is None or self.analysis.report is None:
            raise Refused("fix the table's errors first")
        name = _text(message, "name")
        result = next((r for r in self.analysis.report.results if r.prop.name == name), None)
        if result is None or not result.inputs:
            raise Refused(f"property {name!r} has no counterexample")
        if message.get("where") == "arena":
            await self.reset_arena({})
            self.arena.control("script", {"masks": [t.mask for t in result.inputs]})
            await self.send({"type": "control", **self.arena.status()})
            return
        from tablebot.replay import replay
        lines = list(replay(self.analysis.report.machine, result.inputs))
        await self.send({"type": "trace", "name": f"counterexample: {name}", "columns": trace_columns(lines),
                         "at_tick": result.at_tick})


def _conflict(message: str, how: str, theirs: str, path: str, op: str) -> dict[str, Any]:
    """The page's choice when the file on disk is not the draft's: save yours over theirs (version
    ``theirs``, kept as NAME.bak) or load theirs."""
    return {"type": "conflict", "op": op, "message": message, "how": how, "theirs": theirs, "path": path,
            "backup": path + BACKUP_SUFFIX,
            "hint": f"your edits are kept: save yours (theirs are kept as {path}{BACKUP_SUFFIX}), "
                    "or load theirs (yours are dropped)"}


def _grid_lines(doc: CsvDocument) -> list[int]:
    starts = doc.record_lines()
    return [starts[i] for i in doc.row_ids]


def _text(message: dict[str, Any], key: str, allow_empty: bool = False) -> str:
    value = message.get(key)
    if not isinstance(value, str) or (not value and not allow_empty):
        raise Refused(f'"{key}" must be text')
    return value


def _rows(message: dict[str, Any], key: str, single: bool = False) -> list[list[str]]:
    """A list of rows of text (``single``: one row) from the page."""
    value = message.get(key)
    rows = [value] if single else value
    if not isinstance(rows, list) or len(rows) > MAX_ROWS or not all(
            isinstance(row, list) and len(row) <= MAX_COLUMNS and all(isinstance(c, str) for c in row) for row in rows):
        raise Refused(f'"{key}" must be {"a row" if single else "rows"} of text (at most {MAX_ROWS:,} rows of '
                      f"{MAX_COLUMNS} cells)")
    return rows


def _int(message: dict[str, Any], key: str) -> int:
    value = message.get(key)
    if not isinstance(value, int) or isinstance(value, bool):
        raise Refused(f'"{key}" must be a whole number')
    return value


async def _list(session: Session, message: dict[str, Any]) -> None:
    await session.send({"type": "files", **await asyncio.to_thread(session.workspace.listing)})


HANDLERS: dict[str, Callable[[Session, dict[str, Any]], Awaitable[None]]] = {
    "open": Session.open_table, "edit": Session.edit, "insert_row": Session.insert_row,
    "delete_row": Session.delete_row, "save": Session.save, "restore": Session.restore, "sim": Session.control,
    "trace": Session.open_trace, "counterexample": Session.counterexample, "files": _list,
}
