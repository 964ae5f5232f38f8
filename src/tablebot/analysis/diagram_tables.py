"""The diagram of a robot of several tables (:mod:`tablebot.tables`): one diagram per table, side by side in one
picture (a Graphviz cluster, a Mermaid concurrent region each), the cross-table events on their edges written as
the other table's states they need (``drive in {11,12}``) and explained in the legend."""

from __future__ import annotations

import graphviz

from tablebot.analysis.diagram import digraph, draw_table, drawn, event_label, mermaid_lines, motion_legend
from tablebot.escape import dot_id, dot_label, mermaid_label
from tablebot.i18n import _
from tablebot.robot_tables import CrossEvent
from tablebot.tables import RobotTables


def render_tables(tables: RobotTables, fmt: str, colour: bool = True) -> bytes:
    """The diagram of every table of the robot as file contents in ``fmt`` (one of diagram.FORMATS)."""
    if fmt == "mermaid":
        return tables_mermaid(tables).encode()
    return drawn(tables_graphviz(tables, colour), fmt)


def tables_graphviz(tables: RobotTables, colour: bool = True) -> graphviz.Digraph:
    robot = tables.robot
    graph = digraph(
        _("{robot}: {count} tables, run together on every tick").format(robot=robot.name, count=len(tables.tables))
    )
    for k, table in enumerate(tables.tables):
        with graph.subgraph(name=f"cluster_{k}") as cluster:
            role = _("main table {name}") if k == 0 else _("table {name}")
            cluster.attr(
                label=f"<<b>{dot_label(role.format(name=table.name))}</b> {dot_label(table.path)}>",
                style="rounded",
                color="#999999",
                fontsize="12",
            )
            draw_table(cluster, table, colour, prefix=f"{dot_id(table.name)}_")
    graph.node("__legend", _legend(tables, colour), shape="plain", fontsize="9")
    return graph


def _legend(tables: RobotTables, colour: bool) -> str:
    robot = tables.robot
    own_timer = _("the table's own timer ran out")
    cells = [f"<b>T</b> {dot_label(own_timer)}"]
    names = [*tables.input_bits, *robot.motors, *robot.lamps]
    cells += [f"<b>{dot_label(name)}</b> {dot_label(robot.labels.get(name, ''))}" for name in names]
    for table in tables.tables:
        for event in table.cross.values():
            cells.append(f"<b>{dot_label(event_label(table, event.column))}</b> {dot_label(_cross_words(event))}")
    cells.append(dot_label(_("times: timer loaded by the row")))
    if colour:
        cells += motion_legend()
    body = "".join(f'<tr><td align="left">{c}</td></tr>' for c in cells)
    return f'<<table border="1" cellborder="0" cellspacing="1" color="#999999">{body}</table>>'


def _cross_words(event: CrossEvent) -> str:
    """What a cross-table event needs: ``table drive was in state 11 or 12 at the start of the tick``."""
    either = _(" or ")
    states = either.join(map(str, event.states))
    spans = either.join(_("{low} to {high}").format(low=low, high=high) for low, high in event.ranges)
    return _("table {table} was in state {states} at the start of the tick").format(
        table=event.table, states=either.join(part for part in (states, spans) if part)
    )


def tables_mermaid(tables: RobotTables) -> str:
    """A Mermaid ``stateDiagram-v2``: the robot as one composite state, each table a concurrent region."""
    robot = dot_id(f"robot_{tables.robot.name}")
    out = [
        "stateDiagram-v2",
        "    direction LR",
        f"    [*] --> {robot}",
        f'    state "{mermaid_label(tables.robot.name)}" as {robot}',
        f"    state {robot} {{",
    ]
    for k, table in enumerate(tables.tables):
        if k:
            out.append("        --")
        out += mermaid_lines(table, prefix=f"{dot_id(table.name)}_", indent="        ")
    out.append("    }")
    return "\n".join(out) + "\n"
