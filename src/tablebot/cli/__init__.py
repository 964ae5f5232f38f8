"""Command-line interface: one module per group of commands, all registered on one Typer app."""

from tablebot.cli import analysis, core, export, firmware, run, sim, studio  # noqa: F401  (importing registers the commands)
from tablebot.cli.app import app


def main() -> None:
    app()
