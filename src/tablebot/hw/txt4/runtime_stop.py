"""How the TXT 4.0 program stops (:mod:`tablebot.hw.txt4.runtime`'s :func:`run` and ``main``): a stop request
from any thread, and a guard that ends the run with its outputs off however the program is ended (SIGTERM in
the main thread or in a worker's, the interpreter exiting). Standard library only, as the runtime: ``tablebot
export --to txt4`` writes this module's code into the program after the runtime's (see :func:`runtime_text`
in :mod:`tablebot.hw.txt4.export`), so the controller gets one file.
"""

from __future__ import annotations

import atexit
import contextlib
import os
import signal
import threading
from collections.abc import Callable
from typing import Any

HANDOVER_S = 1.0  # how long a SIGTERM handled in the main thread waits for the run's thread to stop


class Terminated(Exception):
    """SIGTERM (ROBO Pro Coding's stop, or ``DELETE /api/v1/stop``) arrived."""


class Stop:
    """A request to end the run, from any thread: a signal handler, ``atexit``, a caller."""

    def __init__(self) -> None:
        self.requested = threading.Event()
        self.done = threading.Event()  # set once the run has stopped the outputs and said so
        self.reason = ""

    def request(self, reason: str) -> None:
        self.reason = self.reason or reason
        self.requested.set()


class Guard:
    """Ends the run with its outputs off however the program is ended: SIGTERM to the process (in the
    main thread, or in the runner's thread when the program runs in a worker thread, as harbaum/SofTXT's
    run.py runs it), the interpreter exiting (``atexit``), and -- in :func:`run` -- Ctrl-C, the end of the
    thread and any exception."""

    def __init__(self, stop: Stop) -> None:
        self.stop = stop
        self.robot: Any = None  # set once it is built: a stop before then has nothing to switch off
        self.previous: Any = signal.SIG_DFL

    def install(self) -> str:
        """Take SIGTERM over (after ``fischertechnik.factories`` installed its own on import); returns a
        sentence saying how SIGTERM is handled."""
        if threading.current_thread() is threading.main_thread():
            self.previous = signal.signal(signal.SIGTERM, self.in_run_thread)
            return "tablebot: SIGTERM stops the outputs"
        # Only the main thread may set a signal handler: ask it to, at its next Python step.
        if _in_main_thread(self._install_for_worker):
            return "tablebot: running in a worker thread; the main thread hands SIGTERM over"
        return "tablebot: warning: running in a worker thread and SIGTERM cannot be caught here"

    def attach(self, robot: Any) -> None:
        """The robot to stop; its exit hook runs before the package's own (registered when the controller
        was made: atexit runs the last registered first)."""
        self.robot = robot
        atexit.register(self.at_exit)

    def in_run_thread(self, signum: int, frame: Any) -> None:
        if not self.stop.requested.is_set():  # a second SIGTERM while stopping must not cut the stop short
            self.stop.request("terminated")
            raise Terminated()

    def _install_for_worker(self) -> None:
        self.previous = signal.signal(signal.SIGTERM, self.for_worker)

    def for_worker(self, signum: int, frame: Any) -> None:
        """In the main thread while the run is in another: stop it, wait for its outputs-off, then end
        as SIGTERM would have ended the process without us."""
        self.stop.request("terminated")
        if not self.stop.done.wait(HANDOVER_S) and self.robot is not None:
            self.robot.stop()
        previous, self.previous = self.previous, signal.SIG_DFL
        signal.signal(signum, previous)
        if previous == signal.SIG_DFL:
            os.kill(os.getpid(), signum)
        elif callable(previous):
            previous(signum, frame)

    def at_exit(self) -> None:
        if not self.stop.done.is_set():
            self.stop.request("exit")
            if not self.stop.done.wait(HANDOVER_S) and self.robot is not None:
                self.robot.stop()


_PENDING: list = []  # ctypes callbacks must outlive the call


def _in_main_thread(func: Callable[[], None]) -> bool:
    """Have the main thread call ``func`` at its next Python step (CPython's ``Py_AddPendingCall``,
    which runs pending calls in the main thread only)."""
    try:
        import ctypes

        callback_type = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p)

        def call(_: Any) -> int:
            with contextlib.suppress(Exception):
                func()
            return 0

        callback = callback_type(call)
        _PENDING.append(callback)
        add = ctypes.pythonapi.Py_AddPendingCall
        add.argtypes, add.restype = [callback_type, ctypes.c_void_p], ctypes.c_int
        return add(callback, None) == 0
    except (ImportError, AttributeError, OSError):
        return False
