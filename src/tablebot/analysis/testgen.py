"""Golden tests for any implementation of the engine: input sequences that together fire every row
that can fire, each with the trace the reference engine gives for it, and a coverage report.

Sequences are built greedily on the explored model: from where the robot is, the shortest way
to a row not fired yet, again and again; a new sequence starts from power-on when nothing new
can be reached any more (or the current one is long enough).
"""

from __future__ import annotations

import json
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path

from tablebot.analysis.lints import find_all
from tablebot.analysis.model import Graph, Model, ModelTooLarge, Node, Tick, walk_back
from tablebot.diagnostics import fail
from tablebot.files import atomic_write, write_text
from tablebot.fileset import file_set
from tablebot.formats.inputs_csv import TickInput, write_inputs
from tablebot.formats.trace_lines import write_trace
from tablebot.i18n import N_
from tablebot.machine import Machine
from tablebot.replay import replay

MAX_STEPS = 400
REASON_CODES = ("shadowed-row", "unreachable-state", "timer-never-expires", "row-never-fires")


@dataclass
class GoldenSequence:
    name: str
    inputs: list[TickInput]
    rows: list[int]  # rows fired, in first-fired order

    @property
    def inputs_name(self) -> str:
        return f"{self.name}.csv"

    @property
    def trace_name(self) -> str:
        return f"{self.name}.jsonl"


@dataclass
class GoldenSet:
    machine: Machine
    sequences: list[GoldenSequence] = field(default_factory=list)
    fireable: set[int] = field(default_factory=set)
    covered: set[int] = field(default_factory=set)
    reasons: dict[int, str] = field(default_factory=dict)  # rows never fired -> why (from check)


def generate(machine: Machine) -> GoldenSet:
    model = Model(machine)
    try:
        graph = model.explore()
    except ModelTooLarge as exc:
        raise fail(
            machine.table.path, N_("too large to explore: {reason}", reason=exc.args[0]), N_("split the table")
        ) from None
    golden = GoldenSet(machine, fireable=graph.fired_rows())
    while golden.fireable - golden.covered:
        path = _sequence(model, golden.fireable - golden.covered)
        if not path:
            break  # cannot happen for rows the exploration saw fire, but never loop forever
        inputs, _ = model.concretize(path)
        fired = [line["row"] for line in replay(machine, inputs) if line["row"] is not None]
        rows = list(dict.fromkeys(fired))
        golden.covered |= set(rows)
        golden.sequences.append(GoldenSequence(f"seq-{len(golden.sequences) + 1:02d}", inputs, rows))
    golden.reasons = _reasons(machine, graph, golden)
    return golden


def _sequence(model: Model, wanted: set[int]) -> list[tuple[Node, Tick]]:
    node = model.initial()
    path: list[tuple[Node, Tick]] = []
    wanted = set(wanted)
    while wanted and len(path) < MAX_STEPS:
        step = _nearest(model, node, wanted)
        if step is None:
            break
        path += step
        wanted -= {tick[2] for _, tick in step}
        node = step[-1][1][3]
    return path


def _nearest(model: Model, start: Node, wanted: set[int]) -> list[tuple[Node, Tick]] | None:
    """Breadth-first: the fewest model steps from ``start`` to a tick that fires a wanted row."""
    parent: dict[Node, tuple[Node, Tick] | None] = {start: None}
    queue = deque([start])
    while queue:
        node = queue.popleft()
        for tick in model.successors(node):
            if tick[2] in wanted:
                return [*walk_back(parent, node), (node, tick)]
            after = tick[3]
            if after not in parent:
                parent[after] = (node, tick)
                queue.append(after)
    return None


def _reasons(machine: Machine, graph: Graph, golden: GoldenSet) -> dict[int, str]:
    by_line: dict[int, str] = {}
    for finding in find_all(machine, graph):
        if finding.code in REASON_CODES:
            for line in finding.lines[:1] if finding.code == "shadowed-row" else finding.lines:
                by_line.setdefault(line, finding.message)
    return {
        row.index: by_line.get(row.line, "not reached by the generated sequences")
        for row in machine.table.rows
        if row.index not in golden.covered
    }


def write_golden(golden: GoldenSet, out: Path) -> None:
    """``seq-NN.csv`` (inputs) and ``seq-NN.jsonl`` (expected trace) per sequence, and coverage.json."""
    machine = golden.machine
    with file_set(out):  # the tests replace the previous ones at once
        for seq in golden.sequences:
            write_inputs(machine, seq.inputs, out / seq.inputs_name)
            with atomic_write(out / seq.trace_name) as stream:
                write_trace(replay(machine, seq.inputs), stream)
        write_text(out / "coverage.json", json.dumps(coverage(golden), indent=2) + "\n")


def coverage(golden: GoldenSet) -> dict:
    table = golden.machine.table
    fired_by: dict[int, list[str]] = {}
    for seq in golden.sequences:
        for row in seq.rows:
            fired_by.setdefault(row, []).append(seq.name)
    rows = [
        {
            "line": r.line,
            "row": r.index,
            "state": r.state,
            "description": r.description,
            "covered": r.index in golden.covered,
            "fired_by": fired_by.get(r.index, []),
            **({"why_not": golden.reasons[r.index]} if r.index in golden.reasons else {}),
        }
        for r in table.rows
    ]
    return {
        "table": table.path,
        "rows_total": len(table.rows),
        "rows_fireable": len(golden.fireable),
        "rows_covered": len(golden.covered),
        "sequences": [
            {
                "inputs": s.inputs_name,
                "trace": s.trace_name,
                "ticks": len(s.inputs),
                "lines_fired": [table.rows[i].line for i in s.rows],
            }
            for s in golden.sequences
        ],
        "rows": rows,
    }


__all__ = ["GoldenSet", "coverage", "generate", "write_golden"]
