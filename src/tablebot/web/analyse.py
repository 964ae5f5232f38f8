"""What the studio shows about a table as it is edited: the parser's errors on their cells, ``check``'s
findings and property results on their rows, and why each row of a state did or did not fire.

Everything comes from the same code as the CLI (``formats.table_read``, ``analysis``), so the words
and hints are the CLI's.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path, PurePosixPath
from typing import Any

from tablebot.analysis.check import CheckReport
from tablebot.colours import state_colours
from tablebot.diagnostics import Diagnostic, TableBotError
from tablebot.formats import table_read
from tablebot.formats.csv_document import CsvDocument
from tablebot.formats.table_parts import robot_for_table
from tablebot.i18n import N_
from tablebot.loading import Loaded, property_files
from tablebot.loading import robot_for as robot_for  # the robot a table file runs on, as the CLI finds it
from tablebot.machine import NO_ROW, Machine, compile_table
from tablebot.robot import Robot
from tablebot.robot_tables import CrossEvent, parse_cross, tables_of
from tablebot.table import Table, normalise_header
from tablebot.tables import RobotTables, load_tables

#: Column kinds the grid draws differently (see table_read.Column.kind).
FLAG_KINDS = ("event", "dir")


@dataclass
class Analysis:
    """One edit's verdict: the parsed table (None while it has errors) and what to show where; ``tables``: a
    robot of several tables, all of them (this one as edited), which the arena runs and check proves together."""

    table: Table | None
    machine: Machine | None
    report: CheckReport | None
    data: dict[str, Any] = field(default_factory=dict)
    tables: RobotTables | None = None


def columns_of(header: list[str], robot: Robot) -> list[dict[str, str]]:
    """Per header cell: its kind for the grid (event, dir, speed, signed, timer, state, ...) and a label."""
    out = []
    for text in header:
        if isinstance(parse_cross(text, robot), CrossEvent):  # another table's state: an event like an input's
            out.append({"kind": "event", "name": text.strip(), "label": ""})
            continue
        name = normalise_header(text)  # the parser's own reading of a header cell
        kind_name = table_read._classify(name, robot) if name else None
        kind, base = kind_name if kind_name else ("unknown", name)
        label = robot.labels.get(base, N_("timer ran out") if base == "T" else "")  # said in the tab's language
        out.append({"kind": kind, "name": base, "label": label})
    return out


def unknown_columns(doc: CsvDocument) -> list[dict[str, str]]:
    """Every header cell of ``doc`` as a column of unknown kind (no robot to tell what it is)."""
    return [{"kind": "unknown", "name": h, "label": ""} for h in doc.header_values()]


def table_columns(doc: CsvDocument, path: Path, robot: Robot | None) -> list[dict[str, str]]:
    """The grid's columns of ``doc`` as :func:`analyse` will give them (the table's own robot, for one of several
    tables), sent with the table itself so the page draws its grid once; every column unknown without a robot."""
    if robot is None:
        return unknown_columns(doc)
    with contextlib.suppress(TableBotError):  # the analysis says what is wrong; its columns are the file's robot's
        robot, _ = robot_for_table(path, robot)
    return columns_of(doc.header_values(), robot)


def analyse(
    doc: CsvDocument, path: Path, robot: Robot, display: str, others: Mapping[str, Table] | None = None
) -> Analysis:
    """Parse the document's text as the CLI would, then check it; located results for the grid. A table of a
    robot of several tables is read as one of them (its name, start and rule) and checked with the others:
    ``others`` as the studio has them (edited), the rest from their files."""
    started = time.perf_counter()
    places = _cell_places(doc)
    lines = {line: grid for grid, line in enumerate(_row_lines(doc))}
    header_line = _header_line(doc)
    table = machine = report = tables = None
    diagnostics: list[dict[str, Any]] = []
    try:
        robot, name = robot_for_table(path, robot)  # one of several tables: its own start and rule
        # the parser names the file as the page shows it; the table keeps its real path, where the
        # simulator looks for the arena beside it
        table = replace(table_read.parse_table(doc.text(), display, robot, name), path=str(path))
        machine = compile_table(table)
        tables = load_tables(table, others) if tables_of(robot) else None
        loaded = (
            Loaded(table, machine, property_files=tuple(property_files(path)))
            if tables is None
            else Loaded(tables.table, tables.machines[0], property_files=tuple(property_files(path)), tables=tables)
        )
        report = loaded.check_report()  # its properties found and proved as check does
    except TableBotError as exc:
        diagnostics = [
            _locate(_as_shown(d, path, display), display, places, lines, header_line) for d in exc.diagnostics
        ]
    data: dict[str, Any] = {
        "ok": table is not None and not diagnostics,
        "diagnostics": diagnostics,
        "columns": columns_of(doc.header_values(), robot),
    }
    if table is not None and machine is not None:
        data["machine"] = machine_json(table, machine, tables)
    if report is not None and table is not None:
        data.update(_report_json(report, lines, "" if tables is None or table is tables.table else table.name))
    data["ms"] = round(1000 * (time.perf_counter() - started), 2)
    return Analysis(table if report is not None else None, machine, report, data, tables)


def robot_failed(error: TableBotError, doc: CsvDocument) -> dict[str, Any]:
    """What the grid shows when the robot file itself does not read: its errors, the columns unknown."""
    return {
        "ok": False,
        "columns": unknown_columns(doc),
        "diagnostics": [_locate(d, "", {}, {}, None) for d in error.diagnostics],
        "ms": 0,
    }


def machine_json(table: Table, machine: Machine, tables: RobotTables | None = None) -> dict[str, Any]:
    """The machine as the page needs it; each state carries its colour from ``tablebot.colours``, the one
    the PNGs of a run give it (the page only looks colours up, so the two can never disagree). A robot of
    several tables: its name and the main one's, and each table's rows as a trace names them (as written) ->
    their lines, for the trace player's other tables."""
    several = (
        {}
        if tables is None
        else {
            "name": table.name,
            "main_name": tables.names[0],
            "table_lines": {t.name: {r.as_written: r.line for r in t.rows} for t in tables.tables},
        }
    )
    robot = table.robot
    colours = state_colours(machine.states)
    return {
        "states": [
            {"id": str(s), "label": table.state_name(s), "colour": c}
            for s, c in zip(machine.states, colours, strict=True)
        ],
        "rows": len(table.rows),
        "events": list(table.events),
        "inputs": list(table.input_events),
        "input_bits": machine.input_bits,
        "timer_bit": machine.timer_bit,
        "outputs": list(machine.output_names),
        "motors": list(robot.motors),
        "lamps": list(robot.lamps),
        "tick_ms": robot.tick_ms,
        "initial_state": str(robot.initial_state),
        "robot": robot.name,
        "labels": dict(robot.labels),
        # row i (a trace's 0-based ``row``) is this line of the file: the number the grid and every message show
        "row_lines": [row.line for row in table.rows],
        # a trace names a row as written (a group's row once): that row's line, by the trace's number
        "written_lines": {row.as_written: row.line for row in table.rows},
        **several,
    }


def _report_json(report: CheckReport, lines: dict[int, int], table: str) -> dict[str, Any]:
    """``table``: the name of the table the grid shows ("" the main one): only its findings mark its rows."""
    findings = [
        {
            "code": f.code,
            "severity": f.severity,
            "message": f.message,
            "hint": f.hint,
            "lines": list(f.lines),
            "rows": [lines[n] for n in f.lines if n in lines] if f.table == table else [],
        }
        for f in report.findings
    ]
    props = []
    for result in report.results:
        prop = result.prop
        props.append(
            {
                "name": prop.name,
                "text": prop.text,
                "claim": prop.claim(),
                "status": result.status,
                "level": prop.level,
                "note": prop.note,
                "detail": result.detail,
                "severity": report.severity_of(result),
                "ticks": len(result.inputs),
                "at_tick": result.at_tick,
                "example": prop.kind == "reachable",
            }
        )
    return {"findings": findings, "properties": props, "counts": report.counts(), "situations": report.situations}


# --- placing diagnostics ------------------------------------------------------------------------------


def _cell_places(doc: CsvDocument) -> dict[tuple[int, int], tuple[int, int]]:
    """(line, column) of each cell -> (grid row, column); the header is grid row -1."""
    places: dict[tuple[int, int], tuple[int, int]] = {}
    grid_of = {index: row for row, index in enumerate(doc.row_ids)}
    for index, (record, where) in enumerate(zip(doc.records, doc.positions(), strict=True)):
        row = -1 if record.kind == "header" else grid_of.get(index)
        if row is None:
            continue
        for column, place in enumerate(where):
            places[place] = (row, column)
    return places


def _row_lines(doc: CsvDocument) -> list[int]:
    starts = doc.record_lines()
    return [starts[index] for index in doc.row_ids]


def _header_line(doc: CsvDocument) -> int | None:
    starts = doc.record_lines()
    return next((starts[i] for i, r in enumerate(doc.records) if r.kind == "header"), None)


def _as_shown(d: Diagnostic, path: Path, display: str) -> Diagnostic:
    """A diagnostic about a file of the robot named as the page names files (relative to the folder): the robot's
    tables checked together name theirs by their real paths (this table's too), the parser by ``display``."""
    if d.path == str(path):
        return replace(d, path=display)
    try:
        inside = Path(d.path).relative_to(path.parent)
    except ValueError:  # not beside this table: named as it is
        return d
    return replace(d, path=(PurePosixPath(display).parent / inside.as_posix()).as_posix())


def _locate(
    d: Diagnostic,
    display: str,
    places: dict[tuple[int, int], tuple[int, int]],
    lines: dict[int, int],
    header_line: int | None,
) -> dict[str, Any]:
    """A diagnostic with the grid cell (or row) it belongs to; problems of other files have none."""
    row = column = None
    if d.path == display and d.line is not None:
        if d.column is not None and (d.line, d.column) in places:
            row, column = places[(d.line, d.column)]
        elif d.line == header_line:
            row = -1
        else:
            row = lines.get(d.line)
    return {
        "file": d.path,
        "line": d.line,
        "column": d.column,
        "message": d.message,
        "hint": d.hint,
        "severity": d.severity,
        "text": d.render(),
        "row": row,
        "col": column,
    }


# --- why a row fired ---------------------------------------------------------------------------------


def explain(table: Table, machine: Machine, state: int, events: int) -> list[dict[str, Any]]:
    """For each row of ``state`` (an index), in table order: fired, or why not, given the event mask."""
    out = []
    fired = machine.lookup(state, events)
    names = table.events
    for compiled in machine.rows:
        if compiled.state != state:
            continue
        row = table.rows[compiled.index]
        missing = [e for e in names if compiled.mask & table.bit(e) and not events & table.bit(e)]
        line = (
            N_("line {line} ({description})", line=row.line, description=row.description)
            if row.description
            else N_("line {line}", line=row.line)
        )
        if compiled.index == fired:
            why = (
                N_(
                    "{line} fired: it needs {events}, all present",
                    line=line,
                    events=" + ".join(e for e in names if e in row.events),
                )
                if row.events
                else N_("{line} fired: it needs nothing", line=line)
            )
            status = "fired"
        elif missing:
            why = N_("{line} did not fire: it needs {events}", line=line, events=" + ".join(missing))
            status = "missing"
        elif fired == NO_ROW:  # it needs nothing, yet nothing fired: the document's rule on a tick with no event
            why = N_(
                '{line} did not fire: no event this tick, and with match = "document" no row is looked up then',
                line=line,
            )
            status = "missing"
        else:
            why = N_(
                "{line} did not fire: line {first} comes first and matches too", line=line, first=table.rows[fired].line
            )
            status = "shadowed"
        out.append({"row": compiled.index, "status": status, "why": why, "line": row.line})
    if fired == NO_ROW:
        out.append({"row": None, "status": "none", "why": N_("no row fired: nothing changes this tick")})
    return out
