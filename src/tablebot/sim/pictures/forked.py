"""Work done by a forked copy of this process on the machine's other core, its result handed back as bytes
(matplotlib holds the GIL, so a thread would not help, and a fork inherits what is already imported).

The copy starts at once and may get ready (imports, a warm-up) while this process goes on; what it needs
later (a run's arrays) is handed to it as messages, in order. It writes no file (the parent writes every
file, under the rules of :mod:`tablebot.fileset`), ends with ``os._exit`` (no clean-up of the parent's runs
twice), and dies with the parent, even when the parent is killed with SIGKILL (at once on Linux; elsewhere
within :data:`WATCH_S`); Ctrl-C and SIGTERM end it as they end any process. The parent kills and reaps it
on every way out, so no error path leaves a process behind.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import signal
import struct
import sys
import threading
import time
import traceback
import warnings
from collections.abc import Callable, Sequence
from types import TracebackType
from typing import Any

#: What the copy calls itself (``ps``, /proc/PID/comm): tests look for strays by this name.
NAME = b"tablebot-draw"
_SIGNALS = {signal.SIGINT, signal.SIGTERM}
_DONE, _FAILED = b"+", b"!"
_PIPE_BYTES = 1 << 20  # a message of a few MB passes in a few system calls (Linux's most for a user)
_LENGTHS = struct.Struct("<QQ")  # a message's frame: the pickle's length, how many raw buffers follow
#: Where the kernel cannot kill the copy with its parent (not Linux), how often the copy looks for it.
WATCH_S = 0.2


class Inbox:
    """The messages :meth:`Forked.send` hands the work, in order: :meth:`get` waits for the next one."""

    def __init__(self, pipe: int | None = None, messages: Sequence[object] = ()) -> None:
        self.pipe, self.messages = pipe, list(messages)

    def get(self) -> Any:
        if self.pipe is None:  # the work runs here: the messages were kept
            if not self.messages:
                raise RuntimeError("the work asked for a message that was never sent")
            return self.messages.pop(0)
        return _read_message(self.pipe)

    def waiting(self) -> bool:
        """Whether another message is already there (:meth:`get` would not wait)."""
        if self.pipe is None:
            return bool(self.messages)
        import select

        return bool(select.select([self.pipe], [], [], 0)[0])


class Forked:
    """``work(inbox)`` started in a forked copy of this process; :meth:`send` hands it messages, :meth:`result`
    waits for its bytes (or raises what it raised). Without ``fork`` or a second core, ``work`` runs in
    :meth:`result` instead, with the messages sent; a copy that died without an answer (killed by the
    system) is replaced the same way. Use it as a context manager: leaving the block without the result
    kills the copy."""

    def __init__(self, work: Callable[[Inbox], bytes]) -> None:
        self.work = work
        self.sent: list[object] = []
        self.pid: int | None = None
        self.answers = self.questions = -1
        if hasattr(os, "fork") and (os.cpu_count() or 1) > 1:
            with contextlib.suppress(OSError):  # no fork to be had (no memory, too many processes): done here
                self._start()

    def _start(self) -> None:
        pipes: list[int] = []
        try:
            answers, answer_end = _pipe(pipes)
            question_end, questions = _pipe(pipes)
            pid = self._fork(answers, answer_end, question_end, questions)
        except BaseException:
            for fd in pipes:
                os.close(fd)
            raise
        os.close(answer_end)
        os.close(question_end)
        self.pid, self.answers, self.questions = pid, answers, questions

    def _fork(self, answers: int, answer_end: int, question_end: int, questions: int) -> int:
        # signals wait until each side is set up: a Ctrl-C landing in the copy before it has its own
        # handlers would otherwise run the parent's clean-up (the staging folder's removal) in the copy
        blocked = signal.pthread_sigmask(signal.SIG_BLOCK, _SIGNALS)
        try:
            parent = os.getpid()
            with warnings.catch_warnings():  # Python 3.12 warns of fork in a threaded process: the copy
                warnings.simplefilter("ignore", DeprecationWarning)  # runs only its work and this module
                pid = os.fork()
            if pid == 0:
                os.close(answers)
                os.close(questions)
                _child(self.work, answer_end, question_end, parent, blocked)  # never returns
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
        return pid

    def send(self, message: object) -> None:
        """Hand ``message`` to the work (pickled; numpy arrays go as their raw bytes). It waits while the
        copy is busy and the pipe is full."""
        self.sent.append(message)
        if self.questions < 0:
            return
        try:
            _write_message(self.questions, message)
        except BrokenPipeError:  # the copy died: the work is done here, with the messages kept
            self._close_questions()

    def result(self) -> bytes:
        """The work's bytes, from the copy (or done here when there is none, or it died without answering)."""
        if self.pid is None:
            return self.work(Inbox(messages=self.sent))
        self._close_questions()
        with os.fdopen(self.answers, "rb") as stream:
            self.answers = -1
            answer = stream.read()
        self._reap()
        if answer[:1] == _DONE:
            return answer[1:]
        if answer[:1] == _FAILED:
            raise pickle.loads(answer[1:])
        return self.work(Inbox(messages=self.sent))

    def _close_questions(self) -> None:
        if self.questions >= 0:
            os.close(self.questions)
            self.questions = -1

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
        """Kill and reap the copy if it still runs, close the pipes."""
        self._close_questions()
        if self.answers >= 0:
            os.close(self.answers)
            self.answers = -1
        self._reap(kill=True)

    def __enter__(self) -> Forked:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        self.close()


def _pipe(opened: list[int]) -> tuple[int, int]:
    read, write = os.pipe()
    opened += [read, write]
    # a smaller pipe only costs more system calls (no F_SETPIPE_SZ: not Linux; no fcntl: not POSIX)
    with contextlib.suppress(OSError, AttributeError, ImportError):
        import fcntl

        fcntl.fcntl(write, fcntl.F_SETPIPE_SZ, _PIPE_BYTES)
    return read, write


def _child(
    work: Callable[[Inbox], bytes], answers: int, questions: int, parent: int, blocked: set[int | signal.Signals]
) -> None:
    """The copy: do the work, write the answer, end without any of the parent's clean-up."""
    code = 1
    try:
        for sig in _SIGNALS:
            signal.signal(sig, signal.SIG_DFL)
        _die_with(parent)
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)  # a signal that came meanwhile ends the copy now
        try:
            answer = _DONE + work(Inbox(questions))
            code = 0
        except EOFError:  # the parent stopped sending before the work had what it needed: it wants no answer
            os._exit(code)
        except BaseException as exc:  # handed to the parent, which raises it
            answer = _FAILED + _pickled(exc)
        with open(answers, "wb", closefd=True) as stream:
            stream.write(answer)
    finally:
        os._exit(code)


def _die_with(parent: int) -> None:
    """The copy ends when the parent dies, even by SIGKILL (else it would go on holding the parent's stdout:
    ``sim | tee`` would not end): on Linux the kernel kills it (and it is named NAME), elsewhere a thread
    of its own watches for the parent (:func:`watch_parent`)."""
    if not sys.platform.startswith("linux"):
        watch_parent(parent)
        return
    import ctypes

    libc = ctypes.CDLL(None, use_errno=True)
    pr_set_name, pr_set_pdeathsig = 15, 1
    libc.prctl(pr_set_name, ctypes.c_char_p(NAME), 0, 0, 0)
    libc.prctl(pr_set_pdeathsig, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:  # the parent died before the line above
        os._exit(1)


def watch_parent(parent: int, every_s: float = WATCH_S) -> None:
    """End this process (``os._exit``) once ``parent`` is no longer its parent: the parent died and another
    process (init, or a subreaper) took this one over. Every POSIX system has getppid; Linux has better
    (:func:`_die_with`)."""

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(every_s)
        os._exit(1)

    threading.Thread(target=watch, name="tablebot-parent-watch", daemon=True).start()


def _write_message(pipe: int, message: object) -> None:
    buffers: list[pickle.PickleBuffer] = []
    text = pickle.dumps(message, protocol=5, buffer_callback=buffers.append)
    raws = [buffer.raw() for buffer in buffers]  # large arrays: written from where they are, not copied first
    _write_all(pipe, _LENGTHS.pack(len(text), len(raws)) + struct.pack(f"<{len(raws)}Q", *map(len, raws)))
    pieces: tuple[bytes | memoryview, ...] = (text, *raws)
    for piece in pieces:
        _write_all(pipe, piece)


def _write_all(pipe: int, data: bytes | memoryview) -> None:
    view = memoryview(data).cast("B")
    while len(view):
        view = view[os.write(pipe, view) :]


def _read_message(pipe: int) -> Any:
    size, count = _LENGTHS.unpack(_read_exactly(pipe, _LENGTHS.size))
    sizes = struct.unpack(f"<{count}Q", _read_exactly(pipe, 8 * count))
    text = _read_exactly(pipe, size)
    return pickle.loads(text, buffers=[_read_exactly(pipe, n) for n in sizes])


def _read_exactly(pipe: int, size: int) -> bytearray:
    """``size`` bytes from the pipe; EOFError when it closes first."""
    data = bytearray(size)
    view, got = memoryview(data), 0
    while got < size:
        n = os.readv(pipe, [view[got:]])
        if n == 0:
            raise EOFError("the pipe closed mid-message")
        got += n
    return data


def _pickled(exc: BaseException) -> bytes:
    try:
        text = pickle.dumps(exc)
        pickle.loads(text)
        return text
    except Exception:  # an exception that does not survive pickling goes as its traceback
        return pickle.dumps(RuntimeError("".join(traceback.format_exception(exc))))
