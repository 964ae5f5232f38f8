"""The studio's WebSocket protocol, both ways, in one place: every operation the page sends (``op``) and
every message the server sends back (``type``), each a typed object with its fields.

:func:`operation` reads a message from the page into its :class:`Operation` (a mistake in it is a
:class:`~tablebot.web.errors.Refused` in the studio's words, which the page shows); a :class:`Message`'s
:meth:`~Message.data` is what goes to the page as JSON. The page's side is ``static/js/studio/protocol.js``,
which names the same operations and kinds (tests/web/test_studio_protocol.py holds them equal).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

from tablebot.i18n import N_
from tablebot.web.errors import Refused
from tablebot.web.wire import READERS, any_text, text, wire

__all__ = [
    "MESSAGES", "OPERATIONS", "AnalysisMsg", "ArenaMsg", "ConflictMsg", "ControlMsg", "Counterexample",
    "DeleteRow", "DiagramMsg", "Edit", "ErrorMsg", "Files", "FilesMsg", "FrameMsg", "GridMsg", "InsertRow",
    "Message", "NewRobot", "NoticeMsg", "Open", "OpenLink", "Operation", "Restore", "Save", "SavedMsg", "Share",
    "SharedMsg", "Sim", "TableMsg", "Trace", "TraceMsg", "op_name", "operation",
]

#: What the page is told when a message is not an operation at all.
NOT_AN_OPERATION = N_('a message must be a JSON object with an "op"')


# --- operations: the page to the server -----------------------------------------------------------------

@dataclass(frozen=True)
class Operation:
    """One message from the page; ``op`` is its name on the wire, each field read by :data:`READERS`."""

    op: ClassVar[str]

    @classmethod
    def of(cls, message: Mapping[str, Any]) -> Operation:
        return cls(**{f.name: f.metadata.get("read", READERS[str(f.type)])(message, f.name) for f in fields(cls)})

    @classmethod
    def wire_fields(cls) -> tuple[str, ...]:
        """The fields it may carry on the wire, besides ``op``."""
        return tuple(f.name for f in fields(cls))


@dataclass(frozen=True)
class Open(Operation):
    """Open a table of the folder (``path``, relative to it)."""

    op: ClassVar[str] = "open"
    path: str


@dataclass(frozen=True)
class Edit(Operation):
    """Set one cell of the draft (grid ``row`` and ``col``) to ``value``; ``seq`` comes back on the analysis."""

    op: ClassVar[str] = "edit"
    row: int
    col: int
    value: str = wire(any_text)
    seq: Any = None


@dataclass(frozen=True)
class InsertRow(Operation):
    """A new row after grid row ``after``."""

    op: ClassVar[str] = "insert_row"
    after: int
    seq: Any = None


@dataclass(frozen=True)
class DeleteRow(Operation):
    op: ClassVar[str] = "delete_row"
    row: int
    seq: Any = None


@dataclass(frozen=True)
class Save(Operation):
    """Save the draft; ``force``: the version on disk a conflict named, to save over it anyway."""

    op: ClassVar[str] = "save"
    force: bool | str = False


@dataclass(frozen=True)
class Restore(Operation):
    """A draft the page kept (``header`` and ``grid``, started from version ``base``) made the draft again."""

    op: ClassVar[str] = "restore"
    header: list[str]
    grid: list[list[str]]
    base: str
    seq: Any = None


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
        return cls(text(message, "action"), {k: v for k, v in message.items() if k not in ("op", "action")})

    @classmethod
    def wire_fields(cls) -> tuple[str, ...]:
        return ("action", *cls.ARENA_FIELDS)


@dataclass(frozen=True)
class Trace(Operation):
    """Play a trace file of the folder (``path``)."""

    op: ClassVar[str] = "trace"
    path: str


@dataclass(frozen=True)
class Counterexample(Operation):
    """Property ``name``'s counterexample, played in the trace player, or ``where`` = "arena" in the arena."""

    op: ClassVar[str] = "counterexample"
    name: str
    where: str | None = None


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


@dataclass(frozen=True)
class Share(Operation):
    """A link carrying the table as edited (the Share button): answered by a ``shared`` message."""

    op: ClassVar[str] = "share"


@dataclass(frozen=True)
class OpenLink(Operation):
    """Open the table a share link carries (pasted in the page, or in its address): written into a new folder."""

    op: ClassVar[str] = "open_link"
    link: str


OPERATIONS: dict[str, type[Operation]] = {
    kind.op: kind for kind in (Open, Edit, InsertRow, DeleteRow, Save, Restore, Sim, Trace, Counterexample, Files,
                               NewRobot, Share, OpenLink)
}


def op_name(message: Any) -> str:
    """The name of the operation a message from the page asks for; anything else is refused."""
    if not isinstance(message, dict) or not isinstance(message.get("op"), str):
        raise Refused(NOT_AN_OPERATION)
    if message["op"] not in OPERATIONS:
        raise Refused(N_("unknown op {op}", op=repr(message["op"])))
    return message["op"]


def operation(message: Any) -> Operation:
    """The operation a message from the page asks for, its fields checked (:func:`op_name` first)."""
    return OPERATIONS[op_name(message)].of(message)


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
    dirty: bool = False  # a tab of a robot's other table shown again, with its edits not yet saved


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
class Spread(Message):
    """A message that is another part's own data (``more``), spread into it."""

    more: Mapping[str, Any]


class ArenaMsg(Spread):
    """The arena after a reset: its world, settings and state (``more``, :meth:`Arena.reset`'s)."""

    kind: ClassVar[str] = "arena"


class ControlMsg(Spread):
    """The arena's robot's state (``more``: paused, speed, held inputs, error)."""

    kind: ClassVar[str] = "control"


class FrameMsg(Spread):
    """What the arena's robot did since the last frame (``more``: :meth:`Arena.frame`'s)."""

    kind: ClassVar[str] = "frame"


@dataclass(frozen=True)
class TraceMsg(Message):
    """A trace to play: its ``columns`` (``at_tick``: where a counterexample breaks its property)."""

    kind: ClassVar[str] = "trace"
    OMITTED_WHEN_NONE: ClassVar[frozenset[str]] = frozenset({"at_tick"})
    name: str
    columns: Mapping[str, Any]
    at_tick: int | None = None


class FilesMsg(Spread):
    """The folder's tables and traces (``more``: :meth:`Workspace.listing`'s)."""

    kind: ClassVar[str] = "files"


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
