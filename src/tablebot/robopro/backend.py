"""``export --to robopro`` (the document's three lists as CSV) and ``--to robopro-rpp`` (the lists written into
a ROBO Pro program), registered as export back-ends."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.diagnostics import Diagnostic, fail
from tablebot.files import out_folder
from tablebot.formats.robopro_program import DEFAULT_NAMES
from tablebot.registry import Backend, Exported, Options, register

if TYPE_CHECKING:
    from tablebot.machine import Machine

def fit(machine: Machine) -> list[Diagnostic]:
    from tablebot.formats.robopro_lists import fit_problems

    return fit_problems(machine.table)


def export_lists(machine: Machine, out: Path | None, options: Options) -> Exported:
    from tablebot.formats import robopro_lists

    assert out is not None
    lists = robopro_lists.encode(machine.table)
    files = tuple(robopro_lists.write_lists(lists, out_folder(out, "OUTDIR")))
    return Exported(files, tuple(f"wrote {path}" for path in files))


def export_rpp(machine: Machine, out: Path | None, options: Options) -> Exported:
    """The three lists written into a ROBO Pro program: ``--into`` itself, or its copy in ``out``."""
    from tablebot.formats import robopro_lists
    from tablebot.formats import robopro_program as rpp

    into: Path | None = options.get("into")
    names = tuple(options.get("lists", DEFAULT_NAMES))
    if into is None:
        raise fail("--into", "robopro-rpp needs the program to write into", "add --into ENGINE.rpp")
    lists = robopro_lists.encode(machine.table)
    named = dict(zip(names, (lists.event, lists.action, lists.timer), strict=True))
    if len(named) < 3:
        raise fail("--event-list", "the three list names must differ", "give each list its own name")
    target = out_folder(out, "OUTDIR") / into.name if out else None
    written, from_csv = rpp.write_lists(into, named, target)
    return Exported((written,), (f"wrote {written} (lists {', '.join(named)}: {len(lists.event)} values each)",),
                    tuple(f"list {name} loads its values from a CSV file in ROBO Pro (initcsvcolumn), which "
                          "replaces the values written here" for name in from_csv))


ROBOPRO = register(Backend("robopro", "export", "the document's three ROBO Pro lists (event, action, timer)",
                           help="the three lists as CSV", fit=fit, export=export_lists))
ROBOPRO_RPP = register(Backend("robopro-rpp", "export", "the three lists written into a ROBO Pro program",
                               help="the lists written into a ROBO Pro program (--into)", fit=fit, export=export_rpp,
                               needs_out=False))
