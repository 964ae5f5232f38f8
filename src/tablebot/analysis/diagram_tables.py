"""The diagram of a robot of several tables (:mod:`tablebot.tables`): one diagram per table, side by side in one
picture (a Graphviz cluster, a Mermaid concurrent region each), the cross-table events on their edges written as
the other table's states they need (``drive in {11,12}``) and explained in the legend."""

from __future__ import annotations

import graphviz

from tablebot.analysis.diagram import COLOURS, digraph, draw_table, drawn, event_label, mermaid_lines
from tablebot.escape import dot_id, dot_label, mermaid_label
from tablebot.tables import RobotTables


def render_tables(tables: RobotTables, fmt: str, colour: bool = True) -> bytes:
    """The diagram of every table of the robot as file contents in ``fmt`` (one of diagram.FORMATS)."""
    if fmt == "mermaid":
        return tables_mermaid(tables).encode()
    return drawn(tables_graphviz(tables, colour), fmt)


def tables_graphviz(tables: RobotTables, colour: bool = True) -> graphviz.Digraph:
    robot = tables.robot
    graph = digraph(f"{robot.name}: {len(tables.tables)} tables, run together on every tick")
    for k, table in enumerate(tables.tables):
        with graph.subgraph(name=f"cluster_{k}") as cluster:
            role = "main table" if k == 0 else "table"
            cluster.attr(label=f"<<b>{dot_label(f'{role} {table.name}')}</b> {dot_label(table.path)}>",
                         style="rounded", color="#999999", fontsize="12")
            draw_table(cluster, table, colour, prefix=f"{dot_id(table.name)}_")
    graph.node("__legend", _legend(tables, colour), shape="plain", fontsize="9")
    return graph


def _legend(tables: RobotTables, colour: bool) -> str:
    robot = tables.robot
    cells = ["<b>T</b> the table's own timer ran out"]
    names = [*tables.input_bits, *robot.motors, *robot.lamps]
    cells += [f"<b>{dot_label(name)}</b> {dot_label(robot.labels.get(name, ''))}" for name in names]
    for table in tables.tables:
        for event in table.cross.values():
            states = " or ".join(map(str, event.states))
            spans = " or ".join(f"{low} to {high}" for low, high in event.ranges)
            cells.append(f"<b>{dot_label(event_label(table, event.column))}</b> "
                         f"{dot_label(f'table {event.table} was in state {states or spans}')}"
                         f"{dot_label(f' or {spans}' if states and spans else '')} at the start of the tick")
    cells.append("times: timer loaded by the row")
    if colour:
        cells += [f'<font color="{c}">■ {m}</font>' for m, c in COLOURS.items()]
    body = "".join(f'<tr><td align="left">{c}</td></tr>' for c in cells)
    return f'<<table border="1" cellborder="0" cellspacing="1" color="#999999">{body}</table>>'


def tables_mermaid(tables: RobotTables) -> str:
    """A Mermaid ``stateDiagram-v2``: the robot as one composite state, each table a concurrent region."""
    robot = dot_id(f"robot_{tables.robot.name}")
    out = ["stateDiagram-v2", "    direction LR", f"    [*] --> {robot}",
           f'    state "{mermaid_label(tables.robot.name)}" as {robot}', f"    state {robot} {{"]
    for k, table in enumerate(tables.tables):
        if k:
            out.append("        --")
        out += mermaid_lines(table, prefix=f"{dot_id(table.name)}_", indent="        ")
    out.append("    }")
    return "\n".join(out) + "\n"
