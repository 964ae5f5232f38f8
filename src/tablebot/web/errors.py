"""What the studio tells the page when it turns a request down: :class:`Refused` carries the studio's
own words. Any other exception is a bug: the page is told only that, and the terminal gets the traceback.
"""

from __future__ import annotations

import logging

# The document the studio edits refuses edits in the studio's words; its refusal is the studio's.
from tablebot.formats.csv_document import Refused
from tablebot.i18n import N_, Message

__all__ = ["INTERNAL", "Refused", "log", "said"]

#: Where the studio's own bugs are reported (the terminal that runs ``tablebot studio``).
log = logging.getLogger("tablebot.studio")

#: What the page is told about a bug; the traceback goes to the terminal, never to the page.
INTERNAL = N_("internal error in the studio (the terminal running tablebot studio shows the details)")


def said(exc: Exception) -> str:
    """What a refusal says: its :class:`~tablebot.i18n.Message` when it carries one (so that the tab's language
    renders it; ``str(exc)`` would be its English text alone), else its text."""
    first = exc.args[0] if exc.args else None
    return first if isinstance(first, Message) else str(exc)
