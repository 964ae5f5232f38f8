"""A run as one self-contained HTML file (no server, nothing fetched): the arena, the timeline, the
table and the state diagram, replayed by the studio's own drawing modules (bundled into the page), to
send to a pupil.

``tablebot sim ... --html`` writes it; :func:`write_html` takes the run's trace lines, its world and
its table.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from tablebot.diagnostics import TableBotError
from tablebot.files import write_text
from tablebot.formats.csv_document import CsvDocument
from tablebot.formats.table_write import format_table
from tablebot.machine import compile_table
from tablebot.sim.model.params import Params
from tablebot.sim.model.world import World
from tablebot.table import Table
from tablebot.tables import several
from tablebot.web.analyse import columns_of, machine_json
from tablebot.web.bundle import bundle
from tablebot.web.simulate import studio_diagram
from tablebot.web.tracefile import trace_columns
from tablebot.web.worldview import world_json

STATIC = Path(__file__).parent / "static"
ENTRY = "replay/main.js"  # under static/js; it and the modules it imports are inlined as one script
#: Decimals kept per column: what the eye can see (0.1 mm, 0.1°), an eighth of the file size.
ROUNDING = {"x": 4, "y": 4, "heading": 1, "battery_v": 2}


def json_for_script(data: Any) -> str:
    """JSON that is safe inside an HTML ``<script>`` element: no ``<``, ``>`` or ``&`` (so no ``</script>``
    or ``<!--``) and no U+2028/U+2029 (line ends to old JavaScript), all written as ``\\uXXXX``."""
    text = json.dumps(data, ensure_ascii=False, separators=(",", ":"))
    return re.sub("[<>&\u2028\u2029]", lambda m: f"\\u{ord(m.group()):04x}", text)


def replay_data(
    lines: Iterable[Mapping[str, Any] | str],
    world: World,
    table: Table,
    params: Params | None = None,
    title: str | None = None,
) -> dict[str, Any]:
    """Everything the replay page shows, as plain JSON-able data."""
    parsed = [json.loads(line) if isinstance(line, str) else dict(line) for line in lines]
    columns = trace_columns(parsed)
    for name, places in ROUNDING.items():
        if name in columns:
            columns[name] = [None if v is None else round(v, places) for v in columns[name]]
    for name in [k for k in columns if k.endswith("_light")]:
        columns[name] = [None if v is None else round(v, 3) for v in columns[name]]
    header, grid, lines_of = _table_cells(table)
    machine = compile_table(table)
    try:  # a robot of several tables: the player says the other tables' states and lines beside the main one's
        tables = several(table)
    except TableBotError:  # its other files changed since the run: their states are still said, not their lines
        tables = None
    return {
        "title": title or f"{table.robot.name}: {Path(table.path).name} in {world.name}",
        "table": {
            "path": Path(table.path).name,
            "header": header,
            "grid": grid,
            "lines": lines_of,
            "columns": columns_of(header, table.robot),
        },
        "machine": machine_json(table, machine, tables),
        "world": world_json(world, params),
        "diagram": studio_diagram(table),
        "trace": columns,
    }


def _table_cells(table: Table) -> tuple[list[str], list[list[str]], list[int]]:
    """The table as its file shows it (as the parser read it), else as ``format_table`` writes it."""
    try:
        doc = CsvDocument.from_bytes(Path(table.path).read_bytes(), table.path)
    except (OSError, ValueError, TableBotError):
        doc = CsvDocument.from_text(format_table(table))
    starts = doc.record_lines()
    return doc.header_values(), doc.grid(), [starts[i] for i in doc.row_ids]


def render_html(data: dict[str, Any]) -> str:
    """The page: the replay template with the stylesheet, the scripts and the data inlined."""
    template = (STATIC / "replay.html").read_text(encoding="utf-8")
    style = (STATIC / "studio.css").read_text(encoding="utf-8")
    scripts = bundle(STATIC / "js", ENTRY)
    for part in (style, scripts):
        if "</" + "script" in part.lower() or "</" + "style" in part.lower():
            raise ValueError("an inlined script or stylesheet would end its element")  # a bug in the package files
    return (
        template.replace("/*STYLE*/", style).replace("/*SCRIPTS*/", scripts).replace("/*DATA*/", json_for_script(data))
    )


def write_html(
    path: str | Path,
    lines: Iterable[Mapping[str, Any] | str],
    world: World,
    table: Table,
    *,
    params: Params | None = None,
    title: str | None = None,
) -> Path:
    """Write the replay of a run to ``path`` (atomically): ``lines`` are its trace lines (dicts, or the
    JSON text lines of a trace.jsonl), ``world`` and ``table`` what it ran in and on, ``params`` the
    simulator's parameters (for the robot's outline; the default body when None)."""
    if params is None:
        from tablebot.sim.model.params import merged

        params = merged(world.params)
    return write_text(path, render_html(replay_data(lines, world, table, params, title)))
