"""Ctrl-C and SIGTERM outside the run loop: SIGTERM raised as :class:`Terminated`, which, like
KeyboardInterrupt, is no ``Exception``, so every clean-up on the way out runs; :func:`held` keeps both
signals out of the few lines that must not be cut (a set of files being swapped in).

It also holds the test hook ``TABLEBOT_FAULT=N[:SIGNAL]``: at the N-th file step (a file written, a
file of a set renamed into place) the process sends itself SIGNAL (INT, TERM or KILL; default INT), so
a test can interrupt a command at every point of its writing, deterministically.
"""

from __future__ import annotations

import os
import signal
import threading
from collections.abc import Iterator
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
    process at once: no temporary file removed, no terminal restored, nothing kept); the fault hook
    counts its steps from the command's start."""
    _fault[:] = [None, 0]
    if not _main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous if previous is not None else signal.SIG_DFL)


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
