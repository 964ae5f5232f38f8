"""The one registry of back-ends: every export target, board and live robot tablebot knows, with what it
needs of a robot file and what in a table it cannot hold.

A back-end is one module that builds a :class:`Backend` and calls :func:`register` when imported;
:func:`tablebot.catalog.load_all` imports every such module. ``tablebot export --to``, ``build --board``,
``run --on`` and ``check --target`` take their choices from here, and a back-end's robot-file section is
read through the reader it registers (:func:`tablebot.robot.register_section`). See docs/architecture.md,
"Where to add".
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from tablebot.diagnostics import Diagnostic, TableBotError
from tablebot.robot import SectionReader, register_section

if TYPE_CHECKING:
    from tablebot.loop import RobotIO
    from tablebot.machine import Machine

Kind = Literal["export", "board", "live"]
KINDS: tuple[Kind, ...] = ("export", "board", "live")
#: Options a command hands an exporter or a live back-end (``--into``, ``--lookup``, ``--seed``, ...), by name.
Options = Mapping[str, Any]
FitCheck = Callable[["Machine"], list[Diagnostic]]


@dataclass(frozen=True)
class Exported:
    """What an export (or a board's build) wrote, and the lines the command prints about it, in order
    (plain text; the command escapes it for the terminal)."""

    files: tuple[Path, ...]
    lines: tuple[str, ...]
    warnings: tuple[str, ...] = ()
    #: The back-end's own result (a board's firmware, for ``flash``), for commands that need more.
    value: Any = None


@dataclass(frozen=True)
class Opened:
    """A live robot ready to run: the :class:`~tablebot.loop.RobotIO`, where it is and what it is (for the
    live view and the run's summary), and what the user should know before it moves (a link that keeps the
    table's tick only just: :mod:`tablebot.hw.link_speed`)."""

    robot: RobotIO
    where: str
    device: str
    warnings: tuple[str, ...] = ()


@dataclass(frozen=True)
class Backend:
    """One back-end.

    * ``name``: what the user types (``--to c``, ``--board uno``, ``check --target txt``); for a live one,
      the scheme of its address (``txt`` for ``txt://HOST``, ``sim`` for ``sim`` or ``sim:WORLD``).
    * ``kind``: ``export`` (writes files), ``board`` (builds firmware for a board) or ``live`` (a robot
      driven tick by tick through :func:`tablebot.loop.run`).
    * ``makes``: one line saying what it is; ``help``: its words in the command's option help.
    * ``fit``: what in a table it cannot hold (``[]`` when the table fits); ``None``: everything fits, and it
      is no ``check --target``.
    * ``section``, ``read_section``: the robot-file section it reads, and the reader
      ``(src, data, robot) -> value`` that checks it (errors go to ``src``). Back-ends may share a
      section (``[txt]``: the live TXT and the TXT 4.0 export): it is registered once.
    * ``export(machine, out, options) -> Exported`` for an export or a board;
      ``open(machine, address, options) -> Opened`` for a live back-end (``address``: all ``--on`` says,
      its scheme included; a mistake in it is a located error on ``--on``).
    * ``addresses``: a live back-end's address forms, for ``--on``'s help and hints.
    """

    name: str
    kind: Kind
    makes: str
    help: str = ""
    fit: FitCheck | None = None
    section: str | None = None
    read_section: SectionReader | None = None
    export: Callable[[Machine, Path | None, Options], Exported] | None = None
    open: Callable[[Machine, str, Options], Opened] | None = None
    addresses: tuple[str, ...] = field(default=())
    #: An export that writes nowhere without an ``OUTDIR`` (all but one that edits a file in place).
    needs_out: bool = True

    def problems(self, machine: Machine) -> list[Diagnostic]:
        """What in ``machine``'s table this back-end cannot hold."""
        return self.fit(machine) if self.fit else []


_BACKENDS: dict[str, Backend] = {}


def register(backend: Backend) -> Backend:
    """Add a back-end (and its robot-file section's reader); a name is registered once."""
    if backend.kind not in KINDS:
        raise ValueError(f"back-end {backend.name}: kind {backend.kind!r} is not one of {KINDS}")
    if (backend.export is None) == (backend.open is None):
        raise ValueError(f"back-end {backend.name}: give export (export, board) or open (live), not both")
    if (backend.open is not None) != (backend.kind == "live"):
        raise ValueError(f"back-end {backend.name}: only a live back-end opens a robot")
    known = _BACKENDS.get(backend.name)
    if known is not None and known != backend:
        raise ValueError(f"two back-ends are named {backend.name!r}")
    if backend.section is not None and backend.read_section is not None:
        register_section(backend.section, backend.read_section)
    _BACKENDS[backend.name] = backend
    return backend


def backends(kind: Kind | None = None) -> list[Backend]:
    """The registered back-ends (of one kind), in the order they were registered."""
    return [b for b in _BACKENDS.values() if kind is None or b.kind == kind]


def names(kind: Kind | None = None) -> list[str]:
    return [b.name for b in backends(kind)]


def get(name: str) -> Backend:
    return _BACKENDS[name]


def check_targets() -> list[str]:
    """The back-ends ``check --target`` knows: those with a fit check."""
    return [b.name for b in backends() if b.fit is not None]


def refused(action: Callable[[], object]) -> list[Diagnostic]:
    """The diagnostics of an exporter's own refusal (a fit check reuses the exporter's checks as they are)."""
    try:
        action()
    except TableBotError as exc:
        return list(exc.diagnostics)
    return []


def live_for(address: str) -> Backend | None:
    """The live back-end an ``--on`` address names by its scheme (``txt://HOST``: txt; ``sim`` or
    ``sim:WORLD``: sim), or None; the back-end's ``open`` reads the rest of the address."""
    backend = _BACKENDS.get(address.partition(":")[0])
    return backend if backend is not None and backend.kind == "live" else None
