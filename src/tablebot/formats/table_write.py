"""Writing a parsed table back as CSV in the document's column layout (direction + speed, 7 = keep).

A motor that some row drives at a real speed of 7 cannot be written that way (7 means keep there),
so that motor gets one signed column instead (``=`` = keep); the table reads back the same.
"""

from __future__ import annotations

import csv
import io

from tablebot.i18n.headers import header_name
from tablebot.table import DOC_KEEP_SPEED, Row, Table, to_direction_speed


def signed_motors(table: Table) -> frozenset[str]:
    """Motors that need the signed form: some row sets them to speed 7 (or -7)."""
    speeds = [
        {abs(speed) for row in table.rows if (speed := row.motors[i]) is not None}
        for i in range(len(table.robot.motors))
    ]
    return frozenset(motor for motor, used in zip(table.robot.motors, speeds, strict=True) if DOC_KEEP_SPEED in used)


def owns(table: Table, output: str) -> bool:
    """Whether the table has a column for ``output``: one table of a robot of several (``[tables]``) only for the
    outputs it writes (another column would make it a second writer); a robot's one table for every output."""
    return not table.name or output in table.writes


def header(table: Table, signed: frozenset[str], language: str = "en") -> list[str]:
    """The header's cells, in ``language`` (German: Zustand, Folgezustand, M1_Richtung: tablebot.i18n.headers)."""
    robot = table.robot
    motors = [
        name for m in robot.motors if owns(table, m) for name in ([m] if m in signed else [f"{m}_dir", f"{m}_speed"])
    ]
    lamps = [lamp for lamp in robot.lamps if owns(table, lamp)]
    loads = [f"{c}_load" for c in robot.counter_names if owns(table, c)]
    return [
        header_name(name, language)
        for name in ["description", "state", *table.events, *motors, *lamps, *loads, "timer", "next"]
    ]


def _motor_cells(speed: int | None, signed: bool) -> list[str]:
    if signed:
        return ["=" if speed is None else str(speed)]
    direction, level = to_direction_speed(speed)
    return ["1" if direction else "", str(level)]


def _keep(value: int | None) -> str:
    return "=" if value is None else str(value)


def row_cells(table: Table, row: Row, previous: Row | None, signed: frozenset[str]) -> list[str]:
    description = "" if previous and previous.description == row.description else row.description
    robot = table.robot
    motors = [(m, speed) for m, speed in zip(robot.motors, row.motors, strict=True) if owns(table, m)]
    lamps = [v for lamp, v in zip(robot.lamps, row.lamps, strict=True) if owns(table, lamp)]
    loads = [v for c, v in zip(robot.counter_names, row.counters, strict=True) if owns(table, c)]
    return [
        description,
        str(row.state),
        *("1" if e in row.events else "" for e in table.events),
        *(cell for motor, speed in motors for cell in _motor_cells(speed, motor in signed)),
        *(_keep(v) for v in lamps),
        *("" if v is None else str(v) for v in loads),
        str(row.timer),
        str(row.next),
    ]


def format_table(table: Table, language: str = "en") -> str:
    """CSV text that :func:`tablebot.formats.table_read.parse_table` reads back into the same machine (its header in
    ``language``: the reader takes either)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    signed = signed_motors(table)
    writer.writerow(header(table, signed, language))
    previous = None
    for row in table.rows:
        writer.writerow(row_cells(table, row, previous, signed))
        previous = row
    return buffer.getvalue()
