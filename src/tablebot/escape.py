"""The one escaping function per output language: text from a user's file passes through one of these on
its way into generated code, so that no text can become code there.

(The safety engineer's escape.py holds the same ``python_string`` beside the other languages; this file
exists on the txt branch only until that one is merged.)
"""

from __future__ import annotations


def python_string(text: str) -> str:
    """A Python string literal (ASCII only, with its quotes) that evaluates to ``text``: quotes, backslashes,
    line ends and every other non-printable or non-ASCII character are escapes, so nothing ends the
    literal or the line it sits on."""
    return ascii(text)
