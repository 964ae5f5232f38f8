"""Grading against a robot of several tables (issue 36 §2): a submission's table is the robot's main table, run
beside the challenge's other tables, so that the whole robot's behaviour is proved and scored. The robot file
names its tables by file, beside it: the submission is graded in a folder of its own (temporary) holding the
challenge's robot file, the submission's table as the main table's file and, for each other table, the
submission's own copy when it hands one in (a file of that name beside its table), else the challenge's."""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from tablebot.diagnostics import fail
from tablebot.grade.challenge import Challenge
from tablebot.grade.submissions import Submission
from tablebot.i18n import N_
from tablebot.robot import load_robot
from tablebot.robot_tables import tables_of

__all__ = ["robot_of"]


@contextlib.contextmanager
def robot_of(challenge: Challenge, sub: Submission) -> Iterator[tuple[Path, Path]]:
    """The table and robot file to grade ``sub`` with (for a robot of one table: its table and the challenge's
    robot file, as ever)."""
    assert sub.table is not None  # a submission without a table has its error already
    specs = tables_of(load_robot(challenge.robot))
    if not specs:
        yield sub.table, challenge.robot
        return
    with tempfile.TemporaryDirectory(prefix="tablebot-grade-") as folder:
        root = Path(folder).resolve()
        robot = root / challenge.robot.name
        shutil.copyfile(challenge.robot, robot)
        for k, spec in enumerate(specs):
            target = (root / spec.file).resolve()
            if not target.is_relative_to(root):
                raise fail(
                    challenge.robot.name,
                    N_("[tables] names {file}, a file outside the challenge's folder", file=spec.file),
                    N_("keep the challenge's tables beside its robot file"),
                )
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(sub.table if k == 0 else _other(challenge, sub, spec.file), target)
        yield root / specs[0].file, robot


def _other(challenge: Challenge, sub: Submission, file: str) -> Path:
    """A table other than the main one: the submission's own copy (beside its table, inside its folder), else
    the challenge's."""
    assert sub.table is not None
    mine = sub.table.parent / file
    own = os.path.realpath(sub.own) if sub.own is not None else None
    if own is not None and mine.is_file() and Path(os.path.realpath(mine)).is_relative_to(own):
        return mine
    return challenge.robot.parent / file
