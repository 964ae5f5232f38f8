"""Command-line interface: one module per group of commands, all registered on one Typer app.

Internal to tablebot: its public API is ``tablebot`` and ``tablebot.api`` (docs/api.md, which also names the
modules stable enough to use beside them); anything here may change in any release.
"""

from __future__ import annotations

import atexit
import gc
import os
import sys
import traceback

# Typer draws help with rich when it can, and that costs a third of `tablebot --help` (rich's Markdown
# renderer is imported for it): plain help unless the user asks with TYPER_USE_RICH=1. Typer reads the
# variable once, when it is first imported, which is just below.
os.environ.setdefault("TYPER_USE_RICH", "0")

# The commands' modules are imported when a command runs or its help is asked for (tablebot.cli.index lists
# them, with the summaries `tablebot --help` shows), not here.
from tablebot.cli.app import app
from tablebot.diagnostics import Diagnostic
from tablebot.i18n import LANGUAGES, N_, LanguageError, set_from
from tablebot.interrupts import Terminated

#: Exit code of an internal error (a tablebot bug): sysexits' EX_SOFTWARE, apart from 1 (warnings), 2 (bad
#: input) and the run's own codes (tablebot.loop.EXIT_CODES: 3 is a lost link).
INTERNAL_ERROR = 70
DEBUG_ENV = "TABLEBOT_DEBUG"


def main() -> None:
    """Run the app; an exception no command expected is a tablebot bug: one line says so and how to see
    the whole traceback (TABLEBOT_DEBUG=1), never a traceback by default."""
    # A run builds large tables of small objects and then exits: at the default threshold (700) the
    # cyclic collector re-scans them thousands of times, half the time of checking a 100,000-row table.
    gc.set_threshold(100_000, 50, 100)
    # At exit the interpreter's last collections walk every object there is: after numba and LLVM have
    # loaded, 0.1-0.3 s of a sim's or sweep's exit, to free memory the process is about to give back whole.
    # gc.freeze as the last exit handler (registered first) takes them out of those walks; every file is
    # written and closed by then, and the other exit handlers and weakref finalizers still run.
    atexit.unregister(gc.freeze)  # once, however many times one process calls main (tests)
    atexit.register(gc.freeze)
    _choose_language()
    try:
        app()
    except (SystemExit, KeyboardInterrupt):
        raise
    except Terminated:  # SIGTERM outside a command's own handling (the commands end with 143 themselves)
        sys.exit(143)
    except BaseException as exc:
        if os.environ.get(DEBUG_ENV, "") not in ("", "0"):
            traceback.print_exc()
        else:
            where = traceback.extract_tb(exc.__traceback__)[-1] if exc.__traceback__ else None
            place = f" at {os.path.basename(where.filename)}:{where.lineno}" if where else ""
            print(
                f"tablebot: internal error: {type(exc).__name__}{place}: {str(exc)[:200]!r}; this is a bug in "
                f"tablebot: please report it with the command and the files it read "
                f"(run again with {DEBUG_ENV}=1 to see the traceback)",
                file=sys.stderr,
            )
        sys.exit(INTERNAL_ERROR)


def _choose_language() -> None:
    """Speak the language asked for (--lang, TABLEBOT_LANG, the system's) before typer builds any help; --lang
    is taken off the command line here, so that every command accepts it."""
    try:
        sys.argv[1:] = set_from(sys.argv[1:])
    except LanguageError as exc:
        from tablebot.cli.common import print_diagnostic

        print_diagnostic(
            Diagnostic(
                exc.where,
                None,
                None,
                N_("{value!r} is not a language tablebot speaks", value=exc.value),
                N_("use one of: {choices}", choices=", ".join(LANGUAGES)),
            )
        )
        sys.exit(2)
