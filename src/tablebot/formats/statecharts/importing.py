"""``tablebot import FILE --from scxml|xstate``: a statechart tablebot exported, read back into its tables and written
as table CSV (:func:`tablebot.formats.table_write.format_table`: the same bytes as the exported table's, in their
written form: a group's rows once, with the group as their state, :func:`table_text`).

One table: its CSV goes to ``--out`` (or standard output). Several: ``--out`` is a folder, the main table is
written there as ``table.csv`` and each other as ``NAME.csv``, the robot file's ``[tables]`` lines said on the
terminal (and ``[groups]``, when rows were written for groups). A robot file given with ``--robot`` must name
every input, motor, lamp and counter the statechart has.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from tablebot.csvtext import read_text
from tablebot.diagnostics import fail
from tablebot.files import out_folder, write_text
from tablebot.fileset import file_set
from tablebot.formats.table_write import format_table
from tablebot.i18n import N_, _
from tablebot.robot import Robot, StateId
from tablebot.table import Table

__all__ = ["KINDS", "import_statechart", "read_statechart"]

KINDS = ("scxml", "xstate")
#: The largest statechart read: a table of 100,000 rows exports to some 60 MB of SCXML.
MAX_BYTES = 128 * 1024 * 1024


def table_text(table: Table) -> str:
    """A table as its file writes it (:func:`format_table`): a group's rows once, with the group as their state,
    and in a robot of several tables only the outputs the table writes (another table's column would make it a
    second writer)."""
    rows, seen = [], set()
    for row in table.rows:
        if row.group:
            if row.as_written in seen:
                continue
            seen.add(row.as_written)
            row = replace(row, state=row.group)
        rows.append(row)
    robot = table.robot
    if table.name:
        motors = [i for i, m in enumerate(robot.motors) if m in table.writes]
        lamps = [i for i, lamp in enumerate(robot.lamps) if lamp in table.writes]
        counters = [i for i, c in enumerate(robot.counter_names) if c in table.writes]
        rows = [
            replace(
                r,
                motors=tuple(r.motors[i] for i in motors),
                lamps=tuple(r.lamps[i] for i in lamps),
                counters=tuple(r.counters[i] for i in counters),
            )
            for r in rows
        ]
        robot = replace(
            robot,
            motors=tuple(robot.motors[i] for i in motors),
            lamps=tuple(robot.lamps[i] for i in lamps),
            counters=tuple(robot.counters[i] for i in counters),
        )
    return format_table(replace(table, robot=robot, rows=tuple(rows)))


def groups(tables: tuple[Table, ...]) -> dict[str, list[StateId]]:
    """The state groups the tables' rows were written for, each with its states in the order it lists them."""
    found: dict[str, list[StateId]] = {}
    for table in tables:
        for row in table.rows:
            if row.group and row.state not in found.setdefault(row.group, []):
                found[row.group].append(row.state)
    return found


def read_statechart(path: Path, kind: str) -> tuple[Table, ...]:
    """The tables in an exported SCXML (``kind`` "scxml") or XState config ("xstate"), the main one first."""
    from tablebot.formats.statecharts.read_scxml import read_scxml
    from tablebot.formats.statecharts.read_xstate import read_xstate

    text = read_text(path, "save it as UTF-8", limit=MAX_BYTES, spreadsheet=False)
    return read_scxml(text, str(path)) if kind == "scxml" else read_xstate(text, str(path))


def _against(tables: tuple[Table, ...], robot: Robot) -> None:
    """Every name the statechart uses is the robot file's, or a located error on the robot file."""
    used = tables[0].robot
    for section, names, known in (
        ("inputs", used.inputs, robot.inputs),
        ("motors", used.motors, robot.motors),
        ("lamps", used.lamps, robot.lamps),
        ("counters", used.counter_names, robot.counter_names),
    ):
        missing = [name for name in names if name not in known]
        if missing:
            raise fail(
                robot.source,
                N_("[{section}] has no {names}, which the statechart uses", section=section, names=tuple(missing)),
                N_(
                    'add {name} = "what it is" to [{section}], or import without --robot',
                    name=missing[0],
                    section=section,
                ),
                robot.line(section),
            )


def import_statechart(path: Path, kind: str, out: Path | None, robot: Robot | None) -> tuple[str | None, list[str]]:
    """Read the statechart and write its tables: (the CSV text for standard output, or None when written to
    ``out``; the lines to say)."""
    if out is not None and out.resolve() == path.resolve():
        raise fail(
            "--out",
            N_("--out is {out}, the statechart being read", out=str(out)),
            N_("write the table to another file"),
        )
    tables = read_statechart(path, kind)
    if robot is not None:
        _against(tables, robot)
    said = [
        _("the robot file's [groups]: ")
        + "; ".join(f"{name} = {list(states)!r}".replace("'", '"') for name, states in groups(tables).items())
    ]
    said = said if groups(tables) else []
    if len(tables) == 1:
        text = table_text(tables[0])
        if out is None:
            return text, said
        write_text(out, text)
        return None, [_("wrote {file} ({count} rows)").format(file=out, count=len(tables[0].rows)), *said]
    if out is None:
        raise fail(
            "--out",
            N_("{file} holds {count} tables", file=str(path), count=len(tables)),
            N_("give --out FOLDER: the main table is written there as table.csv, each other as NAME.csv"),
        )
    folder = out_folder(out, "--out")
    files = ["table.csv", *(f"{t.name}.csv" for t in tables[1:])]  # the main one where a folder's table is
    with file_set(folder):  # all the tables or none: a refused one (a table of yours, no --force) leaves none
        lines = [
            _("wrote {file}").format(file=write_text(folder / name, table_text(t)))
            for name, t in zip(files, tables, strict=True)
        ]
    lines.append(
        _("the robot file's [tables]: ")
        + "; ".join(
            f'{t.name} = {{ file = "{name}", initial_state = {t.robot.initial_state!r}, '
            f'initial_timer = {t.robot.initial_timer}, match = "{t.robot.match}" }}'
            for name, t in zip(files, tables, strict=True)
        ).replace("'", '"')
    )
    return None, [*lines, *said]
