"""How the tree benchmarks/kernel.py measures takes a robot's rows: as records read by name
(sim.physics.layout) or, in a tree from before them, as the float64 rows themselves (a baseline revision)."""

from __future__ import annotations

import importlib
from typing import Any

import numpy as np


def viewers(fast: Any) -> tuple[Any, Any]:
    """How the tree's physics takes a robot's state and parameter rows: as records read by name
    (sim.physics.layout's as_state, as_params) or, in a tree from before, as the float64 rows themselves."""
    try:
        layout = importlib.import_module("tablebot.sim.physics.layout")
    except ModuleNotFoundError:

        @fast
        def same(row: np.ndarray) -> np.ndarray:
            return row

        return same, same
    return layout.as_state, layout.as_params


def as_rows(rows: np.ndarray) -> np.ndarray:
    """Recorded robot rows as the tree's physics takes them: records (the same memory) or the rows."""
    try:
        return rows.view(importlib.import_module("tablebot.sim.physics.layout").STATE)[:, 0]
    except ModuleNotFoundError:
        return rows
