"""What the studio tells the page when it turns a request down: :class:`Refused` carries the studio's
own words. Any other exception is a bug: the page is told only that, and the terminal gets the traceback.
"""

from __future__ import annotations

import logging

#: Where the studio's own bugs are reported (the terminal that runs ``tablebot studio``).
log = logging.getLogger("tablebot.studio")

#: What the page is told about a bug; the traceback goes to the terminal, never to the page.
INTERNAL = "internal error in the studio (the terminal running tablebot studio shows the details)"


class Refused(ValueError):
    """A request the studio will not carry out; ``str()`` is the sentence the page shows.

    A ValueError, so that code that reads a table outside the studio treats it as bad input."""
