"""``tablebot import FILE --from scxml|xstate``: a statechart tablebot exported, read back into its tables and written
as table CSV (:func:`tablebot.formats.table_write.format_table`: the same bytes as the exported table's).

One table: its CSV goes to ``--out`` (or standard output). Several: ``--out`` is a folder, and each table is written
there as ``NAME.csv``, the robot file's ``[tables]`` lines said on the terminal. A robot file given with ``--robot``
must name every input, motor, lamp and counter the statechart has (the table is then read with it).
"""

from __future__ import annotations

from pathlib import Path

from tablebot.csvtext import read_text
from tablebot.diagnostics import fail
from tablebot.files import out_folder, write_text
from tablebot.formats.table_write import format_table
from tablebot.robot import Robot
from tablebot.table import Table

__all__ = ["KINDS", "import_statechart", "read_statechart"]

KINDS = ("scxml", "xstate")
#: The largest statechart read: a table of 100,000 rows exports to some 60 MB of SCXML.
MAX_BYTES = 128 * 1024 * 1024


def read_statechart(path: Path, kind: str) -> tuple[Table, ...]:
    """The tables in an exported SCXML (``kind`` "scxml") or XState config ("xstate"), the main one first."""
    from tablebot.formats.statecharts.read_scxml import read_scxml
    from tablebot.formats.statecharts.read_xstate import read_xstate

    text = read_text(path, "save it as UTF-8", limit=MAX_BYTES, spreadsheet=False)
    return read_scxml(text, str(path)) if kind == "scxml" else read_xstate(text, str(path))


def _against(tables: tuple[Table, ...], robot: Robot) -> None:
    """Every name the statechart uses is the robot file's, or a located error on the robot file."""
    used = tables[0].robot
    for section, names, known in (("inputs", used.inputs, robot.inputs), ("motors", used.motors, robot.motors),
                                  ("lamps", used.lamps, robot.lamps),
                                  ("counters", used.counter_names, robot.counter_names)):
        missing = [name for name in names if name not in known]
        if missing:
            raise fail(robot.source, f"[{section}] has no {', '.join(missing)}, which the statechart uses",
                       f'add {missing[0]} = "what it is" to [{section}], or import without --robot',
                       robot.line(section))


def import_statechart(path: Path, kind: str, out: Path | None, robot: Robot | None) -> tuple[str | None, list[str]]:
    """Read the statechart and write its tables: (the CSV text for standard output, or None when written to
    ``out``; the lines to say)."""
    if out is not None and out.resolve() == path.resolve():
        raise fail("--out", f"--out is {out}, the statechart being read", "write the table to another file")
    tables = read_statechart(path, kind)
    if robot is not None:
        _against(tables, robot)
    if len(tables) == 1:
        text = format_table(tables[0])
        if out is None:
            return text, []
        write_text(out, text)
        return None, [f"wrote {out} ({len(tables[0].rows)} rows)"]
    if out is None:
        raise fail("--out", f"{path} holds {len(tables)} tables",
                   "give --out FOLDER: each is written there as NAME.csv")
    folder = out_folder(out, "--out")
    lines = [f"wrote {write_text(folder / f'{t.name}.csv', format_table(t))}" for t in tables]
    lines.append("the robot file's [tables]: " + "; ".join(
        f'{t.name} = {{ file = "{t.name}.csv", initial_state = {t.robot.initial_state!r}, '
        f'initial_timer = {t.robot.initial_timer}, match = "{t.robot.match}" }}' for t in tables).replace("'", '"'))
    return None, lines
