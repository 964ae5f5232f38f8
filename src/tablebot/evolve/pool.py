"""Proving in worker processes: the proofs of a generation's children, the repairs and the written tables'
``check`` reports run on the machine's other cores while this process goes on (proofs are pure Python:
threads would wait for one another).

Workers only compute; every decision stays with the caller, which asks for the answers in the order the
search needs them, so a run with workers makes the same choices, counts and files as a run without.
Workers come from a fork server (a clean process: no fork of this one's threads), ignore Ctrl-C (this
process stops them) and are ended with the run; killed outright (SIGKILL), this process cannot end them, so
each ends itself when it sees this process gone. With one worker or none (``--workers 1``), every task
runs here, when its answer is asked for, so a task nobody asks for costs nothing.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import sys
import threading
from collections import deque
from collections.abc import Callable, Generator, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from tablebot.evolve.proofs import Prover, canonical
from tablebot.evolve.space import Candidate, to_table
from tablebot.machine import Machine, compile_table
from tablebot.table import Table

if TYPE_CHECKING:
    from tablebot.evolve.whole import Whole

#: Per property tried (by its place in the property list), whether it holds; then, when all of them
#: hold, whether a zero-time loop traps the robot (None: not looked at).
Statuses = tuple[dict[int, bool], bool | None]


class Answer(Protocol):
    def get(self) -> Any: ...

    def drop(self) -> None: ...


class Later:
    """A task run here, when its answer is first asked for (or never, when nobody asks)."""

    def __init__(self, fn: Callable[..., Any], args: tuple[Any, ...]) -> None:
        self.fn, self.args = fn, args
        self.done, self.value = False, None

    def get(self) -> Any:
        if not self.done:
            self.value, self.done = self.fn(*self.args), True
        return self.value

    def drop(self) -> None:
        pass


class Answered:
    """A worker's answer (a future), asked for with :meth:`get`; :meth:`drop` when it is not wanted."""

    def __init__(self, future: Any) -> None:
        self.future = future

    def get(self) -> Any:
        return self.future.result()

    def drop(self) -> None:
        self.future.cancel()  # not started yet: it never will be (a running one finishes unheard)


@dataclass(frozen=True)
class Context:
    """What every task needs: a prover of the run's property files (no cache: the run keeps that) and the
    starting table (candidates become tables of its robot and columns); of several tables, the prover knows the
    robot (:class:`tablebot.evolve.whole.Whole`)."""

    prover: Prover
    base: Table


class Workers:
    """``count`` worker processes (default: one per core) knowing the property files and the starting
    table; with a count of 1 none, and tasks run here. Use as a context manager: the workers end with it.

    They come from a fork server (spawned afresh on Windows), so, as for any ``multiprocessing`` program, the
    main module must be importable without side effects (``tablebot``, ``python -m tablebot`` and pytest are)."""

    def __init__(
        self, files: Sequence[Path], base: Table, count: int | None = None, whole: Whole | None = None
    ) -> None:
        self.count = max(1, count if count is not None else os.cpu_count() or 1)
        self.context = Context(Prover(list(files), whole=whole), base)
        self.pool: Any = None
        if self.count > 1:
            from concurrent.futures import ProcessPoolExecutor

            self.pool = ProcessPoolExecutor(
                self.count, _spawner(), initializer=_start, initargs=(list(files), base, whole)
            )

    def __enter__(self) -> Workers:
        return self

    def __exit__(self, kind: object, *rest: object) -> None:
        self.close()

    def close(self) -> None:
        """End the workers now: every answer the run needed is in, and anything still running was
        speculative (or the run was stopped)."""
        if self.pool is None:
            return
        pool, self.pool = self.pool, None
        stop = getattr(pool, "terminate_workers", None)  # Python 3.14
        if stop is not None:
            stop()
        else:
            for process in list(getattr(pool, "_processes", {}).values()):
                process.terminate()
        pool.shutdown(wait=True, cancel_futures=True)

    def window(self) -> int:
        """How many proofs to have under way: one per worker (past the last child a generation wants,
        each is wasted work)."""
        return self.count if self.pool is not None else 1

    def submit(self, fn: Callable[..., Any], *args: Any) -> Answer:
        """``fn(context, *args)`` in a worker (or here, when its answer is asked for); ``fn`` must be a
        function of this module."""
        if self.pool is None:
            return Later(fn, (self.context, *args))
        return Answered(self.pool.submit(_run, fn, args))


Ahead = tuple[Candidate | None, Machine | None, str, Answer | None]
_END = object()


def proved_ahead(
    workers: Workers, prover: Prover, children: Iterator[Candidate | None], window: Callable[[], int]
) -> Generator[Ahead, None, None]:
    """The children in order, each with its machine, its canonical key and, unless the prover knows that
    key already, the answer of its proof, started in a worker up to ``window()`` children ahead of the one
    handed out (None children: a variation that gave nothing, handed out as they come)."""
    queue: deque[Ahead] = deque()
    sent: dict[str, Answer] = {}
    try:
        yield from _ahead(workers, prover, children, window, queue, sent)
    finally:  # the caller has what it wanted: proofs not started are dropped
        for *_, answer in queue:
            if answer is not None:
                answer.drop()


def _ahead(
    workers: Workers,
    prover: Prover,
    children: Iterator[Candidate | None],
    window: Callable[[], int],
    queue: deque[Ahead],
    sent: dict[str, Answer],
) -> Iterator[Ahead]:
    while True:
        while len(queue) < window():
            child = next(children, _END)
            if child is _END:
                break
            if child is None:
                queue.append((None, None, "", None))
                continue
            machine = compile_table(to_table(child, workers.context.base))  # type: ignore[arg-type]
            key = canonical(machine)
            answer = None
            if key not in prover.verdicts:
                answer = sent.get(key) or workers.submit(statuses, child, prover.order(machine))
                sent[key] = answer
            queue.append((child, machine, key, answer))  # type: ignore[arg-type]
        if not queue:
            return
        yield queue.popleft()


def _spawner() -> Any:
    """A fork server where the system has one (POSIX): the modules the workers need are imported once, in
    it, not in each worker. Windows has none: each worker starts as a fresh Python (spawn) and imports them."""
    try:
        spawner = multiprocessing.get_context("forkserver")
    except ValueError:  # "cannot find context for 'forkserver'"
        return multiprocessing.get_context("spawn")
    spawner.set_forkserver_preload(preload())
    return spawner


def preload() -> list[str]:
    """What the fork server imports for its workers: the tasks' modules, and the main module's imports when
    a worker runs the main module again (a script by path, as the ``tablebot`` command is: its guard keeps
    it from running, but it imports the command line)."""
    main = sys.modules.get("__main__")
    script = getattr(main, "__spec__", None) is None and getattr(main, "__file__", None)
    return [__name__, "tablebot.evolve.repair", "tablebot.evolve.report", *(["tablebot.cli"] if script else [])]


# --- in a worker --------------------------------------------------------------------------------------

_context: Context | None = None


def _start(files: list[Path], base: Table, whole: Whole | None) -> None:
    global _context
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C reaches the whole process group: the run stops us
    _context = Context(Prover(files, whole=whole), base)
    _end_with_parent()


def _end_with_parent() -> None:
    """End this worker as soon as the process that started it is gone, however it went (SIGKILL leaves it no
    chance to end its workers): otherwise the worker waits forever for its next task, holding the run's stdout
    and stderr open (``evolve | tee`` never ends). The parent's sentinel (the end of a pipe only the parent
    writes to, or its process handle on Windows) becomes ready when the parent ends, on every platform."""
    parent = multiprocessing.parent_process()
    if parent is not None:
        threading.Thread(
            target=_exit_when_ready, args=(parent.sentinel,), name="tablebot-parent-watch", daemon=True
        ).start()


def _exit_when_ready(sentinel: int) -> None:
    from multiprocessing.connection import wait

    wait([sentinel])
    os._exit(1)  # at once: the worker holds nothing to save, and its answers have nobody to go to


def _run(fn: Callable[..., Any], args: tuple[Any, ...]) -> Any:
    assert _context is not None
    return fn(_context, *args)


# --- the tasks ----------------------------------------------------------------------------------------


def statuses(context: Context, candidate: Candidate, order: Sequence[int]) -> Statuses:
    """The candidate's properties in ``order`` (places in its property list) until one does not hold
    (``check``'s proof, as :meth:`Prover.prove` runs it); when all hold, whether a zero-time loop traps it."""
    machine = compile_table(to_table(candidate, context.base))
    props = context.prover.properties(machine)
    known: dict[int, bool] = {}
    for index in order:
        known[index] = context.prover.check(props[index], machine).status == "holds"
        if not known[index]:
            return known, None
    return known, context.prover.stuck(machine)


def repaired(context: Context, candidate: Candidate, space: Any, prefer: str) -> Any:
    """:func:`tablebot.evolve.repair.repair` of the candidate."""
    from tablebot.evolve.repair import repair

    return repair(candidate, context.base, context.prover, space, prefer)


def check_report(context: Context, table: Table, language: str = "en") -> tuple[str, bool]:
    """The table's ``check`` report as text in ``language`` (a worker process speaks the reader's language only
    when told), and whether every property holds in it."""
    from tablebot.evolve.report import check_text
    from tablebot.i18n import use

    use(language)
    report = context.prover.report(compile_table(table))
    return check_text(report, context.prover), all(r.status == "holds" for r in report.results)
