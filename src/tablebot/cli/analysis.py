"""Analysis commands: ``check`` (a table is valid, and what the checker finds in it)."""

from __future__ import annotations

from pathlib import Path

from tablebot.cli.app import app
from tablebot.cli.common import ROBOT_OPT, TABLE_ARG, console, guarded, load


@app.command("check")
@guarded
def check_cmd(table: Path = TABLE_ARG, robot: Path | None = ROBOT_OPT) -> None:
    """Parse and compile a table; every problem is reported as file:line:column (exit code 2)."""
    parsed, machine = load(table, robot)
    console.print(f"{parsed.path}: {len(parsed.rows)} rows, {len(machine.states)} states, "
                  f"events {' '.join(parsed.events)}, robot {parsed.robot.name}: ok")
