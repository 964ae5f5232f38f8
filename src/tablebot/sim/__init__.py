"""The simulator: a table runs on a modelled BumberBot (motors, battery, bumpers, light sensors) in a world.

world (TOML) + robot [sim] -> scene -> runner (core engine + physics core) -> trace, summary, pictures.
"""
