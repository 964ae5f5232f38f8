"""Ctrl-C and SIGTERM outside the run loop: SIGTERM raised as :class:`Terminated`, which, like
KeyboardInterrupt, is no ``Exception``, so every clean-up on the way out runs; :func:`held` keeps both
signals out of the few lines that must not be cut (a set of files being swapped in); and neither is lost
when it lands in a weakref callback or a ``__del__``, where Python prints and drops any exception (see
:func:`_delivered_again`).

It also holds the test hook ``TABLEBOT_FAULT=N[:SIGNAL]``: at the N-th file step (a file written, a
file of a set renamed into place) the process sends itself SIGNAL (INT, TERM or KILL; default INT), so
a test can interrupt a command at every point of its writing, deterministically.
"""

from __future__ import annotations

import _thread
import functools
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

FAULT_ENV = "TABLEBOT_FAULT"
SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Terminated(BaseException):
    """SIGTERM arrived: the command ends as Ctrl-C would end it (exit code 143)."""


#: What ends a command early on the user's (or the system's) word.
INTERRUPTS = (KeyboardInterrupt, Terminated)


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def _raise_terminated(signum: int, frame: Any) -> None:
    raise Terminated("terminated by SIGTERM")


@contextmanager
def sigterm_raises() -> Iterator[None]:
    """One command: while it runs, SIGTERM raises :class:`Terminated` (Python's default would end the
    process at once: no temporary file removed, no terminal restored, nothing kept), and a Ctrl-C or SIGTERM
    Python dropped is delivered again (:func:`_delivered_again`); the fault hook counts its steps from the
    command's start."""
    _fault[:] = [None, 0]
    if not _main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    hook = sys.unraisablehook
    sys.unraisablehook = functools.partial(_delivered_again, hook)
    try:
        yield
    finally:
        sys.unraisablehook = hook
        signal.signal(signal.SIGTERM, previous if previous is not None else signal.SIG_DFL)


#: How long the helper thread waits before delivering a dropped signal again: the callback that dropped it
#: is over by then (delivered while it still ran, the signal would be dropped once more).
AGAIN_AFTER_S = 0.01


def _delivered_again(previous: Callable[[Any], object], unraisable: Any) -> None:
    """``sys.unraisablehook`` while a command runs. A signal's exception raised inside a weakref callback or a
    ``__del__`` (the main thread runs them wherever an object happens to be freed: in the middle of an
    import, say) cannot leave it: Python prints "Exception ignored" and goes on as if the user had never
    pressed Ctrl-C -- a tune interrupted that way ran to its end. Here such a KeyboardInterrupt or
    :class:`Terminated` is raised again in the main thread, by the same signal sent from a helper thread once
    the callback is over; any other exception goes to the hook there was (``previous``)."""
    kind = unraisable.exc_type
    if kind is not None and issubclass(kind, INTERRUPTS):
        signum = signal.SIGTERM if issubclass(kind, Terminated) else signal.SIGINT
        threading.Thread(target=_interrupt_main, args=(signum,), name="tablebot-signal-again", daemon=True).start()
        return
    previous(unraisable)


def _interrupt_main(signum: signal.Signals) -> None:
    time.sleep(AGAIN_AFTER_S)
    _thread.interrupt_main(signum)


@contextmanager
def held() -> Iterator[None]:
    """SIGINT and SIGTERM that arrive while the block runs wait until it is done, then act as they would
    have (in the main thread only: Python runs signal handlers nowhere else)."""
    if not _main_thread():
        yield
        return
    caught: list[int] = []
    previous = {sig: signal.signal(sig, lambda signum, frame: caught.append(signum)) for sig in SIGNALS}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler if handler is not None else signal.SIG_DFL)
        for signum in dict.fromkeys(caught):
            signal.raise_signal(signum)


# --- the test hook --------------------------------------------------------------------------------

_fault: list[Any] = [None, 0]  # the hook's setting as last read, and the steps counted under it


def fault_point() -> None:
    """One file step; with ``TABLEBOT_FAULT=N[:SIGNAL]`` set, the N-th sends SIGNAL to this process.
    The count starts again with each command and whenever the setting changes."""
    spec = os.environ.get(FAULT_ENV)
    if not spec:
        return
    if _fault[0] != spec:
        _fault[:] = [spec, 0]
    _fault[1] += 1
    at, _, name = spec.partition(":")
    if at.strip().isdigit() and _fault[1] == int(at):
        os.kill(os.getpid(), getattr(signal, f"SIG{(name or 'INT').upper()}"))
