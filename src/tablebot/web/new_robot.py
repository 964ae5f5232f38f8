"""A robot from one of ``tablebot new``'s templates, made by the studio in a folder without a table."""

from __future__ import annotations

import re
from pathlib import Path

from tablebot.diagnostics import TableBotError
from tablebot.i18n import N_
from tablebot.web.errors import Refused, said

__all__ = ["NEW_NAME", "new_robot"]

NEW_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]{0,63}")  # a new robot's folder: one plain name


def new_robot(root: Path, template: object, name: object) -> str:
    """Make the folder ``name`` in ``root`` (the served folder) from ``template`` as ``tablebot new`` does (all
    its files at once, or none); the relative name of its table."""
    from tablebot.templates import TEMPLATES, make, write_folder

    if template not in TEMPLATES:
        raise Refused(
            N_(
                "no template {template}: tablebot new has {templates}",
                template=repr(str(template)[:40]),
                templates=", ".join(TEMPLATES),
            )
        )
    if not isinstance(name, str) or not NEW_NAME.fullmatch(name):
        raise Refused(N_("a new robot's name is letters, digits, - and _ (at most 64, not starting with - or _)"))
    folder = root / name
    if folder.is_symlink() or folder.exists():
        raise Refused(N_("{name} is there already: choose another name", name=name))
    try:
        write_folder(folder, make(template, name, [], []))
    except TableBotError as exc:
        raise Refused(said(exc)) from None
    return f"{name}/table.csv"
