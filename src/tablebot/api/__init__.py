"""tablebot's front door (public): open a robot and simulate, check, sweep, tune, evolve, export or run it, with
the results as objects. Every ``tablebot`` command that does one of these is this package called with the
command's options, its results printed; so each result's ``save`` writes what the command writes.

>>> import tablebot
>>> robot = tablebot.open("examples/bumberbot")
>>> robot.check().ok
True

The names below are imported on first use: ``import tablebot.api`` loads neither numpy's simulator (numba) nor
matplotlib nor Dask. The modules of the other tablebot packages are its internals (docs/api.md says which of
them are documented for use beside it).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from tablebot.api.checking import Check, PropertyResult
    from tablebot.api.evolution import Evolution
    from tablebot.api.progress import Progress, Stopped
    from tablebot.api.project import Project, open
    from tablebot.api.running import Connection, LiveRun
    from tablebot.api.simulation import Simulation
    from tablebot.api.sweeping import Sweep
    from tablebot.api.tuning import Tuning

#: Each public name and the module of this package that defines it.
_HOMES = {
    "open": "project",
    "Project": "project",
    "Simulation": "simulation",
    "Check": "checking",
    "PropertyResult": "checking",
    "Sweep": "sweeping",
    "Tuning": "tuning",
    "Evolution": "evolution",
    "Connection": "running",
    "LiveRun": "running",
    "Progress": "progress",
    "Stopped": "progress",
}

__all__ = [
    "Check",
    "Connection",
    "Evolution",
    "LiveRun",
    "Progress",
    "Project",
    "PropertyResult",
    "Simulation",
    "Stopped",
    "Sweep",
    "Tuning",
    "open",
]


def __getattr__(name: str) -> Any:
    """The public names, imported on first use (see the module)."""
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'tablebot.api' has no attribute {name!r}")
    return getattr(importlib.import_module(f"tablebot.api.{home}"), name)


def __dir__() -> list[str]:
    return sorted([*globals(), *__all__])
