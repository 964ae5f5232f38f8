"""What a long call of the front door tells as it goes, and how it ends when Ctrl-C cuts it short. The library
prints nothing: a caller that wants a progress bar or messages passes a :class:`Progress` of its own (the
commands pass theirs, which draw rich's bars on a terminal)."""

from __future__ import annotations

from typing import Any

from tablebot.i18n import N_


class Progress:
    """Told what a long call is doing; every method does nothing here. Subclass it and pass it as
    ``progress=`` to :meth:`~tablebot.api.project.Project.simulate`, ``sweep``, ``tune`` or ``evolve``.

    >>> class Dots(Progress):
    ...     def advance(self, count: int) -> None:
    ...         print("." * count, end="")
    """

    def compiling(self, what: str, *functions: Any) -> None:
        """Compiled code (``functions``, numba's) is about to be used: loaded from the cache at once, or, the
        first time, compiled for this machine, which takes a minute (:func:`tablebot.jit.compiled` tells)."""

    def start(self, what: str, total: int, done: int = 0, ticks: int | None = None) -> None:
        """Work on ``total`` items begins (``what``: ticks, robots, candidates, tables), ``done`` of them
        already done (a resumed sweep); ``ticks``: the robot-ticks of one item, when that means something."""

    def advance(self, count: int) -> None:
        """``count`` more items are done."""

    def step(self, what: str) -> None:
        """The next step of a call made of steps begins (``check``: exploring, findings, each property); the
        previous one is done."""

    def note(self, text: str) -> None:
        """A line the user should see (``evolve`` mending the start table, ``tune`` resuming), plain text."""

    def stop(self) -> None:
        """The work is over (done, failed or interrupted): always called once after :meth:`start`."""


class Stopped(KeyboardInterrupt):
    """Ctrl-C (or SIGTERM, inside a command) cut a long call short, after it kept what it had done: ``kept``
    says what and where, in one line of plain text; calling it again the same way resumes from there.
    ``terminated`` says SIGTERM did it, and ``exit_code`` is the command's (130 or 143).

    >>> stopped = Stopped("12 of 40 runs finished, kept in out/sweep/results.partial.csv")
    >>> isinstance(stopped, KeyboardInterrupt), stopped.word, stopped.exit_code
    (True, 'interrupted', 130)
    """

    def __init__(self, kept: str, terminated: bool = False) -> None:
        super().__init__(kept)
        self.kept, self.terminated = kept, terminated

    @property
    def exit_code(self) -> int:
        return 143 if self.terminated else 130

    @property
    def word(self) -> str:
        """``interrupted`` or ``terminated``."""
        return N_("terminated") if self.terminated else N_("interrupted")


def stopped(kept: str, why: BaseException) -> Stopped:
    """The :class:`Stopped` of an interrupt (``why``: KeyboardInterrupt, or tablebot.interrupts.Terminated)."""
    from tablebot.interrupts import Terminated

    return Stopped(kept, isinstance(why, Terminated))
