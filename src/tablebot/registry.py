"""The one registry of back-ends: every export target, board and live robot tablebot knows, with what it
needs of a robot file and what in a table it cannot hold.

A back-end is one module that builds an :class:`ExportBackend` (an export target or a board) or a
:class:`LiveBackend` (a robot driven tick by tick) and calls :func:`register` when imported;
:func:`tablebot.catalog.load_all` imports every such module, before the registry is first asked
(:func:`tablebot.plugins.load`). ``tablebot export --to``, ``build --board``,
``run --on`` and ``check --target`` take their choices from here, and a back-end's robot-file section is
read through the reader it registers (:func:`tablebot.robot.register_section`). What a command's options
say reaches a back-end by name, in :class:`ExportOptions` or :class:`LinkOptions`. See
docs/architecture.md, "Where to add".
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, TypeVar

from tablebot import plugins
from tablebot.diagnostics import Diagnostic, TableBotError
from tablebot.robot import SectionReader, register_section

if TYPE_CHECKING:
    from tablebot.loop import RobotIO
    from tablebot.machine import Machine

__all__ = [
    "KINDS",
    "Backend",
    "ExportBackend",
    "ExportOptions",
    "Exported",
    "LinkOptions",
    "LiveBackend",
    "Opened",
    "backends",
    "check_targets",
    "exporter",
    "exporters",
    "get",
    "live_for",
    "lives",
    "names",
    "put_in_order",
    "refused",
    "register",
]

Kind = Literal["export", "board", "live"]
KINDS: tuple[Kind, ...] = ("export", "board", "live")
Lookup = Literal["auto", "dense", "scan"]
FitCheck = Callable[["Machine"], list[Diagnostic]]
#: Ticks without a valid reply that end a live run as link_lost when ``--link-timeout`` is not given.
DEFAULT_TIMEOUT_TICKS = 5


@dataclass(frozen=True)
class ExportOptions:
    """What ``export --to`` (and ``build --board``) hands its back-end, each option by its name.

    * ``into``: ``--into``, the ROBO Pro program robopro-rpp writes its lists into.
    * ``lists``: ``--event-list``, ``--action-list``, ``--timer-list``: that program's lists' names (None: the
      document's own, :data:`tablebot.robopro.rpp_edit.DEFAULT_NAMES`).
    * ``lookup``: ``--lookup``, the C engine's first-match lookup.
    """

    into: Path | None = None
    lists: tuple[str, str, str] | None = None
    lookup: Lookup = "auto"


@dataclass(frozen=True)
class LinkOptions:
    """How ``run --on`` reaches a live robot, each option by its name.

    * ``address``: all ``--on`` says, its scheme included (``txt://192.168.7.2``, ``robotx://auto``, ``sim``);
      a mistake in it is a located error on ``--on``, with ``hint`` (every back-end's address forms).
    * ``link_timeout_s``: ``--link-timeout``, seconds without a valid reply that end the run as link_lost
      (None: :data:`DEFAULT_TIMEOUT_TICKS` ticks, :meth:`timeout_s`).
    * ``behind_limit_s``: ``--behind-limit``; 0 also accepts a link too slow for the table's tick.
    * ``seed``: ``--seed``, the simulator's noise.

    The wiring is no option: each back-end reads it from its section of the robot file.
    """

    address: str
    link_timeout_s: float | None = None
    behind_limit_s: float = 0.5
    seed: int = 1
    hint: str = ""

    def timeout_s(self, tick_s: float) -> float:
        """The link's timeout for a table ticking every ``tick_s`` seconds."""
        return self.link_timeout_s if self.link_timeout_s is not None else DEFAULT_TIMEOUT_TICKS * tick_s

    @property
    def accept_slow(self) -> bool:
        """``--behind-limit 0``: run on a link too slow for the tick, its timers running slow."""
        return self.behind_limit_s == 0

    def hint_or(self, own: str) -> str:
        """The hint for a mistake in the address: every back-end's forms, else the back-end's own."""
        return self.hint or own


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


Exporter = Callable[["Machine", Path | None, ExportOptions], Exported]
Opener = Callable[["Machine", LinkOptions], Opened]


@dataclass(frozen=True, kw_only=True)
class _Described:
    """What every back-end has.

    * ``name``: what the user types (``--to c``, ``--board uno``, ``check --target txt``); for a live one,
      the scheme of its address (``txt`` for ``txt://HOST``, ``sim`` for ``sim`` or ``sim:WORLD``).
    * ``makes``: one line saying what it is; ``help``: its words in the command's option help.
    * ``fit``: what in a table it cannot hold (``[]`` when the table fits); ``None``: everything fits, and it
      is no ``check --target``.
    * ``section``, ``read_section``: the robot-file section it reads, and the reader
      ``(src, data, robot) -> value`` that checks it (errors go to ``src``). Back-ends may share a
      section (``[txt]``: the live TXT and the TXT 4.0 export): it is registered once.
    """

    name: str
    makes: str
    help: str = ""
    fit: FitCheck | None = None
    section: str | None = None
    read_section: SectionReader | None = None

    @property
    def kind(self) -> Kind:
        raise NotImplementedError

    def problems(self, machine: Machine) -> list[Diagnostic]:
        """What in ``machine``'s table this back-end cannot hold."""
        return self.fit(machine) if self.fit else []


@dataclass(frozen=True, kw_only=True)
class ExportBackend(_Described):
    """An export target (writes files) or, with ``board``, a board firmware is built for:
    ``export(machine, out, options) -> Exported``; ``needs_out``: it writes nowhere without an ``OUTDIR``
    (all but one that edits a file in place)."""

    export: Exporter
    board: bool = False
    needs_out: bool = True

    @property
    def kind(self) -> Kind:
        return "board" if self.board else "export"


@dataclass(frozen=True, kw_only=True)
class LiveBackend(_Described):
    """A robot driven tick by tick through :func:`tablebot.loop.run`: ``open(machine, link) -> Opened``;
    ``addresses``: its address forms, for ``--on``'s help and hints."""

    open: Opener
    addresses: tuple[str, ...] = field(default=())

    @property
    def kind(self) -> Kind:
        return "live"


Backend = ExportBackend | LiveBackend
B = TypeVar("B", bound=ExportBackend | LiveBackend)

_BACKENDS: dict[str, Backend] = {}


def register(backend: B) -> B:
    """Add a back-end (and its robot-file section's reader); a name is registered once."""
    if not isinstance(backend, ExportBackend | LiveBackend):
        raise TypeError(f"back-end {getattr(backend, 'name', backend)!r}: an ExportBackend or a LiveBackend")
    known = _BACKENDS.get(backend.name)
    if known is not None and known != backend:
        raise ValueError(f"two back-ends are named {backend.name!r}")
    if backend.section is not None and backend.read_section is not None:
        register_section(backend.section, backend.read_section)
    _BACKENDS[backend.name] = backend
    return backend


def put_in_order(names: tuple[str, ...]) -> None:
    """List the back-ends ``names`` first, in that order, then any other in the order it registered: the
    order commands list them in, whichever back-end a robot file's section registered first
    (:func:`tablebot.catalog.load_all` calls this once every back-end has registered)."""
    first = [_BACKENDS[name] for name in names if name in _BACKENDS]
    rest = [backend for name, backend in _BACKENDS.items() if name not in names]
    _BACKENDS.clear()
    _BACKENDS.update((backend.name, backend) for backend in (*first, *rest))


def backends(kind: Kind | None = None) -> list[Backend]:
    """The registered back-ends (of one kind), in the order they were registered."""
    plugins.load()
    return [b for b in _BACKENDS.values() if kind is None or b.kind == kind]


def names(kind: Kind | None = None) -> list[str]:
    return [b.name for b in backends(kind)]


def get(name: str) -> Backend:
    plugins.load()
    return _BACKENDS[name]


def exporter(name: str) -> ExportBackend | None:
    """The export target or board of that name, or None."""
    plugins.load()
    backend = _BACKENDS.get(name)
    return backend if isinstance(backend, ExportBackend) else None


def exporters(kind: Literal["export", "board"] = "export") -> list[ExportBackend]:
    plugins.load()
    return [b for b in _BACKENDS.values() if isinstance(b, ExportBackend) and b.kind == kind]


def lives() -> list[LiveBackend]:
    plugins.load()
    return [b for b in _BACKENDS.values() if isinstance(b, LiveBackend)]


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


def live_for(address: str) -> LiveBackend | None:
    """The live back-end an ``--on`` address names by its scheme (``txt://HOST``: txt; ``sim`` or
    ``sim:WORLD``: sim), or None; the back-end's ``open`` reads the rest of the address."""
    plugins.load()
    backend = _BACKENDS.get(address.partition(":")[0])
    return backend if isinstance(backend, LiveBackend) else None
