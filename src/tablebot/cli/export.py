"""The ``export`` command: a table for another system (ROBO Pro lists, a ROBO Pro program, C, a TXT 4.0 program)."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from tablebot.cli.app import app
from tablebot.cli.common import ROBOT_OPT, TABLE_ARG, console, err_console, guarded, load, out_folder
from tablebot.diagnostics import fail
from tablebot.escape import shell_word, terminal
from tablebot.formats import robopro_program as rpp

if TYPE_CHECKING:
    from tablebot.table import Table


class Target(StrEnum):
    robopro = "robopro"
    robopro_rpp = "robopro-rpp"
    c = "c"
    txt4 = "txt4"


class Lookup(StrEnum):
    auto = "auto"
    dense = "dense"
    scan = "scan"


@app.command("export")
@guarded
def export_cmd(
    table: Path = TABLE_ARG,
    outdir: Path | None = typer.Argument(None, metavar="OUTDIR", help="Folder to write into (created if missing); "
                                         "for robopro-rpp, where to put the program instead of rewriting it."),
    to: Target = typer.Option(..., "--to", help="robopro: the three lists as CSV; robopro-rpp: the lists "
                              "written into a ROBO Pro program (--into); c: portable C99 engine + table; "
                              "txt4: a program that runs the table on a TXT 4.0 itself (then: tablebot upload)."),
    into: Path | None = typer.Option(None, "--into", help="robopro-rpp: the ROBO Pro program (.rpp) to update."),
    event_list: str = typer.Option(rpp.DEFAULT_NAMES[0], "--event-list", help="robopro-rpp: the event list's name."),
    action_list: str = typer.Option(rpp.DEFAULT_NAMES[1], "--action-list", help="robopro-rpp: the action list's name."),
    timer_list: str = typer.Option(rpp.DEFAULT_NAMES[2], "--timer-list", help="robopro-rpp: the timer list's name."),
    lookup: Lookup = typer.Option(Lookup.auto, "--lookup", help="c: first-match lookup, dense (O(1) table) or "
                                  "scan (rows per state); auto takes dense while it needs at most 8 KB."),
    robot: Path | None = ROBOT_OPT,
) -> None:
    """Export a table for another system: ROBO Pro lists, a ROBO Pro program, or C source.

    Its files replace an earlier export's in OUTDIR, all at once; a table or robot file of yours that has
    one of their names is never replaced (choose another OUTDIR).
    """
    from tablebot.formats import robopro_lists as robopro

    parsed, machine = load(table, robot)
    if to == Target.robopro_rpp:
        _export_rpp(parsed, outdir, into, (event_list, action_list, timer_list))
        return
    if outdir is None:
        raise fail("OUTDIR", f"--to {to.value} needs a folder to write into", f"tablebot export TABLE OUTDIR --to {to}")
    if to == Target.c:
        from tablebot.codegen import generate

        source = generate(machine, lookup.value)  # before the folder is made: a refused table leaves none
        for path in source.write(out_folder(outdir, "OUTDIR")):
            console.print(f"wrote {terminal(str(path))}")
        lookup_kind = "dense" if source.layout.dense else "scan"
        console.print(f"lookup: {lookup_kind}, {source.layout.lookup_bytes} bytes; "
                      f"table hash 0x{source.layout.table_hash:08x}")
        return
    if to == Target.txt4:
        from tablebot.hw.txt4_export import export_txt4

        workspace = export_txt4(machine)  # a table that does not fit is refused before anything is written
        for path in workspace.write(out_folder(outdir, "OUTDIR")):
            console.print(f"wrote {terminal(str(path))}")
        console.print(f"upload and start it: tablebot upload {terminal(shell_word(str(outdir)))} "
                      "--to txt4://192.168.7.2 --key API_KEY")
        return
    lists = robopro.encode(parsed)
    for path in robopro.write_lists(lists, out_folder(outdir, "OUTDIR")):
        console.print(f"wrote {terminal(str(path))}")


def _export_rpp(table: Table, outdir: Path | None, into: Path | None, names: tuple[str, str, str]) -> None:
    """The three lists written into a ROBO Pro program: ``into`` itself, or its copy in ``outdir``."""
    from tablebot.formats import robopro_lists as robopro

    if into is None:
        raise fail("--into", "robopro-rpp needs the program to write into", "add --into ENGINE.rpp")
    lists = robopro.encode(table)
    named = dict(zip(names, (lists.event, lists.action, lists.timer), strict=True))
    if len(named) < 3:
        raise fail("--event-list", "the three list names must differ", "give each list its own name")
    out = out_folder(outdir, "OUTDIR") / into.name if outdir else None
    written, from_csv = rpp.write_lists(into, named, out)
    console.print(f"wrote {terminal(str(written))} (lists {terminal(', '.join(named))}: "
                  f"{len(lists.event)} values each)")
    for name in from_csv:
        err_console.print(f"warning: list {terminal(name)} loads its values from a CSV file in ROBO Pro "
                          "(initcsvcolumn), which replaces the values written here")
