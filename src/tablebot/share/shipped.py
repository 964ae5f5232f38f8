"""The files tablebot ships that a share link names instead of carrying: a shipped example's robot or world
file, copied unchanged into a pupil's folder, travels as its name and digest (:func:`reference`) and is read
back from this tablebot's own copy (:func:`shipped`), refused when this tablebot ships it otherwise."""

from __future__ import annotations

import functools
import hashlib

from tablebot.diagnostics import fail
from tablebot.i18n import N_

#: A robot's own world, as a link carries it and a folder holds it.
WORLD_NAME = "arena.toml"
#: The shipped examples whose robot and world files a link names instead of carrying them (a pupil's folder
#: made by ``tablebot new --from bumberbot`` keeps them as they are: its link carries the table alone).
SHIPPED = ("bumberbot", "bumberbot-counters", "bumberbot-lights", "line-follower", "obstacle-avoider")


def digest(text: str) -> str:
    """A file's short digest, as a link names a shipped file by."""
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


@functools.cache
def shipped_files() -> dict[str, str]:
    """Each shipped robot and world file's text, by ``EXAMPLE/FILE``."""
    from tablebot.examples import example_path

    found = {}
    for example in SHIPPED:
        for name in ("robot.toml", WORLD_NAME):
            path = example_path(example) / name
            if path.is_file():
                found[f"{example}/{name}"] = path.read_text(encoding="utf-8")
    return found


def reference(text: str) -> str | dict[str, str]:
    """A file's text, or the name and digest of the shipped file it is a copy of."""
    for key, copy in shipped_files().items():
        if copy == text:
            return {"example": key, "sha256": digest(text)}
    return text


def shipped(reference: dict[str, object], where: str) -> str:
    """The text of the shipped file a link names, as the link's tablebot shipped it."""
    key, named = reference.get("example"), reference.get("sha256")
    text = shipped_files().get(key) if isinstance(key, str) else None
    if text is None or digest(text) != named:
        raise fail(
            where,
            N_(
                "this share link names tablebot's example file {key!r} as another version of "
                "tablebot ships it, not as this one does",
                key=key,
            ),
            N_("use the same version of tablebot as the link's maker, or ask for the files"),
        )
    return text
