"""The studio's operations: every message the page sends (``op``), each a typed object with its fields.

:func:`operation` reads a message from the page into its :class:`Operation` (a mistake in it is a
:class:`~tablebot.web.errors.Refused` in the studio's words, which the page shows). The page's side is
``static/js/studio/protocol.js``; :mod:`tablebot.web.protocol` holds these and the messages back together.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

from tablebot.i18n import N_
from tablebot.web.errors import Refused
from tablebot.web.wire import READERS, any_text, text, wire

#: What the page is told when a message is not an operation at all.
NOT_AN_OPERATION = N_('a message must be a JSON object with an "op"')


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
    ARENA_FIELDS: ClassVar[tuple[str, ...]] = (
        "speed",
        "input",
        "on",
        "masks",
        "seed",
        "charge",
        "start",
        "lamp",
        "paused",
    )
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
    kind.op: kind
    for kind in (
        Open,
        Edit,
        InsertRow,
        DeleteRow,
        Save,
        Restore,
        Sim,
        Trace,
        Counterexample,
        Files,
        NewRobot,
        Share,
        OpenLink,
    )
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
