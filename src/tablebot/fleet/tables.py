"""What a fleet's plan needs of a robot of several tables (issue 36 §2): a digest of all its table files, and the
note that a plan running its main table alone gives (``make_plan`` without ``every_table``; ``sweep``, ``tune``,
``grade`` and ``evolve`` run them all)."""

from __future__ import annotations

import hashlib
from pathlib import Path

from tablebot.diagnostics import Diagnostic, notify
from tablebot.fleet.spec import digest
from tablebot.i18n import N_
from tablebot.robot import Robot
from tablebot.robot_tables import tables_of
from tablebot.table import Table
from tablebot.tables import RobotTables

__all__ = ["main_table_only", "tables_digest"]


def tables_digest(table: Table, tables: RobotTables | None) -> str:
    """The table file's digest; for a robot of several tables, of every table file (a resumed sweep of a robot
    whose lights table changed starts again, as one whose main table changed does)."""
    if tables is None:
        return digest(Path(table.path))
    return hashlib.sha256("".join(digest(Path(t.path)) for t in tables.tables).encode()).hexdigest()[:16]


def main_table_only(robot: Robot) -> None:
    """A note that a plan of a robot of several tables runs its main table alone (no command asks for one now)."""
    specs = tables_of(robot)
    if specs:
        others = ", ".join(spec.name for spec in specs[1:])
        notify(
            Diagnostic(
                robot.source,
                robot.line("tables"),
                1,
                N_(
                    "this runs the main table ({main}) only so far, not {others}: the outputs only they write "
                    "stay at 0",
                    main=specs[0].name,
                    others=others,
                ),
                N_("tablebot sim, sweep, tune and grade run every table (docs/engine.md)"),
                "note",
            )
        )
