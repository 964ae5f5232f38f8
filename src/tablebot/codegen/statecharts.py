"""``export --to scxml`` and ``export --to xstate``: a robot's tables (all of them, when its robot file names
several) as statecharts in the standard formats, registered as back-ends (:mod:`tablebot.formats.statecharts`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.files import out_folder, write_text
from tablebot.fileset import file_set
from tablebot.i18n import N_
from tablebot.registry import ExportBackend, Exported, ExportOptions, register

if TYPE_CHECKING:
    from tablebot.machine import Machine
    from tablebot.table import Table

__all__ = ["SCXML", "SCXML_FILE", "XSTATE", "XSTATE_FILE"]

SCXML_FILE = "machine.scxml"
XSTATE_FILE = "machine.json"


def _tables(machine: Machine) -> tuple[Table, ...]:
    """The robot's tables, the main one first (one table: just it)."""
    from tablebot.tables import several

    tables = several(machine.table)
    return (machine.table,) if tables is None else tables.tables


def _write(out: Path | None, files: dict[str, str], how: str) -> Exported:
    assert out is not None
    folder = out_folder(out, "OUTDIR")
    with file_set(folder):
        written = tuple(write_text(folder / name, text) for name, text in files.items())
    return Exported(written, (*(N_("wrote {file}", file=str(path)) for path in written), how))


def export_scxml(machine: Machine, out: Path | None, options: ExportOptions) -> Exported:
    from tablebot.formats.statecharts.scxml import export_scxml as scxml

    text = scxml(_tables(machine))
    return _write(
        out,
        {SCXML_FILE: text},
        N_("send it one event 'tick' per tick, the inputs and pulses as its data (docs: Statecharts)"),
    )


def export_xstate(machine: Machine, out: Path | None, options: ExportOptions) -> Exported:
    from tablebot.formats.statecharts.xstate import RUNTIME, export_xstate, runtime_module

    text = export_xstate(_tables(machine))
    return _write(
        out,
        {XSTATE_FILE: text, RUNTIME: runtime_module()},
        N_(
            "createActor(tablebotMachine(config)) from {runtime}, then one 'tick' event per tick (docs: Statecharts)",
            runtime=RUNTIME,
        ),
    )


SCXML = register(
    ExportBackend(
        name="scxml",
        makes="a W3C SCXML statechart, one 'tick' event per tick",
        help="SCXML statechart",
        export=export_scxml,
    )
)
XSTATE = register(
    ExportBackend(
        name="xstate",
        makes="an XState 5 machine config (JSON) and the module that implements its guards and actions",
        help="XState 5 machine",
        export=export_xstate,
    )
)
