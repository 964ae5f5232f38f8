"""The quality-diversity archive: pyribs' MAP-Elites grid over one or two behaviour descriptors, each
cell keeping the best table that behaves that way, and a pyribs emitter that breeds new tables from the
archive's elites with :mod:`tablebot.evolve.operators`.

A solution in the archive is a candidate's canonical key (a string: pyribs stores object solutions);
the run keeps the tables by key. Parents are drawn with a generator seeded by the run's seed and the
generation (not pyribs' own), so generation g asks for the same children in a fresh run and in a
resumed one.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from tablebot.evolve.measures import Descriptor
from tablebot.evolve.pyribs import EmitterBase, GridArchive

#: breed(parents, rng, count) -> up to ``count`` new children's keys (proved, not seen before)
Breed = Callable[[Sequence[str], np.random.Generator, int], list[str]]


def make_archive(descriptors: Sequence[Descriptor], worst: float = 0.0, seed: int = 0) -> GridArchive:
    """A grid of ``cells`` per descriptor over its range; solutions are candidate keys. ``worst``: the
    lowest objective (as maximised) a run can have, so the QD score counts every elite as a gain."""
    return GridArchive(
        solution_dim=(),
        dims=[d.cells for d in descriptors],
        ranges=[(d.low, d.high) for d in descriptors],
        solution_dtype=object,
        qd_score_offset=worst,
        seed=seed,
    )  # pyribs draws with it only in sample_elites, which evolve does not call


class TableEmitter(EmitterBase):
    """Asks for ``batch`` children of elites chosen uniformly from the archive (MAP-Elites' selection);
    ``breed`` varies, proves and deduplicates them."""

    def __init__(self, archive: GridArchive, breed: Breed, batch: int, seed: int) -> None:
        super().__init__(archive, solution_dim=archive.solution_dim, bounds=None, lower_bounds=None, upper_bounds=None)
        self.breed, self.batch, self.seed = breed, batch, seed
        self.generation = 0

    @property
    def batch_size(self) -> int:
        return self.batch

    def ask(self) -> np.ndarray:
        rng = np.random.default_rng([self.seed, self.generation])
        self.generation += 1
        data = self.archive.data(["solution", "index"])
        order = np.argsort(data["index"], kind="stable")  # the store's order is an implementation detail
        elites = [str(data["solution"][k]) for k in order]
        children = self.breed(elites, rng, self.batch) if elites else []
        out = np.empty(len(children), dtype=object)
        for k, key in enumerate(children):
            out[k] = key
        return out


def add(
    archive: GridArchive, keys: Sequence[str], objective: Sequence[float], measures: Sequence[Sequence[float]]
) -> Any:
    """Put candidates into the archive directly (the start and the repaired table, before any asking)."""
    solutions = np.empty(len(keys), dtype=object)
    for k, key in enumerate(keys):
        solutions[k] = key
    return archive.add(solutions, np.asarray(objective, dtype=float), np.asarray(measures, dtype=float))


def elites(archive: GridArchive) -> list[tuple[str, float, tuple[float, ...], tuple[int, ...]]]:
    """Every elite: key, objective (as the archive maximises it), measures, grid cell; best first."""
    data = archive.data(["solution", "objective", "measures", "index"])
    cells = archive.int_to_grid_index(data["index"]) if len(data["index"]) else []
    out = [
        (str(s), float(o), tuple(float(v) for v in m), tuple(int(c) for c in cell))
        for s, o, m, cell in zip(data["solution"], data["objective"], data["measures"], cells, strict=True)
    ]
    return sorted(out, key=lambda e: (-e[1], e[3]))
