"""A Ctrl-C or SIGTERM that lands inside a weakref callback is not lost (tablebot.interrupts): Python cannot let a
callback's exception out, prints "Exception ignored" and goes on, so a command went on as if nobody had pressed
Ctrl-C (a tune, interrupted at the moment an import freed its module lock, ran to its end). While a command runs,
the interrupt is raised again in the main thread once the callback is over.

Real processes, real signals: the child's main thread is kept busy in Python inside a weakref callback when the
signal comes."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

pytestmark = [pytest.mark.kernel_free]

CHILD = textwrap.dedent(
    """
    import contextlib, os, signal, sys, threading, time, weakref
    from tablebot.interrupts import INTERRUPTS, sigterm_raises

    class Thing:
        pass

    inside = threading.Event()

    def callback(ref):  # what the main thread runs when the object is freed, wherever that happens
        inside.set()
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline:  # Python running inside the callback when the signal comes
            pass

    def send():
        inside.wait()
        time.sleep(0.2)
        os.kill(os.getpid(), getattr(signal, sys.argv[1]))

    thing = Thing()
    ref = weakref.ref(thing, callback)
    threading.Thread(target=send, daemon=True).start()
    context = sigterm_raises() if sys.argv[2] == "command" else contextlib.nullcontext()
    with context:
        try:
            del thing  # the callback runs here; the signal lands in it
            time.sleep(8)
            print("went on", flush=True)
        except INTERRUPTS as exc:
            print(f"stopped by {type(exc).__name__}", flush=True)
    """
)


def child(signal_name: str, where: str) -> subprocess.CompletedProcess[str]:
    done = subprocess.run([sys.executable, "-c", CHILD, signal_name, where], capture_output=True, text=True, timeout=60)
    return done


@pytest.mark.parametrize(("signal_name", "stopped_by"), [("SIGINT", "KeyboardInterrupt"), ("SIGTERM", "Terminated")])
def test_a_signal_dropped_in_a_callback_is_delivered_again_while_a_command_runs(
    signal_name: str, stopped_by: str
) -> None:
    done = child(signal_name, "command")
    assert done.stdout.strip() == f"stopped by {stopped_by}", done.stderr
    assert "Exception ignored" not in done.stderr  # nothing said of the dropped one: it was not dropped


def test_without_a_command_python_drops_it_as_ever() -> None:
    """The child's set-up does reproduce the drop: outside a command the Ctrl-C is printed and lost."""
    done = child("SIGINT", "bare")
    assert done.stdout.strip() == "went on"
    assert "Exception ignored" in done.stderr and "KeyboardInterrupt" in done.stderr


def test_any_other_exception_in_a_callback_goes_to_the_hook_there_was() -> None:
    from tablebot.interrupts import sigterm_raises

    seen: list[type[BaseException] | None] = []

    def mine(unraisable: object) -> None:
        seen.append(getattr(unraisable, "exc_type", None))

    class Broken:
        def __del__(self) -> None:
            raise ValueError("in __del__")

    previous, sys.unraisablehook = sys.unraisablehook, mine
    try:
        with sigterm_raises():
            Broken()
        assert seen == [ValueError]
        assert sys.unraisablehook is mine  # the command's own hook is gone with it
    finally:
        sys.unraisablehook = previous
