"""The ``export`` command: a table for another system (ROBO Pro lists; later C and firmware)."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path

import typer

from tablebot import robopro
from tablebot.cli.app import app
from tablebot.cli.common import ROBOT_OPT, TABLE_ARG, console, guarded, load


class Target(StrEnum):
    robopro = "robopro"


@app.command("export")
@guarded
def export_cmd(
    table: Path = TABLE_ARG,
    outdir: Path = typer.Argument(..., help="Folder to write into (created if missing)."),
    to: Target = typer.Option(..., "--to", help="Export target."),
    robot: Path | None = ROBOT_OPT,
) -> None:
    """Export a table for another system (robopro: the document's three ROBO Pro lists as CSV)."""
    parsed, _ = load(table, robot)
    lists = robopro.encode(parsed)
    for path in robopro.write_lists(lists, outdir):
        console.print(f"wrote {path}")


