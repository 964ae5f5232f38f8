"""``export`` from Python: the table for another system (ROBO Pro lists, a ROBO Pro program, C, a TXT 4.0
program, ...), each target a back-end of :mod:`tablebot.registry`."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.diagnostics import fail
from tablebot.i18n import N_

if TYPE_CHECKING:
    from tablebot.loading import Loaded, PathLike
    from tablebot.registry import Exported, Lookup

#: ``lookup``'s choices (``--lookup``).
LOOKUPS = ("auto", "dense", "scan")


def targets() -> list[str]:
    """The names ``to`` takes: every registered export back-end."""
    from tablebot import registry

    return [b.name for b in registry.exporters("export")]


def export(
    project: Loaded,
    to: str,
    out: PathLike | None = None,
    *,
    into: PathLike | None = None,
    lists: Sequence[str] | None = None,
    lookup: str = "auto",
) -> Exported:
    """Export the table (``tablebot export TABLE OUT --to TO``): its files replace an earlier export's in
    ``out`` all at once (a table or robot file of yours is never replaced). ``into``: the ROBO Pro program to
    update (``robopro-rpp``); ``lists``: its event, action and timer lists' names; ``lookup``: the C engine's
    first-match lookup, ``dense``, ``scan`` or ``auto``. Returns what was written and what to say about it.

    >>> import tablebot
    >>> done = tablebot.open("examples/bumberbot").export(to="c", out="out/c")
    >>> sorted(p.name for p in done.files)
    ['tb_config.h', 'tb_engine.c', 'tb_engine.h', 'tb_table.c']
    """
    from tablebot import registry

    backend = registry.exporter(to)
    if backend is None or backend.kind != "export":
        raise fail(
            "--to", N_("unknown export target {name!r}", name=to), N_("use one of {known}", known=tuple(targets()))
        )
    if out is None and backend.needs_out:
        raise fail(
            "OUTDIR",
            N_("--to {to} needs a folder to write into", to=to),
            N_("tablebot export TABLE OUTDIR --to {to}", to=to),
        )
    options = registry.ExportOptions(
        into=Path(into) if into is not None else None, lists=_three(lists), lookup=_lookup(lookup)
    )
    with project.writing():
        return backend.export(project.machine, Path(out) if out is not None else None, options)


def _three(lists: Sequence[str] | None) -> tuple[str, str, str] | None:
    """The event, action and timer lists' names, or None for the document's own."""
    if lists is None:
        return None
    if len(lists) != 3:
        raise fail(
            "--event-list",
            N_("give three list names (event, action, timer), not {n}", n=len(lists)),
            N_("--event-list, --action-list and --timer-list"),
        )
    return lists[0], lists[1], lists[2]


def _lookup(lookup: str) -> Lookup:
    if lookup not in LOOKUPS:
        raise fail(
            "--lookup", N_("unknown lookup {name!r}", name=lookup), N_("use one of {known}", known=tuple(LOOKUPS))
        )
    return lookup  # type: ignore[return-value]  # one of LOOKUPS
