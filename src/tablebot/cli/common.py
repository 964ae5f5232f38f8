"""What every command shares: loading a table into a machine, and turning errors into exit code 2."""

from __future__ import annotations

import functools
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import typer
from rich.console import Console
from rich.markup import escape

from tablebot.diagnostics import Diagnostic, TableBotError
from tablebot.machine import Machine, compile_table
from tablebot.robot import load_robot
from tablebot.table import Table
from tablebot.tablefile import load_table

F = TypeVar("F", bound=Callable[..., Any])
err_console = Console(stderr=True, highlight=False)
console = Console(highlight=False, soft_wrap=True)

TABLE_ARG = typer.Argument(..., help="Table file (CSV or TSV) or a folder holding table.csv.")
ROBOT_OPT = typer.Option(None, "--robot", help="Robot TOML file (default: NAME.toml or robot.toml beside the table).")


def resolve_table_path(path: Path) -> Path:
    """A folder stands for the table.csv inside it, so ``tablebot trace examples/bumberbot`` works."""
    if path.is_dir():
        for name in ("table.csv", "table.tsv"):
            if (path / name).is_file():
                return path / name
    return path


def load(path: Path, robot_path: Path | None = None) -> tuple[Table, Machine]:
    robot = load_robot(robot_path) if robot_path else None
    table = load_table(resolve_table_path(path), robot)
    return table, compile_table(table)


def print_diagnostic(d: Diagnostic) -> None:
    """Coloured on a terminal, plain text when piped (rich decides)."""
    colour = {"error": "red", "warning": "yellow"}.get(d.severity, "cyan")
    err_console.print(f"[bold]{escape(d.location())}[/bold]: [{colour}]{d.severity}[/{colour}]: "
                      f"{escape(d.message)}", soft_wrap=True)
    if d.hint:
        err_console.print(f"    [dim]hint:[/dim] {escape(d.hint)}", soft_wrap=True)


def guarded(func: F) -> F:
    """Run a command so that user errors print as file:line:column messages and exit with 2."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return func(*args, **kwargs)
        except TableBotError as exc:
            for d in exc.diagnostics:
                print_diagnostic(d)
            raise typer.Exit(2) from None
        except OSError as exc:  # a file the command had to write (or read) is not there to be had
            where = exc.filename if exc.filename is not None else "tablebot"
            print_diagnostic(Diagnostic(str(where), None, None, exc.strerror or str(exc),
                                        "check the path: its folder must exist, be a folder, and be writable"))
            raise typer.Exit(2) from None
        except KeyboardInterrupt:
            print("interrupted", file=sys.stderr)
            raise typer.Exit(130) from None

    return wrapper  # type: ignore[return-value]
