"""The simulator: a table runs on a modelled BumberBot (motors, battery, bumpers, light sensors) in a world.

world (TOML) + robot [sim] -> scene -> runner (core engine + physics core) -> trace, summary, pictures.

Internal to tablebot: its public API is ``tablebot`` and ``tablebot.api`` (docs/api.md, which also names the
modules stable enough to use beside them); anything here may change in any release.
"""
