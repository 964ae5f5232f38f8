"""A wrong option or argument answered as every other tablebot error: ``--from: error: 'nothing' is not
one of the choices`` with a hint naming them, not in the option parser's words (click's "'x' is not a valid
float range", "Invalid value for '--seconds'")."""

from __future__ import annotations

import difflib
import math
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
from typer.core import TyperGroup

from tablebot.cli.words import localise
from tablebot.diagnostics import Diagnostic


class Group(TyperGroup):
    """tablebot's command group: the commands' usage errors come out in tablebot's words, and their number
    options take finite numbers only."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        for command in self.commands.values():
            for param in command.params:
                if isinstance(param.type, FloatParamType):
                    param.type = FiniteFloat.like(param.type)
        localise(self)  # every help text in the reader's language, before any is shown

    def invoke(self, ctx: Any) -> Any:
        given = [*ctx._protected_args, *ctx.args]  # the command line, for the value a user gave
        try:
            return super().invoke(ctx)
        except NoArgsIsHelpError:
            raise
        except UsageError as exc:
            raise OptionError(explain(exc, given)) from None

    def resolve_command(self, ctx: Any, args: list[str]) -> Any:
        name = args[0] if args else ""
        if name and not name.startswith("-") and self.get_command(ctx, name) is None:
            near = difflib.get_close_matches(name, self.list_commands(ctx), n=2)
            hint = f"did you mean {' or '.join(near)}? " if near else ""
            raise OptionError(Diagnostic(name, None, None, f"{name!r} is not a tablebot command",
                                         f"{hint}tablebot -h lists the commands"))
        return super().resolve_command(ctx, args)


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
            self.fail(f"{number} is not a finite number", param, ctx)
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
    command = f"tablebot {exc.ctx.info_name} -h" if exc.ctx is not None and exc.ctx.info_name else "tablebot -h"
    if not isinstance(exc, BadParameter | NoSuchOption):  # an extra argument, say
        return Diagnostic("tablebot", None, None, exc.message.rstrip("."), f"{command} says how to call it")
    if isinstance(exc, NoSuchOption):
        near = f"did you mean {' or '.join(sorted(exc.possibilities))}? " if exc.possibilities else ""
        return Diagnostic(exc.option_name, None, None, f"{exc.option_name} is not an option of this command",
                          f"{near}{command} lists the options")
    param = exc.param
    name = _name(param)
    choices = _choices(param)
    if isinstance(exc, MissingParameter):
        hint = f"give {name} one of: {', '.join(choices)}" if choices else f"{command} says what {name} takes"
        return Diagnostic(name, None, None, f"{name} is missing", hint)
    value = _value(given, param)
    shown = repr(value) if value is not None else "the value given"
    if choices:
        return Diagnostic(name, None, None, f"{shown} is not one of the choices of {name}",
                          f"use one of: {', '.join(choices)}")
    number = _number_kind(param)
    if number and value is not None and not _parses(value, number):
        return Diagnostic(name, None, None, f"{shown} is not a number",
                          "give a whole number" if number is int else "give a number, such as 2 or 0.5")
    if number:
        assert param is not None  # a number kind comes only from a parameter's type
        low, high = getattr(param.type, "min", None), getattr(param.type, "max", None)
        limits = f"from {low} to {high}" if low is not None and high is not None else \
            f"of at least {low}" if low is not None else f"of at most {high}" if high is not None else "such as 0.5"
        finite = number is int or value is None or math.isfinite(float(value))
        wrong = "is out of range" if finite else "is not a finite number"
        return Diagnostic(name, None, None, f"{name} {value} {wrong}", f"give {name} a value {limits}")
    message = exc.message
    return Diagnostic(name, None, None, f"{shown}: {message}", f"{command} says what {name} takes")


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
                found = word[len(opt) + 1:]
    return found
