"""Writing output files safely: to a temporary name in the same folder, renamed into place only when complete.

A full disk, a crash or Ctrl-C therefore never leaves a truncated file that looks whole, and never
destroys the previous version before the new one is ready. Inside a :func:`tablebot.fileset.file_set`
the finished file waits in the set's staging folder until the whole set is swapped in.
"""

from __future__ import annotations

import codecs
import errno
import json
import os
import stat
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

from tablebot import fileset, overwrite
from tablebot.csvtext import split_records
from tablebot.diagnostics import TableBotError, fail
from tablebot.i18n import N_
from tablebot.interrupts import fault_point
from tablebot.table import is_table_header

#: Per errno of a failed read or write: what the user can do about it.
OS_HINTS = {
    errno.EEXIST: N_("a file stands where a folder is needed: choose another path"),
    errno.ENOTDIR: N_("a file stands where a folder is needed: choose another path"),
    errno.EISDIR: N_("a folder stands where a file is needed: give a file name"),
    errno.ENOENT: N_("the folder does not exist: create it or choose another path"),
    errno.EACCES: N_("you may not write there: choose another path or change its permissions"),
    errno.EPERM: N_("you may not write there: choose another path or change its permissions"),
    errno.EROFS: N_("the disk is read-only: choose another path"),
    errno.ENOSPC: N_("the disk is full: free some space or choose another disk"),
}


def out_folder(path: Path, option: str) -> Path:
    """The folder an option names for writing into, created (with its parents) if missing."""
    if path.exists() and not path.is_dir():
        raise fail(
            path,
            N_("{option} names a file, not a folder", option=option),
            N_("give {option} a folder (it is created if missing)", option=option),
        )
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise fail(
            exc.filename or path,
            N_("cannot create the folder for {option}: {reason}", option=option, reason=exc.strerror),
            OS_HINTS.get(exc.errno or 0, N_("give {option} another folder", option=option)),
        ) from None
    return path


def out_file(path: Path, option: str, make_folder: bool = False) -> Path:
    """The file an option names for writing (an existing file is replaced); its folder must exist,
    unless ``make_folder`` says to create it."""
    if path.is_dir():
        raise fail(
            path,
            N_("{option} names a folder, not a file", option=option),
            N_("give {option} a file name", option=option),
        )
    if make_folder:
        if path.parent.exists() and not path.parent.is_dir():
            raise fail(
                path.parent,
                N_("the folder of {option} {path} is a file", option=option, path=path),
                N_("give {option} a file in a folder", option=option),
            )
        out_folder(path.parent, option)
    elif not path.parent.is_dir():
        problem = (
            N_("the folder of {option} {path} is not a folder", option=option, path=path)
            if path.parent.exists()
            else N_("the folder of {option} {path} does not exist", option=option, path=path)
        )
        raise fail(
            path.parent,
            problem,
            N_("create the folder first, or give {option} a file in an existing folder", option=option),
        )
    return path


def _target(path: str | Path) -> Path:
    """``path``, refused if it is a symbolic link to a file (see :func:`tablebot.overwrite.not_a_link`)."""
    path = Path(path)
    overwrite.not_a_link(path)
    return path


def is_special(path: Path) -> bool:
    """A device, pipe or socket (``/dev/stdout``, ``/dev/full``, a FIFO): written directly, never replaced
    by a rename (that would put a regular file where the device was)."""
    try:
        mode = path.stat().st_mode
    except OSError:
        return False
    return not stat.S_ISREG(mode) and not stat.S_ISDIR(mode)


def _open_direct(path: Path, mode: str, encoding: str | None, newline: str | None) -> IO:
    writing(path)
    return open(path, mode, encoding=None if "b" in mode else encoding, newline=None if "b" in mode else newline)


def _temporary(path: Path, where: Path, mode: str, encoding: str | None, newline: str | None) -> tuple[IO, Path]:
    """An open temporary file beside ``where`` (same folder, so the rename is atomic: ``where`` is ``path``,
    or its place in a set's staging folder) and its name; the command's guard first refuses a path it must
    not write over (see :mod:`tablebot.overwrite`)."""
    writing(path)
    with fileset.named_as(path):
        fd, name = tempfile.mkstemp(prefix=f".{where.name}.", suffix=".tmp", dir=where.parent)
    try:
        stream = os.fdopen(fd, mode, encoding=encoding, newline=newline)
    except BaseException:
        _close_if_mine(fd, name)
        os.unlink(name)
        raise
    return stream, Path(name)


def _close_if_mine(fd: int, name: str) -> None:
    """Close ``fd`` if it is still the temporary file ``name``. A Ctrl-C can land just after ``os.fdopen`` has
    made its file object, which then closes the descriptor as the interrupt unwinds: closing it again raised
    EBADF in the interrupt's place (a sweep stopped with Ctrl-C said "cannot write or read: Bad file
    descriptor", exit 2, not "interrupted", 130), or would close whatever another thread opened meanwhile under
    the same number. Compared by device and inode, so only our own file is closed."""
    try:
        mine = os.path.samestat(os.fstat(fd), os.stat(name))
    except OSError:  # closed already
        return
    if mine:
        os.close(fd)


@contextmanager
def atomic_write(
    path: str | Path, mode: str = "w", encoding: str | None = "utf-8", newline: str | None = None
) -> Iterator[IO]:
    """Open ``path`` for writing through a temporary file that replaces it only if the block completes.

    An OSError raised while writing names ``path`` (a full disk reports no file name of its own).
    """
    path = _target(path)
    if is_special(path):
        try:
            with _open_direct(path, mode, encoding, newline) as stream:
                yield stream
        except OSError as exc:
            exc.filename = str(path) if exc.filename is None else exc.filename
            raise
        return
    where = fileset.staged(path)
    stream, temp = _temporary(path, where, mode, None if "b" in mode else encoding, None if "b" in mode else newline)
    try:
        with stream:
            yield stream
        _keep_mode(path, temp)
        os.replace(temp, where)
    except BaseException as exc:
        temp.unlink(missing_ok=True)
        if isinstance(exc, OSError) and exc.filename is None:
            exc.filename = str(path)
        raise
    fault_point()


@contextmanager
def replacing(path: str | Path) -> Iterator[Path]:
    """A temporary name beside ``path`` for a tool that writes its output file itself (a compiler's
    ``-o``); renamed to ``path`` if the block completes, removed if not."""
    path = _target(path)
    if is_special(path):
        writing(path)
        yield path
        return
    where = fileset.staged(path)
    stream, temp = _temporary(path, where, "wb", None, None)
    stream.close()
    try:
        yield temp
        _keep_mode(path, temp)
        os.replace(temp, where)
    except BaseException:
        temp.unlink(missing_ok=True)
        raise
    fault_point()


def write_text(path: str | Path, text: str, encoding: str = "utf-8", newline: str | None = None) -> Path:
    with atomic_write(path, "w", encoding=encoding, newline=newline) as f:
        f.write(text)
    return Path(path)


def write_bytes(path: str | Path, data: bytes) -> Path:
    with atomic_write(path, "wb") as f:
        f.write(data)
    return Path(path)


def remove(path: str | Path) -> None:
    """Remove ``path``: at once, or, inside a set that holds it, when the new set is swapped in."""
    owner = fileset.owner(Path(path))
    if owner is not None:
        owner.remove(Path(path))
    else:
        Path(path).unlink(missing_ok=True)


def json_records(path: Path, keys: Sequence[str]) -> list[dict[str, Any]]:
    """The records of a JSON Lines file this program appends to as its work goes (one record per line, for
    a cut run to keep what it did), each a JSON object with ``keys``. A line cut by a kill, or one that is
    not such a record, is skipped (its work is done again); a cut last line is ended, so that the next
    record appended starts a line of its own rather than joining it."""
    if not path.exists():
        return []
    data = path.read_bytes()
    if data and not data.endswith(b"\n"):
        with append(path, "b") as f:
            f.write(b"\n")
    found = []
    for line in data.decode("utf-8", errors="replace").splitlines():
        try:
            item = json.loads(line)
        except ValueError:  # cut, or not JSON at all
            continue
        if isinstance(item, dict) and all(key in item for key in keys):
            found.append(item)
    return found


#: Opening for appending: never through a link (O_NOFOLLOW where the system has it; elsewhere, see append).
APPEND_FLAGS = os.O_WRONLY | os.O_APPEND | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)


@contextmanager
def append(path: str | Path, mode: str = "") -> Iterator[IO]:
    """``path`` opened for appending (a record log a cut run keeps), text unless ``mode`` is ``"b"``; a link
    at ``path`` is refused, as for every file tablebot writes."""
    path = _target(path)
    flags = APPEND_FLAGS & ~getattr(os, "O_NOFOLLOW", 0) if path.is_symlink() else APPEND_FLAGS  # to a device
    try:
        fd = os.open(path, flags, 0o666)
    except OSError as exc:
        if exc.errno == errno.ELOOP:  # the link appeared after the check
            overwrite.not_a_link(path)
        raise
    with os.fdopen(fd, "a" + mode, encoding=None if mode == "b" else "utf-8") as stream:
        yield stream


def _keep_mode(path: Path, temp: Path) -> None:
    """The new file gets the old one's permissions, or the usual ones for a new file (mkstemp makes 0600)."""
    try:
        mode = path.stat().st_mode & 0o777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    os.chmod(temp, mode)


class PendingFile:
    """A file written over time (a live trace): open under a temporary name, then :meth:`commit` it
    to its final name or :meth:`keep_partial` under a name that says it is incomplete."""

    def __init__(self, path: str | Path, encoding: str = "utf-8") -> None:
        self.path = _target(path)
        self.direct = is_special(self.path)  # a device or pipe is written as it comes, never renamed onto
        if self.direct:
            self.stream, self.temp = _open_direct(self.path, "w", encoding, "\n"), self.path
        else:
            self.stream, self.temp = _temporary(self.path, fileset.staged(self.path), "w", encoding, "\n")
        self.closed_as: Path | None = None

    def commit(self) -> Path:
        """Close and rename into place (replacing the previous file; inside a set that holds it, when the
        set is swapped in: the set open now, which need not be the one open when the file was begun)."""
        return self._finish(self.path)

    def keep_partial(self) -> Path:
        """Close and rename to ``NAME.partial.EXT``: the final name keeps the previous complete run."""
        return self._finish(partial_name(self.path))

    def discard(self) -> None:
        if self.closed_as is None:
            self.stream.close()
            if not self.direct:
                self.temp.unlink(missing_ok=True)
            self.closed_as = self.temp

    def _finish(self, target: Path) -> Path:
        """Close and rename to ``target`` (or its place in a set's staging folder); returns ``target``."""
        if self.closed_as is not None:
            return self.closed_as
        if self.direct:
            target = self.path
        try:
            self.stream.close()
            if self.direct:
                self.closed_as = target
                return target
            _keep_mode(target, self.temp)
            os.replace(self.temp, fileset.staged(target))
        except OSError as exc:
            self.temp.unlink(missing_ok=True)
            if exc.filename is None:
                exc.filename = str(target)
            raise
        self.closed_as = target
        fault_point()
        return target


def partial_name(path: Path) -> Path:
    """``trace.jsonl`` -> ``trace.partial.jsonl``."""
    return path.with_name(f"{path.stem}.partial{path.suffix}")


#: Files the table reader would take: a CSV with state and next columns is a table.
TABLE_SUFFIXES = {".csv", ".tsv", ".txt"}
#: How much of a CSV file is read to find its header.
HEAD_BYTES = 4096


def writing(path: str | Path) -> None:
    """Called before ``path`` is written: the current command's overwrite guard may refuse it. A file the
    open set already removes (a table a previous run of the command wrote) is no user's file to protect."""
    owner = fileset.owner(Path(path))
    if owner is not None and owner.dropping(Path(path)):
        overwrite.writing(path, lambda _: False)  # still never one of the command's own inputs
        return
    overwrite.writing(path, is_user_file)


def is_user_file(path: Path) -> bool:
    """A TOML file, or a CSV whose header has a state and a next column as the table reader reads it
    (any delimiter, quotes, a BOM, a ``sep=`` line, aliases such as ``Next-State``)."""
    suffix = path.suffix.lower()
    if suffix in overwrite.USER_SUFFIXES:
        return True
    if suffix not in TABLE_SUFFIXES:
        return False
    head = _head(path)
    try:
        records = split_records(head[: head.rfind("\n") + 1] or head, str(path))  # whole lines only
    except TableBotError:
        return False  # a quote never closed in the first lines: no table the reader would take
    header = next((record for record in records if not record.is_blank()), None)
    return header is not None and is_table_header(cell.text for cell in header.cells)


def _head(path: Path) -> str:
    """The first HEAD_BYTES of a file as text, decoded as the table reader does (UTF-8 or UTF-16 with its
    BOM; a bad byte is only replaced: this decides whether a file is a table, not what it says)."""
    try:
        with path.open("rb") as stream:
            data = stream.read(HEAD_BYTES)
    except OSError:
        return ""
    if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        return data.decode("utf-16", "replace")
    return data.decode("utf-8-sig", "replace")
