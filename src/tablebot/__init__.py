"""tablebot: robot behaviour written as a transition table, and the engine that runs it.

The front door is :func:`open` (:mod:`tablebot.api`): open a robot's folder, table or robot file, then
simulate, check, sweep, tune, evolve, export or run it, the results as objects::

    import tablebot
    robot = tablebot.open("examples/bumberbot")
    run = robot.simulate(seconds=60, seed=1)

Beside it, the table and its engine: :func:`load_table`, :func:`compile_table`, :class:`Engine`. These names
are the public API (``__all__``; docs/api.md); the other modules are tablebot's internals. Data flows one way:
table file (formats.table_read) -> parsed table (table) -> compiled machine (machine) -> engine tick (engine)
<-> robot I/O (loop) -> trace. See docs/architecture.md.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from tablebot.api import Project, open
    from tablebot.engine import Engine
    from tablebot.formats.table_read import load_table
    from tablebot.machine import Machine, compile_table
    from tablebot.table import Row, Table

__all__ = ["Engine", "Machine", "Project", "Row", "Table", "compile_table", "load_table", "open"]
__version__ = "0.2.0"


def __getattr__(name: str) -> Any:
    """The public names, imported on first use, so `import tablebot` (and `tablebot --help`) does not load numpy."""
    if name in ("open", "Project"):
        from tablebot import api

        return getattr(api, name)
    if name == "Engine":
        from tablebot.engine import Engine

        return Engine
    if name in ("Machine", "compile_table"):
        from tablebot import machine

        return getattr(machine, name)
    if name in ("Row", "Table"):
        from tablebot import table

        return getattr(table, name)
    if name == "load_table":
        from tablebot.formats.table_read import load_table

        return load_table
    raise AttributeError(f"module 'tablebot' has no attribute {name!r}")


# Every back-end registers itself and its robot-file section when the registry or a robot file's reader first
# needs them (tablebot.plugins): their modules bring the table machinery, which `tablebot --help` does without.
from tablebot import catalog  # noqa: E402

catalog.defer()
