"""pyribs' ``GridArchive`` and ``EmitterBase``, the two classes evolve uses, imported without the rest of the
package: ``import ribs`` imports every archive, and its CVT archive imports scikit-learn and SciPy's
statistics -- about two CPU-seconds of every evolve process, for classes evolve never uses.

The modules that define the two classes are imported under placeholder parent packages (modules whose
``__init__`` has not run), which are then removed: a later ``import ribs`` anywhere runs pyribs' own
``__init__`` files as usual, which find these modules loaded and use them (the same classes). Should
pyribs move them, the package is imported whole, as before.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from typing import Any

PARENTS = ("ribs", "ribs.archives", "ribs.emitters")


def _load() -> tuple[Any, Any]:
    """The two classes: from the modules that define them when the package is not imported yet."""
    if "ribs" in sys.modules:
        return _whole()
    placed = []
    try:
        for name in PARENTS:
            spec = importlib.util.find_spec(name)
            if spec is None or spec.submodule_search_locations is None:
                raise ImportError(name)
            sys.modules[name] = importlib.util.module_from_spec(spec)  # its __init__ never runs
            placed.append(name)
        base = importlib.import_module("ribs.archives._archive_base").ArchiveBase
        # what ribs.emitters._emitter_base takes from there (through __dict__: ModuleType declares no such attribute)
        sys.modules["ribs.archives"].__dict__["ArchiveBase"] = base
        grid = importlib.import_module("ribs.archives._grid_archive").GridArchive
        emitter = importlib.import_module("ribs.emitters._emitter_base").EmitterBase
    except (ImportError, AttributeError):
        grid = emitter = None
    finally:
        for name in placed:
            del sys.modules[name]
    if grid is None:
        return _whole()
    return grid, emitter


def _whole() -> tuple[Any, Any]:
    from ribs.archives import GridArchive
    from ribs.emitters import EmitterBase

    return GridArchive, EmitterBase


GridArchive, EmitterBase = _load()
