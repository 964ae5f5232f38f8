"""The ``tablebot`` command-line application object that every command module registers on, with the
options every invocation shares: ``--version``, ``-h``/``--help`` and shell completion."""

import typer

from tablebot.cli.usage import Group
from tablebot.cli.words import LANG_HELP


class AppGroup(Group):
    """tablebot's group, whose commands are those registered on :data:`app`."""

    def typer_app(self) -> typer.Typer:
        return app


app = typer.Typer(
    name="tablebot",
    cls=AppGroup,  # a wrong option is answered in tablebot's words, with the choices; commands built when used
    rich_markup_mode=None,  # errors through OptionError.show, and plain help, wherever typer finds rich
    help="Robot behaviour written as a table: check it, trace it, simulate it, export it.",
    no_args_is_help=True,
    add_completion=True,  # --install-completion / --show-completion for bash, zsh, fish, PowerShell
    pretty_exceptions_enable=False,
    context_settings={"help_option_names": ["-h", "--help"]},  # inherited by every command
)


def version() -> str:
    """The running code's version (``tablebot.__version__``, which the wheel's version is read from): an installed
    distribution's metadata can be older than a source tree on the path."""
    from tablebot import __version__

    return __version__


def _print_version(value: bool) -> None:
    if value:
        typer.echo(f"tablebot {version()}")
        raise typer.Exit()


@app.callback()
def main(
    show_version: bool = typer.Option(
        False, "--version", callback=_print_version, is_eager=True, help="Print tablebot's version and exit."
    ),
    lang: str = typer.Option("", "--lang", metavar="de|en", show_default=False, help=LANG_HELP),
) -> None:
    """Robot behaviour written as a table: check it, trace it, simulate it, export it."""
