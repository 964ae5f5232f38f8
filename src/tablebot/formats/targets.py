"""Export targets: each one's name, what it makes, and its fit check (what in a table it cannot hold).

``tablebot export --to`` and ``tablebot check --target`` both read this registry, so a table that
``check`` passes for a target is one its exporter accepts. Fit checks are imported only when used.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from tablebot.diagnostics import Diagnostic, TableBotError

if TYPE_CHECKING:
    from tablebot.machine import Machine


@dataclass(frozen=True)
class Target:
    name: str
    makes: str
    fit: str  # "module:function", a function (machine) -> list of Diagnostic; [] when the table fits

    def problems(self, machine: Machine) -> list[Diagnostic]:
        module, function = self.fit.split(":")
        check: Callable[[Machine], list[Diagnostic]] = getattr(importlib.import_module(module), function)
        return check(machine)


TARGETS: dict[str, Target] = {t.name: t for t in (
    Target("robopro", "the document's three ROBO Pro lists (event, action, timer)",
           "tablebot.formats.targets:robopro_fit"),
    Target("robopro-rpp", "the three lists written into a ROBO Pro program",
           "tablebot.formats.targets:robopro_fit"),
    Target("robopro-program", "a whole ROBO Pro program running the table (the document's engine)",
           "tablebot.robopro.fit:machine_problems"),
    Target("c", "a portable C99 engine and the table as const data", "tablebot.formats.targets:c_fit"),
    Target("uno", "AVR firmware for an Arduino Uno with the Motor Shield Rev3", "tablebot.formats.targets:uno_fit"),
    Target("ftduino", "AVR firmware for the ftDuino", "tablebot.formats.targets:ftduino_fit"),
    Target("txt", "a TXT (or TXT 4.0 with ftrobopy_server) driven live by `tablebot run`",
           "tablebot.formats.targets:txt_fit"),
    Target("txt4", "a program that runs the table on a TXT 4.0 by itself", "tablebot.formats.targets:txt_fit"),
)}


def refused(action: Callable[[], object]) -> list[Diagnostic]:
    """The diagnostics of an exporter's own refusal (a fit check reuses the exporter's checks as they are)."""
    try:
        action()
    except TableBotError as exc:
        return list(exc.diagnostics)
    return []


def robopro_fit(machine: Machine) -> list[Diagnostic]:
    from tablebot.robopro.lists import fit_problems

    return fit_problems(machine.table)


def c_fit(machine: Machine) -> list[Diagnostic]:
    from tablebot.codegen.layout import check_fits, plan

    return refused(lambda: check_fits(machine)) or refused(lambda: plan(machine))


def _board_fit(machine: Machine, board: str) -> list[Diagnostic]:
    from tablebot.firmware.boards import load_board, wire

    return c_fit(machine) or refused(lambda: wire(machine.table.robot, load_board(board)))


def uno_fit(machine: Machine) -> list[Diagnostic]:
    return _board_fit(machine, "uno")


def ftduino_fit(machine: Machine) -> list[Diagnostic]:
    return _board_fit(machine, "ftduino")


def txt_fit(machine: Machine) -> list[Diagnostic]:
    from tablebot.hw.txt_wiring import txt_wiring

    return refused(lambda: txt_wiring(machine))
