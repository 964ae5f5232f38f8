"""Links that carry a table (``tablebot share``): the table, its robot file and its world (when it has one of
its own), compressed into the fragment of a studio address, the part after ``#`` that a browser never sends
to any server.

A link reads ``http://127.0.0.1:8765/#share=1.PAYLOAD``: the studio's default address, ``share=``, the link
format's version, a dot, and the payload: the files as compact JSON (a robot or world file that is a copy
of a shipped example's is named, with its digest, instead of carried), compressed with zlib (deflate with its
checksum, so a cut link is told from a whole one) and written in base64url without padding. The studio opens
such a link wherever it is served (only the part from ``#share=`` on is read), and so do
:func:`decode` and ``tablebot grade``.

>>> shared = collect("examples/bumberbot")
>>> decode(encode(shared)) == shared
True
"""

from __future__ import annotations

import base64
import binascii
import contextlib
import json
import re
import tempfile
import zlib
from dataclasses import dataclass, replace
from pathlib import Path

from tablebot.diagnostics import TableBotError, fail
from tablebot.i18n import N_
from tablebot.robot_tables import tables_of
from tablebot.share.shipped import WORLD_NAME, reference, shipped

__all__ = ["FORMAT", "STUDIO", "Shared", "collect", "decode", "encode"]

#: The link format this tablebot writes and reads: a link of another version is refused with a clear message.
FORMAT = 1
#: The studio's default address (``tablebot studio`` serves it): the part of a link before the fragment.
STUDIO = "http://127.0.0.1:8765/"
KEY = "share="
#: A shared robot is a few KB; more than this, unpacked, is no link tablebot made (a zip bomb is refused early).
MAX_UNPACKED = 2 * 1024 * 1024
_PAYLOAD_RE = re.compile(r"[A-Za-z0-9_-]*")
_FILE_RE = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_. -]{0,99}$")  # a plain file name: no folder, no leading dot
_NAME_RE = re.compile(r"[^A-Za-z0-9_. -]+")


@dataclass(frozen=True)
class Shared:
    """What a link carries: a ``name`` (the folder's, or the table's when it is not ``table.csv``), the table
    as (file name, text), the robot file as (file name, text) or None (the built-in BumberBot), and the world's
    text or None (an empty room). The world is always written as ``arena.toml`` beside the table, where every
    command finds it; a robot file's ``sim.world`` is made to name it. A robot of several tables: ``table`` is
    its main table and ``tables`` the others, each (file name, text), as its ``[tables]`` names them."""

    name: str
    table: tuple[str, str]
    robot: tuple[str, str] | None = None
    world: str | None = None
    tables: tuple[tuple[str, str], ...] = ()

    def files(self) -> dict[str, str]:
        """The files to write into a folder, by name."""
        files = {self.table[0]: self.table[1], **dict(self.tables)}
        if self.robot is not None:
            files[self.robot[0]] = self.robot[1]
        if self.world is not None:
            files[WORLD_NAME] = self.world
        return files

    def write(self, folder: Path) -> Path:
        """Write the files into ``folder`` (it must not exist, or be empty): the folder appears whole or not at
        all. Returns the table's path."""
        from tablebot.files import write_text
        from tablebot.fileset import new_folder

        if folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
            raise fail(
                folder,
                N_("this folder is not empty") if folder.is_dir() else N_("this is a file, not a folder"),
                N_("give the name of a new folder (a shared table never writes over files)"),
            )
        with new_folder(folder) as stage:
            for name, text in self.files().items():
                write_text(stage / name, text, newline="")  # byte for byte as shared
        return folder / self.table[0]

    def with_text(self, file: str, text: str) -> Shared:
        """The same files with the table named ``file`` (the main table or another) holding ``text`` instead:
        the studio shares a tab's table as edited, beside the robot's other tables as saved."""
        if file == self.table[0]:
            return replace(self, table=(file, text))
        if file not in dict(self.tables):
            raise fail(
                file,
                N_("this table is not one of the robot's tables"),
                N_("share the robot's folder: its robot file's [tables] names the tables a link carries"),
            )
        return replace(self, tables=tuple((name, text if name == file else old) for name, old in self.tables))

    def check(self, where: str = "link") -> None:
        """Read the files as every command would (the table against its robot file, the world): a broken one
        raises the errors, each named ``WHERE: FILE`` and with its line and column."""
        from tablebot.api.project import open as open_robot

        with tempfile.TemporaryDirectory(prefix="tablebot-share-") as tmp:
            folder = Path(tmp) / "shared"
            table = self.write(folder)
            try:
                project = open_robot(table)
                project.default_world()
            except TableBotError as exc:
                raise TableBotError(replace(d, path=_renamed(d.path, folder, where)) for d in exc.diagnostics) from None


def _renamed(path: str, folder: Path, where: str) -> str:
    """A diagnostic's path in the temporary folder, as the link's file name."""
    with contextlib.suppress(ValueError):
        return f"{where}: {Path(path).resolve().relative_to(folder.resolve()).as_posix()}"
    return path


def collect(path: str | Path) -> Shared:
    """What a link for ``path`` (a folder, a table file or a robot file) carries: the files every command
    reads for it, checked as they would be (a broken table is refused here, with its errors)."""
    from tablebot.api.project import open as open_robot
    from tablebot.csvtext import read_text

    project = open_robot(path)
    specs = tables_of(project.robot)
    table = _table_path(project.robot.source, specs[0].file) if specs else project.path
    robot_path = Path(project.robot.source) if project.robot.source and Path(project.robot.source).is_file() else None
    robot = None
    if robot_path is not None:
        robot = (_file_name(robot_path), _robot_text(robot_path, read_text(robot_path, spreadsheet=False)))
    world_path = project.robot_world() or (table.parent / WORLD_NAME if (table.parent / WORLD_NAME).is_file() else None)
    world = read_text(world_path, spreadsheet=False) if world_path is not None else None
    project.default_world()  # a broken world is refused before it is shared
    name = table.parent.resolve().name if table.stem == "table" else table.stem
    others = tuple(
        (_file_name(other), read_text(other))
        for other in (_table_path(project.robot.source, spec.file) for spec in specs[1:])
    )
    return Shared(
        _NAME_RE.sub("-", name).strip(" .-") or "shared", (_file_name(table), read_text(table)), robot, world, others
    )


def _table_path(robot_file: str | None, file: str) -> Path:
    """A ``[tables]`` entry's file: beside the robot file, as every command reads it. A link writes its files
    into one folder, so a table in another folder cannot be carried (:func:`_file_name` says so)."""
    path = Path(robot_file or ".").parent / file
    if Path(file).name != file:
        raise fail(
            path,
            N_(
                "a link carries the robot's tables beside its robot file, and this one is in another folder ({file})",
                file=file,
            ),
            N_("move the table beside the robot file and name it in [tables] by its file name alone"),
        )
    return path


def _file_name(path: Path) -> str:
    if not _FILE_RE.match(path.name):
        raise fail(
            path,
            N_("a link carries files with plain names (letters, digits, '_', '-', '.', spaces)"),
            N_("rename the file"),
        )
    return path.name


def _robot_text(path: Path, text: str) -> str:
    """The robot file's text with its ``sim.world`` (if any) naming the world the link carries, arena.toml:
    the folder a link is opened into holds the world there, whatever folder it came from."""
    from tablebot.tomlfile import Source

    src = Source.parse(path, text)
    sim = src.data.get("sim")
    if not isinstance(sim, dict) or "world" not in sim:
        return text
    number = src.line("sim", None, "world")
    lines = text.splitlines(keepends=True)
    if number is not None:
        new, count = re.subn(
            r"""(world\s*=\s*)("[^"\n]*"|'[^'\n]*')""", rf'\g<1>"{WORLD_NAME}"', lines[number - 1], count=1
        )
        if count:
            lines[number - 1] = new
            return "".join(lines)
    raise fail(
        path,
        N_("cannot find the line of sim.world to point it at the world the link carries"),
        N_('write it in a [sim] section as world = "FILE.toml"'),
        number,
    )


def encode(shared: Shared, base: str = STUDIO) -> str:
    """The link carrying ``shared``: ``BASE#share=1.PAYLOAD`` (see the module). The same files always give
    the same link."""
    body: dict[str, object] = {
        "name": shared.name,
        "table": list(shared.table),
        "robot": [shared.robot[0], reference(shared.robot[1])] if shared.robot else None,
        "world": None if shared.world is None else reference(shared.world),
    }
    if shared.tables:  # only then: a link of one table stays what it was, byte for byte
        body["tables"] = [list(pair) for pair in shared.tables]
    packed = zlib.compress(json.dumps(body, ensure_ascii=False, separators=(",", ":")).encode("utf-8"), 9)
    payload = base64.urlsafe_b64encode(packed).decode("ascii").rstrip("=")
    return f"{base}#{KEY}{FORMAT}.{payload}"


def decode(link: str, where: str = "link") -> Shared:
    """The files a link carries (as :func:`encode` made it; anything before ``#share=`` is ignored, so a
    link to any studio address works, and so does the bare ``share=...`` part). A link that is not one, from
    another version of tablebot, cut short or damaged raises a :class:`~tablebot.diagnostics.TableBotError`
    naming ``where`` (the option, or a file and line) and what to do. The files are not read as a table
    here: :meth:`Shared.check` does that."""
    text = link.strip()
    at = text.find(KEY)
    if at < 0:
        raise fail(
            where,
            N_("this is not a tablebot share link: it has no '#share='"),
            N_("copy the whole link that `tablebot share` printed or the studio's Share button gave"),
        )
    version, dot, payload = text[at + len(KEY) :].partition(".")
    if not version.isdigit() or not dot:
        raise fail(where, N_("this share link is damaged: its version is missing"), N_("copy the whole link again"))
    _check_version(int(version), where)
    bad = _PAYLOAD_RE.match(payload)
    if bad is None or bad.end() != len(payload):
        end = 0 if bad is None else bad.end()
        raise fail(
            where,
            N_(
                "this share link holds a character no share link has ({char!r} at character {at} of the link)",
                char=payload[end],
                at=at + len(KEY) + len(version) + 1 + end + 1,
            ),
            N_("copy the link again whole: a chat program or e-mail may have changed or wrapped it"),
        )
    return _unpack(_inflate(payload, where), where)


def _check_version(version: int, where: str) -> None:
    if version > FORMAT:
        raise fail(
            where,
            N_(
                "this link was made by a newer tablebot (link format {version}; this one reads format {format})",
                version=version,
                format=FORMAT,
            ),
            N_("update tablebot (pip install --upgrade tablebot), or ask for the files"),
        )
    if version < FORMAT:
        raise fail(
            where,
            N_(
                "this link was made by an older tablebot (link format {version}), which this one no "
                "longer reads (it reads format {format})",
                version=version,
                format=FORMAT,
            ),
            N_("ask for a new link, or for the files"),
        )


def _inflate(payload: str, where: str) -> bytes:
    cut = N_(
        "this share link is cut short or damaged (its {count:,} characters of contents do not unpack)",
        count=len(payload),
    )
    hint = N_("copy the whole link again: it is one long line, and the end is often lost")
    try:
        packed = base64.urlsafe_b64decode(payload + "=" * (-len(payload) % 4))
    except (binascii.Error, ValueError):
        raise fail(where, cut, hint) from None
    unpacker = zlib.decompressobj()
    try:
        data = unpacker.decompress(packed, MAX_UNPACKED + 1)
    except zlib.error:
        raise fail(where, cut, hint) from None
    if len(data) > MAX_UNPACKED or unpacker.unconsumed_tail:
        raise fail(
            where,
            N_("this share link unpacks to more than {mb} MB: no table is that large", mb=MAX_UNPACKED // 2**20),
            N_("share the files instead"),
        )
    if not unpacker.eof:
        raise fail(where, cut, hint)
    return data


def _unpack(data: bytes, where: str) -> Shared:
    broken = fail(
        where,
        N_("this share link unpacks, but not to a table and its files"),
        N_("make it again with `tablebot share` or the studio's Share button"),
    )
    try:
        body = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError):
        raise broken from None
    if not isinstance(body, dict) or not isinstance(body.get("name"), str):
        raise broken
    table, robot = _pair(body.get("table"), where), _pair(body.get("robot"), where, optional=True)
    world = body.get("world")
    world = shipped(world, where) if isinstance(world, dict) else world
    if table is None or (world is not None and not isinstance(world, str)):
        raise broken
    if not table[0].lower().endswith((".csv", ".tsv")) or (robot and not robot[0].lower().endswith(".toml")):
        raise fail(
            where,
            N_("this share link's files are not a table and a robot file"),
            N_("make it again with `tablebot share`"),
        )
    name = _NAME_RE.sub("-", body["name"]).strip(" .-")[:100] or "shared"
    return Shared(name, table, robot, world, _other_tables(body.get("tables", []), table[0], where))


def _other_tables(value: object, main: str, where: str) -> tuple[tuple[str, str], ...]:
    """A link's other tables (a robot of several): each a table file of its own name, none the main table's."""
    if not isinstance(value, list):
        raise fail(
            where,
            N_("this share link unpacks, but not to a table and its files"),
            N_("make it again with `tablebot share` or the studio's Share button"),
        )
    pairs = tuple(pair for pair in (_pair(item, where) for item in value) if pair is not None)
    names = [main, *(name for name, _ in pairs)]
    if len(set(names)) != len(names) or not all(name.lower().endswith((".csv", ".tsv")) for name in names):
        raise fail(
            where,
            N_("this share link's files are not a table and a robot file"),
            N_("make it again with `tablebot share`"),
        )
    return pairs


def _pair(value: object, where: str, optional: bool = False) -> tuple[str, str] | None:
    """A (file name, text) pair of the payload; a name that is not a plain file name is refused, so that a
    link never writes outside the folder it is opened into."""
    if value is None and optional:
        return None
    if not (
        isinstance(value, list) and len(value) == 2 and isinstance(value[0], str) and isinstance(value[1], str | dict)
    ):
        raise fail(
            where,
            N_("this share link unpacks, but not to a table and its files"),
            N_("make it again with `tablebot share` or the studio's Share button"),
        )
    name, text = value[0], shipped(value[1], where) if isinstance(value[1], dict) else value[1]
    if not _FILE_RE.match(name) or name == WORLD_NAME or not name.lower().endswith((".csv", ".tsv", ".toml")):
        raise fail(
            where,
            N_("this share link names a file {name!r} that no shared table has", name=name),
            N_("make it again with `tablebot share`"),
        )
    return name, text
