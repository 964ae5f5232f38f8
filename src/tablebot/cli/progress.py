"""What the commands show while the front door works (:class:`tablebot.api.Progress`): rich's bars on a
terminal's stderr, the first compile's notice, and notes; nothing on a pipe but the notes."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from tablebot.api.progress import Progress
from tablebot.cli.common import Stages, err_console
from tablebot.escape import plain
from tablebot.i18n import _, localise, number

if TYPE_CHECKING:
    from rich.progress import Progress as RichProgress
    from rich.progress import TaskID

    from tablebot.jit import Compiling


class TickBar(Progress):
    """``sim``'s: while a first run compiles the simulator, :class:`tablebot.jit.Compiling` talks (even when
    ``quiet``); once ticks run, a bar of them with the time left, on a terminal and unless ``quiet``."""

    def __init__(self, quiet: bool) -> None:
        from tablebot.talk import Talking

        self.quiet = quiet
        self.compile: Compiling | None = None
        self.bar: RichProgress | None = None
        self.task: TaskID | None = None
        # until the compile (or the run) starts: a first start compiles numba's and numpy's bytecode, seconds
        # with nothing to show (said only past 3 s)
        self.loading = Talking(
            _("loading the simulator"), _("a first start compiles numba's and numpy's bytecode"), delay_s=3.0
        )

    def compiling(self, what: str, *functions: Any) -> None:
        from tablebot.jit import Compiling

        self.loading.done(finished=False)
        self.compile = Compiling(what, *functions)  # talks until the first ticks have run (first run only)

    def start(self, what: str, total: int, done: int = 0, ticks: int | None = None) -> None:
        if self.quiet or not err_console.is_terminal:
            return
        from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

        columns = (
            TextColumn(_("simulating")),
            BarColumn(),
            TextColumn("{task.percentage:>3.0f}%"),
            TimeRemainingColumn(),
        )
        self.bar = Progress(*columns, console=err_console, transient=True)
        self.task = self.bar.add_task("sim", total=total, completed=done)
        if self.compile is None or not self.compile.active:
            self.bar.start()

    def advance(self, count: int) -> None:
        if self.compile is not None:
            self.compile.done()  # the first ticks ran: the compile (if any) is over
        if self.bar is not None and self.task is not None:
            if not self.bar.live.is_started:
                self.bar.start()
            self.bar.update(self.task, advance=count)

    def stop(self) -> None:
        self.loading.done(finished=False)
        if self.compile is not None:
            self.compile.done(finished=False)  # an error or Ctrl-C during the compile: the notice stops
        if self.bar is not None:
            self.bar.stop()


class CountBar(Progress):
    """``sweep``'s, ``tune``'s and ``evolve``'s: a bar of the items done out of all and the time left (on a
    terminal, unless ``quiet``); given the robot-ticks of one item, also the robot-ticks per second. A first
    run's compile is said in one line; notes go to stderr unless ``quiet``."""

    def __init__(self, quiet: bool) -> None:
        self.quiet = quiet
        self.shown = not quiet and err_console.is_terminal
        self.bar: RichProgress | None = None
        self.ticks: int | None = None
        self.new = 0
        self.started = time.perf_counter()

    def compiling(self, what: str, *functions: Any) -> None:
        from tablebot.jit import say_compiling

        say_compiling(what, *functions)

    def start(self, what: str, total: int, done: int = 0, ticks: int | None = None) -> None:
        self.ticks, self.new, self.started = ticks, 0, time.perf_counter()
        if not self.shown:
            return
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

        rate = [TextColumn("{task.fields[rate]}")] if ticks else []
        self.bar = Progress(
            TextColumn(str(localise(what))),
            BarColumn(),
            MofNCompleteColumn(),
            *rate,
            TimeRemainingColumn(),
            console=err_console,
            transient=True,
        )
        self.bar.start()
        self.task = self.bar.add_task(what, total=total, completed=done, rate="")

    def advance(self, count: int) -> None:
        self.new += count
        if self.bar is None:
            return
        rate = ""
        if self.ticks:
            per_s = self.new * self.ticks / max(time.perf_counter() - self.started, 1e-9)
            rate = _("{rate} M robot-ticks/s").format(rate=number(per_s / 1e6, ".2f"))
        self.bar.update(self.task, advance=count, rate=rate)

    def note(self, text: str) -> None:
        if not self.quiet:
            err_console.print(plain(str(localise(text))), markup=False)

    def stop(self) -> None:
        if self.bar is not None:
            self.bar.stop()
            self.bar = None


class StepBar(Progress):
    """``check``'s: the steps of :class:`tablebot.cli.common.Stages` (a bar shown only past a second)."""

    def __init__(self, stages: Stages) -> None:
        self.stages = stages

    def start(self, what: str, total: int, done: int = 0, ticks: int | None = None) -> None:
        self.stages.expect(total)

    def step(self, what: str) -> None:
        self.stages.step(what)
