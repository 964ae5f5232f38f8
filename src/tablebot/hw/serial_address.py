"""``SCHEME://DEVICE`` addresses of controllers on a serial port, for ``run --on``: ``robotx://auto``,
``robotx:///dev/ttyACM0``, ``robotx://ttyACM0`` (a device under /dev), ``robotx://COM3`` (Windows)."""

from __future__ import annotations

import os

from tablebot.diagnostics import fail
from tablebot.i18n import N_


def parse_serial_address(text: str, scheme: str, hint: str) -> str | None:
    """The serial device ``text`` names (None for ``auto``); anything else is a located error on ``--on``."""
    prefix = f"{scheme}://"
    if not text.startswith(prefix):
        raise fail("--on", N_("unknown target {text!r}", text=text), hint)
    rest = text[len(prefix) :]
    if rest == "auto":
        return None
    if not rest or rest.endswith("/") or "\0" in rest:
        raise fail("--on", N_("{text!r} names no serial device", text=text), hint)
    if rest.startswith("/") or os.name == "nt":
        return rest
    return f"/dev/{rest}"
