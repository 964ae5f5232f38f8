"""Zero-time loops: cycles of rows that fire on consecutive ticks with no input pressed at all, so
the robot hops between states every tick (motors may flicker) and never waits for anything.
A row that fires every tick without changing anything (same state, same outputs) is not one."""

from __future__ import annotations

from collections.abc import Iterable

from tablebot.analysis.finding import Finding
from tablebot.analysis.model import Graph, Node
from tablebot.analysis.names import rows_phrase, state_text
from tablebot.i18n import N_, Message
from tablebot.machine import NO_ROW


def zero_time_loops(graph: Graph) -> list[Finding]:
    """One finding per distinct set of rows that forms such a cycle in the explored model."""
    machine = graph.model.machine
    table = machine.table
    edges: dict[Node, list[tuple[Node, int]]] = {}
    for node, (events, zeroed, row, after) in graph.ticks():
        # Encoder pulses are input too: a loop that needs them does wait for something. A row that
        # fires but leaves the situation as it was (a "rest" or polling row) is like no row firing.
        if row != NO_ROW and not events & machine.input_mask and not zeroed and after != node:
            edges.setdefault(node, []).append((after, row))
    found, reported = [], set()
    for component in _cycles(edges):
        rows = frozenset(r for n in component for a, r in edges.get(n, []) if a in component)
        if rows in reported:
            continue
        reported.add(rows)
        row_objs = [table.rows[i] for i in sorted(rows)]
        states = list(dict.fromkeys(table.rows[i].state for i in sorted(rows)))
        trapped = not _can_escape(graph, component)
        path = state_text(table, states[0]) if len(states) < 2 else _arrows([state_text(table, s) for s in states])
        goes = N_("cycles {path}", path=path) if len(states) > 1 else N_("stays in {path}", path=path)
        several = len({r.line for r in row_objs}) > 1
        message = (
            N_(
                "zero-time loop: {rows} fire on every tick with no input pressed, so the robot {goes} without "
                "ever waiting",
                rows=rows_phrase(row_objs),
                goes=goes,
            )
            if several
            else N_(
                "zero-time loop: {rows} fires on every tick with no input pressed, so the robot {goes} without ever "
                "waiting",
                rows=rows_phrase(row_objs),
                goes=goes,
            )
        )
        message = (
            N_("{loop} and no input can ever get it out: it is stuck for good", loop=message)
            if trapped
            else N_("{loop}; it only leaves when an input arrives", loop=message)
        )
        found.append(
            Finding(
                "zero-time-loop",
                "error" if trapped else "warning",
                message,
                tuple(r.line for r in row_objs),
                N_("load a timer above 0 and wait for T, or wait for an input"),
                states[0],
                {"states": states},
            )
        )
    return found


def _arrows(states: list[Message]) -> Message:
    """``a → b → c``, each state in the reader's language."""
    if len(states) == 2:
        return N_("{first} → {second}", first=states[0], second=states[1])
    return N_("{first} → {second}", first=states[0], second=_arrows(states[1:]))


def _can_escape(graph: Graph, component: set[Node]) -> bool:
    """Whether some tick (any inputs) leaves the loop's situations."""
    return any(tick[3] not in component for node in component for tick in graph.model.successors(node))


def _cycles(edges: dict[Node, list[tuple[Node, int]]]) -> Iterable[set[Node]]:
    """Strongly connected components with at least one edge inside (iterative Tarjan)."""
    index: dict[Node, int] = {}
    low: dict[Node, int] = {}
    stack: list[Node] = []
    on_stack: set[Node] = set()
    counter = 0
    for root in list(edges):
        if root in index:
            continue
        work = [(root, iter(edges.get(root, [])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, successors = work[-1]
            advanced = False
            for after, _ in successors:
                if after not in index:
                    index[after] = low[after] = counter
                    counter += 1
                    stack.append(after)
                    on_stack.add(after)
                    work.append((after, iter(edges.get(after, []))))
                    advanced = True
                    break
                if after in on_stack:
                    low[node] = min(low[node], index[after])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = set()
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.add(member)
                    if member == node:
                        break
                if len(component) > 1 or any(a == node for a, _ in edges.get(node, [])):
                    yield component
