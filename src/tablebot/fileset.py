"""Writing a set of files so that it replaces the previous set at once: after any interruption a folder
holds the complete old set or the complete new one, never a mix, and no temporary file.

Inside ``with file_set(folder):`` every file tablebot writes into ``folder`` (through :mod:`tablebot.files`)
goes to a staging folder inside it, ``folder/.tablebot-PID-XXXXXXXX``. When the block completes, the new
files are renamed into place, in name order, with Ctrl-C and SIGTERM held off, after a journal in the
staging folder (``.commit``) has named them all; then the staging folder goes. When the block fails or is
interrupted, the staging folder goes and nothing in ``folder`` has changed. The other files of the folder
(the user's own) are never touched.

A process killed outright (SIGKILL, a crash) can leave a staging folder behind. The next set written into
that folder finishes its swap if its journal was complete, and removes it otherwise. A staging folder is
locked by the process that writes it (``flock``; on Windows a byte lock, ``msvcrt.locking``), so a live one
is never taken for a dead one; where neither exists, the process named in its name is asked whether it lives.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path

from tablebot.diagnostics import fail
from tablebot.i18n import N_
from tablebot.interrupts import fault_point, held

try:  # POSIX
    import fcntl
except ImportError:  # Windows
    fcntl = None  # type: ignore[assignment]
try:  # Windows
    import msvcrt
except ImportError:  # POSIX
    msvcrt = None  # type: ignore[assignment]

STAGE_PREFIX = ".tablebot-"
STAGE_RE = re.compile(r"^\.tablebot-(\d+)-[A-Za-z0-9_]{8}$")  # what tempfile.mkdtemp makes of the prefix
JOURNAL, LOCK = ".commit", ".lock"


@dataclass
class FileSet:
    """A set being written: its folder (a real path), the staging folder, and the names (relative to the
    folder) that the new set no longer has and that go when it is swapped in."""

    folder: Path
    stage: Path
    lock: int  # the open, flock-ed lock file: the stage belongs to a live process
    removals: set[str] = field(default_factory=set)

    def relative(self, path: Path) -> Path | None:
        """``path`` relative to the folder when it lies in it (not in the stage); None otherwise."""
        parent = os.path.realpath(path.parent)
        if _within(parent, str(self.stage)) or not _within(parent, str(self.folder)):
            return None
        return Path(os.path.relpath(parent, self.folder)) / path.name

    def dropping(self, path: Path) -> bool:
        """Whether the set has already been told to remove ``path`` (so writing it anew replaces nobody's file)."""
        relative = self.relative(path)
        return relative is not None and relative.as_posix() in self.removals

    def remove(self, path: Path) -> None:
        """``path`` goes when the set is swapped in (unless the set writes it)."""
        relative = self.relative(path)
        if relative is not None:
            self.removals.add(relative.as_posix())


_active: ContextVar[tuple[FileSet, ...]] = ContextVar("tablebot_file_sets", default=())


def _within(path: str, folder: str) -> bool:
    return path == folder or path.startswith(folder.rstrip(os.sep) + os.sep)


def owner(path: Path) -> FileSet | None:
    """The open set whose folder holds ``path`` (the innermost one)."""
    for fs in reversed(_active.get()):
        if fs.relative(path) is not None:
            return fs
    return None


def staged(path: Path) -> Path:
    """Where a file meant for ``path`` is written now: in the staging folder of the set that holds it
    (its parent folders made), else ``path`` itself."""
    fs = owner(path)
    if fs is None:
        return path
    target = fs.stage / fs.relative(path)  # type: ignore[operator]
    target.parent.mkdir(parents=True, exist_ok=True)
    return target


def current(path: Path) -> Path:
    """Where the file that will be ``path`` is now: its staged copy while its set is open, if written."""
    fs = owner(Path(path))
    if fs is not None:
        copy = fs.stage / fs.relative(Path(path))  # type: ignore[operator]
        if copy.exists():
            return copy
    return Path(path)


@contextmanager
def file_set(folder: str | Path, remove: Iterable[str] = ()) -> Iterator[FileSet]:
    """Everything written into ``folder`` inside the block replaces the previous files at once, or not at
    all; ``remove`` names files of the folder that the new set drops (a previous run's extra file).

    A set for a folder inside an open set's folder (or its staging folder) is part of that set.
    """
    folder = Path(folder)
    real = os.path.realpath(folder)
    for fs in reversed(_active.get()):
        if _within(real, str(fs.stage)) or _within(real, str(fs.folder)):
            base = fs.stage if _within(real, str(fs.stage)) else fs.folder
            fs.removals.update(Path(os.path.relpath(real, base), name).as_posix() for name in remove)
            yield fs
            return
    folder.mkdir(parents=True, exist_ok=True)
    recover(Path(real))
    stage, lock = _make_stage(Path(real), folder)
    fs = FileSet(Path(real), stage, lock, set(remove))
    token = _active.set((*_active.get(), fs))
    try:
        try:
            yield fs
        finally:
            _active.reset(token)
        _commit(fs)
    except BaseException:
        with held():
            _discard(fs)
        raise


@contextmanager
def new_folder(folder: Path) -> Iterator[Path]:
    """A folder that appears whole or not at all: the block writes into the staging folder it is given,
    beside ``folder``, which is then renamed to ``folder`` (which must not exist, or be empty)."""
    parent = Path(os.path.realpath(folder.parent if str(folder.parent) else "."))
    parent.mkdir(parents=True, exist_ok=True)
    recover(parent)
    stage, lock = _make_stage(parent, folder)
    try:
        yield stage
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(stage, 0o777 & ~umask)  # mkdtemp's 0700 is no mode for a folder the user asked for
        with held():
            os.close(lock)
            lock = -1
            (stage / LOCK).unlink()
            fault_point()
            _rename_folder(stage, folder)
    except BaseException:
        with held():
            if lock >= 0:
                os.close(lock)
            shutil.rmtree(stage, ignore_errors=True)
        raise


def _rename_folder(stage: Path, folder: Path) -> None:
    """POSIX renames a folder onto an empty folder in one step; Windows refuses to, so there the empty
    folder goes first (a folder that is not empty stays, and the rename's error says so)."""
    if os.name == "nt" and folder.is_dir() and not folder.is_symlink():
        with contextlib.suppress(OSError):
            folder.rmdir()
    os.rename(stage, folder)


@contextmanager
def named_as(path: str | Path) -> Iterator[None]:
    """An OSError of the block names ``path``, what the user asked for, instead of the temporary file or
    staging folder made for it, a name the user never saw."""
    try:
        yield
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror, str(path)) from None


def _make_stage(folder: Path, named: Path) -> tuple[Path, int]:
    """A staging folder inside ``folder``, locked; a failure to make it names ``named``."""
    with named_as(named):
        stage = Path(tempfile.mkdtemp(prefix=f"{STAGE_PREFIX}{os.getpid()}-", dir=folder))
    lock = os.open(stage / LOCK, os.O_RDWR | os.O_CREAT, 0o600)
    try_lock(lock)  # a fresh file: nobody else holds it
    return stage, lock


def try_lock(fd: int) -> bool:
    """Lock the open file ``fd`` for this process, without waiting: False when another process holds it.
    Where the system has no file locks (neither flock nor msvcrt), True: callers then ask whether the
    process is alive (:func:`process_alive`)."""
    try:
        if fcntl is not None:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        elif msvcrt is not None:
            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)  # the first byte; released when the file is closed
    except OSError:
        return False
    return True


def can_lock() -> bool:
    """Whether :func:`try_lock` really locks (else a stage's process is judged by its pid alone)."""
    return fcntl is not None or msvcrt is not None


def process_alive(pid: int) -> bool:
    """Whether process ``pid`` is running (or may be: one we may not look at counts as alive)."""
    if os.name == "nt":  # os.kill(pid, 0) on Windows would end the process (TerminateProcess with code 0)
        return _windows_process_alive(pid)
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _windows_process_alive(pid: int) -> bool:
    import ctypes

    kernel32 = ctypes.WinDLL("kernel32", use_last_error=True)  # type: ignore[attr-defined]
    query_limited_information, still_active, invalid_parameter = 0x1000, 259, 87
    handle = kernel32.OpenProcess(query_limited_information, False, pid)
    if not handle:  # no such process (or one we may not open: alive)
        return ctypes.get_last_error() != invalid_parameter  # type: ignore[attr-defined]
    try:
        code = ctypes.c_ulong()
        if not kernel32.GetExitCodeProcess(handle, ctypes.byref(code)):
            return True
        return code.value == still_active
    finally:
        kernel32.CloseHandle(handle)


def _files(stage: Path) -> list[str]:
    """The staged files, relative to the stage, in the order they are swapped in."""
    found = []
    for root, _, names in os.walk(stage):
        for name in names:
            relative = os.path.relpath(os.path.join(root, name), stage)
            if relative not in (JOURNAL, LOCK):
                found.append(Path(relative).as_posix())
    return sorted(found)


def _commit(fs: FileSet) -> None:
    """Check every target, write the journal, then rename each file into place with signals held."""
    names = _files(fs.stage)
    for name in names:  # everything that could refuse comes before the first rename (each file passed the
        target = fs.folder / name  # command's overwrite guard when tablebot.files wrote it into the stage)
        if target.is_dir() and not target.is_symlink():
            raise fail(target, N_("a folder stands where this file is to be written"), N_("move the folder away"))
        target.parent.mkdir(parents=True, exist_ok=True)
    removals = sorted(fs.removals - set(names))
    with held():
        if names or removals:
            _write_journal(fs.stage, names, removals)
        _swap(fs.folder, fs.stage, names, removals)
        _discard(fs)


def _write_journal(stage: Path, names: list[str], removals: list[str]) -> None:
    temp = stage / (JOURNAL + ".tmp")
    temp.write_text(json.dumps({"files": names, "remove": removals}), encoding="utf-8")
    os.replace(temp, stage / JOURNAL)


def _swap(folder: Path, stage: Path, names: list[str], removals: list[str]) -> None:
    """Every rename and removal is tried even when one fails (the system refused it: the first such error
    is raised at the end, naming its file), so that one refusal costs one file, not the rest of the set."""
    failed: OSError | None = None
    for name in names:
        fault_point()
        source = stage / name
        try:
            if source.exists():  # a recovery finds some already moved
                os.replace(source, folder / name)
        except OSError as exc:
            failed = failed or exc
    for name in removals:
        try:
            (folder / name).unlink(missing_ok=True)
        except OSError as exc:
            failed = failed or exc
    if failed is not None:
        raise failed


def _discard(fs: FileSet) -> None:
    shutil.rmtree(fs.stage, ignore_errors=True)
    if fs.lock >= 0:
        with contextlib.suppress(OSError):
            os.close(fs.lock)
        fs.lock = -1
        _remove_rest(fs.stage)


def _remove_rest(stage: Path) -> None:
    """Windows removes no open file: the lock file (and so the stage) outlives a removal made while it was
    open, and goes now that it is closed. Elsewhere the stage is gone already."""
    if os.path.lexists(stage):
        shutil.rmtree(stage, ignore_errors=True)


# --- what a killed process left ---------------------------------------------------------------------


def recover(folder: Path) -> list[Path]:
    """Finish the swap of every staging folder in ``folder`` whose process died after its journal was
    written, and remove the others whose process is gone; returns the staging folders dealt with."""
    try:
        entries = [e for e in os.scandir(folder) if STAGE_RE.match(e.name) and e.is_dir(follow_symlinks=False)]
    except OSError:
        return []
    done = []
    for entry in entries:
        stage = Path(entry.path)
        lock = _take(stage)
        if lock is None:
            continue
        try:
            journal = stage / JOURNAL
            if journal.exists():
                plan = json.loads(journal.read_text(encoding="utf-8"))
                _swap(folder, stage, plan["files"], plan["remove"])
            shutil.rmtree(stage, ignore_errors=True)
            done.append(stage)
        finally:
            if lock >= 0:
                os.close(lock)
        _remove_rest(stage)
    return done


def _take(stage: Path) -> int | None:
    """The stage's lock if its process is gone (-1: a stage with no lock file, whose process is gone);
    None while its process lives."""
    pid = int(STAGE_RE.match(stage.name)[1])  # type: ignore[index]
    try:
        lock = os.open(stage / LOCK, os.O_RDWR)
    except FileNotFoundError:  # made but not yet locked, or being renamed into place: ask about its process
        return None if process_alive(pid) else -1
    except OSError:
        return None
    if not try_lock(lock) or (not can_lock() and process_alive(pid)):
        os.close(lock)
        return None
    return lock
