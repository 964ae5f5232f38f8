"""The simulator's compiled physics (numba, through :mod:`tablebot.jit`): one tick of a robot (:mod:`.step`), its
body's contacts (:mod:`.contacts`, its broad phase in :mod:`.broad`), sensors (:mod:`.sensing`), shadows
(:mod:`.shadows`), plane geometry (:mod:`.geometry`), the noise generator (:mod:`.normals`), a robot's rows as
records read by name (:mod:`.layout`), the named structures the loops take (:mod:`.structures`) and the loops
themselves (:mod:`.kernel` for one table, :mod:`.several` for a robot of several tables). Only this package and
tablebot.jit import numba (pyproject.toml's import-linter contracts)."""

__all__ = [
    "broad",
    "contacts",
    "geometry",
    "kernel",
    "layout",
    "normals",
    "sensing",
    "several",
    "shadows",
    "step",
    "structures",
]
