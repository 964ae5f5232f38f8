"""Work done by a forked copy of this process on the machine's other core, its result handed back as bytes
(the run's two pictures are drawn at once, one here and one there: matplotlib holds the GIL, so a thread
would not help, and a fork inherits the imported matplotlib and the run's arrays without copying them).

The copy does nothing but the work and the write of its result to a pipe: it writes no file (the parent
writes every file, under the rules of :mod:`tablebot.fileset`), ends with ``os._exit`` (no clean-up of the
parent's runs twice), dies on Ctrl-C or SIGTERM as any process does, and dies with the parent (Linux). The
parent kills and reaps it on every way out, so no error path leaves a process behind.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import signal
import sys
import traceback
import warnings
from collections.abc import Callable
from types import TracebackType

#: What the copy calls itself (``ps``, /proc/PID/comm): tests look for strays by this name.
NAME = b"tablebot-draw"
_SIGNALS = {signal.SIGINT, signal.SIGTERM}
_DONE, _FAILED = b"+", b"!"


class Forked:
    """``work()`` started in a forked copy of this process; :meth:`result` waits for its bytes (or raises
    what it raised). Without ``fork`` or a second core, ``work`` runs in :meth:`result` instead; a copy
    that died without an answer (killed by the system) is replaced the same way. Use it as a context
    manager: leaving the block without the result kills the copy."""

    def __init__(self, work: Callable[[], bytes]):
        self.work = work
        self.pid: int | None = None
        self.pipe = -1
        if hasattr(os, "fork") and (os.cpu_count() or 1) > 1:
            with contextlib.suppress(OSError):  # no fork to be had (no memory, too many processes): done here
                self._start()

    def _start(self) -> None:
        read, write = os.pipe()
        parent = os.getpid()
        try:
            pid = self._fork(read, write, parent)
        except BaseException:
            os.close(read)
            os.close(write)
            raise
        os.close(write)
        self.pid, self.pipe = pid, read

    def _fork(self, read: int, write: int, parent: int) -> int:
        # signals wait until each side is set up: a Ctrl-C landing in the copy before it has its own
        # handlers would otherwise run the parent's clean-up (the staging folder's removal) in the copy
        blocked = signal.pthread_sigmask(signal.SIG_BLOCK, _SIGNALS)
        try:
            with warnings.catch_warnings():  # Python 3.12 warns of fork in a threaded process: the copy
                warnings.simplefilter("ignore", DeprecationWarning)  # runs only matplotlib and this module
                pid = os.fork()
            if pid == 0:
                os.close(read)
                _child(self.work, write, parent, blocked)  # never returns
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
        return pid

    def result(self) -> bytes:
        """The work's bytes, from the copy (or done here when there is none, or it died without answering)."""
        if self.pid is None:
            return self.work()
        with os.fdopen(self.pipe, "rb") as stream:
            self.pipe = -1
            answer = stream.read()
        self._reap()
        if answer[:1] == _DONE:
            return answer[1:]
        if answer[:1] == _FAILED:
            raise pickle.loads(answer[1:])
        return self.work()

    def _reap(self, kill: bool = False) -> None:
        if self.pid is None:
            return
        if kill:
            with contextlib.suppress(ProcessLookupError):
                os.kill(self.pid, signal.SIGKILL)
        with contextlib.suppress(ChildProcessError):
            os.waitpid(self.pid, 0)
        self.pid = None

    def close(self) -> None:
        """Kill and reap the copy if it still runs, close the pipe."""
        if self.pipe >= 0:
            os.close(self.pipe)
            self.pipe = -1
        self._reap(kill=True)

    def __enter__(self) -> Forked:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        self.close()


def _child(work: Callable[[], bytes], pipe: int, parent: int, blocked: set[signal.Signals]) -> None:
    """The copy: do the work, write the answer, end without any of the parent's clean-up."""
    code = 1
    try:
        for sig in _SIGNALS:
            signal.signal(sig, signal.SIG_DFL)
        _die_with(parent)
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)  # a signal that came meanwhile ends the copy now
        try:
            answer = _DONE + work()
            code = 0
        except BaseException as exc:  # handed to the parent, which raises it
            answer = _FAILED + _pickled(exc)
        with open(pipe, "wb", closefd=True) as stream:
            stream.write(answer)
    finally:
        os._exit(code)


def _die_with(parent: int) -> None:
    """On Linux, the copy is killed when the parent dies (even by SIGKILL) and is named NAME."""
    if not sys.platform.startswith("linux"):
        return
    import ctypes

    libc = ctypes.CDLL(None, use_errno=True)
    pr_set_name, pr_set_pdeathsig = 15, 1
    libc.prctl(pr_set_name, ctypes.c_char_p(NAME), 0, 0, 0)
    libc.prctl(pr_set_pdeathsig, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:  # the parent died before the line above
        os._exit(1)


def _pickled(exc: BaseException) -> bytes:
    try:
        text = pickle.dumps(exc)
        pickle.loads(text)
        return text
    except Exception:  # an exception that does not survive pickling goes as its traceback
        return pickle.dumps(RuntimeError("".join(traceback.format_exception(exc))))
