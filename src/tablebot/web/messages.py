"""The studio's messages: everything the server sends the page (``type``), each a typed object with its
fields; a :class:`Message`'s :meth:`~Message.data` is what goes to the page as JSON. The page's side is
``static/js/studio/protocol.js``; :mod:`tablebot.web.protocol` holds these and the operations together.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar


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
    # each header cell's kind and label, as the analysis will give them, and the robot's tick: the grid is
    # drawn once, with its flags as buttons and its timers' times, before the analysis comes
    columns: list[dict[str, str]] = field(default_factory=list)
    tick_ms: int | None = None


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
    kind.kind: kind
    for kind in (
        TableMsg,
        GridMsg,
        AnalysisMsg,
        DiagramMsg,
        ArenaMsg,
        ControlMsg,
        FrameMsg,
        TraceMsg,
        FilesMsg,
        SavedMsg,
        ConflictMsg,
        NoticeMsg,
        ErrorMsg,
        SharedMsg,
    )
}
