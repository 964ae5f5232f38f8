"""What one command may write over: never a file it read, and never a table or robot file unless the user
said ``--force`` (then the old file is kept as ``NAME.bak``).

The CLI opens one :func:`command` scope per command; every loader reads through :mod:`tablebot.csvtext`,
which calls :func:`read`, and every writer writes through :mod:`tablebot.files`, which calls :func:`writing`
first. Outside a scope (library use) nothing is refused.
"""

from __future__ import annotations

import os
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path

from tablebot.diagnostics import fail
from tablebot.i18n import N_, Message

#: Files a user writes by hand: tablebot never writes TOML, and a CSV with state and next columns is a table.
USER_SUFFIXES = {".toml"}


@dataclass
class Scope:
    """The files one command read (by real path and by inode), and whether it may replace user files."""

    force: bool = False
    offered: bool = True  # whether the command has a --force at all (else no message suggests it)
    paths: set[str] = field(default_factory=set)
    inodes: set[tuple[int, int]] = field(default_factory=set)
    replaced: set[str] = field(default_factory=set)


_scope: ContextVar[Scope | None] = ContextVar("tablebot_guard_scope", default=None)


@contextmanager
def command(force: bool = False, offered: bool = True) -> Iterator[Scope]:
    """The scope of one command: reads are remembered, writes checked against them."""
    token = _scope.set(Scope(force, offered))
    try:
        yield _scope.get()  # type: ignore[misc]
    finally:
        _scope.reset(token)


def active() -> bool:
    """Whether a command's scope is open (library calls open their own only outside one)."""
    return _scope.get() is not None


def read(path: str | Path) -> None:
    """Remember that the current command read ``path``."""
    scope = _scope.get()
    if scope is None:
        return
    scope.paths.add(os.path.realpath(path))
    inode = _inode(path)
    if inode is not None:
        scope.inodes.add(inode)


def _inode(path: str | Path) -> tuple[int, int] | None:
    """The file's (device, inode): the same for a hard link or any other spelling of it; None if absent."""
    try:
        info = os.stat(path)
    except OSError:
        return None
    return info.st_dev, info.st_ino


def _is_input(scope: Scope, path: Path) -> bool:
    return os.path.realpath(path) in scope.paths or _inode(path) in scope.inodes


def writing(path: str | Path, is_user_file: Callable[[Path], bool]) -> None:
    """Called before ``path`` is written: refuse an input of this command; refuse to replace a user file
    without --force, and with it keep the old one as ``NAME.bak`` first. ``is_user_file`` says whether a
    file is one a user writes by hand (:func:`tablebot.files.is_user_file`)."""
    scope = _scope.get()
    if scope is None:
        return
    path = Path(path)
    if _is_input(scope, path):
        raise fail(
            path,
            N_("this command reads this file, so it will not write over it"),
            N_("write the output to another file"),
        )
    key = os.path.realpath(path)
    if key in scope.replaced or not path.is_file() or not is_user_file(path):
        return
    if not scope.force and not scope.offered:
        raise fail(
            path,
            N_("{name} exists and is a {kind}: this command never replaces it", name=path.name, kind=kind(path)),
            N_("write into another folder, or move the file away"),
        )
    if not scope.force:
        raise fail(
            path,
            N_("{name} exists and is a {kind}: it is not replaced without --force", name=path.name, kind=kind(path)),
            N_("write to another file, or add --force (the old file is then kept as {name}.bak)", name=path.name),
        )
    _back_up(scope, path)


def rewrite(path: str | Path) -> None:
    """Let the current command write over ``path`` although it read it (an edit in place, such as a
    ROBO Pro program taking new lists); the old file is kept as ``NAME.bak``."""
    scope = _scope.get()
    if scope is None:
        return
    path = Path(path)
    scope.paths.discard(os.path.realpath(path))
    inode = _inode(path)
    if inode is None:
        return
    scope.inodes.discard(inode)
    _back_up(scope, path)


def _back_up(scope: Scope, path: Path) -> None:
    """Keep ``path`` as ``NAME.bak`` once per command: a second write of it replaces the first's output."""
    back_up(path)
    scope.replaced.add(os.path.realpath(path))


def back_up(path: Path) -> Path:
    """Copy ``path`` to ``NAME.bak`` through a temporary file in the same folder, renamed into place: a link
    already sitting at ``NAME.bak`` (a cloned project can carry ``prog.rpp.bak -> ~/.bashrc``) is replaced,
    never written through, and a full disk leaves the previous backup whole instead of truncating it."""
    not_a_link(path)
    backup = path.with_name(path.name + ".bak")
    fd, name = tempfile.mkstemp(prefix=f".{backup.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as copy, open(path, "rb") as original:
            shutil.copyfileobj(original, copy)
        shutil.copystat(path, name)
        os.replace(name, backup)
    except BaseException as exc:
        Path(name).unlink(missing_ok=True)
        if isinstance(exc, OSError) and exc.filename in (None, name):
            exc.filename = str(backup)  # the user never named the temporary file
        raise
    return backup


def not_a_link(path: Path) -> None:
    """Refuse to write through a symbolic link at ``path``: in a project cloned from someone else (git keeps
    links) ``out/trace.jsonl -> ~/.bashrc`` would otherwise overwrite whatever it points at. A link to a
    device or pipe (``/dev/stdout``) is no such file and is written as the device it names."""
    if not path.is_symlink():
        return
    try:
        special = not stat.S_ISREG(os.stat(path).st_mode) and not stat.S_ISDIR(os.stat(path).st_mode)
    except OSError:
        special = False  # a dangling link: writing would create whatever it names
    if not special:
        raise fail(
            path,
            N_(
                "{name} is a symbolic link (to {target}): tablebot never writes through a link",
                name=path.name,
                target=os.readlink(path),
            ),
            N_("remove the link, or give the path of the file it points to if that is the one to replace"),
        )


def kind(path: Path) -> Message:
    """The kind of a user file, as a refusal names it (a word of the reader's language when shown)."""
    return N_("robot or settings file") if path.suffix.lower() in USER_SUFFIXES else N_("table file")
