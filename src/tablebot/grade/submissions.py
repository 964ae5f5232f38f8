"""What pupils hand in: a table file, a folder holding ``table.csv``, or a text file of share links (one a
line). Each becomes a :class:`Submission` with a name (its file or folder name, or the name its link carries,
made unique) and the folder of its own files; a link's files are written into ``OUT/submissions/NAME``.
A submission may read its own files only: a table or robot file that is a link to elsewhere, or a robot file
whose ``sim.world`` names a file outside the submission, is refused before anything reads it."""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

from tablebot.diagnostics import TableBotError, fail
from tablebot.i18n import N_

TABLE_SUFFIXES = (".csv", ".tsv")
_SLUG_RE = re.compile(r"[^A-Za-z0-9_.-]+")


@dataclass(frozen=True)
class Submission:
    """One pupil's work: ``table`` (None when it could not be had: ``error`` says why), ``own`` the folder
    its files must lie in, ``robot_file`` its own robot file, if any (compared with the challenge's)."""

    name: str
    given: str  # as the teacher gave it: a path, or FILE:LINE of a link
    table: Path | None = None
    own: Path | None = None
    robot_file: Path | None = None
    error: str = ""


def collect(given: list[Path], out: Path) -> list[Submission]:
    """Every submission the arguments name, in order, each with a unique name."""
    found: list[Submission] = []
    for path in given:
        if path.is_dir():
            found.append(_folder(path))
        elif path.suffix.lower() in TABLE_SUFFIXES:
            found.append(_table(path))
        elif path.is_file():
            found += _links(path, out)
        else:
            found.append(Submission(path.name or str(path), str(path), error="no such file or folder"))
    return _unique(found)


def _unique(found: list[Submission]) -> list[Submission]:
    """Names made unique in order: a second ``anna`` is ``anna (2)``."""
    seen: dict[str, int] = {}
    out = []
    for sub in found:
        seen[sub.name] = seen.get(sub.name, 0) + 1
        name = sub.name if seen[sub.name] == 1 else f"{sub.name} ({seen[sub.name]})"
        out.append(Submission(name, sub.given, sub.table, sub.own, sub.robot_file, sub.error))
    return out


def _folder(path: Path) -> Submission:
    from tablebot.robot import find_robot_file

    name = path.resolve().name
    table = next((path / n for n in ("table.csv", "table.tsv") if (path / n).exists()), None)
    if table is None:
        return Submission(name, str(path), error="no table.csv in this folder")
    return Submission(name, str(path), table, path, find_robot_file(table))


def _table(path: Path) -> Submission:
    from tablebot.robot import find_robot_file

    if not path.exists():
        return Submission(path.name, str(path), error="no such file")
    return Submission(path.name, str(path), path, path.parent, find_robot_file(path))


def _links(path: Path, out: Path) -> list[Submission]:
    """Each link of a text file, its files written into ``out/submissions/NAME`` (a broken one is listed with
    its error, under ``FILE:LINE``)."""
    from tablebot import share
    from tablebot.csvtext import read_text

    found = []
    text = read_text(path, "save the list of links as UTF-8 text", 16 * 1024 * 1024, spreadsheet=False)
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        where = f"{path.name}:{number}"
        try:
            shared = share.decode(line, where)
        except TableBotError as exc:
            found.append(Submission(where, where, error=exc.diagnostics[0].message))
            continue
        folder = out / "submissions" / _free_slug(out / "submissions", shared.name)
        table = shared.write(folder)
        robot = folder / shared.robot[0] if shared.robot else None
        found.append(Submission(shared.name, where, table, folder, robot))
    return found


def _free_slug(parent: Path, name: str) -> str:
    base = _SLUG_RE.sub("-", name).strip(".-") or "submission"
    slug, k = base, 1
    while (parent / slug).exists():
        k += 1
        slug = f"{base}-{k}"
    return slug


def confine(sub: Submission) -> None:
    """Refuse a submission whose table or robot file lies outside its own folder (a symbolic link to
    elsewhere), or whose robot file names a world outside it: grading reads nothing else."""
    assert sub.table is not None and sub.own is not None
    own = os.path.realpath(sub.own)
    for path in (sub.table, sub.robot_file):
        if path is not None and not _inside(os.path.realpath(path), own):
            raise fail(
                path.name,
                N_("this file is a link to a file outside the submission"),
                N_("hand in the file itself, not a link to it"),
            )
    if sub.robot_file is not None:
        world = _named_world(sub.robot_file)
        if world is not None and not _inside(os.path.realpath(sub.robot_file.parent / world), own):
            raise fail(
                sub.robot_file.name,
                N_("sim.world names {world}, a file outside the submission", world=world),
                N_("a submission runs in the challenge's worlds: remove sim.world, or name a file beside it"),
            )


def _named_world(robot_file: Path) -> str | None:
    """The robot file's ``sim.world`` as written (read as data, nothing else opened)."""
    from tablebot.tomlfile import Source

    sim = Source.read(robot_file).data.get("sim")
    world = sim.get("world") if isinstance(sim, dict) else None
    return world if isinstance(world, str) else None


def _inside(path: str, folder: str) -> bool:
    return path == folder or path.startswith(folder.rstrip(os.sep) + os.sep)
