"""tablebot: robot behaviour written as a transition table, and the engine that runs it.

Data flows one way: table file (formats.table_read) -> parsed table (table) -> compiled machine (machine)
-> engine tick (engine) <-> robot I/O -> trace (trace).
"""

from tablebot.engine import Engine
from tablebot.formats.table_read import load_table
from tablebot.machine import Machine, compile_table
from tablebot.table import Row, Table

__all__ = ["Engine", "Machine", "Row", "Table", "compile_table", "load_table"]
__version__ = "0.1.0"
