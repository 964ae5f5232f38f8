"""``export --to scxml``: a robot's tables as a W3C SCXML statechart, under the tick model of :mod:`.chart`.

Expressions are the part of ECMAScript that is Python too (``==``, ``-``, ``&&``, ``||``, numbers, ``In('id')``,
``_event.data.I3``), so that an ECMAScript data model runs it and so does python-statemachine's restricted Python
one (tests/formats/test_scxml.py; its reader and evaluator: fgmacedo/python-statemachine,
statemachine/io/scxml/reader.py and statemachine/io/evaluators.py, which maps ``&&`` and ``||`` in conditions
but not in values, so every boolean is computed in a condition or as a comparison). What only tablebot reads
back (each row's description, its index as written, its group; what each data item is) is in attributes of
tablebot's namespace, which SCXML processors ignore.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from tablebot.formats.statecharts.chart import STARTED, TICK, WRAPPER, Chart, Part, chart_of, pulses
from tablebot.formats.statecharts.xmltree import Element, serialise
from tablebot.table import Row, Table

__all__ = ["export_scxml", "scxml_tree"]

COMMENT = (
    "written by tablebot (export, to scxml): send one event, tick, per tick with each input (0 or 1) and "
    "the pulses of each counter (C1_pulses) as its data; the timers live in the data model"
)


def export_scxml(tables: Sequence[Table]) -> str:
    """The SCXML document of a robot's tables (the main one first)."""
    return serialise(scxml_tree(chart_of(tables)), COMMENT)


def scxml_tree(chart: Chart) -> Element:
    main = chart.main
    robot = main.robot
    root = Element(
        "scxml",
        {
            "version": "1.0",
            "datamodel": "ecmascript",
            "name": identifier(robot.name),
            "initial": WRAPPER,
            "tb:name": robot.name,
            "tb:tick-ms": str(robot.tick_ms),
        },
    )
    _datamodel(root.add("datamodel"), chart)
    wrapper = root.add("parallel" if chart.several else "state", id=WRAPPER)
    if not chart.several:
        wrapper.attrs["initial"] = chart.parts[0].state(main.robot.initial_state)
    _tick(wrapper.add("transition", event=TICK), chart)
    for part in chart.parts:
        holder = (
            wrapper
            if not chart.several
            else wrapper.add("state", id=part.region, initial=part.state(part.table.robot.initial_state))
        )
        holder.attrs.update({"tb:events": " ".join(part.table.events), "tb:match": part.table.robot.match})
        if chart.several:
            holder.attrs["tb:writes"] = " ".join(part.table.writes)
        for state, rows in part.states_rows():
            node = holder.add("state", id=part.state(state))
            for row in rows:
                _row(node, part, row, chart)
            idle = node.add("transition", cond=part.pending)
            _assign(idle, part.row, "-1")
            _assign(idle, part.pending, "0")
    return root


def identifier(name: str) -> str:
    """The robot's name as the document's ``name``: letters, digits and ``_`` only (its exact text is in
    ``tb:name``). Some processors make code of it (SCION 4, @scion-scxml/scxml, names a JavaScript function after
    it, so "BumberBot with counters" was a syntax error there, and a crafted name would have been code)."""
    word = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return word if word[:1].isalpha() or word[:1] == "_" else f"_{word}"


def _datamodel(model: Element, chart: Chart) -> None:
    robot = chart.main.robot
    model.add("data", id=STARTED, expr="0")
    for name in chart.inputs:
        model.add("data", id=f"has_{name}", expr="0", tb_input=name)
    for name in robot.motors:
        model.add("data", id=name, expr="0", tb_kind="motor")
    for name in robot.lamps:
        model.add("data", id=name, expr="0", tb_kind="lamp")
    for counter in robot.counters:
        model.add("data", id=counter.name, expr="0", tb_kind="counter", tb_motor=counter.motor)
        model.add("data", id=f"has_{counter.name}", expr="0")
    for part in chart.parts:
        model.add("data", id=part.timer, expr=str(part.table.robot.initial_timer))
        model.add("data", id=f"{part.prefix}has_T", expr="0")
        model.add("data", id=part.pending, expr="0")
        model.add("data", id=part.row, expr="-1")


def _assign(parent: Element, location: str, expr: str) -> None:
    parent.add("assign", location=location, expr=expr)


def _tick(transition: Element, chart: Chart) -> None:
    """The first half of a tick: count down (not on the first tick), then the event flags, then ``pending``."""
    counting = transition.add("if", cond=STARTED)
    for part in chart.parts:
        _assign(counting.add("if", cond=f"{part.timer} > 0"), part.timer, f"{part.timer} - 1")
    for counter in chart.main.robot.counter_names:
        _assign(counting, counter, f"{counter} - _event.data.{pulses(counter)}")
        _assign(counting.add("if", cond=f"{counter} < 0"), counter, "0")
    _assign(transition, STARTED, "1")
    for name in chart.inputs:
        _assign(transition, f"has_{name}", f"_event.data.{name} == 1")
    for counter in chart.main.robot.counter_names:
        _assign(transition, f"has_{counter}", f"{counter} == 0")
    for part in chart.parts:
        _assign(transition, f"{part.prefix}has_T", f"{part.timer} == 0")
        _assign(transition, part.pending, "1")


def _present(part: Part, event: str, chart: Chart) -> str:
    """A condition that holds when ``event`` is present this tick."""
    flag = part.flag(event)
    if flag is not None:
        return flag
    _, _, ids = part.cross_states(event, chart.parts)
    return "(" + " || ".join(f"In('{ident}')" for ident in ids) + ")"


def guard(part: Part, row: Row, chart: Chart) -> str:
    """A row's condition: its table's ``pending`` and each event it requires (and some event, under the
    document's rule, for a row that requires none)."""
    table = part.table
    terms = [part.pending, *(_present(part, e, chart) for e in table.events if e in row.events)]
    if part.needs_some(row):
        terms.append("(" + (" || ".join(_present(part, e, chart) for e in table.events) or "false") + ")")
    return " && ".join(terms)


def _row(state: Element, part: Part, row: Row, chart: Chart) -> None:
    robot = part.table.robot
    transition = state.add(
        "transition",
        cond=guard(part, row, chart),
        target=part.state(row.next),
        tb_row=str(row.as_written),
        tb_description=row.description,
        tb_events=" ".join(e for e in part.table.events if e in row.events),
    )
    if row.group:  # one row as written for each state of a group: its group, and where in the table it runs
        transition.attrs.update({"tb:group": row.group, "tb:index": str(row.index)})
    outputs = [
        *zip(robot.motors, row.motors, strict=True),
        *zip(robot.lamps, row.lamps, strict=True),
        *zip(robot.counter_names, row.counters, strict=True),
    ]
    for name, value in outputs:
        if value is not None:
            _assign(transition, name, str(value))
    _assign(transition, part.timer, str(row.timer))
    _assign(transition, part.row, str(row.as_written))
    _assign(transition, part.pending, "0")
