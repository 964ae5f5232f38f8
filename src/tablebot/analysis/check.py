"""One whole ``tablebot check`` run as data: findings, property results, exit code, and the
counterexample CSVs (inputs files that ``tablebot trace`` replays)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tablebot.analysis.finding import Finding
from tablebot.analysis.lints import find_all
from tablebot.analysis.model import Model, ModelTooLarge
from tablebot.analysis.properties import Property
from tablebot.analysis.prove import Result, check_property
from tablebot.diagnostics import fail
from tablebot.formats.inputs_csv import write_inputs
from tablebot.i18n import N_, Message
from tablebot.machine import Machine
from tablebot.replay import replay
from tablebot.tables import RobotTables


@dataclass
class CheckReport:
    """Everything one check found; ``counterexamples`` maps property names to written CSV files."""

    machine: Machine
    findings: list[Finding]
    results: list[Result]
    situations: int
    property_files: list[Path] = field(default_factory=list)
    counterexamples: dict[str, Path] = field(default_factory=dict)
    #: A robot of several tables: all of them (findings are each table's, proofs over them together).
    tables: RobotTables | None = None

    def severity_of(self, result: Result) -> str | None:
        """A property's failure counts as its level; an undecided one as a warning."""
        if result.status == "violated":
            return result.prop.level
        return "warning" if result.status == "unknown" else None

    def counts(self) -> dict[str, int]:
        counts = {"error": 0, "warning": 0, "info": 0}
        for f in self.findings:
            counts[f.severity] += 1
        for r in self.results:
            level = self.severity_of(r)
            if level:
                counts[level] += 1
        return counts

    def exit_code(self, strict: bool) -> int:
        """0 clean, 1 warnings under ``--strict``, 2 errors."""
        counts = self.counts()
        if counts["error"]:
            return 2
        return 1 if strict and counts["warning"] else 0


def run_check(
    machine: Machine,
    props: Sequence[Property],
    targets: tuple[str, ...] = (),
    step: Callable[[str], None] = lambda what: None,
) -> CheckReport:
    """Explore, find, prove; ``step`` is told what starts next (a progress display). A robot of several
    tables: :func:`tablebot.analysis.check_tables.run_check_tables`."""
    try:
        step(N_("exploring the situations"))
        graph = Model(machine).explore()
        step(N_("looking for findings"))
        findings = find_all(machine, graph, targets)
        results = []
        for prop in props:
            step(N_("property {name}", name=prop.name))
            results.append(check_property(prop, machine))
    except ModelTooLarge as exc:
        raise fail(
            machine.table.path,
            N_("too large to explore: {reason}", reason=exc.args[0]),
            N_("split the table, or give states fewer inputs to look at"),
        ) from None
    return CheckReport(machine, findings, results, len(graph.nodes))


def write_counterexamples(report: CheckReport, outdir: Path) -> None:
    """Write each counterexample (and each ``reachable`` witness) as ``outdir/NAME.csv``, all at once."""
    from tablebot.fileset import file_set

    written = {}
    with file_set(outdir):
        for result in report.results:
            if result.inputs:
                path = outdir / f"{result.prop.name}.csv"
                write_inputs(report.tables or report.machine, result.inputs, path)
                written[result.prop.name] = path
    report.counterexamples.update(written)


def story(machine: Machine, result: Result, limit: int = 12) -> list[str]:
    """What happens in a counterexample, tick by tick, with quiet stretches folded into one line (several
    tables: :func:`tablebot.analysis.check_tables.story_of_tables`)."""
    lines = list(replay(machine, result.inputs))
    items: list[str] = []
    quiet_from = None
    for i, line in enumerate(lines):
        pressed = [n for n, b in machine.input_bits.items() if line["event"] & b]
        last = i == len(lines) - 1
        if line["row"] is None and not pressed and not last:
            quiet_from = i if quiet_from is None else quiet_from
            continue
        if quiet_from is not None:
            items.append(_quiet(quiet_from, i - 1, lines[i - 1]))
            quiet_from = None
        text = _tick_text(machine, line, pressed)
        items.append(N_("{step}   <- it shows here", step=text) if last else text)
    if len(items) > limit:
        items = [items[0], N_("... ({n} more steps) ...", n=len(items) - limit + 1), *items[-(limit - 2) :]]
    return items


def _quiet(first: int, last: int, line: dict[str, Any]) -> Message:
    if first == last:
        return N_(
            "tick {first}: nothing pressed, nothing fires (state {state}, timer counts down)",
            first=first,
            state=line["state"],
        )
    return N_(
        "ticks {first}-{last}: nothing pressed, nothing fires (state {state}, timer counts down)",
        first=first,
        last=last,
        state=line["state"],
    )


def _tick_text(machine: Machine, line: dict[str, Any], pressed: list[str]) -> Message:
    table = machine.table
    what: str = " + ".join(pressed) if pressed else N_("nothing pressed")
    if line["event"] & machine.timer_bit:
        what = N_("{what}, timer ran out", what=what)
    outputs = " ".join(f"{n} {line[n]}" for n in machine.output_names)
    if line["row"] is None:
        return N_(
            "tick {tick}: {what}; no row fires (state {state}, {outputs})",
            tick=line["tick"],
            what=what,
            state=line["state"],
            outputs=outputs,
        )
    row = table.rows[line["row"]]
    label = f" ({row.description})" if row.description else ""
    return N_(
        "tick {tick}: {what} -> line {line}{label} fires: state {state}, {outputs}",
        tick=line["tick"],
        what=what,
        line=row.line,
        label=label,
        state=line["state"],
        outputs=outputs,
    )


def report_json(report: CheckReport, strict: bool) -> dict[str, Any]:
    table = report.machine.table
    return {
        "table": table.path,
        "robot": table.robot.name,
        "rows": len(table.rows),
        "states": len(report.machine.states),
        "situations_explored": report.situations,
        "findings": [f.as_json() for f in report.findings],
        "properties": [_result_json(report, r) for r in report.results],
        "counts": report.counts(),
        "exit_code": report.exit_code(strict),
        **(
            {
                "tables": [
                    {"name": t.name, "table": t.path, "rows": len(t.rows), "states": len(m.states)}
                    for t, m in zip(report.tables.tables, report.tables.machines, strict=True)
                ]
            }
            if report.tables is not None
            else {}
        ),
    }


def _result_json(report: CheckReport, result: Result) -> dict[str, Any]:
    prop = result.prop
    data: dict[str, Any] = {
        "name": prop.name,
        "text": prop.text,
        "claim": prop.claim(),
        "status": result.status,
        "level": prop.level,
        "note": prop.note,
        "source": prop.source,
        "line": prop.line,
        "situations_explored": result.explored,
    }
    if result.inputs:
        path = report.counterexamples.get(prop.name)
        data["inputs_csv"] = str(path) if path else None
        data["ticks"] = len(result.inputs)
        data["shows_at_tick"] = result.at_tick
        data["shortest"] = result.exact
    if result.state is not None:
        data["trapped_in_state"] = result.state
    if result.detail:
        data["detail"] = result.detail
    return data
