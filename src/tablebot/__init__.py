"""tablebot: robot behaviour written as a transition table, and the engine that runs it.

Data flows one way: table file (formats.table_read) -> parsed table (table) -> compiled machine
(machine) -> engine tick (engine) <-> robot I/O (loop) -> trace (trace). See docs/architecture.md.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from tablebot.engine import Engine
    from tablebot.formats.table_read import load_table
    from tablebot.machine import Machine, compile_table
    from tablebot.table import Row, Table

__all__ = ["Engine", "Machine", "Row", "Table", "compile_table", "load_table"]
__version__ = "0.2.0"

#: Where each public name lives; imported on first use, so `import tablebot` (and `tablebot --help`)
#: does not load numpy.
_HOMES = {"Engine": "tablebot.engine", "Machine": "tablebot.machine", "compile_table": "tablebot.machine",
          "Row": "tablebot.table", "Table": "tablebot.table", "load_table": "tablebot.formats.table_read"}


def __getattr__(name: str) -> Any:
    if name in _HOMES:
        return getattr(importlib.import_module(_HOMES[name]), name)
    raise AttributeError(f"module 'tablebot' has no attribute {name!r}")
