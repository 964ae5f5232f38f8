"""The ``export`` command: a table for another system (ROBO Pro lists, a ROBO Pro program, C, a TXT 4.0 program),
through :func:`tablebot.api.exporting.export`."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path

import typer

from tablebot import registry
from tablebot.cli.app import app
from tablebot.cli.common import ROBOT_OPT, TABLE_ARG, console, err_console, guarded, open_project
from tablebot.diagnostics import severity_word
from tablebot.escape import terminal
from tablebot.i18n import localise
from tablebot.robopro import rpp_edit as rpp

#: ``--to``'s choices: every registered export back-end.
Target = StrEnum("Target", {b.name: b.name for b in registry.exporters()})  # type: ignore[misc]


class Lookup(StrEnum):
    auto = "auto"
    dense = "dense"
    scan = "scan"


@app.command("export")
@guarded
def export_cmd(
    table: Path = TABLE_ARG,
    outdir: Path | None = typer.Argument(
        None,
        metavar="OUTDIR",
        help="Folder to write into (created if missing); "
        "for robopro-rpp, where to put the program instead of rewriting it.",
    ),
    to: Target = typer.Option(..., "--to", help="; ".join(f"{b.name}: {b.help}" for b in registry.exporters()) + "."),
    into: Path | None = typer.Option(None, "--into", help="robopro-rpp: the ROBO Pro program (.rpp) to update."),
    event_list: str = typer.Option(rpp.DEFAULT_NAMES[0], "--event-list", help="robopro-rpp: the event list's name."),
    action_list: str = typer.Option(rpp.DEFAULT_NAMES[1], "--action-list", help="robopro-rpp: the action list's name."),
    timer_list: str = typer.Option(rpp.DEFAULT_NAMES[2], "--timer-list", help="robopro-rpp: the timer list's name."),
    lookup: Lookup = typer.Option(
        Lookup.auto,
        "--lookup",
        help="c: first-match lookup, dense (O(1) table) or "
        "scan (rows per state); auto takes dense while it needs at most 8 KB.",
    ),
    robot: Path | None = ROBOT_OPT,
) -> None:
    """Export a table for another system: ROBO Pro lists, a ROBO Pro program, or C source.

    Its files replace an earlier export's in OUTDIR, all at once; a table or robot file of yours that has
    one of their names is never replaced (choose another OUTDIR).
    """
    project = open_project(table, robot)
    done = project.export(to.value, outdir, into=into, lists=(event_list, action_list, timer_list), lookup=lookup.value)
    for line in done.lines:
        console.print(terminal(str(localise(line))))
    for line in done.warnings:
        err_console.print(f"{severity_word('warning')}: {terminal(str(localise(line)))}")
