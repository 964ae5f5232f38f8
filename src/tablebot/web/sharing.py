"""The studio's Share button: a link that carries the table as edited (with its robot file and world) and its
QR code. Links are made by ``tablebot.share``, a layer above the web's: ``tablebot studio`` hands its maker in
(:data:`maker`), so the web never imports it."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from tablebot.i18n import N_
from tablebot.web.errors import Refused

__all__ = ["Maker", "Opener", "maker", "open_link", "opener", "share"]

#: (the table's path, the draft's text) -> (the link, its QR code as an SVG data: address, "" if too long)
Maker = Callable[[Path, str], tuple[str, str]]
maker: Maker | None = None
#: (the served folder, a link) -> the table it carries, written into a new folder there (relative name)
Opener = Callable[[Path, str], str]
opener: Opener | None = None


def share(table: Path, text: str) -> tuple[str, str]:
    """The link and QR code of the table at ``table`` with ``text`` as its contents (the draft on the page)."""
    if maker is None:
        raise Refused(N_("this studio makes no links: start it with tablebot studio"))
    return maker(table, text)


def open_link(root: Path, link: str) -> str:
    """Write the files ``link`` carries into a new folder of ``root``; the relative name of its table."""
    if opener is None:
        raise Refused(N_("this studio opens no links: start it with tablebot studio"))
    return opener(root, link)
