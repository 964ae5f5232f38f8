"""What every command shares: loading a table, checking output paths, and turning errors into exit code 2."""

from __future__ import annotations

import functools
import inspect
import os
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import typer
from rich.console import Console

from tablebot import overwrite
from tablebot.diagnostics import HINT_LABEL, Diagnostic, TableBotError, notes_to, severity_word
from tablebot.escape import terminal
from tablebot.files import OS_HINTS, out_file, out_folder  # noqa: F401  (re-exported for the commands)
from tablebot.i18n import N_, _, localise
from tablebot.interrupts import Terminated, sigterm_raises

if TYPE_CHECKING:  # the table machinery is imported when a command loads a table: `--help` stays quick
    from tablebot.api.project import Project
    from tablebot.machine import Machine
    from tablebot.table import Table

F = TypeVar("F", bound=Callable[..., Any])
# emoji=False: a ':x:' in user text prints as it is (tablebot.escape.terminal escapes the markup).
# soft_wrap: rich never breaks a line itself (into a pipe it would at 80 columns, splitting URLs and paths).
err_console = Console(stderr=True, highlight=False, soft_wrap=True, emoji=False)
console = Console(highlight=False, soft_wrap=True, emoji=False)

TABLE_ARG = typer.Argument(..., metavar="TABLE", help="Table file (CSV or TSV) or a folder holding table.csv.")
ROBOT_OPT = typer.Option(None, "--robot", help="Robot TOML file (default: NAME.toml or robot.toml beside the table).")
FORCE_OPT = typer.Option(
    False,
    "--force",
    help="Replace an existing table or robot file (the old one is kept as "
    "NAME.bak); without it such a file is never replaced.",
)


def open_project(
    path: Path, robot_path: Path | None = None, worlds: list[Path] | None = None, properties: list[Path] | None = None
) -> Project:
    """The command's TABLE (a table, or a folder holding table.csv) with ``--robot``, ``--world`` and
    ``--properties`` as given (None: found as tablebot.api.open finds them)."""
    from tablebot.api import open as open_robot

    return open_robot(path, robot=robot_path, worlds=worlds or (), properties=properties)


def load(path: Path, robot_path: Path | None = None) -> tuple[Table, Machine]:
    """The table and its compiled machine (for the commands that only read a table)."""
    project = open_project(path, robot_path)
    return project.table, project.machine


class Stages:
    """A progress bar on a terminal's stderr for a command made of steps, shown only once it has taken
    longer than ``delay`` seconds (a quick run prints nothing extra); use as a context manager."""

    def __init__(self, total: int, delay: float = 1.0) -> None:
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

        self.progress = Progress(
            TextColumn("{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            console=err_console,
            transient=True,
        )
        self.task = self.progress.add_task(_("reading"), total=total)
        self.timer = threading.Timer(delay, self.progress.start)
        self.timer.daemon = True
        self.started = False

    def __enter__(self) -> Stages:
        if err_console.is_terminal:
            self.timer.start()
        return self

    def step(self, what: str) -> None:
        """The next step begins (the previous one is done)."""
        if self.started:
            self.progress.advance(self.task)
        self.started = True
        self.progress.update(self.task, description=terminal(str(localise(what))))

    def expect(self, total: int) -> None:
        """How many steps there are, once that is known (a check learns it after reading the properties)."""
        self.progress.update(self.task, total=total)

    def __exit__(self, *exc: object) -> None:
        self.timer.cancel()
        if self.progress.live.is_started:  # rich's stop prints an empty line off a terminal, shown or not
            self.progress.stop()


def print_diagnostic(d: Diagnostic) -> None:
    """Coloured on a terminal, plain text when piped (rich decides). The message and hint are one line
    each (a line break in a name is shown as \\n: it cannot forge a line of its own); a tool's output
    follows, each of its lines marked as part of this diagnostic."""
    colour = {"error": "red", "warning": "yellow"}.get(d.severity, "cyan")
    err_console.print(
        f"[bold]{terminal(d.location())}:[/bold] [{colour}]{severity_word(d.severity)}[/{colour}]: "
        f"{terminal(localise(d.message))}"
    )
    if d.hint:
        err_console.print(f"    [dim]{localise(HINT_LABEL)}:[/dim] {terminal(localise(d.hint))}")
    for line in d.detail.splitlines():
        err_console.print(f"    [dim]|[/dim] {terminal(line)}")


def _interrupted_import(exc: ImportError) -> None:
    """Ctrl-C or SIGTERM that landed while a compiled module was being imported comes back as an
    ImportError (pybind11's "initialization failed", caused by the interrupt): end as the interrupt would,
    at once: the half-made module cannot be finalized safely (it aborts the interpreter on the way out),
    and every clean-up of the command has already run on the way here."""
    cause: BaseException | None = exc
    while cause is not None and not isinstance(cause, KeyboardInterrupt | Terminated):
        cause = cause.__cause__ or cause.__context__
    if cause is None:
        return
    print(_("interrupted") if isinstance(cause, KeyboardInterrupt) else _("terminated"), file=sys.stderr)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(130 if isinstance(cause, KeyboardInterrupt) else 143)


def guarded(func: F) -> F:
    """Run a command so that user errors print as file:line:column messages and exit with 2."""

    offered = "force" in inspect.signature(func).parameters  # a guard's message suggests --force only then

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            with (
                sigterm_raises(),
                notes_to(print_diagnostic),
                overwrite.command(bool(kwargs.get("force", False)), offered),
            ):
                return func(*args, **kwargs)
        except TableBotError as exc:
            for d in exc.diagnostics:
                print_diagnostic(d)
            raise typer.Exit(2) from None
        except BrokenPipeError:  # the reader went away (`tablebot trace ... | head`): stop quietly, as Unix tools do
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no second error at exit
            raise typer.Exit(0) from None
        except OSError as exc:  # a file the command had to write (or read) is not there to be had
            where = exc.filename if exc.filename is not None else "tablebot"
            print_diagnostic(
                Diagnostic(
                    str(where),
                    None,
                    None,
                    N_("cannot write or read: {reason}", reason=exc.strerror or exc),
                    OS_HINTS.get(exc.errno or 0, N_("check the path")),
                )
            )
            raise typer.Exit(2) from None
        except KeyboardInterrupt:
            print(_("interrupted"), file=sys.stderr)
            raise typer.Exit(130) from None
        except Terminated:
            print(_("terminated"), file=sys.stderr)
            raise typer.Exit(143) from None
        except ImportError as exc:
            _interrupted_import(exc)
            raise

    return wrapper  # type: ignore[return-value]
