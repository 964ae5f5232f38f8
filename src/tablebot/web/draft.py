"""A tab's table: the file as it was read (or last saved), the draft edited from it, its robot file, and the
check of every edit (the analysis). Saving writes only the file the tab opened; a save that lost to a change
on disk leaves the draft as it is, to save anyway or drop."""

from __future__ import annotations

import asyncio
from collections.abc import Awaitable, Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from tablebot.diagnostics import TableBotError
from tablebot.formats.csv_document import MAX_TABLE_BYTES, CsvDocument
from tablebot.i18n import N_
from tablebot.robot import Robot
from tablebot.robot_tables import tables_of
from tablebot.table import Table
from tablebot.web.analyse import Analysis, analyse, robot_failed, robot_for, table_columns
from tablebot.web.errors import Refused, said
from tablebot.web.protocol import (
    AnalysisMsg,
    ConflictMsg,
    DeleteRow,
    DiagramMsg,
    Edit,
    GridMsg,
    InsertRow,
    Message,
    Restore,
    Save,
    SavedMsg,
    TableMsg,
)
from tablebot.web.workspace import BACKUP_SUFFIX, ChangedOnDisk, Kind, Opened, Workspace

Say = Callable[[Message], Awaitable[None]]


@dataclass(eq=False)
class Draft:
    """The table a tab edits; ``diagram`` draws a table's state diagram as SVG (the arena's, cached)."""

    workspace: Workspace
    say: Say
    diagram: Callable[[Table], str]
    opened: Opened | None = None  # the table file as read (or last saved): a save writes only this file
    base: str | None = None  # the version a restored draft started from, when not opened's
    doc: CsvDocument | None = None
    dirty: bool = False
    edits: int = 0  # changes made to the draft, ever: a reload does not replace a draft edited meanwhile
    analysis: Analysis | None = None
    robot: Robot | None = None  # the table's robot file, read when the table is opened
    robot_error: TableBotError | None = None
    #: The robot's other tables as this tab has them (edited), by name: checked and run with this one.
    others: Callable[[], Mapping[str, Table]] = dict

    @property
    def name(self) -> str:
        """The table's name in its robot's ``[tables]`` ("" for a robot of one table, or before it reads)."""
        table = None if self.analysis is None else self.analysis.table
        return "" if table is None else table.name

    def tabs(self) -> list[dict[str, str]]:
        """The robot's tables, a tab each on the page: name and file (relative to the folder, as opened)."""
        if self.robot is None or self.path is None:
            return []
        base = Path(self.robot.source).parent
        found = []
        for spec in tables_of(self.robot):
            path = (base / spec.file).resolve()
            if path.is_relative_to(self.workspace.root):
                found.append({"name": spec.name, "file": path.relative_to(self.workspace.root).as_posix()})
        return found

    @property
    def path(self) -> Path | None:
        """Where the open table is (the robot file, world and properties are looked for beside it)."""
        return None if self.opened is None else self.workspace.root / self.opened.name

    @property
    def version(self) -> str | None:
        """Digest of the file on disk this draft started from."""
        return self.base or (None if self.opened is None else self.opened.version)

    def runnable(self) -> Analysis | None:
        """The analysis of a table that reads (one the robot can run), or None."""
        analysis = self.analysis
        return analysis if analysis is not None and analysis.table is not None else None

    async def read(self, name: str) -> tuple[Opened, CsvDocument]:
        opened = await asyncio.to_thread(self.workspace.read, name, Kind.TABLE, MAX_TABLE_BYTES)
        return opened, CsvDocument.from_bytes(opened.data, opened.name)

    async def show(
        self,
        opened: Opened,
        doc: CsvDocument,
        unless_edited_since: int | None = None,
        replaced: Callable[[], None] = lambda: None,
    ) -> bool:
        """Make ``doc`` (read from ``opened``) the draft, with no edits, and send it to the page; not if the
        draft was edited after edit count ``unless_edited_since`` meanwhile (the edit would be lost).
        ``replaced`` runs once the draft is replaced, before the page hears of it (the old robot stops)."""
        path = self.workspace.root / opened.name
        try:
            robot, robot_error = await asyncio.to_thread(robot_for, path), None
        except TableBotError as exc:  # the grid still opens; the robot file's errors are listed
            robot, robot_error = None, exc
        if unless_edited_since is not None and self.edits != unless_edited_since:
            return False
        self.robot, self.robot_error = robot, robot_error
        self.opened, self.base, self.doc, self.dirty = opened, None, doc, False
        replaced()
        await self.resend()
        return True

    async def resend(self) -> None:
        """The draft to the page as it is now (opened, or its tab shown again with its edits)."""
        doc, opened = self.need_doc(), self.opened
        assert opened is not None
        await self.say(
            TableMsg(
                opened.name,
                doc.header_values(),
                doc.grid(),
                grid_lines(doc),
                self.version,
                {
                    "delimiter": doc.dialect.delimiter,
                    "encoding": doc.dialect.encoding,
                    "newline": repr(doc.dialect.newline)[1:-1],
                },
                self.dirty,
                table_columns(doc, self.workspace.root / opened.name, self.robot),
                None if self.robot is None else self.robot.tick_ms,
            )
        )

    async def reanalyse(self, seq: object) -> None:
        """Check the draft and send the analysis (and the state diagram of a table that reads)."""
        assert self.doc is not None and self.path is not None and self.opened is not None
        if self.robot is None:
            assert self.robot_error is not None
            await self.say(AnalysisMsg(seq, self.dirty, grid_lines(self.doc), robot_failed(self.robot_error, self.doc)))
            return
        self.analysis = await asyncio.to_thread(
            analyse, self.doc, self.path, self.robot, self.opened.name, self.others()
        )
        data = {**self.analysis.data, "tables": self.tabs()}
        await self.say(AnalysisMsg(seq, self.dirty, grid_lines(self.doc), data))
        if self.analysis.table is not None:
            await self.say(DiagramMsg(await asyncio.to_thread(self.diagram, self.analysis.table)))

    def touched(self) -> None:
        """The draft was edited (right after the change, before any await: see :meth:`show`)."""
        self.dirty = True
        self.edits += 1

    def need_doc(self) -> CsvDocument:
        if self.doc is None:
            raise Refused(N_("open a table first"))
        return self.doc

    async def edit(self, op: Edit) -> None:
        self.need_doc().set_cell(op.row, op.col, op.value)
        self.touched()
        await self.reanalyse(op.seq)

    async def insert_row(self, op: InsertRow) -> None:
        doc = self.need_doc()
        row = doc.insert_row(op.after)
        self.touched()
        await self.say(GridMsg(doc.grid(), focus=row))
        await self.reanalyse(op.seq)

    async def delete_row(self, op: DeleteRow) -> None:
        doc = self.need_doc()
        doc.delete_row(op.row)
        self.touched()
        await self.say(GridMsg(doc.grid()))
        await self.reanalyse(op.seq)

    async def save(self, op: Save) -> Opened | None:
        """Save the draft under the name this tab opened (see Workspace.save): the file saved, or None when the
        save lost to a change on disk (another tab's save among them), which the page is told."""
        doc = self.need_doc()
        assert self.opened is not None
        try:
            saved = await asyncio.to_thread(self.workspace.save, self.opened, doc.to_bytes(), op.force, self.base)
        except ChangedOnDisk as exc:
            await self.say(conflict(said(exc), exc.how, exc.theirs, exc.name, "save"))
            return None
        self.opened, self.base, self.dirty = saved.file, None, False
        await self.say(
            SavedMsg(
                "save",
                saved.file.version,
                saved.file.name,
                None if saved.backup is None else saved.file.name + BACKUP_SUFFIX,
                saved.backup,
            )
        )
        return saved.file

    async def restore(self, op: Restore) -> None:
        """A draft the page kept (the WebSocket dropped, the page was reloaded) made the draft again, over the
        file as it is now; if it started from another version, a save asks first."""
        self.need_doc()
        assert self.opened is not None
        doc = CsvDocument.from_bytes(self.opened.data, self.opened.name)
        doc.replace_grid(op.header, op.grid)
        if len(doc.to_bytes()) > MAX_TABLE_BYTES:
            raise Refused(N_("the restored table would have more than {most:,} bytes", most=MAX_TABLE_BYTES))
        self.doc, self.base = doc, op.base if op.base != self.opened.version else None
        self.touched()
        await self.say(GridMsg(doc.grid(), grid_lines(doc)))
        await self.reanalyse(op.seq)


def conflict(message: str, how: str, theirs: str, path: str, op: str) -> ConflictMsg:
    """The page's choice when the file on disk is not the draft's: save yours over theirs (version
    ``theirs``, kept as NAME.bak) or load theirs."""
    return ConflictMsg(
        op,
        message,
        how,
        theirs,
        path,
        path + BACKUP_SUFFIX,
        N_(
            "your edits are kept: save yours (theirs are kept as {backup}), or load theirs (yours are dropped)",
            backup=path + BACKUP_SUFFIX,
        ),
    )


def grid_lines(doc: CsvDocument) -> list[int]:
    """Each grid row's line in the file."""
    starts = doc.record_lines()
    return [starts[i] for i in doc.row_ids]
