"""The folder the studio serves: paths inside it only, the tables and traces it holds, and saving a
table safely (previous version kept as a backup, never over a file that changed on disk meanwhile).
"""

from __future__ import annotations

import hashlib
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from tablebot.diagnostics import fail
from tablebot.files import write_bytes

TABLE_SUFFIXES = (".csv", ".tsv")
TRACE_SUFFIXES = (".jsonl",)
SKIP_DIRS = {".git", ".venv", "node_modules", "__pycache__", ".backup"}
MAX_LISTED = 500  # files listed for the open menus; a home folder is not a project
BACKUP_SUFFIX = ".bak"


class OutsideFolder(ValueError):
    """A path that is not inside the served folder."""


def digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()[:16]


@dataclass
class Workspace:
    """The served folder; every path the page names is resolved (and refused) here."""

    root: Path

    def __post_init__(self) -> None:
        self.root = self.root.resolve()

    def resolve(self, name: str) -> Path:
        """The file ``name`` (relative to the folder) names; anything outside the folder is refused."""
        if not isinstance(name, str) or not name or "\x00" in name or len(name) > 1000:
            raise OutsideFolder("no file name given")
        candidate = Path(name)
        if candidate.is_absolute() or ".." in candidate.parts:
            raise OutsideFolder(f"{name!r} is outside the served folder")
        path = (self.root / candidate).resolve()  # follows symbolic links: a link out of the folder is refused
        if not path.is_relative_to(self.root):
            raise OutsideFolder(f"{name!r} is outside the served folder")
        return path

    def relative(self, path: Path) -> str:
        return path.resolve().relative_to(self.root).as_posix()

    def listing(self) -> dict[str, list[str]]:
        """Tables and traces in the folder (and its subfolders), relative names, sorted."""
        tables: list[str] = []
        traces: list[str] = []
        count = 0
        for folder, dirs, files in os.walk(self.root):
            dirs[:] = sorted(d for d in dirs if d not in SKIP_DIRS and not d.startswith("."))
            for name in sorted(files):
                suffix = Path(name).suffix.lower()
                if suffix not in TABLE_SUFFIXES + TRACE_SUFFIXES or name.startswith("."):
                    continue
                rel = (Path(folder) / name).relative_to(self.root).as_posix()
                if suffix in TRACE_SUFFIXES:
                    traces.append(rel)
                elif _looks_like_table(Path(folder) / name):
                    tables.append(rel)
                count += 1
                if count >= MAX_LISTED:
                    return {"tables": tables, "traces": traces}
        return {"tables": tables, "traces": traces}


def _looks_like_table(path: Path) -> bool:
    """A CSV whose header names state and next (inputs CSVs and counterexamples are not tables)."""
    try:
        with path.open("rb") as f:
            head = f.read(4096).decode("utf-8", "replace").lower()
    except OSError:
        return False
    return "state" in head and "next" in head


def backup_path(path: Path) -> Path:
    return path.with_name(path.name + BACKUP_SUFFIX)


def save_table(path: Path, data: bytes, expected: str | None) -> str:
    """Write ``data`` over ``path`` if the file on disk is still the version ``expected`` (its digest;
    None = overwrite whatever is there), keeping that version as ``NAME.bak``; returns the new digest."""
    try:
        current = path.read_bytes()
    except FileNotFoundError:
        current = None
    except OSError as exc:
        raise fail(path, f"cannot read: {exc.strerror}", "check the file's permissions") from None
    if expected is not None and (current is None or digest(current) != expected):
        raise ChangedOnDisk(path)
    try:
        if current is not None:
            backup = backup_path(path)
            write_bytes(backup, current)
            shutil.copymode(path, backup)
        write_bytes(path, data)
    except OSError as exc:
        raise fail(exc.filename or path, f"not saved: {exc.strerror or exc}",
                   "check the folder's permissions and free space") from None
    return digest(data)


class ChangedOnDisk(Exception):
    """The file was changed by someone else since the page loaded it."""

    def __init__(self, path: Path):
        super().__init__(f"{path.name} was changed on disk since you opened it")
        self.path = path
