"""A wrong option or argument answered as every other tablebot error: ``--from: error: 'nothing' is not
one of the choices`` with a hint naming them, not in the option parser's words (click's "'x' is not a valid
float range", "Invalid value for '--seconds'")."""

from __future__ import annotations

import difflib
import math
import re
from collections.abc import Sequence
from enum import Enum
from typing import IO, Any

from typer._click.exceptions import (
    BadParameter,
    ClickException,
    MissingParameter,
    NoArgsIsHelpError,
    NoSuchOption,
    UsageError,
)
from typer._click.types import FloatParamType, FloatRange, IntParamType
from typer._types import TyperChoice
from typer.core import TyperGroup, TyperOption
from typer.main import Typer, get_command_from_info

from tablebot.cli.index import BY_NAME, COMMANDS, Commands, load_module
from tablebot.cli.words import LANG_HELP, localise, localise_params
from tablebot.diagnostics import Diagnostic
from tablebot.i18n import LANGUAGES, N_, Message, as_typed, gettext, use
from tablebot.i18n import localise as l10n


class Group(TyperGroup):
    """tablebot's command group: the commands' usage errors come out in tablebot's words, and their number
    options take finite numbers only."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        # Each command is built when it is first looked up (tablebot.cli.index): `tablebot --help` and a
        # command's run import the command modules they need, not all of them.
        self.commands = Commands({name: _prepared(cmd) for name, cmd in self.commands.items()}, self._build)
        localise(self, commands=False)  # the group's help in the reader's language, before any is shown

    def typer_app(self) -> Typer:
        """The app whose commands this group builds (tablebot.cli.app's group says which)."""
        raise NotImplementedError

    def _build(self, name: str) -> Any:
        """Command ``name``'s click command: its module imported (which registers it on the app), then built as
        typer builds it, with tablebot's touches (:func:`_prepared`)."""
        app = self.typer_app()
        load_module(name)
        info = next(i for i in app.registered_commands if i.name == name)
        command = get_command_from_info(
            info, pretty_exceptions_short=app.pretty_exceptions_short, rich_markup_mode=app.rich_markup_mode
        )
        return _prepared(command)

    def list_commands(self, ctx: Any) -> list[str]:
        return list(self.commands)  # the names alone: typer's would build every command

    def format_commands(self, ctx: Any, formatter: Any) -> None:
        """The commands and their summaries from the index, in the reader's language: none is imported."""
        rows = [(entry.name, str(l10n(entry.summary))) for entry in COMMANDS]
        with formatter.section(gettext("Commands")):
            formatter.write_dl(rows)

    def get_params(self, ctx: Any) -> list[Any]:
        # typer adds the completion options after the group is made: translated when first asked for
        params: list[Any] = super().get_params(ctx)
        localise_params(self, ctx)
        return params

    def invoke(self, ctx: Any) -> Any:
        given = [*ctx._protected_args, *ctx.args]  # the command line, for the value a user gave
        try:
            return super().invoke(ctx)
        except NoArgsIsHelpError:
            raise
        except UsageError as exc:
            raise OptionError(explain(exc, given)) from None

    def parse_args(self, ctx: Any, args: list[str]) -> list[str]:
        given = list(args)
        try:
            return list(super().parse_args(ctx, args))
        except NoArgsIsHelpError:
            raise
        except UsageError as exc:  # tablebot's own options (--bogus before any command)
            raise OptionError(explain(exc, given)) from None

    def resolve_command(self, ctx: Any, args: list[str]) -> Any:
        name = args[0] if args else ""
        if name and not name.startswith("-") and self.get_command(ctx, name) is None:
            near = difflib.get_close_matches(name, self.list_commands(ctx), n=2)
            hint = (
                N_("did you mean {names}? tablebot -h lists the commands", names=_or(near))
                if near
                else N_("tablebot -h lists the commands")
            )
            raise OptionError(Diagnostic(name, None, None, N_("{name!r} is not a tablebot command", name=name), hint))
        return super().resolve_command(ctx, args)


def _prepared(command: Any) -> Any:
    """A command as tablebot shows and parses it: finite numbers only, ``--lang`` among its options, every help
    text in the reader's language, and the index's summary as its short help (shell completion shows it)."""
    for param in command.params:
        if isinstance(param.type, FloatParamType):
            param.type = FiniteFloat.like(param.type)
    if not any("--lang" in param.opts for param in command.params):
        command.params.append(lang_option())
    localise(command)
    if command.name in BY_NAME:
        command.short_help = str(l10n(BY_NAME[command.name].summary))
    return command


def lang_option() -> TyperOption:
    """``--lang`` on every command, in its help as in the main one: tablebot.cli.main takes it off the command
    line before typer sees it, so this one is met only when the app is called in-process (a test's CliRunner),
    where it sets the language of what follows."""
    return TyperOption(
        param_decls=["--lang"],
        type=TyperChoice(LANGUAGES),
        expose_value=False,
        metavar="de|en",
        default=None,
        callback=lambda ctx, param, value: use(value) if value else None,
        help=LANG_HELP,
    )


class FiniteFloat(FloatRange):
    """A float option's type that refuses nan and inf: click's range test lets nan through (every comparison
    with it is false), and no tablebot option means anything by it (``sim --battery nan`` wrote NaN, which is
    not JSON, into its trace; ``sweep --seconds nan`` ended in an internal error)."""

    @classmethod
    def like(cls, kind: FloatParamType) -> FiniteFloat:
        """The same range as ``kind`` (none when it is a plain float), finite."""
        if not isinstance(kind, FloatRange):
            return cls()
        return cls(kind.min, kind.max, kind.min_open, kind.max_open, kind.clamp)

    def convert(self, value: Any, param: Any, ctx: Any) -> Any:
        number = FloatParamType.convert(self, value, param, ctx)  # a number at all, before its range
        if not math.isfinite(number):
            self.fail(N_("{number} is not a finite number", number=number), param, ctx)
        return super().convert(number, param, ctx)


class OptionError(ClickException):
    """A usage error as a tablebot diagnostic (exit code 2, as a bad file)."""

    exit_code = 2

    def __init__(self, diagnostic: Diagnostic) -> None:
        super().__init__(diagnostic.message)
        self.diagnostic = diagnostic

    def show(self, file: IO[Any] | None = None) -> None:
        from tablebot.cli.common import print_diagnostic

        print_diagnostic(self.diagnostic)


def explain(exc: UsageError, given: Sequence[str]) -> Diagnostic:
    """What was wrong with the command line, and what to write instead."""
    sub = exc.ctx is not None and exc.ctx.parent is not None and exc.ctx.info_name
    command = f"tablebot {exc.ctx.info_name} -h" if sub and exc.ctx is not None else "tablebot -h"
    if not isinstance(exc, BadParameter | NoSuchOption):  # an extra argument, say
        return Diagnostic(
            "tablebot", None, None, _click_message(exc.message), N_("{command} says how to call it", command=command)
        )
    if isinstance(exc, NoSuchOption):
        lists = N_("{command} lists the options", command=command)
        hint = (
            N_("did you mean {names}? {then}", names=_or(sorted(exc.possibilities)), then=lists)
            if exc.possibilities
            else lists
        )
        return Diagnostic(
            exc.option_name, None, None, N_("{option} is not an option of this command", option=exc.option_name), hint
        )
    param = exc.param
    name = _name(param)
    choices = _choices(param)
    if isinstance(exc, MissingParameter):
        hint = (
            N_("give {name} one of: {choices}", name=name, choices=", ".join(choices))
            if choices
            else N_("{command} says what {name} takes", command=command, name=name)
        )
        return Diagnostic(name, None, None, N_("{name} is missing", name=name), hint)
    value = _value(given, param)
    shown = repr(value) if value is not None else N_("the value given")
    if choices:
        return Diagnostic(
            name,
            None,
            None,
            N_("{shown} is not one of the choices of {name}", shown=shown, name=name),
            N_("use one of: {choices}", choices=", ".join(choices)),
        )
    number = _number_kind(param)
    if number and value is not None and not _parses(value, number):
        return Diagnostic(
            name,
            None,
            None,
            N_("{shown} is not a number", shown=shown),
            N_("give a whole number") if number is int else N_("give a number, such as 2 or 0.5"),
        )
    if number:
        assert param is not None  # a number kind comes only from a parameter's type
        # the bounds as the command line takes them (0.01, not German 0,01): the user types them next
        bounds = (getattr(param.type, "min", None), getattr(param.type, "max", None))
        low, high = (None if b is None else as_typed(b) for b in bounds)
        hint = (
            N_("give {name} a value from {low} to {high}", name=name, low=low, high=high)
            if low is not None and high is not None
            else N_("give {name} a value of at least {low}", name=name, low=low)
            if low is not None
            else N_("give {name} a value of at most {high}", name=name, high=high)
            if high is not None
            else N_("give {name} a value such as 0.5", name=name)
        )
        finite = number is int or value is None or math.isfinite(float(value))
        wrong = (
            N_("{name} {value} is out of range", name=name, value=value)
            if finite
            else N_("{name} {value} is not a finite number", name=name, value=value)
        )
        return Diagnostic(name, None, None, wrong, hint)
    return Diagnostic(
        name,
        None,
        None,
        N_("{shown}: {problem}", shown=shown, problem=_click_message(exc.message)),
        N_("{command} says what {name} takes", command=command, name=name),
    )


def _or(names: Sequence[str]) -> str:
    """``a or b`` (``a, b or c``), in the reader's language."""
    if len(names) == 1:
        return names[0]
    return N_("{first} or {last}", first=", ".join(names[:-1]), last=names[-1])


#: click's own messages that reach a user (its copy in typer writes them in English), as tablebot's: a pattern
#: of click's text, and the message with the pattern's groups as its arguments.
CLICK_MESSAGES = (
    (
        re.compile(r"Got unexpected extra argument(?:s|\(s\))? \((?P<args>.*)\)$", re.S),
        lambda args: N_("unexpected extra argument(s): {args}", args=args),
    ),
    (
        re.compile(r"Option '(?P<option>[^']*)' requires (?:an argument|(?P<n>\d+) arguments)\.?$"),
        lambda option, n: N_("{option} needs a value", option=option),
    ),
    (
        re.compile(r"Option '(?P<option>[^']*)' does not take a value\.?$"),
        lambda option: N_("{option} takes no value", option=option),
    ),
    (
        re.compile(r"(?P<value>'.*') is not a valid (?P<kind>[a-z ]+)\.?$", re.S),
        lambda value, kind: N_("{value} is not a valid value", value=value),
    ),
)


def _click_message(text: Any) -> Any:
    """A message of click's own in tablebot's words (one of ours, FiniteFloat's, as it is); one not known here in
    click's English."""
    if isinstance(text, Message):
        return text
    for pattern, message in CLICK_MESSAGES:
        if found := pattern.match(str(text)):
            return message(**found.groupdict())
    return text


def _name(param: Any) -> str:
    """An option by its flag (``--from``), an argument by its metavar (``FOLDER``)."""
    if param is None:
        return "tablebot"
    if getattr(param, "param_type_name", "") == "argument":
        return param.metavar or (param.name or "").upper()
    return "/".join(param.opts) if param.opts else param.name or "tablebot"


def _choices(param: Any) -> list[str]:
    kind = getattr(param, "type", None)
    found = kind.choices if isinstance(kind, TyperChoice) else ()
    return [str(c.value) if isinstance(c, Enum) else str(c) for c in found]


def _number_kind(param: Any) -> type | None:
    """int or float for an option click parses as a number (a range is a subclass), else None."""
    kind = getattr(param, "type", None)
    return int if isinstance(kind, IntParamType) else float if isinstance(kind, FloatParamType) else None


def _parses(text: str, kind: type) -> bool:
    try:
        kind(text)
    except ValueError:
        return False
    return True


def _value(given: Sequence[str], param: Any) -> str | None:
    """The text the user wrote for ``param`` (its last use), if it was an option given on the line."""
    found = None
    opts = tuple(getattr(param, "opts", ()) or ())
    for k, word in enumerate(given):
        for opt in opts:
            if word == opt and k + 1 < len(given):
                found = given[k + 1]
            elif word.startswith(opt + "="):
                found = word[len(opt) + 1 :]
    return found
