"""A file in a folder the studio holds open, reached without following links: opened and read (never
blocking on a pipe or a device), written through a temporary name renamed into place, and saved one writer at
a time. :mod:`tablebot.web.workspace` decides which files the page may name; this module only reaches them.

Where the system cannot open files relative to an open folder (Windows), a folder is its path, each part
checked to be no link on the way."""

from __future__ import annotations

import contextlib
import errno
import os
import threading
from collections.abc import Iterator

from tablebot.i18n import N_
from tablebot.web.errors import Refused
from tablebot.web.temporaries import temp_name

try:  # POSIX; without it (Windows) this studio's own lock still holds saves one at a time
    import fcntl
except ImportError:
    fcntl = None  # type: ignore[assignment]

# the POSIX-only flags are 0 where the system has none of them (Windows)
NOFOLLOW, CLOEXEC = getattr(os, "O_NOFOLLOW", 0), getattr(os, "O_CLOEXEC", 0)
#: Files opened relative to an open folder (openat: POSIX); where the system cannot (Windows), a folder is
#: its path, each part checked to be no link on the way (Windows makes links only for administrators).
AT_FOLDER = {os.open, os.replace, os.unlink} <= os.supports_dir_fd
Folder = int | str  # an open folder's descriptor, or (without AT_FOLDER) its path
READ_FLAGS = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | NOFOLLOW | getattr(os, "O_NOCTTY", 0) | CLOEXEC
DIR_FLAGS = os.O_RDONLY | getattr(os, "O_DIRECTORY", 0) | NOFOLLOW | CLOEXEC


def open_at(folder: Folder, leaf: str, flags: int, mode: int = 0o777) -> int:
    """``os.open`` of ``leaf`` in ``folder``; without AT_FOLDER, a link there is refused as O_NOFOLLOW would."""
    if isinstance(folder, int):
        return os.open(leaf, flags, mode, dir_fd=folder)
    path = os.path.join(folder, leaf)
    if os.path.islink(path):
        raise OSError(errno.ELOOP, "a link", path)
    return os.open(path, flags | getattr(os, "O_BINARY", 0), mode)


def at(folder: Folder, leaf: str) -> tuple[str, dict[str, int]]:
    """``leaf`` in ``folder`` as a name and the keywords that say where (dir_fd), or as a path."""
    return (leaf, {"dir_fd": folder}) if isinstance(folder, int) else (os.path.join(folder, leaf), {})


def read_all(fd: int, limit: int) -> bytes:
    chunks: list[bytes] = []
    size = 0
    while size <= limit:
        chunk = os.read(fd, 1 << 20)
        if not chunk:
            break
        chunks.append(chunk)
        size += len(chunk)
    if size > limit:
        raise Refused(N_("the file grew past {limit:,} bytes while the studio read it", limit=limit))
    return b"".join(chunks)


_LOCKS: dict[tuple[int, int, str], threading.Lock] = {}
_LOCKS_LOCK = threading.Lock()


@contextlib.contextmanager
def one_save_at_a_time(folder: Folder, leaf: str) -> Iterator[None]:
    """Hold the save of ``leaf`` in the open ``folder``: one thread of this studio at a time, and (where the
    file system has flock) one studio process at a time."""
    info = os.fstat(folder) if isinstance(folder, int) else os.stat(folder)
    with _LOCKS_LOCK:
        lock = _LOCKS.setdefault((info.st_dev, info.st_ino, leaf), threading.Lock())
    with lock:
        locked = False
        with contextlib.suppress(OSError):  # no flock on this file system: this studio's own lock still holds
            if fcntl is not None and isinstance(folder, int):
                fcntl.flock(folder, fcntl.LOCK_EX)
                locked = True
        try:
            yield
        finally:
            if locked and fcntl is not None and isinstance(folder, int):
                fcntl.flock(folder, fcntl.LOCK_UN)


def write_at(folder: Folder, leaf: str, data: bytes, mode: int) -> tuple[int, int]:
    """Write ``leaf`` in the open ``folder`` through a temporary file renamed onto it (a link there is
    replaced, never written through); returns the new file's (device, inode)."""
    temp = temp_name(leaf)
    fd = open_at(folder, temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | NOFOLLOW | CLOEXEC, 0o600)
    try:
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view) :]
            if hasattr(os, "fchmod"):  # Windows before Python 3.13 has none (and modes are only read-only there)
                os.fchmod(fd, mode)
            os.fsync(fd)
            info = os.fstat(fd)
        finally:
            os.close(fd)
        if isinstance(folder, int):
            os.replace(temp, leaf, src_dir_fd=folder, dst_dir_fd=folder)
        else:
            os.replace(os.path.join(folder, temp), os.path.join(folder, leaf))
    except BaseException:
        with contextlib.suppress(OSError):
            name, where = at(folder, temp)
            os.unlink(name, **where)
        raise
    return info.st_dev, info.st_ino
