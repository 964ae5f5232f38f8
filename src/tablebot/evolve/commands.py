"""The commands report.md offers for each table evolve wrote: ``tablebot sim`` in each world of the search, and
``tablebot sweep`` on all its scenarios; for one table of several, in a copy of the robot's folder (its robot
file names its tables by file). User text reaches the shell only through :func:`tablebot.escape.shell_word`."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.escape import shell_word

if TYPE_CHECKING:
    from tablebot.evolve.whole import Whole

__all__ = ["Replay", "placed", "sim_commands", "sweep_command", "world_names"]


@dataclass(frozen=True)
class Replay:
    """How the written tables were run, for the commands that run one again: the robot file, every world,
    the seconds of each run, the search's ``--seeds`` and ``--grid``, and the output folder."""

    robot: str | None
    worlds: tuple[str, ...]
    seconds: float
    seeds: str
    grid: tuple[str, ...]
    out: Path


def _files_given(replay: Replay, worlds: Sequence[str], robot: str | None = None) -> list[str]:
    """``--robot`` and ``--world`` for the files the search read (beside a written table in OUT there are
    neither, and on its own the table would be read as the built-in BumberBot)."""
    robot = robot or replay.robot
    words = ["--robot", str(robot)] if robot and (robot != replay.robot or Path(robot).is_file()) else []
    for world in worlds:
        if world and Path(world).is_file():
            words += ["--world", str(world)]
    return words


def world_names(worlds: Sequence[str]) -> list[str]:
    """A short name per world (its file's stem; numbered when two stems are the same)."""
    stems = [Path(w).stem or "world" for w in worlds]
    return [stem if stems.count(stem) == 1 else f"{k + 1}-{stem}" for k, stem in enumerate(stems)]


def placed(path: Path, label: str, replay: Replay, whole: Whole | None) -> tuple[str, str, str | None]:
    """What a command runs a written table as: of one table, the table itself (no shell words before the
    command, the search's robot file); of one of several, a copy of the robot's folder under ``OUT/robot`` with
    the table in its file's place (the robot file names its tables by file): the shell words that make the copy,
    its main table and its robot file."""
    if whole is None or not replay.robot:
        return "", str(path), None
    from tablebot.robot_tables import tables_of

    robot = Path(replay.robot)
    specs = tables_of(whole.tables.robot)
    folder = replay.out / "robot" / label
    words = [
        ["mkdir", "-p", str(folder)],
        ["cp", "-R", f"{robot.parent}/.", f"{folder}/"],
        ["cp", str(path), str(folder / specs[whole.index].file)],
    ]
    setup = " && ".join(" ".join(shell_word(w) for w in command) for command in words) + " && "
    return setup, str(folder / specs[0].file), str(folder / robot.name)


def sim_commands(path: Path, label: str, replay: Replay, whole: Whole | None = None) -> list[tuple[str, str]]:
    """Per world of the search, its name and the ``tablebot sim`` of a written table there, as long as the
    search ran it, into its own folder under ``OUT/sim`` (so no run writes over another's)."""
    names = world_names(replay.worlds)
    setup, table, robot = placed(path, label, replay, whole)
    found = []
    for world, name in zip(replay.worlds, names, strict=True):
        out = replay.out / "sim" / label if len(replay.worlds) == 1 else replay.out / "sim" / label / name
        words = [
            "tablebot",
            "sim",
            table,
            *_files_given(replay, [world], robot),
            "--seconds",
            f"{replay.seconds:g}",
            "--out",
            str(out),
        ]
        found.append((name, setup + " ".join(shell_word(word) for word in words)))
    return found


def sweep_command(path: Path, label: str, replay: Replay, whole: Whole | None = None) -> str:
    """``tablebot sweep`` of a written table on every world and scenario the search ran it on."""
    setup, table, robot = placed(path, label, replay, whole)
    words = ["tablebot", "sweep", table, *_files_given(replay, replay.worlds, robot), "--seeds", replay.seeds]
    for grid in replay.grid:
        words += ["--grid", grid]
    words += ["--seconds", f"{replay.seconds:g}", "--out", str(replay.out / "sweep" / label)]
    return setup + " ".join(shell_word(word) for word in words)
