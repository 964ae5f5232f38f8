"""``export --to robopro`` (the document's three lists as CSV), ``--to robopro-rpp`` (the lists written into
a ROBO Pro program) and ``--to robopro-program`` (the document's whole engine as a ROBO Pro program, with the
table in it), registered as export back-ends, with the robot file's ``[robopro]`` section."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.diagnostics import Diagnostic, TableBotError, fail
from tablebot.files import out_folder
from tablebot.i18n import N_
from tablebot.registry import ExportBackend, Exported, ExportOptions, register
from tablebot.robopro.rpp_edit import DEFAULT_NAMES
from tablebot.robopro.wiring import read_robot_robopro

if TYPE_CHECKING:
    from tablebot.machine import Machine


def fit(machine: Machine) -> list[Diagnostic]:
    from tablebot.robopro.lists import fit_problems

    return cross_problems(machine) or fit_problems(machine.table)


def cross_problems(machine: Machine) -> list[Diagnostic]:
    """A cross-table column of the main table: the three lists hold the main table alone, so the state it
    reads is nowhere (refused at the column, rather than read as never present)."""
    table = machine.table
    return [
        Diagnostic(
            table.path,
            event.line,
            event.at,
            N_(
                "{column}: the ROBO Pro lists hold table {table} alone, without table {other} whose "
                "state this column reads",
                column=event.column,
                table=table.name,
                other=event.table,
            ),
            N_("export --to robopro-program runs every table, one process each (docs: ROBO Pro)"),
        )
        for event in table.cross.values()
    ]


def _refuse_cross(machine: Machine) -> None:
    """Before anything is written: a main table reading another table's state cannot be exported alone."""
    problems = cross_problems(machine)
    if problems:
        raise TableBotError(problems)


def main_only(machine: Machine) -> tuple[str, ...]:
    """The warning for a robot of several tables, whose three lists hold its main table alone (the document's
    lists are one table's; the whole program runs every table, one process each)."""
    from tablebot.robot_tables import tables_of

    specs = tables_of(machine.table.robot)
    if not specs:
        return ()
    return (
        N_(
            "the robot has {n} tables: the ROBO Pro lists hold its main table ({main}) only, not {others}; "
            "export --to robopro-program runs every table, one process each",
            n=len(specs),
            main=specs[0].name,
            others=", ".join(spec.name for spec in specs[1:]),
        ),
    )


def export_lists(machine: Machine, out: Path | None, options: ExportOptions) -> Exported:
    from tablebot.robopro import lists

    assert out is not None
    _refuse_cross(machine)
    encoded = lists.encode(machine.table)
    files = tuple(lists.write_lists(encoded, out_folder(out, "OUTDIR")))
    return Exported(files, tuple(N_("wrote {file}", file=str(path)) for path in files), main_only(machine))


def export_rpp(machine: Machine, out: Path | None, options: ExportOptions) -> Exported:
    """The three lists written into a ROBO Pro program: ``--into`` itself, or its copy in ``out``."""
    from tablebot.robopro import lists
    from tablebot.robopro import rpp_edit as rpp

    into = options.into
    names = options.lists or DEFAULT_NAMES
    if into is None:
        raise fail("--into", N_("robopro-rpp needs the program to write into"), N_("add --into ENGINE.rpp"))
    _refuse_cross(machine)
    encoded = lists.encode(machine.table)
    named = dict(zip(names, (encoded.event, encoded.action, encoded.timer), strict=True))
    if len(named) < 3:
        raise fail("--event-list", N_("the three list names must differ"), N_("give each list its own name"))
    target = out_folder(out, "OUTDIR") / into.name if out else None
    written, from_csv = rpp.write_lists(into, named, target)
    return Exported(
        (written,),
        (
            N_(
                "wrote {file} (lists {lists}: {n} values each)",
                file=str(written),
                lists=tuple(named),
                n=len(encoded.event),
            ),
        ),
        main_only(machine)
        + tuple(
            N_(
                "list {name} loads its values from column {column} of a CSV file when the program starts "
                "(its load-from-CSV setting), which replaces the values written here; turn that off in "
                "the list's properties in ROBO Pro, or load the lists from `tablebot export --to robopro` "
                "CSV files instead",
                name=name,
                column=column,
            )
            for name, column in from_csv.items()
        ),
    )


def program_fit(machine: Machine) -> list[Diagnostic]:
    """Every reason the program does not take the table (a robot of several tables: any of its tables)."""
    from tablebot.robopro.fit import problems
    from tablebot.robopro.processes import several_problems
    from tablebot.tables import several

    tables = several(machine.table)
    if tables is None:
        return problems(machine.table)
    # each table's own rows; the robot file's problems once, with the main table
    found = several_problems(tables)
    files = {table.path for table in tables.tables}
    main = machine.table.name == tables.names[0]
    return [d for d in found if d.path == machine.table.path or (main and d.path not in files)]


def export_program(machine: Machine, out: Path | None, options: ExportOptions) -> Exported:
    """The whole engine as one .rpp, named after the robot; a table that does not fit is refused before the
    folder is made."""
    from tablebot.files import write_text
    from tablebot.robopro.processes import generate_several
    from tablebot.robopro.program import file_name, generate
    from tablebot.tables import several

    assert out is not None
    tables = several(machine.table)
    text = generate(machine.table) if tables is None else generate_several(tables)
    path = write_text(out_folder(out, "OUTDIR") / file_name(machine.table), text)
    lines: tuple[str, ...] = (N_("wrote {file}: open it in ROBO Pro 4.x", file=str(path)),)
    if tables is not None:
        lines += (
            N_(
                "its main program runs a process per table ({tables}) and a clock process that starts "
                "each tick for all of them",
                tables=", ".join(tables.names),
            ),
        )
    return Exported((path,), lines)


ROBOPRO = register(
    ExportBackend(
        name="robopro",
        makes="the document's three ROBO Pro lists (event, action, timer)",
        help="the three lists as CSV",
        fit=fit,
        export=export_lists,
    )
)
ROBOPRO_RPP = register(
    ExportBackend(
        name="robopro-rpp",
        makes="the three lists written into a ROBO Pro program",
        help="the lists written into a ROBO Pro program (--into)",
        fit=fit,
        export=export_rpp,
        needs_out=False,
    )
)
ROBOPRO_PROGRAM = register(
    ExportBackend(
        name="robopro-program",
        makes="a whole ROBO Pro program running the table (the document's engine)",
        help="a whole ROBO Pro program that runs the table",
        fit=program_fit,
        export=export_program,
        section="robopro",
        read_section=read_robot_robopro,
    )
)
