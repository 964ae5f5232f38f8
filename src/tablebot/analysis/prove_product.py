"""Properties of a robot of several tables, proved over the product of its tables
(:class:`tablebot.analysis.product.ProductModel`) by the searches of :mod:`tablebot.analysis.prove`, and each
counterexample confirmed by replaying it on the robot's engine (:class:`tablebot.engine.several.Several`)."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any

from tablebot.analysis.conditions import Obs
from tablebot.analysis.model import ModelTooLarge
from tablebot.analysis.product import ProductModel
from tablebot.analysis.properties import Property
from tablebot.analysis.prove import EXACT_BUDGET, NEVER, NO_REPLAY, VIOLATION, Result, monitor_of, search, trapped
from tablebot.engine.several import Several
from tablebot.formats.inputs_csv import TickInput
from tablebot.i18n import N_
from tablebot.tables import RobotTables


def check_product_property(prop: Property, tables: RobotTables, budget: int = EXACT_BUDGET) -> Result:
    """Prove ``prop`` over every run of the robot's tables together, or find its shortest counterexample."""
    if prop.kind == "always_reachable":
        return _always_reachable(prop, tables, budget)
    reachable = prop.kind == "reachable"
    relevant = tables.influence(prop.tables)  # the tables that can change what the property sees
    try:
        model = ProductModel(tables, prop.horizon, prop.watch, relevant)
        path, explored = search(model, monitor_of(prop))  # type: ignore[arg-type]  # same interface as Model
    except ModelTooLarge as exc:
        return Result(
            prop,
            "unknown",
            detail=N_(
                "too large to search ({reason}); a condition that reads fewer "
                "inputs or a shorter within makes it smaller",
                reason=exc.args[0],
            ),
        )
    if path is None:
        return Result(prop, "violated" if reachable else "holds", explored, detail=NEVER if reachable else "")
    try:
        exact = model if model.is_exact else ProductModel.exact(tables, prop.watch, relevant)
        if exact is not model:
            path, _ = search(exact, monitor_of(prop), budget)  # type: ignore[arg-type]
        if path is None:  # the abstraction was too coarse about when a long timer runs out
            return Result(prop, "violated" if reachable else "holds", explored)
        model = exact
    except ModelTooLarge:
        pass
    inputs, _ = model.concretize(path)  # type: ignore[arg-type]
    shown = first_violation(prop, tables, inputs)
    if shown is None:
        return Result(prop, "unknown", explored, detail=NO_REPLAY)
    return Result(
        prop, "holds" if reachable else "violated", explored, inputs[: shown + 1], shown, exact=model.is_exact
    )


def _always_reachable(prop: Property, tables: RobotTables, budget: int) -> Result:
    relevant = tables.influence(prop.tables)
    model = ProductModel(tables, 1, prop.watch, relevant)
    graph = model.explore()
    path, _ = trapped(graph, prop.cond)
    if path is None:
        return Result(prop, "holds", len(graph.nodes))
    try:
        exact = ProductModel.exact(tables, prop.watch, relevant)
        path, _ = trapped(exact.explore(budget), prop.cond)
        model = exact
    except ModelTooLarge:
        pass
    inputs, _ = model.concretize(path or [])  # type: ignore[arg-type]
    states: tuple[int, ...] = path[-1][1][3][0] if path else model.initial()[0]  # type: ignore[assignment]
    state = ", ".join(f"{name} {m.states[s]}" for name, m, s in zip(tables.names, tables.machines, states, strict=True))
    return Result(
        prop,
        "violated",
        len(graph.nodes),
        inputs,
        len(inputs) - 1 if inputs else None,
        state=state,
        exact=model.is_exact,
        detail=N_("from {state} on, no inputs can ever make it happen again", state=state),
    )


def first_violation(prop: Property, tables: RobotTables, inputs: Sequence[TickInput]) -> int | None:
    """Run the property's monitor over the robot's engine fed ``inputs``: the tick where it is broken (or reached)."""
    monitor = monitor_of(prop)
    state: Any = monitor.start
    for tick, obs in enumerate(observe(tables, inputs)):
        state = monitor.step(state, obs)
        if state is VIOLATION:
            return tick
    return None


def observe(tables: RobotTables, inputs: Sequence[TickInput]) -> Iterator[Obs]:
    """Each tick of the robot's engine as conditions see it (the event word of :mod:`tablebot.analysis.product`)."""
    robot = Several(tables)
    width = len(tables.input_bits)
    main = tables.machines[0]
    for n, tick in enumerate(inputs):
        before = robot.counters
        robot.step(tick.mask, tick.pulses)
        counted = (
            before if n == 0 else [max(0, c - p) for c, p in zip(before, tick.pulses or [0] * len(before), strict=True)]
        )
        word = tick.mask | (1 << width if robot.engines[0].event & main.timer_bit else 0)
        word |= sum(1 << (width + 1 + c) for c, value in enumerate(counted) if value == 0)
        yield word, robot.engines[0].row, tuple(e.state for e in robot.engines), robot.outputs
