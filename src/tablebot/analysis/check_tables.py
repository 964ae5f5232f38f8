"""``tablebot check`` of a robot of several tables (:mod:`tablebot.tables`): each table's findings, named by its
table and file lines as written (a table's cross-table events are free there, as inputs are), and the properties
proved over the tables together (:mod:`tablebot.analysis.prove_product`); the situations counted are those of
the product (:class:`tablebot.analysis.product.ProductModel`)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

from tablebot.analysis.lints import find_all
from tablebot.analysis.model import Model, ModelTooLarge
from tablebot.analysis.product import ProductModel
from tablebot.analysis.properties import Property
from tablebot.analysis.prove import Result
from tablebot.analysis.prove_product import check_product_property
from tablebot.diagnostics import fail
from tablebot.engine.several import Several
from tablebot.i18n import N_, Message
from tablebot.machine import NO_ROW
from tablebot.tables import RobotTables

if TYPE_CHECKING:
    from tablebot.analysis.check import CheckReport


def run_check_tables(
    tables: RobotTables,
    props: Sequence[Property],
    targets: tuple[str, ...] = (),
    step: Callable[[str], None] = lambda what: None,
) -> CheckReport:
    """Explore the product, find each table's findings, prove the properties over the product."""
    from tablebot.analysis.check import CheckReport

    main = tables.machines[0]
    try:
        step(N_("exploring the situations"))
        situations = len(ProductModel(tables).explore().nodes)
        step(N_("looking for findings"))
        findings = []
        for k, machine in enumerate(tables.machines):
            found = find_all(machine, Model(machine).explore(), targets)
            if k:  # the main table's findings read as a one-table robot's; the others' name their table
                table = machine.table
                found = [
                    replace(
                        f,
                        message=N_("table {name}: {message}", name=table.name, message=f.message),
                        table=table.name,
                        path=table.path,
                    )
                    for f in found
                ]
            findings += found
        results = []
        for prop in props:
            step(N_("property {name}", name=prop.name))
            results.append(check_product_property(prop, tables))
    except ModelTooLarge as exc:
        raise fail(
            main.table.path,
            N_("too large to explore: {reason}", reason=exc.args[0]),
            N_("split the tables, or give their states fewer inputs to look at"),
        ) from None
    return CheckReport(main, findings, results, situations, tables=tables)


def story_of_tables(tables: RobotTables, result: Result, limit: int = 12) -> list[str]:
    """What happens in a counterexample of several tables, tick by tick (a tick where nothing fires in any table
    and nothing is pressed is folded into the stretch around it)."""
    robot = Several(tables)
    items: list[str] = []
    quiet_from: int | None = None
    for n, tick in enumerate(result.inputs):
        robot.step(tick.mask, tick.pulses)
        pressed = [name for name, bit in tables.input_bits.items() if tick.mask & bit]
        fired = [(name, e) for name, e in zip(tables.names, robot.engines, strict=True) if e.row != NO_ROW]
        last = n == len(result.inputs) - 1
        if not fired and not pressed and not last:
            quiet_from = n if quiet_from is None else quiet_from
            continue
        if quiet_from is not None:
            items.append(_quiet(quiet_from, n - 1))
            quiet_from = None
        what = " + ".join(pressed) or N_("nothing pressed")
        lines = tuple(
            N_("{table} line {line}", table=name, line=e.machine.table.rows[e.row].line) for name, e in fired
        ) or N_("no row fires")
        states = " ".join(
            f"{name} {e.machine.states[e.state]}" for name, e in zip(tables.names, robot.engines, strict=True)
        )
        outputs = " ".join(f"{name} {value}" for name, value in zip(tables.output_names, robot.outputs, strict=True))
        step = N_(
            "tick {tick}: {what} -> {lines}: {states}, {outputs}",
            tick=n,
            what=what,
            lines=lines,
            states=states,
            outputs=outputs,
        )
        items.append(N_("{step}   <- it shows here", step=step) if last else step)
    if len(items) > limit:
        items = [items[0], N_("... ({n} more steps) ...", n=len(items) - limit + 1), *items[-(limit - 2) :]]
    return items


def _quiet(first: int, last: int) -> Message:
    if first == last:
        return N_("tick {first}: nothing pressed, nothing fires (timers count down)", first=first)
    return N_("ticks {first}-{last}: nothing pressed, nothing fires (timers count down)", first=first, last=last)
