"""One browser tab's session: what it owns is in three parts, its table (:class:`~tablebot.web.draft.Draft`:
the draft, its checks, saving), its arena robot (:class:`~tablebot.web.arena_robot.ArenaRobot`) and its trace
player (:class:`~tablebot.web.trace_player.TracePlayer`); this module dispatches each operation from the page
to its part and tells the other tabs of a save.

Messages in and out are the typed operations and messages of :mod:`tablebot.web.protocol`;
:meth:`Session.handle` answers one message and never raises for bad input: the page gets an ``error`` reply
instead.
"""

from __future__ import annotations

import asyncio
from collections.abc import Awaitable, Callable
from dataclasses import dataclass, field
from typing import Any

from tablebot.diagnostics import TableBotError
from tablebot.formats.csv_document import CsvDocument
from tablebot.i18n import N_, speaking
from tablebot.table import Table
from tablebot.web.arena_robot import ArenaRobot
from tablebot.web.draft import Draft, conflict
from tablebot.web.errors import Refused, log, said
from tablebot.web.new_robot import new_robot
from tablebot.web.protocol import (
    Counterexample,
    DeleteRow,
    Edit,
    ErrorMsg,
    Files,
    FilesMsg,
    InsertRow,
    Message,
    NewRobot,
    NoticeMsg,
    Open,
    OpenLink,
    Operation,
    Restore,
    Save,
    Share,
    SharedMsg,
    Sim,
    Trace,
    op_name,
    operation,
)
from tablebot.web.sharing import open_link, share
from tablebot.web.trace_player import TracePlayer
from tablebot.web.words import diagnostics_text, localised
from tablebot.web.workspace import OTHER_TAB, Kind, Opened, Workspace

Send = Callable[[dict[str, Any]], Awaitable[None]]


def _nothing() -> None:
    """What replacing a draft does to a robot that goes on running (another table of its robot shown)."""


class Hub:
    """Which sessions have which file open, so that a save reaches the other tabs."""

    def __init__(self) -> None:
        self.sessions: set[Session] = set()

    async def saved(self, by: Session, file: Opened) -> None:
        for other in list(self.sessions):
            if other is not by and file.name in other.drafts:
                try:
                    await other.saved_elsewhere(file)
                except Exception as exc:  # that tab closed meanwhile (its send failed): this save stands
                    log.info("a tab was not told of the save of %s: %r", file.name, exc, exc_info=True)


@dataclass(eq=False)  # sessions are compared (and hashed) by identity
class Session:
    workspace: Workspace
    hub: Hub
    send: Send
    language: str = "en"  # the page's (tablebot.i18n's name): what the server says to this tab is in it
    robot: ArenaRobot = field(init=False)
    draft: Draft = field(init=False)  # the table the page shows
    #: Every table this tab has open, by file: a robot of several tables has a tab for each on the page, each
    #: with its own draft (edits kept while another is shown) and saved to its own file.
    drafts: dict[str, Draft] = field(init=False, default_factory=dict)
    player: TracePlayer = field(init=False)

    def __post_init__(self) -> None:
        self.robot = ArenaRobot(self.say, lambda: self.draft.analysis)
        self.draft = self.new_draft()
        self.player = TracePlayer(self.workspace, self.say, lambda: self.draft.analysis, self.robot)

    def diagram(self, table: Table) -> str:
        """The state diagram in this tab's language, whatever the studio process speaks (its timers' 1,5 s,
        its words): another tab may speak another."""
        with speaking(self.language):
            return self.robot.diagram(table)

    def new_draft(self) -> Draft:
        draft = Draft(self.workspace, self.say, self.diagram)
        draft.others = lambda: {
            d.name: d.analysis.table
            for d in self.drafts.values()
            if d is not draft and d.name and d.analysis is not None and d.analysis.table
        }
        return draft

    async def say(self, message: Message) -> None:
        await self.send(localised(message.data(), self.language))

    async def handle(self, message: Any) -> None:
        try:
            name = op_name(message)
        except Refused as exc:
            await self.error(said(exc))
            return
        try:
            await self.dispatch(operation(message))
        except TableBotError as exc:
            await self.say(
                ErrorMsg(
                    exc.diagnostics[0].message if exc.diagnostics else said(exc),
                    name,
                    diagnostics_text(exc.diagnostics, self.language),
                )
            )
        except Refused as exc:
            await self.error(said(exc), name)

    async def dispatch(self, op: Operation) -> None:
        """Carry out one operation, by the part that owns what it changes."""
        match op:
            case Open():
                await self.open(op.path)
            case Edit():
                await self.draft.edit(op)
            case InsertRow():
                await self.draft.insert_row(op)
            case DeleteRow():
                await self.draft.delete_row(op)
            case Save():
                saved = await self.draft.save(op)
                if saved is not None:
                    await self.hub.saved(self, saved)
            case Restore():
                await self.draft.restore(op)
            case Sim():
                await self.robot.control(op)
            case Trace():
                await self.player.open(op)
            case Counterexample():
                await self.player.counterexample(op)
            case Files():
                await self.say(FilesMsg(await asyncio.to_thread(self.workspace.listing)))
            case Share():
                doc, table = self.draft.need_doc(), self.draft.path
                assert table is not None
                link, qr = await asyncio.to_thread(share, table, doc.text())
                await self.say(SharedMsg(link, qr))
            case OpenLink():
                path = await asyncio.to_thread(open_link, self.workspace.root, op.link)
                await self.say(FilesMsg(await asyncio.to_thread(self.workspace.listing)))
                await self.dispatch(Open(path))
                await self.say(NoticeMsg(N_("the link's table is in {path}, as it was shared", path=path)))
            case NewRobot():
                path = await asyncio.to_thread(new_robot, self.workspace.root, op.template, op.name)
                await self.say(FilesMsg(await asyncio.to_thread(self.workspace.listing)))
                await self.dispatch(Open(path))
            case _:
                raise AssertionError(f"no handler for {op!r}")  # protocol.OPERATIONS and this match differ

    async def open(self, path: str) -> None:
        """Show table ``path``: the draft this tab has of it (another table's tab of the same robot, shown
        again with its edits), else the file read afresh."""
        kept = self.drafts.get(await asyncio.to_thread(self.workspace.locate, path, Kind.TABLE))
        if kept is not None and kept.doc is not None and kept is not self.draft:
            self.draft = kept
            await kept.resend()
            await self.reanalyse_shown()
            return
        draft = self.new_draft()
        opened, doc = await draft.read(path)
        same = self.same_robot(opened.name)
        first_look = same and opened.name not in self.drafts  # another table's tab: the robot runs on
        if not same:
            self.drafts.clear()  # another robot: its tables' drafts are not this one's
        self.draft = self.drafts[opened.name] = draft
        await self.show(opened, doc, restart=not first_look)

    def same_robot(self, name: str) -> bool:
        """Whether table ``name`` is one of the tables of the robot this tab shows (a tab of it)."""
        return any(tab["file"] == name for tab in self.draft.tabs())

    async def show(
        self, opened: Opened, doc: CsvDocument, unless_edited_since: int | None = None, restart: bool = True
    ) -> bool:
        """Make ``doc`` this tab's draft (:meth:`Draft.show`), check it, and start its arena robot over (not
        with ``restart`` False, when it runs this table's robot already: the first look at another table)."""
        if not await self.draft.show(opened, doc, unless_edited_since, self.robot.restart if restart else _nothing):
            return False
        await self.reanalyse_shown()
        return True

    async def reanalyse_shown(self) -> None:
        """Check the draft shown, and run its robot in the arena (the frames speak of the table shown)."""
        await self.draft.reanalyse(None)
        analysis = self.draft.runnable()
        if analysis is not None and not self.robot.runs(analysis):
            self.robot.restart()
            self.robot.view(self.draft.name)
            await self.robot.reset({})
        self.robot.view(self.draft.name)

    async def saved_elsewhere(self, file: Opened) -> None:
        """Another tab saved this file: reload it when this tab has no edits of its own, else say so (a table
        not shown now, without edits, is read afresh when its tab is shown again)."""
        if self.draft is not self.drafts.get(file.name):
            if not self.drafts[file.name].dirty:
                del self.drafts[file.name]
            return
        if not self.draft.dirty:
            shown = await self.show(file, CsvDocument.from_bytes(file.data, file.name), self.draft.edits)
            if shown:
                await self.say(NoticeMsg(N_("reloaded: the table was saved in another tab")))
                return
        await self.say(
            conflict(
                N_("another tab saved {name} while this one has unsaved edits", name=file.name),
                OTHER_TAB,
                file.version,
                file.name,
                "",
            )
        )

    async def error(self, text: str, op: str = "") -> None:
        await self.say(ErrorMsg(text, op))

    async def frame(self) -> None:
        """Send what the arena robot did since the last frame (called by the app's timer)."""
        await self.robot.frame()

    def close(self) -> None:
        self.robot.close()
