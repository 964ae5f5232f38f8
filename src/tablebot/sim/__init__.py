"""The simulator: a table runs on a modelled BumberBot (motors, battery, bumpers, light sensors) in a world.

world (TOML) + robot [sim] -> scene -> runner (core engine + physics core) -> trace, summary, pictures.

Split by what each part owns, bottom to top (pyproject.toml's import-linter contracts hold it):
:mod:`.columns` (the column layout of a robot's arrays, shared by all), :mod:`.physics` (the compiled code,
numba), :mod:`.model` (parameters, worlds, the scene), :mod:`.simrobot` (the simulated robot the engine drives),
:mod:`.runner` (a run), :mod:`.summary` and :mod:`.backend` (``run --on sim``), :mod:`.pictures` (matplotlib).

Internal to tablebot: its public API is ``tablebot`` and ``tablebot.api`` (docs/api.md, which also names the
modules stable enough to use beside them); anything here may change in any release.
"""

__all__ = ["backend", "columns", "model", "physics", "pictures", "runner", "simrobot", "summary"]
