"""The studio's own temporary files: how a save names them, and sweeping the ones a stopped studio left.

A save writes ``.NAME.studio-PID-XXXXXXXX.tmp`` beside the table and renames it into place; a studio killed
between the two (``kill -9``, a power cut) leaves it behind, hidden. On start the studio removes such files,
and only them: the exact name a save gives (a table's name, or its ``.bak``, then ``studio``, the writer's
process id and eight hex digits), a regular file (never a link), whose writer is no longer running or which
is older than an hour (a save takes milliseconds; an old process id may have been given to another process).
"""

from __future__ import annotations

import os
import re
import secrets
import stat
import time
from collections.abc import Iterator
from pathlib import PurePosixPath

from tablebot.fileset import process_alive
from tablebot.web.errors import log

#: Only names a save gives: ``.`` + a table's name (or its .bak) + ``.studio-PID-8HEX.tmp``.
TEMP_RE = re.compile(r"\.(?P<leaf>.+\.(?i:csv|tsv)(?:\.bak)?)\.studio-(?P<pid>[1-9][0-9]{0,9})-[0-9a-f]{8}\.tmp")
STALE_S = 3600.0  # older than this, a temporary is abandoned whoever wrote it
MAX_SWEPT_FOLDERS = 2000  # a home folder served by mistake is not walked to its end at every start
SKIP_DIRS = {"node_modules", "__pycache__"}  # besides every folder whose name starts with a dot


def temp_name(leaf: str) -> str:
    """The temporary name a save of ``leaf`` writes first (in the same folder)."""
    return f".{leaf}.studio-{os.getpid()}-{secrets.token_hex(4)}.tmp"


def sweep(root: str | os.PathLike[str]) -> list[str]:
    """Remove the stale temporaries of studio saves under ``root``; their names relative to it."""
    removed: list[str] = []
    now = time.time()
    for count, (folder, dirs, files, fd) in enumerate(_walk(root)):  # never follows a link
        keep = count < MAX_SWEPT_FOLDERS
        dirs[:] = [d for d in dirs if keep and d not in SKIP_DIRS and not d.startswith(".")]
        for name in files:
            if _stale(name, folder, fd, now):
                try:
                    os.unlink(name, dir_fd=fd) if fd is not None else os.unlink(os.path.join(folder, name))
                except OSError:
                    continue  # gone meanwhile, or not ours to remove: left alone
                removed.append(PurePosixPath(os.path.relpath(os.path.join(folder, name), root)).as_posix())
    for name in removed:
        leaf = TEMP_RE.fullmatch(PurePosixPath(name).name)
        log.warning(
            "removed %s: a save of %s that a stopped studio never finished (the table is as it was)",
            name,
            leaf["leaf"] if leaf else "a table",
        )
    return removed


def _walk(root: str | os.PathLike[str]) -> Iterator[tuple[str, list[str], list[str], int | None]]:
    """os.fwalk (each folder open, so a link swapped in meanwhile leads nowhere); where the system has none
    (Windows), os.walk, which follows no link either, and no folder descriptor (None)."""
    if hasattr(os, "fwalk"):
        yield from os.fwalk(root)
    else:
        for folder, dirs, files in os.walk(root):
            yield folder, dirs, files, None


def _stale(name: str, folder: str, fd: int | None, now: float) -> bool:
    found = TEMP_RE.fullmatch(name)
    if found is None:
        return False
    try:
        info = (
            os.stat(name, dir_fd=fd, follow_symlinks=False)
            if fd is not None
            else os.stat(os.path.join(folder, name), follow_symlinks=False)
        )
    except OSError:
        return False
    if not stat.S_ISREG(info.st_mode):
        return False
    return not _running(int(found["pid"])) or now - info.st_mtime > STALE_S


def _running(pid: int) -> bool:
    """Whether process ``pid`` exists (this one always does: one of its saves may be under way)."""
    if pid == os.getpid():
        return True
    try:
        return process_alive(pid)  # not os.kill(pid, 0): on Windows that would end the process
    except (OSError, OverflowError):  # another user's process (EPERM), or no such number: left alone
        return True
