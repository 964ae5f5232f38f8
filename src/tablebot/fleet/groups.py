"""How a sweep's results are grouped, for its report and its pictures: per grid axis (or per world) its values,
each with the rows that had it. Apart from the pictures' module, so that a sweep without pictures never loads
matplotlib."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from tablebot.fleet.spec import value_index

if TYPE_CHECKING:
    from tablebot.fleet.plan import Plan

REPORT_COLUMNS = ("run", "reached", "collisions", "distance_m")  # what the summary of a sweep reads


def groups(plan: Plan, rows: Sequence[dict[str, Any]]) -> list[tuple[str, list[tuple[str, list[dict[str, Any]]]]]]:
    """Per grid axis (or "all runs" without one): its values, each with the rows that had it."""
    out = []
    if len(plan.spec.worlds) > 1:
        by_world: list[list[dict[str, Any]]] = [[] for _ in plan.worlds]
        for r in rows:
            by_world[int(r["run"]) // plan.spec.runs_per_world].append(r)
        out.append(("world", list(zip(world_labels(plan), by_world, strict=True))))
    for k, axis in enumerate(plan.spec.axes):
        if len(axis.values) < 2:
            continue
        # by the run's value (a random start has no other mark)
        chosen: list[list[dict[str, Any]]] = [[] for _ in axis.values]
        for r in rows:
            chosen[value_index(plan.spec, int(r["run"]), k)].append(r)
        labels = [
            ":".join(f"{v:g}" for v in value) if isinstance(value, tuple) else str(value) for value in axis.values
        ]
        out.append((axis.key, list(zip(labels, chosen, strict=True))))
    return out or [("all runs", [("all", list(rows))])]


def world_labels(plan: Plan) -> list[str]:
    """Each world's name, numbered where two share one (two files both called arena.toml, say)."""
    names = [world.name for world in plan.worlds]
    return [f"{name} ({k + 1})" if names.count(name) > 1 else name for k, name in enumerate(names)]
