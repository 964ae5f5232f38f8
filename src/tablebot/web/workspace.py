"""The folder the studio serves: which of its files the page may name (tables and traces, never a
dotfile, a dot-folder or any other kind of file), reading them without ever blocking on a pipe or a
device, and saving a table safely.

Every file is reached from the folder through directory descriptors opened without following links
(``O_NOFOLLOW``), so a link swapped in while the studio works never leads it outside the folder. A save
writes only under the name the session opened, keeps the previous version as ``NAME.bak``, and refuses
a file that changed on disk (edited in place, replaced by a rename, deleted) unless the page says to
overwrite that version. Saves of one file are one at a time, so two tabs saving at once never both
think they won: each save's backup is the save before it.
"""

from __future__ import annotations

import codecs
import contextlib
import enum
import errno
import hashlib
import os
import stat
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from tablebot.i18n import N_
from tablebot.web.errors import Refused
from tablebot.web.folder_fd import (
    AT_FOLDER,
    CLOEXEC,
    DIR_FLAGS,
    READ_FLAGS,
    Folder,
    one_save_at_a_time,
    open_at,
    read_all,
    write_at,
)
from tablebot.web.refusals import OTHER_TAB, not_regular
from tablebot.web.refusals import changed as _changed
from tablebot.web.refusals import refusal as _refusal
from tablebot.web.temporaries import sweep

TABLE_SUFFIXES = (".csv", ".tsv")
TRACE_SUFFIXES = (".jsonl",)
SKIP_DIRS = {"node_modules", "__pycache__"}  # besides every folder whose name starts with a dot
MAX_LISTED = 500  # files listed for the open menus; a home folder is not a project
BACKUP_SUFFIX = ".bak"
HEAD_BYTES = 4096  # read to tell a table from another CSV
MAX_BACKUP_BYTES = 16 * 1024 * 1024  # what a save copies to NAME.bak (a table the studio opened is 1 MB at most)
GONE = "deleted"  # the version of a file that is not there (what a forced save over nothing names)


class Kind(enum.Enum):
    """The kinds of file the page may name, by suffix."""

    TABLE = TABLE_SUFFIXES
    TRACE = TRACE_SUFFIXES


def digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()[:16]


@dataclass(frozen=True)
class Opened:
    """A file as the studio read it: its name in the folder, which file it is, and its bytes."""

    name: str  # where it really is, relative to the folder (links inside the folder resolved)
    identity: tuple[int, int]  # (st_dev, st_ino): a save writes only this file
    data: bytes
    mode: int  # permission bits, kept by a save

    @property
    def version(self) -> str:
        return digest(self.data)


@dataclass(frozen=True)
class Saved:
    """A save's outcome: the file as now written, and the version it moved to ``NAME.bak`` (None: none)."""

    file: Opened
    backup: str | None


class ChangedOnDisk(Exception):
    """The file on disk is not the version the draft started from (a save may overwrite it if asked).

    ``how``: changed (in place), replaced (another file renamed over it: an editor's or tablebot's own
    atomic save, ``sed -i``, ``git checkout``), :data:`OTHER_TAB`, or deleted; ``theirs``: the version on
    disk now (:data:`GONE` if none), which a forced save must name."""

    def __init__(self, name: str, how: str, theirs: str) -> None:
        super().__init__(_changed(name, how))
        self.name, self.how, self.theirs = name, how, theirs


@dataclass
class Workspace:
    """The served folder; every name the page sends is checked (and refused) here."""

    root: Path
    written: dict[str, str] = field(default_factory=dict)  # the version each table was last saved at here

    def __post_init__(self) -> None:
        self.root = self.root.resolve()
        sweep(self.root)  # the unfinished saves of a studio that was killed mid-save

    # --- names -----------------------------------------------------------------------------------------

    def locate(self, name: object, kind: Kind) -> str:
        """The file ``name`` (relative to the folder) really is, as a relative name, if the page may open
        it: inside the folder, of ``kind``, no part starting with a dot (before and after links)."""
        if not isinstance(name, str) or not name or "\x00" in name or len(name) > 1000:
            raise Refused(N_("no file name given"))
        given = PurePosixPath(name)
        shown = _shown(name)
        if given.is_absolute() or ".." in given.parts:
            raise Refused(N_("{shown} is outside the served folder", shown=shown))
        _check_name(given, kind, shown)
        try:
            real = (self.root / given).resolve()
        except (OSError, RuntimeError):  # a loop of links
            raise Refused(N_("{shown} cannot be opened: its links go round in a circle", shown=shown)) from None
        if not real.is_relative_to(self.root):
            raise Refused(N_("{shown} is outside the served folder (a link leads out of it)", shown=shown))
        inside = PurePosixPath(real.relative_to(self.root).as_posix())
        _check_name(inside, kind, shown)
        return inside.as_posix()

    # --- reading ---------------------------------------------------------------------------------------

    def read(self, name: object, kind: Kind, limit: int) -> Opened:
        """Read a file the page named: a regular file of ``kind`` in the folder, at most ``limit`` bytes
        (a table must also look like one: its header names state and next)."""
        real = self.locate(name, kind)
        with self._file(real) as (fd, info):
            if info.st_size > limit:
                raise Refused(
                    N_(
                        "{real} has {size:,} bytes; the studio opens such files up to {limit:,}",
                        real=real,
                        size=info.st_size,
                        limit=limit,
                    )
                )
            data = read_all(fd, limit)
        if kind is Kind.TABLE and not _looks_like_table(data[:HEAD_BYTES]):
            raise Refused(N_("{real} is not a table: its first line names no state and next column", real=real))
        return Opened(real, (info.st_dev, info.st_ino), data, stat.S_IMODE(info.st_mode))

    @contextlib.contextmanager
    def _file(self, real: str) -> Iterator[tuple[int, os.stat_result]]:
        """An open descriptor of the regular file ``real`` (a relative name from :meth:`locate`)."""
        parent, leaf = _split(real)
        with self._folder(parent, real) as folder:
            try:
                fd = open_at(folder, leaf, READ_FLAGS)
            except OSError as exc:
                raise _refusal(exc, real) from None
            try:
                info = os.fstat(fd)
                if not stat.S_ISREG(info.st_mode):
                    raise Refused(not_regular(real))
                yield fd, info
            finally:
                os.close(fd)

    @contextlib.contextmanager
    def _folder(self, parts: tuple[str, ...], real: str) -> Iterator[Folder]:
        """A descriptor of a folder inside the served one, reached without following any link (without
        AT_FOLDER: its path, no part of it a link)."""
        if not AT_FOLDER:
            path = str(self.root)
            for part in parts:
                path = os.path.join(path, part)
                if os.path.islink(path) or not os.path.isdir(path):
                    raise _refusal(OSError(errno.ENOTDIR, "not a folder"), real)
            yield path
            return
        fd = os.open(self.root, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0) | CLOEXEC)
        try:
            for part in parts:
                try:
                    inner = os.open(part, DIR_FLAGS, dir_fd=fd)
                except OSError as exc:
                    raise _refusal(exc, real) from None
                os.close(fd)
                fd = inner
            yield fd
        finally:
            os.close(fd)

    # --- saving ----------------------------------------------------------------------------------------

    def save(self, opened: Opened, data: bytes, force: bool | str = False, base: str | None = None) -> Saved:
        """Write ``data`` under the name ``opened`` came from, keeping what is there as ``NAME.bak``.

        The draft started from version ``base`` (by default ``opened``'s). Refused if the name now leads
        to another file or outside the folder; :class:`ChangedOnDisk` if the file there is not that
        version, unless ``force`` is True or names the version there now. One save of a file at a time:
        the check and the rename are never interleaved with another save's."""
        if self.locate(opened.name, Kind.TABLE) != opened.name:
            raise Refused(N_("{name} now leads to another file: reload it before saving", name=opened.name))
        parent, leaf = _split(opened.name)
        with self._folder(parent, opened.name) as folder, one_save_at_a_time(folder, leaf):
            current, mode, identity = self._current(folder, leaf, opened)
            theirs = GONE if current is None else digest(current)
            if theirs != (base or opened.version) and force is not True and force != theirs:
                how = "deleted" if current is None else "changed" if identity == opened.identity else "replaced"
                raise ChangedOnDisk(opened.name, OTHER_TAB if self.written.get(opened.name) == theirs else how, theirs)
            try:
                if current is not None:
                    write_at(folder, leaf + BACKUP_SUFFIX, current, mode)
                written = write_at(folder, leaf, data, mode)
                self.written[opened.name] = digest(data)  # still one save at a time: the next one sees it
            except OSError as exc:
                raise Refused(
                    N_(
                        "{name} was not saved: {why} (check the folder's permissions and free space)",
                        name=opened.name,
                        why=exc.strerror or N_("the system refused"),
                    )
                ) from None
        return Saved(Opened(opened.name, written, data, mode), None if current is None else theirs)

    def _current(self, folder: Folder, leaf: str, opened: Opened) -> tuple[bytes | None, int, tuple[int, int]]:
        """What is on disk now under the opened name (None: nothing), its permissions and identity."""
        try:
            fd = open_at(folder, leaf, READ_FLAGS)
        except FileNotFoundError:
            return None, opened.mode, opened.identity
        except OSError as exc:
            raise _refusal(exc, opened.name) from None
        try:
            info = os.fstat(fd)
            if not stat.S_ISREG(info.st_mode):
                raise Refused(
                    N_(
                        "{name} is no longer a regular file (a folder, pipe or device took its place): "
                        "nothing was written",
                        name=opened.name,
                    )
                )
            return read_all(fd, MAX_BACKUP_BYTES), stat.S_IMODE(info.st_mode), (info.st_dev, info.st_ino)
        finally:
            os.close(fd)

    # --- listing ---------------------------------------------------------------------------------------

    def listing(self) -> dict[str, list[str]]:
        """Tables and traces in the folder (and its subfolders), relative names, sorted; never blocks."""
        tables: list[str] = []
        traces: list[str] = []
        count = 0
        for folder, dirs, files in os.walk(self.root):
            dirs[:] = sorted(d for d in dirs if d not in SKIP_DIRS and not d.startswith("."))
            for name in sorted(files):
                rel = (Path(folder) / name).relative_to(self.root).as_posix()
                kind = self._listable(rel)
                if kind is None:
                    continue
                (tables if kind is Kind.TABLE else traces).append(rel)
                count += 1
                if count >= MAX_LISTED:
                    return {"tables": tables, "traces": traces}
        return {"tables": tables, "traces": traces}

    def _listable(self, rel: str) -> Kind | None:
        suffix = PurePosixPath(rel).suffix.lower()
        kind = Kind.TABLE if suffix in TABLE_SUFFIXES else Kind.TRACE if suffix in TRACE_SUFFIXES else None
        if kind is None or PurePosixPath(rel).name.startswith("."):
            return None
        try:
            real = self.locate(rel, kind)
            if kind is Kind.TRACE:
                with self._file(real):
                    return kind
            with self._file(real) as (fd, _):
                return kind if _looks_like_table(os.read(fd, HEAD_BYTES)) else None
        except (Refused, OSError):
            return None


# --- helpers ---------------------------------------------------------------------------------------------


def _shown(name: str) -> str:
    """A name from the page as a message shows it (quoted, control characters escaped, cut short)."""
    return repr(name[:200])


def _check_name(path: PurePosixPath, kind: Kind, shown: str) -> None:
    if any(part.startswith(".") for part in path.parts):
        raise Refused(
            N_("{shown}: the studio does not open hidden files or folders (names starting with a dot)", shown=shown)
        )
    if path.suffix.lower() not in kind.value:
        raise Refused(
            N_("{shown} is not a table: the studio opens .csv and .tsv files here", shown=shown)
            if kind is Kind.TABLE
            else N_("{shown} is not a trace: the studio opens .jsonl files here", shown=shown)
        )


def _split(real: str) -> tuple[tuple[str, ...], str]:
    parts = PurePosixPath(real).parts
    return parts[:-1], parts[-1]


def _looks_like_table(head: bytes) -> bool:
    """A header that names state and next (inputs CSVs and counterexamples are not tables)."""
    if head.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        text = head[: len(head) // 2 * 2].decode("utf-16", "replace")
    else:
        text = head.decode("utf-8", "replace")
    text = text.lower()
    return "state" in text and "next" in text
