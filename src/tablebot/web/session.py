"""One browser tab's session: its table draft, the checks of every edit, saving, and its live robot.

Messages in and out are plain JSON objects (``op`` in, ``type`` out); :meth:`Session.handle` answers
one message and never raises for bad input: the page gets an ``error`` reply instead.
"""

from __future__ import annotations

import asyncio
from collections.abc import Awaitable, Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from tablebot.diagnostics import TableBotError
from tablebot.robot import Robot
from tablebot.web.analyse import Analysis, analyse, explain, robot_failed, robot_for
from tablebot.web.document import MAX_TABLE_BYTES, CsvDocument
from tablebot.web.errors import Refused
from tablebot.web.simulate import Arena, ArenaSettings
from tablebot.web.tracefile import MAX_PLAYER_TRACE_BYTES, read_trace_bytes, trace_columns
from tablebot.web.workspace import ChangedOnDisk, Kind, Opened, Workspace

Send = Callable[[dict[str, Any]], Awaitable[None]]


class Hub:
    """Which sessions have which file open, so that a save reaches the other tabs."""

    def __init__(self) -> None:
        self.sessions: set[Session] = set()

    async def saved(self, by: Session, file: Opened) -> None:
        for other in list(self.sessions):
            if other is not by and other.opened is not None and other.opened.name == file.name:
                await other.saved_elsewhere(file)


@dataclass(eq=False)  # sessions are compared (and hashed) by identity
class Session:
    workspace: Workspace
    hub: Hub
    send: Send
    opened: Opened | None = None  # the table file as read (or last saved): a save writes only this file
    doc: CsvDocument | None = None
    dirty: bool = False
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
        return None if self.opened is None else self.opened.version

    async def error(self, text: str, op: str = "") -> None:
        await self.send({"type": "error", "message": text, "op": op})

    def close(self) -> None:
        self.arena.close()

    # --- the table -------------------------------------------------------------------------------------

    async def open_table(self, message: dict[str, Any]) -> None:
        opened = await asyncio.to_thread(self.workspace.read, _text(message, "path"), Kind.TABLE, MAX_TABLE_BYTES)
        doc = CsvDocument.from_bytes(opened.data, opened.name)
        path = self.workspace.root / opened.name
        try:
            self.robot, self.robot_error = await asyncio.to_thread(robot_for, path), None
        except TableBotError as exc:  # the grid still opens; the robot file's errors are listed
            self.robot, self.robot_error = None, exc
        self.opened, self.doc, self.dirty = opened, doc, False
        self.arena.close()
        self.arena = Arena()
        await self.send({"type": "table", "path": opened.name, "header": doc.header_values(),
                         "grid": doc.grid(), "lines": _grid_lines(doc), "version": self.version,
                         "dialect": {"delimiter": doc.dialect.delimiter, "encoding": doc.dialect.encoding,
                                     "newline": repr(doc.dialect.newline)[1:-1]}})
        await self.reanalyse(None)
        if self.analysis and self.analysis.table is not None:
            await self.reset_arena({})

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

    def _need_doc(self) -> CsvDocument:
        if self.doc is None:
            raise Refused("open a table first")
        return self.doc

    async def edit(self, message: dict[str, Any]) -> None:
        doc = self._need_doc()
        doc.set_cell(_int(message, "row"), _int(message, "col"), _text(message, "value", allow_empty=True))
        self.dirty = True
        await self.reanalyse(message.get("seq"))

    async def insert_row(self, message: dict[str, Any]) -> None:
        doc = self._need_doc()
        row = doc.insert_row(_int(message, "after"))
        self.dirty = True
        await self.send({"type": "grid", "grid": doc.grid(), "focus": row})
        await self.reanalyse(message.get("seq"))

    async def delete_row(self, message: dict[str, Any]) -> None:
        doc = self._need_doc()
        doc.delete_row(_int(message, "row"))
        self.dirty = True
        await self.send({"type": "grid", "grid": doc.grid()})
        await self.reanalyse(message.get("seq"))

    async def save(self, message: dict[str, Any]) -> None:
        """Save the draft over the file this session opened, and only that file (see Workspace.save)."""
        doc = self._need_doc()
        assert self.opened is not None
        try:
            saved = await asyncio.to_thread(self.workspace.save, self.opened, doc.to_bytes(),
                                            message.get("force") is True)
        except ChangedOnDisk as exc:
            await self.send({"type": "conflict", "message": f"{exc}: saving now would overwrite those changes",
                             "hint": "reload to see them (your edits are lost), or save anyway (theirs are lost)"})
            return
        self.opened, self.dirty = saved, False
        await self.send({"type": "saved", "version": saved.version, "path": saved.name,
                         "backup": saved.name + ".bak"})
        await self.hub.saved(self, saved)

    async def saved_elsewhere(self, file: Opened) -> None:
        """Another tab saved this file: reload it when this tab has no edits of its own, else say so."""
        assert self.opened is not None
        if self.dirty:  # the file on disk is now the one the other tab wrote: a forced save may replace it
            self.opened = replace(self.opened, identity=file.identity, mode=file.mode)
            await self.send({"type": "conflict", "message": "another tab saved this table; yours has unsaved edits",
                             "hint": "reload to take theirs, or save anyway to keep yours"})
            return
        await self.open_table({"path": file.name, "reason": "saved in another tab"})
        await self.send({"type": "notice", "message": "reloaded: the table was saved in another tab"})

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


def _grid_lines(doc: CsvDocument) -> list[int]:
    starts = doc.record_lines()
    return [starts[i] for i in doc.row_ids]


def _text(message: dict[str, Any], key: str, allow_empty: bool = False) -> str:
    value = message.get(key)
    if not isinstance(value, str) or (not value and not allow_empty):
        raise Refused(f'"{key}" must be text')
    return value


def _int(message: dict[str, Any], key: str) -> int:
    value = message.get(key)
    if not isinstance(value, int) or isinstance(value, bool):
        raise Refused(f'"{key}" must be a whole number')
    return value


async def _list(session: Session, message: dict[str, Any]) -> None:
    await session.send({"type": "files", **await asyncio.to_thread(session.workspace.listing)})


HANDLERS: dict[str, Callable[[Session, dict[str, Any]], Awaitable[None]]] = {
    "open": Session.open_table, "edit": Session.edit, "insert_row": Session.insert_row,
    "delete_row": Session.delete_row, "save": Session.save, "sim": Session.control,
    "trace": Session.open_trace, "counterexample": Session.counterexample, "files": _list,
}
