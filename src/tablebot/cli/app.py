"""The ``tablebot`` command-line application object that every command module registers on."""

import typer

app = typer.Typer(
    name="tablebot",
    help="Robot behaviour written as a table: check it, trace it, simulate it, export it.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
