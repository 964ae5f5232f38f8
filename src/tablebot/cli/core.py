"""Core commands: ``import``, ``trace`` and ``demo`` (the table, the engine, the lists)."""

from __future__ import annotations

import sys
from enum import StrEnum
from pathlib import Path

import typer

from tablebot.cli.app import app
from tablebot.cli.common import (
    FORCE_OPT,
    ROBOT_OPT,
    TABLE_ARG,
    console,
    err_console,
    guarded,
    load,
    open_project,
    out_file,
    out_folder,
)
from tablebot.diagnostics import severity_word
from tablebot.escape import terminal
from tablebot.i18n import N_, Message, _, asked, localise, ngettext
from tablebot.table import Table


class Source(StrEnum):
    robopro = "robopro"
    scxml = "scxml"
    xstate = "xstate"


@app.command("import")
@guarded
def import_cmd(
    directory: Path = typer.Argument(
        ...,
        metavar="FOLDER|FILE",
        help="Folder with event.csv, action.csv, timer.csv (robopro), or the exported statechart (scxml, xstate).",
    ),
    source: Source = typer.Option(
        ..., "--from", help="What it holds: robopro lists, or what export --to scxml or --to xstate wrote."
    ),
    out: Path | None = typer.Option(
        None,
        "--out",
        help="Table CSV to write (default: standard output); a folder for a statechart of several tables.",
    ),
    robot: Path | None = ROBOT_OPT,
    force: bool = FORCE_OPT,
) -> None:
    """Rebuild a table from ROBO Pro lists (descriptions are lost: the lists never held them), or from an SCXML or
    XState statechart that tablebot exported."""
    from tablebot.files import write_text
    from tablebot.formats.table_write import format_table
    from tablebot.robopro import lists as robopro
    from tablebot.robot import BUMBERBOT, load_robot

    if source is not Source.robopro:
        from tablebot.formats.statecharts.importing import import_statechart

        target = out if out is None or out.is_dir() else out_file(out, "--out")  # a folder: several tables
        text, said = import_statechart(directory, source.value, target, load_robot(robot) if robot else None)
        sys.stdout.write(text or "")
        for line in said:
            err_console.print(terminal(line))
        return

    table = robopro.read_table(directory, load_robot(robot) if robot else BUMBERBOT)
    for line in _rule_warnings(table):
        err_console.print(f"{severity_word('warning')}: {terminal(localise(line))}")
    text = format_table(table, asked())  # its header in the language asked for (--lang): the reader takes either
    if out is None:
        sys.stdout.write(text)
    else:
        write_text(out_file(out, "--out"), text)
        err_console.print(
            ngettext(
                "wrote {path} ({n} row; descriptions are not in the lists)",
                "wrote {path} ({n} rows; descriptions are not in the lists)",
                len(table.rows),
            ).format(path=terminal(str(out)), n=len(table.rows))
        )


def _rule_warnings(table: Table) -> list[Message]:
    """The lists ran in the document's engine; a robot whose rule is "always" would run a row that requires no
    event differently wherever a tick with no event can come."""
    from tablebot.robot import MATCH_DOCUMENT
    from tablebot.table import no_event_rows

    if table.robot.match == MATCH_DOCUMENT:
        return []
    return [
        N_(
            "line {line} of the lists requires no event: the document's engine, which ran these lists, fires "
            'nothing on a tick with no event, but {source} follows match = "always" (it fires the row there), '
            'and such a tick can come in state {state!r} ({why}); write match = "document" in {source} to run '
            "the table as the lists ran",
            line=f.row.line,
            source=table.robot.source,
            state=f.row.state,
            why=f.quiet,
        )
        for f in no_event_rows(table)
        if f.quiet
    ]


@app.command("trace")
@guarded
def trace_cmd(
    table: Path = TABLE_ARG,
    inputs: Path = typer.Option(..., "--inputs", help="Inputs CSV: header of input names, one row per tick."),
    out: Path | None = typer.Option(None, "--out", help="Trace file (JSON Lines; default: standard output)."),
    robot: Path | None = ROBOT_OPT,
    force: bool = FORCE_OPT,
) -> None:
    """Replay recorded inputs through the engine and write the trace, one JSON line per tick."""
    from tablebot.files import atomic_write
    from tablebot.formats.inputs_csv import load_inputs
    from tablebot.formats.trace_lines import write_trace
    from tablebot.replay import replay, replay_several

    project = open_project(table, robot)
    several = project.tables  # a robot of several tables runs them all (tablebot.tables)
    ticks = load_inputs(inputs, several or project.machine)
    lines = replay_several(several, ticks) if several else replay(project.machine, ticks)
    if out is None:
        write_trace(lines, sys.stdout)
        return
    with atomic_write(out_file(out, "--out")) as stream:
        count = write_trace(lines, stream)
    err_console.print(
        ngettext("wrote {path} ({n} tick)", "wrote {path} ({n} ticks)", count).format(path=terminal(str(out)), n=count)
    )


@app.command("demo")
@guarded
def demo_cmd(
    out: Path = typer.Option(
        Path("out/replay"),
        "--out",
        help="Folder for the replayed trace (its own: "
        "make demo fills out/demo with a simulated run's trace and pictures).",
    ),
) -> None:
    """Replay the BumberBot on its built-in recorded inputs and summarise what it did."""
    from tablebot.examples import example_path
    from tablebot.files import atomic_write
    from tablebot.formats.inputs_csv import load_inputs
    from tablebot.formats.trace_lines import write_trace
    from tablebot.replay import replay

    folder = example_path("bumberbot")
    machine = load(folder / "table.csv")[1]
    ticks = load_inputs(folder / "inputs.csv", machine)
    out_folder(out, "--out")
    lines = list(replay(machine, ticks))
    with atomic_write(out / "trace.jsonl") as stream:
        write_trace(lines, stream)
    visits: dict[object, int] = {}
    for line in lines:
        visits[line["state"]] = visits.get(line["state"], 0) + 1
    fired = sum(1 for line in lines if line["row"] is not None)
    console.print(
        _("BumberBot: {ticks} ticks ({seconds:.1f} s), {fired} rows fired").format(
            ticks=len(lines), seconds=machine.table.robot.seconds(len(lines)), fired=fired
        )
    )
    for state, count in visits.items():
        console.print(
            "  "
            + _("state {state:>4}: {seconds:6.2f} s").format(
                state=terminal(str(state)), seconds=machine.table.robot.seconds(count)
            )
        )
    console.print(_("wrote {path}").format(path=terminal(str(out / "trace.jsonl"))))
