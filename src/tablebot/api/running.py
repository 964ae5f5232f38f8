"""``run`` from Python: the table driving a live robot (a fischertechnik controller) or the simulator in real
time, through the run loop (:mod:`tablebot.loop`): outputs off on every way out, a trace as it goes."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.diagnostics import fail
from tablebot.i18n import N_

if TYPE_CHECKING:
    from tablebot.api.progress import Progress
    from tablebot.loading import Loaded, PathLike
    from tablebot.loop import RunEnd, Sink
    from tablebot.registry import LiveBackend, Opened
    from tablebot.tables import RobotTables


def address_hint() -> str:
    """Every address form of every live back-end: ``write --on txt://HOST:PORT, ..., sim or sim:WORLD.toml``."""
    from tablebot import registry

    forms = [form for backend in registry.lives() for form in backend.addresses]
    if len(forms) > 1:
        return N_("write --on {forms} or {last}", forms=tuple(forms[:-1]), last=forms[-1])
    return N_("write --on {form}", form="".join(forms))


def live_backend(text: str) -> LiveBackend:
    """The live back-end an address (``--on``) names; anything else is a located error."""
    from tablebot import registry

    backend = registry.live_for(text)
    if backend is None:
        raise fail("--on", N_("unknown target {text!r}", text=text), address_hint())
    return backend


@dataclass(frozen=True)
class LiveRun:
    """How a live run ended (:attr:`end`: its ``reason``, ``ticks``, ``exit_code``, late ticks) and the files
    its trace went to (``trace.jsonl`` and ``summary.json``, or ``trace.partial.jsonl`` for a planned run
    cut short).

    >>> import tablebot
    >>> done = tablebot.open("examples/bumberbot").run(on="sim", seconds=0.05)
    >>> done.end.reason, done.end.ticks
    ('done', 5)
    """

    end: RunEnd
    files: tuple[Path, ...] = ()


@dataclass(frozen=True)
class Connection:
    """A live robot opened for the project's table (:func:`connect`): :attr:`opened` says where it is and
    what it is (``where``, ``device``) and what to know before it moves (``warnings``); :meth:`run` drives it.

    >>> import tablebot
    >>> connection = tablebot.open("examples/bumberbot").connect("sim", seed=2)
    >>> connection.opened.device, connection.run(seconds=0.03).end.ticks
    ('simulated, seed 2', 3)
    """

    project: Loaded
    opened: Opened
    behind_limit: float
    #: A robot of several tables on a controller or the simulator: all of them, stepped together.
    tables: RobotTables | None = None

    def run(
        self,
        seconds: float | None = None,
        out: PathLike | None = None,
        sinks: Sequence[Sink] = (),
        progress: Progress | None = None,
    ) -> LiveRun:
        """Drive the robot for ``seconds`` (None: until Ctrl-C), paced by the wall clock, ``sinks`` seeing every
        tick (the command's live view); with ``out`` the trace and summary are written there as it goes. The
        robot's outputs are off on every way out."""
        from tablebot.engine import Engine
        from tablebot.engine.as_one import RobotEngine
        from tablebot.files import out_folder
        from tablebot.loop import RealTimeClock, run
        from tablebot.sinks.run_trace import RunTrace

        machine = self.project.machine
        tick_s = machine.table.robot.tick_s
        ticks = None if seconds is None else max(1, round(seconds / tick_s))
        trace = RunTrace(out_folder(Path(out), "--out")) if out is not None else None
        switch = sys.getswitchinterval()
        sys.setswitchinterval(0.001)  # a live view's thread hands the interpreter back within 1 ms, not 5
        try:
            engine = RobotEngine(self.tables) if self.tables is not None else Engine(machine)
            end = run(
                engine,
                self.opened.robot,
                clock=RealTimeClock(tick_s),
                sinks=[*sinks, *([trace] if trace is not None else [])],
                ticks=ticks,
                target=self.opened.where,
                behind_limit_s=self.behind_limit or None,
            )
        finally:
            sys.setswitchinterval(switch)
        return LiveRun(end, tuple(trace.files) if trace is not None else ())


def connect(
    project: Loaded, on: str, *, link_timeout: float | None = None, behind_limit: float = 0.5, seed: int = 1
) -> Connection:
    """Open the live robot ``on`` names (``txt://192.168.7.2``, ``robotx://auto``, ``roboif:///dev/ttyUSB0``,
    ``sim`` or ``sim:WORLD.toml``, ...) for the table: ``link_timeout`` seconds without a valid reply end a
    run as ``link_lost`` (default: 5 ticks); a run ends as ``behind`` when the table's time falls
    ``behind_limit`` seconds behind the wall clock within any 5 s (0: never); ``seed``: the simulator's."""
    from tablebot.engine.as_one import robot_machine
    from tablebot.registry import LinkOptions

    link = LinkOptions(on, link_timeout_s=link_timeout, behind_limit_s=behind_limit, seed=seed, hint=address_hint())
    backend = live_backend(on)
    tables = project.tables
    # a controller of a robot of several tables is wired for every input any table reads (the robot's layout)
    opened = backend.open(project.machine if tables is None else robot_machine(tables), link)
    return Connection(project, opened, behind_limit, tables)
