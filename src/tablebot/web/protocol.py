"""The studio's WebSocket protocol, both ways, in one place: every operation the page sends (``op``) and
every message the server sends back (``type``), each a typed object with its fields.

:func:`operation` reads a message from the page into its :class:`Operation` (a mistake in it is a
:class:`~tablebot.web.errors.Refused` in the studio's words, which the page shows); a :class:`Message`'s
:meth:`~Message.data` is what goes to the page as JSON. The page's side is ``static/js/studio/protocol.js``,
which names the same operations and kinds (tests/web/test_studio_protocol.py holds them equal).

The operations live in :mod:`tablebot.web.operations`, the messages in :mod:`tablebot.web.messages`; this
module is where the rest of the studio, and the tests, find both.
"""

from __future__ import annotations

from tablebot.web.messages import (
    MESSAGES,
    AnalysisMsg,
    ArenaMsg,
    ConflictMsg,
    ControlMsg,
    DiagramMsg,
    ErrorMsg,
    FilesMsg,
    FrameMsg,
    GridMsg,
    Message,
    NoticeMsg,
    SavedMsg,
    SharedMsg,
    TableMsg,
    TraceMsg,
)
from tablebot.web.operations import (
    OPERATIONS,
    Counterexample,
    DeleteRow,
    Edit,
    Files,
    InsertRow,
    NewRobot,
    Open,
    OpenLink,
    Operation,
    Restore,
    Save,
    Share,
    Sim,
    Trace,
    op_name,
    operation,
)

__all__ = [
    "MESSAGES",
    "OPERATIONS",
    "AnalysisMsg",
    "ArenaMsg",
    "ConflictMsg",
    "ControlMsg",
    "Counterexample",
    "DeleteRow",
    "DiagramMsg",
    "Edit",
    "ErrorMsg",
    "Files",
    "FilesMsg",
    "FrameMsg",
    "GridMsg",
    "InsertRow",
    "Message",
    "NewRobot",
    "NoticeMsg",
    "Open",
    "OpenLink",
    "Operation",
    "Restore",
    "Save",
    "SavedMsg",
    "Share",
    "SharedMsg",
    "Sim",
    "TableMsg",
    "Trace",
    "TraceMsg",
    "op_name",
    "operation",
]
