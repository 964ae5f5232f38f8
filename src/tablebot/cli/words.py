"""The command line's help in the reader's language: every command's and option's help, the argument names
(``TABLE`` is ``TABELLE`` in German), and typer's and click's own words ("Usage:", "Options", "[default: …]",
"Show this message and exit.").

Typer builds the click commands anew on every call of the app, from the English texts in the code (help=
and docstrings); :func:`localise` translates the built tree through the catalog, in the language in use, before
anything is shown. The catalog's template lists the same texts (:func:`help_texts`, read by scripts/catalog.py):
a command or option added with a help text is in the template when it is extracted again.

Typer's own words come two ways: those it passes through gettext (``typer.core``'s ``_``: the section titles,
"default", "required") are sent to tablebot's catalog; the ones typer's copy of click writes as they are
("Usage: ", "[OPTIONS]", the help option's text, the types' names such as ``<path>``) are replaced here.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import typer.core
from typer._click.core import Context
from typer._click.formatting import HelpFormatter

from tablebot.i18n import N_, gettext

#: The words typer's copy of click writes itself, marked for the catalog (they are translated in :func:`localise`).
CLICK_WORDS = (
    N_("Usage: "),
    N_("[OPTIONS]"),
    N_("COMMAND [ARGS]..."),
    N_("Show this message and exit."),
    N_("<path>"),
    N_("<text>"),
    N_("<integer>"),
    N_("<float>"),
    N_("<int range>"),
    N_("<float range>"),
    N_("<file>"),
    N_("<directory>"),
    N_("<boolean>"),
    N_("<filename>"),
    # typer.core's gettext calls (the section titles, the extras after an option's help)
    N_("Arguments"),
    N_("Options"),
    N_("Commands"),
    N_("default: {default}"),
    N_("required"),
    N_("(dynamic)"),
    N_("env var: {var}"),
    N_("Aborted!"),
    N_("Missing command."),
)
HELP_NAMES = ["-h", "--help"]
#: ``--lang``'s help, the main one's and every command's (the option is taken anywhere on the line).
LANG_HELP = (
    "The language of tablebot's messages: de (Deutsch) or en (English); default: TABLEBOT_LANG, else the "
    "system's language. It may stand anywhere on the line."
)


def _translate(text: str) -> str:
    """A text through the catalog (typer.core's gettext calls come here too)."""
    return gettext(text)


class LocalFormatter(HelpFormatter):
    """click's help formatter with its usage prefix in the reader's language."""

    def write_usage(self, prog: str, args: str = "", prefix: str | None = None) -> None:
        super().write_usage(prog, args, gettext("Usage: ") if prefix is None else prefix)


class LocalContext(Context):
    formatter_class = LocalFormatter


def localise(command: Any, commands: bool = True) -> None:
    """Translate a built click command into the language in use: a group with its commands, or without them
    (``commands=False``: tablebot's group translates each command as it builds it)."""
    # typer.core took the stdlib's gettext at import (`from gettext import gettext as _`): its few words are
    # sent to tablebot's catalog instead, whose language tablebot chooses (the stdlib's follows LANGUAGE).
    setattr(typer.core, "_", _translate)  # noqa: B010  (typer's module-level name, not an attribute of ours)
    for cmd in _commands(command) if commands else [command]:
        cmd.context_class = LocalContext
        if cmd.help:
            cmd.help = gettext(cmd.help)
        if cmd.short_help:
            cmd.short_help = gettext(cmd.short_help)
        if cmd.options_metavar:
            cmd.options_metavar = gettext(cmd.options_metavar)
        if getattr(cmd, "subcommand_metavar", None):
            cmd.subcommand_metavar = gettext(cmd.subcommand_metavar)
        localise_params(cmd, LocalContext(cmd, info_name=cmd.name, help_option_names=HELP_NAMES))


def localise_params(cmd: Any, ctx: Context) -> None:
    """Translate a command's options and arguments (and its help option), each once: typer adds some to a group
    after it is made (the completion options), so this runs again when they are asked for."""
    helper = cmd.get_help_option(ctx)
    for param in [*cmd.params, *([helper] if helper is not None else [])]:
        if not getattr(param, "_tablebot_localised", False):
            _param(param, ctx)
            param._tablebot_localised = True


def _param(param: Any, ctx: Context) -> None:
    if getattr(param, "help", None):
        param.help = gettext(param.help)
    if param.metavar:  # an argument's name (TABLE), or an option's value as the code names it (URL, FILE.png)
        param.metavar = gettext(param.metavar)
        return
    if param.param_type_name == "argument":
        return
    if (
        param.metavar is None
        and not getattr(param, "is_flag", False)
        and not getattr(param, "count", False)
        and param.type.get_metavar(param=param, ctx=ctx) is None
    ):
        name = param.type.name
        shown = name if name.startswith("<") else f"<{name}>"  # click's own form of a type's name
        param.metavar = gettext(shown)


def _commands(command: Any) -> Iterator[Any]:
    yield command
    for sub in getattr(command, "commands", {}).values():
        yield from _commands(sub)


def help_texts(command: Any) -> Iterator[str]:
    """Every text of a built command tree that :func:`localise` translates, in English (for the catalog)."""
    for cmd in _commands(command):
        yield from (t for t in (cmd.help, cmd.short_help) if t)
        for param in cmd.params:
            if getattr(param, "help", None):
                yield param.help
            if param.metavar:
                yield param.metavar
