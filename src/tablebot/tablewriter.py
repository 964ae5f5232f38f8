"""Writing a parsed table back as CSV in the document's column layout (direction + speed, 7 = keep)."""

from __future__ import annotations

import csv
import io

from tablebot.table import DOC_KEEP_SPEED, Row, Table


def header(table: Table) -> list[str]:
    robot = table.robot
    return ["description", "state", *table.events,
            *(f"{m}_{field}" for m in robot.motors for field in ("dir", "speed")),
            *robot.lamps, *(f"{c}_load" for c in robot.counter_names), "timer", "next"]


def _motor_cells(speed: int | None) -> list[str]:
    if speed is None:
        return ["", str(DOC_KEEP_SPEED)]
    return ["1" if speed < 0 else "", str(abs(speed))]


def _keep(value: int | None) -> str:
    return "=" if value is None else str(value)


def row_cells(table: Table, row: Row, previous: Row | None) -> list[str]:
    description = "" if previous and previous.description == row.description else row.description
    return [description, str(row.state), *("1" if e in row.events else "" for e in table.events),
            *(cell for speed in row.motors for cell in _motor_cells(speed)),
            *(_keep(v) for v in row.lamps), *("" if v is None else str(v) for v in row.counters),
            str(row.timer), str(row.next)]


def format_table(table: Table) -> str:
    """CSV text that :func:`tablebot.tablefile.parse_table` reads back into the same machine."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header(table))
    previous = None
    for row in table.rows:
        writer.writerow(row_cells(table, row, previous))
        previous = row
    return buffer.getvalue()
