"""The document's Figure 1 drawn from the table: states as nodes, rows as labelled edges (rows
between the same two states merged), coloured by the motion they start; Graphviz (drawn by the program
graphviz_run finds: no system package needed) or Mermaid."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import graphviz

from tablebot.analysis.graphviz_run import INSTALL, GraphvizFailed, NoGraphviz, draw
from tablebot.colours import state_colours
from tablebot.diagnostics import fail
from tablebot.escape import dot_id, dot_label, mermaid_label
from tablebot.i18n import N_, _, localise, number
from tablebot.robot import StateId
from tablebot.table import TIMER_EVENT, Row, Table

FORMATS = ("svg", "png", "dot", "mermaid")
PNG_DPI = 150  # Graphviz's default 72 dpi draws 9-point labels a few pixels high
COLOURS = {"forward": "#2e7d32", "reverse": "#c62828", "turn": "#1565c0", "stop": "#222222", "keep": "#888888"}
#: The legend's word for each colour (the keys above are class names, never shown).
MOTIONS = {
    "forward": N_("forward"),
    "reverse": N_("reverse"),
    "turn": N_("turn"),
    "stop": N_("stop"),
    "keep": N_("keep"),
}


def motion_legend() -> list[str]:
    """The legend's cells for the edge colours, in the reader's language."""
    return [f'<font color="{c}">■ {dot_label(localise(MOTIONS[m]))}</font>' for m, c in COLOURS.items()]


@dataclass(frozen=True)
class Action:
    """What a group of merged rows does: a motion word, its colour class, and the timer load."""

    text: str
    motion: str
    timer: str


@dataclass(frozen=True)
class Edge:
    source: StateId
    target: StateId
    lines: tuple[tuple[str, Action], ...]  # (condition, action) per distinct action, in row order


def edges(table: Table) -> list[Edge]:
    """One edge per (state, next) pair; rows with the same action are merged into one condition."""
    groups: dict[tuple[StateId, StateId], list[Row]] = {}
    first: dict[StateId, int] = {}
    for row in table.rows:
        groups.setdefault((row.state, row.next), []).append(row)
        first.setdefault(row.state, row.index)
    result = []
    for (source, target), rows in groups.items():
        by_action: dict[Action, list[frozenset[str]]] = {}
        fallback: dict[Action, bool] = {}
        for row in rows:
            act = action(table, row)
            by_action.setdefault(act, []).append(row.events)
            fallback[act] = fallback.get(act, False) or (not row.events and row.index > first[row.state])
        lines = tuple((condition(table, sets, fallback[act]), act) for act, sets in by_action.items())
        result.append(Edge(source, target, lines))
    return result


def condition(table: Table, event_sets: Sequence[frozenset[str]], otherwise: bool = False) -> str:
    """``I3 or I4`` for rows {I3,I4}, {I3}, {I4}: a set that contains another adds nothing. A row that
    needs no event reads "always" when it is its state's first row, and "otherwise" (``otherwise``) when
    earlier rows of its state are tried first."""
    minimal = [s for s in event_sets if not any(o < s for o in event_sets)]
    unique = list(dict.fromkeys(minimal))
    empty = _("otherwise") if otherwise else _("always")
    parts = ["+".join(event_label(table, e) for e in table.events if e in s) or empty for s in unique]
    return _(" or ").join(parts)


def event_label(table: Table, event: str) -> str:
    """An event as diagrams write it: a cross-table event (``drive=11,12``) as ``drive in {11,12}`` (``drive in
    20..29`` for a range): the other table's states it needs at the start of the tick."""
    cross = table.cross.get(event)
    if cross is None:
        return event
    states = ",".join([*map(str, cross.states), *(f"{low}..{high}" for low, high in cross.ranges)])
    return (
        _("{table} in {{{states}}}").format(table=cross.table, states=states)
        if cross.states or len(cross.ranges) > 1
        else _("{table} in {states}").format(table=cross.table, states=states)
    )


def action(table: Table, row: Row) -> Action:
    text, motion = motion_of(table, row.motors)
    extras = [f"{n}={v}" for n, v in zip(table.robot.lamps, row.lamps, strict=True) if v is not None]
    extras += [f"{n}:={v}" for n, v in zip(table.robot.counter_names, row.counters, strict=True) if v is not None]
    if extras and table.name and not set(table.robot.motors) & set(table.writes):
        text = " ".join(extras)  # one table of several that drives no motor: its lamps and counters are its action
    elif extras:
        text = f"{text} {' '.join(extras)}"
    return Action(text, motion, duration(table, row.timer))


def duration(table: Table, ticks: int) -> str:
    if ticks == 0:
        return ""
    ms = ticks * table.robot.tick_ms
    return f"{number(ms / 1000)} s" if ms >= 1000 else f"{ms} ms"  # 1,5 s in German


def motion_of(table: Table, motors: tuple[int | None, ...]) -> tuple[str, str]:
    """A word for what the motors do, and its colour class (forward, reverse, turn, stop, keep)."""
    if not motors or all(m is None for m in motors):
        return _("keep"), "keep"
    if any(m is None for m in motors):
        return " ".join(
            f"{n} {'=' if m is None else f'{m:+d}'}" for n, m in zip(table.robot.motors, motors, strict=True)
        ), "turn"
    speeds = tuple(m for m in motors if m is not None)  # all of them: none is None past the test above
    if all(m == 0 for m in speeds):
        return _("stop"), "stop"
    sides = _sides(table)
    if len(speeds) != 2 or sides is None:
        text = " ".join(f"{n} {m:+d}" for n, m in zip(table.robot.motors, speeds, strict=True))
        return text, "forward" if all(m > 0 for m in speeds) else "reverse" if all(m < 0 for m in speeds) else "turn"
    left, right = speeds[sides[0]], speeds[sides[1]]
    if left == right:
        return (
            (_("forward {speed}").format(speed=left), "forward")
            if left > 0
            else (_("reverse {speed}").format(speed=-left), "reverse")
        )
    # The heading turns toward the slower side going forward (signed: right > left turns left).
    wheels = f"L{left} R{right}"
    if left * right < 0:
        words = _("spin left {wheels}") if right > left else _("spin right {wheels}")
        return words.format(wheels=wheels), "turn"
    if left < 0 or right < 0:
        words = _("back, turn left {wheels}") if right > left else _("back, turn right {wheels}")
        return words.format(wheels=wheels), "reverse"
    if left * right == 0:
        words = _("pivot left {wheels}") if right > left else _("pivot right {wheels}")
    else:
        words = _("curve left {wheels}") if right > left else _("curve right {wheels}")
    return words.format(wheels=wheels), "turn"


def _sides(table: Table) -> tuple[int, int] | None:
    """Indices of the left and right motor, from their labels ("left motor", "right motor")."""
    labels = [table.robot.labels.get(m, m).lower() for m in table.robot.motors]
    if len(labels) != 2:
        return None
    left = [i for i, lab in enumerate(labels) if "left" in lab]
    right = [i for i, lab in enumerate(labels) if "right" in lab]
    return (left[0], right[0]) if len(left) == len(right) == 1 and left != right else None


# --- Graphviz ---------------------------------------------------------------------------------------


def to_graphviz(table: Table, colour: bool = True) -> graphviz.Digraph:
    # Every user text goes into HTML-like labels (<…>): the only Graphviz strings without escapes of their own.
    graph = digraph(f"{table.robot.name}: {table.path}")
    draw_table(graph, table, colour)
    graph.node("__legend", _legend(table, colour), shape="plain", fontsize="9")
    return graph


def digraph(title: str) -> graphviz.Digraph:
    """An empty diagram titled ``title``, with the house style for its nodes and edges."""
    graph = graphviz.Digraph(
        "tablebot",
        graph_attr={
            "rankdir": "TB",
            "fontname": "Helvetica",
            "fontsize": "11",
            "nodesep": "0.35",
            "ranksep": "0.9",
            "labelloc": "t",
            "label": f"<{dot_label(title)}>",
            "pad": "0.2",
        },
    )
    graph.attr(
        "node",
        shape="box",
        style="rounded,filled",
        fillcolor="#f4f4f4",
        fontname="Helvetica",
        fontsize="12",
        color="#555555",
    )
    graph.attr("edge", fontname="Helvetica", fontsize="9", arrowsize="0.7")
    return graph


def draw_table(graph: graphviz.Digraph, table: Table, colour: bool, prefix: str = "") -> None:
    """The table's states, start and edges into ``graph`` (a whole diagram, or one table's cluster of a robot of
    several tables, whose ids then start with ``prefix``)."""
    robot = table.robot
    ids = {state: prefix + mid for state, mid in state_ids(table.states).items()}
    start = f"{prefix}__start"
    graph.node(start, "", shape="circle", style="filled", fillcolor="black", width="0.18")
    colours = state_colours(table.states)  # each state's colour in the pictures of a run
    for state, state_colour in zip(table.states, colours, strict=True):
        label = table.state_name(state)
        title = f"<<b>{dot_label(str(state))}</b>" + (f"<br/>{dot_label(label)}>" if label else ">")
        initial = state == robot.initial_state
        graph.node(
            ids[state],
            title,
            penwidth="3" if initial else "2",
            color=state_colour,
            fillcolor="#fff7d6" if initial else "#f4f4f4",
        )
    graph.edge(
        start,
        ids[robot.initial_state],
        label="< " + dot_label(_("start, timer {timer}").format(timer=robot.initial_timer)) + ">",
    )
    for edge in edges(table):
        first = edge.lines[0][1].motion
        same = all(a.motion == first for _, a in edge.lines)
        graph.edge(
            ids[edge.source],
            ids[edge.target],
            label=_html_label(edge, colour),
            color=COLOURS[first] if colour and same else "#666666",
            penwidth="1.6" if colour and same else "1.0",
        )


def state_ids(states: Sequence[StateId]) -> dict[StateId, str]:
    """Diagram ids (``s_20``, ``s_seek``): ASCII letters, digits and ``_`` (:func:`escape.dot_id`), which
    Graphviz and Mermaid both take as they are; states whose names differ only in characters an id
    cannot hold (``a.b``, ``a-b``) get a number to stay apart."""
    ids: dict[StateId, str] = {}
    for state in states:
        base = dot_id(f"s_{state}")
        mid, count = base, 1
        while mid in ids.values():
            count += 1
            mid = f"{base}_{count}"
        ids[state] = mid
    return ids


def _html_label(edge: Edge, colour: bool) -> str:
    timers = {act.timer for _, act in edge.lines}
    shared = len(edge.lines) > 1 and len(timers) == 1  # say a common timer once, not on every line
    rows = []
    for cond, act in edge.lines:
        timer = f" · {act.timer}" if act.timer and not shared else ""
        text = f"<b>{dot_label(cond)}</b> → {dot_label(act.text)}{dot_label(timer)}"
        if colour:
            text = f'<font color="{COLOURS[act.motion]}">{text}</font>'
        rows.append(text)
    if shared and next(iter(timers)):
        rows.append(dot_label(_("timer {time}").format(time=next(iter(timers)))))
    return "<" + "<br/>".join(rows) + ">"


def _legend(table: Table, colour: bool) -> str:
    robot = table.robot
    cells = [
        f"<b>{dot_label(name)}</b> {dot_label(robot.labels.get(name, ''))}"
        for name in (*table.events, *robot.motors)
        if name != TIMER_EVENT
    ]
    ran_out = _("timer ran out")  # outside the f-string: Babel does not look inside one
    cells.insert(0, f"<b>T</b> {dot_label(ran_out)}")
    cells.append(dot_label(_("times: timer loaded by the row")))
    cells.append(dot_label(_("state border: its colour in the run's pictures")))
    if colour:
        cells += motion_legend()
    body = "".join(f'<tr><td align="left">{c}</td></tr>' for c in cells)
    return f'<<table border="1" cellborder="0" cellspacing="1" color="#999999">{body}</table>>'


def render(table: Table, fmt: str, colour: bool = True) -> bytes:
    """The diagram as file contents in ``fmt`` (one of FORMATS); a robot of several tables:
    :func:`tablebot.analysis.diagram_tables.render_tables`."""
    if fmt == "mermaid":
        return to_mermaid(table).encode()
    return drawn(to_graphviz(table, colour), fmt)


def drawn(graph: graphviz.Digraph, fmt: str) -> bytes:
    """A Graphviz diagram as file contents in ``fmt`` (dot, svg or png)."""
    if fmt == "dot":
        return graph.source.encode()
    if fmt == "png":
        graph.attr(dpi=str(PNG_DPI))
    try:
        return draw(graph.source, fmt)
    except NoGraphviz as exc:
        raise fail(
            "graphviz", exc.args[0], N_("{install}; or use --format dot or --format mermaid", install=INSTALL)
        ) from None
    except GraphvizFailed as exc:
        raise fail("graphviz", exc.args[0], N_("report this with the table attached")) from None


# --- Mermaid ----------------------------------------------------------------------------------------


def to_mermaid(table: Table) -> str:
    """A Mermaid ``stateDiagram-v2`` (renders on GitHub and in many Markdown viewers)."""
    return "\n".join(["stateDiagram-v2", "    direction LR", *mermaid_lines(table)]) + "\n"


def mermaid_lines(table: Table, prefix: str = "", indent: str = "    ") -> list[str]:
    """The table's states and edges as Mermaid lines (ids starting with ``prefix``, for one table of several)."""
    ids = {state: prefix + mid for state, mid in state_ids(table.states).items()}
    out = [f"{indent}[*] --> {ids[table.robot.initial_state]}"]
    for state in table.states:
        label = table.state_name(state)
        name = f"{state} - {label}" if label else str(state)
        out.append(f'{indent}state "{mermaid_label(name)}" as {ids[state]}')
    for edge in edges(table):
        parts = []
        for cond, act in edge.lines:
            timer = f" {act.timer}" if act.timer else ""
            parts.append(f"{cond} / {act.text}{timer}")
        out.append(f"{indent}{ids[edge.source]} --> {ids[edge.target]}: {mermaid_label(', '.join(parts))}")
    return out
