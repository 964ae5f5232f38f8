"""``export --to c``: the portable C99 engine and the table as const data, registered as a back-end."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.diagnostics import Diagnostic
from tablebot.files import out_folder
from tablebot.i18n import N_
from tablebot.registry import ExportBackend, Exported, ExportOptions, refused, register

if TYPE_CHECKING:
    from tablebot.machine import Machine


def fit(machine: Machine) -> list[Diagnostic]:
    """What the C engine's data layout cannot hold (also the base of every board's fit)."""
    from tablebot.tables import several

    tables = several(machine.table)  # a robot of several tables: each must fit
    machines = (machine,) if tables is None else tables.machines
    return [found for m in machines for found in _fit_one(m)]


def _fit_one(machine: Machine) -> list[Diagnostic]:
    from tablebot.codegen.packing import check_fits, plan

    return refused(lambda: check_fits(machine)) or refused(lambda: plan(machine))


def export(machine: Machine, out: Path | None, options: ExportOptions) -> Exported:
    from tablebot.codegen.several import generate_several
    from tablebot.codegen.source import generate
    from tablebot.tables import several

    assert out is not None
    tables = several(machine.table)  # a robot of several tables: all of them, stepped by tb_robot.c
    # before the folder is made: a refused table leaves none
    source = generate(machine, options.lookup) if tables is None else generate_several(tables, options.lookup)
    files = tuple(source.write(out_folder(out, "OUTDIR")))
    kind = "dense" if source.layout.dense else "scan"
    return Exported(
        files,
        (
            *(N_("wrote {file}", file=str(path)) for path in files),
            N_(
                "lookup: {kind}, {size} bytes; table hash 0x{hash:08x}",
                kind=kind,
                size=source.layout.lookup_bytes,
                hash=source.layout.table_hash,
            ),
        ),
    )


C = register(
    ExportBackend(
        name="c",
        makes="a portable C99 engine and the table as const data",
        help="portable C99 engine + table",
        fit=fit,
        export=export,
    )
)
