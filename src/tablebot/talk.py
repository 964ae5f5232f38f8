"""Saying that something slow is under way, all the while it is (a first start's imports, a first compile):
on a terminal one line redrawn with a spinner and the seconds so far, elsewhere (a pipe, a log) a line at the
start and one every few seconds. Standard library only: it talks before the heavy modules are imported."""

from __future__ import annotations

import sys
import threading
import time
from typing import Any

from tablebot.i18n import _, localise

SPINNER = "⠋⠙⠹⠸⠼⠴⠦⠧⠇⠏"


class Talking:
    """From construction until :meth:`done`: ``what`` (and ``why``), with the seconds so far; ``delay_s``
    first says nothing (a step that ends sooner needs no word). :meth:`done` stops it and, if it spoke and
    ``finished``, says ``done_text`` with the time taken (``{s}``)."""

    def __init__(
        self,
        what: str,
        why: str = "",
        done_text: str = "",
        *,
        every_s: float = 10.0,
        delay_s: float = 0.0,
        stream: Any = None,
    ) -> None:
        self.what, self.why, self.done_text, self.every_s = what, why, done_text, every_s
        self.stream = stream if stream is not None else sys.stderr
        self.live = bool(getattr(self.stream, "isatty", lambda: False)())
        self.started = time.monotonic()
        self.spoke = False
        self._stop = threading.Event()
        self._thread: threading.Thread | None = threading.Thread(
            target=self._talk, args=(delay_s,), name="talking", daemon=True
        )
        self._thread.start()

    def elapsed(self) -> float:
        return time.monotonic() - self.started

    def say(self, text: str, end: str = "\n") -> None:
        try:
            self.stream.write(text + end)
            self.stream.flush()
        except (OSError, ValueError):  # a closed or broken stream: nobody to tell
            pass

    def _talk(self, delay_s: float) -> None:
        if self._stop.wait(delay_s):
            return
        self.spoke = True
        what = localise(self.what)
        why = f" ({localise(self.why)})" if self.why else ""
        if not self.live:
            self.say(f"{what}{why}")
        turn = 0
        while not self._stop.wait(0.1 if self.live else self.every_s):
            if self.live:  # one line, redrawn in place (\r, then erase to its end)
                self.say(f"\r{SPINNER[turn % len(SPINNER)]} {what}: {self.elapsed():.0f} s{why}\x1b[K", end="")
                turn += 1
            else:
                self.say("  " + _("still {what}: {seconds:.0f} s").format(what=what, seconds=self.elapsed()))

    def done(self, finished: bool = True) -> None:
        """Stop talking (only the first call does anything)."""
        if self._thread is None:
            return
        self._stop.set()
        self._thread.join()
        self._thread = None
        if not self.spoke:
            return
        clear = "\r\x1b[K" if self.live else ""
        if finished and self.done_text:
            self.say(clear + str(localise(self.done_text)).format(s=f"{self.elapsed():.0f}"))
        elif clear:
            self.say(clear, end="")
