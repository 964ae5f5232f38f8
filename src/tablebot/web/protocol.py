"""The studio's WebSocket protocol, both ways, in one place: every operation the page sends (``op``) and
every message the server sends back (``type``), each a typed object with its fields.

:func:`operation` reads a message from the page into its :class:`Operation` (a mistake in it is a
:class:`~tablebot.web.errors.Refused` in the studio's words, which the page shows); a :class:`Message`'s
:meth:`~Message.data` is what goes to the page as JSON. The page's side is ``static/js/studio/protocol.js``,
which names the same operations and kinds (tests/test_studio_protocol.py holds them equal).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

from tablebot.web.errors import Refused

__all__ = [
    "MESSAGES", "OPERATIONS", "AnalysisMsg", "ArenaMsg", "ConflictMsg", "ControlMsg", "Counterexample",
    "DeleteRow", "DiagramMsg", "Edit", "ErrorMsg", "Files", "FilesMsg", "FrameMsg", "GridMsg", "InsertRow",
    "Message", "NewRobot", "NoticeMsg", "Open", "OpenLink", "Operation", "Restore", "Save", "SavedMsg", "Share",
    "SharedMsg", "Sim", "TableMsg", "Trace", "TraceMsg", "op_name", "operation",
]

MAX_ROWS = 20_000  # a restored draft: far more than a table a person edits in a grid
MAX_COLUMNS = 200
#: What the page is told when a message is not an operation at all.
NOT_AN_OPERATION = 'a message must be a JSON object with an "op"'


# --- operations: the page to the server -----------------------------------------------------------------


@dataclass(frozen=True)
class Operation:
    """One message from the page; ``op`` is its name on the wire."""

    op: ClassVar[str]

    @classmethod
    def of(cls, message: Mapping[str, Any]) -> Operation:
        return cls()

    @classmethod
    def wire_fields(cls) -> tuple[str, ...]:
        """The fields it may carry on the wire, besides ``op``."""
        return tuple(f.name for f in fields(cls))


@dataclass(frozen=True)
class Open(Operation):
    """Open a table of the folder (``path``, relative to it)."""

    op: ClassVar[str] = "open"
    path: str

    @classmethod
    def of(cls, message: Mapping[str, Any]) -> Open:
        return cls(_text(message, "path"))


@dataclass(frozen=True)
class Edit(Operation):
    """Set one cell of the draft (grid ``row`` and ``col``) to ``value``; ``seq`` comes back on the analysis."""

    op: ClassVar[str] = "edit"
    row: int
    col: int
    value: str
    seq: Any = None

    @classmethod
    def of(cls, message: Mapping[str, Any]) -> Edit:
        return cls(_int(message, "row"), _int(message, "col"), _text(message, "value", allow_empty=True),
                   message.get("seq"))


@dataclass(frozen=True)
class InsertRow(Operation):
    """A new row after grid row ``after``."""

    op: ClassVar[str] = "insert_row"
    after: int
    seq: Any = None

    @classmethod
    def of(cls, message: Mapping[str, Any]) -> InsertRow:
        return cls(_int(message, "after"), message.get("seq"))


@dataclass(frozen=True)
class DeleteRow(Operation):
    op: ClassVar[str] = "delete_row"
    row: int
    seq: Any = None

    @classmethod
    def of(cls, message: Mapping[str, Any]) -> DeleteRow:
        return cls(_int(message, "row"), message.get("seq"))


@dataclass(frozen=True)
class Save(Operation):
    """Save the draft; ``force``: the version on disk a conflict named, to save over it anyway."""

    op: ClassVar[str] = "save"
    force: bool | str = False

    @classmethod
    def of(cls, message: Mapping[str, Any]) -> Save:
        force = message.get("force", False)
        if not isinstance(force, bool | str):
            raise Refused('"force" must be the version the conflict named ("theirs")')
        return cls(force)


@dataclass(frozen=True)
class Restore(Operation):
    """A draft the page kept (``header`` and ``grid``, started from version ``base``) made the draft again."""

    op: ClassVar[str] = "restore"
    header: list[str]
    grid: list[list[str]]
    base: str
    seq: Any = None

    @classmethod
    def of(cls, message: Mapping[str, Any]) -> Restore:
        return cls(_rows(message, "header", single=True)[0], _rows(message, "grid"), _text(message, "base"),
                   message.get("seq"))


@dataclass(frozen=True)
class Sim(Operation):
    """The arena's robot: ``action`` is play, pause, step, speed (``speed``), hold (``input``, ``on``), script
    (``masks``) or reset (``seed``, ``charge``, ``start`` [x, y, heading], ``lamp`` [x, y], ``speed``,
    ``paused``); ``fields`` holds those, which the arena reads and refuses in its own words
    (:mod:`tablebot.web.simulate`)."""

    op: ClassVar[str] = "sim"
    #: The actions' fields, all optional.
    ARENA_FIELDS: ClassVar[tuple[str, ...]] = ("speed", "input", "on", "masks", "seed", "charge", "start", "lamp",
                                               "paused")
    action: str
    fields: Mapping[str, Any] = field(default_factory=dict)

    @classmethod
    def of(cls, message: Mapping[str, Any]) -> Sim:
        action = _text(message, "action")
        return cls(action, {k: v for k, v in message.items() if k not in ("op", "action")})

    @classmethod
    def wire_fields(cls) -> tuple[str, ...]:
        return ("action", *cls.ARENA_FIELDS)


@dataclass(frozen=True)
class Trace(Operation):
    """Play a trace file of the folder (``path``)."""

    op: ClassVar[str] = "trace"
    path: str

    @classmethod
    def of(cls, message: Mapping[str, Any]) -> Trace:
        return cls(_text(message, "path"))


@dataclass(frozen=True)
class Counterexample(Operation):
    """Property ``name``'s counterexample, played in the trace player, or ``where`` = "arena" in the arena."""

    op: ClassVar[str] = "counterexample"
    name: str
    where: str | None = None

    @classmethod
    def of(cls, message: Mapping[str, Any]) -> Counterexample:
        where = message.get("where")
        return cls(_text(message, "name"), where if isinstance(where, str) else None)


@dataclass(frozen=True)
class Files(Operation):
    """The folder's tables and traces, again."""

    op: ClassVar[str] = "files"


@dataclass(frozen=True)
class NewRobot(Operation):
    """A robot from ``template`` (one of ``tablebot new``'s) in a new folder ``name`` of the served one, opened:
    what the page offers in a folder without a table (web.new_robot checks both)."""

    op: ClassVar[str] = "new"
    template: str
    name: str

    @classmethod
    def of(cls, message: Mapping[str, Any]) -> NewRobot:
        return cls(_text(message, "template"), _text(message, "name"))


@dataclass(frozen=True)
class Share(Operation):
    """A link carrying the table as edited (the Share button): answered by a ``shared`` message."""

    op: ClassVar[str] = "share"


@dataclass(frozen=True)
class OpenLink(Operation):
    """Open the table a share link carries (pasted in the page, or in its address): written into a new folder."""

    op: ClassVar[str] = "open_link"
    link: str

    @classmethod
    def of(cls, message: Mapping[str, Any]) -> OpenLink:
        return cls(_text(message, "link"))


OPERATIONS: dict[str, type[Operation]] = {
    kind.op: kind for kind in (Open, Edit, InsertRow, DeleteRow, Save, Restore, Sim, Trace, Counterexample, Files,
                               NewRobot, Share, OpenLink)
}


def op_name(message: Any) -> str:
    """The name of the operation a message from the page asks for; anything else is refused."""
    if not isinstance(message, dict) or not isinstance(message.get("op"), str):
        raise Refused(NOT_AN_OPERATION)
    if message["op"] not in OPERATIONS:
        raise Refused(f"unknown op {message['op']!r}")
    return message["op"]


def operation(message: Any) -> Operation:
    """The operation a message from the page asks for, its fields checked (:func:`op_name` first)."""
    return OPERATIONS[op_name(message)].of(message)


def _text(message: Mapping[str, Any], key: str, allow_empty: bool = False) -> str:
    value = message.get(key)
    if not isinstance(value, str) or (not value and not allow_empty):
        raise Refused(f'"{key}" must be text')
    return value


def _rows(message: Mapping[str, Any], key: str, single: bool = False) -> list[list[str]]:
    """A list of rows of text (``single``: one row) from the page."""
    value = message.get(key)
    rows = [value] if single else value
    if not isinstance(rows, list) or len(rows) > MAX_ROWS or not all(
            isinstance(row, list) and len(row) <= MAX_COLUMNS and all(isinstance(c, str) for c in row) for row in rows):
        raise Refused(f'"{key}" must be {"a row" if single else "rows"} of text (at most {MAX_ROWS:,} rows of '
                      f"{MAX_COLUMNS} cells)")
    return rows


def _int(message: Mapping[str, Any], key: str) -> int:
    value = message.get(key)
    if not isinstance(value, int) or isinstance(value, bool):
        raise Refused(f'"{key}" must be a whole number')
    return value


# --- messages: the server to the page ---------------------------------------------------------------------


@dataclass(frozen=True)
class Message:
    """One message to the page; ``kind`` is its ``type`` on the wire. Fields named in ``OMITTED_WHEN_NONE``
    are left out when None; a field named ``more`` (another part's own data: the analysis, the arena's state)
    is spread into the message."""

    kind: ClassVar[str]
    OMITTED_WHEN_NONE: ClassVar[frozenset[str]] = frozenset()

    def data(self) -> dict[str, Any]:
        out: dict[str, Any] = {"type": self.kind}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "more":
                out.update(value)
            elif not (value is None and f.name in self.OMITTED_WHEN_NONE):
                out[f.name] = value
        return out


@dataclass(frozen=True)
class TableMsg(Message):
    """A table opened (or reloaded): its grid, each row's line in the file, the version it was read at."""

    kind: ClassVar[str] = "table"
    path: str
    header: list[str]
    grid: list[list[str]]
    lines: list[int]
    version: str | None
    dialect: Mapping[str, str]


@dataclass(frozen=True)
class GridMsg(Message):
    """The draft's rows after a change of rows (``focus``: the row to select)."""

    kind: ClassVar[str] = "grid"
    OMITTED_WHEN_NONE: ClassVar[frozenset[str]] = frozenset({"lines", "focus"})
    grid: list[list[str]]
    lines: list[int] | None = None
    focus: int | None = None


@dataclass(frozen=True)
class AnalysisMsg(Message):
    """The draft's check after edit ``seq`` (None: not after an edit): findings, cells, machine, in ``more``."""

    kind: ClassVar[str] = "analysis"
    seq: Any
    dirty: bool
    lines: list[int]
    more: Mapping[str, Any]


@dataclass(frozen=True)
class DiagramMsg(Message):
    kind: ClassVar[str] = "diagram"
    svg: str


@dataclass(frozen=True)
class ArenaMsg(Message):
    """The arena after a reset: its world, settings and state (``more``, :meth:`Arena.reset`'s)."""

    kind: ClassVar[str] = "arena"
    more: Mapping[str, Any]


@dataclass(frozen=True)
class ControlMsg(Message):
    """The arena's robot's state (``more``: paused, speed, held inputs, error)."""

    kind: ClassVar[str] = "control"
    more: Mapping[str, Any]


@dataclass(frozen=True)
class FrameMsg(Message):
    """What the arena's robot did since the last frame (``more``: :meth:`Arena.frame`'s)."""

    kind: ClassVar[str] = "frame"
    more: Mapping[str, Any]


@dataclass(frozen=True)
class TraceMsg(Message):
    """A trace to play: its ``columns`` (``at_tick``: where a counterexample breaks its property)."""

    kind: ClassVar[str] = "trace"
    OMITTED_WHEN_NONE: ClassVar[frozenset[str]] = frozenset({"at_tick"})
    name: str
    columns: Mapping[str, Any]
    at_tick: int | None = None


@dataclass(frozen=True)
class FilesMsg(Message):
    """The folder's tables and traces (``more``: :meth:`Workspace.listing`'s)."""

    kind: ClassVar[str] = "files"
    more: Mapping[str, Any]


@dataclass(frozen=True)
class SharedMsg(Message):
    """The Share button's link (``tablebot share``'s, of the table as edited) and its QR code (an SVG data:
    address; empty when the link is too long for one)."""

    kind: ClassVar[str] = "shared"
    link: str
    qr: str


@dataclass(frozen=True)
class SavedMsg(Message):
    kind: ClassVar[str] = "saved"
    op: str
    version: str
    path: str
    backup: str | None
    backup_version: str | None


@dataclass(frozen=True)
class ConflictMsg(Message):
    """The file on disk is not the draft's: save yours over theirs (version ``theirs``, kept as ``backup``)
    or load theirs; ``how`` it changed; ``op``: "save" when a save lost, "" when another tab saved."""

    kind: ClassVar[str] = "conflict"
    op: str
    message: str
    how: str
    theirs: str
    path: str
    backup: str
    hint: str


@dataclass(frozen=True)
class NoticeMsg(Message):
    kind: ClassVar[str] = "notice"
    message: str


@dataclass(frozen=True)
class ErrorMsg(Message):
    """A request refused (``message``: the studio's words; ``op``: the operation, "" when there was none;
    ``text``: a table error's whole text, file:line:column and hint; ``hint``: what to do instead)."""

    kind: ClassVar[str] = "error"
    OMITTED_WHEN_NONE: ClassVar[frozenset[str]] = frozenset({"text", "hint"})
    message: str
    op: str = ""
    text: str | None = None
    hint: str | None = None


MESSAGES: dict[str, type[Message]] = {
    kind.kind: kind for kind in (TableMsg, GridMsg, AnalysisMsg, DiagramMsg, ArenaMsg, ControlMsg, FrameMsg,
                                 TraceMsg, FilesMsg, SavedMsg, ConflictMsg, NoticeMsg, ErrorMsg, SharedMsg)
}
